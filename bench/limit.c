/*
 * limit.c -- how close SILC gets to the library it calls: SpMV against a
 * plain C CSR loop, and a dense solve against LAPACKE's dgesv (issue 30,
 * items 2 and 3).
 *
 *     limit [spmv|dense|all] [max_dense_n]    (default: all, n up to 3000)
 *     limit spmv [max_nnz]                     (the SpMV rows up to max_nnz:
 *                                               `limit spmv 1e4` for profiling)
 *     limit --cpu ...                          (times by the thread's CPU clock)
 *     limit bare [n] [solves]                  (SILC's bare dense solves alone,
 *                                               untimed: for callgrind)
 *
 * --cpu: on a shared machine a process waits for a core for longer than a
 * 5 us product takes, and wall-clock ratios scatter by +-25 % at a load
 * average of 18 on 2 cores; the thread's CPU time leaves the waiting out
 * (not the caches other processes evict).  Both sides run on this thread
 * (OPENBLAS_NUM_THREADS=1), so their CPU times compare.
 *
 * Part 1, SpMV: "y = A * x" through SILC against the plain C loop over the
 * same CSR arrays (int64 row pointers and column indices, as SILC holds
 * them), for the 5-point matrix of k x k grids with about 1e4, 1e5 and 1e6
 * nonzeros, after a 2 x 2 grid (12 nonzeros) whose SILC time is the fixed
 * cost of a statement (issue 30: parse, lookups, dispatch, the new value,
 * the memo's key, binding).  The two are timed in alternating batches (SILC, then C, then
 * SILC, ...) and the ratio taken batch by batch, so that load from other
 * processes shifts both sides of a ratio alike; the table shows the
 * medians, and the page faults of a SILC statement (0 when its result
 * array comes back from the allocator warm).  A last line times the 2 x 2
 * grid's statement right after the C loop has streamed the 1e5 matrix
 * through the caches: what a 1e5 product pays above the C loop is that
 * statement from L3, not the back-to-back fixed cost.
 *
 * Part 2, dense solve: "x = A \ b" (a fresh PUT of A before each EXEC, so
 * every EXEC factors) against LAPACK's dgesv (LAPACKE_dgesv_work: the
 * LAPACK call itself, without LAPACKE's NaN scan of A).  dgesv destroys
 * its input, so a program that keeps A solves a copy, and SILC, whose
 * values are immutable, factors a copy: the "dgesv" column times dgesv on
 * a copy made outside the timing, the "copy+dgesv" column includes the
 * memcpy of A into the (warm) array, the same work SILC does.  SILC runs
 * three times, each on its own new A: bare (`accuracy.condest = off`,
 * `solve.backward_error = on_request`: the accuracy report's extra work
 * left out), with the backward error (its residual pass over A, the
 * default `deferred` setting measures it on the first solve of every
 * factorization), and with the condition estimate as well (the default
 * report); "berr" and "condest" are the differences, medians of the
 * per-round differences.  A is random with a dominant diagonal (not
 * symmetric), b = A * ones.
 *
 * Instructions per statement, which no load changes (this VM has no
 * hardware counters): `valgrind --tool=callgrind --dump-before=spmv_row
 * limit --cpu spmv 1e4` writes one profile per SpMV row; silc_exec's
 * inclusive count over its calls is a statement, spmv_c's lines over
 * theirs the C loop (docs/overhead.md).
 *
 * Set OPENBLAS_NUM_THREADS (1 for the figures in docs/overhead.md).  Not
 * run by the test suite: timings never are.
 */
#define _POSIX_C_SOURCE 200809L
#include <lapacke.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/resource.h>
#include <time.h>

#include "diffusion_common.h"
#include "timing.h"
#include "silc.h"

#define BATCHES 7

static silc_context *ctx;
static volatile double sink;

static double thread_cpu_now(void)
{
    struct timespec t;
    clock_gettime(CLOCK_THREAD_CPUTIME_ID, &t);
    return (double)t.tv_sec + 1e-9 * (double)t.tv_nsec;
}

/* bench_now (wall clock), or thread_cpu_now under --cpu */
static double (*now)(void) = bench_now;
static const char *clock_name = "wall clock";


/* Page faults of this process so far: an array that comes from fresh pages
 * each time shows here, whatever the load. */
static double minor_faults(void)
{
    struct rusage u;
    getrusage(RUSAGE_SELF, &u);
    return (double)u.ru_minflt;
}

static int check(int rc, const char *what)
{
    if (rc) fprintf(stderr, "limit: %s: %s\n", what, silc_context_errmsg(ctx));
    return rc;
}

/* ---- part 1: SpMV ----------------------------------------------------------- */

static void spmv_c(const silc_envelope_t *A, const double *x, double *y)
{
    for (int64_t i = 0; i < A->m; i++) {
        double s = 0;
        for (int64_t p = A->rowptr[i]; p < A->rowptr[i + 1]; p++) s += A->values[p] * x[A->colind[p]];
        y[i] = s;
    }
}

/* Distinct vectors the products cycle through: more than the memo's 64 keys
 * (core/lang/memo.c), so that no product is ever handed out again from it,
 * as in a loop whose x changes every step.  The C loop cycles through the
 * same vectors, so both sides read x from the same level of the cache. */
#define SPMV_XS 80

/* PUTs A and SPMV_XS vectors x0, x1, ... (A's m entries each, from x),
 * writes the statements "y = A * xV" into text and runs each once. */
static int put_operands(const silc_envelope_t *A, const double *x, char text[][32])
{
    int rc = check(silc_put(ctx, "A", A), "PUT A");
    for (int v = 0; !rc && v < SPMV_XS; v++) {
        silc_envelope_t xe = {0};
        char name[16];
        snprintf(name, sizeof name, "x%d", v);
        snprintf(text[v], 32, "y = A * x%d", v);
        rc = silc_envelope_vector(&xe, A->m, x + (size_t)v * (size_t)A->m) || check(silc_put(ctx, name, &xe), "PUT x");
        silc_envelope_free(&xe);
    }
    for (int v = 0; !rc && v < SPMV_XS; v++) rc = check(silc_exec(ctx, text[v]), text[v]); /* warm */
    return rc;
}

static int spmv_row(int64_t k)
{
    silc_envelope_t A = {0};
    int64_t n = k * k;
    double *x = malloc((size_t)n * SPMV_XS * sizeof *x), *y = malloc((size_t)n * sizeof *y);
    double ts[BATCHES], tc[BATCHES], ratio[BATCHES], faults[BATCHES];
    char text[SPMV_XS][32];
    int rc = !x || !y;
    if (rc) fprintf(stderr, "limit: out of memory\n");
    for (int64_t i = 0; !rc && i < n * SPMV_XS; i++) x[i] = 1.0 + (double)(i % 7) + (double)(i / n);
    if (!rc) rc = diff_shifted_laplacian(2, k, diff2d_h(k), -1.0, &A) || put_operands(&A, x, text);
    /* about 0.1 s of work per batch and side, whole cycles (at most 40000
     * statements: the tiny row's products are all fixed cost) */
    int reps = (int)(2e7 / (double)(A.nnz > 0 ? A.nnz : 1));
    reps = reps > 40000 ? 40000 : reps;
    reps = reps < SPMV_XS ? SPMV_XS : reps / SPMV_XS * SPMV_XS;
    for (int b = 0; !rc && b < BATCHES; b++) {
        double f0 = minor_faults(), t0 = now();
        for (int r = 0; !rc && r < reps; r++) rc = check(silc_exec(ctx, text[r % SPMV_XS]), "y = A * x");
        ts[b] = (now() - t0) / reps;
        faults[b] = (minor_faults() - f0) / reps;
        t0 = now();
        for (int r = 0; r < reps; r++) {
            spmv_c(&A, x + (size_t)(r % SPMV_XS) * (size_t)n, y);
            sink = y[r % n];
        }
        tc[b] = (now() - t0) / reps;
        ratio[b] = ts[b] / tc[b];
    }
    if (!rc)
        printf("%9lld %10lld %12.1f %12.1f %8.3f %12.2f\n", (long long)A.nnz, (long long)n,
               bench_median(ts, BATCHES) * 1e6, bench_median(tc, BATCHES) * 1e6, bench_median(ratio, BATCHES),
               bench_median(faults, BATCHES));
    silc_envelope_free(&A);
    free(x);
    free(y);
    return rc || check(silc_exec(ctx, "clear"), "clear");
}

static int spmv_after_stream(void);

static int spmv(double max_nnz)
{
    printf("SpMV y = A * x, 5-point matrix of a k x k grid; microseconds per product (%s), median of %d\n"
           "alternating batches; ratio = SILC / plain C, median of the per-batch ratios; faults: page faults\n"
           "per SILC statement\n", clock_name, BATCHES);
    printf("%9s %10s %12s %12s %8s %12s\n", "nnz", "rows", "SILC us", "plain C us", "ratio", "faults/stmt");
    /* k x k grids of about 1e4, 1e5 and 1e6 nonzeros (5 k^2 of them), after
     * a 2 x 2 grid whose SILC column is the fixed cost of a statement */
    return spmv_row(2) || spmv_row(45) || (max_nnz >= 1e5 && spmv_row(141)) ||
           (max_nnz >= 1e6 && spmv_row(447)) || (max_nnz >= 1e5 && spmv_after_stream());
}

/* The fixed cost of a statement as a product of about 1e5 nonzeros leaves
 * the caches: the statement on the 2 x 2 grid (all fixed cost) right after
 * the C loop has streamed the k = 141 matrix (1.7 MB, more than an L2)
 * through them -- the median of the per-batch differences between batches
 * of (C loop, statement) and of the C loop alone -- against the same
 * statement back to back, whose code and data stay cached (the first
 * row's SILC column).  The first is what a 1e5 product pays above the C
 * loop's time (docs/overhead.md). */
static int spmv_after_stream(void)
{
    silc_envelope_t A = {0}, B = {0};
    const int64_t kb = 141, nb = kb * kb, reps = 800;
    double *x = malloc(4 * SPMV_XS * sizeof *x), *xb = malloc((size_t)nb * sizeof *xb),
           *yb = malloc((size_t)nb * sizeof *yb);
    double alone[BATCHES], diff[BATCHES];
    char text[SPMV_XS][32];
    int rc = !x || !xb || !yb;
    if (rc) fprintf(stderr, "limit: out of memory\n");
    for (int64_t i = 0; !rc && i < 4 * SPMV_XS; i++) x[i] = 1.0 + (double)i;
    for (int64_t i = 0; !rc && i < nb; i++) xb[i] = 1.0 + (double)(i % 7);
    if (!rc)
        rc = diff_shifted_laplacian(2, 2, diff2d_h(2), -1.0, &A) ||
             diff_shifted_laplacian(2, kb, diff2d_h(kb), -1.0, &B) || put_operands(&A, x, text);
    for (int b = 0; !rc && b < BATCHES; b++) {
        double t0 = now(), without;
        for (int r = 0; r < reps; r++) {
            spmv_c(&B, xb, yb);
            sink = yb[r % nb];
        }
        without = now() - t0;
        t0 = now();
        for (int r = 0; !rc && r < reps; r++) {
            spmv_c(&B, xb, yb);
            sink = yb[r % nb];
            rc = check(silc_exec(ctx, text[r % SPMV_XS]), "y = A * x");
        }
        diff[b] = (now() - t0 - without) / (double)reps;
        t0 = now();
        for (int r = 0; !rc && r < reps; r++) rc = check(silc_exec(ctx, text[r % SPMV_XS]), "y = A * x");
        alone[b] = (now() - t0) / (double)reps;
    }
    if (!rc)
        printf("the 2 x 2 grid's statement: %.2f us back to back, %.2f us right after a C loop over %lld nonzeros\n",
               bench_median(alone, BATCHES) * 1e6, bench_median(diff, BATCHES) * 1e6, (long long)B.nnz);
    silc_envelope_free(&A);
    silc_envelope_free(&B);
    free(x), free(xb), free(yb);
    return rc || check(silc_exec(ctx, "clear"), "clear");
}

/* ---- part 2: dense solve ------------------------------------------------------ */

static unsigned long long rng = 88172645463325252ULL;
static double urand(void) /* uniform in [0, 1) */
{
    rng ^= rng << 13, rng ^= rng >> 7, rng ^= rng << 17;
    return (double)(rng >> 11) * (1.0 / 9007199254740992.0);
}

/* SILC's settings for its three columns: the bare solve, then with the
 * backward error, then with the condition estimate too (the defaults). */
enum { BARE, BERR, FULL, MODES };
static const char *const mode_settings[MODES] = {
    "set accuracy.condest = off; set solve.backward_error = on_request",
    "set accuracy.condest = off; set solve.backward_error = deferred",
    "set accuracy.condest = auto; set solve.backward_error = deferred",
};

/* Seconds and page faults of one EXEC "x = A \ b" after a fresh PUT of A. */
static int silc_solve_time(const silc_envelope_t *A, double *t, double *faults)
{
    double t0, f0;
    if (check(silc_put(ctx, "A", A), "PUT A")) return 1;
    f0 = minor_faults();
    t0 = now();
    if (check(silc_exec(ctx, "x = A \\ b"), "x = A \\ b")) return 1;
    *t = now() - t0;
    *faults = minor_faults() - f0;
    return 0;
}

/* Median of a[r] - b[r] over the rounds: a cost measured as the difference
 * of two runs of the same round, which load drifting between rounds moves
 * less than a difference of medians. */
static double median_difference(const double *a, const double *b, int reps)
{
    double d[16];
    for (int r = 0; r < reps; r++) d[r] = a[r] - b[r];
    return bench_median(d, reps);
}

/* The bench's system: A random n x n with a dominant diagonal in a, b = A *
 * ones in b, both also as envelopes, b PUT. */
static int dense_system(int64_t n, double *a, double *b, silc_envelope_t *A, silc_envelope_t *be)
{
    for (int64_t j = 0; j < n; j++)
        for (int64_t i = 0; i < n; i++) a[i + j * n] = urand() - 0.5 + (i == j ? (double)n / 4 : 0);
    for (int64_t i = 0; i < n; i++) {
        double s = 0;
        for (int64_t j = 0; j < n; j++) s += a[i + j * n];
        b[i] = s;
    }
    return silc_envelope_dense(A, n, n, a) || silc_envelope_vector(be, n, b) || check(silc_put(ctx, "b", be), "PUT b");
}

static int dense_row(int64_t n, int reps)
{
    size_t nn = (size_t)n * (size_t)n;
    double *a = malloc(nn * sizeof *a), *w = malloc(nn * sizeof *w);
    double *b = malloc((size_t)n * sizeof *b), *xb = malloc((size_t)n * sizeof *xb);
    lapack_int *ipiv = malloc((size_t)n * sizeof *ipiv), info = 0;
    double tl[16], tcl[16], ts[MODES][16], faults[MODES][16];
    silc_envelope_t A = {0}, be = {0};
    int rc = !a || !w || !b || !xb || !ipiv;
    if (rc) fprintf(stderr, "limit: out of memory\n");
    if (!rc) rc = dense_system(n, a, b, &A, &be);
    for (int r = -1; !rc && r < reps; r++) { /* r = -1: a warm-up, not counted */
        double t0, t, f = 0;
        /* dgesv on a copy made before the clock starts, then with the copy
         * timed (into the same, warm array) */
        memcpy(w, a, nn * sizeof *w);
        memcpy(xb, b, (size_t)n * sizeof *xb);
        t0 = now();
        info = LAPACKE_dgesv_work(LAPACK_COL_MAJOR, (lapack_int)n, 1, w, (lapack_int)n, ipiv, xb, (lapack_int)n);
        t = now() - t0;
        if (r >= 0) tl[r] = t;
        memcpy(xb, b, (size_t)n * sizeof *xb);
        t0 = now();
        memcpy(w, a, nn * sizeof *w);
        info |= LAPACKE_dgesv_work(LAPACK_COL_MAJOR, (lapack_int)n, 1, w, (lapack_int)n, ipiv, xb, (lapack_int)n);
        t = now() - t0;
        if (r >= 0) tcl[r] = t;
        sink = xb[0];
        if (info) {
            fprintf(stderr, "limit: dgesv failed (info %d)\n", (int)info);
            rc = 1;
        }
        for (int m = 0; !rc && m < MODES; m++) {
            /* A new matrix each time: SILC recognises a PUT of the same
             * entries under the same name and keeps its factorization
             * (core/client/api.c). */
            a[(size_t)(MODES * (r + 1) + m) % (size_t)n * (size_t)(n + 1)] += 1e-3;
            memcpy(A.values, a, nn * sizeof *a);
            rc = check(silc_exec(ctx, mode_settings[m]), mode_settings[m]) || silc_solve_time(&A, &t, &f);
            if (r >= 0) ts[m][r] = t;
            if (r >= 0) faults[m][r] = f;
        }
    }
    if (!rc) {
        double l = bench_median(tl, reps), cl = bench_median(tcl, reps), s = bench_median(ts[BARE], reps);
        char fl[48];
        snprintf(fl, sizeof fl, "%.0f/%.0f/%.0f", bench_median(faults[BARE], reps),
                 bench_median(faults[BERR], reps), bench_median(faults[FULL], reps));
        printf("%6lld %9.4f %11.4f %9.4f %17s %8.4f %8.4f %8.3f %10.3f %8.3f\n", (long long)n, l, cl, s, fl,
               median_difference(ts[BERR], ts[BARE], reps),
               median_difference(ts[FULL], ts[BERR], reps), s / l, s / cl, bench_median(ts[FULL], reps) / l);
    }
    silc_envelope_free(&A);
    silc_envelope_free(&be);
    free(a), free(w), free(b), free(xb), free(ipiv);
    return rc || check(silc_exec(ctx, "clear A b x"), "clear") || check(silc_exec(ctx, mode_settings[FULL]), "set");
}

/* `limit bare n [solves]`: only SILC's bare solves of the dense part, each
 * after a fresh PUT of A, nothing timed: what an instruction and cache
 * profile of them needs (`valgrind --tool=callgrind --cache-sim=yes`,
 * docs/overhead.md), without dgesv's and the other modes' runs. */
static int bare_solves(int64_t n, int solves)
{
    size_t nn = (size_t)n * (size_t)n;
    double *a = malloc(nn * sizeof *a), *b = malloc((size_t)n * sizeof *b), t, f;
    silc_envelope_t A = {0}, be = {0};
    int rc = !a || !b;
    if (rc) fprintf(stderr, "limit: out of memory\n");
    if (!rc) rc = dense_system(n, a, b, &A, &be) || check(silc_exec(ctx, mode_settings[BARE]), "set");
    for (int r = 0; !rc && r < solves; r++) {
        A.values[(size_t)r % (size_t)n * (size_t)(n + 1)] += 1e-3; /* a new A: no kept factorization */
        rc = silc_solve_time(&A, &t, &f);
    }
    silc_envelope_free(&A);
    silc_envelope_free(&be);
    free(a), free(b);
    return rc;
}

static int dense(int64_t max_n)
{
    printf("\nDense solve x = A \\ b, A random n x n with a dominant diagonal (not symmetric); seconds (%s),\n"
           "median of the rounds; SILC factors afresh each time (a new PUT of A)\n", clock_name);
    printf("%6s %9s %11s %9s %17s %8s %8s %8s %10s %8s\n", "n", "dgesv s", "copy+dgesv", "SILC s", "faults",
           "berr s", "condest", "ratio", "ratio(cp)", "ratio+r");
    for (int64_t n = 1000; n <= max_n; n += 1000)
        if (dense_row(n, n <= 2000 ? 5 : 3)) return 1;
    printf("SILC = bare (accuracy.condest = off, solve.backward_error = on_request); faults = minor page\n"
           "faults an EXEC (medians: bare/with berr/with both); berr = the backward error's cost, condest = the condition\n"
           "estimate's (the accuracy report's extra work, each the median difference of two SILC runs);\n"
           "ratio = SILC / dgesv, ratio(cp) = SILC / copy+dgesv, ratio+r = SILC with the whole report\n"
           "(the defaults) / dgesv\n");
    return 0;
}

int main(int argc, char **argv)
{
    const char *what;
    if (argc > 1 && !strcmp(argv[1], "--cpu")) {
        now = thread_cpu_now;
        clock_name = "the thread's CPU clock";
        argv++, argc--;
    }
    what = argc > 1 ? argv[1] : "all";
    int spmv_only = !strcmp(what, "spmv"), bare = !strcmp(what, "bare");
    double max_nnz = spmv_only && argc > 2 ? atof(argv[2]) : 1e6;
    int64_t max_n = !spmv_only && argc > 2 ? atoll(argv[2]) : bare ? 1000 : 3000;
    int solves = bare && argc > 3 ? atoi(argv[3]) : 3;
    int rc;
    if (argc > 3 + bare || (strcmp(what, "all") && !spmv_only && !bare && strcmp(what, "dense")) ||
        max_n < (bare ? 1 : 1000) || max_nnz < 1e4 || solves < 1) {
        fprintf(stderr, "usage: limit [--cpu] [dense|all] [max_dense_n >= 1000]\n"
                        "       limit [--cpu] spmv [max_nnz >= 1e4]\n"
                        "       limit bare [n] [solves]\n");
        return 2;
    }
    if (silc_open(&ctx, NULL)) {
        fprintf(stderr, "limit: %s\n", ctx ? silc_context_errmsg(ctx) : silc_errmsg());
        silc_close(&ctx);
        return 1;
    }
    if (bare) rc = bare_solves(max_n, solves);
    else rc = (strcmp(what, "dense") && spmv(max_nnz)) || (strcmp(what, "spmv") && dense(max_n));
    silc_close(&ctx);
    return rc ? 1 : 0;
}
