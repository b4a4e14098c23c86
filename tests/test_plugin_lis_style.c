/*
 * test_plugin_lis_style.c -- the lis-style iterative backend through the
 * public API, against exact solutions and the reference direct solver.
 *
 * A context sends solve.sparse, solve.sparse.spd and solve.band to lis-style
 * (band too, because the structure rules classify a CSR matrix of small
 * bandwidth, such as the Toeplitz case below, as banded); a second context
 * sends them to "reference".  Checked:
 *   - Lis's reference behaviours: the 10x10-grid 2-D Laplacian (100 unknowns,
 *     460 nonzeros, b = A*ones) with -i bicg -p none -tol 1e-12 converges in
 *     10..30 iterations (read from `info x`) to within 1e-10 of ones; the
 *     n = 200 Toeplitz matrix (2 on the diagonal, 1 above, 2 two below) with
 *     -i bicg -maxiter 1000 -f double is reported not converged, with the
 *     residual, leaving the store unchanged, and with -f quad converges;
 *   - every solver with every preconditioner on an SPD grid operator (CG, CR
 *     and MINRES only there) and on an unsymmetric convection-diffusion
 *     operator, against the exact solution x_i = 1 + i/n; every solver in
 *     -f quad;
 *   - SA-AMG: CG's iterations on the k x k Laplacian stay nearly flat for
 *     k = 64, 128, 256 (at most 25, and at least 4x fewer than IC(0)'s at
 *     k = 128), the 256 x 256 hierarchy has at least 3 levels; an
 *     unsymmetric matrix is refused without -saamg_unsym true, and with it
 *     by the methods that need M^-T; a bad -saamg_theta is refused; every
 *     SPD shared matrix is solved with CG + SA-AMG or honestly not;
 *   - the BiCR family's shadow residual: on a symmetric matrix BiCR's
 *     residual after 8 iterations is CR's and BiCG's is CG's, and CRS,
 *     BiCRSTAB, GPBiCR part from CGS, BiCGSTAB, GPBiCG;
 *   - the SPD shared matrices with CG+IC(0), CG+ILU(0), CG+SA-AMG (-tol 1e-10
 *     -maxiter 20000): converged => reported residual <= tol and the relative
 *     error against the reference direct solve <= 1e-10 * its condition
 *     estimate (the 1-norm estimate bounds the 2-norm condition of a symmetric
 *     matrix from above, up to the estimator's slack); not converged => an
 *     honest error and an unchanged store;
 *   - option strings good (names, Lis numbers, config file, `set`, per call)
 *     and bad (unknown solver with a suggestion, malformed number, missing
 *     value, unknown option), breakdown reporting, a right-hand side near
 *     overflow solved scaled;
 *   - preconditioner reuse while A is unchanged, rebuild after A changes;
 *     dense A accepted by conversion; several right-hand sides; two threads.
 */
#define _POSIX_C_SOURCE 200809L /* clock_gettime */
#include <ctype.h>
#include <float.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "check.h"
#include "silc.h"
#include "testlib.h"

/* ---- helpers -------------------------------------------------------------------- */

static double now(void)
{
    struct timespec t;
    clock_gettime(CLOCK_MONOTONIC, &t);
    return (double)t.tv_sec + 1e-9 * (double)t.tv_nsec;
}

static silc_context *open_ctx(const char *backend, const char *config)
{
    static const char *const classes[] = {"solve.sparse", "solve.sparse.spd", "solve.band",
                                          "solve.dense", "solve.dense.spd", NULL};
    silc_context *c = NULL;
    char cmd[160];
    if (silc_open(&c, config)) {
        fprintf(stderr, "silc_open: %s\n", c ? silc_context_errmsg(c) : silc_errmsg());
        return NULL;
    }
    silc_set_output(c, tl_out_fn, NULL);
    for (int i = 0; classes[i]; i++) {
        snprintf(cmd, sizeof cmd, "set dispatch.%s = %s", classes[i], backend);
        CHECK(silc_exec(c, cmd) == 0, "%s: %s", cmd, silc_context_errmsg(c));
    }
    return c;
}

/* ||x - y||_2 / ||y||_2 */
static double rel_err2(const double *x, const double *y, int64_t n)
{
    double d = 0, s = 0;
    for (int64_t i = 0; i < n; i++) {
        d += (x[i] - y[i]) * (x[i] - y[i]);
        s += y[i] * y[i];
    }
    return s > 0 ? sqrt(d / s) : sqrt(d);
}

static double max_dev(const double *x, double v, int64_t n)
{
    double d = 0;
    for (int64_t i = 0; i < n; i++)
        if (!(fabs(x[i] - v) <= d)) d = fabs(x[i] - v);
    return d;
}

/* ---- generated matrices -------------------------------------------------------- */

/* 5-point operator on a k x k grid: 4 on the diagonal, -1 -/+ beta west/east
 * (beta = 0: the Laplacian; beta > 0 an upwinded convection, still an
 * M-matrix, so Jacobi and Gauss-Seidel converge on it). */
static void grid(silc_envelope_t *e, int64_t k, double beta)
{
    CHECK(tl_grid2d(e, k, beta, 4 + 2 * beta) == 0, "grid envelope");
}

/* Toeplitz: 2 on the diagonal, 1 on the superdiagonal, gamma two below. */
static void toeplitz(silc_envelope_t *e, int64_t n, double gamma)
{
    int64_t nz = 0;
    int64_t *rp = malloc((size_t)(n + 1) * sizeof *rp), *ci = malloc((size_t)(3 * n) * sizeof *ci);
    double *v = malloc((size_t)(3 * n) * sizeof *v);
    for (int64_t i = 0; i < n; i++) {
        rp[i] = nz;
        if (i >= 2) ci[nz] = i - 2, v[nz++] = gamma;
        ci[nz] = i, v[nz++] = 2;
        if (i + 1 < n) ci[nz] = i + 1, v[nz++] = 1;
    }
    rp[n] = nz;
    CHECK(silc_envelope_csr(e, n, n, rp, ci, v) == 0, "toeplitz envelope");
    free(rp);
    free(ci);
    free(v);
}

/* Puts A and b = A * xt. */
static void put_system(silc_context *c, const silc_envelope_t *A, const double *xt)
{
    double *b = malloc((size_t)A->m * sizeof *b);
    tl_csr_matvec(A, xt, b);
    tl_put_checked(c, "A", A);
    tl_put_dense_checked(c, "b", A->m, 1, b);
    free(b);
}

/* ---- Lis's reference behaviours ------------------------------------------------ */

static void test_laplacian_bicg(silc_context *c)
{
    silc_envelope_t A;
    double ones[100], *x, it;
    const char *in;
    for (int i = 0; i < 100; i++) ones[i] = 1;
    grid(&A, 10, 0);
    CHECK(A.m == 100 && A.nnz == 460, "10x10 Laplacian is %lldx%lld with %lld nonzeros", (long long)A.m,
          (long long)A.n, (long long)A.nnz);
    put_system(c, &A, ones);
    CHECK(silc_exec(c, "x = solve(A, b, \"lis-style.options = -i bicg -p none -tol 1e-12\")") == 0,
          "laplacian bicg: %s", silc_context_errmsg(c));
    in = tl_out_info(c, "x");
    it = tl_out_number(in, "iterations: ");
    CHECK(tl_contains(in, "backend: lis-style"), "info does not name lis-style:\n%s", in);
    CHECK(tl_contains(in, "BiCG, no preconditioner"), "method not reported:\n%s", in);
    CHECK(it >= 10 && it <= 30, "BiCG on the 10x10 Laplacian took %g iterations (Lis: about 15)", it);
    CHECK(tl_out_number(in, "final relative residual: ") <= 1e-12, "residual above tol:\n%s", in);
    x = tl_get_dense_checked(c, "x", 100, 1);
    if (x) CHECK(max_dev(x, 1, 100) <= 1e-10, "laplacian bicg: |x - 1| = %g", max_dev(x, 1, 100));
    printf("  10x10 Laplacian, BiCG, no preconditioner: %g iterations\n", it);
    free(x);
    silc_envelope_free(&A);
}

static void test_toeplitz(silc_context *c)
{
    silc_envelope_t A;
    int64_t n = 200;
    double *ones = malloc((size_t)n * sizeof *ones), *x, it, t;
    const char *in, *msg;
    for (int64_t i = 0; i < n; i++) ones[i] = 1;
    toeplitz(&A, n, 2.0);
    put_system(c, &A, ones);
    CHECK(silc_exec(c, "x = zeros(200, 1) + 7") == 0, "x = 7: %s", silc_context_errmsg(c));
    CHECK(silc_exec(c, "x = solve(A, b, \"lis-style.options = -i bicg -maxiter 1000 -f double\")") != 0,
          "toeplitz: BiCG in double converged, Lis reports it does not");
    msg = silc_context_errmsg(c);
    CHECK(tl_contains(msg, "lis-style BiCG: not converged after 1000 iterations") &&
              tl_contains(msg, "relative residual"), "toeplitz double: message '%s'", msg);
    printf("  Toeplitz n=200 gamma=2, BiCG double: %s\n", msg);
    x = tl_get_dense_checked(c, "x", n, 1);
    if (x) CHECK(max_dev(x, 7, n) == 0, "a failed solve changed x");
    free(x);
    t = now();
    CHECK(silc_exec(c, "x = solve(A, b, \"lis-style.options = -i bicg -maxiter 1000 -f quad\")") == 0,
          "toeplitz: BiCG in quad: %s", silc_context_errmsg(c));
    t = now() - t;
    in = tl_out_info(c, "x");
    it = tl_out_number(in, "iterations: ");
    CHECK(tl_contains(in, "double-double"), "quad not in the method:\n%s", in);
    CHECK(tl_out_number(in, "final relative residual: ") <= 1e-12, "quad residual above tol:\n%s", in);
    x = tl_get_dense_checked(c, "x", n, 1);
    /* The matrix is well conditioned (cond_1 ~ 10): 1e-12 residual, 1e-10 error. */
    if (x) CHECK(max_dev(x, 1, n) <= 1e-10, "toeplitz quad: |x - 1| = %g", max_dev(x, 1, n));
    printf("  Toeplitz n=200 gamma=2, BiCG quad: converged in %g iterations, %.3f s, |x-1| = %.2g\n",
           it, t, x ? max_dev(x, 1, n) : -1);
    free(x);
    free(ones);
    silc_envelope_free(&A);
}

/* ---- every solver, every preconditioner ------------------------------------------ */

static const char *const krylov[] = {"cg", "cr", "minres", "bicg", "bicr", "cgs", "crs", "bicgstab",
                                     "bicrstab", "bicgstabl", "gpbicg", "gpbicr", "tfqmr", "gmres",
                                     "fgmres", "orthomin", "idrs", "idr1", NULL};
static const char *const stationary[] = {"jacobi", "gs", "sor", NULL};
static const char *const precons[] = {"none", "jacobi", "ilu", "ilu -ilu_fill 1", "ic", "ssor",
                                      "ilut", "saamg", "saamg -saamg_unsym true", NULL};

static int run_one(silc_context *c, const char *opts, int64_t n, const double *xt, double tol_err,
                   const char *label)
{
    char cmd[256];
    double *x, it, res;
    const char *in;
    int ok = 1;
    snprintf(cmd, sizeof cmd, "x = solve(A, b, \"lis-style.options = %s\")", opts);
    if (silc_exec(c, cmd)) {
        CHECK(0, "%s: %s: %s", label, opts, silc_context_errmsg(c));
        return 0;
    }
    in = tl_out_info(c, "x");
    it = tl_out_number(in, "iterations: ");
    res = tl_out_number(in, "final relative residual: ");
    ok &= it > 0 && res >= 0 && res <= 1e-10;
    CHECK(it > 0 && res >= 0 && res <= 1e-10, "%s: %s: iterations %g, residual %g", label, opts, it, res);
    x = tl_get_dense_checked(c, "x", n, 1);
    if (x) {
        double e = rel_err2(x, xt, n);
        ok &= e <= tol_err;
        CHECK(e <= tol_err, "%s: %s: relative error %g > %g", label, opts, e, tol_err);
    }
    free(x);
    return ok;
}

static void test_all_methods(silc_context *c)
{
    int64_t k = 12, n = k * k;
    double *xt = malloc((size_t)n * sizeof *xt);
    char opts[160];
    int ran = 0, good = 0;
    for (int64_t i = 0; i < n; i++) xt[i] = 1 + (double)i / (double)n;
    for (int sym = 1; sym >= 0; sym--) {
        silc_envelope_t A;
        const char *label = sym ? "SPD 12x12 Laplacian" : "unsymmetric convection-diffusion";
        grid(&A, k, sym ? 0 : 0.4);
        put_system(c, &A, xt);
        /* cond_2 is below 100 for both: residual 1e-10 -> error below 1e-8. */
        for (int s = 0; krylov[s]; s++) {
            int symmetric_method =
                !strcmp(krylov[s], "cg") || !strcmp(krylov[s], "cr") || !strcmp(krylov[s], "minres");
            if (!sym && symmetric_method) continue;
            for (int p = 0; precons[p]; p++) {
                /* IC and SA-AMG are for symmetric matrices; CG, CR and MINRES
                 * need a symmetric preconditioner, which ILUT's dropping is not. */
                if (!sym && (!strcmp(precons[p], "ic") || !strcmp(precons[p], "saamg"))) continue;
                /* SA-AMG on an unsymmetric matrix has no M^-T. */
                if (!sym && strstr(precons[p], "unsym") &&
                    (!strcmp(krylov[s], "bicg") || !strcmp(krylov[s], "bicr") || !strcmp(krylov[s], "crs") ||
                     !strcmp(krylov[s], "bicrstab") || !strcmp(krylov[s], "gpbicr")))
                    continue;
                if (symmetric_method && !strcmp(precons[p], "ilut")) continue;
                snprintf(opts, sizeof opts, "-i %s -p %s -tol 1e-10 -maxiter 5000", krylov[s], precons[p]);
                good += run_one(c, opts, n, xt, 1e-8, label);
                ran++;
            }
            snprintf(opts, sizeof opts, "-i %s -p none -tol 1e-12 -maxiter 5000 -f quad", krylov[s]);
            good += run_one(c, opts, n, xt, 1e-8, label);
            ran++;
        }
        for (int s = 0; stationary[s]; s++) {
            snprintf(opts, sizeof opts, "-i %s -p none -tol 1e-10 -maxiter 20000", stationary[s]);
            good += run_one(c, opts, n, xt, 1e-8, label);
            snprintf(opts, sizeof opts, "-i %s -p none -tol 1e-10 -maxiter 20000 -f quad", stationary[s]);
            good += run_one(c, opts, n, xt, 1e-8, label);
            ran += 2;
        }
        silc_envelope_free(&A);
    }
    printf("  every solver x preconditioner (double and quad): %d of %d runs agree with the exact solution\n",
           good, ran);
    free(xt);
}

/* ---- the BiCR family's shadow residual ------------------------------------------------ */

/* The relative residual after exactly k iterations: the message of a run
 * stopped by -maxiter k. */
static double residual_after(silc_context *c, const char *method, int k)
{
    char cmd[200];
    const char *msg, *p;
    snprintf(cmd, sizeof cmd, "x = solve(A, b, \"lis-style.options = -i %s -p none -tol 1e-30 -maxiter %d\")",
             method, k);
    CHECK(silc_exec(c, cmd) != 0, "%s: converged to 1e-30 in %d iterations", method, k);
    msg = silc_context_errmsg(c);
    p = strstr(msg, "relative residual ");
    CHECK(p && tl_contains(msg, "not converged"), "%s: %s", method, msg);
    return p ? strtod(p + 18, NULL) : -1;
}

/* BiCR is BiCG from the shadow residual A' r0, and on a symmetric matrix
 * that makes it CR (both leave r_k orthogonal to A K_k(A, r0)), as BiCG
 * from r0 is CG; CRS, BiCRSTAB and GPBiCR are CGS, BiCGSTAB and GPBiCG from
 * that shadow, so they must part from them. */
static void test_bicr_shadow(silc_context *c)
{
    static const char *const pairs[][2] = {{"cgs", "crs"}, {"bicgstab", "bicrstab"}, {"gpbicg", "gpbicr"}};
    silc_envelope_t A;
    int64_t k = 12, n = k * k;
    double *xt = malloc((size_t)n * sizeof *xt), cg, cr, bicg, bicr;
    size_t i;
    for (int64_t j = 0; j < n; j++) xt[j] = 1 + (double)j / (double)n;
    grid(&A, k, 0);
    put_system(c, &A, xt);
    cg = residual_after(c, "cg", 8), cr = residual_after(c, "cr", 8);
    bicg = residual_after(c, "bicg", 8), bicr = residual_after(c, "bicr", 8);
    printf("  after 8 iterations on the 12x12 Laplacian: CG %.2g BiCG %.2g, CR %.2g BiCR %.2g\n", cg, bicg,
           cr, bicr);
    CHECK(fabs(bicr - cr) <= 0.05 * cr, "BiCR %.3g is not CR %.3g on a symmetric matrix", bicr, cr);
    CHECK(fabs(bicg - cg) <= 0.05 * cg, "BiCG %.3g is not CG %.3g on a symmetric matrix", bicg, cg);
    CHECK(fabs(cr - cg) > 0.2 * cr, "CR %.3g and CG %.3g too close to tell the shadows apart", cr, cg);
    silc_envelope_free(&A);
    grid(&A, k, 1.0);
    put_system(c, &A, xt);
    for (i = 0; i < sizeof pairs / sizeof pairs[0]; i++) {
        double g = residual_after(c, pairs[i][0], 8), r = residual_after(c, pairs[i][1], 8);
        printf("  after 8 iterations on convection-diffusion (beta 1): %s %.2g, %s %.2g\n", pairs[i][0], g,
               pairs[i][1], r);
        CHECK(fabs(g - r) > 0.1 * g, "%s %.3g and %s %.3g: the same shadow?", pairs[i][0], g, pairs[i][1], r);
    }
    silc_envelope_free(&A);
    free(xt);
}

/* ---- SA-AMG ------------------------------------------------------------------------------ */

static void expect_error(silc_context *c, const char *opts, const char *want1, const char *want2);

/* Iterations of CG with preconditioner pc on the k x k Laplacian, b = A xt,
 * after checking the solution against xt; the info's note in *note. */
static double cg_iterations(silc_context *c, int64_t k, const char *pc, char *note, size_t notelen)
{
    silc_envelope_t A;
    int64_t n = k * k;
    double *xt = malloc((size_t)n * sizeof *xt), it = -1;
    char opts[96], label[128];
    for (int64_t i = 0; i < n; i++) xt[i] = 1 + (double)i / (double)n;
    grid(&A, k, 0);
    put_system(c, &A, xt);
    snprintf(opts, sizeof opts, "-i cg -p %s -tol 1e-10 -maxiter 5000", pc);
    snprintf(label, sizeof label, "%lldx%lld Laplacian", (long long)k, (long long)k);
    /* cond_2 of the k x k Laplacian is about 0.4 k^2: residual 1e-10 leaves an error below 1e-5 */
    if (run_one(c, opts, n, xt, 1e-5, label)) {
        const char *in = tl_out_info(c, "x");
        const char *p = strstr(in, "note: ");
        it = tl_out_number(in, "iterations: ");
        snprintf(note, notelen, "%.*s", p ? (int)strcspn(p, "\n") : 0, p ? p : "");
    }
    silc_envelope_free(&A);
    free(xt);
    return it;
}

/* Smoothed aggregation keeps CG's iteration count nearly flat as the grid is
 * refined, where IC(0)'s grows like k; it builds several levels, reports
 * them, and refuses an unsymmetric matrix. */
static void test_saamg(silc_context *c)
{
    char note[256];
    double ic = cg_iterations(c, 128, "ic", note, sizeof note);
    double a64 = cg_iterations(c, 64, "saamg", note, sizeof note);
    double a128 = cg_iterations(c, 128, "saamg", note, sizeof note);
    double a256 = cg_iterations(c, 256, "saamg", note, sizeof note);
    silc_envelope_t A;
    double xt[144];
    printf("  CG iterations on the k x k Laplacian: IC(0) %g at k = 128; SA-AMG %g, %g, %g at k = 64, 128, 256"
           " (%s)\n", ic, a64, a128, a256, note);
    CHECK(a64 > 0 && a128 > 0 && a256 > 0 && ic > 0, "a run failed");
    CHECK(a256 <= 25 && a256 <= a64 + 6, "SA-AMG iterations grow with the grid: %g, %g, %g", a64, a128, a256);
    CHECK(ic >= 4 * a128, "IC(0) %g against SA-AMG %g: not the multigrid gap", ic, a128);
    CHECK(tl_contains(note, "levels") && !tl_contains(note, " 1 levels") && !tl_contains(note, " 2 levels"),
          "256x256 SA-AMG: %s", note);
    for (int i = 0; i < 144; i++) xt[i] = 1;
    grid(&A, 12, 0.4);
    put_system(c, &A, xt);
    expect_error(c, "-i gmres -p saamg", "-p saamg is for symmetric matrices", "-saamg_unsym true");
    expect_error(c, "-i bicg -p saamg -saamg_unsym true", "-i BiCG needs M^-T", "unsymmetric");
    expect_error(c, "-i gmres -p saamg -saamg_theta 1.5", "-saamg_theta", "1.5");
    run_one(c, "-i gmres -p saamg -saamg_unsym true -tol 1e-11", 144, xt, 1e-8, "unsymmetric SA-AMG");
    silc_envelope_free(&A);
}

/* ---- the SPD shared matrices against the reference direct solve -------------------- */

static void test_shared_spd(silc_context *c, silc_context *ref)
{
    tl_spd_sweep(c, ref, "CG+IC(0)",
                 "x = solve(A, b, \"lis-style.options = -i cg -p ic -tol 1e-10 -maxiter 20000\")", 1e-10);
    tl_spd_sweep(c, ref, "CG+ILU(0)",
                 "x = solve(A, b, \"lis-style.options = -i cg -p ilu -tol 1e-10 -maxiter 20000\")", 1e-10);
    tl_spd_sweep(c, ref, "CG+SA-AMG",
                 "x = solve(A, b, \"lis-style.options = -i cg -p saamg -tol 1e-10 -maxiter 20000\")", 1e-10);
}

/* ---- options -------------------------------------------------------------------------- */

static void expect_error(silc_context *c, const char *opts, const char *want1, const char *want2)
{
    char cmd[256];
    const char *msg;
    snprintf(cmd, sizeof cmd, "x = solve(A, b, \"lis-style.options = %s\")", opts);
    CHECK(silc_exec(c, cmd) != 0, "'%s' was accepted", opts);
    msg = silc_context_errmsg(c);
    CHECK(tl_contains(msg, want1) && tl_contains(msg, want2), "'%s': message '%s' lacks '%s' / '%s'", opts,
          msg, want1, want2);
}

static void test_options(silc_context *c)
{
    silc_envelope_t A;
    int64_t k = 10, n = k * k;
    double *xt = malloc((size_t)n * sizeof *xt);
    const char *in;
    char conf[] = "/tmp/silc_lis_style_XXXXXX";
    int fd;
    for (int64_t i = 0; i < n; i++) xt[i] = 1 + (double)i / (double)n;
    grid(&A, k, 0.4);
    put_system(c, &A, xt);
    /* Good: names, Lis numbers, every knob. */
    run_one(c, "-i 2 -p 0 -tol 1e-11", n, xt, 1e-8, "options");
    in = tl_out_info(c, "x");
    CHECK(tl_contains(in, "BiCG, no preconditioner"), "-i 2 -p 0 is not BiCG without preconditioner:\n%s", in);
    run_one(c, "-i 4 -p 2 -ilu_fill 2 -tol 1e-11", n, xt, 1e-8, "options");
    CHECK(tl_contains(tl_out_info(c, "x"), "BiCGSTAB + ILU(2)"), "-i 4 -p 2 -ilu_fill 2:\n%s", tl_out());
    run_one(c, "-i bicgstabl -ell 4 -p 9 -ilut_drop 0.01 -ilut_rate 3 -tol 1e-11", n, xt, 1e-8, "options");
    CHECK(tl_contains(tl_out_info(c, "x"), "BiCGSTAB(4) + ILUT(0.01,3)"), "bicgstabl/ilut:\n%s", tl_out());
    run_one(c, "-i 21 -idrs_s 4 -tol 1e-11", n, xt, 1e-8, "options");
    CHECK(tl_contains(tl_out_info(c, "x"), "IDR(4)"), "-i 21 -idrs_s 4:\n%s", tl_out());
    run_one(c, "-i idr1 -idrs_s 4 -tol 1e-11", n, xt, 1e-8, "options");
    CHECK(tl_contains(tl_out_info(c, "x"), "IDR(1)"), "-i idr1 is not IDR(1):\n%s", tl_out());
    run_one(c, "-i 8 -restart 3 -p ilu -tol 1e-11", n, xt, 1e-8, "options");
    CHECK(tl_contains(tl_out_info(c, "x"), "Orthomin(3) + ILU(0)"), "-i 8 -restart 3:\n%s", tl_out());
    run_one(c, "-i 20 -restart 5 -p 3 -ssor_omega 1.2 -tol 1e-11", n, xt, 1e-8, "options");
    CHECK(tl_contains(tl_out_info(c, "x"), "FGMRES(5) + SSOR(1.2)"), "-i 20 -restart 5:\n%s", tl_out());
    run_one(c, "-i 12 -omega 1.5 -tol 1e-11 -maxiter 5000", n, xt, 1e-8, "options");
    CHECK(tl_contains(tl_out_info(c, "x"), "SOR(1.5)"), "-i 12 -omega 1.5:\n%s", tl_out());
    run_one(c, "-i gmres -conv_cond nrm2_b -tol 1e-11", n, xt, 1e-8, "options");
    CHECK(tl_contains(tl_out_info(c, "x"), "||b||"), "-conv_cond nrm2_b not in the note:\n%s", tl_out());
    run_one(c, "-i gmres -conv_cond 0 -initx_zeros false -print none -f 0 -tol 1e-11", n, xt, 1e-8, "options");
    CHECK(tl_contains(tl_out_info(c, "x"), "started from 0"), "-initx_zeros false not noted:\n%s", tl_out());
    /* Bad. */
    expect_error(c, "-i cgx", "unknown solver 'cgx'", "did you mean 'cg'");
    expect_error(c, "-tol abc", "-tol", "'abc'");
    expect_error(c, "-p", "-p needs a value", "ilu");
    expect_error(c, "-foo 1", "unknown option '-foo'", "did you mean");
    expect_error(c, "-i bicg -maxiter", "-maxiter needs a value", "");
    expect_error(c, "-i bicgsafe", "'bicgsafe'", "not implemented");
    expect_error(c, "-i 25", "'cocr'", "not implemented");
    expect_error(c, "-i gs -p ilu", "takes no preconditioner", "");
    expect_error(c, "-omega 2.5", "-omega", "2.5");
    expect_error(c, "-f single", "-f", "single");
    expect_error(c, "cg", "unexpected 'cg'", "-i cg");
    /* Session `set`, and the config file. */
    CHECK(silc_exec(c, "set lis-style.options = -i tfqmr -p jacobi -tol 1e-11") == 0, "set: %s",
          silc_context_errmsg(c));
    CHECK(silc_exec(c, "x = A \\ b") == 0, "set options: %s", silc_context_errmsg(c));
    CHECK(tl_contains(tl_out_info(c, "x"), "TFQMR + Jacobi"), "set lis-style.options not used:\n%s", tl_out());
    fd = mkstemp(conf);
    if (fd >= 0) {
        FILE *f = fdopen(fd, "w");
        silc_context *cf;
        fputs("[dispatch]\nsolve.sparse = lis-style\n[lis-style]\noptions = -i cgs -p ssor -tol 1e-11\n", f);
        fclose(f);
        cf = open_ctx("lis-style", conf);
        if (cf) {
            silc_set_output(cf, tl_out_fn, NULL);
            put_system(cf, &A, xt);
            CHECK(silc_exec(cf, "x = A \\ b") == 0, "config options: %s", silc_context_errmsg(cf));
            CHECK(tl_contains(tl_out_info(cf, "x"), "CGS + SSOR(1)"), "config file options not used:\n%s", tl_out());
            silc_close(&cf);
        }
        remove(conf);
    }
    CHECK(silc_exec(c, "set lis-style.options = -i bicgstab") == 0, "reset: %s", silc_context_errmsg(c));
    silc_envelope_free(&A);
    free(xt);
}

/* ---- breakdown, NaN ------------------------------------------------------------------------ */

static void test_failures(silc_context *c)
{
    /* [0 1; 1 0] (padded to 4x4 so it is not classified as banded) with b =
     * e1: CG's first curvature p'Ap is 0. */
    static const int64_t rp[] = {0, 1, 2, 3, 4}, ci[] = {1, 0, 3, 2};
    static const double v[] = {1, 1, 1, 1}, b[] = {1, 0, 1, 0};
    static const double hugeb[] = {1e300, 0, 1e300, 0};
    silc_envelope_t A;
    const char *msg;
    CHECK(silc_envelope_csr(&A, 4, 4, rp, ci, v) == 0, "swap envelope");
    tl_put_checked(c, "A", &A);
    tl_put_dense_checked(c, "b", 4, 1, b);
    CHECK(silc_exec(c, "x = solve(A, b, \"lis-style.options = -i cg -p none\")") != 0,
          "CG on [0 1; 1 0] did not break down");
    msg = silc_context_errmsg(c);
    CHECK(tl_contains(msg, "lis-style CG: breakdown at iteration 1") && tl_contains(msg, "relative residual"),
          "breakdown message '%s'", msg);
    /* A finite right-hand side whose squares overflow: solved scaled by a
     * power of two (lis_style.c), so the inner products stay finite and x is
     * right: [2 1; 1 2] x = [1e300; 0] gives x = 1e300 [2/3; -1/3]. */
    static const int64_t rp2[] = {0, 2, 4, 6, 8}, ci2[] = {0, 1, 0, 1, 2, 3, 2, 3};
    static const double v2[] = {2, 1, 1, 2, 2, 1, 1, 2};
    silc_envelope_free(&A);
    CHECK(silc_envelope_csr(&A, 4, 4, rp2, ci2, v2) == 0, "blocks envelope");
    tl_put_checked(c, "A", &A);
    tl_put_dense_checked(c, "b", 4, 1, hugeb);
    CHECK(silc_exec(c, "x = solve(A, b, \"lis-style.options = -i bicgstab -p none\")") == 0,
          "right-hand side near overflow: %s", silc_context_errmsg(c));
    {
        double *x = tl_get_dense_checked(c, "x", 4, 1);
        static const double want[] = {2e300 / 3, -1e300 / 3, 2e300 / 3, -1e300 / 3};
        CHECK(x && tl_rel_diff(x, want, 4) < 1e-12, "1e300 right-hand side: x differs by %g",
              x ? tl_rel_diff(x, want, 4) : -1.0);
        free(x);
    }
    silc_envelope_free(&A);
}

/* ---- reuse, dense, several right-hand sides, threads ------------------------------------------ */

static void test_reuse_and_formats(silc_context *c)
{
    silc_envelope_t A;
    int64_t k = 20, n = k * k;
    double *xt = malloc((size_t)n * sizeof *xt), *x, *B = malloc((size_t)(2 * n) * sizeof *B);
    const char *opts = "lis-style.options = -i cg -p ic -tol 1e-12";
    char cmd[160];
    for (int64_t i = 0; i < n; i++) xt[i] = 1 + (double)i / (double)n;
    grid(&A, k, 0);
    put_system(c, &A, xt);
    snprintf(cmd, sizeof cmd, "x = solve(A, b, \"%s\")", opts);
    CHECK(silc_exec(c, cmd) == 0, "reuse 1: %s", silc_context_errmsg(c));
    CHECK(tl_contains(tl_out_info(c, "x"), "reused factorization: no"), "first solve reused:\n%s", tl_out());
    CHECK(silc_exec(c, cmd) == 0, "reuse 2: %s", silc_context_errmsg(c));
    CHECK(tl_contains(tl_out_info(c, "x"), "reused factorization: yes") && tl_contains(tl_out(), "preconditioner reused"),
          "second solve with the same A did not reuse the preconditioner:\n%s", tl_out());
    CHECK(silc_exec(c, "A = 2 * A; b = 2 * b") == 0, "A = 2A: %s", silc_context_errmsg(c));
    CHECK(silc_exec(c, cmd) == 0, "reuse 3: %s", silc_context_errmsg(c));
    CHECK(tl_contains(tl_out_info(c, "x"), "reused factorization: no"), "a new A reused the old preconditioner:\n%s",
          tl_out());
    x = tl_get_dense_checked(c, "x", n, 1);
    if (x) CHECK(rel_err2(x, xt, n) <= 1e-9, "after A = 2A: error %g", rel_err2(x, xt, n));
    free(x);
    /* Dense A (converted once to CSR), two right-hand sides. */
    CHECK(silc_exec(c, "D = dense(A)") == 0, "dense: %s", silc_context_errmsg(c));
    {
        silc_envelope_t Ae;
        double *bb = malloc((size_t)n * sizeof *bb);
        CHECK(silc_get(c, &Ae, "b") == 0, "get b");
        silc_envelope_to_dense(&Ae, bb);
        silc_envelope_free(&Ae);
        for (int64_t i = 0; i < n; i++) B[i] = bb[i], B[n + i] = 3 * bb[i];
        free(bb);
    }
    tl_put_dense_checked(c, "B", n, 2, B);
    snprintf(cmd, sizeof cmd, "X = solve(D, B, \"%s\")", opts);
    CHECK(silc_exec(c, cmd) == 0, "dense, 2 rhs: %s", silc_context_errmsg(c));
    CHECK(tl_contains(tl_out_info(c, "X"), "backend: lis-style"), "dense solve not by lis-style:\n%s", tl_out());
    x = tl_get_dense_checked(c, "X", n, 2);
    if (x) {
        double e1 = rel_err2(x, xt, n), e2;
        for (int64_t i = 0; i < n; i++) x[n + i] /= 3;
        e2 = rel_err2(x + n, xt, n);
        CHECK(e1 <= 1e-9 && e2 <= 1e-9, "dense 2 rhs: errors %g %g", e1, e2);
    }
    free(x);
    silc_envelope_free(&A);
    free(xt);
    free(B);
}

static void test_threads(silc_context *c)
{
    silc_envelope_t A;
    int64_t k = 90, n = k * k; /* above the kernels' parallel threshold */
    double *xt = malloc((size_t)n * sizeof *xt), *x1, *x2, t1, t2;
    const char *cmd = "x = solve(A, b, \"lis-style.options = -i bicgstab -p ilu -tol 1e-10\")";
    for (int64_t i = 0; i < n; i++) xt[i] = 1 + (double)i / (double)n;
    grid(&A, k, 0.4);
    put_system(c, &A, xt);
    CHECK(silc_exec(c, cmd) == 0, "warm-up: %s", silc_context_errmsg(c)); /* builds ILU(0) */
    CHECK(silc_exec(c, "set tune.threads = 1") == 0, "threads 1: %s", silc_context_errmsg(c));
    t1 = now();
    CHECK(silc_exec(c, cmd) == 0, "1 thread: %s", silc_context_errmsg(c));
    t1 = now() - t1;
    x1 = tl_get_dense_checked(c, "x", n, 1);
    CHECK(silc_exec(c, "set tune.threads = 2") == 0, "threads 2: %s", silc_context_errmsg(c));
    t2 = now();
    CHECK(silc_exec(c, cmd) == 0, "2 threads: %s", silc_context_errmsg(c));
    t2 = now() - t2;
    x2 = tl_get_dense_checked(c, "x", n, 1);
    if (x1 && x2) {
        CHECK(rel_err2(x1, xt, n) <= 1e-7 && rel_err2(x2, xt, n) <= 1e-7, "threads: errors %g %g",
              rel_err2(x1, xt, n), rel_err2(x2, xt, n));
        printf("  90x90 convection-diffusion BiCGSTAB+ILU(0): 1 thread %.3f s, 2 threads %.3f s\n", t1, t2);
    }
    CHECK(silc_exec(c, "set tune.threads = 1") == 0, "threads back: %s", silc_context_errmsg(c));
    free(x1);
    free(x2);
    free(xt);
    silc_envelope_free(&A);
}

/* An empty option string picks a method for the class; Lis's defaults
 * (BiCG, no preconditioner) apply once options are written. */
static void test_defaults(void)
{
    silc_context *c = open_ctx("lis-style", NULL);
    silc_envelope_t A;
    int64_t k = 15, n = k * k;
    double *xt = malloc((size_t)n * sizeof *xt);
    for (int64_t i = 0; i < n; i++) xt[i] = 1 + (double)i / (double)n;
    if (!c) return;
    for (int sym = 1; sym >= 0; sym--) {
        grid(&A, k, sym ? 0 : 0.4);
        put_system(c, &A, xt);
        CHECK(silc_exec(c, "x = A \\ b") == 0, "default: %s", silc_context_errmsg(c));
        CHECK(tl_contains(tl_out_info(c, "x"), sym ? "CG + IC(0)" : "BiCGSTAB + ILU(0)"), "default method:\n%s", tl_out());
        CHECK(silc_exec(c, "x = solve(A, b, \"lis-style.options = -tol 1e-10\")") == 0, "lis defaults: %s",
              silc_context_errmsg(c));
        CHECK(tl_contains(tl_out_info(c, "x"), "BiCG, no preconditioner"), "Lis defaults:\n%s", tl_out());
        silc_envelope_free(&A);
    }
    free(xt);
    silc_close(&c);
}

int main(void)
{
    silc_context *c = open_ctx("lis-style", NULL), *ref = open_ctx("reference", NULL);
    if (!c || !ref) {
        CHECK(0, "cannot open contexts");
        return check_done();
    }
    printf("lis-style: Lis reference behaviours\n");
    test_laplacian_bicg(c);
    test_toeplitz(c);
    printf("lis-style: solvers and preconditioners\n");
    test_all_methods(c);
    test_bicr_shadow(c);
    test_saamg(c);
    printf("lis-style: options\n");
    test_options(c);
    test_defaults();
    test_failures(c);
    test_reuse_and_formats(c);
    test_threads(c);
    {
        silc_envelope_t A;
        double *ones = malloc(900 * sizeof *ones);
        for (int i = 0; ones && i < 900; i++) ones[i] = 1;
        grid(&A, 30, 0);
        if (ones) {
            put_system(c, &A, ones);
            printf("lis-style: warm starts\n");
            tl_check_warm_start(c, "x = solve(A, b, \"lis-style.options = -i cg -p none -tol 1e-10\")", 900,
                                1e-7, "lis-style CG");
        }
        free(ones);
        silc_envelope_free(&A);
    }
    printf("lis-style: SPD shared matrices, CG + IC(0) / ILU(0), tol 1e-10\n");
    test_shared_spd(c, ref);
    silc_close(&c);
    silc_close(&ref);
    return check_done();
}
