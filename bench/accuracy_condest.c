/*
 * accuracy_condest.c -- bench/accuracy_condest: what the condition estimate
 * costs next to the factorization it rides on, per shared matrix and backend.
 *
 * For every real square nonsingular matrix of ../shared/matrices (index.tsv)
 * and every direct backend that takes it, the first solve x = A \ b with a
 * freshly put A (so it factors) is timed with accuracy.condest = off and on,
 * alternately, best of --reps each (default CE_REPS; three times as many
 * for matrices under 20000 entries), and so is a second
 * solve with the same A (the factorization reused):
 *
 *   factor   the first solve without the estimate (factorization + one solve);
 *   solve    the second solve (one more solve with the factors, and SILC's
 *            per-statement work: parse, dispatch, report);
 *   condest  the difference of the first solves, on - off (the estimate's
 *            extra solves and bookkeeping);
 *   ratio    condest / factor;
 *   solves   condest / solve: the estimate's cost counted in solves.
 *
 * The budget is 15 % of a factorization; rows above it are marked '!', and
 * the last lines give each backend's median ratio.  Times are the process's
 * CPU time (CLOCK_PROCESS_CPUTIME_ID; every backend runs single-threaded
 * here with OPENBLAS_NUM_THREADS=1 OMP_NUM_THREADS=1): on a shared machine
 * wall time counts the other jobs' time slices too, and moved rows by 10-20
 * points between runs.  A difference is printed as measured (a negative one
 * is noise).  lapack is not listed: its estimate (dgecon & co., O(n^2) after
 * an O(n^3) factorization) is made whatever accuracy.condest says, so on and
 * off time the same work.
 *
 *   ./build/bench/accuracy_condest [--reps N] [--matrix SUBSTRING] [--backend SUBSTRING]
 *   (OPENBLAS_NUM_THREADS=1 OMP_NUM_THREADS=1)
 */
#define _POSIX_C_SOURCE 200809L
#include "testlib.h"

#include <float.h>
#include <time.h>

#define CE_REPS 7
#define CE_BUDGET 0.15

typedef struct backend {
    const char *name, *opts;
    int spd_only, dense;
    int64_t max_n;          /* larger matrices are left out (slow, and not its use) */
} backend;

static const backend backends[] = {
    {"reference", "", 0, 0, 5000},
    {"suitesparse.umfpack", "", 0, 0, 1 << 30},
    {"suitesparse.klu", "", 0, 0, 1 << 30},
    {"suitesparse.cholmod", "", 1, 0, 1 << 30},
    {"mumps", "", 0, 0, 1 << 30},
    {"petsc", "; petsc.options = -ksp_type preonly -pc_type lu", 0, 0, 5000}, /* memplus: 15 s */
};
#define NB (sizeof backends / sizeof backends[0])
#define MAX_ROWS 64         /* per backend, for the medians */

static double cpu_now(void)
{
    struct timespec t;
    clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &t);
    return (double)t.tv_sec + 1e-9 * (double)t.tv_nsec;
}

/* CPU seconds of one first solve with a fresh A, and in *again of a second
 * solve reusing its factorization (when again is not NULL); -1 when the
 * backend fails.  The first entry of A is nudged by an ulp each time, so
 * that no factorization, symbolic or numeric, is found again by its values. */
static double timed_solve(silc_context *c, silc_envelope_t *A, const backend *be, const char *condest,
                          double *again)
{
    char stmt[512];
    double t;
    A->values[0] = nextafter(A->values[0], INFINITY);
    if (silc_put(c, "A", A)) return -1;
    snprintf(stmt, sizeof stmt, "set accuracy.condest = %s%s", condest, be->dense ? "; A = dense(A)" : "");
    if (silc_exec(c, stmt)) return -1;
    snprintf(stmt, sizeof stmt, "x = solve(A, b, \"backend = %s%s\")", be->name, be->opts);
    t = cpu_now();
    if (silc_exec(c, stmt)) return -1;
    t = cpu_now() - t;
    if (again) {
        *again = cpu_now();
        if (silc_exec(c, stmt)) return -1;
        *again = cpu_now() - *again;
        /* Its backward error is deferred and keeps A alive: dropped, so
         * that both timed first solves find A's predecessor dead (KLU
         * refactors into its factors then, as in a time loop). */
        if (silc_exec(c, "x = 0")) return -1;
    }
    return t;
}

static int by_value(const void *a, const void *b)
{
    double x = *(const double *)a, y = *(const double *)b;
    return (x > y) - (x < y);
}

int main(int argc, char **argv)
{
    silc_context *c = NULL;
    char path[1024], line[1024];
    const char *only_matrix = NULL, *only_backend = NULL;
    FILE *idx;
    int over = 0, rows = 0, reps = CE_REPS;
    int nratio[NB] = {0}, nover[NB] = {0};
    static double ratios[NB][MAX_ROWS];
    for (int i = 1; i < argc; i++) {
        if (!strcmp(argv[i], "--reps") && i + 1 < argc && atoi(argv[i + 1]) > 0) reps = atoi(argv[++i]);
        else if (!strcmp(argv[i], "--matrix") && i + 1 < argc) only_matrix = argv[++i];
        else if (!strcmp(argv[i], "--backend") && i + 1 < argc) only_backend = argv[++i];
        else {
            fprintf(stderr, "usage: %s [--reps N] [--matrix SUBSTRING] [--backend SUBSTRING]\n", argv[0]);
            return 2;
        }
    }
    if (silc_open(&c, NULL)) {
        fprintf(stderr, "silc_open: %s\n", silc_errmsg());
        return 1;
    }
    snprintf(path, sizeof path, "%s/index.tsv", SILC_SHARED_MATRICES);
    if (!(idx = fopen(path, "r"))) {
        fprintf(stderr, "cannot open %s\n", path);
        return 1;
    }
    printf("condition estimate cost: first solve (factorization + solve) with accuracy.condest = off / on, "
           "CPU time, best of %d (%d under 20000 entries)\n\n", reps, 3 * reps);
    printf("  %-17s %-20s %6s  %11s  %11s  %11s  %7s  %6s\n", "matrix", "backend", "n", "factor [s]", "solve [s]",
           "condest [s]", "ratio", "solves");
    while (fgets(line, sizeof line, idx)) {
        char file[256], field[32], sym[32], cls[32];
        long long m, n, nnz;
        silc_envelope_t A;
        char err[256];
        if (sscanf(line, "%255s %lld %lld %lld %31s %31s %31s", file, &m, &n, &nnz, field, sym, cls) != 7 ||
            !strcmp(file, "file"))
            continue;
        if ((strcmp(field, "real") && strcmp(field, "integer")) || m != n || !strcmp(cls, "singular") ||
            !strcmp(cls, "rect") || (only_matrix && !strstr(file, only_matrix)))
            continue;
        snprintf(path, sizeof path, "%s/%s", SILC_SHARED_MATRICES, file);
        if (tl_read_mtx(&A, path, err, sizeof err)) {
            fprintf(stderr, "%s: %s\n", path, err);
            continue;
        }
        if (silc_put(c, "A", &A) || silc_exec(c, "b = A * ones(rows(A), 1)")) {
            fprintf(stderr, "%s: %s\n", file, silc_context_errmsg(c));
            silc_envelope_free(&A);
            continue;
        }
        for (size_t k = 0; k < NB; k++) {
            const backend *be = &backends[k];
            double off = INFINITY, on = INFINITY, again = INFINITY, d, ratio;
            /* Small rows are cheap and the noisiest next to the budget:
             * three times the repetitions. */
            int ok = 1, reps_here = nnz < 20000 ? 3 * reps : reps;
            if ((be->spd_only && strcmp(cls, "spd")) || n > be->max_n ||
                (only_backend && !strstr(be->name, only_backend)))
                continue;
            for (int r = 0; r < reps_here && ok; r++) {
                double a, t0 = timed_solve(c, &A, be, "off", &a), t1 = timed_solve(c, &A, be, "on", NULL);
                ok = t0 >= 0 && t1 >= 0;
                if (t0 < off) off = t0;
                if (t1 < on) on = t1;
                if (a < again) again = a;
            }
            if (!ok) continue; /* not built, declines, or fails on it */
            d = on - off;
            ratio = d / off;
            over += ratio > CE_BUDGET;
            nover[k] += ratio > CE_BUDGET;
            rows++;
            if (nratio[k] < MAX_ROWS) ratios[k][nratio[k]++] = ratio;
            printf("%c %-17s %-20s %6lld  %11.3g  %11.3g  %11.3g  %6.1f%%  %6.1f\n", ratio > CE_BUDGET ? '!' : ' ',
                   file, be->name, n, off, again, d, 100 * ratio, d / again);
            fflush(stdout);
        }
        silc_envelope_free(&A);
    }
    fclose(idx);
    printf("\n%d of %d rows above %.0f %% of the factorization ('!')\n", over, rows, 100 * CE_BUDGET);
    printf("median ratio per backend:\n");
    for (size_t k = 0; k < NB; k++) {
        if (!nratio[k]) continue;
        qsort(ratios[k], (size_t)nratio[k], sizeof(double), by_value);
        printf("  %-20s %4.0f %%  (%d of %d rows over)\n", backends[k].name,
               100 * (nratio[k] % 2 ? ratios[k][nratio[k] / 2]
                                    : 0.5 * (ratios[k][nratio[k] / 2 - 1] + ratios[k][nratio[k] / 2])),
               nover[k], nratio[k]);
    }
    silc_close(&c);
    return 0;
}
