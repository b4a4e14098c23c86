/*
 * accuracy_condest.c -- bench/accuracy_condest: what the condition estimate
 * costs next to the factorization it rides on, per shared matrix and backend.
 *
 * For every real square nonsingular matrix of ../shared/matrices (index.tsv)
 * and every direct backend that takes it, the first solve x = A \ b with a
 * freshly put A (so it factors) is timed with accuracy.condest = off, now
 * and auto, in turn, best of --reps each (default CE_REPS; three times as
 * many for matrices under 20000 entries), and so are `info x` after it and
 * a second solve with the same A (the factorization reused):
 *
 *   factor   the first solve without the estimate (factorization + one solve);
 *   solve    the second solve (one more solve with the factors, and SILC's
 *            per-statement work: parse, dispatch, report);
 *   now      accuracy.condest = now, the estimate at solve time: (now - off)
 *            over factor, as a share;
 *   auto     the default, accuracy.condest = auto: the same share at solve
 *            time, where the estimate is made when it costs at most 15 % of
 *            the factorization (predicted by the backend's timings) or its
 *            condition warnings could fire (a lower bound of cond_1 from
 *            the estimator's start block, or the pivot ratio: docs/
 *            accuracy.md), and is otherwise deferred;
 *   at       where auto made it: "solve", "read" (deferred), or "N/M" when
 *            the prediction (from the call's wall-clock timings) deferred
 *            it in N of the M repetitions only (auto's share is the best
 *            run's, so the deferred way's);
 *   read     what `info x` costs more under auto than under now (the
 *            deferred estimate, and the residual pass for its bound), in
 *            solves (read / solve) and as a share of factor.
 *
 * The budget is 15 % of a factorization; auto rows above it are marked '!',
 * and the last lines give each backend's median shares.  Times are the
 * process's CPU time (CLOCK_PROCESS_CPUTIME_ID; every backend runs
 * single-threaded here with OPENBLAS_NUM_THREADS=1 OMP_NUM_THREADS=1): on a
 * shared machine wall time counts the other jobs' time slices too, and moved
 * rows by 10-20 points between runs.  A difference is printed as measured (a
 * negative one is noise).  lapack is not listed: its estimate (dgecon & co.,
 * O(n^2) after an O(n^3) factorization) is made whatever accuracy.condest
 * says, so every mode times the same work.
 *
 * --floor adds what no cut can go below, for a row that must make its
 * estimate (or its bound) at solve time to give every condition warning
 * there (docs/accuracy.md, "The warning is not lost"):
 *
 *   1 solve  the backend's own time of one solve with the factors (`solve
 *            time` in `info` of the second solve, best of the repetitions:
 *            KLU's, UMFPACK's, CHOLMOD's or the reference's pass over the
 *            factors for one column, one MUMPS solve phase, JOB=3), without
 *            SILC's per-statement work;
 *   column   what one more column costs in such a solve: (the backend's
 *            time of a solve of [b, b, b] - 1 solve) / 2, best times of
 *            each: the cost of a column that rides along with others, and
 *            at most that of a column solved alone (the estimator's);
 *            1 solve and column are not the unit of UMFPACK's and the
 *            reference's estimates, whose solves for the user refine
 *            (UMFPACK_IRSTEP 2, the reference up to two steps) where the
 *            estimator's do not: their floor is printed "--";
 *   floor    min x unit / factor, min the solves the warning needs (unit:
 *            column for KLU and CHOLMOD, 1 solve for MUMPS's phases):
 *            where auto made the estimate at solve time, the whole
 *            Hager-Higham estimate from its start block, i.e. four column
 *            solves (the start's two and one A', one A step: an estimate
 *            whose last step may raise it past the warning threshold
 *            cannot stop earlier) for KLU and CHOLMOD, two solve phases
 *            after the user's for MUMPS (its start block rides along with
 *            the user's columns in one phase), none for PETSc (it never
 *            defers: not a floor of this rule); where the estimate was
 *            deferred, the start block's bound (two column solves) where
 *            KLU solves it at once, when its pivot ratio exceeds
 *            SILC_CONDEST_PIVOT_HINT.
 *
 *   ./build/bench/accuracy_condest [--reps N] [--matrix SUBSTRING] [--backend SUBSTRING] [--floor]
 *   (OPENBLAS_NUM_THREADS=1 OMP_NUM_THREADS=1)
 */
#define _POSIX_C_SOURCE 200809L
#include "testlib.h"
#include "../plugins/silc_plugin.h" /* SILC_CONDEST_PIVOT_HINT */

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

static int by_value(const void *a, const void *b)
{
    double x = *(const double *)a, y = *(const double *)b;
    return (x > y) - (x < y);
}

/* What `info` printed (silc_set_output), to tell where auto made the estimate. */
static char info_text[8192];
static void keep_text(void *user, const char *text)
{
    size_t len = strlen(info_text);
    (void)user;
    snprintf(info_text + len, sizeof info_text - len, "%s", text);
}

/* One run of a mode: CPU seconds of the first solve with a fresh A, of
 * `info x` after it, and of a second solve reusing the factorization; *read
 * says whether info made the estimate.  -1 when the backend fails.  The
 * first entry of A is nudged by an ulp each time, so that no factorization,
 * symbolic or numeric, is found again by its values. */
typedef struct timing {
    double first, info, again;
    double solve;       /* the backend's own time of the second solve (--floor), else INFINITY */
    double solve3;      /* the same for a solve of three columns (--floor), else INFINITY */
    double pivot_ratio; /* the factor-diagonal ratio info showed, 0 when none */
    int read;
} timing;

/* The number after label in info's text, or fallback. */
static double info_number(const char *label, double fallback)
{
    const char *p = strstr(info_text, label);
    return p ? strtod(p + strlen(label), NULL) : fallback;
}

static int timed_solve(silc_context *c, silc_envelope_t *A, const backend *be, const char *condest, int with_floor,
                       timing *t)
{
    char stmt[512];
    A->values[0] = nextafter(A->values[0], INFINITY);
    if (silc_put(c, "A", A)) return -1;
    snprintf(stmt, sizeof stmt, "set accuracy.condest = %s%s", condest, be->dense ? "; A = dense(A)" : "");
    if (silc_exec(c, stmt)) return -1;
    snprintf(stmt, sizeof stmt, "x = solve(A, b, \"backend = %s%s\")", be->name, be->opts);
    t->first = cpu_now();
    if (silc_exec(c, stmt)) return -1;
    t->first = cpu_now() - t->first;
    info_text[0] = 0;
    t->info = cpu_now();
    if (silc_exec(c, "info x")) return -1;
    t->info = cpu_now() - t->info;
    t->read = strstr(info_text, "deferred at solve time") != NULL;
    t->pivot_ratio = info_number("condition (factor-diagonal ratio, not a bound): ", 0);
    t->again = cpu_now();
    if (silc_exec(c, stmt)) return -1;
    t->again = cpu_now() - t->again;
    t->solve = t->solve3 = INFINITY;
    if (with_floor) { /* untimed: the backend's own clock of those solves */
        info_text[0] = 0;
        if (silc_exec(c, "info x")) return -1;
        t->solve = info_number("solve time: ", INFINITY);
        snprintf(stmt, sizeof stmt, "x3 = solve(A, [b, b, b], \"backend = %s%s\")", be->name, be->opts);
        info_text[0] = 0;
        if (silc_exec(c, stmt) || silc_exec(c, "info x3; x3 = 0")) return -1;
        t->solve3 = info_number("solve time: ", INFINITY);
    }
    /* Its backward error is deferred and keeps A alive: dropped, so that
     * every timed first solve finds A's predecessor dead (KLU refactors
     * into its factors then, as in a time loop). */
    return silc_exec(c, "x = 0") ? -1 : 0;
}

/* The fewest solves the condition warnings need at solve time (--floor, in
 * the header): made_now when auto made the whole estimate then, else the
 * start block's bound where the backend solves it; -1 where the backend's
 * solve time is no unit of its estimate (UMFPACK, the reference). */
static int floor_solves(const backend *be, int made_now, double pivot_ratio)
{
    int klu = !strcmp(be->name, "suitesparse.klu");
    if (!strcmp(be->name, "suitesparse.umfpack") || !strcmp(be->name, "reference")) return -1;
    if (made_now) return klu || !strcmp(be->name, "suitesparse.cholmod") ? 4 : !strcmp(be->name, "mumps") ? 2 : 0;
    return klu && pivot_ratio > SILC_CONDEST_PIVOT_HINT ? 2 : 0;
}

static double median(double *v, int n)
{
    if (!n) return NAN;
    qsort(v, (size_t)n, sizeof *v, by_value);
    return n % 2 ? v[n / 2] : 0.5 * (v[n / 2 - 1] + v[n / 2]);
}

int main(int argc, char **argv)
{
    silc_context *c = NULL;
    char path[1024], line[1024];
    const char *only_matrix = NULL, *only_backend = NULL;
    FILE *idx;
    int over = 0, rows = 0, reps = CE_REPS, with_floor = 0;
    int nrow[NB] = {0}, nover[NB] = {0}, nread[NB] = {0};
    static double now_share[NB][MAX_ROWS], auto_share[NB][MAX_ROWS], read_solves[NB][MAX_ROWS];
    for (int i = 1; i < argc; i++) {
        if (!strcmp(argv[i], "--reps") && i + 1 < argc && atoi(argv[i + 1]) > 0) reps = atoi(argv[++i]);
        else if (!strcmp(argv[i], "--matrix") && i + 1 < argc) only_matrix = argv[++i];
        else if (!strcmp(argv[i], "--backend") && i + 1 < argc) only_backend = argv[++i];
        else if (!strcmp(argv[i], "--floor")) with_floor = 1;
        else {
            fprintf(stderr, "usage: %s [--reps N] [--matrix SUBSTRING] [--backend SUBSTRING] [--floor]\n",
                    argv[0]);
            return 2;
        }
    }
    if (silc_open(&c, NULL)) {
        fprintf(stderr, "silc_open: %s\n", silc_errmsg());
        return 1;
    }
    silc_set_output(c, keep_text, NULL);
    snprintf(path, sizeof path, "%s/index.tsv", SILC_SHARED_MATRICES);
    if (!(idx = fopen(path, "r"))) {
        fprintf(stderr, "cannot open %s\n", path);
        return 1;
    }
    printf("condition estimate cost: first solve (factorization + solve) with accuracy.condest = off, now and "
           "auto, CPU time, best of %d (%d under 20000 entries)\n\n", reps, 3 * reps);
    printf("  %-17s %-20s %6s  %10s  %10s  %6s  %6s  %-5s  %12s  %6s%s\n", "matrix", "backend", "n", "factor [s]",
           "solve [s]", "now", "auto", "at", "read [solves]", "read",
           with_floor ? "   1 solve [s]  column [s]  min   floor" : "");
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
            timing off = {INFINITY, INFINITY, INFINITY, INFINITY, INFINITY, 0, 0}, now = off, au = off, t = off;
            /* info's best where it made the estimate */
            double auto_d, now_d, read_d, info_read = INFINITY;
            /* Small rows are cheap and the noisiest next to the budget:
             * three times the repetitions. */
            int ok = 1, reps_here = nnz < 20000 ? 3 * reps : reps, read = 0;
            char at[32];
            if ((be->spd_only && strcmp(cls, "spd")) || n > be->max_n ||
                (only_backend && !strstr(be->name, only_backend)))
                continue;
            for (int r = 0; r < reps_here && ok; r++) {
                static const char *const modes[3] = {"off", "now", "auto"};
                timing *best[3] = {&off, &now, &au};
                for (int m = 0; m < 3 && ok; m++) {
                    ok = timed_solve(c, &A, be, modes[m], with_floor && m == 0, &t) == 0;
                    if (t.first < best[m]->first) best[m]->first = t.first;
                    if (t.solve < best[m]->solve) best[m]->solve = t.solve;
                    if (t.solve3 < best[m]->solve3) best[m]->solve3 = t.solve3;
                    if (m == 0) off.pivot_ratio = t.pivot_ratio;
                    if (t.info < best[m]->info) best[m]->info = t.info;
                    if (t.again < best[m]->again) best[m]->again = t.again;
                    if (m == 2) read += t.read;
                    if (m == 2 && t.read && t.info < info_read) info_read = t.info;
                }
            }
            if (!ok) continue; /* not built, declines, or fails on it */
            now_d = (now.first - off.first) / off.first;
            auto_d = (au.first - off.first) / off.first;
            read_d = info_read - now.info;
            over += auto_d > CE_BUDGET;
            nover[k] += auto_d > CE_BUDGET;
            nread[k] += read > 0;
            rows++;
            if (nrow[k] < MAX_ROWS) {
                now_share[k][nrow[k]] = now_d;
                auto_share[k][nrow[k]] = auto_d;
                read_solves[k][nrow[k]++] = read ? read_d / off.again : 0;
            }
            if (read > 0 && read < reps_here) snprintf(at, sizeof at, "%d/%d", read, reps_here);
            else snprintf(at, sizeof at, "%s", read ? "read" : "solve");
            printf("%c %-17s %-20s %6lld  %10.3g  %10.3g  %5.1f%%  %5.1f%%  %-5s", auto_d > CE_BUDGET ? '!' : ' ',
                   file, be->name, n, off.first, off.again, 100 * now_d, 100 * auto_d, at);
            if (read) printf("  %12.1f  %5.1f%%", read_d / off.again, 100 * read_d / off.first);
            else printf("  %12s  %6s", "--", "--");
            if (with_floor) {
                int least = floor_solves(be, !read, off.pivot_ratio);
                double column = (off.solve3 - off.solve) / 2, unit = strcmp(be->name, "mumps") ? column : off.solve;
                printf("   %11.3g  %10.3g", off.solve, column);
                if (least < 0) printf("  %3s  %6s", "--", "--");
                else printf("  %3d  %5.1f%%", least, 100 * least * unit / off.first);
            }
            printf("\n");
            fflush(stdout);
        }
        silc_envelope_free(&A);
    }
    fclose(idx);
    printf("\n%d of %d rows above %.0f %% of the factorization at solve time under auto ('!')\n", over, rows,
           100 * CE_BUDGET);
    printf("median per backend: now, auto (share of the factorization at solve time), rows deferred, "
           "their cost when read (solves)\n");
    for (size_t k = 0; k < NB; k++) {
        double rs[MAX_ROWS];
        int nr = 0;
        if (!nrow[k]) continue;
        for (int i = 0; i < nrow[k]; i++)
            if (read_solves[k][i] != 0) rs[nr++] = read_solves[k][i];
        printf("  %-20s %5.0f %%  %5.0f %%  %2d of %2d  %5.1f  (%d over)\n", backends[k].name,
               100 * median(now_share[k], nrow[k]), 100 * median(auto_share[k], nrow[k]), nread[k], nrow[k],
               median(rs, nr), nover[k]);
    }
    silc_close(&c);
    return 0;
}
