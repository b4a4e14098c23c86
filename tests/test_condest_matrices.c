/*
 * test_condest_matrices.c -- the condition estimate and the forward-error
 * bound that `info` reports, for every real square nonsingular shared
 * matrix (../shared/matrices/index.tsv) and every backend that takes it,
 * against a truth computed here with LAPACKE, independently of SILC.
 *
 * For each matrix A (n <= CM_DENSE_MAX: the truth is dense):
 *   cond_1(A) = ||A||_1 ||A^-1||_1, A^-1 by dgetrf + dgetri on the dense A;
 *   x_true_i = 1 + (i mod 7) / 8 with alternating signs, b = A x_true with
 *   compensated sums (fma + TwoSum), rounded once;
 * and for each backend (reference, lapack on dense(A), suitesparse.umfpack,
 * .klu, .cholmod for the spd class, mumps, petsc with -pc_type lu) that
 * solves x = A \ b:
 *
 *   (1) the estimate is within a factor CM_RATIO of cond_1(A):
 *           cond_1 / 10 <= cond_est <= 10 cond_1,
 *       where the truth has digits to compare (cond_1 eps < CM_TRUTH_EPS;
 *       beyond that both numbers only say "about 1/eps or more", and the
 *       estimate must say so: cond_est >= 1e-3 / eps);
 *   (2) the forward error is under the reported bound.  The bound B
 *       (accuracy.h) is est||A^-1||_1 ||b - A x||_1 / ||x||_1, with
 *       est||A^-1||_1 = cond_est / ||A||_1.  Exactly, x - x_s = A^-1 r for
 *       the solution x_s of the stored system A x_s = b, and b differs from
 *       A x_true by its final rounding, |b - A x_true| <= eps |b|, so with
 *       the estimate in place of ||A^-1||_1 the inequality tested is
 *
 *         ||x - x_true||_1 / ||x_true||_1
 *             <= (B ||x||_1 + (cond_est / ||A||_1) eps ||b||_1) / ||x_true||_1.
 *
 * Matrices larger than CM_DENSE_MAX (bcsstk13, bcsstk16, bayer10, memplus)
 * have no dense truth here: they check (2) only, with the backends that
 * factor them in well under a second (umfpack, klu, cholmod for spd, mumps).
 * Singular, rectangular and complex matrices have no cond_1 to estimate and
 * are skipped.  The iterative backends (lis-style, petsc's CG) make no
 * estimate: on gr_30_30 `info` must say "not estimated (iterative solver)"
 * and print no bound; accuracy.condest = off must say "not estimated" too.
 *
 * The table printed (per matrix and backend: true cond_1, estimate, ratio,
 * forward error, bound) is the one docs/accuracy.md records.
 */
#include <float.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <lapacke.h>

#include "check.h"
#include "testlib.h"

#define CM_DENSE_MAX 2000   /* largest n whose inverse is computed densely */
#define CM_RATIO 10.0       /* the estimate's allowed distance from cond_1, both ways */
#define CM_TRUTH_EPS 1e-3   /* cond_1 eps below which the dense truth has digits */

typedef struct backend {
    const char *name;   /* as in `backend = X` */
    const char *opts;   /* more per-call options, "" if none */
    int spd_only;       /* runs only under the spd class (Cholesky) */
    int dense;          /* solves dense(A) (LAPACK's dense LU) */
    int large;          /* also runs the matrices without dense truth */
    int defers;         /* makes its estimate when the report is read (ABI 1.8) */
} backend;

static const backend backends[] = {
    {"reference", "", 0, 0, 0, 1},
    {"lapack", "", 0, 1, 0, 0},
    {"suitesparse.umfpack", "", 0, 0, 1, 1},
    {"suitesparse.klu", "", 0, 0, 1, 1},
    {"suitesparse.cholmod", "", 1, 0, 1, 1},
    {"mumps", "", 0, 0, 1, 1},
    {"petsc", "; petsc.options = -ksp_type preonly -pc_type lu", 0, 0, 0, 0},
};
#define NBACKENDS (sizeof backends / sizeof backends[0])

/* r + e = a * b + c exactly enough: the compensated dot's step. */
static void dot2_step(double *s, double *c, double a, double x)
{
    double p = a * x, pe = fma(a, x, -p), t = *s + p, z = t - *s;
    *c += (*s - (t - z)) + (p - z) + pe;
    *s = t;
}

/* b = A x for CSR A with compensated sums: b carries only its final rounding. */
static void matvec_compensated(const silc_envelope_t *A, const double *x, double *b)
{
    for (int64_t i = 0; i < A->m; i++) {
        double s = 0, c = 0;
        for (int64_t p = A->rowptr[i]; p < A->rowptr[i + 1]; p++) dot2_step(&s, &c, A->values[p], x[A->colind[p]]);
        b[i] = s + c;
    }
}

static double norm1_vec(const double *x, int64_t n)
{
    double s = 0;
    for (int64_t i = 0; i < n; i++) s += fabs(x[i]);
    return s;
}

/* ||A||_1 of CSR A (largest column sum). */
static double norm1_csr(const silc_envelope_t *A)
{
    double *col = calloc((size_t)A->n, sizeof *col), best = 0;
    if (!col) return -1;
    for (int64_t p = 0; p < A->nnz; p++) col[A->colind[p]] += fabs(A->values[p]);
    for (int64_t j = 0; j < A->n; j++) best = col[j] > best ? col[j] : best;
    free(col);
    return best;
}

/* The exact cond_1 of A (up to rounding) by a dense inverse; -1 on failure,
 * INFINITY when dgetrf finds an exact zero pivot. */
static double true_cond1(const silc_envelope_t *A, double norm_a)
{
    int64_t n = A->n;
    double *D = calloc((size_t)(n * n), sizeof *D), best = 0;
    lapack_int *ipiv = malloc((size_t)n * sizeof *ipiv), info;
    if (!D || !ipiv) {
        free(D);
        free(ipiv);
        return -1;
    }
    for (int64_t i = 0; i < n; i++)
        for (int64_t p = A->rowptr[i]; p < A->rowptr[i + 1]; p++) D[i + A->colind[p] * n] += A->values[p];
    info = LAPACKE_dgetrf(LAPACK_COL_MAJOR, (lapack_int)n, (lapack_int)n, D, (lapack_int)n, ipiv);
    if (info == 0) info = LAPACKE_dgetri(LAPACK_COL_MAJOR, (lapack_int)n, D, (lapack_int)n, ipiv);
    if (info == 0)
        for (int64_t j = 0; j < n; j++) {
            double s = norm1_vec(D + j * n, n);
            best = s > best || s != s ? s : best;
        }
    free(D);
    free(ipiv);
    return info > 0 ? INFINITY : info < 0 ? -1 : norm_a * best;
}

/* Runs x = A \ b by backend be under accuracy.condest = mode; 0 and the
 * numbers of `info x`, else -1.  Under on_request a backend that defers
 * must say that the estimate was made when `info` read it. */
static int solve_with(silc_context *c, const backend *be, const char *mode, double *est, double *bound, char *why,
                      size_t whylen)
{
    char stmt[512];
    const char *in;
    int now = !strcmp(mode, "now");
    snprintf(stmt, sizeof stmt, "set accuracy.condest = %s; x = solve(%s, b, \"backend = %s%s\")", mode,
             be->dense ? (now ? "And" : "Ad") : (now ? "An" : "A"), be->name, be->opts);
    if (silc_exec(c, stmt)) {
        snprintf(why, whylen, "%s", silc_context_errmsg(c));
        return -1;
    }
    in = tl_out_info(c, "x");
    *est = tl_out_number(in, "condition estimate: ");
    *bound = tl_out_number(in, "forward error bound (estimate: est ||A^-1||_1 ||b - A x||_1 / ||x||_1): ");
    if (tl_contains(in, "condition estimate: inf")) *est = INFINITY;
    if (!(*est >= 0)) snprintf(why, whylen, "no condition estimate:\n%s", in);
    else if (be->defers && !strcmp(mode, "on_request") && !tl_contains(in, "computed when the report was first read)"))
        *est = -1, snprintf(why, whylen, "not deferred under on_request:\n%s", in);
    return 0;
}

/* 1 when backend be is installed in c. */
static int installed(silc_context *c, const char *name)
{
    char stmt[160];
    snprintf(stmt, sizeof stmt, "x0 = solve(1, 1, \"backend = %s\")", name);
    return silc_exec(c, stmt) == 0 || !tl_contains(silc_context_errmsg(c), "not installed");
}

static int worst_ok = 1;
static double worst_low = 1, worst_high = 1;

static void run_matrix(silc_context *c, const tl_index_row *row, const int *have)
{
    silc_envelope_t A;
    int64_t n;
    double *xt = NULL, *b = NULL, *x = NULL, norm_a, cond = -1, nb, nxt;
    int spd = !strcmp(row->cls, "spd");
    int dense_truth = row->rows <= CM_DENSE_MAX;
    if (tl_read_shared(row->file, &A)) return;
    n = A.n;
    xt = malloc((size_t)n * sizeof *xt);
    b = malloc((size_t)n * sizeof *b);
    if (!xt || !b) {
        CHECK(0, "%s: out of memory", row->file);
        goto out;
    }
    for (int64_t i = 0; i < n; i++) xt[i] = (i % 2 ? -1 : 1) * (1 + (double)(i % 7) / 8);
    matvec_compensated(&A, xt, b);
    nb = norm1_vec(b, n);
    nxt = norm1_vec(xt, n);
    norm_a = norm1_csr(&A);
    if (dense_truth) cond = true_cond1(&A, norm_a);
    tl_put_checked(c, "A", &A);
    if (tl_put_vector(c, "b", n, b)) {
        CHECK(0, "%s: put b: %s", row->file, silc_context_errmsg(c));
        goto out;
    }
    /* Each estimate twice: made when `info` reads the report (on_request),
     * and at solve time (now), with a fresh A (An: a PUT of the same
     * contents under the same name would keep A and its factorizations);
     * the large matrices, without a dense truth, only the first way (the
     * test's time: they check the bound alone). */
    tl_put_checked(c, "An", &A);
    if (dense_truth)
        CHECK(silc_exec(c, "Ad = dense(A); And = dense(An)") == 0, "%s: dense(A): %s", row->file,
              silc_context_errmsg(c));
    for (int pass = 0; pass < (dense_truth ? 2 : 1); pass++) {
        const char *mode = pass ? "now" : "on_request";
        for (size_t k = 0; k < NBACKENDS; k++) {
            const backend *be = &backends[k];
            char why[2048] = "";
            double est, bound, fe, allowed, ratio;
            if (!have[k] || (be->spd_only && !spd) || (!dense_truth && !be->large)) continue;
            if (solve_with(c, be, mode, &est, &bound, why, sizeof why)) {
                /* PETSc's own LU does not pivot: a zero diagonal stops it, and
                 * then it takes no part; the others must solve every matrix. */
                CHECK(!strcmp(be->name, "petsc") && tl_contains(why, "petsc"), "%s, %s: %s", row->file, be->name, why);
                printf("  %-17s %-20s (does not take it: %.60s)\n", row->file, be->name, why);
                continue;
            }
            CHECK(est >= 0, "%s, %s, %s: %s", row->file, be->name, mode, why);
            x = tl_get_dense_checked(c, "x", n, 1);
            if (!x || !(est >= 0)) goto next;
            fe = 0;
            for (int64_t i = 0; i < n; i++) fe += fabs(x[i] - xt[i]);
            fe /= nxt;
            allowed = isinf(est) ? INFINITY : (bound * norm1_vec(x, n) + est / norm_a * DBL_EPSILON * nb) / nxt;
            CHECK(bound >= 0 || isinf(est), "%s, %s: no forward error bound in info", row->file, be->name);
            CHECK(fe <= allowed, "%s, %s: forward error %.3g above the bound %.3g (cond_est %.3g, reported bound %.3g)",
                  row->file, be->name, fe, allowed, est, bound);
            ratio = cond > 0 ? est / cond : NAN;
            if (dense_truth && cond * DBL_EPSILON < CM_TRUTH_EPS) {
                int ok = est >= cond / CM_RATIO && est <= cond * CM_RATIO;
                CHECK(ok, "%s, %s: estimate %.3g, true cond_1 %.3g (ratio %.3g)", row->file, be->name, est, cond, ratio);
                if (ratio < worst_low) worst_low = ratio;
                if (ratio > worst_high) worst_high = ratio;
                worst_ok &= ok;
            } else if (dense_truth) {
                CHECK(est >= CM_TRUTH_EPS / DBL_EPSILON, "%s, %s: estimate %.3g, but cond_1 ~ %.3g is past 1/eps",
                      row->file, be->name, est, cond);
            }
            if (dense_truth)
                printf("  %-17s %-20s %-10s %6lld  %10.3g  %10.3g  %7.3f  %10.3g  %10.3g\n", row->file, be->name, mode,
                       (long long)n, cond, est, ratio, fe, allowed);
            else
                printf("  %-17s %-20s %-10s %6lld  %10s  %10.3g  %7s  %10.3g  %10.3g\n", row->file, be->name, mode,
                       (long long)n, "(n > 2000)", est, "", fe, allowed);
        next:
            free(x);
            x = NULL;
        }
    }
out:
    free(xt);
    free(b);
    free(x);
    silc_envelope_free(&A);
}

/* Iterative backends and accuracy.condest = off: "not estimated", no bound. */
static void check_not_estimated(silc_context *c, const int *have)
{
    static const char *const iterative[][2] = {
        {"lis-style", "; lis-style.options = -i cg -p ic -tol 1e-12"},
        {"petsc", "; petsc.options = -ksp_type cg -pc_type icc -ksp_rtol 1e-12"},
    };
    silc_envelope_t A;
    char stmt[512];
    const char *in;
    if (tl_read_shared("gr_30_30.mtx", &A)) return;
    tl_put_checked(c, "A", &A);
    CHECK(silc_exec(c, "b = A * ones(rows(A), 1)") == 0, "b: %s", silc_context_errmsg(c));
    for (size_t k = 0; k < 2; k++) {
        if (!installed(c, iterative[k][0])) continue;
        snprintf(stmt, sizeof stmt, "x = solve(A, b, \"backend = %s%s\")", iterative[k][0], iterative[k][1]);
        CHECK(silc_exec(c, stmt) == 0, "%s: %s", stmt, silc_context_errmsg(c));
        in = tl_out_info(c, "x");
        CHECK(tl_contains(in, "condition estimate: not estimated (iterative solver); no forward error bound") &&
                  !tl_contains(in, "forward error bound ("),
              "%s says plainly that it made no estimate:\n%s", iterative[k][0], in);
    }
    for (size_t k = 0; k < NBACKENDS; k++) {
        if (!have[k] || backends[k].dense) continue;
        snprintf(stmt, sizeof stmt, "set accuracy.condest = off; y = solve(A, b, \"backend = %s%s\"); "
                                    "set accuracy.condest = on; z = solve(A, b, \"backend = %s%s\")",
                 backends[k].name, backends[k].opts, backends[k].name, backends[k].opts);
        CHECK(silc_exec(c, stmt) == 0, "%s: %s", stmt, silc_context_errmsg(c));
        in = tl_out_info(c, "y");
        CHECK(tl_contains(in, "condition estimate: not estimated (accuracy.condest = off); no forward error bound") &&
                  !tl_contains(in, "forward error bound ("),
              "%s, accuracy.condest = off:\n%s", backends[k].name, in);
        /* on again, with the factorization made without it: an estimate now */
        in = tl_out_info(c, "z");
        CHECK(tl_out_number(in, "condition estimate: ") > 1 && tl_contains(in, "forward error bound ("),
              "%s, accuracy.condest = on after off:\n%s", backends[k].name, in);
    }
    CHECK(silc_exec(c, "set accuracy.condest = maybe") != 0 &&
              tl_contains(silc_context_errmsg(c), "accuracy.condest expects auto, now, on_request, on (= auto) or off"),
          "a bad accuracy.condest: %s", silc_context_errmsg(c));
    silc_envelope_free(&A);
}

int main(void)
{
    silc_context *c = tl_open_printing();
    int have[NBACKENDS];
    char path[1024];
    tl_index_row row;
    FILE *idx;
    if (!c) return check_done();
    for (size_t k = 0; k < NBACKENDS; k++) {
        have[k] = installed(c, backends[k].name);
        if (!have[k]) printf("test_condest_matrices: %s is not installed: skipped\n", backends[k].name);
    }
    CHECK(have[0], "the reference backend is always there");
    if (!(idx = tl_index_open(NULL, path, sizeof path))) return check_done();
    printf("  %-17s %-20s %-10s %6s  %10s  %10s  %7s  %10s  %10s\n", "matrix", "backend", "condest", "n", "cond_1",
           "estimate", "ratio", "fwd error", "bound");
    while (tl_index_next(idx, &row)) {
        if (strcmp(row.field, "real") && strcmp(row.field, "integer")) continue; /* complex, pattern */
        if (row.rows != row.cols || !strcmp(row.cls, "singular") || !strcmp(row.cls, "rect")) continue;
        run_matrix(c, &row, have);
    }
    fclose(idx);
    printf("  estimate / cond_1 over the matrices with a dense truth: %.3f ... %.3f\n", worst_low, worst_high);
    check_not_estimated(c, have);
    silc_close(&c);
    return check_done();
}
