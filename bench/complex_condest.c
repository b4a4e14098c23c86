/*
 * complex_condest.c -- bench/complex_condest: what the complex condition
 * estimate's start block costs under accuracy.condest = auto with
 * UMFPACK and KLU (docs/accuracy.md, "When the estimate is made").
 *
 * On examples/helmholtz's complex 2-D Helmholtz matrix (plane wave, k = 40)
 * of (n+1)^2 unknowns, for each backend, best of --reps (CPU time of the
 * process, every backend single-threaded):
 *
 *   first off    the first solve x = A \ b of a freshly put A (factorization
 *                and one solve) with accuracy.condest = off: the baseline;
 *   first auto   the same under auto, and where auto made the estimate:
 *                "solve", or "read" when it was left owed (then the solve
 *                solved the estimator's start block, e/n and the
 *                alternating vector, for the owed estimate's lower bound);
 *   column       one solve with the factorization reused, under off, with
 *                UMFPACK's refinement off (umfpack_irstep = 0): one column
 *                solve, what each start vector costs, and its share of
 *                first off;
 *   later auto / later off   a solve with the factorization reused under
 *                auto and under off: their ratio is what an owed estimate
 *                costs each later solve (its bound comes from the kept
 *                block: nothing).
 *
 *   ./build/bench/complex_condest [--reps N] [--sizes 100,200,400]
 *   (OPENBLAS_NUM_THREADS=1 OMP_NUM_THREADS=1)
 */
#define _POSIX_C_SOURCE 200809L
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "helmholtz.h"
#include "silc.h"

static double cpu_now(void)
{
    struct timespec t;
    clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &t);
    return (double)t.tv_sec + 1e-9 * (double)t.tv_nsec;
}

static void run_or_die(silc_context *c, const char *stmt)
{
    if (silc_exec(c, stmt)) {
        fprintf(stderr, "complex_condest: %s: %s\n", stmt, silc_context_errmsg(c));
        exit(1);
    }
}

/* What `info` printed last (capture). */
static char info_text[8192];

static void capture(void *user, const char *text)
{
    size_t have = strlen(info_text);
    (void)user;
    snprintf(info_text + have, sizeof info_text - have, "%s", text);
}

/* CPU seconds of one statement. */
static double timed(silc_context *c, const char *stmt)
{
    double t0 = cpu_now();
    run_or_die(c, stmt);
    return cpu_now() - t0;
}

/* Best first solve of a fresh copy of A under mode; *owed (when asked):
 * whether auto left the estimate for `info` to make. */
static double first_solve(silc_context *c, const silc_envelope_t *A, const char *be, const char *mode, int reps,
                          int *owed)
{
    double best = 1e300;
    char stmt[256];
    for (int r = 0; r < reps; r++) {
        if (silc_put(c, "Af", A)) {
            fprintf(stderr, "complex_condest: put: %s\n", silc_context_errmsg(c));
            exit(1);
        }
        snprintf(stmt, sizeof stmt, "set accuracy.condest = %s; x = solve(Af, b, \"backend = suitesparse.%s\")",
                 mode, be);
        double t = timed(c, stmt);
        if (t < best) best = t;
        if (owed && r == 0) { /* the report says when the estimate was made */
            info_text[0] = 0;
            silc_set_output(c, capture, NULL);
            run_or_die(c, "info x");
            silc_set_output(c, NULL, NULL);
            *owed = strstr(info_text, "computed when the report was first read") != NULL;
        }
        run_or_die(c, "clear Af x");
    }
    return best;
}

int main(int argc, char **argv)
{
    int reps = 3, sizes[8] = {100, 200, 400}, nsizes = 3;
    silc_context *c;
    for (int i = 1; i < argc; i++) {
        if (!strcmp(argv[i], "--reps") && i + 1 < argc) {
            reps = atoi(argv[++i]);
        } else if (!strcmp(argv[i], "--sizes") && i + 1 < argc) {
            char *p = argv[++i];
            for (nsizes = 0; nsizes < 8 && *p; nsizes++) {
                sizes[nsizes] = (int)strtol(p, &p, 10);
                if (*p == ',') p++;
            }
        } else {
            fprintf(stderr, "usage: complex_condest [--reps N] [--sizes 100,200,400]\n");
            return 2;
        }
    }
    if (reps < 1 || silc_open(&c, NULL)) {
        fprintf(stderr, "complex_condest: %s\n", reps < 1 ? "--reps must be positive" : silc_errmsg());
        return 1;
    }
    printf("%-22s %-8s %10s %10s %-5s %10s %8s %10s %10s %7s\n", "matrix", "backend", "first off", "first auto",
           "made", "column", "% first", "later auto", "later off", "ratio");
    for (int s = 0; s < nsizes; s++) {
        int n = sizes[s];
        silc_envelope_t A;
        char err[256], label[40];
        double *rhs = malloc(sizeof(double) * 2 * (size_t)(n + 1) * (size_t)(n + 1));
        memset(&A, 0, sizeof A);
        if (!rhs || helmholtz_assemble(n, 40.0, HELMHOLTZ_PLANE_WAVE, &A, rhs, err, sizeof err)) {
            fprintf(stderr, "complex_condest: %s\n", rhs ? err : "out of memory");
            return 1;
        }
        free(rhs);
        snprintf(label, sizeof label, "helmholtz %d^2 (%lld)", n, (long long)A.m);
        if (silc_put(c, "A", &A)) {
            fprintf(stderr, "complex_condest: put: %s\n", silc_context_errmsg(c));
            return 1;
        }
        run_or_die(c, "b = A * ones(rows(A), 1)");
        for (int k = 0; k < 2; k++) {
            const char *be = k ? "klu" : "umfpack";
            char stmt[256];
            double off, au, col = 1e300, lat_auto = 1e300, lat_off = 1e300;
            int owed = 0;
            off = first_solve(c, &A, be, "off", reps, NULL);
            au = first_solve(c, &A, be, "auto", reps, &owed);
            /* Later solves: A's own factorization, made once here. */
            snprintf(stmt, sizeof stmt, "set accuracy.condest = auto; y = solve(A, b, \"backend = suitesparse.%s\")",
                     be);
            run_or_die(c, stmt);
            for (int r = 0; r < 3 * reps; r++) {
                snprintf(stmt, sizeof stmt, "set accuracy.condest = off; y = solve(A, b, \"backend = "
                         "suitesparse.%s; suitesparse.umfpack_irstep = 0\")", be);
                double t = timed(c, stmt);
                if (t < col) col = t;
                snprintf(stmt, sizeof stmt, "set accuracy.condest = auto; y = solve(A, b, \"backend = suitesparse.%s\")",
                         be);
                if ((t = timed(c, stmt)) < lat_auto) lat_auto = t;
                snprintf(stmt, sizeof stmt, "set accuracy.condest = off; y = solve(A, b, \"backend = suitesparse.%s\")",
                         be);
                if ((t = timed(c, stmt)) < lat_off) lat_off = t;
            }
            printf("%-22s %-8s %10.4f %10.4f %-5s %10.5f %7.1f%% %10.5f %10.5f %7.3f\n", label, be, off, au,
                   owed ? "read" : "solve", col, 100 * col / off, lat_auto, lat_off, lat_auto / lat_off);
            fflush(stdout);
        }
        run_or_die(c, "clear A b y");
        silc_envelope_free(&A);
    }
    silc_close(&c);
    return 0;
}
