/*
 * test_plugin_mumps.c -- the "mumps" backend against exact solutions and the reference plugin.
 *
 * Two contexts: one whose sparse solve classes are forced to mumps, one forced
 * to reference.  Checked here, with every number computed by this program:
 *   - 2-D Laplacian (SPD, so MUMPS's SYM=1 LDL'): x close to the exact
 *     solution within eps * cond * 100, cond being the condition estimate
 *     `info` shows; info names mumps and the LDL' method, and MUMPS's own
 *     error analysis only when asked (mumps.icntl_11 = 1 or 2); a second
 *     solve with the same A reuses the factorization; several right-hand
 *     sides at once;
 *   - a shifted Laplacian (symmetric, positive diagonal, indefinite): SYM=1
 *     meets negative pivots, the dispatcher falls back to LU (SYM=0), and the
 *     result is still right;
 *   - west0479, sherman1, memplus from ../shared/matrices: mumps and reference
 *     agree within eps * cond * 100 and both have small backward errors;
 *   - the condition estimate (the host's block estimator, first block folded
 *     into the first solve) on fifteen shared matrices: a lower bound of the
 *     exact cond_1 = ||A||_1 ||A^-1||_1 (A^-1 from the reference's LU) and
 *     within a factor 3 of it;
 *   - options: `set mumps.icntl_7 = 5` is taken, `mumps.icntl_99` is refused
 *     with a suggestion, a layout-fixing ICNTL (icntl_5 = 1) is refused at
 *     solve time with the reason;
 *   - neumann (singular): an error naming dmumps_c and the INFOG meaning, or a
 *     warning that the matrix is singular to working precision;
 *   - plugins loaded together: solves through mumps, reference and whichever
 *     other library plugins are installed interleave in one process;
 *   - mumps.precision = single (smumps factor, refined in double by the core):
 *     the Laplacian, west0479 and sherman1 reach backward error <= 1e-14 with
 *     the refinement steps in `info`; the factor is reused; a 1e-300-scaled
 *     Laplacian still works (power-of-two scaling into float range); entries
 *     spanning more than float's range fall back to double with a note;
 *     Hilbert n = 9 (cond 5e11 > 1 / eps_single) gets a warning that
 *     refinement did not converge; a bad precision value is refused.
 */
#include <float.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "check.h"
#include "silc.h"
#include "testlib.h"

/* PUTs A and b = A * xs (xs_i = 1 + i/n) into c. */
static int put_system(silc_context *c, const silc_envelope_t *A, double *xs, double *b)
{
    for (int64_t i = 0; i < A->m; i++) xs[i] = 1.0 + (double)i / (double)A->m;
    return tl_put_system(c, A, xs, b);
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
    if (!xs || !b || !x || !X || tl_grid2d(&A, k, 0, 4)) {
        CHECK(0, "laplacian: setup failed");
        goto out;
    }
    CHECK(put_system(cm, &A, xs, b) == 0, "put: %s", silc_context_errmsg(cm));
    CHECK(silc_exec(cm, "x = A \\ b") == 0, "laplacian solve: %s", silc_context_errmsg(cm));
    t = tl_out_info(cm, "x");
    CHECK(strstr(t, "  backend: mumps\n") != NULL, "laplacian backend:\n%s", t);
    CHECK(strstr(t, "LDL'") && strstr(t, "SYM=1") && strstr(t, "AMF"), "laplacian method:\n%s", t);
    CHECK(strstr(t, "omega1") == NULL, "MUMPS's error analysis is off by default:\n%s", t);
    CHECK(strstr(t, "block Hager-Higham (2 columns, 2 steps)") != NULL, "the note names the estimate:\n%s", t);
    CHECK(strstr(t, "reused factorization: no") != NULL, "first solve factors:\n%s", t);
    cond = tl_out_number(t, "condition estimate: ");
    /* The 1-norm condition of the 40x40 Laplacian is about 1e3. */
    CHECK(cond > 1e2 && cond < 1e4, "laplacian condition estimate %g", cond);
    CHECK(tl_get_vec(cm, "x", x, n) == 0, "get x: %s", silc_context_errmsg(cm));
    CHECK(tl_rel_diff(x, xs, n) <= 100 * DBL_EPSILON * cond, "laplacian forward error %g (cond %g)",
          tl_rel_diff(x, xs, n), cond);
    CHECK(tl_backward_error(&A, x, b) < 1e-14, "laplacian backward error %g", tl_backward_error(&A, x, b));

    /* Same A: the factorization is reused, the answer the same. */
    CHECK(silc_exec(cm, "y = A \\ (2 * b)") == 0, "second solve: %s", silc_context_errmsg(cm));
    t = tl_out_info(cm, "y");
    CHECK(strstr(t, "reused factorization: yes") != NULL, "second solve reuses:\n%s", t);
    CHECK(tl_get_vec(cm, "y", x, n) == 0, "get y");
    for (int64_t i = 0; i < n; i++) x[i] /= 2;
    CHECK(tl_rel_diff(x, xs, n) <= 100 * DBL_EPSILON * cond, "reused forward error %g", tl_rel_diff(x, xs, n));

    /* Three right-hand sides at once, on a fresh copy of A, so that the
     * estimator's first block rides along with three columns (and its
     * estimate is the one the single-column first solve made). */
    CHECK(silc_exec(cm, "A2 = A + 0; B = b * ones(1, 3); Z = A2 \\ B") == 0, "multi-rhs: %s",
          silc_context_errmsg(cm));
    t = tl_out_info(cm, "Z");
    CHECK(strstr(t, "reused factorization: no") != NULL && tl_out_number(t, "condition estimate: ") == cond,
          "multi-rhs first solve: a new factorization, the same estimate (%g):\n%s", cond, t);
    {
        silc_envelope_t e;
        if (silc_get(cm, &e, "Z") == 0 && e.m == n && e.n == 3 && silc_envelope_to_dense(&e, X) == 0) {
            for (int j = 0; j < 3; j++)
                CHECK(tl_rel_diff(X + j * n, xs, n) <= 100 * DBL_EPSILON * cond, "column %d error %g", j,
                      tl_rel_diff(X + j * n, xs, n));
        } else {
            CHECK(0, "get Z: %s", silc_context_errmsg(cm));
        }
        silc_envelope_free(&e);
    }
    silc_envelope_free(&A);

    /* Symmetric, positive diagonal, indefinite: SYM=1 fails, LU (SYM=0) answers. */
    if (tl_grid2d(&A, k, 0, 4 - 1.0) == 0) {
        CHECK(put_system(cm, &A, xs, b) == 0, "put shifted");
        CHECK(silc_exec(cm, "x = A \\ b") == 0, "shifted solve: %s", silc_context_errmsg(cm));
        t = tl_out_info(cm, "x");
        CHECK(strstr(t, "  backend: mumps\n") && strstr(t, "SYM=0"), "shifted uses mumps LU:\n%s", t);
        CHECK(strstr(t, "Cholesky failed") != NULL, "shifted notes the fallback:\n%s", t);
        cond = tl_out_number(t, "condition estimate: ");
        CHECK(tl_get_vec(cm, "x", x, n) == 0, "get shifted x");
        CHECK(cond > 0 && tl_rel_diff(x, xs, n) <= 100 * DBL_EPSILON * cond, "shifted forward error %g (cond %g)",
              tl_rel_diff(x, xs, n), cond);
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
    silc_envelope_t A;
    if (tl_read_shared(file, &A)) return;
    int64_t n = A.m;
    double *xs = malloc((size_t)n * sizeof *xs), *b = malloc((size_t)n * sizeof *b),
           *xm = malloc((size_t)n * sizeof *xm), *xr = malloc((size_t)n * sizeof *xr);
    if (xs && b && xm && xr && put_system(cm, &A, xs, b) == 0 && put_system(cr, &A, xs, b) == 0) {
        CHECK(silc_exec(cm, "x = A \\ b") == 0, "%s mumps: %s", file, silc_context_errmsg(cm));
        const char *t = tl_out_info(cm, "x");
        double cond = tl_out_number(t, "condition estimate: ");
        CHECK(strstr(t, "  backend: mumps\n") != NULL, "%s backend:\n%s", file, t);
        CHECK(cond >= 1, "%s condition estimate %g", file, cond);
        CHECK(silc_exec(cr, "x = A \\ b") == 0, "%s reference: %s", file, silc_context_errmsg(cr));
        if (tl_get_vec(cm, "x", xm, n) == 0 && tl_get_vec(cr, "x", xr, n) == 0) {
            double bound = 100 * DBL_EPSILON * cond, d = tl_rel_diff(xm, xr, n);
            CHECK(tl_backward_error(&A, xm, b) < 1e-12, "%s mumps backward error %g", file,
                  tl_backward_error(&A, xm, b));
            CHECK(d <= bound || bound >= 1, "%s: mumps vs reference %g > %g", file, d, bound);
            CHECK(tl_rel_diff(xm, xs, n) <= bound || bound >= 1, "%s: mumps vs exact %g > %g", file,
                  tl_rel_diff(xm, xs, n), bound);
            printf("%-14s n %6lld  cond %8.2g  |x_mumps - x_ref| %8.2g  |x_mumps - x*| %8.2g\n", file,
                   (long long)n, cond, d, tl_rel_diff(xm, xs, n));
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

/* mumps.amalgamation (KEEP(1)): fewer, larger fronts than MUMPS's own 5,
 * the same accuracy; out-of-range values are refused by name. */
static void test_amalgamation(silc_context *cm)
{
    const char *t, *e;
    double fronts5 = -1, fronts16 = -1;
    CHECK(silc_exec(cm, "x = solve(A, b, \"mumps.amalgamation = 5\")") == 0, "amalgamation 5: %s",
          silc_context_errmsg(cm));
    t = tl_out_info(cm, "x");
    if ((t = strstr(t, "mumps.amalgamation = 5: "))) fronts5 = strtod(t + 24, NULL);
    CHECK(silc_exec(cm, "x = solve(A, b, \"mumps.amalgamation = 16\"); r = norm(A * x - b, inf) / (norm(A, inf) * "
                        "norm(x, inf) + norm(b, inf))") == 0,
          "amalgamation 16: %s", silc_context_errmsg(cm));
    t = tl_out_info(cm, "x");
    CHECK(strstr(t, "reused factorization: no") != NULL, "amalgamation 16 refactors:\n%s", t);
    if ((t = strstr(t, "mumps.amalgamation = 16: "))) fronts16 = strtod(t + 25, NULL);
    CHECK(fronts5 > 0 && fronts16 > 0 && fronts16 < fronts5, "fronts: %g with 5, %g with 16", fronts5, fronts16);
    {
        silc_envelope_t r;
        double rv = 1;
        if (silc_get(cm, &r, "r") == 0) silc_envelope_to_dense(&r, &rv);
        silc_envelope_free(&r);
        CHECK(rv < 1e-14, "amalgamation 16: backward error %g", rv);
    }
    CHECK(silc_exec(cm, "x = solve(A, b, \"mumps.amalgamation = 0\")") != 0, "amalgamation 0 accepted");
    e = silc_context_errmsg(cm);
    CHECK(strstr(e, "mumps.amalgamation") && strstr(e, "got 0"), "amalgamation 0 message: %s", e);
}

static void test_options(silc_context *cm)
{
    const char *e;
    CHECK(silc_exec(cm, "set mumps.icntl_7 = 5") == 0, "icntl_7 = 5: %s", silc_context_errmsg(cm));
    CHECK(silc_exec(cm, "x = A \\ b") == 0, "solve with icntl_7 = 5: %s", silc_context_errmsg(cm));
    CHECK(strstr(tl_out_info(cm, "x"), "reused factorization: no") != NULL,
          "changed options refactor:\n%s", tl_out());
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
    CHECK(strstr(tl_out_info(cm, "x"), "cond1") != NULL, "full error analysis shows cond1:\n%s", tl_out());
    CHECK(silc_exec(cm, "x = solve(A, b, \"mumps.icntl_11 = 2\")") == 0, "icntl_11 = 2: %s",
          silc_context_errmsg(cm));
    CHECK(strstr(tl_out_info(cm, "x"), "omega1") != NULL, "error analysis shows omega1:\n%s", tl_out());
    CHECK(silc_exec(cm, "x = solve(A, b, \"mumps.condest = false\")") == 0, "condest = false: %s",
          silc_context_errmsg(cm));
    CHECK(strstr(tl_out_info(cm, "x"), "condition estimate: not estimated") && !strstr(tl_out(), "Hager"),
          "condest = false: no estimate, and info says so:\n%s", tl_out());
    test_amalgamation(cm);
}

/* The condition estimate (the host's block estimator, two columns, two
 * steps, its first block folded into the first solve) against the exact
 * cond_1 = ||A||_1 ||A^{-1}||_1, A^{-1} from the reference plugin's sparse LU
 * with n right-hand sides.  An estimate is a lower bound (up to rounding)
 * and, for these matrices, within the factor 3 Hager's method is known for. */
static void test_estimate(silc_context *cm, silc_context *cr, const char *file)
{
    int64_t m = 0, n = 0;
    double exact = -1, est;
    char err[256];
    if (tl_put_shared(cm, "E", file, &m, &n, err, sizeof err) ||
        tl_put_shared(cr, "E", file, &m, &n, err, sizeof err)) {
        CHECK(0, "%s: %s", file, err);
        return;
    }
    CHECK(silc_exec(cr, "Ei = E \\ eye(rows(E)); ce = norm(E, 1) * norm(Ei, 1)") == 0, "%s exact: %s", file,
          silc_context_errmsg(cr));
    CHECK(tl_get_vec(cr, "ce", &exact, 1) == 0 && exact > 0, "%s: exact cond_1 %g", file, exact);
    CHECK(silc_exec(cm, "xe = E \\ ones(rows(E), 1)") == 0, "%s mumps: %s", file, silc_context_errmsg(cm));
    est = tl_out_number(tl_out_info(cm, "xe"), "condition estimate: ");
    /* info prints 3 significant digits: a lower bound may read 0.5% high. */
    CHECK(est <= exact * 1.005 && est >= exact / 3, "%s: estimate %g, exact cond_1 %g", file, est, exact);
    printf("%-14s n %6lld  cond_1 %8.3g  estimate %8.3g  (ratio %.3f)\n", file, (long long)n, exact, est,
           est / exact);
    silc_exec(cr, "clear E Ei ce");
    silc_exec(cm, "clear E xe");
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
    silc_envelope_t A, eb;
    if (tl_read_shared("neumann.mtx", &A)) return;
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
        const int64_t n = 20 * 20;
        double *c = malloc((size_t)n * sizeof *c);
        for (int64_t r = 0; c && r < n; r++) c[r] = 1;
        if (c && tl_singular_block_laplacian(&A, 20) == 0 && silc_put(cm, "N", &A) == 0 &&
            silc_envelope_vector(&eb, n, c) == 0) {
            silc_put(cm, "c", &eb);
            silc_envelope_free(&eb);
            check_singular(cm, "singular block");
        } else {
            CHECK(0, "singular block setup");
        }
        silc_envelope_free(&A); /* zeroed by the free above, so safe if never built */
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

/* ---- mumps.precision = single ---------------------------------------------------- */

/* Solves the system in cm with mumps.precision = single; checks the method,
 * that refinement ran and that the backward error reached 1e-14.  Returns the
 * number of refinement steps, -1 on failure. */
static int single_solve(silc_context *cm, const silc_envelope_t *A, const double *b, double *x,
                        const char *what)
{
    const char *t;
    double steps, be;
    if (silc_exec(cm, "x = solve(A, b, \"mumps.precision = single\")")) {
        CHECK(0, "%s single: %s", what, silc_context_errmsg(cm));
        return -1;
    }
    t = tl_out_info(cm, "x");
    CHECK(strstr(t, "  backend: mumps\n") && strstr(t, "MUMPS single precision) + refinement"),
          "%s single method:\n%s", what, t);
    steps = tl_out_number(t, "refinement: ");
    CHECK(steps >= 1 && steps <= 10, "%s single: refinement steps %g:\n%s", what, steps, t);
    CHECK(strstr(t, "backward error before: ") != NULL, "%s single: no unrefined error:\n%s", what, t);
    if (tl_get_vec(cm, "x", x, A->m)) {
        CHECK(0, "%s single: get x", what);
        return -1;
    }
    be = tl_backward_error(A, x, b);
    CHECK(be <= 1e-14, "%s single: backward error %g after refinement", what, be);
    CHECK(strstr(silc_context_warnings(cm), "single-precision") == NULL, "%s single warns: %s", what,
          silc_context_warnings(cm));
    printf("%-14s single + %g refinement steps: backward error %.2g, before %.2g\n", what, steps, be,
           tl_out_number(t, "backward error before: "));
    return (int)steps;
}

/* The n x n Hilbert matrix as CSR. */
static int hilbert_csr(silc_envelope_t *H, int64_t n)
{
    int64_t *rp = malloc((size_t)(n + 1) * sizeof *rp), *ci = malloc((size_t)(n * n) * sizeof *ci);
    double *v = malloc((size_t)(n * n) * sizeof *v);
    int rc = -1;
    if (rp && ci && v) {
        for (int64_t i = 0; i <= n; i++) rp[i] = i * n;
        for (int64_t i = 0; i < n; i++)
            for (int64_t j = 0; j < n; j++) ci[i * n + j] = j, v[i * n + j] = 1.0 / (double)(i + j + 1);
        rc = silc_envelope_csr(H, n, n, rp, ci, v);
    }
    free(rp);
    free(ci);
    free(v);
    return rc;
}

/* With tune.accuracy set, the default refinement of a single factor stops
 * once the backward error reaches it (refine.c): fewer steps than the
 * steps_eps it takes to working precision, the target met (checked here
 * from x), no warning. */
static void test_single_target(silc_context *cm, const silc_envelope_t *A, const double *b, double *x,
                               int steps_eps)
{
    const char *t;
    double steps, before, be;
    CHECK(silc_exec(cm, "set tune.accuracy = 1e-9; x = solve(A, b, \"mumps.precision = single\")") == 0,
          "target: %s", silc_context_errmsg(cm));
    t = tl_out_info(cm, "x");
    steps = tl_out_number(t, "refinement: ");
    before = tl_out_number(t, "backward error before: ");
    CHECK(before > 1e-9, "target: the single solve alone reached %g (the test needs a step)", before);
    CHECK(steps >= 1 && steps < steps_eps, "target: %g steps, %d to working precision:\n%s", steps, steps_eps, t);
    CHECK(strstr(t, "at tune.accuracy") != NULL, "target: stop reason:\n%s", t);
    be = tl_get_vec(cm, "x", x, A->m) == 0 ? tl_backward_error(A, x, b) : 1;
    CHECK(be <= 1e-9, "target: backward error %g above tune.accuracy 1e-9", be);
    CHECK(strstr(silc_context_warnings(cm), "single-precision") == NULL, "target warns: %s",
          silc_context_warnings(cm));
    /* below eps: the refinement stops at working precision again, as unset */
    CHECK(silc_exec(cm, "set tune.accuracy = 1e-17") == 0, "tune.accuracy back: %s", silc_context_errmsg(cm));
    printf("laplacian single, tune.accuracy 1e-9: %g step(s), backward error %.2g (to eps: %d)\n", steps, be,
           steps_eps);
}

static void test_single(silc_context *cm)
{
    silc_envelope_t A;
    const int k = 40;
    int64_t n = (int64_t)k * k;
    double *xs = malloc((size_t)n * sizeof *xs), *b = malloc((size_t)n * sizeof *b),
           *x = malloc((size_t)n * sizeof *x);
    const char *t;
    int steps_eps;
    if (!xs || !b || !x || tl_laplacian2d(&A, k)) {
        CHECK(0, "single: setup failed");
        goto out;
    }
    CHECK(put_system(cm, &A, xs, b) == 0, "put: %s", silc_context_errmsg(cm));
    steps_eps = single_solve(cm, &A, b, x, "laplacian");
    CHECK(tl_rel_diff(x, xs, n) <= 1e-12, "laplacian single forward error %g", tl_rel_diff(x, xs, n));
    /* The single factor stays on A next to the double one and is reused. */
    CHECK(silc_exec(cm, "y = A \\ b; x = solve(A, b, \"mumps.precision = single\")") == 0, "again: %s",
          silc_context_errmsg(cm));
    t = tl_out_info(cm, "x");
    CHECK(strstr(t, "reused factorization: yes") && strstr(t, "single precision"),
          "single factor reused:\n%s", t);
    test_single_target(cm, &A, b, x, steps_eps);
    CHECK(silc_exec(cm, "x = solve(A, b, \"mumps.precision = half\")") != 0, "precision = half accepted");
    CHECK(strstr(silc_context_errmsg(cm), "expects double or single") != NULL, "half: %s",
          silc_context_errmsg(cm));

    /* Scaled far outside float's range: the power-of-two scaling takes it. */
    for (int64_t p = 0; p < A.nnz; p++) A.values[p] *= 1e-300;
    CHECK(put_system(cm, &A, xs, b) == 0, "put scaled");
    single_solve(cm, &A, b, x, "laplacian*1e-300");
    CHECK(tl_rel_diff(x, xs, n) <= 1e-12, "scaled single forward error %g", tl_rel_diff(x, xs, n));

    /* Rows scaled from 1e-30 to 1e30: no power of two fits all entries into
     * float, so the matrix is factored in double, and the note says so. */
    for (int64_t i = 0; i < n; i++)
        for (int64_t p = A.rowptr[i]; p < A.rowptr[i + 1]; p++)
            A.values[p] = A.values[p] * 1e300 * pow(10.0, 60.0 * (double)i / (double)(n - 1) - 30);
    CHECK(put_system(cm, &A, xs, b) == 0, "put wide");
    CHECK(silc_exec(cm, "x = solve(A, b, \"mumps.precision = single\")") == 0, "wide: %s",
          silc_context_errmsg(cm));
    t = tl_out_info(cm, "x");
    CHECK(strstr(t, "factored in double") && strstr(t, "range") && !strstr(t, "single precision)"),
          "wide range falls back to double:\n%s", t);
    CHECK(tl_get_vec(cm, "x", x, n) == 0 && tl_backward_error(&A, x, b) <= 1e-14,
          "wide backward error %g", tl_backward_error(&A, x, b));
    silc_envelope_free(&A);

    static const char *files[] = {"west0479.mtx", "sherman1.mtx"};
    for (size_t f = 0; f < sizeof files / sizeof files[0]; f++) {
        if (tl_read_shared(files[f], &A)) continue;
        if (A.m <= n && put_system(cm, &A, xs, b) == 0)
            single_solve(cm, &A, b, x, files[f]);
        else
            CHECK(0, "%s: setup failed", files[f]);
        silc_envelope_free(&A);
    }

    /* Hilbert 9: cond_1 5e11, beyond 1 / eps_single even after scaling.  The
     * single factor cannot be refined to double accuracy, and a warning says
     * so; in double the same system gets no such warning. */
    if (hilbert_csr(&A, 9) == 0 && put_system(cm, &A, xs, b) == 0) {
        CHECK(silc_exec(cm, "x = solve(A, b, \"mumps.precision = single\")") == 0, "hilbert single: %s",
              silc_context_errmsg(cm));
        const char *w = silc_context_warnings(cm);
        CHECK(strstr(w, "single-precision factorization stopped") && strstr(w, "ill-conditioned"),
              "hilbert single must warn: '%s'", w);
        CHECK(tl_get_vec(cm, "x", x, 9) == 0 && tl_backward_error(&A, x, b) > 1e-12,
              "hilbert single: backward error %g reached double accuracy", tl_backward_error(&A, x, b));
        printf("hilbert9 single: %s\n", w);
        CHECK(silc_exec(cm, "x = A \\ b") == 0, "hilbert double: %s", silc_context_errmsg(cm));
        CHECK(strstr(silc_context_warnings(cm), "single-precision") == NULL, "hilbert double warns: %s",
              silc_context_warnings(cm));
    } else {
        CHECK(0, "hilbert setup");
    }
    silc_envelope_free(&A);
out:
    free(xs);
    free(b);
    free(x);
}

int main(void)
{
    silc_context *cm = tl_open_forced("mumps"), *cr = tl_open_forced("reference");
    if (cm && cr) {
        test_laplacian(cm);
        test_shared(cm, cr, "west0479.mtx");
        test_shared(cm, cr, "sherman1.mtx");
        test_shared(cm, cr, "memplus.mtx");
        {
            static const char *const est_files[] = {"bcsstk01.mtx", "LFAT5.mtx", "494_bus.mtx", "gr_30_30.mtx",
                                                    "1138_bus.mtx", "sherman1.mtx", "hangGlider_2.mtx",
                                                    "west0067.mtx", "fs_183_6.mtx", "impcol_a.mtx",
                                                    "west0479.mtx", "olm1000.mtx", "orsirr_1.mtx",
                                                    "rajat19.mtx", "watt_2.mtx"};
            size_t i;
            for (i = 0; i < sizeof est_files / sizeof est_files[0]; i++) test_estimate(cm, cr, est_files[i]);
        }
        test_options(cm);
        test_together(cm);
        test_singular(cm);
        test_single(cm);
    }
    silc_close(&cm);
    silc_close(&cr);
    return check_done();
}
