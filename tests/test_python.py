"""test_python.py -- the Python package silc (bindings/python/silc) in both
of its modes: against the silcd of the test fixture (SILC_SERVER set: the
pure-Python protocol client) and embedded (no SILC_SERVER: libsilc through
ctypes, SILC_LIBRARY naming it): numpy arrays and CSR in, EXEC, values out
and compared; s["x"] indexing; errors, output, warnings, names, delete,
info as a typed dict, explain; the conventions a SciPy user expects (shapes
kept, scalars as floats, csr_array/csr_matrix kept, band as dia_array,
complex refused, KeyError, __version__, docstrings, errors naming the
socket); and the 1-D diffusion example against the exact solution.

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

    # Complex input is refused, not made real; nothing is stored.
    import scipy.sparse as sp
    for what, z in (("complex array", np.array([1 + 2j, 3])), ("complex scalar", 1j),
                    ("complex sparse", sp.csr_array(np.array([[1j, 0], [0, 1]])))):
        expect_error(lambda: s.put("z", z), "'z': complex values are not supported", what)
    check("z" not in s, "a refused complex value stores nothing")
    expect_error(lambda: s.put("t", "text"), "'t': cannot store a str", "a string")

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

# Limits given wrong are errors naming them.
expect_error(lambda: silc.Session(missing, timeout=-1), "a timeout must be >= 0", "timeout=-1")
os.environ["SILC_IO_TIMEOUT"] = "soon"
expect_error(lambda: silc.Session(missing), "SILC_IO_TIMEOUT = 'soon': expected seconds",
             "SILC_IO_TIMEOUT=soon")
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
