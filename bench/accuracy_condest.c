/*
 * accuracy_condest.c -- bench/accuracy_condest: what the condition estimate
 * costs next to the factorization it rides on, per shared matrix and backend.
 *
 * For every real square nonsingular matrix of ../shared/matrices (index.tsv)
 * and every direct backend that takes it, the first solve x = A \ b with a
 * freshly put A (so it factors) is timed with accuracy.condest = off and on,
 * alternately, best of CE_REPS each:
 *
 *   factor   the solve without the estimate (factorization + one solve);
 *   condest  the difference, on - off (the estimate's extra solves);
 *   ratio    condest / factor.
 *
 * The budget is 15 % of a factorization; rows above it are marked '!'.
 * Timings on a shared machine are noisy: best of CE_REPS, alternating, and
 * a difference is printed as measured (a negative one is noise).  lapack
 * is not listed: its estimate (dgecon & co., O(n^2) after an O(n^3)
 * factorization) is made whatever accuracy.condest says, so on and off
 * time the same work.
 *
 *   ./build/bench/accuracy_condest            (OPENBLAS_NUM_THREADS=1)
 */
#define _POSIX_C_SOURCE 200809L
#include "testlib.h"

#include <float.h>

#define CE_REPS 5
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

/* Seconds of one first solve with a fresh A; -1 when the backend fails.
 * The first entry of A is nudged by an ulp each time, so that no
 * factorization, symbolic or numeric, is found again by its values. */
static double timed_solve(silc_context *c, silc_envelope_t *A, const backend *be, const char *condest)
{
    char stmt[512];
    double t;
    A->values[0] = nextafter(A->values[0], INFINITY);
    if (silc_put(c, "A", A)) return -1;
    snprintf(stmt, sizeof stmt, "set accuracy.condest = %s%s", condest, be->dense ? "; A = dense(A)" : "");
    if (silc_exec(c, stmt)) return -1;
    snprintf(stmt, sizeof stmt, "x = solve(A, b, \"backend = %s%s\")", be->name, be->opts);
    t = tl_now();
    if (silc_exec(c, stmt)) return -1;
    return tl_now() - t;
}

int main(void)
{
    silc_context *c = NULL;
    char path[1024], line[1024];
    FILE *idx;
    int over = 0, rows = 0;
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
           "best of %d\n\n", CE_REPS);
    printf("  %-17s %-20s %6s  %11s  %11s  %7s\n", "matrix", "backend", "n", "factor [s]", "condest [s]", "ratio");
    while (fgets(line, sizeof line, idx)) {
        char file[256], field[32], sym[32], cls[32];
        long long m, n, nnz;
        silc_envelope_t A;
        char err[256];
        if (sscanf(line, "%255s %lld %lld %lld %31s %31s %31s", file, &m, &n, &nnz, field, sym, cls) != 7 ||
            !strcmp(file, "file"))
            continue;
        if ((strcmp(field, "real") && strcmp(field, "integer")) || m != n || !strcmp(cls, "singular") ||
            !strcmp(cls, "rect"))
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
            double off = INFINITY, on = INFINITY, d, ratio;
            int ok = 1;
            if ((be->spd_only && strcmp(cls, "spd")) || n > be->max_n) continue;
            for (int r = 0; r < CE_REPS && ok; r++) {
                double t0 = timed_solve(c, &A, be, "off"), t1 = timed_solve(c, &A, be, "on");
                ok = t0 >= 0 && t1 >= 0;
                if (t0 < off) off = t0;
                if (t1 < on) on = t1;
            }
            if (!ok) continue; /* not built, declines, or fails on it */
            d = on - off;
            ratio = d / off;
            over += ratio > CE_BUDGET;
            rows++;
            printf("%c %-17s %-20s %6lld  %11.3g  %11.3g  %6.1f%%\n", ratio > CE_BUDGET ? '!' : ' ', file, be->name,
                   n, off, d, 100 * ratio);
            fflush(stdout);
        }
        silc_envelope_free(&A);
    }
    fclose(idx);
    printf("\n%d of %d rows above %.0f %% of the factorization ('!')\n", over, rows, 100 * CE_BUDGET);
    silc_close(&c);
    return 0;
}
