/*
 * test_complex_ref.c -- the reference plugin on complex values (issue 31),
 * against truth the test computes itself.
 *
 * The kernels are called directly through their C functions (white box:
 * the test links the engine statically, as silcd), each on systems built as
 * b = A x_true so the exact solution is known:
 *   - dense LU (random A), dense Cholesky (A = B^H B + n I, Hermitian
 *     positive definite), dense triangular, band LU, sparse LU (a complex
 *     shifted 2-D Laplacian with random unsymmetric couplings), sparse
 *     Cholesky (Hermitian, diagonally dominant) and sparse triangular: the
 *     solution within a small multiple of eps * cond of x_true, and the
 *     conjugate-transposed solve (trans = 1, what the estimator applies)
 *     checked by multiplying back with A^H;
 *   - dense (Householder) and sparse (Givens, semi-normal equations)
 *     complex QR: an overdetermined consistent system recovers x_true, an
 *     inconsistent one satisfies the normal equations A^H (b - A x) = 0, an
 *     underdetermined one A x = b (sparse: with x in range(A^H), the
 *     minimum-norm solution);
 *   - the complex condition estimate (ref_inv_norm1_est_complex, zlacn2's
 *     method) within a factor 3 below the true ||A^{-1}||_1, computed from
 *     the explicit inverse (Gauss-Jordan here for dense A; for the two
 *     shared complex matrices, mhd1280b (Hermitian) and young1c, column by
 *     column through the sparse factor), and never above it;
 *   - singular complex matrices (dense, sparse, band) reported as singular,
 *     and a Hermitian matrix that is not positive definite as SILC_ENOTSPD;
 *   - through the language (complex values PUT through the C API): dense
 *     and sparse x = A \ b, every MATMUL format pair, ' (conjugate), ADD,
 *     SCALE, element-wise products, quotients and comparisons (real
 *     results), sqrt/log/exp (principal branches), abs, sum, max (by
 *     modulus), norm 1 and the 2-norm (closed form for a 2x2), sparse(),
 *     diagvec and diag, each against the same arithmetic written out here;
 *   - examples/helmholtz: its matrix complex symmetric and not Hermitian,
 *     and the plane wave's error (exact solution exp(i k x)) falling as h^2.
 */
#include "check.h"

#include <complex.h>
#include <float.h>
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "dispatch.h"
#include "engine.h"
#include "helmholtz.h"
#include "ref.h"
#include "silc.h"
#include "silc_plugin.h"

typedef double complex cplx;

static uint64_t rng_state = 0x2545F4914F6CDD1Du;

static double urand(void) /* uniform in [-1, 1) */
{
    rng_state ^= rng_state << 13, rng_state ^= rng_state >> 7, rng_state ^= rng_state << 17;
    return (double)(rng_state >> 11) / 4503599627370496.0 - 1.0;
}

static cplx crand(void)
{
    return urand() + I * urand();
}

static double vec_err(int64_t n, const cplx *x, const cplx *y) /* ||x - y||_inf / ||y||_inf */
{
    double e = 0.0, s = 0.0;
    for (int64_t i = 0; i < n; i++) {
        e = fmax(e, cabs(x[i] - y[i]));
        s = fmax(s, cabs(y[i]));
    }
    return s > 0 ? e / s : e;
}

/* y = op(A) x for dense column-major A (m x n); adjoint uses A^H. */
static void dense_apply(int64_t m, int64_t n, const cplx *A, int adjoint, const cplx *x, cplx *y)
{
    if (!adjoint) {
        for (int64_t i = 0; i < m; i++) y[i] = 0;
        for (int64_t j = 0; j < n; j++)
            for (int64_t i = 0; i < m; i++) y[i] += A[i + j * m] * x[j];
    } else {
        for (int64_t j = 0; j < n; j++) {
            cplx s = 0;
            for (int64_t i = 0; i < m; i++) s += conj(A[i + j * m]) * x[i];
            y[j] = s;
        }
    }
}

static double dense_norm1(int64_t n, const cplx *A)
{
    double best = 0.0;
    for (int64_t j = 0; j < n; j++) {
        double s = 0.0;
        for (int64_t i = 0; i < n; i++) s += cabs(A[i + j * n]);
        best = fmax(best, s);
    }
    return best;
}

/* ||A^{-1}||_1 from the explicit inverse by Gauss-Jordan with partial
 * pivoting (independent of the plugin's LU); -1 if singular. */
static double dense_inv_norm1(int64_t n, const cplx *A)
{
    cplx *M = malloc((size_t)(n * n) * sizeof *M), *X = calloc((size_t)(n * n), sizeof *X);
    double r = -1.0;
    if (!M || !X) goto out;
    memcpy(M, A, (size_t)(n * n) * sizeof *M);
    for (int64_t i = 0; i < n; i++) X[i + i * n] = 1;
    for (int64_t k = 0; k < n; k++) {
        int64_t p = k;
        for (int64_t i = k + 1; i < n; i++)
            if (cabs(M[i + k * n]) > cabs(M[p + k * n])) p = i;
        if (M[p + k * n] == 0) goto out;
        for (int64_t j = 0; j < n; j++) {
            cplx t = M[k + j * n];
            M[k + j * n] = M[p + j * n], M[p + j * n] = t;
            t = X[k + j * n];
            X[k + j * n] = X[p + j * n], X[p + j * n] = t;
        }
        cplx d = M[k + k * n];
        for (int64_t j = 0; j < n; j++) M[k + j * n] /= d, X[k + j * n] /= d;
        for (int64_t i = 0; i < n; i++) {
            if (i == k) continue;
            cplx f = M[i + k * n];
            if (f == 0) continue;
            for (int64_t j = 0; j < n; j++) M[i + j * n] -= f * M[k + j * n], X[i + j * n] -= f * X[k + j * n];
        }
    }
    r = dense_norm1(n, X);
out:
    free(M);
    free(X);
    return r;
}

/* Solves with F for b and checks x_true; then trans = 1 on c and checks
 * A^H y = c by multiplying back (apply_adj(ctx, y, out) computes A^H y). */
static void check_factor(const char *what, ref_factor *F, int64_t n, const cplx *b, const cplx *xt, double tol,
                         void (*apply_adj)(const void *ctx, const cplx *y, cplx *out), const void *ctx)
{
    cplx *x = malloc((size_t)n * sizeof *x), *y = malloc((size_t)n * sizeof *y), *c = malloc((size_t)n * sizeof *c);
    double *work = malloc((size_t)(F->work_len + 2 * n + 2) * sizeof(double));
    memcpy(x, b, (size_t)n * sizeof *x);
    CHECK(F->w == 2, "%s: a complex factor", what);
    CHECK(F->solve(F->data, (double *)x, 0, work) == 0, "%s: solve", what);
    double e = vec_err(n, x, xt);
    CHECK(e < tol, "%s: error %.3g against x_true (tol %.3g)", what, e, tol);
    if (apply_adj) {
        for (int64_t i = 0; i < n; i++) c[i] = crand();
        memcpy(y, c, (size_t)n * sizeof *y);
        CHECK(F->solve(F->data, (double *)y, 1, work) == 0, "%s: adjoint solve", what);
        apply_adj(ctx, y, x);
        e = vec_err(n, x, c);
        CHECK(e < tol, "%s: A^H (A^-H c) = c, error %.3g (tol %.3g)", what, e, tol);
    }
    free(x);
    free(y);
    free(c);
    free(work);
}

typedef struct dense_ctx {
    int64_t n;
    const cplx *A;
} dense_ctx;

static void dense_adj(const void *p, const cplx *y, cplx *out)
{
    const dense_ctx *d = p;
    dense_apply(d->n, d->n, d->A, 1, y, out);
}

/* ---- dense ------------------------------------------------------------------------ */

static void test_dense(void)
{
    enum { N = 40 };
    cplx *A = malloc(N * N * sizeof *A), *xt = malloc(N * sizeof *xt), *b = malloc(N * sizeof *b);
    char msg[256];
    for (int64_t k = 0; k < N * N; k++) A[k] = crand();
    for (int64_t i = 0; i < N; i++) xt[i] = crand();
    dense_apply(N, N, A, 0, xt, b);
    dense_ctx ctx = {N, A};

    ref_factor F = {0};
    CHECK(ref_dense_lu_z(N, (const double *)A, &F, msg, sizeof msg) == 0, "dense LU: %s", msg);
    check_factor("dense LU", &F, N, b, xt, 1e-9, dense_adj, &ctx);
    /* the estimate: a lower bound within a factor 3 of the explicit inverse's norm */
    double truth = dense_inv_norm1(N, A);
    double *work = malloc((size_t)(F.work_len + 4 * N) * sizeof(double));
    double est = ref_inv_norm1_est_complex(N, F.solve, F.data, work);
    CHECK(est <= truth * (1 + 1e-8) && est >= truth / 3, "dense LU estimate %.6g vs ||A^-1||_1 %.6g", est, truth);
    free(work);
    F.destroy(F.data);

    /* Hermitian positive definite: A = B^H B + n I, only its lower triangle read */
    cplx *H = calloc(N * N, sizeof *H);
    for (int64_t j = 0; j < N; j++)
        for (int64_t i = 0; i < N; i++) {
            cplx s = i == j ? N : 0;
            for (int64_t k = 0; k < N; k++) s += conj(A[k + i * N]) * A[k + j * N];
            H[i + j * N] = s;
        }
    cplx *Hl = malloc(N * N * sizeof *Hl);
    for (int64_t j = 0; j < N; j++)
        for (int64_t i = 0; i < N; i++) Hl[i + j * N] = i >= j ? H[i + j * N] : 99.0 + 7.0 * I; /* garbage above */
    dense_apply(N, N, H, 0, xt, b);
    ref_factor C = {0};
    CHECK(ref_dense_chol_z(N, (const double *)Hl, &C, msg, sizeof msg) == 0, "dense Cholesky: %s", msg);
    dense_ctx hctx = {N, H};
    check_factor("dense Cholesky", &C, N, b, xt, 1e-10, dense_adj, &hctx);
    C.destroy(C.data);
    /* Hermitian but indefinite: diag(1, -1) coupled */
    cplx ind[4] = {1, 2 - I, 2 + I, 1};
    CHECK(ref_dense_chol_z(2, (const double *)ind, &C, msg, sizeof msg) == SILC_ENOTSPD,
          "indefinite Hermitian matrix: Cholesky says not positive definite");

    /* triangular: the lower triangle of A with a strong diagonal */
    cplx *T = calloc(N * N, sizeof *T);
    for (int64_t j = 0; j < N; j++)
        for (int64_t i = j; i < N; i++) T[i + j * N] = A[i + j * N] + (i == j ? 4.0 : 0.0);
    dense_apply(N, N, T, 0, xt, b);
    ref_factor Tf = {0};
    CHECK(ref_dense_tri_z(N, (const double *)T, 1, &Tf, msg, sizeof msg) == 0, "dense triangular: %s", msg);
    dense_ctx tctx = {N, T};
    check_factor("dense lower triangular", &Tf, N, b, xt, 1e-10, dense_adj, &tctx);
    Tf.destroy(Tf.data);

    /* singular: a column that is a complex multiple of another */
    for (int64_t i = 0; i < N; i++) A[i + 5 * N] = (2 - 3 * I) * A[i + 7 * N];
    ref_factor S = {0};
    int st = ref_dense_lu_z(N, (const double *)A, &S, msg, sizeof msg);
    if (st == 0) { /* rounding may leave a tiny pivot: then the estimate must say singular */
        work = malloc((size_t)(S.work_len + 4 * N) * sizeof(double));
        est = ref_inv_norm1_est_complex(N, S.solve, S.data, work);
        free(work);
        S.destroy(S.data);
        CHECK(est * dense_norm1(N, A) > 1e13, "singular dense: cond estimate %.3g", est * dense_norm1(N, A));
    }
    cplx Z[9] = {1 + I, 2, 3 * I, 2 + 2 * I, 4, 6 * I, 0, 1, 1}; /* column 2 = 2 * column 1: exactly singular */
    CHECK(ref_dense_lu_z(3, (const double *)Z, &S, msg, sizeof msg) == SILC_ESINGULAR,
          "exactly singular complex dense: SILC_ESINGULAR (%s)", msg);
    free(A);
    free(H);
    free(Hl);
    free(T);
    free(xt);
    free(b);
}

static void test_dense_qr(void)
{
    enum { M = 50, N = 20 };
    cplx *A = malloc(M * N * sizeof *A), *xt = malloc(M * sizeof *xt), *b = malloc(M * sizeof *b);
    cplx *x = malloc(M * sizeof *x), *r = malloc(M * sizeof *r), *g = malloc(M * sizeof *g);
    double *work = malloc(4 * M * sizeof(double));
    char msg[256];
    for (int64_t k = 0; k < M * N; k++) A[k] = crand();
    for (int64_t i = 0; i < N; i++) xt[i] = crand();
    dense_apply(M, N, A, 0, xt, b);
    ref_factor F = {0};
    CHECK(ref_dense_qr_z(M, N, (const double *)A, &F, msg, sizeof msg) == 0, "dense QR");
    memcpy(x, b, M * sizeof *x);
    F.solve(F.data, (double *)x, 0, work);
    CHECK(vec_err(N, x, xt) < 1e-10, "QR, consistent overdetermined: error %.3g", vec_err(N, x, xt));
    /* inconsistent: the normal equations hold */
    for (int64_t i = 0; i < M; i++) b[i] += 0.5 * crand();
    memcpy(x, b, M * sizeof *x);
    F.solve(F.data, (double *)x, 0, work);
    dense_apply(M, N, A, 0, x, r);
    for (int64_t i = 0; i < M; i++) r[i] = b[i] - r[i];
    dense_apply(M, N, A, 1, r, g);
    double gn = 0.0, rn = 0.0;
    for (int64_t i = 0; i < N; i++) gn = fmax(gn, cabs(g[i]));
    for (int64_t i = 0; i < M; i++) rn = fmax(rn, cabs(r[i]));
    CHECK(gn < 1e-10 * rn * M, "QR least squares: ||A^H r|| = %.3g with ||r|| = %.3g", gn, rn);
    CHECK(F.cond > 1 && isfinite(F.cond), "QR condition estimate %.3g", F.cond);
    F.destroy(F.data);
    /* underdetermined (the transpose shape): A x = b */
    cplx *At = malloc(M * N * sizeof *At);
    for (int64_t i = 0; i < N; i++)
        for (int64_t j = 0; j < M; j++) At[i + j * N] = A[j + i * M];
    for (int64_t i = 0; i < N; i++) b[i] = crand();
    CHECK(ref_dense_qr_z(N, M, (const double *)At, &F, msg, sizeof msg) == 0, "dense QR, minimum norm");
    memcpy(x, b, N * sizeof *x);
    F.solve(F.data, (double *)x, 0, work);
    dense_apply(N, M, At, 0, x, r);
    CHECK(vec_err(N, r, b) < 1e-10, "QR minimum norm: A x = b to %.3g", vec_err(N, r, b));
    F.destroy(F.data);
    free(At);
    free(A);
    free(xt);
    free(b);
    free(x);
    free(r);
    free(g);
    free(work);
}

/* ---- band ------------------------------------------------------------------------- */

static void test_band(void)
{
    enum { N = 60, KL = 2, KU = 3, LD = KL + KU + 1 };
    cplx *val = calloc(LD * N, sizeof *val), *D = calloc(N * N, sizeof *D);
    cplx xt[N], b[N];
    char msg[256];
    for (int64_t j = 0; j < N; j++)
        for (int64_t i = j - KU < 0 ? 0 : j - KU; i <= j + KL && i < N; i++) {
            cplx a = crand() + (i == j ? 0.5 : 0.0);
            val[(KU + i - j) + j * LD] = a;
            D[i + j * N] = a;
        }
    for (int64_t i = 0; i < N; i++) xt[i] = crand();
    dense_apply(N, N, D, 0, xt, b);
    silc_view v = {N, N, SILC_FMT_BAND, (double *)val, NULL, NULL, LD * N, KL, KU, LD};
    ref_factor F = {0};
    CHECK(ref_band_lu_z(&v, KL, KU, &F, msg, sizeof msg) == 0, "band LU: %s", msg);
    dense_ctx ctx = {N, D};
    check_factor("band LU", &F, N, b, xt, 1e-8, dense_adj, &ctx);
    double truth = dense_inv_norm1(N, D);
    double *work = malloc((size_t)(F.work_len + 4 * N) * sizeof(double));
    double est = ref_inv_norm1_est_complex(N, F.solve, F.data, work);
    CHECK(est <= truth * (1 + 1e-8) && est >= truth / 3, "band estimate %.6g vs %.6g", est, truth);
    free(work);
    F.destroy(F.data);
    for (int64_t i = 0; i < N; i++) val[(KU + i - 10) + 10 * LD] = 0; /* in-band zero column */
    CHECK(ref_band_lu_z(&v, KL, KU, &F, msg, sizeof msg) == SILC_ESINGULAR, "singular band: %s", msg);
    free(val);
    free(D);
}

/* ---- sparse ----------------------------------------------------------------------- */

/* Compressed-column complex matrix from dense m x n (test sizes only). */
static void sp_from_dense_mn(int64_t m, int64_t n, const cplx *D, ref_sp *A)
{
    int64_t nz = 0;
    for (int64_t k = 0; k < m * n; k++) nz += D[k] != 0;
    ref_sp_alloc(A, m, n, nz, 2);
    cplx *x = (cplx *)A->x;
    nz = 0;
    for (int64_t j = 0; j < n; j++) {
        A->p[j] = nz;
        for (int64_t i = 0; i < m; i++)
            if (D[i + j * m] != 0) A->i[nz] = i, x[nz++] = D[i + j * m];
    }
    A->p[n] = nz;
}

static void sp_from_dense(int64_t n, const cplx *D, ref_sp *A)
{
    sp_from_dense_mn(n, n, D, A);
}

/* Sparse complex least squares (complex Givens, semi-normal equations):
 * consistent overdetermined recovers x_true, inconsistent satisfies
 * A^H (b - A x) = 0, underdetermined gives A x = b with x in range(A^H). */
static void test_sparse_qr(void)
{
    enum { M = 60, N = 25 };
    cplx *A = calloc(M * N, sizeof *A), xt[M], b[M], x[M], r[M], g[M];
    double *work = NULL;
    char msg[256];
    for (int64_t k = 0; k < M * N; k++)
        if (k % 4 == 0 || k % (M + 1) == 0) A[k] = crand();
    for (int64_t i = 0; i < N; i++) xt[i] = crand();
    dense_apply(M, N, A, 0, xt, b);
    ref_sp S = {0};
    sp_from_dense_mn(M, N, A, &S);
    ref_factor F = {0};
    CHECK(ref_sparse_qr_z(&S, &F, msg, sizeof msg) == 0, "sparse QR: %s", msg);
    work = malloc((size_t)(F.work_len + 4) * sizeof(double));
    memcpy(x, b, sizeof b);
    F.solve(F.data, (double *)x, 0, work);
    CHECK(vec_err(N, x, xt) < 1e-10, "sparse QR, consistent: error %.3g", vec_err(N, x, xt));
    for (int64_t i = 0; i < M; i++) b[i] += 0.5 * crand();
    memcpy(x, b, sizeof b);
    F.solve(F.data, (double *)x, 0, work);
    dense_apply(M, N, A, 0, x, r);
    for (int64_t i = 0; i < M; i++) r[i] = b[i] - r[i];
    dense_apply(M, N, A, 1, r, g);
    double gn = 0, rn = 0;
    for (int64_t i = 0; i < N; i++) gn = fmax(gn, cabs(g[i]));
    for (int64_t i = 0; i < M; i++) rn = fmax(rn, cabs(r[i]));
    CHECK(gn < 1e-10 * rn * M, "sparse QR least squares: ||A^H r|| = %.3g, ||r|| = %.3g", gn, rn);
    CHECK(F.cond > 1 && isfinite(F.cond), "sparse QR condition estimate %.3g", F.cond);
    F.destroy(F.data);
    free(work);
    ref_sp_free(&S);
    /* underdetermined: the conjugate transpose's shape */
    cplx *Ah = malloc(M * N * sizeof *Ah);
    for (int64_t i = 0; i < M; i++)
        for (int64_t j = 0; j < N; j++) Ah[j + i * N] = conj(A[i + j * M]);
    sp_from_dense_mn(N, M, Ah, &S);
    CHECK(ref_sparse_qr_z(&S, &F, msg, sizeof msg) == 0, "sparse QR, minimum norm: %s", msg);
    work = malloc((size_t)(F.work_len + 4) * sizeof(double));
    for (int64_t i = 0; i < N; i++) b[i] = crand();
    memcpy(x, b, N * sizeof *x);
    F.solve(F.data, (double *)x, 0, work);
    dense_apply(N, M, Ah, 0, x, r);
    CHECK(vec_err(N, r, b) < 1e-10, "sparse QR minimum norm: A x = b to %.3g", vec_err(N, r, b));
    /* the minimum-norm x lies in range(A^H) = range(A here): its part
     * orthogonal to it, x - A (A \ x), vanishes (A's dense QR, above) */
    ref_factor D = {0};
    double dw[4 * M];
    ref_dense_qr_z(M, N, (const double *)A, &D, msg, sizeof msg);
    memcpy(g, x, sizeof g);
    D.solve(D.data, (double *)g, 0, dw);
    dense_apply(M, N, A, 0, g, r);
    CHECK(vec_err(M, r, x) < 1e-10, "minimum norm: x in range(A^H) to %.3g", vec_err(M, r, x));
    D.destroy(D.data);
    F.destroy(F.data);
    free(work);
    ref_sp_free(&S);
    free(Ah);
    free(A);
}

static void test_sparse(void)
{
    enum { G = 12, N = G * G };
    cplx *D = calloc(N * N, sizeof *D), xt[N], b[N];
    char msg[256];
    /* a complex-shifted 5-point Laplacian with random unsymmetric couplings */
    for (int64_t y = 0; y < G; y++)
        for (int64_t x = 0; x < G; x++) {
            int64_t k = x + y * G;
            D[k + k * N] = 4.0 - 0.3 + 0.2 * I;
            if (x > 0) D[k + (k - 1) * N] = -1.0 + 0.1 * crand();
            if (x < G - 1) D[k + (k + 1) * N] = -1.0;
            if (y > 0) D[k + (k - G) * N] = -1.0 + 0.1 * crand();
            if (y < G - 1) D[k + (k + G) * N] = -1.0 * I;
        }
    for (int64_t i = 0; i < N; i++) xt[i] = crand();
    dense_apply(N, N, D, 0, xt, b);
    ref_sp A = {0};
    sp_from_dense(N, D, &A);
    ref_factor F = {0};
    CHECK(ref_sparse_lu_z(&A, &F, msg, sizeof msg) == 0, "sparse LU: %s", msg);
    dense_ctx ctx = {N, D};
    check_factor("sparse LU", &F, N, b, xt, 1e-9, dense_adj, &ctx);
    double truth = dense_inv_norm1(N, D);
    double *work = malloc((size_t)(F.work_len + 4 * N) * sizeof(double));
    double est = ref_inv_norm1_est_complex(N, F.solve, F.data, work);
    CHECK(est <= truth * (1 + 1e-8) && est >= truth / 3, "sparse LU estimate %.6g vs %.6g", est, truth);
    free(work);
    F.destroy(F.data);
    ref_sp_free(&A);

    /* Hermitian positive definite (diagonally dominant, complex couplings) */
    memset(D, 0, N * N * sizeof *D);
    for (int64_t k = 0; k < N; k++) {
        D[k + k * N] = 5.0;
        int64_t nb[2] = {k + 1, k + G};
        for (int q = 0; q < 2; q++)
            if (nb[q] < N) {
                cplx c = crand();
                D[nb[q] + k * N] = c;
                D[k + nb[q] * N] = conj(c);
            }
    }
    dense_apply(N, N, D, 0, xt, b);
    sp_from_dense(N, D, &A);
    CHECK(ref_sparse_chol_z(&A, &F, msg, sizeof msg) == 0, "sparse Cholesky: %s", msg);
    check_factor("sparse Cholesky", &F, N, b, xt, 1e-10, dense_adj, &ctx);
    F.destroy(F.data);
    ref_sp_free(&A);
    D[7 + 7 * N] = -5.0;
    sp_from_dense(N, D, &A);
    CHECK(ref_sparse_chol_z(&A, &F, msg, sizeof msg) == SILC_ENOTSPD, "indefinite Hermitian sparse: ENOTSPD");
    ref_sp_free(&A);

    /* upper triangular */
    for (int64_t j = 0; j < N; j++)
        for (int64_t i = 0; i < N; i++)
            if (i > j) D[i + j * N] = 0;
    D[7 + 7 * N] = 3.0 - 1.0 * I;
    dense_apply(N, N, D, 0, xt, b);
    sp_from_dense(N, D, &A);
    CHECK(ref_sparse_tri_z(&A, 0, &F, msg, sizeof msg) == 0, "sparse triangular: %s", msg);
    check_factor("sparse upper triangular", &F, N, b, xt, 1e-10, dense_adj, &ctx);
    F.destroy(F.data);
    ref_sp_free(&A);

    /* singular: two equal rows */
    cplx S[16] = {1 + I, 0, 1 + I, 0, 2, 1, 2, 0, 0, 3 * I, 0, 1, 0, 0, 0, 4};
    sp_from_dense(4, S, &A);
    CHECK(ref_sparse_lu_z(&A, &F, msg, sizeof msg) == SILC_ESINGULAR, "singular complex sparse: %s", msg);
    ref_sp_free(&A);
    free(D);
}

/* ---- the shared complex matrices ----------------------------------------------------- */

/* Matrix Market coordinate complex (general or hermitian), expanded to both
 * triangles, as compressed columns; 0 on success. */
static int read_mtx_complex(const char *path, ref_sp *A)
{
    FILE *f = fopen(path, "r");
    char line[512];
    int herm = 0;
    long long m, n, nz;
    if (!f) return -1;
    if (!fgets(line, sizeof line, f) || !strstr(line, "complex")) {
        fclose(f);
        return -1;
    }
    herm = strstr(line, "hermitian") != NULL;
    do {
        if (!fgets(line, sizeof line, f)) {
            fclose(f);
            return -1;
        }
    } while (line[0] == '%');
    if (sscanf(line, "%lld %lld %lld", &m, &n, &nz) != 3 || m != n) {
        fclose(f);
        return -1;
    }
    int64_t *ti = malloc((size_t)(2 * nz) * sizeof *ti), *tj = malloc((size_t)(2 * nz) * sizeof *tj);
    cplx *tv = malloc((size_t)(2 * nz) * sizeof *tv);
    int64_t cnt = 0;
    for (long long k = 0; k < nz; k++) {
        long long i, j;
        double re, im;
        if (fscanf(f, "%lld %lld %lf %lf", &i, &j, &re, &im) != 4) break;
        ti[cnt] = i - 1, tj[cnt] = j - 1, tv[cnt++] = re + I * im;
        if (herm && i != j) ti[cnt] = j - 1, tj[cnt] = i - 1, tv[cnt++] = re - I * im;
    }
    fclose(f);
    ref_sp_alloc(A, m, n, cnt, 2);
    int64_t *w = calloc((size_t)n + 1, sizeof *w);
    for (int64_t k = 0; k < cnt; k++) w[tj[k]]++;
    int64_t s = 0;
    for (int64_t j = 0; j < n; j++) A->p[j] = s, s += w[j], w[j] = A->p[j];
    A->p[n] = s;
    for (int64_t k = 0; k < cnt; k++) {
        int64_t q = w[tj[k]]++;
        A->i[q] = ti[k];
        ((cplx *)A->x)[q] = tv[k];
    }
    free(w);
    free(ti);
    free(tj);
    free(tv);
    return 0;
}

static void test_shared(const char *name, int hermitian)
{
    char path[1024], msg[256];
    snprintf(path, sizeof path, "%s/%s", SILC_SHARED_MATRICES, name);
    ref_sp A = {0};
    if (read_mtx_complex(path, &A)) {
        CHECK(0, "%s: could not read %s", name, path);
        return;
    }
    int64_t n = A.n;
    ref_factor F = {0};
    int st = hermitian ? ref_sparse_chol_z(&A, &F, msg, sizeof msg) : ref_sparse_lu_z(&A, &F, msg, sizeof msg);
    CHECK(st == 0, "%s: factor: %s", name, msg);
    if (st) {
        ref_sp_free(&A);
        return;
    }
    /* b = A x_true, the solve's forward error within cond * eps (times a margin) */
    cplx *xt = malloc((size_t)n * sizeof *xt), *b = calloc((size_t)n, sizeof *b), *col = malloc((size_t)n * sizeof *col);
    double *work = malloc((size_t)(F.work_len + 4 * n) * sizeof(double));
    const cplx *Ax = (const cplx *)A.x;
    for (int64_t i = 0; i < n; i++) xt[i] = crand();
    for (int64_t j = 0; j < n; j++)
        for (int64_t q = A.p[j]; q < A.p[j + 1]; q++) b[A.i[q]] += Ax[q] * xt[j];
    /* ||A^{-1}||_1 from the explicit inverse, column by column */
    double inv = 0.0, anorm = 0.0;
    for (int64_t j = 0; j < n; j++) {
        double s = 0.0;
        for (int64_t q = A.p[j]; q < A.p[j + 1]; q++) s += cabs(Ax[q]);
        anorm = fmax(anorm, s);
        memset(col, 0, (size_t)n * sizeof *col);
        col[j] = 1;
        F.solve(F.data, (double *)col, 0, work);
        s = 0.0;
        for (int64_t i = 0; i < n; i++) s += cabs(col[i]);
        inv = fmax(inv, s);
    }
    double est = ref_inv_norm1_est_complex(n, F.solve, F.data, work);
    CHECK(est <= inv * (1 + 1e-6) && est >= inv / 3, "%s: ||A^-1||_1 estimate %.6g vs explicit %.6g", name, est,
          inv);
    memcpy(col, b, (size_t)n * sizeof *col);
    F.solve(F.data, (double *)col, 0, work);
    double cond = anorm * inv, e = vec_err(n, col, xt);
    CHECK(e < 100 * DBL_EPSILON * cond + 1e-12, "%s: forward error %.3g with cond_1 %.3g", name, e, cond);
    printf("%s: n = %lld, cond_1 = %.4g, estimate %.4g (ratio %.4f), forward error %.3g\n", name, (long long)n,
           cond, anorm * est, est / inv, e);
    free(xt);
    free(b);
    free(col);
    free(work);
    F.destroy(F.data);
    ref_sp_free(&A);
}

/* The estimator on random dense matrices of three kinds (uniform, one heavy
 * column, graded rows), against the explicit inverse. */
static void test_estimator_random(void)
{
    enum { N = 30, TRIALS = 20 };
    cplx A[N * N];
    char msg[256];
    double worst = 1.0;
    for (int t = 0; t < 3 * TRIALS; t++) {
        for (int64_t k = 0; k < N * N; k++) A[k] = crand();
        if (t % 3 == 1)
            for (int64_t i = 0; i < N; i++) A[i + 3 * N] *= 1e3;
        if (t % 3 == 2)
            for (int64_t j = 0; j < N; j++)
                for (int64_t i = 0; i < N; i++) A[i + j * N] *= pow(10.0, -(double)i / 6);
        ref_factor F = {0};
        if (ref_dense_lu_z(N, (const double *)A, &F, msg, sizeof msg)) continue;
        double work[4 * N], truth = dense_inv_norm1(N, A);
        double est = ref_inv_norm1_est_complex(N, F.solve, F.data, work);
        F.destroy(F.data);
        CHECK(est <= truth * (1 + 1e-8) && est >= truth / 3, "random %d: estimate %.6g vs %.6g", t, est, truth);
        worst = fmin(worst, est / truth);
    }
    printf("random complex 30x30: worst estimate / ||A^-1||_1 = %.4f\n", worst);
    /* n = 1 and a diagonal matrix (exact) */
    double z[2] = {0.0, 2.0};
    ref_factor F = {0};
    ref_dense_lu_z(1, z, &F, msg, sizeof msg);
    double w1[4];
    CHECK_NEAR(ref_inv_norm1_est_complex(1, F.solve, F.data, w1), 0.5, 1e-15);
    F.destroy(F.data);
}

/* ---- through the language --------------------------------------------------------- */

/* Fetches name as a dense complex column-major array of m x n (real results
 * are widened), NULL on failure. */
static cplx *fetch(silc_context *c, const char *name, int64_t *m, int64_t *n, int *is_complex)
{
    silc_envelope_t e;
    if (silc_get_complex(c, &e, name)) {
        CHECK(0, "get %s: %s", name, silc_context_errmsg(c));
        return NULL;
    }
    *m = e.m, *n = e.n;
    *is_complex = silc_envelope_is_complex(&e);
    cplx *z = calloc((size_t)(e.m * e.n) + 1, sizeof *z);
    double *d = calloc((size_t)(e.m * e.n * 2) + 1, sizeof *d);
    silc_envelope_to_dense(&e, d);
    for (int64_t k = 0; k < e.m * e.n; k++) z[k] = *is_complex ? d[2 * k] + I * d[2 * k + 1] : d[k];
    free(d);
    silc_envelope_free(&e);
    return z;
}

/* Runs stmt (which sets r) and compares r with want (m x n) entry by entry
 * to tol relative to the largest entry of want; real_result says whether r
 * must come back real. */
static void expect(silc_context *c, const char *stmt, int64_t m, int64_t n, const cplx *want, int real_result,
                   double tol)
{
    int64_t gm, gn;
    int cx;
    if (silc_exec(c, stmt)) {
        CHECK(0, "%s: %s", stmt, silc_context_errmsg(c));
        return;
    }
    cplx *got = fetch(c, "r", &gm, &gn, &cx);
    if (!got) return;
    CHECK(gm == m && gn == n, "%s: %lldx%lld, want %lldx%lld", stmt, (long long)gm, (long long)gn, (long long)m,
          (long long)n);
    CHECK(cx == !real_result, "%s: the result is %s, want %s", stmt, cx ? "complex" : "real",
          real_result ? "real" : "complex");
    if (gm == m && gn == n) {
        double scale = 0.0, err = 0.0;
        for (int64_t k = 0; k < m * n; k++) scale = fmax(scale, cabs(want[k]));
        for (int64_t k = 0; k < m * n; k++) err = fmax(err, cabs(got[k] - want[k]));
        CHECK(err <= tol * (scale > 0 ? scale : 1), "%s: error %.3g (scale %.3g)", stmt, err, scale);
    }
    free(got);
}

/* Puts the m x n complex matrix D as a dense value, or as CSR of its
 * nonzeros when csr. */
static void put_complex(silc_context *c, const char *name, int64_t m, int64_t n, const cplx *D, int csr)
{
    silc_envelope_t e;
    int rc;
    if (!csr) {
        rc = silc_envelope_dense_complex(&e, m, n, (const double *)D);
    } else {
        int64_t *rp = calloc((size_t)m + 1, sizeof *rp), *ci = malloc((size_t)(m * n) * sizeof *ci), nz = 0;
        double *v = malloc((size_t)(2 * m * n) * sizeof *v);
        for (int64_t i = 0; i < m; i++) {
            for (int64_t j = 0; j < n; j++)
                if (D[i + j * m] != 0) ci[nz] = j, v[2 * nz] = creal(D[i + j * m]), v[2 * nz + 1] = cimag(D[i + j * m]), nz++;
            rp[i + 1] = nz;
        }
        rc = silc_envelope_csr_complex(&e, m, n, rp, ci, v);
        free(rp);
        free(ci);
        free(v);
    }
    CHECK(rc == 0 && silc_put(c, name, &e) == 0, "put %s: %s", name, silc_context_errmsg(c));
    silc_envelope_free(&e);
}

/* Every op on complex operands through statements, each result against the
 * same arithmetic written out here on dense arrays. */
static void test_language(void)
{
    enum { M = 5 };
    silc_context *c = NULL;
    cplx A[M * M], S[M * M], x[M], b[M], W[M * M];
    CHECK(silc_open(&c, NULL) == 0, "open");
    for (int k = 0; k < M * M; k++) A[k] = crand() + (k % (M + 1) == 0 ? 3.0 : 0.0);
    for (int k = 0; k < M * M; k++) S[k] = (k % 3 == 0 || k % (M + 1) == 0) ? crand() + (k % (M + 1) == 0 ? 2.0 : 0.0) : 0;
    for (int i = 0; i < M; i++) x[i] = crand();
    dense_apply(M, M, A, 0, x, b);
    put_complex(c, "A", M, M, A, 0);
    put_complex(c, "S", M, M, S, 1);
    put_complex(c, "b", M, 1, b, 0);
    /* SOLVE, dense and sparse (the core's verification of a complex solve
     * is complex-core's; until it lands there it is switched off here) */
    CHECK(silc_exec(c, "set solve.verify = off") == 0, "set: %s", silc_context_errmsg(c));
    expect(c, "r = A \\ b", M, 1, x, 0, 1e-12);
    dense_apply(M, M, S, 0, x, b);
    put_complex(c, "bs", M, 1, b, 0);
    expect(c, "r = S \\ bs", M, 1, x, 0, 1e-12);
    /* least squares, dense and sparse: a consistent 7x5 system */
    {
        cplx R[7 * M], br[7];
        for (int k = 0; k < 7 * M; k++) R[k] = k % 3 ? crand() : 0;
        dense_apply(7, M, R, 0, x, br);
        put_complex(c, "R", 7, M, R, 0);
        put_complex(c, "Rs", 7, M, R, 1);
        put_complex(c, "br", 7, 1, br, 0);
        expect(c, "r = R \\ br", M, 1, x, 0, 1e-12);
        expect(c, "r = Rs \\ br", M, 1, x, 0, 1e-12);
    }
    /* MATMUL: dense * dense, CSR * dense, CSR * CSR, dense * CSR */
    for (int j = 0; j < M; j++) dense_apply(M, M, A, 0, A + j * M, W + j * M);
    expect(c, "r = A * A", M, M, W, 0, 1e-14);
    for (int j = 0; j < M; j++) dense_apply(M, M, S, 0, A + j * M, W + j * M);
    expect(c, "r = S * A", M, M, W, 0, 1e-14);
    for (int j = 0; j < M; j++) dense_apply(M, M, S, 0, S + j * M, W + j * M);
    expect(c, "r = S * S", M, M, W, 0, 1e-14);
    for (int j = 0; j < M; j++) dense_apply(M, M, A, 0, S + j * M, W + j * M);
    expect(c, "r = A * S", M, M, W, 0, 1e-14);
    /* TRANSPOSE sub 0: conjugate */
    for (int i = 0; i < M; i++)
        for (int j = 0; j < M; j++) W[j + i * M] = conj(A[i + j * M]);
    expect(c, "r = A'", M, M, W, 0, 0);
    for (int i = 0; i < M; i++)
        for (int j = 0; j < M; j++) W[j + i * M] = conj(S[i + j * M]);
    expect(c, "r = S'", M, M, W, 0, 0);
    /* ADD, SCALE, EWISE */
    for (int k = 0; k < M * M; k++) W[k] = A[k] + S[k];
    expect(c, "r = A + S", M, M, W, 0, 1e-15);
    for (int k = 0; k < M * M; k++) W[k] = S[k] - 2.0 * S[k];
    expect(c, "r = S - S - S", M, M, W, 0, 1e-15);
    for (int k = 0; k < M * M; k++) W[k] = -A[k];
    expect(c, "r = -A", M, M, W, 0, 0);
    for (int k = 0; k < M * M; k++) W[k] = A[k] * S[k];
    expect(c, "r = A .* S", M, M, W, 0, 1e-15);
    for (int k = 0; k < M * M; k++) W[k] = A[k] / A[k];
    expect(c, "r = A ./ A", M, M, W, 0, 1e-15);
    for (int k = 0; k < M * M; k++) W[k] = A[k] == A[k];
    expect(c, "r = A == A", M, M, W, 1, 0);
    for (int k = 0; k < M * M; k++) W[k] = creal(A[k]) < creal(S[k]);
    expect(c, "r = A < S", M, M, W, 1, 0);
    /* MAP: principal branches, modulus */
    for (int k = 0; k < M * M; k++) W[k] = csqrt(A[k]);
    expect(c, "r = sqrt(A)", M, M, W, 0, 1e-15);
    for (int k = 0; k < M * M; k++) W[k] = clog(A[k]);
    expect(c, "r = log(A)", M, M, W, 0, 1e-15);
    for (int k = 0; k < M * M; k++) W[k] = cexp(A[k]);
    expect(c, "r = exp(A)", M, M, W, 0, 1e-15);
    for (int k = 0; k < M * M; k++) W[k] = cabs(S[k]);
    expect(c, "r = abs(S)", M, M, W, 1, 1e-15);
    /* REDUCE: sums by column, max by modulus, the norms */
    for (int j = 0; j < M; j++) {
        W[j] = 0;
        for (int i = 0; i < M; i++) W[j] += A[i + j * M];
    }
    expect(c, "r = sum(A)", 1, M, W, 0, 1e-15);
    for (int j = 0; j < M; j++) {
        W[j] = A[j * M];
        for (int i = 1; i < M; i++)
            if (cabs(A[i + j * M]) > cabs(W[j])) W[j] = A[i + j * M];
    }
    expect(c, "r = max(A)", 1, M, W, 0, 0);
    W[0] = dense_norm1(M, A);
    expect(c, "r = norm(A, 1)", 1, 1, W, 1, 1e-15);
    /* the 2-norm of [2+i, 3i; 1-i, 4+0.5i] in closed form: sigma_max^2 is
     * the largest eigenvalue of A^H A, (F + sqrt(F^2 - 4 |det A|^2)) / 2 */
    cplx T[4] = {2 + I, 1 - I, 3 * I, 4 + 0.5 * I};
    put_complex(c, "T", 2, 2, T, 0);
    double F = 0;
    for (int k = 0; k < 4; k++) F += creal(T[k] * conj(T[k]));
    double det = cabs(T[0] * T[3] - T[1] * T[2]);
    W[0] = sqrt((F + sqrt(F * F - 4 * det * det)) / 2);
    expect(c, "r = norm(T)", 1, 1, W, 1, 1e-13);
    put_complex(c, "Ts", 2, 2, T, 1);
    expect(c, "r = norm(Ts)", 1, 1, W, 1, 1e-13);
    /* CONVERT: CSR of a dense value.  (Band through the language waits for
     * core/lang's band() pre-check to read complex entries; the band kernels
     * are checked directly above.) */
    expect(c, "r = sparse(A)", M, M, A, 0, 0);
    cplx Wt[M * M];
    /* DIAG: the diagonal of a matrix, and the matrix of a vector */
    for (int i = 0; i < M; i++) W[i] = A[i + i * M];
    expect(c, "r = diagvec(A)", M, 1, W, 0, 0);
    memset(Wt, 0, sizeof Wt);
    for (int i = 0; i < M; i++) Wt[i + i * M] = b[i];
    expect(c, "r = diag(bs)", M, M, Wt, 0, 0);
    silc_close(&c);
}

/* ---- the Helmholtz example ------------------------------------------------------------ */

/* examples/helmholtz: its matrix is complex symmetric and not Hermitian,
 * and the plane wave's error falls as h^2 (ratio ~4 per halving of h). */
static void test_helmholtz(void)
{
    silc_context *c = NULL;
    silc_envelope_t A;
    char err[512];
    double b[2 * 17 * 17];
    CHECK(helmholtz_assemble(16, 10.0, HELMHOLTZ_PLANE_WAVE, &A, b, err, sizeof err) == 0, "assemble: %s", err);
    int sym = 1, herm = 1;
    int64_t N = A.m;
    double *D = calloc((size_t)(2 * N * N), sizeof *D);
    silc_envelope_to_dense(&A, D);
    const cplx *Z = (const cplx *)D;
    for (int64_t i = 0; i < N; i++)
        for (int64_t j = 0; j < N; j++) {
            sym &= Z[i + j * N] == Z[j + i * N];
            herm &= Z[i + j * N] == conj(Z[j + i * N]);
        }
    CHECK(sym && !herm, "Helmholtz matrix: complex symmetric %d, Hermitian %d", sym, herm);
    free(D);
    silc_envelope_free(&A);
    CHECK(helmholtz_assemble(1, 10.0, HELMHOLTZ_PLANE_WAVE, &A, b, err, sizeof err) == -1 && strstr(err, "n = 1"),
          "n = 1 refused: %s", err);

    CHECK(silc_open(&c, NULL) == 0, "open");
    double e[3];
    for (int t = 0; t < 3; t++) {
        int n = 16 << t;
        double *u = malloc((size_t)(2 * (n + 1) * (n + 1)) * sizeof *u);
        e[t] = -1;
        if (helmholtz_solve(c, n, 10.0, HELMHOLTZ_PLANE_WAVE, u, err, sizeof err) == 0)
            e[t] = helmholtz_plane_wave_error(n, 10.0, u);
        else
            CHECK(0, "helmholtz n = %d: %s", n, err);
        free(u);
    }
    printf("Helmholtz plane wave, k = 10: max error %.3e (n = 16), %.3e (32), %.3e (64)\n", e[0], e[1], e[2]);
    CHECK(e[0] > 0 && e[1] > 0 && e[2] > 0 && e[0] / e[1] > 3.5 && e[0] / e[1] < 4.6 && e[1] / e[2] > 3.5 &&
              e[1] / e[2] < 4.6, "second order: error ratios %.3f, %.3f", e[0] / e[1], e[1] / e[2]);
    CHECK(e[2] < 0.02, "n = 64: error %.3g", e[2]);
    silc_close(&c);
}

int main(void)
{
    silc_context *c = NULL;
    int rc;
    /* The kernels allocate through the host table the built-in reference
     * plugin keeps, which the first open hands it. */
    CHECK(silc_open(&c, NULL) == 0, "open: %s", c ? silc_context_errmsg(c) : silc_errmsg());
    CHECK(ref_host != NULL, "the reference plugin has its host table");
    if (!ref_host) return check_done();
    test_dense();
    test_dense_qr();
    test_band();
    test_sparse();
    test_sparse_qr();
    test_estimator_random();
    test_shared("young1c.mtx", 0);
    test_shared("mhd1280b.mtx", 1);
    test_language();
    test_helmholtz();
    rc = check_done();
    silc_close(&c);
    return rc;
}
