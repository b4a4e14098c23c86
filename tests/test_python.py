"""test_python.py -- the Python package silc (bindings/python/silc) in both
of its modes: against the silcd of the test fixture (SILC_SERVER set: the
pure-Python protocol client) and embedded (no SILC_SERVER: libsilc through
ctypes, SILC_LIBRARY naming it): numpy arrays and CSR in, EXEC, values out
and compared; s["x"] indexing; errors, output, warnings, names, delete,
info as a dict, explain; and the 1-D diffusion example against the exact
solution.

    SILC_SERVER=unix:/path /usr/bin/python3 tests/test_python.py bindings/python

Prints "N passed, N failed" last and exits 1 on a failure.
"""
import math
import sys

import numpy as np

sys.path.insert(0, sys.argv[1] if len(sys.argv) > 1 else "bindings/python")
import silc  # noqa: E402
import diffusion1d  # noqa: E402

from pychecks import check, done  # noqa: E402 (tests/, beside this file)


def expect_error(fn, text, what):
    try:
        fn()
    except silc.Error as e:
        check(text in str(e), "%s: message '%s' lacks '%s'" % (what, e, text))
        return
    check(False, "%s: no error" % what)


with silc.Session() as s:
    rng = np.random.default_rng(7)
    M = rng.standard_normal((6, 4))
    v = rng.standard_normal(4)
    s.put("M", M)
    s.put("v", v)
    s.exec("y = M * v; n = norm(v)")
    y = s.get("y")
    check(y.shape == (6, 1) and np.allclose(y[:, 0], M @ v, rtol=1e-14, atol=1e-14), "M * v")
    check(abs(s.get("n")[0, 0] - np.linalg.norm(v)) < 1e-14, "norm(v)")
    check(np.array_equal(s.get("M"), M), "dense round trip is exact")
    Mc = np.ascontiguousarray(M[:, :3])
    s.put("Mc", Mc)
    check(np.array_equal(s.get("Mc"), Mc), "C-ordered array round trip")
    s.put("k", 2.5)
    check(s.get("k").shape == (1, 1) and s.get("k")[0, 0] == 2.5, "scalar")

    A = diffusion1d.tridiagonal(50, 4.0, -1.0)
    s.put("A", A)
    s.put("b", np.ones(50))
    s.exec("x = A \\ b; r = norm(A * x - b)")
    check(s.get("r")[0, 0] < 1e-12, "sparse solve residual")
    Aback = s.get("A")
    dense = Aback.toarray() if hasattr(Aback, "toarray") else None
    check(dense is not None and dense[3, 3] == 4.0 and dense[3, 4] == -1.0 and dense[3, 5] == 0,
          "CSR round trip")

    expect_error(lambda: s.get("nosuch"), "undefined name 'nosuch'", "GET undefined")
    expect_error(lambda: s.exec("z = (1 + "), "expected", "parse error")
    expect_error(lambda: s.put("1bad", v), "invalid name '1bad'", "invalid name")
    out = []
    s.exec("who", out)
    text = "".join(out)
    check("M " in text and "Mc" in text, "who output: %r" % text)
    check("would" in s.explain("c = A \\ b"), "explain")
    if s.remote:
        check(s.info()["bytes"] > 0, "session info: %r" % s.info())
    else:
        expect_error(lambda: s.info(), "an embedded session has", "session info is a server's")
    inf = s.info("x")
    check(isinstance(inf["backend"], str) and 0 <= inf["backward error"] < 1e-12
          and inf["value"].startswith("50x1 dense"), "info('x') as a dict: %r" % inf)
    s["k2"] = np.eye(2)
    check("k2" in s and np.array_equal(s["k2"], np.eye(2)), "s[name] = ..., s[name], in")
    del s["k2"]
    check("k2" not in s, "del s[name]")
    check("x" in s.names() and "M" in s.names(), "LIST")
    s.delete("Mc")
    check("Mc" not in s.names(), "DELETE")
    expect_error(lambda: s.delete("Mc"), "undefined name 'Mc'", "DELETE undefined")
    s.exec("W = ones(2,2) + eye(2)*1e-14; q = W \\ ones(2,1)")
    check("condition estimate" in s.warnings, "warnings: %r" % s.warnings)

    err, _ = diffusion1d.run(s, 100, 200, 0.5)
    h = math.pi / 101
    bound = 0.5 * h * h * math.exp(-0.5) / 12
    check(err < 1.5 * bound + 1e-5, "diffusion1d error %.3e vs estimate %.3e" % (err, bound))

# Names never leak between sessions.
with silc.Session() as s2:
    check(s2.names() == [], "a new session sees no names")

done()
