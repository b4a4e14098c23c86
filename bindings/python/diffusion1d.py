"""diffusion1d.py -- the 1-D diffusion example of examples/diffusion1d.c, in
Python, embedded or against a silcd server: Crank-Nicolson for u_t = u_xx
on [0, pi], u(x, 0) = sin x, u = 0 at both ends; exact solution
e^{-t} sin x.

    SILC_LIBRARY=build/lib/libsilc.so.1 /usr/bin/python3 diffusion1d.py [N [steps [T]]]
    SILC_SERVER=tcp://127.0.0.1:7070 /usr/bin/python3 diffusion1d.py [N [steps [T]]]

The tridiagonal A = I - dt/2 L and B = I + dt/2 L are built here as CSR and
deposited once; every step is "b = B * u; u = A \\ b" on the server.  Prints
the maximum error against the exact solution (about T h^2 e^{-T} / 12).
"""
import math
import sys

import numpy as np

import silc


def tridiagonal(n, diag, off):
    """CSR of the n x n matrix with diag on the diagonal, off beside it."""
    indptr, indices, data = [0], [], []
    for i in range(n):
        for j, v in ((i - 1, off), (i, diag), (i + 1, off)):
            if 0 <= j < n:
                indices.append(j)
                data.append(v)
        indptr.append(len(indices))
    return (np.array(indptr), np.array(indices), np.array(data), (n, n))


def run(session, n=100, steps=500, t_end=0.5):
    """Returns (max error, u) after steps Crank-Nicolson steps to t_end."""
    h = math.pi / (n + 1)
    dt = t_end / steps
    r = dt / (2 * h * h)
    x = h * np.arange(1, n + 1)
    session.put("A", tridiagonal(n, 1 + 2 * r, -r))
    session.put("B", tridiagonal(n, 1 - 2 * r, r))
    session.put("u", np.sin(x))
    for _ in range(steps):
        session.exec("b = B * u; u = A \\ b")
    u = session.get("u")                   # 1-D, as it was put
    return float(np.max(np.abs(u - math.exp(-t_end) * np.sin(x)))), u


def main(argv):
    n = int(argv[1]) if len(argv) > 1 else 100
    steps = int(argv[2]) if len(argv) > 2 else 500
    t_end = float(argv[3]) if len(argv) > 3 else 0.5
    with silc.Session() as s:
        err, _ = run(s, n, steps, t_end)
    h = math.pi / (n + 1)
    print("N = %d, steps = %d, T = %g: max error %.3e (spatial estimate %.3e)"
          % (n, steps, t_end, err, t_end * h * h * math.exp(-t_end) / 12))
    return 0


if __name__ == "__main__":
    try:
        sys.exit(main(sys.argv))
    except silc.SilcError as e:
        print("diffusion1d.py: %s" % e, file=sys.stderr)
        sys.exit(1)
