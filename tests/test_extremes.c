/*
 * test_extremes.c -- stability at the numerical extremes, for every backend
 * that accepts the operands.
 *
 * Each case forces one backend at a time with solve(A, b, "backend = X"): a
 * backend that is not built here, does not provide the solve, or declines
 * the operands is skipped (told apart by the error text); every other
 * outcome is checked.  The cases:
 *
 *   Hilbert n = 4..14     agreement with the reference backend and with the
 *                         exact solution to C n cond eps; the condition
 *                         estimate against the true cond_1 (the inverse of
 *                         the Hilbert matrix has integer entries in closed
 *                         form); the "fewer than 4 correct digits" warning
 *                         exactly when the run's estimate says cond eps > 1e-4.
 *   scaling               A, b scaled by 1e-300 ... 1e300 together (x
 *                         unchanged) and b alone (x scales): no overflow or
 *                         underflow in norms, finite backward errors.
 *   NaN / Inf             an error naming the operand, the value and the
 *                         1-based position, before any backend runs.
 *   singular              exactly singular, numerically singular (neumann),
 *                         zero row / column, all-zero sparse: an error that
 *                         says singular or a result with the warning.
 *   tiny systems          0x0 \ 0x1 is 0x1 (as MATLAB), 1x1.
 *   storage               explicit zeros, subnormal entries.
 *   iterative             indefinite and non-normal matrices: breakdown or
 *                         stagnation reported with iteration and residual.
 *   least squares         full rank: the least-squares solution; rank
 *                         deficient: a solution of the normal equations with
 *                         the rank reported; underdetermined of full row
 *                         rank: the minimum-norm solution from every backend.
 */
#include "check.h"
#include "testlib.h"

#include <float.h>

typedef struct backend {
    const char *name;
    int sparse;             /* give it CSR (else dense) */
    int iterative;          /* accuracy is the solver's tolerance, not cond eps */
    const char *opts;       /* extra per-call options */
} backend;

static const backend backends[] = {
    {"reference", 0, 0, ""},
    {"reference", 1, 0, ""},
    {"lapack", 0, 0, ""},
    {"suitesparse.umfpack", 1, 0, ""},
    {"suitesparse.klu", 1, 0, ""},
    {"suitesparse.cholmod", 1, 0, ""},
    {"suitesparse.spqr", 1, 0, ""},
    {"mumps", 1, 0, ""},
    {"petsc", 1, 1, "; petsc.options = -ksp_type gmres -pc_type ilu -ksp_rtol 1e-12 -ksp_max_it 500"},
    {"lis-style", 1, 1, "; lis-style.options = -i gmres -p ilu -tol 1e-12 -maxiter 500"},
};
#define NB (sizeof backends / sizeof backends[0])

static silc_context *ctx;
static tl_capture cap;

/* ---- helpers --------------------------------------------------------------- */

/* Puts the m x n column-major array as dense or CSR; CSR keeps zeros only
 * when keep_zeros is set. */
static int put_matrix(const char *name, int64_t m, int64_t n, const double *a, int sparse,
                      int keep_zeros)
{
    silc_envelope_t e;
    int rc;
    if (!sparse) {
        rc = silc_envelope_dense(&e, m, n, a);
    } else {
        int64_t *rp = malloc((size_t)(m + 1) * sizeof *rp), *ci = malloc((size_t)(m * n + 1) * sizeof *ci);
        double *v = malloc((size_t)(m * n + 1) * sizeof *v);
        int64_t i, j, nz = 0;
        rp[0] = 0;
        for (i = 0; i < m; i++) {
            for (j = 0; j < n; j++)
                if (a[i + j * m] != 0 || keep_zeros) ci[nz] = j, v[nz++] = a[i + j * m];
            rp[i + 1] = nz;
        }
        rc = silc_envelope_csr(&e, m, n, rp, ci, v);
        free(rp);
        free(ci);
        free(v);
    }
    if (rc) return rc;
    rc = silc_put(ctx, name, &e);
    silc_envelope_free(&e);
    return rc;
}

enum { RUN_OK = 0, RUN_SKIP = 1, RUN_ERR = 2 };

/* x = solve(A, b, "backend = B ...extra"); RUN_SKIP when B cannot take it. */
static int run(const backend *B, const char *extra)
{
    char stmt[512];
    const char *err;
    snprintf(stmt, sizeof stmt, "x = solve(A, b, \"backend = %s%s%s\")", B->name, B->opts,
             extra ? extra : "");
    if (silc_exec(ctx, stmt) == 0) return RUN_OK;
    err = silc_context_errmsg(ctx);
    if (tl_contains(err, "not installed") || tl_contains(err, "declines") ||
        tl_contains(err, "does not provide") || tl_contains(err, "no backend can run"))
        return RUN_SKIP;
    return RUN_ERR;
}

static double *get_x(int64_t *m, int64_t *n)
{
    return tl_get_dense(ctx, "x", m, n);
}

static const char *label(const backend *B)
{
    static char buf[80];
    snprintf(buf, sizeof buf, "%s (%s)", B->name, B->sparse ? "csr" : "dense");
    return buf;
}

/* An error that says why, with the numbers a user needs. */
static int singular_text(const char *t)
{
    return tl_contains(t, "singular") || tl_contains(t, "zero pivot") ||
           tl_contains(t, "rank") || tl_contains(t, "fewer than 4 correct digits");
}

/* ---- Hilbert ------------------------------------------------------------------- */

static double binom(int n, int k)
{
    double r = 1;
    int i;
    if (k < 0 || k > n) return 0;
    for (i = 1; i <= k; i++) r = r * (n - k + i) / i;
    return r;
}

/* cond_1 of the n x n Hilbert matrix from its exact inverse (integer entries):
 * (H^-1)_ij = (-1)^(i+j) (i+j-1) C(n+i-1, n-j) C(n+j-1, n-i) C(i+j-2, i-1)^2. */
static double hilbert_cond1(int n)
{
    double hn = 0, hin = 0;
    int i, j;
    for (j = 1; j <= n; j++) {
        double s = 0, t = 0;
        for (i = 1; i <= n; i++) {
            double c = binom(i + j - 2, i - 1);
            s += 1.0 / (i + j - 1);
            t += (i + j - 1) * binom(n + i - 1, n - j) * binom(n + j - 1, n - i) * c * c;
        }
        if (s > hn) hn = s;
        if (t > hin) hin = t;
    }
    return hn * hin;
}

static void test_hilbert(void)
{
    int n;
    size_t k;
    for (n = 4; n <= 14; n++) {
        double *H = malloc((size_t)(n * n) * sizeof *H), *b = calloc((size_t)n, sizeof *b);
        double *xref = NULL, cond = hilbert_cond1(n), ceps = cond * DBL_EPSILON;
        int64_t i, j, m1, n1;
        for (j = 0; j < n; j++)
            for (i = 0; i < n; i++) {
                H[i + j * n] = 1.0 / (double)(i + j + 1);
                b[i] += H[i + j * n];
            }
        tl_put_vector(ctx, "b", n, b);
        for (k = 0; k < NB; k++) {
            const backend *B = &backends[k];
            const char *info, *warn;
            char warnbuf[512];
            double *x, est, be, ferr;
            int rc;
            put_matrix("A", n, n, H, B->sparse, 0);
            rc = run(B, NULL);
            if (rc == RUN_SKIP) continue;
            if (rc == RUN_ERR) {
                const char *e = silc_context_errmsg(ctx);
                /* Past cond eps ~ 1 a direct backend may call H singular; an
                 * iterative one may stop, but must say where and how far. */
                if (B->iterative)
                    CHECK((tl_contains(e, "iteration") && tl_contains(e, "residual")) ||
                              (ceps > 1e-2 && singular_text(e)),
                          "hilbert %d, %s: iterative failure without iteration/residual: %s", n,
                          label(B), e);
                else
                    CHECK(ceps > 1e-2 && singular_text(e), "hilbert %d (cond %.2g), %s failed: %s",
                          n, cond, label(B), e);
                continue;
            }
            x = get_x(&m1, &n1);
            snprintf(warnbuf, sizeof warnbuf, "%s", silc_context_warnings(ctx));
            warn = warnbuf;
            info = tl_info(ctx, &cap, "x");
            est = tl_field(info, "condition estimate");
            be = tl_field(info, "backward error");
            ferr = 0;
            for (i = 0; i < n; i++)
                if (fabs(x[i] - 1) > ferr || x[i] != x[i]) ferr = x[i] != x[i] ? INFINITY : fabs(x[i] - 1);
            if (!B->iterative) {
                CHECK(be < 1e-12 || ceps > 1e-2, "hilbert %d, %s: backward error %.3g", n, label(B), be);
                /* The forward error the condition number allows (b itself is
                 * rounded: another eps of relative perturbation). */
                if (ceps < 1e-2)
                    CHECK(ferr <= 10.0 * n * ceps, "hilbert %d, %s: ||x - 1|| = %.3g > 10 n cond eps = %.3g",
                          n, label(B), ferr, 10.0 * n * ceps);
                if (xref && ceps < 1e-2)
                    CHECK(tl_rel_diff(x, xref, n) <= 20.0 * n * ceps,
                          "hilbert %d, %s differs from the reference by %.3g (cond eps %.2g)", n,
                          label(B), tl_rel_diff(x, xref, n), ceps);
                /* SPQR estimates only when it finds full rank (docs/accuracy.md). */
                CHECK((est == est && est > 0) || strcmp(B->name, "suitesparse.spqr") == 0,
                      "hilbert %d, %s: no condition estimate in info", n, label(B));
                if (est == est && est > 0) {
                    int warned = tl_contains(warn, "correct digits") || tl_contains(warn, "singular");
                    /* The estimate is a lower bound, usually within a factor 3;
                     * beyond cond eps ~ 1 the rounded matrix is another matrix. */
                    /* SPQR estimates ||A||_1 ||R^-1||_1: R^-1 = A^-1 Q, so it may
                     * exceed cond_1(A) by up to sqrt(m n) = n, not only fall short. */
                    double over = strcmp(B->name, "suitesparse.spqr") == 0 ? n : 1.01;
                    if (ceps < 1e-2)
                        CHECK(est <= over * cond && est >= cond / 30,
                              "hilbert %d, %s: estimate %.3g, true cond %.3g", n, label(B), est, cond);
                    CHECK(warned == (est * DBL_EPSILON > 1e-4),
                          "hilbert %d, %s: estimate %.3g (cond eps %.2g) but warning '%s'", n,
                          label(B), est, est * DBL_EPSILON, warn);
                    if (ceps > 1e-3) CHECK(warned, "hilbert %d, %s: no warning at cond %.3g", n, label(B), cond);
                    if (ceps < 1e-6) CHECK(!warned, "hilbert %d, %s: warning at cond %.3g", n, label(B), cond);
                    /* Forward error bound shown next to the backward error. */
                    CHECK(tl_contains(info, "forward error bound (estimate: est ||A^-1||_1 ||b - A x||_1 / ||x||_1): "),
                          "hilbert %d, %s: info lacks the forward error bound", n, label(B));
                }
            } else if (ceps < 1e-6) {
                CHECK(ferr <= 1e-10 * cond + 1e-6, "hilbert %d, %s (iterative): ||x - 1|| = %.3g", n,
                      label(B), ferr);
            }
            if (k == 0) xref = x;
            else free(x);
        }
        free(xref);
        free(H);
        free(b);
    }
}

/* ---- scaling ------------------------------------------------------------------- */

/* A well-conditioned nonsymmetric 6x6 matrix and an SPD one (for Cholesky). */
static void test_matrix(double *A, int spd)
{
    int i, j, n = 6;
    for (j = 0; j < n; j++)
        for (i = 0; i < n; i++) {
            double v = i == j ? 4.0 + i : (i == j + 1 || j == i + 1) ? -1.0 : 0.0;
            if (!spd && j == i + 2) v = 0.5;
            A[i + j * n] = v;
        }
}

/* x = A \\ b for a scaled system must be x1 * f, with a small backward error
 * and the same condition estimate, from every backend: the core solves
 * systems near 1e+-300 scaled by powers of two (core/accuracy/scale.c), so even
 * backends whose norms or pivot tests assume moderate data (PETSc's ILU,
 * CG's inner products) see moderate data. */
static void check_scaled(const backend *B, double sc, const char *what, const double *x1, double f)
{
    char warn[512];
    const char *info;
    double want[6], *x, be, est;
    int i, rc = run(B, NULL);
    CHECK(rc == RUN_OK, "scale %g (%s), %s: %s", sc, what, label(B), silc_context_errmsg(ctx));
    if (rc != RUN_OK) return;
    snprintf(warn, sizeof warn, "%s", silc_context_warnings(ctx));
    x = get_x(NULL, NULL);
    for (i = 0; i < 6; i++) want[i] = x1[i] * f;
    info = tl_info(ctx, &cap, "x");
    be = tl_field(info, "backward error");
    est = tl_field(info, "condition estimate");
    CHECK(tl_rel_diff(x, want, 6) < 1e-10, "scale %g (%s), %s: x differs by %.3g", sc, what, label(B),
          tl_rel_diff(x, want, 6));
    CHECK(be == be && be < 1e-12, "scale %g (%s), %s: backward error %.3g", sc, what, label(B), be);
    if (!B->iterative && strcmp(B->name, "suitesparse.spqr") != 0)
        CHECK(est == est && est > 1 && est < 100, "scale %g (%s), %s: condition estimate %.3g", sc, what,
              label(B), est);
    CHECK(warn[0] == '\0', "scale %g (%s), %s: warning '%s'", sc, what, label(B), warn);
    free(x);
}

static void test_scaling(void)
{
    static const double scales[] = {1e-300, 1e-150, 1e150, 1e300};
    /* CG's inner products (r, r) and (p, A p) are the first to underflow. */
    static const backend lis_cg = {"lis-style", 1, 1,
                                   "; lis-style.options = -i cg -p none -tol 1e-12 -maxiter 200"};
    double M[36], Ms[36], b[6], bs[6], x1[6];
    int spd, s, i, n = 6;
    size_t k;
    for (spd = 0; spd <= 1; spd++) {
        test_matrix(M, spd);
        for (i = 0; i < n; i++) b[i] = 1.0 + i;
        for (k = 0; k <= NB; k++) {
            const backend *B = k < NB ? &backends[k] : &lis_cg;
            if (k == NB && !spd) continue;
            double *x;
            int rc;
            put_matrix("A", n, n, M, B->sparse, 0);
            tl_put_vector(ctx, "b", n, b);
            if ((rc = run(B, NULL)) == RUN_SKIP) continue;
            CHECK(rc == RUN_OK, "scaling base, %s: %s", label(B), silc_context_errmsg(ctx));
            if (rc != RUN_OK) continue;
            x = get_x(NULL, NULL);
            memcpy(x1, x, sizeof x1);
            free(x);
            for (s = 0; s < 4; s++) {
                double sc = scales[s];
                for (i = 0; i < n * n; i++) Ms[i] = M[i] * sc;
                for (i = 0; i < n; i++) bs[i] = b[i] * sc;
                /* A and b scaled together: x unchanged. */
                put_matrix("A", n, n, Ms, B->sparse, 0);
                tl_put_vector(ctx, "b", n, bs);
                check_scaled(B, sc, "A and b", x1, 1.0);
                /* b alone scaled: x scales by the same factor. */
                put_matrix("A", n, n, M, B->sparse, 0);
                check_scaled(B, sc, "b", x1, sc);
            }
        }
    }
}

/* ---- NaN and Inf ----------------------------------------------------------------- */

static void test_nonfinite(void)
{
    double M[36], b[6];
    int i;
    size_t k;
    test_matrix(M, 0);
    for (i = 0; i < 6; i++) b[i] = 1;
    M[2 + 3 * 6] = NAN; /* (3, 4) */
    for (k = 0; k < NB; k++) {
        const backend *B = &backends[k];
        put_matrix("A", 6, 6, M, B->sparse, 0);
        tl_put_vector(ctx, "b", 6, b);
        CHECK(silc_exec(ctx, "x = A \\ b") != 0 &&
                  strstr(silc_context_errmsg(ctx), "'A' has NaN at (3, 4)"),
              "A \\ b with NaN (%s): '%s'", label(B), silc_context_errmsg(ctx));
        CHECK(run(B, NULL) == RUN_ERR && strstr(silc_context_errmsg(ctx), "matrix has NaN at (3, 4)"),
              "solve with NaN, %s: '%s'", label(B), silc_context_errmsg(ctx));
    }
    test_matrix(M, 0);
    M[5 + 0 * 6] = -INFINITY; /* (6, 1) */
    put_matrix("A", 6, 6, M, 1, 0);
    CHECK(silc_exec(ctx, "x = A \\ b") != 0 && strstr(silc_context_errmsg(ctx), "'A' has -Inf at (6, 1)"),
          "-Inf: '%s'", silc_context_errmsg(ctx));
    test_matrix(M, 0);
    put_matrix("A", 6, 6, M, 0, 0);
    b[1] = INFINITY;
    tl_put_vector(ctx, "rhs", 6, b);
    CHECK(silc_exec(ctx, "x = A \\ rhs") != 0 && strstr(silc_context_errmsg(ctx), "'rhs' has Inf at (2, 1)"),
          "Inf in b: '%s'", silc_context_errmsg(ctx));
    CHECK(silc_exec(ctx, "x = solve(A, rhs)") != 0 &&
              strstr(silc_context_errmsg(ctx), "right-hand side has Inf at (2, 1)"),
          "Inf in b via solve(): '%s'", silc_context_errmsg(ctx));
    /* Nothing was bound by the failing statements. */
    CHECK(silc_exec(ctx, "clear x; y = A \\ rhs") != 0 && silc_exec(ctx, "z = x") != 0,
          "a failed solve bound x");
    /* The scans work four entries at a time: a NaN or Inf in the leftover
     * tail (n = 7) and in the last full group is found too. */
    {
        double v[7] = {1, 2, 3, 4, 5, 6, 7};
        const int at[] = {7, 4};
        for (i = 0; i < 2; i++) {
            v[at[i] - 1] = i ? -INFINITY : NAN;
            tl_put_vector(ctx, "rhs7", 7, v);
            v[at[i] - 1] = 1;
            CHECK(silc_exec(ctx, "x = eye(7) \\ rhs7") != 0 &&
                      strstr(silc_context_errmsg(ctx), i ? "'rhs7' has -Inf at (4, 1)"
                                                         : "'rhs7' has NaN at (7, 1)"),
                  "non-finite entry %d of 7: '%s'", at[i], silc_context_errmsg(ctx));
        }
    }
    /* A solution beyond the largest double: the scaled solve represents it,
     * the caller's cannot; Inf is returned with a warning, never silently. */
    CHECK(silc_exec(ctx, "x = (1e-300 * eye(3)) \\ (1e300 * ones(3, 1))") == 0 &&
              strstr(silc_context_warnings(ctx), "beyond the largest double (returned as Inf)"),
          "overflowing solution: '%s' / warnings '%s'", silc_context_errmsg(ctx),
          silc_context_warnings(ctx));
    CHECK(silc_exec(ctx, "x = (1e-150 * eye(3)) \\ (1e150 * ones(3, 1))") == 0 &&
              !strstr(silc_context_warnings(ctx), "largest double"),
          "1e300 is representable: '%s'", silc_context_warnings(ctx));
}

/* ---- singular ------------------------------------------------------------------ */

/* Solves A x = b with every backend; each must fail saying singular, or
 * return with a singular / accuracy warning. */
static void expect_singular(const char *what, int64_t n, const double *A, const double *b,
                            int keep_zeros)
{
    size_t k;
    for (k = 0; k < NB; k++) {
        const backend *B = &backends[k];
        int rc;
        put_matrix("A", n, n, A, B->sparse, keep_zeros);
        tl_put_vector(ctx, "b", n, b);
        rc = run(B, NULL);
        if (rc == RUN_SKIP) continue;
        if (rc == RUN_ERR) {
            const char *e = silc_context_errmsg(ctx);
            if (B->iterative) /* an ILU may stop first, with its own reason */
                CHECK(e[0] != '\0', "%s, %s: iterative failure without a message", what, label(B));
            else
                CHECK(singular_text(e), "%s, %s: error does not say singular: %s", what, label(B), e);
        } else {
            const char *w = silc_context_warnings(ctx);
            CHECK(singular_text(w) || B->iterative, "%s, %s: solved without a warning", what, label(B));
        }
    }
}

static void test_singular(void)
{
    double S[4] = {1, 2, 2, 4}, bs[2] = {1, 3}, Z[9] = {0}, b3[3] = {1, 1, 1};
    double R[9] = {2, 0, 1, 1, 0, 3, 1, 0, 2}; /* row 2 is zero */
    double C[9] = {2, 1, 1, 0, 0, 0, 1, 3, 2}; /* column 2 is zero */
    expect_singular("[1 2; 2 4]", 2, S, bs, 0);
    expect_singular("zero row", 3, R, b3, 0);
    expect_singular("zero column", 3, C, b3, 0);
    expect_singular("all-zero", 3, Z, b3, 0);
    expect_singular("all-zero with explicit zeros", 3, Z, b3, 1);
    {
        char err[256];
        int64_t n = 0;
        double *b;
        size_t k;
        if (tl_put_shared(ctx, "A", "neumann.mtx", &n, NULL, err, sizeof err) == 0) {
            b = malloc((size_t)n * sizeof *b);
            tl_fill(b, n, 7);
            tl_put_vector(ctx, "b", n, b);
            for (k = 0; k < NB; k++) {
                const backend *B = &backends[k];
                int rc;
                if (!B->sparse) continue;
                rc = run(B, NULL);
                if (rc == RUN_SKIP) continue;
                if (rc == RUN_ERR)
                    CHECK(singular_text(silc_context_errmsg(ctx)) || tl_contains(silc_context_errmsg(ctx), "iteration"),
                          "neumann, %s: %s", label(B), silc_context_errmsg(ctx));
                else
                    CHECK(singular_text(silc_context_warnings(ctx)) || B->iterative,
                          "neumann, %s: no singular warning", label(B));
            }
            free(b);
        } else {
            CHECK(0, "neumann.mtx: %s", err);
        }
    }
}

/* ---- tiny and odd storage ------------------------------------------------------------ */

static void test_tiny(void)
{
    size_t k;
    for (k = 0; k < NB; k++) {
        const backend *B = &backends[k];
        double one = 4, two = 2, zero = 0, *x;
        int64_t m = -1, n = -1;
        int rc;
        /* 0x0 \ 0x1 = 0x1, as MATLAB. */
        put_matrix("A", 0, 0, NULL, B->sparse, 0);
        put_matrix("b", 0, 1, NULL, 0, 0);
        rc = run(B, NULL);
        if (rc != RUN_SKIP) {
            CHECK(rc == RUN_OK, "0x0, %s: %s", label(B), silc_context_errmsg(ctx));
            x = get_x(&m, &n);
            CHECK(rc != RUN_OK || (m == 0 && n == 1), "0x0, %s: result %lldx%lld", label(B),
                  (long long)m, (long long)n);
            free(x);
        }
        put_matrix("A", 1, 1, &one, B->sparse, 0);
        put_matrix("b", 1, 1, &two, 0, 0);
        rc = run(B, NULL);
        if (rc != RUN_SKIP) {
            CHECK(rc == RUN_OK, "1x1, %s: %s", label(B), silc_context_errmsg(ctx));
            if (rc == RUN_OK) {
                x = get_x(&m, &n);
                CHECK(m == 1 && n == 1 && fabs(x[0] - 0.5) < 1e-15, "1x1, %s: x = %g", label(B), x[0]);
                free(x);
            }
        }
        put_matrix("A", 1, 1, &zero, B->sparse, 1);
        rc = run(B, NULL);
        if (rc == RUN_ERR)
            CHECK(singular_text(silc_context_errmsg(ctx)) || B->iterative, "1x1 zero, %s: %s",
                  label(B), silc_context_errmsg(ctx));
        else if (rc == RUN_OK)
            CHECK(singular_text(silc_context_warnings(ctx)) || B->iterative,
                  "1x1 zero, %s: no warning", label(B));
    }
}

static void test_storage(void)
{
    double M[36], b[6], xw[6], *x, D[36];
    int i;
    size_t k;
    test_matrix(M, 0);
    for (i = 0; i < 6; i++) xw[i] = 1.0 + 0.25 * i;
    for (i = 0; i < 6; i++) {
        int j;
        b[i] = 0;
        for (j = 0; j < 6; j++) b[i] += M[i + j * 6] * xw[j];
    }
    /* Subnormal entries: off the diagonal they change nothing visible. */
    memcpy(D, M, sizeof D);
    D[4 + 0 * 6] = 1e-310;
    D[0 + 5 * 6] = -3e-320;
    for (k = 0; k < NB; k++) {
        const backend *B = &backends[k];
        int rc;
        /* Explicit zeros in every position of the pattern. */
        put_matrix("A", 6, 6, M, B->sparse, 1);
        tl_put_vector(ctx, "b", 6, b);
        rc = run(B, NULL);
        if (rc == RUN_SKIP) continue;
        CHECK(rc == RUN_OK, "explicit zeros, %s: %s", label(B), silc_context_errmsg(ctx));
        if (rc == RUN_OK) {
            x = get_x(NULL, NULL);
            CHECK(tl_rel_diff(x, xw, 6) < 1e-10, "explicit zeros, %s: error %.3g", label(B),
                  tl_rel_diff(x, xw, 6));
            free(x);
        }
        put_matrix("A", 6, 6, D, B->sparse, 0);
        rc = run(B, NULL);
        CHECK(rc == RUN_OK, "subnormal entries, %s: %s", label(B), silc_context_errmsg(ctx));
        if (rc == RUN_OK) {
            x = get_x(NULL, NULL);
            CHECK(tl_rel_diff(x, xw, 6) < 1e-10, "subnormal entries, %s: error %.3g", label(B),
                  tl_rel_diff(x, xw, 6));
            free(x);
        }
    }
}

/* ---- iterative breakdown and stagnation ------------------------------------------- */

static void test_iterative(void)
{
    enum { N = 40 };
    static double A[N * N], b[N];
    static const struct {
        const char *backend;
        const char *opts;
        int indefinite;
    } cases[] = {
        {"lis-style", "; lis-style.options = -i cg -p none -tol 1e-12 -maxiter 200", 1},
        {"lis-style", "; lis-style.options = -i bicgstab -p none -tol 1e-14 -maxiter 30", 0},
        {"lis-style", "; lis-style.options = -i jacobi -tol 1e-12 -maxiter 100", 0},
        {"petsc", "; petsc.options = -ksp_type cg -pc_type none -ksp_rtol 1e-12 -ksp_max_it 200", 1},
        {"petsc", "; petsc.options = -ksp_type gmres -pc_type none -ksp_rtol 1e-14 -ksp_max_it 30", 0},
    };
    size_t c;
    int i, j;
    for (c = 0; c < sizeof cases / sizeof cases[0]; c++) {
        backend B = {cases[c].backend, 1, 1, cases[c].opts};
        int rc;
        memset(A, 0, sizeof A);
        for (i = 0; i < N; i++) {
            if (cases[c].indefinite) {
                /* Symmetric, eigenvalues of both signs: CG's A-norm is no norm. */
                A[i + i * N] = (i % 2 ? -1.0 : 1.0) * (1.0 + i);
                if (i + 1 < N) A[i + (i + 1) * N] = A[(i + 1) + i * N] = 0.5;
            } else {
                /* Far from normal: a strong superdiagonal and a weak subdiagonal. */
                A[i + i * N] = 1.0;
                if (i + 1 < N) A[i + (i + 1) * N] = 20.0, A[(i + 1) + i * N] = 1e-3;
            }
            b[i] = 1.0;
        }
        (void)j;
        put_matrix("A", N, N, A, 1, 0);
        tl_put_vector(ctx, "b", N, b);
        rc = run(&B, NULL);
        if (rc == RUN_SKIP) continue;
        if (rc == RUN_ERR) {
            const char *e = silc_context_errmsg(ctx);
            CHECK(tl_contains(e, "iteration") && tl_contains(e, "residual"),
                  "%s%s: failure without iteration and residual: %s", B.name, B.opts, e);
        } else {
            /* Converged after all: then the result must be right. */
            const char *info = tl_info(ctx, &cap, "x");
            CHECK(tl_field(info, "backward error") < 1e-10, "%s%s: 'converged' with backward error %.3g",
                  B.name, B.opts, tl_field(info, "backward error"));
        }
    }
}

/* ---- least squares --------------------------------------------------------------- */

/* Solves the small SPD system G y = r in place (Cholesky-free Gauss, no pivoting). */
static void gauss(int n, double *G, double *r)
{
    int i, j, k;
    for (k = 0; k < n; k++)
        for (i = k + 1; i < n; i++) {
            double f = G[i + k * n] / G[k + k * n];
            for (j = k; j < n; j++) G[i + j * n] -= f * G[k + j * n];
            r[i] -= f * r[k];
        }
    for (i = n - 1; i >= 0; i--) {
        for (j = i + 1; j < n; j++) r[i] -= G[i + j * n] * r[j];
        r[i] /= G[i + i * n];
    }
}

static void test_least_squares(void)
{
    enum { M = 7, N = 3 };
    double A[M * N], b[M], G[N * N], y[N], At[N * M], H[M * M], z[M];
    int i, j, l;
    size_t k;
    for (i = 0; i < M; i++) {
        A[i + 0 * M] = 1;
        A[i + 1 * M] = i;
        A[i + 2 * M] = (double)i * i / 4.0;
        b[i] = 1.0 + 0.3 * i - 0.1 * ((i * 7) % 3);
    }
    /* Full rank: the normal equations give the answer. */
    for (i = 0; i < N; i++) {
        y[i] = 0;
        for (l = 0; l < M; l++) y[i] += A[l + i * M] * b[l];
        for (j = 0; j < N; j++) {
            G[i + j * N] = 0;
            for (l = 0; l < M; l++) G[i + j * N] += A[l + i * M] * A[l + j * M];
        }
    }
    gauss(N, G, y);
    for (k = 0; k < NB; k++) {
        const backend *B = &backends[k];
        double *x;
        int rc;
        put_matrix("A", M, N, A, B->sparse, 0);
        tl_put_vector(ctx, "b", M, b);
        rc = run(B, NULL);
        if (rc == RUN_SKIP) continue;
        CHECK(rc == RUN_OK, "least squares, %s: %s", label(B), silc_context_errmsg(ctx));
        if (rc != RUN_OK) continue;
        x = get_x(NULL, NULL);
        CHECK(tl_rel_diff(x, y, N) < 1e-9, "least squares, %s: differs by %.3g", label(B),
              tl_rel_diff(x, y, N));
        free(x);
    }
    /* Rank deficient: column 3 = column 1 + column 2.  Any solution of the
     * normal equations is right; the rank must be reported. */
    for (i = 0; i < M; i++) A[i + 2 * M] = A[i] + A[i + M];
    for (k = 0; k < NB; k++) {
        const backend *B = &backends[k];
        const char *info;
        int rc;
        put_matrix("A", M, N, A, B->sparse, 0);
        rc = run(B, NULL);
        if (rc == RUN_SKIP) continue;
        CHECK(rc == RUN_OK, "rank deficient, %s: %s", label(B), silc_context_errmsg(ctx));
        if (rc != RUN_OK) continue;
        info = tl_info(ctx, &cap, "x");
        CHECK(tl_field(info, "backward error") < 1e-12, "rank deficient, %s: backward error %.3g",
              label(B), tl_field(info, "backward error"));
        CHECK(tl_contains(info, "rank 2"), "rank deficient, %s: rank not reported: %s", label(B), info);
    }
    /* Underdetermined (3x7, full row rank): every backend gives the
     * minimum-norm solution A' (A A')^-1 b. */
    for (i = 0; i < M; i++)
        for (j = 0; j < N; j++) At[j + i * N] = (double)((i + 1) * (j + 2) % 5) + (i == j ? 3 : 0);
    for (i = 0; i < N; i++) {
        z[i] = 1.0 + i;
        for (j = 0; j < N; j++) {
            H[i + j * N] = 0;
            for (l = 0; l < M; l++) H[i + j * N] += At[i + l * N] * At[j + l * N];
        }
    }
    gauss(N, H, z);
    for (k = 0; k < NB; k++) {
        const backend *B = &backends[k];
        double want[M], *x, rhs[N] = {1, 2, 3};
        int rc;
        for (l = 0; l < M; l++) {
            want[l] = 0;
            for (i = 0; i < N; i++) want[l] += At[i + l * N] * z[i];
        }
        put_matrix("A", N, M, At, B->sparse, 0);
        tl_put_vector(ctx, "b", N, rhs);
        rc = run(B, NULL);
        if (rc == RUN_SKIP) continue;
        CHECK(rc == RUN_OK, "underdetermined, %s: %s", label(B), silc_context_errmsg(ctx));
        if (rc != RUN_OK) continue;
        x = get_x(NULL, NULL);
        CHECK(tl_rel_diff(x, want, M) < 1e-10, "underdetermined, %s: not minimum norm (%.3g)",
              label(B), tl_rel_diff(x, want, M));
        CHECK(tl_field(tl_info(ctx, &cap, "x"), "backward error") < 1e-12,
              "underdetermined, %s: backward error too large", label(B));
        free(x);
    }
}

/* ---- the knobs ------------------------------------------------------------------- */

/* Refinement with a double-double residual recovers digits double cannot:
 * on Hilbert 10 (cond 3.5e13) the forward error drops well below cond eps. */
static void test_refinement(void)
{
    int n = 10;
    double H[100], b[10], *first = NULL;
    int64_t i, j;
    size_t k;
    for (i = 0; i < n; i++) b[i] = 0;
    for (j = 0; j < n; j++)
        for (i = 0; i < n; i++) H[i + j * n] = 1.0 / (double)(i + j + 1), b[i] += H[i + j * n];
    CHECK(silc_exec(ctx, "set refine = 3") == 0 && silc_exec(ctx, "set solve.refine = 0") == 0 &&
              silc_exec(ctx, "set solve.refine_residual = quad") != 0 &&
              tl_contains(silc_context_errmsg(ctx), "'double' or 'extended'") &&
              silc_exec(ctx, "set solve.refin = 1") != 0 &&
              tl_contains(silc_context_errmsg(ctx), "did you mean 'solve.refine'"),
          "solve.* keys: %s", silc_context_errmsg(ctx));
    tl_put_vector(ctx, "b", n, b);
    for (k = 0; k < NB; k++) {
        const backend *B = &backends[k];
        double *x;
        const char *info;
        int rc;
        if (B->iterative) continue;
        put_matrix("A", n, n, H, B->sparse, 0);
        rc = run(B, "; refine = 8; refine_residual = extended");
        if (rc == RUN_SKIP) continue;
        CHECK(rc == RUN_OK, "refine extended, %s: %s", label(B), silc_context_errmsg(ctx));
        if (rc != RUN_OK) continue;
        x = get_x(NULL, NULL);
        info = tl_info(ctx, &cap, "x");
        CHECK(tl_contains(info, "refinement:") && tl_contains(info, "double-double residual"),
              "refine, %s: info lacks the refinement lines: %s", label(B), info);
        /* Unrefined, the backends differ by ~cond eps = 8e-3 relative; the
         * double-double residual takes each to the solution of the stored
         * system, to a few eps. */
        if (!first) first = x;
        else {
            CHECK(tl_rel_diff(x, first, n) < 1e-12, "refine extended, %s differs from %s by %.3g",
                  label(B), label(&backends[0]), tl_rel_diff(x, first, n));
            free(x);
        }
        /* Double refinement of a backward-stable solve stops at once. */
        rc = run(B, "; refine = 4");
        info = tl_info(ctx, &cap, "x");
        CHECK(rc == RUN_OK && tl_contains(info, "refinement: 0 steps"),
              "refine double, %s: expected 0 steps: %s", label(B), info);
    }
    free(first);
}

/* lapack.precision = mixed: dsgesv / dsposv, with LAPACK's own fallback to
 * double when single precision cannot serve (out of range, too ill-conditioned). */
static void test_mixed(void)
{
    enum { N = 60 };
    static double A[N * N], As[N * N], b[N], bs[N];
    static const char *const cases[] = {"general", "spd", "scaled 1e300", "hilbert"};
    const backend lapack = {"lapack", 0, 0, ""};
    int c, i, j;
    for (c = 0; c < 4; c++) {
        /* The core scales the 1e300 system by 2^-997 before lapack sees it
         * (scale.c), so single precision serves it too; only Hilbert's
         * conditioning makes dsgesv fall back. */
        const char *info, *want = c == 3 ? "fell back to double precision" : "factored in single precision";
        double tol = c == 3 ? 1e-3 : 1e-12, ref[N], *x, est, est_double;
        int n = c == 3 ? 8 : N, rc;
        for (j = 0; j < n; j++)
            for (i = 0; i < n; i++)
                A[i + j * n] = c == 3 ? 1.0 / (i + j + 1)
                                      : (i == j ? 4.0 : 0.0) + (c == 0 ? 0.02 * ((i * 7 + j * 3) % 11) - 0.1
                                                                       : 0.01 / (1 + abs(i - j)));
        for (i = 0; i < n; i++) b[i] = 1.0 + (i % 5);
        for (i = 0; i < n * n; i++) As[i] = c == 2 ? A[i] * 1e300 : A[i];
        for (i = 0; i < n; i++) bs[i] = c == 2 ? b[i] * 1e300 : b[i];
        put_matrix("A", n, n, A, 0, 0);
        tl_put_vector(ctx, "b", n, b);
        if (run(&lapack, NULL) != RUN_OK) return; /* lapack not built */
        x = get_x(NULL, NULL);
        memcpy(ref, x, (size_t)n * sizeof *x);
        free(x);
        est_double = tl_field(tl_info(ctx, &cap, "x"), "condition estimate");
        put_matrix("A", n, n, As, 0, 0);
        tl_put_vector(ctx, "b", n, bs);
        rc = run(&lapack, "; lapack.precision = mixed");
        CHECK(rc == RUN_OK, "mixed %s: %s", cases[c], silc_context_errmsg(ctx));
        if (rc != RUN_OK) continue;
        x = get_x(NULL, NULL);
        info = tl_info(ctx, &cap, "x");
        CHECK(tl_contains(info, want) && tl_contains(info, "ITER="), "mixed %s: info says %s", cases[c], info);
        CHECK(tl_rel_diff(x, ref, n) < tol, "mixed %s: differs from double by %.3g", cases[c],
              tl_rel_diff(x, ref, n));
        if (c < 3)
            CHECK(tl_field(info, "backward error") < 1e-15, "mixed %s: backward error %.3g", cases[c],
                  tl_field(info, "backward error"));
        /* An estimate from the single factors (or the fallback's double ones)
         * agrees with the double path's to the accuracy an estimate has. */
        est = tl_field(info, "condition estimate");
        CHECK(est > est_double / 3 && est < est_double * 3, "mixed %s: condition estimate %.3g, double %.3g",
              cases[c], est, est_double);
        free(x);
    }
    CHECK(run(&lapack, "; lapack.precision = half") == RUN_ERR &&
              tl_contains(silc_context_errmsg(ctx), "double or mixed"),
          "lapack.precision = half: %s", silc_context_errmsg(ctx));
}

int main(void)
{
    if (silc_open(&ctx, NULL)) {
        fprintf(stderr, "silc_open: %s\n", silc_errmsg());
        return 1;
    }
    tl_capture_attach(ctx, &cap);
    test_hilbert();
    test_scaling();
    test_nonfinite();
    test_singular();
    test_tiny();
    test_storage();
    test_iterative();
    test_least_squares();
    test_refinement();
    test_mixed();
    silc_close(&ctx);
    tl_capture_free(&cap);
    return check_done();
}
