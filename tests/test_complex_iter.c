/*
 * test_complex_iter.c -- complex systems through the iterative backend and
 * the core's refinement (issue 31), and complex band values written as
 * Matrix Market, through the public API.
 *
 * Truth is independent of the code under test:
 *   - the 2-D Helmholtz problem of examples/helmholtz (complex symmetric,
 *     absorbing boundary; its assembly is linked, not copied) solved by
 *     lis-style's COCG, BiCGSTAB, GMRES and FGMRES with Jacobi, ILU(0),
 *     ILU(1) and SSOR, against the reference plugin's
 *     direct complex LU of the same system, within 10 cond_1 tol (cond_1
 *     from that direct solve's estimate), and against the exact plane wave,
 *     whose discretization error (4.576e-02 at n = 32, k = 10,
 *     docs/complex.md) the iterative solution must reproduce;
 *   - the shared complex matrices with b = A x_true: young1c (general) by
 *     BiCGSTAB and GMRES with ILU(0) and ILUT (also as a dense A, which
 *     lis-style converts), mhd1280b (Hermitian positive definite, cond_1
 *     6e12) by CG, each checked by a backward error this file computes
 *     itself and a forward error within 10 cond_1 tol; a method for another
 *     kind of matrix (CG on a non-Hermitian one, COCG on a general one) is
 *     refused by name and the list's next backend solves; a method that
 *     does not converge hands over to the next backend, or fails with the
 *     real path's message when it is alone, leaving the store unchanged;
 *   - refinement of a complex solve: Wilkinson's growth matrix times the
 *     phase 0.6 + 0.8i (partial pivoting's worst case, growth 2^(n-1)) by
 *     LAPACK's zgetrf, whose unrefined backward error is about 1e-6; one
 *     step of complex refinement must bring it to eps and the solution to
 *     x_true; the reported backward errors must equal the ones computed
 *     here from the returned x;
 *   - a complex band value fetched, written with silc_mm_write and read
 *     back by silc_mm_read: every entry equal (an entry with a zero real
 *     part included), nothing of the band's zero corners written.
 */
#define _POSIX_C_SOURCE 200809L
#include <complex.h>
#include <float.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "check.h"
#include "helmholtz/helmholtz.h"
#include "silc.h"
#include "testlib.h"

/* ---- helpers -------------------------------------------------------------------- */

static silc_context *open_ctx(void)
{
    silc_context *c = NULL;
    if (silc_open(&c, NULL)) {
        fprintf(stderr, "silc_open: %s\n", c ? silc_context_errmsg(c) : silc_errmsg());
        return NULL;
    }
    silc_set_output(c, tl_out_fn, NULL);
    return c;
}

static int run(silc_context *c, const char *stmt)
{
    int rc = silc_exec(c, stmt);
    CHECK(rc == 0, "%s: %s", stmt, silc_context_errmsg(c));
    return rc;
}

/* The complex n-vector name into z (n entries); 0 or -1. */
static int get_cvec(silc_context *c, const char *name, double complex *z, int64_t n)
{
    silc_envelope_t e;
    int rc;
    memset(&e, 0, sizeof e);
    if (silc_get_complex(c, &e, name)) return -1;
    rc = e.m == n && e.n == 1 && silc_envelope_is_complex(&e) ? silc_envelope_to_dense(&e, (double *)z) : -1;
    silc_envelope_free(&e);
    return rc;
}

static int put_cvec(silc_context *c, const char *name, const double complex *z, int64_t n)
{
    silc_envelope_t e;
    int rc;
    if (silc_envelope_dense_complex(&e, n, 1, (const double *)z)) return -1;
    rc = silc_put(c, name, &e);
    silc_envelope_free(&e);
    return rc;
}

/* y = A x, A a complex CSR envelope. */
static void cmatvec(const silc_envelope_t *A, const double complex *x, double complex *y)
{
    const double complex *v = (const double complex *)A->values;
    for (int64_t i = 0; i < A->m; i++) {
        double complex s = 0;
        for (int64_t p = A->rowptr[i]; p < A->rowptr[i + 1]; p++) s += v[p] * x[A->colind[p]];
        y[i] = s;
    }
}

/* ||b - A x||_inf / (||A||_inf ||x||_inf + ||b||_inf) by moduli: the
 * report's definition for complex systems (docs/accuracy.md), computed
 * here from the envelope. */
static double cbackward(const silc_envelope_t *A, const double complex *x, const double complex *b)
{
    const double complex *v = (const double complex *)A->values;
    double r = 0, an = 0, xn = 0, bn = 0;
    for (int64_t i = 0; i < A->m; i++) {
        double complex s = b[i];
        double rs = 0;
        for (int64_t p = A->rowptr[i]; p < A->rowptr[i + 1]; p++) {
            s -= v[p] * x[A->colind[p]];
            rs += cabs(v[p]);
        }
        r = fmax(r, cabs(s));
        an = fmax(an, rs);
        bn = fmax(bn, cabs(b[i]));
    }
    for (int64_t j = 0; j < A->n; j++) xn = fmax(xn, cabs(x[j]));
    return r / (an * xn + bn);
}

/* max |x - y| / max |y| */
static double crel(const double complex *x, const double complex *y, int64_t n)
{
    double d = 0, s = 0;
    for (int64_t i = 0; i < n; i++) {
        d = fmax(d, cabs(x[i] - y[i]));
        s = fmax(s, cabs(y[i]));
    }
    return d / s;
}

/* x = A \ b under the per-call options opts into x (n entries); returns
 * the `info x` text (tl_out's buffer) or NULL when the solve failed. */
static const char *solve_into(silc_context *c, const char *opts, double complex *x, int64_t n)
{
    char stmt[512];
    snprintf(stmt, sizeof stmt, "x = solve(A, b, \"%s\")", opts);
    if (silc_exec(c, stmt)) {
        CHECK(0, "%s: %s", stmt, silc_context_errmsg(c));
        return NULL;
    }
    if (get_cvec(c, "x", x, n)) {
        CHECK(0, "fetch x after %s: %s", stmt, silc_context_errmsg(c));
        return NULL;
    }
    return tl_out_info(c, "x");
}

/* ---- the Helmholtz problem ------------------------------------------------------- */

static void test_helmholtz(void)
{
    enum { N = 32 };
    const double k = 10, tol = 1e-10;
    const int64_t n = (N + 1) * (N + 1);
    static const char *const methods[] = {"-i cocg -p ilu",       "-i cocg -p jacobi", "-i cocg -p ssor",
                                          "-i cocg -p ilu -ilu_fill 1", "-i bicgstab -p ilu", "-i gmres -p ilu",
                                          "-i gmres -p ssor",     "-i fgmres -p ilu"};
    silc_context *c = open_ctx();
    silc_envelope_t A;
    double complex *b = malloc((size_t)n * sizeof *b), *xd = malloc((size_t)n * sizeof *xd),
                   *x = malloc((size_t)n * sizeof *x);
    char err[256], opts[256];
    const char *info;
    double cond, err_direct;
    memset(&A, 0, sizeof A);
    if (!c || !b || !xd || !x ||
        helmholtz_assemble(N, k, HELMHOLTZ_PLANE_WAVE, &A, (double *)b, err, sizeof err)) {
        CHECK(0, "helmholtz setup: %s", c ? err : "no context");
        goto out;
    }
    CHECK(silc_put(c, "A", &A) == 0 && put_cvec(c, "b", b, n) == 0, "put: %s", silc_context_errmsg(c));
    run(c, "set dispatch.solve.sparse = reference");
    run(c, "set dispatch.solve.band = reference");
    info = solve_into(c, "", xd, n);
    cond = tl_field(info, "condition estimate");
    CHECK(cond > 1 && cond < 1e8, "direct solve's cond_1 estimate %g", cond);
    err_direct = helmholtz_plane_wave_error(N, k, (double *)xd);
    CHECK(fabs(err_direct - 4.576e-2) < 1e-4, "direct discretization error %.4g (docs/complex.md: 4.576e-02)",
          err_direct);

    run(c, "set dispatch.solve.sparse = lis-style, reference");
    run(c, "set dispatch.solve.band = lis-style, reference");
    for (size_t m = 0; m < sizeof methods / sizeof *methods; m++) {
        double fe, be;
        snprintf(opts, sizeof opts, "lis-style.options = %s -tol %g -maxiter 3000", methods[m], tol);
        info = solve_into(c, opts, x, n);
        if (!info) continue;
        CHECK(tl_contains(info, "backend: lis-style"), "%s: solved by %s", methods[m], info);
        fe = crel(x, xd, n);
        be = cbackward(&A, x, b);
        CHECK(fe <= 10 * cond * tol, "helmholtz %s: |x - x_direct| / |x_direct| = %.2g > 10 cond tol = %.2g",
              methods[m], fe, 10 * cond * tol);
        CHECK(be <= 10 * tol, "helmholtz %s: backward error %.2g", methods[m], be);
        CHECK(fabs(tl_field(info, "backward error") - be) <= 0.01 * be, "%s: reported backward error %g, here %g",
              methods[m], tl_field(info, "backward error"), be);
        CHECK(fabs(helmholtz_plane_wave_error(N, k, (double *)x) - err_direct) < 1e-6,
              "%s: discretization error %.6g, direct %.6g", methods[m], helmholtz_plane_wave_error(N, k, (double *)x),
              err_direct);
    }
    /* CG needs A = A': refused by name, and the reference takes the system. */
    info = solve_into(c, "lis-style.options = -i cg -p jacobi", x, n);
    CHECK(info && tl_contains(info, "backend: reference") && tl_contains(info, "CG needs a Hermitian matrix") &&
              tl_contains(info, "complex symmetric: -i cocg"),
          "CG on Helmholtz: %s", info ? info : "");
    CHECK(crel(x, xd, n) < 1e-12, "CG refused: the reference's solution");
    /* ... and alone it is an error naming why, the store unchanged. */
    run(c, "set dispatch.solve.sparse = lis-style");
    run(c, "set dispatch.solve.band = lis-style");
    CHECK(silc_exec(c, "x = solve(A, b, \"lis-style.options = -i cg\")") != 0 &&
              strstr(silc_context_errmsg(c), "CG needs a Hermitian matrix"),
          "CG alone: %s", silc_context_errmsg(c));
    CHECK(get_cvec(c, "x", x, n) == 0 && crel(x, xd, n) < 1e-12, "x unchanged after the refusal");
    /* Methods and options with no complex form, by name. */
    CHECK(silc_exec(c, "y = solve(A, b, \"lis-style.options = -i bicg\")") != 0 &&
              strstr(silc_context_errmsg(c), "-i BiCG does not take complex values"),
          "bicg: %s", silc_context_errmsg(c));
    CHECK(silc_exec(c, "y = solve(A, b, \"lis-style.options = -i cocg -p saamg\")") != 0 &&
              strstr(silc_context_errmsg(c), "does not take complex values"),
          "saamg: %s", silc_context_errmsg(c));
    CHECK(silc_exec(c, "y = solve(A, b, \"lis-style.options = -i cocg -f quad\")") != 0 &&
              strstr(silc_context_errmsg(c), "-f quad does not take complex values"),
          "quad: %s", silc_context_errmsg(c));
    /* No options: the complex symmetric default, COCG + ILU(0). */
    info = solve_into(c, "", x, n);
    CHECK(info && tl_contains(info, "COCG + ILU(0)") && crel(x, xd, n) <= 10 * cond * 1e-12, "default: %s",
          info ? info : "");
out:
    silc_envelope_free(&A);
    free(b);
    free(xd);
    free(x);
    if (c) silc_close(&c);
}

/* ---- the shared complex matrices ------------------------------------------------ */

/* Reads the shared matrix file into A and puts it, with b = A x_true
 * (x_true_i = 1 + i (i+1)/n), into c. */
static int shared_system(silc_context *c, const char *file, silc_envelope_t *A, double complex **xt,
                         double complex **b)
{
    char path[1024], err[256];
    snprintf(path, sizeof path, "%s/%s", SILC_SHARED_MATRICES, file);
    if (tl_read_mtx(A, path, err, sizeof err)) {
        CHECK(0, "%s: %s", file, err);
        return -1;
    }
    *xt = malloc((size_t)A->n * sizeof **xt);
    *b = malloc((size_t)A->m * sizeof **b);
    if (!*xt || !*b) return -1;
    for (int64_t i = 0; i < A->n; i++) (*xt)[i] = 1 + I * (double)(i + 1) / (double)A->n;
    cmatvec(A, *xt, *b);
    if (silc_put(c, "A", A) || put_cvec(c, "b", *b, A->m)) {
        CHECK(0, "put %s: %s", file, silc_context_errmsg(c));
        return -1;
    }
    return 0;
}

static void check_method(silc_context *c, const silc_envelope_t *A, const double complex *xt,
                         const double complex *b, double cond, const char *name, const char *method, double tol)
{
    char opts[256];
    double complex *x = malloc((size_t)A->n * sizeof *x);
    const char *info;
    snprintf(opts, sizeof opts, "lis-style.options = %s -tol %g -maxiter 20000", method, tol);
    info = x ? solve_into(c, opts, x, A->n) : NULL;
    if (info) {
        double be = cbackward(A, x, b), fe = crel(x, xt, A->n);
        CHECK(tl_contains(info, "backend: lis-style"), "%s %s: %s", name, method, info);
        CHECK(be <= 10 * tol, "%s %s: backward error %.2g", name, method, be);
        CHECK(fe <= 10 * cond * tol, "%s %s: forward error %.2g > 10 cond tol %.2g", name, method, fe,
              10 * cond * tol);
        CHECK(fabs(tl_field(info, "backward error") - be) <= 0.01 * be, "%s %s: reported %g, here %g", name,
              method, tl_field(info, "backward error"), be);
    }
    free(x);
}

static void test_shared(void)
{
    silc_context *c = open_ctx();
    silc_envelope_t A;
    double complex *xt = NULL, *b = NULL, *x = NULL;
    const char *info;
    double cond;
    memset(&A, 0, sizeof A);
    if (!c) return;
    /* young1c: complex general, cond_1 ~ 1e3 (docs/complex.md) */
    run(c, "set dispatch.solve.sparse = reference");
    if (shared_system(c, "young1c.mtx", &A, &xt, &b) == 0 && (x = malloc((size_t)A.n * sizeof *x))) {
        info = solve_into(c, "", x, A.n);
        cond = tl_field(info, "condition estimate");
        CHECK(cond > 100 && cond < 1e5, "young1c cond_1 estimate %g", cond);
        run(c, "set dispatch.solve.sparse = lis-style, reference");
        check_method(c, &A, xt, b, cond, "young1c", "-i bicgstab -p ilu", 1e-10);
        check_method(c, &A, xt, b, cond, "young1c", "-i gmres -p ilu", 1e-10);
        check_method(c, &A, xt, b, cond, "young1c", "-i bicgstab -p ilut", 1e-10);
        /* A dense complex A is converted to CSR (kept with A) and solved alike. */
        run(c, "set dispatch.solve.dense = lis-style");
        if (run(c, "x = solve(dense(A), b, \"lis-style.options = -i bicgstab -p ilu -tol 1e-10\")") == 0 &&
            get_cvec(c, "x", x, A.n) == 0)
            CHECK(cbackward(&A, x, b) <= 1e-9 && crel(x, xt, A.n) <= 10 * cond * 1e-10,
                  "young1c dense by lis-style: backward error %.2g, forward %.2g", cbackward(&A, x, b),
                  crel(x, xt, A.n));
        /* COCG needs A = A.': refused, the reference solves.  (A refusal
         * is a failure on A, which the dispatcher remembers: lis-style is
         * then skipped for A while a fallback is listed, so the next
         * check gets a new A.) */
        info = solve_into(c, "lis-style.options = -i cocg", x, A.n);
        CHECK(info && tl_contains(info, "backend: reference") && tl_contains(info, "COCG needs a complex symmetric"),
              "cocg on young1c: %s", info ? info : "");
        /* Not converged: the next backend takes over, and says why it had to. */
        run(c, "A = 2 * A; b = 2 * b"); /* a new A, the same x_true */
        info = solve_into(c, "lis-style.options = -i bicgstab -maxiter 5", x, A.n);
        CHECK(info && tl_contains(info, "backend: reference") &&
                  tl_contains(info, "lis-style BiCGSTAB: not converged after 5 iterations (relative residual"),
              "not converged, handed over: %s", info ? info : "");
        CHECK(crel(x, xt, A.n) < 1e-10, "the reference's solution after the hand-over");
        /* Alone: the real path's message, the store unchanged. */
        run(c, "set dispatch.solve.sparse = lis-style");
        CHECK(silc_exec(c, "x = solve(A, b, \"lis-style.options = -i gmres -maxiter 7\")") != 0 &&
                  strstr(silc_context_errmsg(c), "lis-style GMRES(40): not converged after 7 iterations"),
              "gmres alone: %s", silc_context_errmsg(c));
        CHECK(get_cvec(c, "x", x, A.n) == 0 && crel(x, xt, A.n) < 1e-10, "x unchanged after not converging");
    }
    silc_envelope_free(&A);
    free(xt);
    free(b);
    free(x);
    xt = b = x = NULL;
    /* mhd1280b: complex Hermitian positive definite, cond_1 ~ 6e12 */
    run(c, "set dispatch.solve.sparse.spd = reference");
    run(c, "set dispatch.solve.sparse = reference");
    if (shared_system(c, "mhd1280b.mtx", &A, &xt, &b) == 0 && (x = malloc((size_t)A.n * sizeof *x))) {
        info = solve_into(c, "", x, A.n);
        cond = tl_field(info, "condition estimate");
        CHECK(cond > 1e11 && cond < 1e14, "mhd1280b cond_1 estimate %g", cond);
        run(c, "set dispatch.solve.sparse.spd = lis-style, reference");
        run(c, "set dispatch.solve.sparse = lis-style, reference");
        check_method(c, &A, xt, b, cond, "mhd1280b", "-i cg -p jacobi", 1e-10);
        check_method(c, &A, xt, b, cond, "mhd1280b", "-i cg -p ilu", 1e-10);
        check_method(c, &A, xt, b, cond, "mhd1280b", "-i gmres -p ilu", 1e-10);
        info = solve_into(c, "", x, A.n);
        CHECK(info && tl_contains(info, "CG + ILU(0)") && tl_contains(info, "backend: lis-style"),
              "mhd1280b default: %s", info ? info : "");
    }
    silc_envelope_free(&A);
    free(xt);
    free(b);
    free(x);
    silc_close(&c);
}

/* ---- refinement of a complex solve ----------------------------------------------- */

static void test_refinement(void)
{
    enum { N = 40 };
    const double complex phase = 0.6 + 0.8 * I;
    silc_context *c = open_ctx();
    int64_t rp[N + 1], ci[N * N];
    double complex v[N * N], xt[N], b[N], x0[N], x1[N];
    silc_envelope_t A;
    const char *info;
    int64_t nnz = 0;
    double be0, be1;
    memset(&A, 0, sizeof A);
    if (!c) return;
    if (silc_exec(c, "set dispatch.solve.dense = lapack")) {
        printf("complex refinement: skipped (no lapack plugin: %s)\n", silc_context_errmsg(c));
        silc_close(&c);
        return;
    }
    /* Wilkinson's matrix: 1 on the diagonal, -1 below, 1 in the last column. */
    for (int64_t i = 0; i < N; i++) {
        rp[i] = nnz;
        for (int64_t j = 0; j < i; j++) ci[nnz] = j, v[nnz++] = -phase;
        ci[nnz] = i, v[nnz++] = phase;
        if (i < N - 1) ci[nnz] = N - 1, v[nnz++] = phase;
    }
    rp[N] = nnz;
    for (int64_t i = 0; i < N; i++) xt[i] = 1 + I * (double)(i + 1);
    if (silc_envelope_csr_complex(&A, N, N, rp, ci, (const double *)v)) {
        CHECK(0, "envelope: %s", silc_errmsg());
        goto out;
    }
    cmatvec(&A, xt, b);
    CHECK(silc_put(c, "S", &A) == 0 && put_cvec(c, "b", b, N) == 0, "put: %s", silc_context_errmsg(c));
    run(c, "A = dense(S)");
    /* Unrefined: zgetrf's growth leaves a backward error far above eps. */
    info = solve_into(c, "refine = 0; verify = off", x0, N);
    be0 = cbackward(&A, x0, b);
    CHECK(info && tl_contains(info, "zgetrf") && be0 > 1e-10, "unrefined backward error %.2g: %s", be0,
          info ? info : "");
    CHECK(fabs(tl_field(info, "backward error") - be0) <= 0.01 * be0, "unrefined: reported %g, here %g",
          tl_field(info, "backward error"), be0);
    /* One step of complex refinement with the same factorization. */
    info = solve_into(c, "refine = 1", x1, N);
    be1 = cbackward(&A, x1, b);
    CHECK(info && tl_contains(info, "refinement: 1 step") && tl_contains(info, "reused factorization: yes"),
          "refined: %s", info ? info : "");
    CHECK(be1 <= 4 * DBL_EPSILON && be1 < 1e-6 * be0, "refined backward error %.2g (before %.2g)", be1, be0);
    CHECK(fabs(tl_field(info, "backward error") - be1) <= 0.01 * be1 + 1e-20, "refined: reported %g, here %g",
          tl_field(info, "backward error"), be1);
    CHECK(fabs(tl_field(info, "backward error before") - be0) <= 0.01 * be0, "before: reported %g, here %g",
          tl_field(info, "backward error before"), be0);
    CHECK(crel(x1, xt, N) < 1e-13 && crel(x0, xt, N) > 1e3 * crel(x1, xt, N),
          "forward error %.2g refined, %.2g unrefined", crel(x1, xt, N), crel(x0, xt, N));
out:
    silc_envelope_free(&A);
    silc_close(&c);
}

/* ---- complex band values in Matrix Market ----------------------------------------- */

static void test_band_mm(void)
{
    silc_context *c = open_ctx();
    silc_envelope_t e, back;
    char path[1024], err[256];
    FILE *f;
    int64_t count = 0;
    memset(&e, 0, sizeof e);
    memset(&back, 0, sizeof back);
    if (!c) return;
    /* 5x5 tridiagonal with an entry of zero real part (2,3) and a zero (4,5). */
    run(c, "T = sparse([1 2 3 4 5 1 2 3 4 2 3 4 5], [1 2 3 4 5 2 3 4 5 1 2 3 4], "
           "[2+1i, 3, 4-2i, 5, 6i, -1, 7i, 0.5, 0, 1+1i, -2, 3-3i, 1e-300i], 5, 5)");
    run(c, "B = band(T, 1, 1)");
    if (silc_get_complex(c, &e, "B")) {
        CHECK(0, "get B: %s", silc_context_errmsg(c));
        goto out;
    }
    CHECK(e.format == SILC_BAND_COMPLEX && e.kl == 1 && e.ku == 1, "B is a complex band value (format %d)",
          (int)e.format);
    snprintf(path, sizeof path, "%s/tests/test_complex_iter_band.mtx", SILC_BINARY_DIR);
    f = fopen(path, "w");
    CHECK(f && silc_mm_write(&e, f) == 0, "write: %s", silc_errmsg());
    if (f) fclose(f);
    CHECK(silc_mm_read(&back, path, err, sizeof err) == 0, "read back: %s", err);
    if (back.format == SILC_CSR_COMPLEX && back.m == 5 && back.n == 5) {
        double complex full[25], got[25];
        CHECK(silc_envelope_to_dense(&e, (double *)full) == 0 && silc_envelope_to_dense(&back, (double *)got) == 0,
              "to dense");
        for (int k = 0; k < 25; k++) {
            CHECK(full[k] == got[k], "entry %d: %g%+gi read back as %g%+gi", k, creal(full[k]), cimag(full[k]),
                  creal(got[k]), cimag(got[k]));
            count += full[k] != 0;
        }
        CHECK(back.nnz == count && count == 12, "%lld entries written, %lld nonzero", (long long)back.nnz,
              (long long)count);
    } else {
        CHECK(0, "read back as format %d, %lldx%lld", (int)back.format, (long long)back.m, (long long)back.n);
    }
    remove(path);
out:
    silc_envelope_free(&e);
    silc_envelope_free(&back);
    silc_close(&c);
}

int main(void)
{
    printf("complex Helmholtz by lis-style\n");
    test_helmholtz();
    printf("shared complex matrices by lis-style\n");
    test_shared();
    printf("complex refinement\n");
    test_refinement();
    printf("complex band to Matrix Market\n");
    test_band_mm();
    return check_done();
}
