/*
 * test_plugin_suitesparse.c -- the four SuiteSparse backends against exact
 * solutions and against the reference backend.
 *
 * Each backend is forced through its class in a context of its own
 * (umfpack and klu: solve.sparse; cholmod: solve.sparse.spd; spqr:
 * solve.rect); a fifth context sends the same classes to "reference".
 *   - generated systems with exact solutions x_i = 1 + i/n (b = A x computed
 *     here): the 2-D Laplacian (SPD) and a 2-D convection-diffusion operator
 *     (unsymmetric); the forward error must be below 1e3 n eps cond;
 *   - shared matrices (cholmod: bcsstk16, 1138_bus; umfpack and klu: memplus,
 *     rajat19, west0479, sherman1; spqr: illc1033, ash219) with b = A * ones,
 *     compared with the reference backend within the same cond-scaled bound
 *     (cond from the reference's 1-norm estimate), backward error < 1e-10;
 *   - singular matrices (neumann, mbeacxc): the solve fails naming the library
 *     function, or succeeds with a "singular to working precision" warning;
 *   - a symmetric indefinite matrix with positive diagonal under cholmod: the
 *     dispatcher falls back to LU and `info` says so;
 *   - factor reuse (second solve with the same A), and a new value with the
 *     same pattern (A2 = 2 * A): the note says the symbolic analysis was
 *     reused; KLU refactors into the factors of a value that died (A = 3 * A);
 *   - CHOLMOD's supernodal factor, solved by the plugin's own triangular
 *     sweeps (cholmod.c, ch_super_solve): three exact columns at once, each
 *     equal to its solve alone, and a Crank-Nicolson loop u = A \ (B * u)
 *     whose u matches the reference backend's loop, and no thread started
 *     by CHOLMOD's OpenMP regions at SILC's thread count 1;
 *   - several and sparse right-hand sides; least squares (tall, inconsistent)
 *     and the minimum-norm (full row rank) or basic (deficient) solution of
 *     an underdetermined system.
 * Every `info` must name the backend.  Timings are printed.
 */
#define _POSIX_C_SOURCE 200809L /* clock_gettime */
#include <ctype.h>
#include <dirent.h>
#include <float.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "check.h"
#include "silc.h"
#include "testlib.h"

/* ---- output capture and helpers ------------------------------------------------ */

static silc_context *open_ctx(const char *const *classes, const char *backend)
{
    silc_context *c = NULL;
    char cmd[192];
    if (silc_open(&c, NULL)) {
        fprintf(stderr, "silc_open: %s\n", c ? silc_context_errmsg(c) : silc_errmsg());
        return NULL;
    }
    silc_set_output(c, tl_out_fn, NULL);
    for (; *classes; classes++) {
        snprintf(cmd, sizeof cmd, "set dispatch.%s = %s", *classes, backend);
        CHECK(silc_exec(c, cmd) == 0, "%s: %s", cmd, silc_context_errmsg(c));
    }
    return c;
}

static double now(void)
{
    struct timespec t;
    clock_gettime(CLOCK_MONOTONIC, &t);
    return (double)t.tv_sec + 1e-9 * (double)t.tv_nsec;
}

static double bound(int64_t n, double cond)
{
    double b = 1e3 * (double)n * DBL_EPSILON * (cond > 1 ? cond : 1);
    return b < 1e-1 ? b : 1e-1;
}

/* ---- generated matrices -------------------------------------------------------- */

/* 5-point operator on a k x k grid: 4 + shift on the diagonal, -1 -/+ beta to
 * the west/east (beta = 0: the Laplacian, symmetric). */
static void grid(silc_envelope_t *e, int64_t k, double beta, double shift)
{
    CHECK(tl_grid2d(e, k, beta, 4 + shift) == 0, "grid envelope");
}

/* x = A \ b in c (A, b already there) with the exact solution xt known. */
static void check_exact(silc_context *c, const char *backend, const char *label,
                        const silc_envelope_t *A, const double *xt)
{
    int64_t n = A->n;
    double *x, cond, be, t;
    const char *in;
    t = now();
    if (silc_exec(c, "x = A \\ b")) {
        CHECK(0, "%s %s: x = A \\ b: %s", backend, label, silc_context_errmsg(c));
        return;
    }
    t = now() - t;
    in = tl_out_info(c, "x");
    CHECK(tl_contains(in, backend), "%s %s: info does not name the backend:\n%s", backend, label, in);
    cond = tl_out_number(in, "condition estimate: ");
    be = tl_out_number(in, "backward error: ");
    CHECK(be >= 0 && be < 1e-12, "%s %s: backward error %g", backend, label, be);
    x = tl_get_dense_checked(c, "x", n, 1);
    if (!x) return;
    CHECK(tl_rel_diff(x, xt, n) <= bound(n, cond), "%s %s: forward error %.3g > %.3g (cond %.3g)",
          backend, label, tl_rel_diff(x, xt, n), bound(n, cond), cond);
    printf("  %-22s %-28s n=%-6lld %.4f s  cond %.3g  backward error %.2g\n", backend, label,
           (long long)n, t, cond, be);
    free(x);
}

/* ---- the four backends on generated systems ----------------------------------- */

static void test_generated(silc_context *c, const char *backend, int symmetric_only)
{
    silc_envelope_t A;
    int64_t k = 60, n = k * k;
    double *xt = malloc((size_t)n * sizeof *xt), *b = malloc((size_t)n * sizeof *b);
    for (int64_t i = 0; i < n; i++) xt[i] = 1 + (double)i / (double)n;
    grid(&A, k, 0, 0);
    tl_csr_matvec(&A, xt, b);
    tl_put_checked(c, "A", &A);
    tl_put_dense_checked(c, "b", n, 1, b);
    check_exact(c, backend, "2-D Laplacian 60x60", &A, xt);
    silc_envelope_free(&A);
    if (!symmetric_only) {
        grid(&A, k, 0.4, 0);
        tl_csr_matvec(&A, xt, b);
        tl_put_checked(c, "A", &A);
        tl_put_dense_checked(c, "b", n, 1, b);
        check_exact(c, backend, "convection-diffusion 60x60", &A, xt);
        silc_envelope_free(&A);
    }
    free(xt);
    free(b);
}

/* SPQR: the Laplacian stacked on the identity (tall, full rank, consistent:
 * the least-squares solution is exact) and, forced per call, square. */
static void test_generated_qr(silc_context *c)
{
    silc_envelope_t L, A;
    int64_t k = 40, n = k * k, nz;
    double *xt = malloc((size_t)n * sizeof *xt), *b = malloc((size_t)(2 * n) * sizeof *b), *x;
    int64_t *rp = malloc((size_t)(2 * n + 1) * sizeof *rp), *ci = malloc((size_t)(6 * n) * sizeof *ci);
    double *v = malloc((size_t)(6 * n) * sizeof *v);
    const char *in;
    for (int64_t i = 0; i < n; i++) xt[i] = 1 + (double)i / (double)n;
    grid(&L, k, 0, 0);
    nz = L.rowptr[n];
    memcpy(rp, L.rowptr, (size_t)(n + 1) * sizeof *rp);
    memcpy(ci, L.colind, (size_t)nz * sizeof *ci);
    memcpy(v, L.values, (size_t)nz * sizeof *v);
    for (int64_t i = 0; i < n; i++) ci[nz + i] = i, v[nz + i] = 1, rp[n + 1 + i] = nz + i + 1;
    CHECK(silc_envelope_csr(&A, 2 * n, n, rp, ci, v) == 0, "tall envelope");
    tl_csr_matvec(&A, xt, b);
    tl_put_checked(c, "A", &A);
    tl_put_dense_checked(c, "b", 2 * n, 1, b);
    check_exact(c, "suitesparse.spqr", "[Laplacian; I] 3200x1600", &A, xt);
    tl_csr_matvec(&L, xt, b);
    tl_put_checked(c, "A", &L);
    tl_put_dense_checked(c, "b", n, 1, b);
    CHECK(silc_exec(c, "x = solve(A, b, \"backend = suitesparse.spqr\")") == 0, "spqr square: %s",
          silc_context_errmsg(c));
    in = tl_out_info(c, "x");
    CHECK(tl_contains(in, "suitesparse.spqr") && tl_contains(in, "full rank 1600"), "spqr square:\n%s", in);
    x = tl_get_dense_checked(c, "x", n, 1);
    if (x) CHECK(tl_rel_diff(x, xt, n) < 1e-10, "spqr square: forward error %.3g", tl_rel_diff(x, xt, n));
    free(x);
    free(xt);
    free(b);
    free(rp);
    free(ci);
    free(v);
    silc_envelope_free(&L);
    silc_envelope_free(&A);
}

/* Second solve reuses the factors; A2 = 2 * A reuses the symbolic analysis. */
static void test_reuse(silc_context *c, const char *backend, int symmetric)
{
    silc_envelope_t A;
    int64_t k = 40, n = k * k;
    double *b = malloc((size_t)n * sizeof *b), *x, *x2;
    const char *in;
    for (int64_t i = 0; i < n; i++) b[i] = sin((double)i);
    grid(&A, k, symmetric ? 0 : 0.3, 0);
    tl_put_checked(c, "A", &A);
    tl_put_dense_checked(c, "b", n, 1, b);
    CHECK(silc_exec(c, "x = A \\ b; y = A \\ (2 * b)") == 0, "%s reuse: %s", backend,
          silc_context_errmsg(c));
    in = tl_out_info(c, "x");
    CHECK(tl_contains(in, "reused factorization: no"), "%s: first solve reused?\n%s", backend, in);
    in = tl_out_info(c, "y");
    CHECK(tl_contains(in, "reused factorization: yes"), "%s: second solve did not reuse:\n%s", backend, in);
    CHECK(silc_exec(c, "A2 = 2 * A; x2 = A2 \\ b") == 0, "%s refactor: %s", backend, silc_context_errmsg(c));
    in = tl_out_info(c, "x2");
    CHECK(tl_contains(in, "symbolic analysis reused"), "%s: same pattern, symbolic not reused:\n%s",
          backend, in);
    CHECK(tl_contains(in, "reused factorization: no"), "%s: A2 is a new value:\n%s", backend, in);
    x = tl_get_dense_checked(c, "x", n, 1);
    x2 = tl_get_dense_checked(c, "x2", n, 1);
    if (x && x2) {
        for (int64_t i = 0; i < n; i++) x2[i] *= 2;
        CHECK(tl_rel_diff(x2, x, n) < 1e-12, "%s: 2 * (2A \\ b) != A \\ b (%.3g)", backend, tl_rel_diff(x2, x, n));
    }
    free(x2);
    if (strstr(backend, "klu")) {
        /* A = 3 * A: the old A dies and gives its factors back; the new value
         * is refactored into them without pivot search. */
        CHECK(silc_exec(c, "clear A2 x2; A = 3 * A; x3 = A \\ b") == 0, "klu refactor: %s",
              silc_context_errmsg(c));
        in = tl_out_info(c, "x3");
        CHECK(tl_contains(in, "klu_l_refactor"), "klu: no numeric refactor:\n%s", in);
        x2 = tl_get_dense_checked(c, "x3", n, 1);
        if (x && x2) {
            for (int64_t i = 0; i < n; i++) x2[i] *= 3;
            CHECK(tl_rel_diff(x2, x, n) < 1e-12, "klu: 3 * (3A \\ b) != A \\ b (%.3g)", tl_rel_diff(x2, x, n));
        }
        free(x2);
    }
    free(x);
    free(b);
    silc_envelope_free(&A);
}

/* Several right-hand sides, dense and sparse. */
static void test_multi_rhs(silc_context *c, const char *backend)
{
    silc_envelope_t A;
    int64_t k = 20, n = k * k;
    double *B = malloc((size_t)(3 * n) * sizeof *B), *X, *x;
    for (int64_t i = 0; i < 3 * n; i++) B[i] = cos((double)i);
    grid(&A, k, 0, 0);
    tl_put_checked(c, "A", &A);
    tl_put_dense_checked(c, "B", n, 3, B);
    CHECK(silc_exec(c, "X = A \\ B; Xs = A \\ sparse(B); x = A \\ B[:, 2]") == 0, "%s multi rhs: %s",
          backend, silc_context_errmsg(c));
    X = tl_get_dense_checked(c, "X", n, 3);
    x = tl_get_dense_checked(c, "x", n, 1);
    if (X && x) CHECK(tl_rel_diff(X + n, x, n) < 1e-13, "%s: column 2 of A\\B differs from A\\b", backend);
    free(x);
    x = tl_get_dense_checked(c, "Xs", n, 3);
    if (X && x) CHECK(tl_rel_diff(X, x, 3 * n) < 1e-13, "%s: A\\sparse(B) differs from A\\B", backend);
    free(x);
    free(X);
    free(B);
    silc_envelope_free(&A);
}

/* Threads of this process (CHOLMOD's OpenMP regions must not add any at
 * SILC's thread count 1: ss_cholmod_factorize). */
static int tl_count_tasks(void)
{
    int count = 0;
    DIR *d = opendir("/proc/self/task");
    struct dirent *e;
    if (!d) return -1;
    while ((e = readdir(d)))
        if (e->d_name[0] != '.') count++;
    closedir(d);
    return count;
}

/* CHOLMOD's supernodal factor, which the plugin solves itself (ch_super_solve):
 * the 80 x 80 Laplacian (6400 unknowns: CHOLMOD's rule picks supernodal) with
 * three exact columns X0(:, j) = 1 + j + i/n, solved at once and one at a
 * time; and 10 Crank-Nicolson steps u = A \ (B * u) (dt / h^2 = 40, as the
 * diffusion example) against the same loop through the reference backend.
 * It runs before any other CHOLMOD solve of the process: its factorizations
 * are the first that could start OpenMP threads, and must start none. */
static void test_cholmod_supernodal(silc_context *c, silc_context *r)
{
    silc_envelope_t L;
    int64_t k = 80, n = k * k, i, j;
    double *X0 = malloc((size_t)(3 * n) * sizeof *X0), *B = malloc((size_t)(3 * n) * sizeof *B);
    double *X, *x, *u, *ur, be, cond;
    int tasks;
    const char *in;
    const char *loop = "I = sparse(1:6400, 1:6400, ones(6400, 1), 6400, 6400); A = I + 20 * L; Bm = I - 20 * L; "
                       "u = ones(6400, 1); "
                       "for s = 1:10 u = A \\ (Bm * u); end";
    for (j = 0; j < 3; j++)
        for (i = 0; i < n; i++) X0[j * n + i] = 1 + (double)j + (double)i / (double)n;
    grid(&L, k, 0, 0);
    for (j = 0; j < 3; j++) tl_csr_matvec(&L, X0 + j * n, B + j * n);
    tl_put_checked(c, "L", &L);
    tl_put_dense_checked(c, "B", n, 3, B);
    tasks = tl_count_tasks();
    CHECK(silc_exec(c, "X = L \\ B; x = L \\ B(:, 3)") == 0, "cholmod supernodal: %s", silc_context_errmsg(c));
    in = tl_out_info(c, "X");
    CHECK(tl_contains(in, "supernodal"), "cholmod: the 80 x 80 Laplacian was not factored supernodally:\n%s", in);
    be = tl_out_number(in, "backward error: ");
    cond = tl_out_number(in, "condition estimate: ");
    CHECK(be >= 0 && be < 1e-14, "cholmod supernodal: backward error %g", be);
    X = tl_get_dense_checked(c, "X", n, 3);
    x = tl_get_dense_checked(c, "x", n, 1);
    if (X) CHECK(tl_rel_diff(X, X0, 3 * n) <= bound(n, cond), "cholmod supernodal: forward error %.3g (cond %.3g)",
                 tl_rel_diff(X, X0, 3 * n), cond);
    if (X && x) CHECK(memcmp(X + 2 * n, x, (size_t)n * sizeof *x) == 0,
                      "cholmod supernodal: column 3 solved with the others differs from its solve alone");
    free(X);
    free(x);
    /* The loop: L is the grid's 4-on-the-diagonal Laplacian (h = 1), so
     * A = I + 20 L is Crank-Nicolson's matrix at dt / h^2 = 40. */
    tl_put_checked(r, "L", &L);
    CHECK(silc_exec(c, loop) == 0, "cholmod loop: %s", silc_context_errmsg(c));
    CHECK(silc_exec(r, loop) == 0, "reference loop: %s", silc_context_errmsg(r));
    in = tl_out_info(c, "u");
    CHECK(tl_contains(in, "suitesparse.cholmod") && tl_contains(in, "reused factorization: yes"),
          "cholmod loop: the last step was not a reused CHOLMOD solve:\n%s", in);
    u = tl_get_dense_checked(c, "u", n, 1);
    ur = tl_get_dense_checked(r, "u", n, 1);
    if (u && ur) CHECK(tl_rel_diff(u, ur, n) < 1e-12, "cholmod loop: u differs from the reference's by %.3g",
                       tl_rel_diff(u, ur, n));
    free(u);
    free(ur);
    CHECK(tl_count_tasks() == tasks, "cholmod: the factorizations at thread count 1 started %d more threads",
          tl_count_tasks() - tasks);
    silc_exec(c, "clear L B X x I A Bm u");
    silc_exec(r, "clear L I A Bm u");
    free(X0);
    free(B);
    silc_envelope_free(&L);
}

/* ---- shared matrices ------------------------------------------------------------ */

/* Solves with the backend in c and the reference in r; they must agree. */
static void test_shared(silc_context *c, silc_context *r, const char *backend, const char *file)
{
    silc_envelope_t A;
    double *x, *xr, cond, mine, be, t, tr;
    const char *in;
    int64_t n;
    if (tl_read_shared(file, &A)) return;
    n = A.n;
    tl_put_checked(c, "A", &A);
    tl_put_checked(r, "A", &A);
    t = now();
    CHECK(silc_exec(c, "b = A * ones(cols(A), 1); x = A \\ b") == 0, "%s %s: %s", backend, file,
          silc_context_errmsg(c));
    t = now() - t;
    tr = now();
    CHECK(silc_exec(r, "b = A * ones(cols(A), 1); x = A \\ b") == 0, "reference %s: %s", file,
          silc_context_errmsg(r));
    tr = now() - tr;
    in = tl_out_info(c, "x");
    CHECK(tl_contains(in, backend), "%s %s: info does not name the backend:\n%s", backend, file, in);
    be = tl_out_number(in, "backward error: ");
    mine = tl_out_number(in, "condition estimate: ");
    CHECK(be >= 0 && be < 1e-10, "%s %s: backward error %g", backend, file, be);
    cond = tl_out_number(tl_out_info(r, "x"), "condition estimate: ");
    /* Above 1e8 the backend's estimate must be a real one, not a pivot ratio. */
    if (cond > 1e8 && !strstr(backend, "spqr"))
        CHECK(mine >= cond / 10 && mine <= cond * 10, "%s %s: condition estimate %.3g, reference %.3g",
              backend, file, mine, cond);
    x = tl_get_dense_checked(c, "x", n, 1);
    xr = tl_get_dense_checked(r, "x", n, 1);
    if (x && xr)
        CHECK(tl_rel_diff(x, xr, n) <= 2 * bound(n, cond),
              "%s %s: differs from reference by %.3g > %.3g (cond %.3g)", backend, file,
              tl_rel_diff(x, xr, n), 2 * bound(n, cond), cond);
    printf("  %-22s %-14s %5lldx%-5lld %8.4f s (reference %8.4f s)  cond %.3g (reference %.3g)  "
           "backward error %.2g\n",
           backend, file, (long long)A.m, (long long)A.n, t, tr, mine, cond, be);
    free(x);
    free(xr);
    silc_envelope_free(&A);
}

/* A singular matrix: an error naming the library function, or a warning. */
static void test_singular(silc_context *c, const char *backend, const char *fn, const char *file)
{
    silc_envelope_t A;
    if (tl_read_shared(file, &A)) return;
    tl_put_checked(c, "A", &A);
    if (silc_exec(c, "b = A * ones(cols(A), 1); x = A \\ b")) {
        const char *msg = silc_context_errmsg(c);
        CHECK(tl_contains(msg, fn) && tl_contains(msg, "singular"), "%s %s: message should name %s: %s",
              backend, file, fn, msg);
        printf("  %-22s %-14s error: %s\n", backend, file, msg);
    } else {
        const char *w = silc_context_warnings(c);
        CHECK(tl_contains(w, "singular to working precision"), "%s %s: singular matrix solved silently",
              backend, file);
        printf("  %-22s %-14s warning: %s", backend, file, w);
    }
    silc_envelope_free(&A);
}

/* Symmetric, positive diagonal, indefinite: CHOLMOD fails, LU takes over. */
static void test_not_spd(void)
{
    static const char *const cls[] = {"solve.sparse.spd", NULL};
    silc_context *c = open_ctx(cls, "suitesparse.cholmod, suitesparse.umfpack");
    silc_envelope_t A;
    int64_t k = 20, n = k * k;
    double *xt = malloc((size_t)n * sizeof *xt), *b = malloc((size_t)n * sizeof *b), *x;
    const char *in;
    if (!c) return;
    for (int64_t i = 0; i < n; i++) xt[i] = 1 + (double)i / (double)n;
    grid(&A, k, 0, -3.7); /* diagonal 0.3, eigenvalues in (-3.7, 4.3) */
    tl_csr_matvec(&A, xt, b);
    tl_put_checked(c, "A", &A);
    tl_put_dense_checked(c, "b", n, 1, b);
    tl_out()[0] = '\0';
    CHECK(silc_exec(c, "explain x = A \\ b") == 0 && tl_contains(tl_out(), "suitesparse.cholmod -> would run"),
          "explain should pick cholmod:\n%s", tl_out());
    CHECK(silc_exec(c, "x = A \\ b") == 0, "not SPD: %s", silc_context_errmsg(c));
    in = tl_out_info(c, "x");
    CHECK(tl_contains(in, "suitesparse.umfpack") && tl_contains(in, "Cholesky failed"),
          "not SPD: expected the LU fallback in info:\n%s", in);
    x = tl_get_dense_checked(c, "x", n, 1);
    if (x) CHECK(tl_rel_diff(x, xt, n) < 1e-8, "not SPD: forward error %.3g", tl_rel_diff(x, xt, n));
    free(x);
    free(xt);
    free(b);
    silc_envelope_free(&A);
    silc_close(&c);
}

/* Least squares: tall inconsistent vs reference; wide: minimum norm, or basic
 * when the row rank is deficient. */
static void test_rect_extra(silc_context *c, silc_context *r)
{
    silc_envelope_t A;
    double *x, *xr, *g, cond;
    int64_t m, n, nnz = 0;
    const char *in;
    if (tl_read_shared("illc1033.mtx", &A)) return;
    m = A.m;
    n = A.n;
    g = malloc((size_t)m * sizeof *g);
    for (int64_t i = 0; i < m; i++) g[i] = sin(3.0 * (double)i);
    tl_put_checked(c, "A", &A);
    tl_put_checked(r, "A", &A);
    tl_put_dense_checked(c, "g", m, 1, g);
    tl_put_dense_checked(r, "g", m, 1, g);
    CHECK(silc_exec(c, "x = A \\ g; y = A \\ g") == 0, "spqr lsq: %s", silc_context_errmsg(c));
    CHECK(silc_exec(r, "x = A \\ g") == 0, "reference lsq: %s", silc_context_errmsg(r));
    in = tl_out_info(c, "y");
    CHECK(tl_contains(in, "reused factorization: yes") && tl_contains(in, "suitesparse.spqr"),
          "spqr: second solve did not reuse the QR:\n%s", in);
    CHECK(tl_contains(in, "least-squares"), "spqr: note should say least squares:\n%s", in);
    cond = tl_out_number(tl_out_info(r, "x"), "condition estimate: ");
    x = tl_get_dense_checked(c, "x", n, 1);
    xr = tl_get_dense_checked(r, "x", n, 1);
    if (x && xr)
        CHECK(tl_rel_diff(x, xr, n) <= 1e-6, "spqr lsq illc1033: differs from reference by %.3g (cond %.3g)",
              tl_rel_diff(x, xr, n), cond);
    free(x);
    free(xr);
    free(g);
    silc_envelope_free(&A);

    /* Underdetermined: A = ash219' is 85 x 219 of full row rank.  SPQR
     * factors A' and returns the minimum-norm solution, as the reference
     * does, with a condition estimate near the reference's. */
    if (tl_read_shared("ash219.mtx", &A)) return;
    tl_put_checked(c, "B", &A);
    tl_put_checked(r, "B", &A);
    CHECK(silc_exec(c, "A = trans(B); b = A * ones(cols(A), 1); x = A \\ b; r = b - A * x") == 0,
          "spqr wide: %s", silc_context_errmsg(c));
    CHECK(silc_exec(r, "A = trans(B); b = A * ones(cols(A), 1); x = A \\ b") == 0,
          "reference wide: %s", silc_context_errmsg(r));
    in = tl_out_info(c, "x");
    CHECK(tl_contains(in, "minimum-norm solution") && tl_contains(in, "of A'"),
          "spqr wide: note should say minimum norm, QR of A':\n%s", in);
    cond = tl_out_number(in, "condition estimate: ");
    {
        double cref = tl_out_number(tl_out_info(r, "x"), "condition estimate: ");
        CHECK(cond > cref / 10 && cond < cref * 10, "spqr wide: condition estimate %.3g, reference %.3g",
              cond, cref);
    }
    x = tl_get_dense_checked(c, "x", A.m, 1);
    xr = tl_get_dense_checked(r, "x", A.m, 1);
    g = tl_get_dense_checked(c, "r", A.n, 1);
    if (x && xr && g) {
        double rn = 0;
        for (int64_t i = 0; i < A.n; i++) rn = fmax(rn, fabs(g[i]));
        CHECK(rn < 1e-12, "spqr wide: residual %.3g", rn);
        CHECK(tl_rel_diff(x, xr, A.m) < 1e-10, "spqr wide: not the minimum-norm solution (%.3g from the reference)",
              tl_rel_diff(x, xr, A.m));
    }
    free(x);
    free(xr);
    free(g);
    /* Deficient row rank (a row repeated): no minimum-norm formula from A';
     * SPQR factors A and gives a basic solution, rank and cond = Inf said. */
    CHECK(silc_exec(c, "W = [A; A[1, :]]; c = W * ones(cols(W), 1); x = W \\ c; r = c - W * x") == 0,
          "spqr wide deficient: %s", silc_context_errmsg(c));
    in = tl_out_info(c, "x");
    CHECK(tl_contains(in, "basic solution") && tl_contains(in, "rank 85 of 86x219") &&
              tl_contains(in, "condition estimate: inf"),
          "spqr wide deficient: note should say basic solution, rank 85:\n%s", in);
    x = tl_get_dense_checked(c, "x", A.m, 1);
    g = tl_get_dense_checked(c, "r", A.n + 1, 1);
    if (x && g) {
        double rn = 0;
        for (int64_t i = 0; i < A.m; i++) nnz += x[i] != 0;
        for (int64_t i = 0; i <= A.n; i++) rn = fmax(rn, fabs(g[i]));
        CHECK(rn < 1e-12, "spqr wide deficient: residual %.3g", rn);
        CHECK(nnz <= A.n, "spqr wide deficient: basic solution has %lld nonzeros > rank %lld",
              (long long)nnz, (long long)A.n);
    }
    free(x);
    free(g);
    silc_envelope_free(&A);
}

/* The condest option replaces the crude estimate by Hager/Higham's. */
static void test_condest(silc_context *c, silc_context *r, const char *backend)
{
    silc_envelope_t A;
    double cond, cref;
    const char *in;
    if (tl_read_shared("sherman1.mtx", &A)) return;
    tl_put_checked(c, "A", &A);
    tl_put_checked(r, "A", &A);
    CHECK(silc_exec(c, "b = A * ones(cols(A), 1); x = solve(A, b, \"suitesparse.condest = true\")") == 0,
          "%s condest: %s", backend, silc_context_errmsg(c));
    CHECK(silc_exec(r, "b = A * ones(cols(A), 1); x = A \\ b") == 0, "reference: %s", silc_context_errmsg(r));
    in = tl_out_info(c, "x");
    cond = tl_out_number(in, "condition estimate: ");
    cref = tl_out_number(tl_out_info(r, "x"), "condition estimate: ");
    CHECK(tl_contains(tl_out_info(c, "x"), "Hager"), "%s: condest note missing:\n%s", backend, tl_out());
    CHECK(cond > 0 && cref > 0 && cond <= 10 * cref && cref <= 10 * cond,
          "%s: condest %.3g vs reference %.3g", backend, cond, cref);
    silc_envelope_free(&A);
}

int main(void)
{
    static const char *const sparse_cls[] = {"solve.sparse", NULL};
    static const char *const spd_cls[] = {"solve.sparse.spd", NULL};
    static const char *const rect_cls[] = {"solve.rect", NULL};
    static const char *const ref_cls[] = {"solve.sparse", "solve.sparse.spd", "solve.rect", NULL};
    static const char *const unsym[] = {"memplus.mtx", "rajat19.mtx", "west0479.mtx", "sherman1.mtx"};
    static const char *const spd[] = {"bcsstk16.mtx", "1138_bus.mtx"};
    static const char *const rect[] = {"illc1033.mtx", "ash219.mtx"};
    static const char *const singular[] = {"neumann.mtx", "mbeacxc.mtx"};
    silc_context *um = open_ctx(sparse_cls, "suitesparse.umfpack");
    silc_context *kl = open_ctx(sparse_cls, "suitesparse.klu");
    silc_context *ch = open_ctx(spd_cls, "suitesparse.cholmod");
    silc_context *qr = open_ctx(rect_cls, "suitesparse.spqr");
    silc_context *ref = open_ctx(ref_cls, "reference");
    size_t i;
    if (!um || !kl || !ch || !qr || !ref) return check_done();

    test_cholmod_supernodal(ch, ref);
    printf("generated systems (exact solutions):\n");
    test_generated(um, "suitesparse.umfpack", 0);
    test_generated(kl, "suitesparse.klu", 0);
    test_generated(ch, "suitesparse.cholmod", 1);
    test_generated_qr(qr);

    test_reuse(um, "suitesparse.umfpack", 0);
    test_reuse(kl, "suitesparse.klu", 0);
    test_reuse(ch, "suitesparse.cholmod", 1);
    test_multi_rhs(um, "suitesparse.umfpack");
    test_multi_rhs(kl, "suitesparse.klu");
    test_multi_rhs(ch, "suitesparse.cholmod");

    printf("shared matrices (against the reference backend):\n");
    for (i = 0; i < sizeof spd / sizeof spd[0]; i++) test_shared(ch, ref, "suitesparse.cholmod", spd[i]);
    for (i = 0; i < sizeof unsym / sizeof unsym[0]; i++) {
        test_shared(um, ref, "suitesparse.umfpack", unsym[i]);
        test_shared(kl, ref, "suitesparse.klu", unsym[i]);
    }
    for (i = 0; i < sizeof rect / sizeof rect[0]; i++) test_shared(qr, ref, "suitesparse.spqr", rect[i]);
    test_rect_extra(qr, ref);

    printf("singular matrices:\n");
    for (i = 0; i < sizeof singular / sizeof singular[0]; i++) {
        test_singular(um, "suitesparse.umfpack", "umfpack_dl_numeric", singular[i]);
        test_singular(kl, "suitesparse.klu", "klu_l_factor", singular[i]);
    }
    test_not_spd();
    test_condest(um, ref, "suitesparse.umfpack");
    test_condest(kl, ref, "suitesparse.klu");

    silc_close(&um);
    silc_close(&kl);
    silc_close(&ch);
    silc_close(&qr);
    silc_close(&ref);
    return check_done();
}
