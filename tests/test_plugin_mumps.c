/*
 * test_plugin_mumps.c -- the "mumps" backend against exact solutions and the reference plugin.
 *
 * Two contexts: one whose sparse solve classes are forced to mumps, one forced
 * to reference.  Checked here, with every number computed by this program:
 *   - 2-D Laplacian (SPD, so MUMPS's SYM=1 LDL'): x close to the exact
 *     solution within eps * cond * 100, cond being the condition estimate
 *     `info` shows; info names mumps, the LDL' method and MUMPS's backward
 *     errors; a second solve with the same A reuses the factorization; several
 *     right-hand sides at once;
 *   - a shifted Laplacian (symmetric, positive diagonal, indefinite): SYM=1
 *     meets negative pivots, the dispatcher falls back to LU (SYM=0), and the
 *     result is still right;
 *   - west0479, sherman1, memplus from ../shared/matrices: mumps and reference
 *     agree within eps * cond * 100 and both have small backward errors;
 *   - options: `set mumps.icntl_7 = 5` is taken, `mumps.icntl_99` is refused
 *     with a suggestion, a layout-fixing ICNTL (icntl_5 = 1) is refused at
 *     solve time with the reason;
 *   - neumann (singular): an error naming dmumps_c and the INFOG meaning, or a
 *     warning that the matrix is singular to working precision;
 *   - plugins loaded together: solves through mumps, reference and whichever
 *     other library plugins are installed interleave in one process.
 */
#include <float.h>
#include <stdlib.h>
#include <string.h>

#include "check.h"
#include "silc.h"

#ifndef SILC_SHARED_MATRICES
#define SILC_SHARED_MATRICES "../shared/matrices"
#endif

static char out_buf[16384];

static void capture(void *user, const char *text)
{
    (void)user;
    strncat(out_buf, text, sizeof out_buf - strlen(out_buf) - 1);
}

/* Runs `info name` and returns its text. */
static const char *info(silc_context *c, const char *name)
{
    char stmt[64];
    out_buf[0] = '\0';
    snprintf(stmt, sizeof stmt, "info %s", name);
    if (silc_exec(c, stmt)) snprintf(out_buf, sizeof out_buf, "info failed: %s", silc_context_errmsg(c));
    return out_buf;
}

/* The "condition estimate: X" of the last info text, -1 if none. */
static double info_cond(const char *text)
{
    const char *p = strstr(text, "condition estimate: ");
    return p ? strtod(p + strlen("condition estimate: "), NULL) : -1;
}

static silc_context *open_forced(const char *backend)
{
    silc_context *c = NULL;
    char stmt[160];
    if (silc_open(&c, NULL)) {
        CHECK(0, "silc_open: %s", c ? silc_context_errmsg(c) : silc_errmsg());
        silc_close(&c);
        return NULL;
    }
    silc_set_output(c, capture, NULL);
    snprintf(stmt, sizeof stmt, "set dispatch.solve.sparse = %s; set dispatch.solve.sparse.spd = %s",
             backend, backend);
    CHECK(silc_exec(c, stmt) == 0, "%s: %s", stmt, silc_context_errmsg(c));
    return c;
}

/* k x k grid, 5-point stencil, diagonal 4 - shift, as CSR. */
static int laplacian(silc_envelope_t *A, int k, double shift)
{
    int64_t n = (int64_t)k * k, nz = 0;
    int64_t *rp = malloc((size_t)(n + 1) * sizeof *rp), *ci = malloc((size_t)(5 * n) * sizeof *ci);
    double *v = malloc((size_t)(5 * n) * sizeof *v);
    int rc = -1;
    if (rp && ci && v) {
        for (int64_t r = 0; r < n; r++) {
            int64_t i = r / k, j = r % k;
            rp[r] = nz;
            if (i > 0) ci[nz] = r - k, v[nz++] = -1;
            if (j > 0) ci[nz] = r - 1, v[nz++] = -1;
            ci[nz] = r, v[nz++] = 4 - shift;
            if (j < k - 1) ci[nz] = r + 1, v[nz++] = -1;
            if (i < k - 1) ci[nz] = r + k, v[nz++] = -1;
        }
        rp[n] = nz;
        rc = silc_envelope_csr(A, n, n, rp, ci, v);
    }
    free(rp);
    free(ci);
    free(v);
    return rc;
}

static void csr_matvec(const silc_envelope_t *A, const double *x, double *y)
{
    for (int64_t i = 0; i < A->m; i++) {
        double s = 0;
        for (int64_t k = A->rowptr[i]; k < A->rowptr[i + 1]; k++) s += A->values[k] * x[A->colind[k]];
        y[i] = s;
    }
}

static double norminf(const double *x, int64_t n)
{
    double s = 0;
    for (int64_t i = 0; i < n; i++)
        if (fabs(x[i]) > s) s = fabs(x[i]);
    return s;
}

/* ||x - y||_inf / ||y||_inf */
static double reldiff(const double *x, const double *y, int64_t n)
{
    double d = 0;
    for (int64_t i = 0; i < n; i++)
        if (fabs(x[i] - y[i]) > d) d = fabs(x[i] - y[i]);
    return d / norminf(y, n);
}

/* ||b - A x||_inf / (||A||_inf ||x||_inf + ||b||_inf), computed here. */
static double backward_error(const silc_envelope_t *A, const double *x, const double *b)
{
    int64_t n = A->m;
    double *r = malloc((size_t)n * sizeof *r), nA = 0;
    if (!r) return INFINITY;
    csr_matvec(A, x, r);
    for (int64_t i = 0; i < n; i++) r[i] -= b[i];
    for (int64_t i = 0; i < n; i++) {
        double s = 0;
        for (int64_t k = A->rowptr[i]; k < A->rowptr[i + 1]; k++) s += fabs(A->values[k]);
        if (s > nA) nA = s;
    }
    double be = norminf(r, n) / (nA * norminf(x, n) + norminf(b, n));
    free(r);
    return be;
}

/* PUTs A and b = A * xs (xs_i = 1 + i/n) into c. */
static int put_system(silc_context *c, const silc_envelope_t *A, double *xs, double *b)
{
    silc_envelope_t eb;
    int64_t n = A->m;
    int rc;
    for (int64_t i = 0; i < n; i++) xs[i] = 1.0 + (double)i / (double)n;
    csr_matvec(A, xs, b);
    if (silc_put(c, "A", A) || silc_envelope_vector(&eb, n, b)) return -1;
    rc = silc_put(c, "b", &eb);
    silc_envelope_free(&eb);
    return rc;
}

/* Fetches the n-vector name into x. */
static int get_vec(silc_context *c, const char *name, double *x, int64_t n)
{
    silc_envelope_t e;
    int rc;
    if (silc_get(c, &e, name)) return -1;
    rc = (e.m == n && e.n == 1) ? silc_envelope_to_dense(&e, x) : -1;
    silc_envelope_free(&e);
    return rc;
}

static void test_laplacian(silc_context *cm)
{
    silc_envelope_t A;
    const int k = 40;
    int64_t n = (int64_t)k * k;
    double *xs = malloc((size_t)n * sizeof *xs), *b = malloc((size_t)n * sizeof *b),
           *x = malloc((size_t)n * sizeof *x), *X = malloc((size_t)(3 * n) * sizeof *X);
    const char *t;
    double cond;
    if (!xs || !b || !x || !X || laplacian(&A, k, 0)) {
        CHECK(0, "laplacian: setup failed");
        goto out;
    }
    CHECK(put_system(cm, &A, xs, b) == 0, "put: %s", silc_context_errmsg(cm));
    CHECK(silc_exec(cm, "x = A \\ b") == 0, "laplacian solve: %s", silc_context_errmsg(cm));
    t = info(cm, "x");
    CHECK(strstr(t, "  backend: mumps\n") != NULL, "laplacian backend:\n%s", t);
    CHECK(strstr(t, "LDL'") && strstr(t, "SYM=1") && strstr(t, "AMF"), "laplacian method:\n%s", t);
    CHECK(strstr(t, "omega1") != NULL, "laplacian error analysis in note:\n%s", t);
    CHECK(strstr(t, "reused factorization: no") != NULL, "first solve factors:\n%s", t);
    cond = info_cond(t);
    /* The 1-norm condition of the 40x40 Laplacian is about 1e3. */
    CHECK(cond > 1e2 && cond < 1e4, "laplacian condition estimate %g", cond);
    CHECK(get_vec(cm, "x", x, n) == 0, "get x: %s", silc_context_errmsg(cm));
    CHECK(reldiff(x, xs, n) <= 100 * DBL_EPSILON * cond, "laplacian forward error %g (cond %g)",
          reldiff(x, xs, n), cond);
    CHECK(backward_error(&A, x, b) < 1e-14, "laplacian backward error %g", backward_error(&A, x, b));

    /* Same A: the factorization is reused, the answer the same. */
    CHECK(silc_exec(cm, "y = A \\ (2 * b)") == 0, "second solve: %s", silc_context_errmsg(cm));
    t = info(cm, "y");
    CHECK(strstr(t, "reused factorization: yes") != NULL, "second solve reuses:\n%s", t);
    CHECK(get_vec(cm, "y", x, n) == 0, "get y");
    for (int64_t i = 0; i < n; i++) x[i] /= 2;
    CHECK(reldiff(x, xs, n) <= 100 * DBL_EPSILON * cond, "reused forward error %g", reldiff(x, xs, n));

    /* Three right-hand sides at once. */
    CHECK(silc_exec(cm, "B = b * ones(1, 3); Z = A \\ B") == 0, "multi-rhs: %s", silc_context_errmsg(cm));
    {
        silc_envelope_t e;
        if (silc_get(cm, &e, "Z") == 0 && e.m == n && e.n == 3 && silc_envelope_to_dense(&e, X) == 0) {
            for (int j = 0; j < 3; j++)
                CHECK(reldiff(X + j * n, xs, n) <= 100 * DBL_EPSILON * cond, "column %d error %g", j,
                      reldiff(X + j * n, xs, n));
        } else {
            CHECK(0, "get Z: %s", silc_context_errmsg(cm));
        }
        silc_envelope_free(&e);
    }
    silc_envelope_free(&A);

    /* Symmetric, positive diagonal, indefinite: SYM=1 fails, LU (SYM=0) answers. */
    if (laplacian(&A, k, 1.0) == 0) {
        CHECK(put_system(cm, &A, xs, b) == 0, "put shifted");
        CHECK(silc_exec(cm, "x = A \\ b") == 0, "shifted solve: %s", silc_context_errmsg(cm));
        t = info(cm, "x");
        CHECK(strstr(t, "  backend: mumps\n") && strstr(t, "SYM=0"), "shifted uses mumps LU:\n%s", t);
        CHECK(strstr(t, "Cholesky failed") != NULL, "shifted notes the fallback:\n%s", t);
        cond = info_cond(t);
        CHECK(get_vec(cm, "x", x, n) == 0, "get shifted x");
        CHECK(cond > 0 && reldiff(x, xs, n) <= 100 * DBL_EPSILON * cond, "shifted forward error %g (cond %g)",
              reldiff(x, xs, n), cond);
        silc_envelope_free(&A);
    } else {
        CHECK(0, "shifted laplacian setup");
    }
out:
    free(xs);
    free(b);
    free(x);
    free(X);
}

/* mumps and reference on a shared matrix: both right, and close to each other. */
static void test_shared(silc_context *cm, silc_context *cr, const char *file)
{
    char path[1024], err[256];
    silc_envelope_t A;
    snprintf(path, sizeof path, "%s/%s", SILC_SHARED_MATRICES, file);
    if (silc_mm_read(&A, path, err, sizeof err)) {
        CHECK(0, "%s: %s", file, err);
        return;
    }
    int64_t n = A.m;
    double *xs = malloc((size_t)n * sizeof *xs), *b = malloc((size_t)n * sizeof *b),
           *xm = malloc((size_t)n * sizeof *xm), *xr = malloc((size_t)n * sizeof *xr);
    if (xs && b && xm && xr && put_system(cm, &A, xs, b) == 0 && put_system(cr, &A, xs, b) == 0) {
        CHECK(silc_exec(cm, "x = A \\ b") == 0, "%s mumps: %s", file, silc_context_errmsg(cm));
        const char *t = info(cm, "x");
        double cond = info_cond(t);
        CHECK(strstr(t, "  backend: mumps\n") != NULL, "%s backend:\n%s", file, t);
        CHECK(cond >= 1, "%s condition estimate %g", file, cond);
        CHECK(silc_exec(cr, "x = A \\ b") == 0, "%s reference: %s", file, silc_context_errmsg(cr));
        if (get_vec(cm, "x", xm, n) == 0 && get_vec(cr, "x", xr, n) == 0) {
            double bound = 100 * DBL_EPSILON * cond, d = reldiff(xm, xr, n);
            CHECK(backward_error(&A, xm, b) < 1e-12, "%s mumps backward error %g", file,
                  backward_error(&A, xm, b));
            CHECK(d <= bound || bound >= 1, "%s: mumps vs reference %g > %g", file, d, bound);
            CHECK(reldiff(xm, xs, n) <= bound || bound >= 1, "%s: mumps vs exact %g > %g", file,
                  reldiff(xm, xs, n), bound);
            printf("%-14s n %6lld  cond %8.2g  |x_mumps - x_ref| %8.2g  |x_mumps - x*| %8.2g\n", file,
                   (long long)n, cond, d, reldiff(xm, xs, n));
        } else {
            CHECK(0, "%s: cannot fetch x", file);
        }
    } else {
        CHECK(0, "%s: setup failed", file);
    }
    free(xs);
    free(b);
    free(xm);
    free(xr);
    silc_envelope_free(&A);
}

static void test_options(silc_context *cm)
{
    const char *e;
    CHECK(silc_exec(cm, "set mumps.icntl_7 = 5") == 0, "icntl_7 = 5: %s", silc_context_errmsg(cm));
    CHECK(silc_exec(cm, "x = A \\ b") == 0, "solve with icntl_7 = 5: %s", silc_context_errmsg(cm));
    CHECK(strstr(info(cm, "x"), "reused factorization: no") != NULL,
          "changed options refactor:\n%s", out_buf);
    CHECK(silc_exec(cm, "set mumps.icntl_7 = 2") == 0, "icntl_7 back to 2");
    CHECK(silc_exec(cm, "set mumps.icntl_99 = 1") != 0, "icntl_99 must be refused");
    e = silc_context_errmsg(cm);
    CHECK(strstr(e, "icntl_99") && strstr(e, "did you mean"), "icntl_99 message: %s", e);
    CHECK(silc_exec(cm, "set mumps.cntl_1 = 0.05") == 0, "cntl_1: %s", silc_context_errmsg(cm));
    CHECK(silc_exec(cm, "set mumps.cntl_1 = abc") != 0, "cntl_1 = abc must be refused");
    CHECK(silc_exec(cm, "x = solve(A, b, \"mumps.icntl_5 = 1\")") != 0, "icntl_5 = 1 must be refused");
    e = silc_context_errmsg(cm);
    CHECK(strstr(e, "icntl_5") && strstr(e, "assembled"), "icntl_5 message: %s", e);
    CHECK(silc_exec(cm, "x = solve(A, b, \"mumps.icntl_11 = 1\")") == 0, "icntl_11 = 1: %s",
          silc_context_errmsg(cm));
    CHECK(strstr(info(cm, "x"), "cond1") != NULL, "full error analysis shows cond1:\n%s", out_buf);
}

/* Fails with a message naming dmumps_c and the INFOG meaning, or warns. */
static void check_singular(silc_context *cm, const char *what)
{
    int rc = silc_exec(cm, "s = 1; s = N \\ c");
    const char *e = rc ? silc_context_errmsg(cm) : "", *w = silc_context_warnings(cm);
    CHECK(rc ? strstr(e, "dmumps_c") && strstr(e, "singular") && strstr(e, "INFOG(1)=")
             : strstr(w, "singular to working precision") != NULL,
          "%s: error '%s', warnings '%s'", what, e, w);
    printf("%s: %s '%s'\n", what, rc ? "error" : "warning", rc ? e : w);
}

static void test_singular(silc_context *cm)
{
    char path[1024], err[256];
    silc_envelope_t A, eb;
    snprintf(path, sizeof path, "%s/neumann.mtx", SILC_SHARED_MATRICES);
    if (silc_mm_read(&A, path, err, sizeof err)) {
        CHECK(0, "neumann: %s", err);
        return;
    }
    double *b = malloc((size_t)A.m * sizeof *b);
    for (int64_t i = 0; b && i < A.m; i++) b[i] = (double)(i % 7) - 3;
    if (b && silc_put(cm, "N", &A) == 0 && silc_envelope_vector(&eb, A.m, b) == 0) {
        silc_put(cm, "c", &eb);
        silc_envelope_free(&eb);
        check_singular(cm, "neumann");
    } else {
        CHECK(0, "neumann setup");
    }
    free(b);
    silc_envelope_free(&A);

    /* Exactly singular: a Laplacian whose last two unknowns are cut off into
     * the block [1 1; 1 1].  Symmetric with a positive diagonal, so SYM=1 runs
     * first, meets the zero pivot and hands over to LU, which meets it too. */
    {
        const int k = 20;
        int64_t n = (int64_t)k * k, nz = 0;
        int64_t *rp = malloc((size_t)(n + 1) * sizeof *rp), *ci = malloc((size_t)(5 * n) * sizeof *ci);
        double *v = malloc((size_t)(5 * n) * sizeof *v), *c = calloc((size_t)n, sizeof *c);
        if (rp && ci && v && c) {
            for (int64_t r = 0; r < n; r++) {
                int64_t i = r / k, j = r % k, cols[5], m = 0;
                rp[r] = nz;
                c[r] = 1;
                if (r >= n - 2) {
                    ci[nz] = n - 2, v[nz++] = 1;
                    ci[nz] = n - 1, v[nz++] = 1;
                    continue;
                }
                if (i > 0) cols[m++] = r - k;
                if (j > 0) cols[m++] = r - 1;
                cols[m++] = r;
                if (j < k - 1) cols[m++] = r + 1;
                if (i < k - 1) cols[m++] = r + k;
                for (int64_t q = 0; q < m; q++)
                    if (cols[q] < n - 2) ci[nz] = cols[q], v[nz++] = cols[q] == r ? 4 : -1;
            }
            rp[n] = nz;
            if (silc_envelope_csr(&A, n, n, rp, ci, v) == 0 && silc_put(cm, "N", &A) == 0 &&
                silc_envelope_vector(&eb, n, c) == 0) {
                silc_put(cm, "c", &eb);
                silc_envelope_free(&eb);
                check_singular(cm, "singular block");
            } else {
                CHECK(0, "singular block setup");
            }
            silc_envelope_free(&A);
        }
        free(rp);
        free(ci);
        free(v);
        free(c);
    }
}

/* All plugins of the build are loaded in this process (in directory-scan
 * order); solves through each of them interleave without interference. */
static void test_together(silc_context *cm)
{
    static const char *others[] = {"reference", "suitesparse.umfpack", "lapack", "mumps"};
    char stmt[128];
    for (int round = 0; round < 2; round++)
        for (size_t i = 0; i < sizeof others / sizeof others[0]; i++) {
            snprintf(stmt, sizeof stmt, "x = solve(A, b, \"backend = %s\"); r = norm(b - A * x) / norm(b)",
                     others[i]);
            if (silc_exec(cm, stmt)) {
                const char *e = silc_context_errmsg(cm);
                /* Plugins not built here, or not taking a sparse solve, are fine. */
                CHECK(i != 0 && i != 3, "%s: %s", others[i], e);
                continue;
            }
            silc_envelope_t r;
            double rv = 1;
            if (silc_get(cm, &r, "r") == 0) silc_envelope_to_dense(&r, &rv);
            silc_envelope_free(&r);
            CHECK(rv < 1e-10, "together: %s residual %g", others[i], rv);
        }
}

int main(void)
{
    silc_context *cm = open_forced("mumps"), *cr = open_forced("reference");
    if (cm && cr) {
        test_laplacian(cm);
        test_shared(cm, cr, "west0479.mtx");
        test_shared(cm, cr, "sherman1.mtx");
        test_shared(cm, cr, "memplus.mtx");
        test_options(cm);
        test_together(cm);
        test_singular(cm);
    }
    silc_close(&cm);
    silc_close(&cr);
    return check_done();
}
