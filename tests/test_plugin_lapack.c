/*
 * test_plugin_lapack.c -- the lapack backend (OpenBLAS + LAPACKE) against exact
 * solutions and against the reference backend.
 *
 * Two contexts are opened: L sends every solve class it serves, and dense
 * products, to "lapack"; R sends them to "reference".  Generated systems have
 * exact solutions x = 1..n (b = A x computed here): general dense (dgetrf),
 * SPD A = M'M + nI (dpotrf), symmetric indefinite with negative and with
 * positive diagonal (dsytrf, the second after Cholesky fails), triangular
 * (dtrtrs), band, SPD band, tridiagonal (dgbtrf, dpbtrf, dgttrf, dpttrf),
 * tall least squares against the normal-equation solution computed here,
 * wide minimum-norm against A'(AA')^{-1}b, and a rank-deficient tall system
 * (dgelsy).  The forward error must be below 10 n eps cond, with cond the
 * backend's own 1-norm estimate, and `info` must name lapack and the LAPACK
 * routine.  A second solve with the same A must reuse the factorization; an
 * exactly singular matrix must fail with a message naming dgetrf; a CSR
 * matrix must be declined.  Then every real matrix of ../shared/matrices with
 * at most 2000 rows, converted with A = dense(A), is solved by both backends,
 * which must agree within the same condition-scaled bound (singular ones must
 * fail or warn); the timings of both are printed.
 */
#include <ctype.h>
#include <float.h>
#include <stdlib.h>
#include <string.h>

#include "check.h"
#include "silc.h"
#include "testlib.h"

static const char *const classes[] = {"solve.dense", "solve.dense.spd", "solve.triangular",
                                      "solve.band", "solve.rect", "matmul.dense"};

/* ---- output capture and helpers ------------------------------------------------ */

static silc_context *open_ctx(const char *backend)
{
    silc_context *c = NULL;
    char cmd[128];
    if (silc_open(&c, NULL)) {
        fprintf(stderr, "silc_open: %s\n", c ? silc_context_errmsg(c) : silc_errmsg());
        return NULL;
    }
    silc_set_output(c, tl_out_fn, NULL);
    for (size_t i = 0; i < sizeof classes / sizeof classes[0]; i++) {
        snprintf(cmd, sizeof cmd, "set dispatch.%s = %s", classes[i], backend);
        CHECK(silc_exec(c, cmd) == 0, "%s: %s", cmd, silc_context_errmsg(c));
    }
    return c;
}

/* The "condition estimate: X" of an info text, -1 if absent. */
static double info_cond(const char *text)
{
    const char *p = strstr(text, "condition estimate: ");
    if (!p || strncmp(p + 20, "not", 3) == 0) return -1;
    return strtod(p + 20, NULL);
}

/* Forward-error bound: 10 n eps cond (cond >= 1). */
static double bound(int64_t n, double cond)
{
    return 10.0 * (double)n * DBL_EPSILON * (cond > 1 ? cond : 1);
}

static unsigned long long rng_state = 12345;
static double urand(void) /* uniform in [-1, 1) */
{
    rng_state = rng_state * 6364136223846793005ULL + 1442695040888963407ULL;
    return (double)(rng_state >> 11) / 4503599627370496.0 - 1.0;
}

static void matvec(int64_t m, int64_t n, const double *A, const double *x, double *y)
{
    for (int64_t i = 0; i < m; i++) y[i] = 0;
    for (int64_t j = 0; j < n; j++)
        for (int64_t i = 0; i < m; i++) y[i] += A[i + j * m] * x[j];
}

/* Solves the n x n system G y = r in place (partial pivoting; test-side truth). */
static void gauss(int64_t n, double *G, double *r)
{
    for (int64_t k = 0; k < n; k++) {
        int64_t p = k;
        for (int64_t i = k + 1; i < n; i++)
            if (fabs(G[i + k * n]) > fabs(G[p + k * n])) p = i;
        for (int64_t j = 0; j < n; j++) {
            double t = G[k + j * n];
            G[k + j * n] = G[p + j * n];
            G[p + j * n] = t;
        }
        double t = r[k];
        r[k] = r[p];
        r[p] = t;
        for (int64_t i = k + 1; i < n; i++) {
            double l = G[i + k * n] / G[k + k * n];
            for (int64_t j = k; j < n; j++) G[i + j * n] -= l * G[k + j * n];
            r[i] -= l * r[k];
        }
    }
    for (int64_t k = n - 1; k >= 0; k--) {
        for (int64_t j = k + 1; j < n; j++) r[k] -= G[k + j * n] * r[j];
        r[k] /= G[k + k * n];
    }
}

/* ---- square systems with x = 1..n ------------------------------------------------ */

/* PUTs A (dense n x n) and b = A (1..n) in both contexts, solves, checks the
 * result against the exact solution and the reference, `info` naming lapack
 * and routine, and factor reuse on a second solve. */
static void check_square(silc_context *L, silc_context *R, const char *label, int64_t n, const double *A,
                         const char *routine)
{
    double *xt = malloc((size_t)n * sizeof(double)), *b = malloc((size_t)n * sizeof(double));
    double *xl, *xr, cond;
    const char *text;
    if (!xt || !b) {
        free(xt);
        free(b);
        CHECK(0, "out of memory");
        return;
    }
    for (int64_t i = 0; i < n; i++) xt[i] = (double)(i + 1);
    matvec(n, n, A, xt, b);
    tl_put_dense_checked(L, "A", n, n, A);
    tl_put_dense_checked(L, "b", n, 1, b);
    tl_put_dense_checked(R, "A", n, n, A);
    tl_put_dense_checked(R, "b", n, 1, b);
    CHECK(silc_exec(L, "x = A \\ b") == 0, "%s: lapack solve: %s", label, silc_context_errmsg(L));
    CHECK(silc_exec(R, "x = A \\ b") == 0, "%s: reference solve: %s", label, silc_context_errmsg(R));
    text = tl_out_info(L, "x");
    CHECK(tl_contains(text, "backend: lapack"), "%s: info does not name lapack:\n%s", label, text);
    CHECK(tl_contains(text, routine), "%s: info does not name %s:\n%s", label, routine, text);
    cond = info_cond(text);
    CHECK(cond >= 1, "%s: no condition estimate (%g)", label, cond);
    xl = tl_get_dense_checked(L, "x", n, 1);
    xr = tl_get_dense_checked(R, "x", n, 1);
    if (xl && xr) {
        CHECK(tl_rel_diff(xl, xt, n) <= bound(n, cond), "%s: lapack error %.3g > %.3g (cond %.3g)", label,
              tl_rel_diff(xl, xt, n), bound(n, cond), cond);
        CHECK(tl_rel_diff(xl, xr, n) <= bound(n, cond), "%s: lapack and reference differ by %.3g > %.3g",
              label, tl_rel_diff(xl, xr, n), bound(n, cond));
    }
    free(xl);
    free(xr);
    /* The same A again: the attached factorization is reused. */
    CHECK(silc_exec(L, "y = A \\ (2 * b)") == 0, "%s: second solve: %s", label, silc_context_errmsg(L));
    text = tl_out_info(L, "y");
    CHECK(tl_contains(text, "reused factorization: yes") || tl_contains(routine, "dtrtrs"),
          "%s: second solve did not reuse the factorization:\n%s", label, text);
    /* The same entries as a new value, factored under accuracy.condest =
     * off (the plugin leaves its estimate out), then solved again with the
     * estimate wanted: it is made then from the kept factors, the number
     * the first solve gave. */
    tl_put_dense_checked(L, "A2", n, n, A);
    CHECK(silc_exec(L, "set accuracy.condest = off; x2 = A2 \\ b") == 0, "%s: solve, condest off: %s", label,
          silc_context_errmsg(L));
    text = tl_out_info(L, "x2");
    CHECK(tl_contains(text, "not estimated (accuracy.condest = off)"), "%s: an estimate under off:\n%s", label,
          text);
    CHECK(silc_exec(L, "set accuracy.condest = auto; y2 = A2 \\ b") == 0, "%s: solve, condest back on: %s",
          label, silc_context_errmsg(L));
    text = tl_out_info(L, "y2");
    CHECK(tl_contains(text, "reused factorization: yes") || tl_contains(routine, "dtrtrs"),
          "%s: the solve after condest off did not reuse the factorization:\n%s", label, text);
    CHECK(info_cond(text) == cond, "%s: estimate made after the factorization %g, with it %g:\n%s", label,
          info_cond(text), cond, text);
    CHECK(silc_exec(L, "clear A2 x2 y2") == 0, "%s: clear: %s", label, silc_context_errmsg(L));
    free(xt);
    free(b);
}

static double *random_matrix(int64_t m, int64_t n)
{
    double *A = malloc((size_t)(m * n) * sizeof(double));
    if (A)
        for (int64_t k = 0; k < m * n; k++) A[k] = urand();
    return A;
}

static void test_dense(silc_context *L, silc_context *R)
{
    const int64_t n = 120;
    double *A = random_matrix(n, n), *M = random_matrix(n, n), *S = malloc((size_t)(n * n) * sizeof(double));
    if (!A || !M || !S) {
        CHECK(0, "out of memory");
        free(A);
        free(M);
        free(S);
        return;
    }
    for (int64_t i = 0; i < n; i++) A[i + i * n] += 10.0; /* well conditioned */
    check_square(L, R, "general dense", n, A, "dgetrf");

    /* SPD: S = M'M + n I. */
    for (int64_t i = 0; i < n; i++)
        for (int64_t j = 0; j < n; j++) {
            double s = i == j ? (double)n : 0.0;
            for (int64_t k = 0; k < n; k++) s += M[k + i * n] * M[k + j * n];
            S[i + j * n] = s;
        }
    check_square(L, R, "SPD dense", n, S, "dpotrf");

    /* Symmetric indefinite with a negative diagonal: straight to solve.dense. */
    for (int64_t j = 0; j < n; j++)
        for (int64_t i = j; i < n; i++) {
            double s = i == j ? ((i % 2) ? -12.0 : 12.0) + urand() : urand();
            S[i + j * n] = S[j + i * n] = s;
        }
    check_square(L, R, "symmetric indefinite", n, S, "dsytrf");

    /* Symmetric, positive diagonal, indefinite: Cholesky fails, LDL' answers. */
    for (int64_t j = 0; j < n; j++)
        for (int64_t i = j; i < n; i++) S[i + j * n] = S[j + i * n] = i == j ? 1.0 : urand();
    check_square(L, R, "symmetric, positive diagonal, indefinite", n, S, "dsytrf");
    {   /* The note names the method that solved (it said "used LU"). */
        const char *text = tl_out_info(L, "x");
        CHECK(tl_contains(text, "Cholesky failed (not positive definite); used symmetric indefinite LDL'"),
              "the fallback note does not name LDL':\n%s", text);
    }

    /* Triangular, lower and upper. */
    for (int64_t j = 0; j < n; j++)
        for (int64_t i = 0; i < n; i++) A[i + j * n] = i < j ? 0.0 : (i == j ? 2.0 + urand() : urand() / 4);
    check_square(L, R, "lower triangular", n, A, "dtrtrs");
    for (int64_t j = 0; j < n; j++)
        for (int64_t i = 0; i < n; i++) A[i + j * n] = i > j ? 0.0 : (i == j ? 2.0 + urand() : urand() / 4);
    check_square(L, R, "upper triangular", n, A, "dtrtrs");

    /* Several right-hand sides at once. */
    {
        double B[120 * 3], *X;
        for (int64_t k = 0; k < n * 3; k++) B[k] = urand();
        tl_put_dense_checked(L, "B", n, 3, B);
        CHECK(silc_exec(L, "X = A \\ B; R = A * X - B") == 0, "multiple rhs: %s", silc_context_errmsg(L));
        X = tl_get_dense_checked(L, "R", n, 3);
        if (X) {
            double r = 0;
            for (int64_t k = 0; k < n * 3; k++) r = fmax(r, fabs(X[k]));
            CHECK(r < 1e-12, "multiple rhs residual %.3g", r);
        }
        free(X);
    }

    /* Exactly singular: a zero column gives an exactly zero pivot. */
    for (int64_t k = 0; k < n * n; k++) A[k] = urand();
    for (int64_t i = 0; i < n; i++) A[i + 7 * n] = 0.0;
    tl_put_dense_checked(L, "Z", n, n, A);
    CHECK(silc_exec(L, "z = Z \\ b") != 0, "singular matrix solved");
    CHECK(tl_contains(silc_context_errmsg(L), "dgetrf") && tl_contains(silc_context_errmsg(L), "singular"),
          "singular message does not name dgetrf: %s", silc_context_errmsg(L));
    free(A);
    free(M);
    free(S);
}

/* ---- least squares ------------------------------------------------------------ */

static void test_rect(silc_context *L, silc_context *R)
{
    const int64_t m = 80, n = 25;
    double *A = random_matrix(m, n), *b = random_matrix(m, 1), *G = malloc((size_t)(n * n) * sizeof(double));
    double r[80], *xl, *xr;
    const char *text;
    if (!A || !b || !G) {
        CHECK(0, "out of memory");
        free(A);
        free(b);
        free(G);
        return;
    }
    /* Tall: x = (A'A) \ (A'b), b not in the range of A. */
    for (int64_t i = 0; i < n; i++) {
        r[i] = 0;
        for (int64_t k = 0; k < m; k++) r[i] += A[k + i * m] * b[k];
        for (int64_t j = 0; j < n; j++) {
            double s = 0;
            for (int64_t k = 0; k < m; k++) s += A[k + i * m] * A[k + j * m];
            G[i + j * n] = s;
        }
    }
    gauss(n, G, r);
    tl_put_dense_checked(L, "T", m, n, A);
    tl_put_dense_checked(L, "c", m, 1, b);
    tl_put_dense_checked(R, "T", m, n, A);
    tl_put_dense_checked(R, "c", m, 1, b);
    CHECK(silc_exec(L, "x = T \\ c") == 0, "tall: %s", silc_context_errmsg(L));
    CHECK(silc_exec(R, "x = T \\ c") == 0, "tall reference: %s", silc_context_errmsg(R));
    text = tl_out_info(L, "x");
    CHECK(tl_contains(text, "backend: lapack") && tl_contains(text, "dgeqrf"), "tall info:\n%s", text);
    xl = tl_get_dense_checked(L, "x", n, 1);
    xr = tl_get_dense_checked(R, "x", n, 1);
    if (xl && xr) {
        CHECK(tl_rel_diff(xl, r, n) < 1e-11, "tall vs normal equations: %.3g", tl_rel_diff(xl, r, n));
        CHECK(tl_rel_diff(xl, xr, n) < 1e-11, "tall vs reference: %.3g", tl_rel_diff(xl, xr, n));
    }
    free(xl);
    free(xr);
    CHECK(silc_exec(L, "y = T \\ c") == 0 && tl_contains(tl_out_info(L, "y"), "reused factorization: yes"),
          "tall: factor not reused:\n%s", tl_out());

    /* Wide: the minimum-norm solution x = W' (W W') \ c, W = T' (n x m). */
    for (int64_t i = 0; i < n; i++) {
        r[i] = b[i];
        for (int64_t j = 0; j < n; j++) {
            double s = 0;
            for (int64_t k = 0; k < m; k++) s += A[k + i * m] * A[k + j * m];
            G[i + j * n] = s;
        }
    }
    gauss(n, G, r);
    {
        double xw[80];
        for (int64_t k = 0; k < m; k++) {
            xw[k] = 0;
            for (int64_t i = 0; i < n; i++) xw[k] += A[k + i * m] * r[i];
        }
        tl_put_dense_checked(L, "d", n, 1, b);
        CHECK(silc_exec(L, "W = T'; w = W \\ d") == 0, "wide: %s", silc_context_errmsg(L));
        text = tl_out_info(L, "w");
        CHECK(tl_contains(text, "backend: lapack") && tl_contains(text, "dgelqf"), "wide info:\n%s", text);
        xl = tl_get_dense_checked(L, "w", m, 1);
        if (xl) CHECK(tl_rel_diff(xl, xw, m) < 1e-11, "wide vs minimum norm: %.3g", tl_rel_diff(xl, xw, m));
        free(xl);
    }

    /* Rank deficient: column 5 repeated as column 6.  The answer must still
     * satisfy the normal equations A'(c - A x) = 0. */
    for (int64_t k = 0; k < m; k++) A[k + 6 * m] = A[k + 5 * m];
    tl_put_dense_checked(L, "D", m, n, A);
    CHECK(silc_exec(L, "x = D \\ c; g = D' * (c - D * x)") == 0, "rank deficient: %s",
          silc_context_errmsg(L));
    text = tl_out_info(L, "x");
    CHECK(tl_contains(text, "dgelsy") && tl_contains(text, "rank 24 of 25"), "rank-deficient info:\n%s", text);
    xl = tl_get_dense_checked(L, "g", n, 1);
    if (xl) {
        double g = 0;
        for (int64_t i = 0; i < n; i++) g = fmax(g, fabs(xl[i]));
        CHECK(g < 1e-10, "rank deficient: normal-equation residual %.3g", g);
    }
    free(xl);
    free(A);
    free(b);
    free(G);
}

/* ---- band and tridiagonal ------------------------------------------------------ */

/* A band envelope (kl, ku) with the given entry function, solved in both contexts. */
static void check_band(silc_context *L, silc_context *R, const char *label, int64_t n, int64_t kl,
                       int64_t ku, double (*entry)(int64_t i, int64_t j), const char *routine)
{
    int64_t ld = kl + ku + 1;
    double *band = calloc((size_t)(ld * n), sizeof(double)), *xt = malloc((size_t)n * sizeof(double));
    double *b = calloc((size_t)n, sizeof(double)), *xl, *xr, cond;
    silc_envelope_t e;
    const char *text;
    if (!band || !xt || !b) {
        CHECK(0, "out of memory");
        free(band);
        free(xt);
        free(b);
        return;
    }
    for (int64_t i = 0; i < n; i++) xt[i] = (double)(i + 1);
    for (int64_t j = 0; j < n; j++)
        for (int64_t i = j - ku > 0 ? j - ku : 0; i <= j + kl && i < n; i++) {
            double a = entry(i, j);
            band[(ku + i - j) + j * ld] = a;
            b[i] += a * xt[j];
        }
    CHECK(silc_envelope_band(&e, n, n, kl, ku, band) == 0, "%s: band envelope", label);
    CHECK(silc_put(L, "A", &e) == 0 && silc_put(R, "A", &e) == 0, "%s: put", label);
    silc_envelope_free(&e);
    tl_put_dense_checked(L, "b", n, 1, b);
    tl_put_dense_checked(R, "b", n, 1, b);
    CHECK(silc_exec(L, "x = A \\ b") == 0, "%s: %s", label, silc_context_errmsg(L));
    CHECK(silc_exec(R, "x = A \\ b") == 0, "%s reference: %s", label, silc_context_errmsg(R));
    text = tl_out_info(L, "x");
    CHECK(tl_contains(text, "backend: lapack") && tl_contains(text, routine), "%s: info does not name %s:\n%s",
          label, routine, text);
    cond = info_cond(text);
    CHECK(cond >= 1, "%s: no condition estimate", label);
    xl = tl_get_dense_checked(L, "x", n, 1);
    xr = tl_get_dense_checked(R, "x", n, 1);
    if (xl && xr) {
        CHECK(tl_rel_diff(xl, xt, n) <= bound(n, cond), "%s: error %.3g (cond %.3g)", label,
              tl_rel_diff(xl, xt, n), cond);
        CHECK(tl_rel_diff(xl, xr, n) <= bound(n, cond), "%s: vs reference %.3g", label, tl_rel_diff(xl, xr, n));
    }
    free(xl);
    free(xr);
    CHECK(silc_exec(L, "y = A \\ b") == 0 && tl_contains(tl_out_info(L, "y"), "reused factorization: yes"),
          "%s: factor not reused:\n%s", label, tl_out());
    /* The same matrix stored dense is still banded: the dispatcher sends it to
     * solve.band and lapack copies the band out of it. */
    CHECK(silc_exec(L, "F = dense(A); z = F \\ b") == 0, "%s dense-stored: %s", label,
          silc_context_errmsg(L));
    text = tl_out_info(L, "z");
    CHECK(tl_contains(text, "backend: lapack") && tl_contains(text, routine), "%s dense-stored: info:\n%s", label,
          text);
    free(band);
    free(xt);
    free(b);
}

static double gen_band(int64_t i, int64_t j)
{
    return i == j ? 8.0 : 1.0 / (double)(1 + i + 2 * j % 7) - 0.3;
}
static double spd_band(int64_t i, int64_t j)
{
    return i == j ? 6.0 : -1.0 / (double)(1 + (i + j) % 5);
}
static double indef_band(int64_t i, int64_t j) /* symmetric, positive diagonal, indefinite */
{
    return i == j ? 1.0 : 2.0;
}
static double lap1d(int64_t i, int64_t j)
{
    return i == j ? 2.0 : -1.0;
}
static double gen_tri(int64_t i, int64_t j)
{
    return i == j ? 4.0 : (i > j ? -1.0 : 1.5 + 0.01 * (double)i);
}

static void test_band(silc_context *L, silc_context *R)
{
    check_band(L, R, "band", 300, 3, 2, gen_band, "dgbtrf");
    check_band(L, R, "SPD band", 300, 2, 2, spd_band, "dpbtrf");
    check_band(L, R, "indefinite symmetric band", 60, 2, 2, indef_band, "dgbtrf");
    CHECK(tl_contains(tl_out_info(L, "x"), "dpbtrf: not positive definite"), "no fallback note:\n%s", tl_out());
    check_band(L, R, "1-D Laplacian", 200, 1, 1, lap1d, "dpttrf");
    check_band(L, R, "tridiagonal", 200, 1, 1, gen_tri, "dgttrf");
}

/* ---- products, declines ------------------------------------------------------- */

static void test_matmul_and_declines(silc_context *L)
{
    const int64_t m = 30, k = 20, n = 15;
    double *A = random_matrix(m, k), *B = random_matrix(k, n), C[30 * 15], *got;
    const char *text;
    if (!A || !B) {
        CHECK(0, "out of memory");
        free(A);
        free(B);
        return;
    }
    for (int64_t j = 0; j < n; j++) matvec(m, k, A, B + j * k, C + j * m);
    tl_put_dense_checked(L, "P", m, k, A);
    tl_put_dense_checked(L, "Q", k, n, B);
    text = tl_out_exec(L, "explain C = P * Q");
    CHECK(tl_contains(text, "lapack -> would run"), "matmul not sent to lapack:\n%s", text);
    CHECK(silc_exec(L, "C = P * Q; v = P * Q[:, 1]; u = P[1, :] * Q") == 0, "matmul: %s",
          silc_context_errmsg(L));
    got = tl_get_dense_checked(L, "C", m, n);
    if (got) CHECK(tl_rel_diff(got, C, m * n) < 1e-14, "dgemm: %.3g", tl_rel_diff(got, C, m * n));
    free(got);
    got = tl_get_dense_checked(L, "v", m, 1);
    if (got) CHECK(tl_rel_diff(got, C, m) < 1e-14, "dgemv: %.3g", tl_rel_diff(got, C, m));
    free(got);
    got = tl_get_dense_checked(L, "u", 1, n);
    if (got) {
        double row[15];
        for (int64_t j = 0; j < n; j++) row[j] = C[j * m];
        CHECK(tl_rel_diff(got, row, n) < 1e-14, "dgemv (transposed): %.3g", tl_rel_diff(got, row, n));
    }
    free(got);

    /* CSR is declined with the reason. */
    CHECK(silc_exec(L, "set dispatch.solve.sparse = lapack; S = sparse(P[1:20, 1:20] + 10 * eye(20))") == 0,
          "sparse setup: %s", silc_context_errmsg(L));
    text = tl_out_exec(L, "explain s = S \\ Q[:, 1]");
    CHECK(tl_contains(text, "needs dense or band storage"), "CSR not declined:\n%s", text);
    free(A);
    free(B);
}

/* ---- shared matrices ------------------------------------------------------------ */

/* Warnings of the last timed() statement (info would clear the context's). */
static char warn_buf[1024];

/* Runs stmt and returns the wall time the engine measured for it (-1 on failure). */
static double timed(silc_context *c, const char *stmt, int *rc)
{
    const char *p;
    *rc = silc_exec(c, stmt);
    if (*rc) return -1;
    snprintf(warn_buf, sizeof warn_buf, "%s", silc_context_warnings(c));
    p = strstr(tl_out_info(c, "x"), "wall time: ");
    return p ? strtod(p + 11, NULL) : -1;
}

static void test_shared(silc_context *L, silc_context *R)
{
    char path[1024];
    tl_index_row r;
    FILE *idx = tl_index_open(NULL, path, sizeof path);
    if (!idx) return;
    printf("%-18s %6s %6s  %-13s %9s %9s %9s %9s %9s\n", "matrix", "rows", "cols", "class", "lapack s",
           "ref s", "cond", "berr", "|xl-xr|");
    while (tl_index_next(idx, &r)) {
        const char *file = r.file, *cls = r.cls;
        long long m = r.rows, n = r.cols;
        silc_envelope_t e;
        double *b, *xt, *xl = NULL, *xr = NULL, tl, tr, cond, berr = -1, diff = -1;
        int rcl, rcr;
        if (m > 2000 || strcmp(r.field, "complex") == 0) continue;
        if (tl_read_shared(file, &e)) continue;
        xt = malloc((size_t)n * sizeof(double));
        b = calloc((size_t)m, sizeof(double));
        if (!xt || !b) {
            CHECK(0, "out of memory");
            goto next;
        }
        for (int64_t j = 0; j < n; j++) xt[j] = 1.0 + (double)j / (double)n;
        for (int64_t i = 0; i < m; i++)
            for (int64_t p = e.rowptr[i]; p < e.rowptr[i + 1]; p++) b[i] += e.values[p] * xt[e.colind[p]];
        CHECK(silc_put(L, "A", &e) == 0 && silc_put(R, "A", &e) == 0, "%s: put", file);
        tl_put_dense_checked(L, "b", m, 1, b);
        tl_put_dense_checked(R, "b", m, 1, b);
        CHECK(silc_exec(L, "A = dense(A)") == 0 && silc_exec(R, "A = dense(A)") == 0, "%s: dense()", file);
        tl = timed(L, "x = A \\ b", &rcl);
        if (rcl) {
            /* Only singular matrices may be refused, and the message must say so. */
            CHECK(strstr(cls, "singular") && tl_contains(silc_context_errmsg(L), "singular"),
                  "%s (%s): lapack failed: %s", file, cls, silc_context_errmsg(L));
            printf("%-18s %6lld %6lld  %-13s refused: %s\n", file, m, n, cls, silc_context_errmsg(L));
            goto next;
        }
        cond = info_cond(tl_out_info(L, "x"));
        CHECK(tl_contains(tl_out(), "backend: lapack"), "%s: not solved by lapack:\n%s", file, tl_out());
        CHECK(cond * DBL_EPSILON <= 1e-4 || tl_contains(warn_buf, "singular") || tl_contains(warn_buf, "digits"),
              "%s: cond %.3g and no warning", file, cond);
        tr = timed(R, "x = A \\ b", &rcr);
        xl = tl_get_dense_checked(L, "x", n, 1);
        xr = rcr ? NULL : tl_get_dense_checked(R, "x", n, 1);
        if (xl) berr = tl_backward_error(&e, xl, b);
        if (xl && xr) diff = tl_rel_diff(xl, xr, n);
        printf("%-18s %6lld %6lld  %-13s %9.4f %9.4f %9.3g %9.3g %9.3g\n", file, m, n, cls, tl, tr, cond,
               berr, diff);
        /* Backward stable whatever the conditioning (LU growth is mild in practice). */
        CHECK(berr >= 0 && berr < 1e-12, "%s: backward error %.3g", file, berr);
        if (cond < 0) {
            CHECK(strcmp(cls, "rect") == 0, "%s: no condition estimate", file);
        } else if (bound(n, cond) < 1e-2 && xl && xr) {
            CHECK(tl_rel_diff(xl, xt, n) <= bound(n, cond), "%s: lapack error %.3g > %.3g", file,
                  tl_rel_diff(xl, xt, n), bound(n, cond));
            CHECK(diff <= bound(n, cond), "%s: lapack vs reference %.3g > %.3g", file, diff, bound(n, cond));
        }
    next:
        free(xl);
        free(xr);
        free(xt);
        free(b);
        silc_envelope_free(&e);
    }
    fclose(idx);
}

int main(void)
{
    silc_context *L = open_ctx("lapack"), *R = open_ctx("reference");
    CHECK(L && R, "cannot open contexts");
    if (L && R) {
        test_dense(L, R);
        test_rect(L, R);
        test_band(L, R);
        test_matmul_and_declines(L);
        test_shared(L, R);
    }
    silc_close(&L);
    silc_close(&R);
    return check_done();
}
