#!/usr/bin/python3
"""gen_truth.py -- writes the independent truth that tests/test_truth.c checks SILC against.

A few small fixed matrices and vectors (seeded, dense and sparse) go to
tests/data/inputs/NAME.mtx, where the file stem is the variable name the test
PUTs them under.  Every case is one SILC statement list that leaves its answer
in `r`; numpy/scipy compute the same answer and it goes to
tests/data/expect/CASE.mtx (always a dense Matrix Market array, %.17g).
tests/data/truth.tsv lists the cases:

    name <TAB> statements <TAB> expect file <TAB> cond

cond is "-" for operations that are exact up to rounding (the test uses a
relative tolerance of 1e-14 of the largest expected magnitude) and otherwise
the number that scales the tolerance to 1e-12 * max(1, cond): numpy's 2-norm
condition number for solves and least squares.

Rerunnable: the output depends only on the seed and the numpy/scipy versions,
which are recorded in the header of truth.tsv.  Run from anywhere with
/usr/bin/python3 tests/gen_truth.py.
"""
import os
import sys

import numpy as np
import scipy
import scipy.sparse as sp

HERE = os.path.dirname(os.path.abspath(__file__))
DATA = os.path.join(HERE, "data")
INPUTS = os.path.join(DATA, "inputs")
EXPECT = os.path.join(DATA, "expect")

rng = np.random.default_rng(20240611)


def write_dense(path, a):
    a = np.atleast_2d(np.asarray(a, dtype=float))
    m, n = a.shape
    with open(path, "w") as f:
        f.write("%%MatrixMarket matrix array real general\n")
        f.write("%d %d\n" % (m, n))
        for j in range(n):
            for i in range(m):
                f.write("%.17g\n" % a[i, j])


def write_sparse(path, a):
    a = sp.coo_matrix(a)
    order = np.lexsort((a.row, a.col))
    with open(path, "w") as f:
        f.write("%%MatrixMarket matrix coordinate real general\n")
        f.write("%d %d %d\n" % (a.shape[0], a.shape[1], a.nnz))
        for k in order:
            f.write("%d %d %.17g\n" % (a.row[k] + 1, a.col[k] + 1, a.data[k]))


def col(v):
    return np.asarray(v, dtype=float).reshape(-1, 1)


# ---- inputs ------------------------------------------------------------------
inputs = {}  # name -> (array or sparse matrix, is_sparse)

A = rng.uniform(-1, 1, (4, 4)) + 4 * np.eye(4)      # dense, well conditioned, unsymmetric
B = rng.uniform(-1, 1, (4, 4))
C = rng.uniform(-1, 1, (4, 3))                      # rectangular
Pos = rng.uniform(0.1, 2.0, (4, 4))                 # positive: sqrt, log, fractional powers
U = np.triu(rng.uniform(0.5, 1.5, (4, 4)) * np.where(rng.random((4, 4)) < 0.5, -1, 1))
U += 3 * np.eye(4)                                  # dense upper triangular
Q = rng.uniform(-1, 1, (8, 3))                      # tall, full column rank
x = col(rng.uniform(-1, 1, 4))
y = col(rng.uniform(-1, 1, 4))
b6 = col(rng.uniform(-1, 1, 6))
b8 = col(rng.uniform(-1, 1, 8))

# 6x6 sparse SPD: a weighted path-graph Laplacian plus a positive diagonal.
w = rng.uniform(0.5, 2.0, 5)
Lap = np.zeros((6, 6))
for k in range(5):
    Lap[k, k] += w[k]; Lap[k + 1, k + 1] += w[k]
    Lap[k, k + 1] -= w[k]; Lap[k + 1, k] -= w[k]
Lap[0, 5] = Lap[5, 0] = -0.3
Lap[0, 0] += 0.3; Lap[5, 5] += 0.3
Spd = sp.csr_matrix(Lap + np.diag(rng.uniform(0.5, 1.0, 6)))

# 6x6 sparse unsymmetric with a nonzero pattern that needs pivoting (zero (1,1)).
Su = sp.random(6, 6, density=0.3, random_state=7, data_rvs=lambda k: rng.uniform(-2, 2, k)).toarray()
Su += np.diag([0.0, 3.0, -2.5, 4.0, 1.5, -3.0])
Su[0, 3] = 2.0; Su[3, 0] = -1.0
Su = sp.csr_matrix(Su)

Ls = sp.csr_matrix(np.tril(sp.random(6, 6, density=0.4, random_state=11,
                                     data_rvs=lambda k: rng.uniform(-1, 1, k)).toarray(), -1)
                   + np.diag(rng.uniform(1.0, 2.0, 6)))          # sparse lower triangular
D = sp.diags(rng.uniform(0.5, 3.0, 6) * np.array([1, -1, 1, 1, -1, 1])).tocsr()
Tr = sp.diags([rng.uniform(-1, 1, 5), rng.uniform(3, 4, 6), rng.uniform(-1, 1, 5)],
              [-1, 0, 1]).tocsr()                                # tridiagonal, unsymmetric

# Triplets with duplicates (1-based), for sparse(i, j, v, m, n).
ti = col([1, 2, 2, 4, 1, 3, 2])
tj = col([1, 3, 3, 5, 1, 2, 1])
tv = col([1.5, -2.0, 0.25, 3.0, 2.5, -1.0, 4.0])

for name, val in [("A", A), ("B", B), ("C", C), ("Pos", Pos), ("U", U), ("Q", Q),
                  ("x", x), ("y", y), ("b6", b6), ("b8", b8), ("ti", ti), ("tj", tj), ("tv", tv)]:
    inputs[name] = (val, False)
for name, val in [("Spd", Spd), ("Su", Su), ("Ls", Ls), ("D", D), ("Tr", Tr)]:
    inputs[name] = (val, True)

dense = {k: (v.toarray() if s else v) for k, (v, s) in inputs.items()}
Spd_d, Su_d, Ls_d, D_d, Tr_d = (dense[k] for k in ("Spd", "Su", "Ls", "D", "Tr"))
cond = np.linalg.cond

# ---- cases: (name, statements, expected, cond or None) --------------------------
cases = []


def case(name, stmt, value, c=None):
    cases.append((name, stmt, np.atleast_2d(np.asarray(value, dtype=float)), c))


# scalars and matrices with + - *
case("add", "r = A + B", A + B)
case("sub", "r = A - B", A - B)
case("mul", "r = A * B", A @ B)
case("scal_mul", "r = 2.5 * A", 2.5 * A)
case("mul_scal", "r = A * -0.5", A * -0.5)
case("scal_add", "r = A + 1.25", A + 1.25)
case("scal_sub", "r = 3 - B", 3 - B)
case("scal_div", "r = A / 4", A / 4)
case("neg", "r = -A + B * 2", -A + B * 2)
case("matvec", "r = A * x + y", A @ x + y)
case("rect_mul", "r = C' * A * C", C.T @ A @ C)
case("inner", "r = x' * y", x.T @ y)
case("outer", "r = x * y'", x @ y.T)
case("transpose", "r = (A + B)' * x", (A + B).T @ x)
case("trans_fn", "r = trans(C)", C.T)
case("sparse_matvec", "r = Spd * b6", Spd_d @ b6)
case("sparse_add", "r = Spd + Su'", Spd_d + Su_d.T)
case("sparse_mul", "r = Spd * Su", Spd_d @ Su_d)
case("sparse_dense_mul", "r = Su * Tr - 2 * D", Su_d @ Tr_d - 2 * D_d)
case("two_statements", "t = A * x; r = t - 2 * y", A @ x - 2 * y)
# element-wise
case("ew_mul", "r = A *@ B", A * B)
case("ew_div", "r = A /@ Pos", A / Pos)
case("ew_pow", "r = Pos ^@ 1.5", Pos ** 1.5)
case("ew_pow_mat", "r = Pos ^@ B", Pos ** B)
case("ew_mul_alias", "r = x .* y", x * y)
case("ew_div_alias", "r = x ./ (y + 3)", x / (y + 3))
case("ew_sparse_mul", "r = Spd *@ Tr", Spd_d * Tr_d)
# powers
case("scalar_pow", "r = 2 ^ 10", 1024.0)
case("mat_pow", "r = A ^ 3", np.linalg.matrix_power(A, 3))
case("mat_pow_sparse", "r = Tr ^ 2", Tr_d @ Tr_d)
# maps
case("abs", "r = abs(B)", np.abs(B))
case("sqrt", "r = sqrt(Pos)", np.sqrt(Pos))
case("exp", "r = exp(B)", np.exp(B))
case("log", "r = log(Pos)", np.log(Pos))
case("sin", "r = sin(A)", np.sin(A))
case("cos", "r = cos(A)", np.cos(A))
# reductions
case("sum_vec", "r = sum(x)", x.sum())
case("sum_mat", "r = sum(A)", A.sum(axis=0, keepdims=True))
case("sum_sparse", "r = sum(Su)", Su_d.sum(axis=0, keepdims=True))
case("max_vec", "r = max(x)", x.max())
case("min_vec", "r = min(y)", y.min())
case("max_mat", "r = max(B)", B.max(axis=0, keepdims=True))
case("max2", "r = max(A, B)", np.maximum(A, B))
case("min2", "r = min(A, B)", np.minimum(A, B))
case("max_scalar", "r = max(x, 0)", np.maximum(x, 0))
case("dot", "r = dot(x, y)", float(x.T @ y))
case("norm_vec", "r = norm(x)", np.linalg.norm(x))
case("norm_vec_1", "r = norm(x, 1)", np.linalg.norm(x, 1))
case("norm_vec_inf", "r = norm(x, inf)", np.linalg.norm(x, np.inf))
case("norm_fro", "r = norm(A, \"fro\")", np.linalg.norm(A, "fro"))
case("norm_1", "r = norm(A, 1)", np.linalg.norm(A, 1))
case("norm_inf", "r = norm(A, inf)", np.linalg.norm(A, np.inf))
case("norm_sparse_1", "r = norm(Su, 1)", np.linalg.norm(Su_d, 1))
# The 2-norm of a matrix may come from an iterative singular-value method: allow
# 1e-12 * 100 (the largest singular value is well-conditioned, this is slack).
case("norm_2", "r = norm(A)", np.linalg.norm(A, 2), 100.0)
case("norm_2_rect", "r = norm(C)", np.linalg.norm(C, 2), 100.0)
# structure
case("diag", "r = diag(x)", np.diag(x.ravel()))
case("diagvec", "r = diagvec(A)", col(np.diag(A)))
case("diagvec_sparse", "r = diagvec(Su)", col(np.diag(Su_d)))
case("size", "r = size(C)", [[4, 3]])
case("rows", "r = rows(Q)", 8)
case("cols", "r = cols(Q)", 3)
case("nnz", "r = nnz(Spd)", Spd.nnz)
case("sparse_triplets", "r = sparse(ti, tj, tv, 4, 5)",
     sp.coo_matrix((tv.ravel(), (ti.ravel().astype(int) - 1, tj.ravel().astype(int) - 1)),
                   shape=(4, 5)).toarray())
case("sub_range", "r = A[2:3, 1]", A[1:3, 0:1])
case("sub_col", "r = A[:, 2]", A[:, 1:2])
case("sub_end", "r = x[end]", x[-1, 0])
case("sub_block", "r = Q[end-2:end, 2:3]", Q[5:8, 1:3])
case("eye_mul", "r = eye(4) * x", x)
case("ones_zeros", "r = ones(2, 3) + zeros(2, 3)", np.ones((2, 3)))
# solves
case("solve_dense", "r = A \\ x", np.linalg.solve(A, x), cond(A))
case("solve_dense_mat", "r = A \\ B", np.linalg.solve(A, B), cond(A))
case("solve_spd", "r = Spd \\ b6", np.linalg.solve(Spd_d, b6), cond(Spd_d))
case("solve_unsym", "r = Su \\ b6", np.linalg.solve(Su_d, b6), cond(Su_d))
case("solve_lower", "r = Ls \\ b6", np.linalg.solve(Ls_d, b6), cond(Ls_d))
case("solve_upper", "r = U \\ x", np.linalg.solve(U, x), cond(U))
case("solve_diag", "r = D \\ b6", np.linalg.solve(D_d, b6), cond(D_d))
case("solve_tridiag", "r = Tr \\ b6", np.linalg.solve(Tr_d, b6), cond(Tr_d))
case("right_div", "r = B / A", B @ np.linalg.inv(A), cond(A))
case("right_div_row", "r = x' / A", np.linalg.solve(A.T, x).T, cond(A))
case("lstsq_tall", "r = Q \\ b8", np.linalg.lstsq(Q, b8, rcond=None)[0], cond(Q))
case("solve_residual", "r = Su * (Su \\ b6) - b6", np.zeros((6, 1)), cond(Su_d))


def main():
    os.makedirs(INPUTS, exist_ok=True)
    os.makedirs(EXPECT, exist_ok=True)
    for d in (INPUTS, EXPECT):
        for f in os.listdir(d):
            if f.endswith(".mtx"):
                os.remove(os.path.join(d, f))
    for name, (val, is_sparse) in inputs.items():
        path = os.path.join(INPUTS, name + ".mtx")
        (write_sparse if is_sparse else write_dense)(path, val)
    names = set()
    with open(os.path.join(DATA, "truth.tsv"), "w") as f:
        f.write("# SILC truth cases, generated by tests/gen_truth.py -- do not edit by hand.\n")
        f.write("# numpy %s, scipy %s, python %s\n"
                % (np.__version__, scipy.__version__, sys.version.split()[0]))
        f.write("# name\tstatements (answer in r)\texpect file\tcond (- = exact op)\n")
        for name, stmt, val, c in cases:
            assert name not in names, name
            names.add(name)
            fname = name + ".mtx"
            write_dense(os.path.join(EXPECT, fname), val)
            f.write("%s\t%s\t%s\t%s\n" % (name, stmt, fname, "-" if c is None else "%.6g" % c))
    print("%d inputs, %d cases" % (len(inputs), len(cases)))


if __name__ == "__main__":
    main()
