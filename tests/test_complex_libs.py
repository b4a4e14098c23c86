"""test_complex_libs.py -- the library plugins on complex values (issue 31).

Each built library backend's complex solve, run by the harness
test_complex_libs.c (a host of its own, so the plugin is tested apart from
the engine), is checked against independent truth:
  (a) the two complex shared matrices (young1c, general; mhd1280b,
      Hermitian positive definite) with b = A x_true: the forward error
      within 10 n eps cond_1(A), and x agreeing with SciPy's spsolve within
      the same bound;
  (b) Hermitian positive definite systems under the .spd classes (CHOLMOD,
      zpotrf), and a Hermitian matrix that is not positive definite refused
      with SILC_ENOTSPD;
  (c) a complex symmetric (A = A.', not Hermitian) system (zsytrf);
  (d) the condition estimate within a factor 10 of the dense cond_1 NumPy
      computes;
  (e) an exactly singular complex matrix reported as singular (status 3);
and a second solve with the same A reuses the factorization.  MUMPS must
send a complex symmetric A to SYM=2, a Hermitian one to SYM=0, and decline
the .spd classes for complex values (it has no Hermitian Cholesky).  The lapack
backend also gets a complex band system (zgbtrf) and tall least squares
(zgeqrf, checked against numpy.linalg.lstsq).

Then, with the silc command given, the same solves through the language
(silc --put, solve(A, b, "backend = NAME"), --get x): each built backend,
named by `info`, and the default dispatch of x = A \ b going to a library.

  test_complex_libs.py HARNESS PLUGIN_DIR MATRICES WORKDIR [SILC]

Prints "N passed, N failed" and exits 1 on any failure.
"""
import os
import subprocess
import sys

import numpy as np
import scipy.io
import scipy.sparse as sp
import scipy.sparse.linalg as sla

MAGIC = 0x51C
EPS = np.finfo(float).eps
SILC_ESINGULAR, SILC_ENOTSPD = 3, 4

harness, plugin_dir, matrices, workdir = sys.argv[1:5]
silc_cli = sys.argv[5] if len(sys.argv) > 5 else None
os.makedirs(workdir, exist_ok=True)
passed = failed = 0


def check(ok, what):
    global passed, failed
    if ok:
        passed += 1
    else:
        failed += 1
        print("FAIL:", what)


def write_value(path, A):
    """A (dense ndarray or scipy sparse) in the harness's format."""
    with open(path, "wb") as f:
        if sp.issparse(A):
            A = sp.csr_matrix(A)
            A.sort_indices()
            cx = np.iscomplexobj(A.data)
            m, n = A.shape
            np.array([MAGIC, 1, int(cx), m, n, A.nnz], dtype=np.int64).tofile(f)
            A.indptr.astype(np.int64).tofile(f)
            A.indices.astype(np.int64).tofile(f)
            A.data.astype(np.complex128 if cx else np.float64).tofile(f)
        else:
            A = np.atleast_2d(A.T).T  # a vector is one column
            cx = np.iscomplexobj(A)
            m, n = A.shape
            np.array([MAGIC, 0, int(cx), m, n, m * n], dtype=np.int64).tofile(f)
            np.asfortranarray(A).astype(np.complex128 if cx else np.float64).ravel(order="F").tofile(f)


def read_value(path):
    with open(path, "rb") as f:
        h = np.fromfile(f, dtype=np.int64, count=6)
        assert h[0] == MAGIC and h[1] == 0
        v = np.fromfile(f, dtype=np.complex128 if h[2] else np.float64, count=h[5])
    return v.reshape((h[3], h[4]), order="F")


def solve(plugin, backend, cls, A, B, tag, solves=1):
    """Runs the harness; returns (report dict of the last solve, x or None)."""
    a, b, x = (os.path.join(workdir, f"{tag}.{s}") for s in ("A", "b", "x"))
    write_value(a, A)
    write_value(b, B)
    if os.path.exists(x):
        os.remove(x)
    lib = os.path.join(plugin_dir, f"libsilc_plugin_{plugin}.so")
    out = subprocess.run([harness, lib, backend, cls, a, b, x, str(solves)], capture_output=True,
                         text=True, timeout=300)
    rep = {"reused": []}
    for line in out.stdout.splitlines():
        key, _, val = line.partition(" ")
        if key == "reused":
            rep["reused"].append(int(val))
        else:
            rep[key] = val
    if out.returncode != 0:
        print(out.stdout, out.stderr)
    check(out.returncode == 0, f"{tag}: harness ran")
    check(rep.get("complex_ops") == "1", f"{tag}: {backend} lists SOLVE in complex_ops")
    return rep, (read_value(x) if rep.get("status") == "0" and os.path.exists(x) else None)


_conds = {}


def cond1(Ad):
    """cond_1 of a dense matrix, computed once per matrix."""
    key = (Ad.shape, Ad.tobytes()[:4096], float(np.abs(Ad).sum()))
    if key not in _conds:
        _conds[key] = float(np.linalg.cond(Ad, 1).real)
    return _conds[key]


def dense(A):
    return A.toarray() if sp.issparse(A) else A


def x_true_for(n, k=1):
    j = np.arange(n * k).reshape(n, k, order="F")
    return (1 + j % 7) + 1j * (j % 5 - 2.0)


def check_solve(plugin, backend, cls, A, tag, truth=True, cond_check=True):
    """(a), (d) and reuse: b = A x_true, the solve, the bounds."""
    n = A.shape[0]
    xt = x_true_for(n)
    b = A @ xt
    rep, x = solve(plugin, backend, cls, A, b, tag, solves=2)
    check(rep.get("status") == "0" and x is not None,
          f"{tag}: solved ({rep.get('status')}: {rep.get('message')})")
    if x is None:
        return
    Ad = dense(A)
    cond = cond1(Ad)
    bound = 10 * n * EPS * cond
    err = np.abs(x - xt).sum() / np.abs(xt).sum()
    check(err <= bound, f"{tag}: forward error {err:.3g} <= 10 n eps cond_1 = {bound:.3g}")
    if truth:
        xs = sla.spsolve(sp.csc_matrix(A), b) if sp.issparse(A) else np.linalg.solve(Ad, b).ravel()
        xs = np.asarray(xs).reshape(x.shape)
        agree = np.abs(x - xs).sum() / np.abs(xs).sum()
        check(agree <= 2 * bound, f"{tag}: agrees with SciPy ({agree:.3g} <= {2 * bound:.3g})")
    check(rep["reused"] == [0, 1], f"{tag}: the second solve reuses the factorization ({rep['reused']})")
    if cond_check:
        est = float(rep.get("cond_est", "-1"))
        check(cond / 10 <= est <= cond * 10,
              f"{tag}: condition estimate {est:.4g} within 10x of cond_1 {cond:.4g}")
    print(f"{tag}: n={n} err={err:.2e} cond_1={cond:.3g} est={rep.get('cond_est')} "
          f"method={rep.get('method')}")


def singular_matrix(n=8):
    rng = np.random.default_rng(31)
    A = rng.standard_normal((n, n)) + 1j * rng.standard_normal((n, n))
    A[:, 3] = 0  # a zero column: exactly singular, whatever the pivoting
    return A


def check_singular(plugin, backend, cls, A, tag):
    rep, _ = solve(plugin, backend, cls, A, np.ones(A.shape[0], complex), tag)
    check(rep.get("status") == str(SILC_ESINGULAR),
          f"{tag}: singular matrix reported as singular (status {rep.get('status')}: {rep.get('message')})")


def hermitian_indefinite(n=30):
    rng = np.random.default_rng(7)
    M = rng.standard_normal((n, n)) + 1j * rng.standard_normal((n, n))
    H = M + M.conj().T
    np.fill_diagonal(H, np.abs(np.diag(H)) + 1)  # positive real diagonal, still indefinite
    return H


def complex_symmetric(n=60):
    rng = np.random.default_rng(5)
    M = rng.standard_normal((n, n)) + 1j * rng.standard_normal((n, n))
    return M + M.T + 2 * n * np.eye(n) * (1 + 1j)


young = sp.csr_matrix(scipy.io.mmread(os.path.join(matrices, "young1c.mtx")))
mhd = sp.csr_matrix(scipy.io.mmread(os.path.join(matrices, "mhd1280b.mtx")))
have = lambda p: os.path.exists(os.path.join(plugin_dir, f"libsilc_plugin_{p}.so"))

if have("lapack"):
    check_solve("lapack", "lapack", "solve.dense", young.toarray(), "lapack.young1c")
    check_solve("lapack", "lapack", "solve.dense.spd", mhd.toarray(), "lapack.mhd1280b.zpotrf")
    rep, _ = solve("lapack", "lapack", "solve.dense.spd", hermitian_indefinite(), np.ones(30, complex),
                   "lapack.indefinite")
    check(rep.get("status") == str(SILC_ENOTSPD), f"lapack: Hermitian indefinite gives ENOTSPD ({rep})")
    S = complex_symmetric()
    check_solve("lapack", "lapack", "solve.dense", S, "lapack.complex_symmetric")
    rep, _ = solve("lapack", "lapack", "solve.dense", S, S @ x_true_for(60), "lapack.zsytrf_method")
    check("zsytrf" in rep.get("method", ""), f"lapack: complex symmetric A goes to zsytrf ({rep.get('method')})")
    n = 200
    rng = np.random.default_rng(3)
    Band = (np.diag(4 + 1j + rng.standard_normal(n)) + np.diag(rng.standard_normal(n - 1) * 1j, 1)
            + np.diag(rng.standard_normal(n - 1), -1) + np.diag(rng.standard_normal(n - 2) * (1 - 1j), -2))
    check_solve("lapack", "lapack", "solve.band", Band, "lapack.band")
    T = rng.standard_normal((80, 30)) + 1j * rng.standard_normal((80, 30))
    bt = rng.standard_normal(80) + 1j * rng.standard_normal(80)
    rep, x = solve("lapack", "lapack", "solve.rect", T, bt, "lapack.rect")
    xl = np.linalg.lstsq(T, bt, rcond=None)[0]
    check(x is not None and np.abs(x.ravel() - xl).sum() / np.abs(xl).sum() <= 1e3 * EPS * np.linalg.cond(T),
          f"lapack: least squares agrees with numpy.linalg.lstsq ({rep.get('method')})")
    check_singular("lapack", "lapack", "solve.dense", singular_matrix(), "lapack.singular")

for backend in ("umfpack", "klu"):
    if have("suitesparse"):
        check_solve("suitesparse", backend, "solve.sparse", young, f"{backend}.young1c")
        check_solve("suitesparse", backend, "solve.sparse", mhd, f"{backend}.mhd1280b")
        check_solve("suitesparse", backend, "solve.sparse", sp.csr_matrix(complex_symmetric()),
                    f"{backend}.complex_symmetric")
        check_singular("suitesparse", backend, "solve.sparse", sp.csr_matrix(singular_matrix()),
                       f"{backend}.singular")
if have("suitesparse"):
    check_solve("suitesparse", "cholmod", "solve.sparse.spd", mhd, "cholmod.mhd1280b")
    rep, _ = solve("suitesparse", "cholmod", "solve.sparse.spd", sp.csr_matrix(hermitian_indefinite()),
                   np.ones(30, complex), "cholmod.indefinite")
    check(rep.get("status") == str(SILC_ENOTSPD), f"cholmod: Hermitian indefinite gives ENOTSPD ({rep})")

if have("mumps"):
    check_solve("mumps", "mumps", "solve.sparse", young, "mumps.young1c")
    check_solve("mumps", "mumps", "solve.sparse", mhd, "mumps.mhd1280b")
    S = sp.csr_matrix(complex_symmetric())
    check_solve("mumps", "mumps", "solve.sparse", S, "mumps.complex_symmetric")
    rep, _ = solve("mumps", "mumps", "solve.sparse", S, S @ x_true_for(60), "mumps.sym2_method")
    check("SYM=2" in rep.get("method", ""), f"mumps: complex symmetric A goes to SYM=2 ({rep.get('method')})")
    rep, _ = solve("mumps", "mumps", "solve.sparse", mhd, mhd @ x_true_for(1280), "mumps.hermitian_method")
    check("SYM=0" in rep.get("method", ""), f"mumps: a Hermitian A goes to SYM=0 ({rep.get('method')})")
    rep, _ = solve("mumps", "mumps", "solve.sparse.spd", mhd, mhd @ x_true_for(1280), "mumps.spd_declined")
    check(rep.get("declined", "").startswith("MUMPS has no Hermitian Cholesky"),
          f"mumps: complex under .spd declined with its reason ({rep})")
    check_singular("mumps", "mumps", "solve.sparse", sp.csr_matrix(singular_matrix()), "mumps.singular")

# ---- through the language: the engine's complex store and dispatcher ----------
# silc --put A=FILE --put b=FILE -e 'x = solve(A, b, "backend = NAME"); info x' --get x
# for each backend built, then the default dispatch of x = A \ b.
def silc_solve(tag, matrix_file, A, backend, expr=None):
    bfile = os.path.join(workdir, f"{tag}.b.mtx")
    xt = x_true_for(A.shape[0]).ravel()
    b = A @ xt
    scipy.io.mmwrite(bfile, b.reshape(-1, 1))
    stmt = expr or f'x = solve(A, b, "backend = {backend}"); info x'
    out = subprocess.run([silc_cli, "--put", f"A={matrix_file}", "--put", f"b={bfile}", "-e", stmt, "--get", "x"],
                         capture_output=True, text=True, timeout=300)
    check(out.returncode == 0, f"{tag}: silc ran ({out.stderr.strip()[:300]})")
    if out.returncode != 0:
        return None, out.stdout
    mm = out.stdout[out.stdout.index("%%MatrixMarket"):]
    import io
    x = np.asarray(scipy.io.mmread(io.StringIO(mm))).ravel()
    Ad = dense(A)
    cond = cond1(Ad)
    xs = sla.spsolve(sp.csc_matrix(A), b)
    bound = 10 * A.shape[0] * EPS * cond
    err = np.abs(x - xt).sum() / np.abs(xt).sum()
    agree = np.abs(x - xs).sum() / np.abs(xs).sum()
    check(err <= bound and agree <= 2 * bound,
          f"{tag}: through the language, forward error {err:.3g} and SciPy agreement {agree:.3g} <= {bound:.3g}")
    print(f"{tag}: through silc, err={err:.2e}")
    return x, out.stdout


if silc_cli:
    young_file = os.path.join(matrices, "young1c.mtx")
    mhd_file = os.path.join(matrices, "mhd1280b.mtx")
    runs = []
    if have("suitesparse"):
        runs += [("suitesparse.umfpack", young_file, young), ("suitesparse.klu", young_file, young),
                 ("suitesparse.cholmod", mhd_file, mhd)]
    if have("mumps"):
        runs += [("mumps", young_file, young)]
    for backend, f, A in runs:
        x, text = silc_solve(f"silc.{backend}", f, A, backend)
        check(f"backend: {backend}" in text, f"silc: info names {backend}:\n{text[:600]}")
    if have("lapack"):
        x, text = silc_solve("silc.lapack", young_file, young, "lapack",
                             'A = dense(A); x = solve(A, b, "backend = lapack"); info x')
        check("backend: lapack" in text and "zgetrf" in text, f"silc: info names lapack and zgetrf:\n{text[:600]}")
    if have("suitesparse") or have("mumps"):
        x, text = silc_solve("silc.default", young_file, young, None, "x = A \\ b; info x")
        check("backend: reference" not in text, f"silc: the default dispatch of a complex sparse solve "
              f"goes to a library backend:\n{text[:600]}")

print(f"{passed} passed, {failed} failed")
sys.exit(1 if failed or not passed else 0)
