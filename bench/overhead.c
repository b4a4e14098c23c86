/*
 * overhead.c -- what a SILC_EXEC costs beyond the arithmetic it asks for.
 *
 *     overhead [reps]          reps = EXECs per batch for tiny statements
 *                              (default 20000); each figure is the median of
 *                              5 batches
 *
 * Part 1, tiny statements: microseconds per silc_exec when the parse cache hits
 * (the same text every time, as in a time loop) and when it misses (each text
 * made unique by a trailing comment "# <serial>", so it is lexed and parsed
 * afresh, and its share of the cache's periodic emptying is included), next
 * to a plain C loop doing the same arithmetic.
 *
 * Part 2, a sparse solve: "x = A \ b" on the 5-point matrix I - L of a 100x100
 * grid (10000 unknowns) with A's factorization reused (A PUT once, factored by
 * a first untimed EXEC), the same with a fresh PUT of A before every EXEC (so it
 * is factored every time), "y = A * b" through SILC, and a tight C loop doing
 * one SpMV with the same matrix as a floor.  The reference solver itself is
 * internal and not callable through the public API, so the floor is SpMV, not a
 * direct triangular solve; each row says exactly what it times.  A solve EXEC
 * also includes the core's accuracy report (a residual SpMV and norms).
 *
 * Part 3, vector updates: `x += y` and `x = x + y` (copy-on-write: x's
 * array is updated in place when nothing else holds it) against `z = x + y`
 * (a new array), with and without a scaled y, for n = 1e3 .. 1e6, next to
 * the plain C loop.
 *
 * Written against the public API only.  Not run by the test suite.
 */
#define _POSIX_C_SOURCE 200809L
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "diffusion_common.h"
#include "timing.h"
#include "silc.h"

#define BATCHES 5

static silc_context *ctx;
static long serial; /* makes every uncached text unique across the whole run */
static volatile double sink;


static double median(double *v)
{
    return bench_median(v, BATCHES); /* BATCHES is odd: the middle one */
}

static int exec_or_die(const char *text)
{
    if (silc_exec(ctx, text)) {
        fprintf(stderr, "overhead: EXEC(\"%s\") failed: %s\n", text, silc_context_errmsg(ctx));
        return 1;
    }
    return 0;
}

static int put_or_die(const char *name, const silc_envelope_t *e)
{
    if (silc_put(ctx, name, e)) {
        fprintf(stderr, "overhead: PUT(\"%s\") failed: %s\n", name, silc_context_errmsg(ctx));
        return 1;
    }
    return 0;
}

/* Median seconds per EXEC of the same text (parse cache hit after the first). */
static int time_cached(const char *stmt, int reps, double *out)
{
    double t[BATCHES];
    if (exec_or_die(stmt)) return 1;
    for (int b = 0; b < BATCHES; b++) {
        double t0 = bench_now();
        for (int r = 0; r < reps; r++)
            if (exec_or_die(stmt)) return 1;
        t[b] = (bench_now() - t0) / reps;
    }
    *out = median(t);
    return 0;
}

/* Median seconds per EXEC of texts never seen before; the texts are made before
 * the clock starts so only the EXEC is timed. */
static int time_uncached(const char *stmt, int reps, double *out)
{
    double t[BATCHES];
    size_t width = strlen(stmt) + 32;
    char *texts = malloc((size_t)reps * width);
    if (!texts) return fprintf(stderr, "overhead: out of memory\n"), 1;
    for (int b = 0; b < BATCHES; b++) {
        for (int r = 0; r < reps; r++)
            snprintf(texts + (size_t)r * width, width, "%s # %ld", stmt, serial++);
        double t0 = bench_now();
        for (int r = 0; r < reps; r++)
            if (exec_or_die(texts + (size_t)r * width)) return free(texts), 1;
        t[b] = (bench_now() - t0) / reps;
    }
    free(texts);
    *out = median(t);
    return 0;
}

/* The same arithmetic in plain C, per operation; kind 0: y = x + x (n = 10),
 * kind 1: y = A * x (10x10 dense, column-major). */
static double time_plain(int kind, int reps)
{
    double A[100], x[10], y[10], t[BATCHES];
    for (int k = 0; k < 100; k++) A[k] = 1.0 / (k + 1);
    for (int k = 0; k < 10; k++) x[k] = k + 1;
    for (int b = 0; b < BATCHES; b++) {
        double t0 = bench_now();
        for (int r = 0; r < reps; r++) {
            if (kind == 0) {
                for (int i = 0; i < 10; i++) y[i] = x[i] + x[i];
            } else {
                for (int i = 0; i < 10; i++) y[i] = 0;
                for (int j = 0; j < 10; j++)
                    for (int i = 0; i < 10; i++) y[i] += A[i + 10 * j] * x[j];
            }
            sink = y[r % 10];
            x[r % 10] += 1e-300; /* keeps the compiler from hoisting the loop */
        }
        t[b] = (bench_now() - t0) / reps;
    }
    return median(t);
}

static int tiny_statements(int reps)
{
    static const struct { const char *stmt; int plain; } rows[] = {
        {"s = 1", -1}, {"y = x + x", 0}, {"y = A * x", 1}};
    silc_envelope_t x = {0}, A = {0};
    double xv[10], Av[100];
    for (int k = 0; k < 10; k++) xv[k] = k + 1;
    for (int k = 0; k < 100; k++) Av[k] = 1.0 / (k + 1);
    int rc = silc_envelope_vector(&x, 10, xv) || silc_envelope_dense(&A, 10, 10, Av) ||
             put_or_die("x", &x) || put_or_die("A", &A);
    silc_envelope_free(&x), silc_envelope_free(&A);
    if (rc) return 1;

    printf("Per-statement cost of EXEC, microseconds (median of %d batches of %d EXECs)\n",
           BATCHES, reps);
    printf("x: 10-vector, A: 10x10 dense.  cached = same text each time (parse cache hit);\n"
           "uncached = text made unique by a comment \"# <serial>\" (cache miss);\n"
           "plain C = the same arithmetic in a C loop.\n\n");
    printf("%-12s %12s %12s %12s %16s %16s\n", "statement", "cached us", "uncached us",
           "plain C us", "uncached/cached", "cached/plain C");
    for (size_t k = 0; k < sizeof rows / sizeof rows[0]; k++) {
        double hit, miss;
        if (time_cached(rows[k].stmt, reps, &hit) || time_uncached(rows[k].stmt, reps, &miss))
            return 1;
        printf("%-12s %12.3f %12.3f", rows[k].stmt, hit * 1e6, miss * 1e6);
        if (rows[k].plain >= 0) {
            double c = time_plain(rows[k].plain, reps * 10);
            printf(" %12.4f %16.2f %16.0f\n", c * 1e6, miss / hit, hit / c);
        } else {
            printf(" %12s %16.2f %16s\n", "-", miss / hit, "-");
        }
    }
    return 0;
}

/* Median seconds per call of one of the part-2 measurements. */
enum { SOLVE_REUSE, SOLVE_FRESH, PUT_ONLY, SPMV_SILC, SPMV_C };

static int time_sparse(int what, const silc_envelope_t *A, const double *b, int reps, double *out)
{
    double t[BATCHES];
    double *y = malloc((size_t)A->m * sizeof *y);
    if (!y) return fprintf(stderr, "overhead: out of memory\n"), 1;
    for (int bt = 0; bt < BATCHES; bt++) {
        double t0 = bench_now();
        for (int r = 0; r < reps; r++) {
            int rc = 0;
            switch (what) {
            case SOLVE_REUSE: rc = exec_or_die("x = A \\ b"); break;
            case SOLVE_FRESH: rc = put_or_die("A", A) || exec_or_die("x = A \\ b"); break;
            case PUT_ONLY: rc = put_or_die("A", A); break;
            case SPMV_SILC: rc = exec_or_die("y = A * b"); break;
            case SPMV_C:
                for (int64_t i = 0; i < A->m; i++) {
                    double s = 0;
                    for (int64_t p = A->rowptr[i]; p < A->rowptr[i + 1]; p++)
                        s += A->values[p] * b[A->colind[p]];
                    y[i] = s;
                }
                sink = y[r % A->m];
                break;
            }
            if (rc) return free(y), 1;
        }
        t[bt] = (bench_now() - t0) / reps;
    }
    free(y);
    *out = median(t);
    return 0;
}

static int sparse_solve(void)
{
    const int64_t n = 100, N = n * n;
    silc_envelope_t A = {0}, be = {0};
    double *b = malloc((size_t)N * sizeof *b);
    if (!b) return fprintf(stderr, "overhead: out of memory\n"), 1;
    for (int64_t k = 0; k < N; k++) b[k] = 1.0 + (double)(k % 7);
    /* I + c L with c = -1: the 5-point Laplacian shifted by I, SPD. */
    int rc = diff_shifted_laplacian(2, n, diff2d_h(n), -1.0, &A) || silc_envelope_vector(&be, N, b);
    if (!rc) rc = put_or_die("A", &A) || put_or_die("b", &be);
    double reuse = 0, fresh = 0, put = 0, spmv = 0, cspmv = 0;
    printf("\nSparse solve, A = I - L (5-point, %lldx%lld grid, %lld unknowns, nnz %lld),"
           " milliseconds per call\n(median of %d batches)\n", (long long)n, (long long)n,
           (long long)N, (long long)A.nnz, BATCHES);
    if (!rc) rc = exec_or_die("x = A \\ b"); /* factors A; later solves reuse it */
    if (!rc) rc = time_sparse(SOLVE_REUSE, &A, b, 20, &reuse);
    if (!rc) rc = time_sparse(SOLVE_FRESH, &A, b, 2, &fresh);
    if (!rc) rc = time_sparse(PUT_ONLY, &A, b, 20, &put);
    if (!rc) rc = time_sparse(SPMV_SILC, &A, b, 200, &spmv);
    if (!rc) rc = time_sparse(SPMV_C, &A, b, 200, &cspmv);
    if (!rc) {
        printf("%-58s %10.3f\n", "EXEC(\"x = A \\ b\"), factorization reused", reuse * 1e3);
        printf("%-58s %10.3f\n", "PUT A (new value) + EXEC(\"x = A \\ b\"): factor + solve", fresh * 1e3);
        printf("%-58s %10.3f\n", "PUT A alone (copy into SILC)", put * 1e3);
        printf("%-58s %10.3f\n", "EXEC(\"y = A * b\") (SpMV through SILC)", spmv * 1e3);
        printf("%-58s %10.3f\n", "plain C SpMV, same CSR arrays (floor)", cspmv * 1e3);
        printf("ratios: solve reused / C SpMV = %.1f, SILC SpMV / C SpMV = %.2f,"
               " fresh / reused = %.1f\n", reuse / cspmv, spmv / cspmv, fresh / reuse);
        /* The last timed solve factored a fresh A; solve twice so `info` shows
         * the reused path that the first row timed. */
        printf("\nHow the reused solve ran (info x):\n");
        fflush(stdout);
        rc = exec_or_die("x = A \\ b") || exec_or_die("x = A \\ b") || exec_or_die("info x");
    }
    silc_envelope_free(&A), silc_envelope_free(&be);
    free(b);
    return rc;
}

/* Copy-on-write (DESIGN 5): `x += y` and `x = x + y` write over x's array
 * when nothing else holds it; `z = x + y` makes a new one.  Plain C is the
 * same loop over arrays of the same size (the floor). */
static int in_place_updates(void)
{
    static const char *const stmts[] = {"z = x + y",       "x += y",       "x = x + y",
                                        "z = x + 0.5 * y", "x += 0.5 * y", "x = x + 0.5 * y"};
    enum { NSTMT = sizeof stmts / sizeof stmts[0] };
    printf("\nUpdates of an n-vector, microseconds per EXEC (median of %d batches)\n", BATCHES);
    printf("%-9s %10s %10s %10s %14s %12s %14s %13s\n", "n", "z = x + y", "x += y", "x = x + y",
           "z = x + 0.5*y", "x += 0.5*y", "x = x + 0.5*y", "plain C x+=y");
    for (int64_t n = 1000; n <= 1000000; n *= 10) {
        char text[96];
        double t[NSTMT], tc[BATCHES];
        int reps = n >= 1000000 ? 40 : n >= 100000 ? 400 : 4000;
        double *x = calloc((size_t)n, sizeof *x), *y = malloc((size_t)n * sizeof *y);
        if (!x || !y) return free(x), free(y), fprintf(stderr, "overhead: out of memory\n"), 1;
        snprintf(text, sizeof text, "x = zeros(%lld, 1); y = rand(%lld, 1)", (long long)n, (long long)n);
        if (exec_or_die(text)) return free(x), free(y), 1;
        for (int k = 0; k < NSTMT; k++)
            if (time_cached(stmts[k], reps, &t[k])) return free(x), free(y), 1;
        for (int64_t i = 0; i < n; i++) y[i] = (double)(i % 13) / 13;
        for (int b = 0; b < BATCHES; b++) {
            double t0 = bench_now();
            for (int r = 0; r < reps; r++) {
                for (int64_t i = 0; i < n; i++) x[i] += y[i];
                sink = x[r % n]; /* as time_plain: no folding of the repetitions */
            }
            tc[b] = (bench_now() - t0) / reps;
        }
        printf("%-9lld %10.2f %10.2f %10.2f %14.2f %12.2f %14.2f %13.2f\n", (long long)n, t[0] * 1e6,
               t[1] * 1e6, t[2] * 1e6, t[3] * 1e6, t[4] * 1e6, t[5] * 1e6, median(tc) * 1e6);
        free(x);
        free(y);
    }
    return exec_or_die("clear x y z");
}

int main(int argc, char **argv)
{
    int reps = 20000;
    if (argc > 2 || (argc == 2 && (reps = atoi(argv[1])) < 1)) {
        fprintf(stderr, "usage: overhead [reps]   (EXECs per batch for tiny statements, default 20000)\n");
        return 2;
    }
    if (silc_open(&ctx, NULL)) {
        fprintf(stderr, "overhead: %s\n", ctx ? silc_context_errmsg(ctx) : silc_errmsg());
        silc_close(&ctx);
        return 1;
    }
    int rc = tiny_statements(reps) || sparse_solve() || in_place_updates();
    silc_close(&ctx);
    return rc ? 1 : 0;
}
