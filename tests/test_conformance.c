/*
 * test_conformance.c -- every real shared matrix through every direct backend
 * that accepts it, each compared with the reference plugin.
 *
 * index.tsv in SILC_SHARED_MATRICES names each matrix's class.  For each real
 * (or integer, or pattern) matrix the right-hand side is b = A x0 with x0 a
 * fixed pseudo-random vector, and the solve is forced onto one backend at a
 * time with solve(A, b, "backend = NAME"):
 *   reference, lapack (on dense(A), only when both sides are <= 2000: the
 *   dense copy of the larger ones costs more than the whole suite),
 *   suitesparse.umfpack, suitesparse.klu, mumps (square), suitesparse.cholmod
 *   (class spd only), suitesparse.spqr (class rect only).
 * Nonsingular matrices: the core's backward error (from `info x`) must be
 * <= 1e-12, and the relative difference from the reference's solution
 *   ||x - x_ref||_inf / ||x_ref||_inf <= C n eps cond,   C = 10,
 * with cond the reference's 1-norm estimate.  Two backward-stable solvers each
 * land within ~ n eps cond of the truth (the usual bound, n eps being a
 * pessimistic backward error), so their difference is within twice that; C = 10
 * leaves room for the estimate being low by a small factor, no more.  A wide
 * system of full row rank has many solutions; every backend returns the
 * minimum-norm one, so it is compared the same way.
 * Singular and near-singular matrices (classes singular, near-singular) must be
 * refused with an error containing "singular" or answered with a warning
 * containing "singular to working precision" or "fewer than 4 correct digits",
 * by every backend.
 * A backend that is not built is skipped with a message.  The matrix x backend
 * table (backward error, or the outcome) goes to stdout.
 */
#include <float.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "check.h"
#include "testlib.h"

#define CONF_C 10.0         /* the honest constant of the forward bound (above) */
#define CONF_MAX_BE 1e-12   /* backward error every direct solver must reach */
#define CONF_DENSE_MAX 2000 /* largest side converted to dense for lapack */

static const char *const backends[] = {"reference",          "lapack",
                                       "suitesparse.umfpack", "suitesparse.klu",
                                       "suitesparse.cholmod", "suitesparse.spqr",
                                       "mumps"};
#define NB ((int)(sizeof backends / sizeof backends[0]))

static int missing[NB]; /* backend reported "not installed" once */

/* Whether backend k is meant to take a matrix of this class and shape. */
static int applies(int k, const char *cls, int64_t m, int64_t n)
{
    const char *b = backends[k];
    int rect = strcmp(cls, "rect") == 0;
    if (!strcmp(b, "reference")) return 1;
    if (!strcmp(b, "lapack")) return m <= CONF_DENSE_MAX && n <= CONF_DENSE_MAX;
    if (!strcmp(b, "suitesparse.cholmod")) return strcmp(cls, "spd") == 0;
    if (!strcmp(b, "suitesparse.spqr")) return rect;
    return !rect && m == n;
}

typedef struct {
    double *xref;      /* reference solution, NULL if the reference failed */
    double cond;       /* reference's estimate */
    int64_t m, n;
    int singular;      /* class singular or near-singular */
} matrix_case;

/* One backend on one matrix; fills cell with the table entry. */
static void run_backend(silc_context *c, tl_capture *cap, const char *file, int k,
                        matrix_case *mc, char *cell, size_t celllen)
{
    const char *b = backends[k];
    char stmt[256], warn[1024];
    const char *err, *info;
    double be;
    double *x;
    int rc;

    snprintf(stmt, sizeof stmt, "x = solve(%s, b, \"backend = %s\")",
             strcmp(b, "lapack") == 0 ? "Ad" : "A", b);
    if (!strcmp(b, "lapack") && silc_exec(c, "Ad = dense(A)")) {
        CHECK(0, "%s: dense(A): %s", file, silc_context_errmsg(c));
        snprintf(cell, celllen, "FAIL");
        return;
    }
    silc_exec(c, "clear x");
    rc = silc_exec(c, stmt);
    snprintf(warn, sizeof warn, "%s", silc_context_warnings(c));
    if (!strcmp(b, "lapack")) silc_exec(c, "clear Ad");
    if (rc) {
        err = silc_context_errmsg(c);
        if (tl_contains(err, "not installed")) {
            if (!missing[k]) printf("skipping %s: not installed (%s)\n", b, err);
            missing[k] = 1;
            snprintf(cell, celllen, "not built");
            return;
        }
        CHECK(mc->singular && tl_contains(err, "singular"), "%s via %s: %s", file, b, err);
        snprintf(cell, celllen, mc->singular && tl_contains(err, "singular") ? "refused" : "FAIL");
        if (mc->singular) printf("  %s via %s refused: %s\n", file, b, err);
        return;
    }
    info = tl_info(c, cap, "x");
    CHECK(tl_contains(info, b), "%s: info x does not name backend %s:\n%s", file, b, info);
    be = tl_field(info, "backward error");
    if (mc->singular) {
        int ok = tl_contains(warn, "singular to working precision") ||
                 tl_contains(warn, "fewer than 4 correct digits");
        CHECK(ok, "%s via %s: a singular matrix was solved without a warning "
                  "(backward error %.3g, warnings '%s')", file, b, be, warn);
        snprintf(cell, celllen, ok ? "warned" : "FAIL");
        return;
    }
    CHECK(be <= CONF_MAX_BE, "%s via %s: backward error %.3g > %.0e", file, b, be, CONF_MAX_BE);
    x = tl_get_dense(c, "x", NULL, NULL);
    CHECK(x != NULL, "%s via %s: cannot fetch x: %s", file, b, silc_context_errmsg(c));
    if (x && mc->xref && k > 0) {
        double d = tl_rel_diff(x, mc->xref, mc->n);
        double bound = CONF_C * (double)mc->n * DBL_EPSILON * mc->cond;
        CHECK(d <= bound, "%s via %s: differs from the reference by %.3g > %.3g "
                          "(= %.0f n eps cond, cond %.3g)", file, b, d, bound, CONF_C, mc->cond);
    }
    free(x);
    snprintf(cell, celllen, be <= CONF_MAX_BE ? "%.1e" : "%.1e!", be);
}

static void run_matrix(silc_context *c, tl_capture *cap, const char *file, const char *cls)
{
    char err[512], cells[NB][16];
    matrix_case mc;
    double *x0;
    int k;

    memset(&mc, 0, sizeof mc);
    mc.singular = !strcmp(cls, "singular") || !strcmp(cls, "near-singular");
    if (tl_put_shared(c, "A", file, &mc.m, &mc.n, err, sizeof err)) {
        CHECK(0, "%s: %s", file, err);
        return;
    }
    x0 = malloc((size_t)mc.n * sizeof *x0);
    if (!x0) return;
    tl_fill(x0, mc.n, 12345);
    CHECK(tl_put_vector(c, "x0", mc.n, x0) == 0 && silc_exec(c, "b = A * x0") == 0,
          "%s: b = A * x0: %s", file, silc_context_errmsg(c));
    free(x0);

    for (k = 0; k < NB; k++) {
        snprintf(cells[k], sizeof cells[k], "-");
        if (!applies(k, cls, mc.m, mc.n) || missing[k]) {
            if (missing[k]) snprintf(cells[k], sizeof cells[k], "not built");
            continue;
        }
        run_backend(c, cap, file, k, &mc, cells[k], sizeof cells[k]);
        if (k == 0 && !mc.singular) {
            mc.cond = tl_field(tl_info(c, cap, "x"), "condition estimate");
            CHECK(mc.cond > 0, "%s: the reference gives no condition estimate", file);
            mc.xref = tl_get_dense(c, "x", NULL, NULL);
        }
    }
    printf("%-18s %-13s", file, cls);
    for (k = 0; k < NB; k++) printf(" %10s", cells[k]);
    printf("\n");
    fflush(stdout);
    free(mc.xref);
    silc_exec(c, "clear A b x0 x");
}

int main(void)
{
    char path[1024];
    silc_context *c = NULL;
    tl_capture cap = {0};
    tl_index_row r;
    double t0 = tl_now();
    FILE *f;
    int k;

    if (!(f = tl_index_open(NULL, path, sizeof path))) return check_done();
    if (silc_open(&c, NULL)) {
        CHECK(0, "silc_open: %s", c ? silc_context_errmsg(c) : silc_errmsg());
        fclose(f);
        return check_done();
    }
    tl_capture_attach(c, &cap);
    printf("backward error of each solve, or: refused / warned (singular), "
           "- (not applicable), not built\n");
    printf("%-18s %-13s", "matrix", "class");
    for (k = 0; k < NB; k++) {
        const char *dot = strchr(backends[k], '.');
        printf(" %10s", dot ? dot + 1 : backends[k]);
    }
    printf("\n");
    while (tl_index_next(f, &r)) {
        if (!strcmp(r.field, "complex")) {
            printf("%-18s %-13s skipped: complex matrices are not supported yet\n", r.file, r.cls);
            continue;
        }
        run_matrix(c, &cap, r.file, r.cls);
    }
    fclose(f);
    silc_close(&c);
    tl_capture_free(&cap);
    printf("conformance: %.1f s\n", tl_now() - t0);
    return check_done();
}
