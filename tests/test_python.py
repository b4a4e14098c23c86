"""test_python.py -- the Python package silc (bindings/python/silc) in both
of its modes: against the silcd of the test fixture (SILC_SERVER set: the
pure-Python protocol client) and embedded (no SILC_SERVER: libsilc through
ctypes, SILC_LIBRARY naming it): numpy arrays and CSR in, EXEC, values out
and compared; s["x"] indexing; errors, output, warnings, names, delete,
info as a typed dict, explain; the conventions a SciPy user expects (shapes
kept, scalars as floats, csr_array/csr_matrix kept, band as dia_array,
KeyError, __version__, docstrings, errors naming the socket); complex
values (issue 31: numpy complex128 and scipy complex sparse in, bit-exact
round trips, a complex tridiagonal solve against its exact solution,
complex64 promoted, object arrays refused, a plain GET refused); and the
1-D diffusion example against the exact solution.

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


def complex_computations(s, Ad, x_true):
    """What a session computes on complex values (Az, bz and zs put):
    x = A \ b, sparse and dense, against x_true within 10 n eps cond_1(A);
    dense() and band() of complex CSR; scalar arithmetic and real(); and
    disp() printed as Octave prints it."""
    import scipy.sparse as sp
    n = len(x_true)
    s.exec("Adz = dense(Az); xd = Adz \\ bz")
    cond1 = np.linalg.norm(Ad, 1) * np.linalg.norm(np.linalg.inv(Ad), 1)
    bound = 10 * n * np.finfo(float).eps * cond1
    for name in ("xz", "xd"):
        x = s.get(name)
        err = np.linalg.norm(x - x_true, np.inf) / np.linalg.norm(x_true, np.inf)
        check(x.dtype == np.complex128 and x.shape == (n,) and err <= bound,
              "complex solve %s: dtype %s shape %r, error %.2e (bound %.2e, cond_1 %.1f)"
              % (name, x.dtype, x.shape, err, bound, cond1))
    Adback = s.get("Adz")
    check(Adback.dtype == np.complex128 and np.array_equal(Adback, Ad),
          "dense(A) of complex CSR comes back the complex dense matrix")
    s.exec("Bz = band(Az, 1, 1)")
    Bz = s.get("Bz")
    check(type(Bz) is sp.dia_array and Bz.dtype == np.complex128 and np.array_equal(Bz.toarray(), Ad),
          "a complex band value comes back a complex dia_array")
    s.exec("w = zs * zs; re = real(w)")
    w = s.get("w")
    check(type(w) is complex and w == -3 + 4j, "(1 + 2i)^2 comes back a Python complex: %r" % (w,))
    check(type(s.get("re")) is float and s.get("re") == -3.0, "real(w) comes back a float")
    out = []
    s.exec("disp(zs)", out)
    check("".join(out).strip() == "1 + 2i", "disp of a complex scalar prints as Octave: %r" % out)


with silc.Session() as s:
    rng = np.random.default_rng(7)
    M = rng.standard_normal((6, 4))
    v = rng.standard_normal(4)
    s.put("M", M)
    s.put("v", v)
    s.exec("y = M * v; n = norm(v)")
    y = s.get("y")
    check(y.shape == (6,) and np.allclose(y, M @ v, rtol=1e-14, atol=1e-14),
          "M * v is 1-D, as spsolve's result: %r" % (y.shape,))
    nv = s.get("n")
    check(type(nv) is float and abs(nv - np.linalg.norm(v)) < 1e-14, "norm(v) is a float: %r" % nv)
    check(np.array_equal(s.get("M"), M), "dense round trip is exact")
    check(s.get("v").shape == (4,) and np.array_equal(s.get("v"), v), "1-D stays 1-D")
    Mc = np.ascontiguousarray(M[:, :3])
    s.put("Mc", Mc)
    check(np.array_equal(s.get("Mc"), Mc), "C-ordered array round trip")
    s.put("k", 2.5)
    check(s.get("k") == 2.5 and type(s.get("k")) is float, "scalar comes back a float")
    s.put("col", np.ones((3, 1)))
    s.put("one", np.ones((1, 1)))
    s.put("v1", np.ones(1))
    check(s.get("col").shape == (3, 1) and s.get("one").shape == (1, 1)
          and s.get("v1").shape == (1,), "2-D (3,1), (1,1) and 1-D (1,) kept as put")
    s.exec("col = col * 2")
    check(s.get("col").shape == (3, 1) and s.get("col")[2, 0] == 2, "a name put 2-D stays 2-D")

    import scipy.sparse as sp
    expect_error(lambda: s.put("t", "text"), "'t': cannot store a str", "a string")
    expect_error(lambda: s.put("t", np.array([1.0, 2j, "a"], dtype=object)),
                 "'t': cannot store a ndarray of dtype object", "an object array")
    check("t" not in s, "a refused value stores nothing")

    # Complex values (issue 31).  A Helmholtz-like complex tridiagonal
    # (complex symmetric, not Hermitian) with the exact solution x_true:
    # b = A x_true exactly enough that x must match x_true within the
    # forward error bound n eps cond_1(A) (times a safety factor of 10).
    nz = 40
    d = np.full(nz, 2.0 - 0.3 + 0.5j)
    off = np.full(nz - 1, -1.0 + 0.1j)
    Az = sp.diags([off, d, off], [-1, 0, 1], format="csr")
    x_true = np.array([complex(1 + k % 3, 2 - k % 5) for k in range(nz)])
    x_true[0] = 1 + 2j
    s.put("Az", sp.csc_array(Az))             # converted to CSR as the real path converts
    s.put("bz", Az @ x_true)
    Aback = s.get("Az")
    check(type(Aback) is sp.csr_array and Aback.dtype == np.complex128
          and (Aback != Az).nnz == 0, "complex CSR comes back a complex csr_array equal to A")
    s.put("zs", 1 + 2j)
    check(type(s.get("zs")) is complex and s.get("zs") == 1 + 2j,
          "a complex scalar comes back a Python complex")
    # silcd --mpi (test_python_mpi_server) does not distribute complex
    # values yet: its refusal must say so and bind nothing; the round trips
    # below hold there too.
    try:
        s.exec("xz = Az \\ bz")
        spmd = False
    except silc.Error as e:
        spmd = True
        check(s.remote and "complex values are not distributed" in str(e) and "xz" not in s,
              "a complex solve refused only by an MPI server, naming why: %s" % e)
    if not spmd:
        complex_computations(s, Az.toarray(), x_true)

    # Bit-for-bit round trips: dense (C- and F-ordered), 1-D, CSR, COO, scalar.
    Z = rng.standard_normal((5, 3)) + 1j * rng.standard_normal((5, 3))
    Z[0, 0] = complex(-0.0, 5e-324)           # a signed zero and a subnormal part
    Zs = sp.random(30, 20, density=0.2, random_state=3, format="coo")
    Zs = sp.coo_array(Zs + 1j * sp.random(30, 20, density=0.2, random_state=4, format="coo"))
    for name, z in (("Zc", Z), ("Zf", np.asfortranarray(Z)), ("zv", Z[:, 1].copy())):
        s.put(name, z)
        back = s.get(name)
        check(back.dtype == np.complex128 and back.shape == z.shape
              and np.array_equal(np.ascontiguousarray(back).view(np.uint64),
                                 np.ascontiguousarray(z).view(np.uint64)),
              "complex %s round trip bit for bit" % name)
    s.put("Zs", Zs)
    want = Zs.tocsr()
    want.sort_indices()
    got = s.get("Zs")
    check(got.dtype == np.complex128 and np.array_equal(got.indptr, want.indptr)
          and np.array_equal(got.indices, want.indices)
          and np.array_equal(got.data.view(np.uint64), want.data.view(np.uint64)),
          "complex COO round trip (as CSR) bit for bit")
    z64 = np.array([1.5 + 0.25j, -2 - 1j], dtype=np.complex64)
    s.put("z64", z64)
    back = s.get("z64")
    check(back.dtype == np.complex128 and np.array_equal(back, z64.astype(np.complex128)),
          "complex64 is promoted to complex128")
    s.put("zl", [1 + 2j, 3])                 # a list: its dtype decides, never float64 by force
    check(np.array_equal(s.get("zl"), np.array([1 + 2j, 3])), "a list of complex numbers stays complex")
    s.put("rv", np.float32(3.5))
    check(type(s.get("rv")) is float, "a real value stays real")
    if s.remote:
        # The plain GET (what a client older than complex values sends) is
        # refused by the server, naming the value, never half of it.
        from silc._remote import GET
        s._s._send(GET, b"zv")
        expect_error(lambda: s._s._reply(), "'zv' is complex", "a plain GET of a complex value")
        check(np.array_equal(s.get("zv"), Z[:, 1]), "the session goes on after the refused GET")

    # A missing name is a KeyError too.
    for what, fn in (("s[name]", lambda: s["nope"]), ("del s[name]", lambda: s.__delitem__("nope"))):
        try:
            fn()
            check(False, "%s: no error" % what)
        except KeyError as e:
            check(isinstance(e, silc.Error) and str(e).startswith("undefined name 'nope'"),
                  "%s: KeyError %s" % (what, e))

    A = diffusion1d.tridiagonal(50, 4.0, -1.0)
    s.put("A", A)
    s.put("b", np.ones(50))
    s.exec("x = A \\ b; r = norm(A * x - b)")
    check(s.get("r") < 1e-12, "sparse solve residual")
    Aback = s.get("A")
    check(type(Aback) is sp.csr_array, "CSR as csr_array by default: %s" % type(Aback))
    dense = Aback.toarray()
    s.put("Am", sp.csr_matrix(dense))
    check(type(s.get("Am")) is sp.csr_matrix and type(s.get("A")) is sp.csr_matrix,
          "after a csr_matrix put, CSR comes back as csr_matrix")
    check(dense[3, 3] == 4.0 and dense[3, 4] == -1.0 and dense[3, 5] == 0, "CSR round trip")
    s.put("As", sp.csr_array(dense))
    check(type(s.get("As")) is sp.csr_array and type(s.get("A")) is sp.csr_array,
          "after a csr_array put, CSR comes back as csr_array")
    s.exec("Bd = band(A, 1, 1)")
    Bd = s.get("Bd")
    check(type(Bd) is sp.dia_array and np.array_equal(Bd.toarray(), dense),
          "band comes back as a dia_array equal to the matrix: %s" % type(Bd))

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
    check(isinstance(inf["backend"], str) and type(inf["backward error"]) is float
          and 0 <= inf["backward error"] < 1e-12 and inf["value"].startswith("50x1 dense")
          and inf["shape"] == (50, 1) and inf["nnz"] == 50 and inf["format"] == "dense"
          and type(inf["iterations"]) is int and type(inf["reused factorization"]) is bool
          and type(inf["wall time"]) is float and type(inf["condition estimate"]) is float,
          "info('x') typed: %r" % inf)
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

import os  # noqa: E402

# A server that is not there: silc.Error naming the socket, not a bare
# FileNotFoundError.
missing = "unix:/nonexistent-dir/silc.sock"
try:
    silc.Session(missing)
    check(False, "no error for a missing socket")
except silc.Error as e:
    check(missing in str(e) and "No such file" in str(e), "missing socket: %s" % e)

# A host that refuses the connection: the error names it (a port just
# bound and closed again, so nothing listens there).
import socket  # noqa: E402
probe = socket.socket()
probe.bind(("127.0.0.1", 0))
refusing = "tcp://127.0.0.1:%d" % probe.getsockname()[1]
probe.close()
try:
    silc.Session(refusing)
    check(False, "no error for a host that refuses")
except silc.Error as e:
    check(refusing in str(e) and "refused" in str(e), "refusing host: %s" % e)

# Limits given wrong are errors naming them.
expect_error(lambda: silc.Session(missing, timeout=-1),
             "a timeout must be 0 (none) or seconds from 0.001 to 31536000, not -1", "timeout=-1")
# Time values outside [1 ms, a year] (issue 32): 1e30 was an OverflowError
# from the socket, 1e-7 a timeout no reply can meet.
for text in ["soon", "1e30", "inf", "0.0000001", "-1"]:
    os.environ["SILC_IO_TIMEOUT"] = text
    expect_error(lambda: silc.Session(missing), "SILC_IO_TIMEOUT = '%s': expected 0 (no timeout) or "
                 "seconds from 0.001 to 31536000" % text, "SILC_IO_TIMEOUT=%s" % text)
del os.environ["SILC_IO_TIMEOUT"]

# __version__ is the CMake project's, and help(silc.Session) shows examples.
import pydoc  # noqa: E402
import re  # noqa: E402
with open(os.path.join(sys.argv[1] if len(sys.argv) > 1 else "bindings/python", "..", "..",
                       "CMakeLists.txt")) as f:
    cmake_version = re.search(r"project\(silc VERSION ([0-9.]+)", f.read()).group(1)
check(silc.__version__ == cmake_version, "__version__ %s, CMake %s" % (silc.__version__, cmake_version))
doc = pydoc.render_doc(silc.Session)
check(">>>" in doc and "max_value_bytes" in doc and "s.exec(" in doc, "help(silc.Session)")

# Names never leak between sessions.
with silc.Session() as s2:
    check(s2.names() == [], "a new session sees no names")

done()
