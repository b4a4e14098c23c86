/*
 * test_matrices.c -- every matrix of ../shared/matrices read and solved, or refused.
 *
 * For each file of SILC_SHARED_MATRICES/index.tsv: complex files must read as
 * complex CSR of the index's shape (their values: test_complex_core).  Real ones are read, checked
 * against the index (shape; symmetric files expanded to both triangles), PUT as
 * A with b = A * ones computed here from the CSR arrays, and solved with
 * `x = A \ b`.  What counts as right depends on the class column:
 *   spd, sym-*, unsym   normwise backward error ||b - A x||_inf /
 *                       (||A||_inf ||x||_inf + ||b||_inf) < 1e-10, computed here;
 *                       for the well-conditioned ones (cond < 1e8, from the
 *                       README's verified numerics) also ||x - 1||_inf <=
 *                       1e-11 * max(cond, 10): generous, it catches wrong answers,
 *                       not lost digits;
 *   singular,           the solve fails with a message containing "singular", or
 *   near-singular       succeeds with a warning "singular to working precision" or
 *                       "fewer than 4 correct digits" -- never a silent answer;
 *   rect, tall          least squares: ||A'(b - A x)||_2 <= 1e-10 ||A||_F^2 ||x||_2,
 *                       and since b is consistent, x ~ ones as above;
 *   rect, wide          any solution (minimum-norm or basic): backward error of
 *                       A x = b below 1e-8.
 * Every number the verdict rests on is computed here, not taken from SILC's own
 * accuracy report.
 */
#include <ctype.h>
#include <stdlib.h>
#include <string.h>

#include "check.h"
#include "silc.h"
#include "testlib.h"

#ifndef SILC_SHARED_MATRICES
#define SILC_SHARED_MATRICES "../shared/matrices"
#endif

/* 2-norm condition numbers below 1e8 from the README's "verified numerics"
 * (memplus: its 1-norm estimate).  Matrices not listed get no forward-error check. */
static const struct {
    const char *file;
    double cond;
} well_conditioned[] = {
    {"bcsstk01.mtx", 8.8e5}, {"bcsstk02.mtx", 4.3e3}, {"494_bus.mtx", 2.4e6},
    {"gr_30_30.mtx", 195},   {"1138_bus.mtx", 8.6e6}, {"sherman1.mtx", 1.6e4},
    {"west0067.mtx", 1.3e2}, {"olm1000.mtx", 1.5e6},  {"orsirr_1.mtx", 7.7e4},
    {"memplus.mtx", 2.7e5},  {"illc1033.mtx", 1.9e4}, {"ash219.mtx", 3.0},
};

static double known_cond(const char *file)
{
    for (size_t i = 0; i < sizeof well_conditioned / sizeof well_conditioned[0]; i++)
        if (strcmp(file, well_conditioned[i].file) == 0)
            return well_conditioned[i].cond;
    return -1;
}

/* Case-insensitive substring test. */
static int contains(const char *hay, const char *needle)
{
    size_t n = strlen(needle);
    for (; hay && *hay; hay++) {
        size_t i = 0;
        while (i < n && hay[i] && tolower((unsigned char)hay[i]) == tolower((unsigned char)needle[i]))
            i++;
        if (i == n)
            return 1;
    }
    return 0;
}

/* y = A x for a CSR envelope. */
static void csr_matvec(const silc_envelope_t *A, const double *x, double *y)
{
    for (int64_t i = 0; i < A->m; i++) {
        double s = 0;
        for (int64_t k = A->rowptr[i]; k < A->rowptr[i + 1]; k++)
            s += A->values[k] * x[A->colind[k]];
        y[i] = s;
    }
}

/* y = A' x for a CSR envelope. */
static void csr_tmatvec(const silc_envelope_t *A, const double *x, double *y)
{
    memset(y, 0, sizeof *y * (size_t)A->n);
    for (int64_t i = 0; i < A->m; i++)
        for (int64_t k = A->rowptr[i]; k < A->rowptr[i + 1]; k++)
            y[A->colind[k]] += A->values[k] * x[i];
}

static double csr_norminf(const silc_envelope_t *A)
{
    double best = 0;
    for (int64_t i = 0; i < A->m; i++) {
        double s = 0;
        for (int64_t k = A->rowptr[i]; k < A->rowptr[i + 1]; k++)
            s += fabs(A->values[k]);
        if (s > best)
            best = s;
    }
    return best;
}

static double csr_normfro2(const silc_envelope_t *A)
{
    double s = 0;
    for (int64_t k = 0; k < A->rowptr[A->m]; k++)
        s += A->values[k] * A->values[k];
    return s;
}

/* A(i, j) by binary search of the sorted row i; 0 if not stored. */
static double csr_at(const silc_envelope_t *A, int64_t i, int64_t j)
{
    int64_t lo = A->rowptr[i], hi = A->rowptr[i + 1];
    while (lo < hi) {
        int64_t mid = lo + (hi - lo) / 2;
        if (A->colind[mid] < j)
            lo = mid + 1;
        else
            hi = mid;
    }
    return lo < A->rowptr[i + 1] && A->colind[lo] == j ? A->values[lo] : 0;
}

/* A file declared symmetric must come back with both triangles stored. */
static int csr_is_symmetric(const silc_envelope_t *A)
{
    for (int64_t i = 0; i < A->m; i++)
        for (int64_t k = A->rowptr[i]; k < A->rowptr[i + 1]; k++)
            if (csr_at(A, A->colind[k], i) != A->values[k])
                return 0;
    return 1;
}

static double vnorminf(int64_t n, const double *x)
{
    double s = 0;
    for (int64_t i = 0; i < n; i++)
        if (!(fabs(x[i]) <= s)) /* NaN propagates */
            s = fabs(x[i]);
    return s;
}

static double vnorm2(int64_t n, const double *x)
{
    double s = 0;
    for (int64_t i = 0; i < n; i++)
        s += x[i] * x[i];
    return sqrt(s);
}

static double dist_to_ones(int64_t n, const double *x)
{
    double s = 0;
    for (int64_t i = 0; i < n; i++)
        if (!(fabs(x[i] - 1) <= s))
            s = fabs(x[i] - 1);
    return s;
}

/* Fetches x as a dense array of length n; NULL (with a failed check) if it cannot. */
static double *fetch(silc_context *ctx, const char *file, const char *name, int64_t n)
{
    silc_envelope_t e = {0};
    double *x = NULL;
    if (silc_get(ctx, &e, name)) {
        CHECK(0, "%s: get %s: %s", file, name, silc_context_errmsg(ctx));
        return NULL;
    }
    if (silc_envelope_rows(&e) != n || silc_envelope_cols(&e) != 1)
        CHECK(0, "%s: %s is %lldx%lld, want %lldx1", file, name, (long long)silc_envelope_rows(&e),
              (long long)silc_envelope_cols(&e), (long long)n);
    else if ((x = malloc(sizeof *x * (size_t)n)) != NULL && silc_envelope_to_dense(&e, x)) {
        CHECK(0, "%s: %s to dense failed", file, name);
        free(x);
        x = NULL;
    }
    silc_envelope_free(&e);
    return x;
}

static void run_matrix(const char *dir, const char *file, long long rows, long long cols,
                       const char *field, const char *symmetry, const char *cls)
{
    char path[2048], err[512] = "";
    silc_envelope_t A = {0}, be = {0};
    snprintf(path, sizeof path, "%s/%s", dir, file);
    int rc = silc_mm_read(&A, path, err, sizeof err);

    if (strcmp(field, "complex") == 0) { /* values and solves: test_complex_core, test_complex_ref */
        CHECK(rc == 0 && A.format == SILC_CSR_COMPLEX && A.m == rows && A.n == cols,
              "%s: a complex file must read as a %lldx%lld complex csr (rc %d, '%s')", file, rows, cols, rc, err);
        silc_envelope_free(&A);
        return;
    }
    if (rc) {
        CHECK(0, "%s: silc_mm_read failed: %s", file, err);
        return;
    }
    if (A.m != rows || A.n != cols || A.format != SILC_CSR) {
        CHECK(0, "%s: read as %lldx%lld format %d, want %lldx%lld CSR", file, (long long)A.m,
              (long long)A.n, (int)A.format, rows, cols);
        silc_envelope_free(&A);
        return;
    }
    if (strcmp(symmetry, "symmetric") == 0)
        CHECK(csr_is_symmetric(&A), "%s: symmetric file not expanded to a symmetric CSR", file);

    int64_t m = A.m, n = A.n;
    double *ones = malloc(sizeof *ones * (size_t)n), *b = malloc(sizeof *b * (size_t)m);
    double *res = malloc(sizeof *res * (size_t)m), *atr = malloc(sizeof *atr * (size_t)n);
    double *x = NULL;
    silc_context *ctx = NULL;
    if (!ones || !b || !res || !atr) {
        CHECK(0, "%s: out of memory", file);
        goto done;
    }
    for (int64_t j = 0; j < n; j++)
        ones[j] = 1;
    csr_matvec(&A, ones, b);

    if (silc_open(&ctx, NULL)) {
        CHECK(0, "%s: silc_open: %s", file, ctx ? silc_context_errmsg(ctx) : silc_errmsg());
        goto done;
    }
    if (silc_envelope_dense(&be, m, 1, b) || silc_put(ctx, "A", &A) || silc_put(ctx, "b", &be)) {
        CHECK(0, "%s: put: %s", file, silc_context_errmsg(ctx));
        goto done;
    }
    rc = silc_exec(ctx, "x = A \\ b");
    const char *warn = silc_context_warnings(ctx);

    if (strcmp(cls, "singular") == 0 || strcmp(cls, "near-singular") == 0) {
        if (rc)
            CHECK(contains(silc_context_errmsg(ctx), "singular"),
                  "%s: failed without saying 'singular': %s", file, silc_context_errmsg(ctx));
        else
            CHECK(contains(warn, "singular to working precision") ||
                      contains(warn, "fewer than 4 correct digits"),
                  "%s: singular matrix answered silently (warnings: '%s')", file, warn ? warn : "");
        goto done;
    }
    if (rc) {
        CHECK(0, "%s (%s): x = A \\ b failed: %s", file, cls, silc_context_errmsg(ctx));
        goto done;
    }
    if (!(x = fetch(ctx, file, "x", n)))
        goto done;

    csr_matvec(&A, x, res);
    for (int64_t i = 0; i < m; i++)
        res[i] = b[i] - res[i];
    double anorm = csr_norminf(&A), xnorm = vnorminf(n, x), bnorm = vnorminf(m, b);
    double berr = vnorminf(m, res) / (anorm * xnorm + bnorm);
    double cond = known_cond(file);

    if (strcmp(cls, "rect") == 0 && m < n) {
        CHECK(berr < 1e-8, "%s: wide system, backward error of A x = b is %.3g", file, berr);
    } else if (strcmp(cls, "rect") == 0) {
        csr_tmatvec(&A, res, atr);
        double ne = vnorm2(n, atr), bound = 1e-10 * csr_normfro2(&A) * vnorm2(n, x);
        CHECK(ne <= bound, "%s: least squares: ||A'(b - A x)|| = %.3g > %.3g", file, ne, bound);
    } else {
        CHECK(berr < 1e-10, "%s (%s): backward error %.3g", file, cls, berr);
    }
    if (cond > 0 && !(strcmp(cls, "rect") == 0 && m < n)) {
        double fe = dist_to_ones(n, x), bound = 1e-11 * (cond > 10 ? cond : 10);
        CHECK(fe <= bound, "%s: ||x - ones||_inf = %.3g > %.3g (cond %.2g)", file, fe, bound, cond);
    }
done:
    free(ones);
    free(b);
    free(res);
    free(atr);
    free(x);
    silc_envelope_free(&A);
    silc_envelope_free(&be);
    silc_close(&ctx);
}

int main(int argc, char **argv)
{
    const char *dir = argc > 1 ? argv[1] : SILC_SHARED_MATRICES;
    char path[2048];
    FILE *f = tl_index_open(dir, path, sizeof path);
    tl_index_row r;
    int count = 0;
    while (f && tl_index_next(f, &r)) {
        printf("%-20s %-14s %lldx%lld\n", r.file, r.cls, r.rows, r.cols);
        fflush(stdout);
        run_matrix(dir, r.file, r.rows, r.cols, r.field, r.symmetry, r.cls);
        count++;
    }
    if (f)
        fclose(f);
    CHECK(count > 0, "no matrices listed in %s", path);
    return check_done();
}
