/*
 * tuner.c -- validation of the tuner's thread-count model (issue 6), the
 * seeds' experiment: the 2-D diffusion example at n = 71, 100, 142, 200
 * points per side (N = n^2 unknowns).
 *
 *     tuner [--steps S] [--backend NAME] [--options TEXT] [--budget B] [n ...]
 *
 * For each n: (1) the truth, by exhaustive measurement: S steps of diff_run at
 * every thread count from 1 to the largest candidate the tuner would try
 * (oversubscribed on a small machine), seconds per step, best of 2 runs;
 * (2) the tuner: a fresh context with `tune on S` and tune.budget = B (default
 * 1: sampling unlimited, so the model is judged; 0.05 is the production
 * default), run for S steps; its p_opt, the steps it spent sampling, why it
 * stopped.  eps_rel = |t_true - t(p_opt)| / t_true with t() from (1).
 * The solve runs on --backend (dispatch.solve.sparse.spd; default: the
 * configured dispatch) with --options as that plugin's options, so a threaded
 * backend (lis-style, mumps, petsc) can be measured.  Thread counts are set
 * with tune.threads = p, which the tuner applies through every plugin's
 * set_threads.  Wisdom goes to a temporary file, forgotten before each run.
 * The tuner is allowed those thread counts (tune.max_threads), which it
 * would not sample by default past the CPUs the process may use.
 *
 * Last, the first-run cost of tuning (issue 18): the main example's loop
 * (n = 200, 200 steps) untuned, tuned from an empty wisdom file
 * (tune.threads = auto with the default budget, the run's length unknown)
 * and tuned again from the wisdom the first run wrote, best of 3 rounds, as
 * ratios to the untuned run.  Target: the first tuned run at most 1.10x.
 * Uses the public API only.  Not run by the test suite.
 */
#define _POSIX_C_SOURCE 200809L
#include "progress.h"
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>
#include <unistd.h>

#include "diffusion_common.h"
#include "silc.h"

static const char *backend, *options;
static progress bar; /* on stderr while the bench runs, when it is a terminal */
static double budget = 1;
static char wisdom[128];

static double now(void)
{
    struct timespec t;
    clock_gettime(CLOCK_MONOTONIC, &t);
    return (double)t.tv_sec + 1e-9 * (double)t.tv_nsec;
}

static char out[65536];
static void capture(void *user, const char *text)
{
    (void)user;
    strncat(out, text, sizeof out - strlen(out) - 1);
}

static int exec(const char *text)
{
    if (SILC_EXEC(text)) {
        fprintf(stderr, "tuner: '%s': %s\n", text, silc_errmsg());
        return 1;
    }
    return 0;
}

/* Opens the default context with the bench's settings. */
static int setup(void)
{
    char cmd[600];
    if (SILC_INIT()) {
        fprintf(stderr, "tuner: %s\n", silc_errmsg());
        return 1;
    }
    silc_set_output(silc_default_context(), capture, NULL);
    snprintf(cmd, sizeof cmd, "set tune.wisdom = %s", wisdom);
    if (exec(cmd)) return 1;
    if (backend) {
        snprintf(cmd, sizeof cmd, "set dispatch.solve.sparse.spd = %s", backend);
        if (exec(cmd)) return 1;
    }
    if (backend && options) {
        snprintf(cmd, sizeof cmd, "set %s.options = %s", backend, options);
        if (exec(cmd)) return 1;
    }
    return 0;
}

static double run(int64_t n, int steps, double *u)
{
    double t0;
    diff2d_initial(n, u);
    t0 = now();
    if (diff_run(2, n, steps, 1e-4, u)) {
        fprintf(stderr, "tuner: diff_run: %s\n", silc_errmsg());
        exit(1);
    }
    return (now() - t0) / steps;
}

static int status_int(const char *key)
{
    char pat[64];
    const char *at;
    snprintf(pat, sizeof pat, "%s = ", key);
    at = strstr(out, pat);
    return at ? atoi(at + strlen(pat)) : -1;
}

static int cores(void)
{
    long n = sysconf(_SC_NPROCESSORS_ONLN);
    return n < 1 ? 1 : (int)n;
}

/* The main example's loop untuned, tuned from no wisdom, tuned from the
 * wisdom that run wrote: seconds for the whole loop, best of 3 rounds. */
static void first_run_cost(void)
{
    enum { N = 200, STEPS = 200, ROUNDS = 3 };
    static const char *const how[3] = {"untuned", "tune.threads = auto, first run (no wisdom)",
                                       "tune.threads = auto, with the wisdom of the first"};
    double best[3] = {1e300, 1e300, 1e300}, *u = malloc((size_t)N * N * sizeof *u);
    int r, k;
    if (!u) return;
    for (r = 0; r < ROUNDS; r++)
        for (k = 0; k < 3; k++) {
            double t;
            if (setup()) exit(1);
            if (k == 1 && exec("tune forget")) exit(1);
            if (k > 0 && exec("set tune.threads = auto")) exit(1);
            t = run(N, STEPS, u) * STEPS;
            if (t < best[k]) best[k] = t;
            SILC_FINALIZE();
        }
    printf("\n# first-run cost of tuning: n = %d, %d steps, best of %d rounds\n", N, STEPS, ROUNDS);
    printf("| run | seconds | ratio to untuned |\n|---|---:|---:|\n");
    for (k = 0; k < 3; k++) printf("| %s | %.3f | %.2f |\n", how[k], best[k], best[k] / best[0]);
    free(u);
}

int main(int argc, char **argv)
{
    int sides[16], nsides = 0, steps = 40, i, p, pmax, c = cores(), good = 0;
    static const int def[] = {71, 100, 142, 200};
    for (i = 1; i < argc; i++) {
        if (!strcmp(argv[i], "--steps") && i + 1 < argc) steps = atoi(argv[++i]);
        else if (!strcmp(argv[i], "--backend") && i + 1 < argc) backend = argv[++i];
        else if (!strcmp(argv[i], "--options") && i + 1 < argc) options = argv[++i];
        else if (!strcmp(argv[i], "--budget") && i + 1 < argc) budget = atof(argv[++i]);
        else if (atoi(argv[i]) > 0 && nsides < 16) sides[nsides++] = atoi(argv[i]);
        else {
            fprintf(stderr, "usage: tuner [--steps S] [--backend NAME] [--options TEXT] "
                            "[--budget B] [n ...]\n");
            return 2;
        }
    }
    if (!nsides) memcpy(sides, def, sizeof def), nsides = 4;
    if (steps < 10) steps = 10;
    snprintf(wisdom, sizeof wisdom, "/tmp/silc-bench-wisdom-%ld", (long)getpid());
    /* the tuner's largest candidate: 4x the cores on a small machine */
    pmax = c <= 4 ? 4 * c : c;
    printf("# %d cores, %d steps, backend %s%s%s, budget %g; times are seconds per step\n", c,
           steps, backend ? backend : "(configured)", options ? " " : "", options ? options : "",
           budget);
    printf("%6s %8s %7s %11s %6s %11s %8s %8s  %s\n", "n", "N", "p_true", "t_true", "p_opt",
           "t(p_opt)", "eps_rel", "sampled", "stopped because");
    for (i = 0; i < nsides; i++) {
        int64_t n = sides[i];
        double *u = malloc((size_t)(n * n) * sizeof *u), t[65], best = 1e300;
        int pbest = 1, popt, sampled;
        char cmd[200], *why, none[] = "not finished within the run";
        if (!u) return 1;
        for (p = 1; p <= pmax && p <= 64; p++) {
            double a, b;
            progress_show(&bar, "tuner bench: n = %lld, p = %d of %d", (long long)n, p, pmax);
            if (setup()) return 1;
            snprintf(cmd, sizeof cmd, "set tune.threads = %d", p);
            if (exec(cmd)) return 1;
            a = run(n, steps, u);
            b = run(n, steps, u);
            t[p] = a < b ? a : b;
            if (t[p] < best) best = t[p], pbest = p;
            SILC_FINALIZE();
        }
        progress_done(&bar);
        if (setup()) return 1;
        snprintf(cmd, sizeof cmd, "set tune.max_threads = %d", pmax);
        if (exec(cmd)) return 1;
        /* budget 1: the run length is not told, so sampling may cost up to
         * the run so far, and the leave-one-out rule and the candidate set
         * end it */
        if (budget >= 1) snprintf(cmd, sizeof cmd, "tune forget; tune on");
        else snprintf(cmd, sizeof cmd, "tune forget; set tune.budget = %g; tune on %d", budget, steps);
        if (exec(cmd)) return 1;
        run(n, budget >= 1 && steps < 60 ? 60 : steps, u);
        out[0] = 0;
        if (exec("tune status")) return 1;
        popt = status_int("p_opt");
        sampled = status_int("sampled steps");
        why = strstr(out, "stopped because = ");
        why = why ? why + 18 : none;
        why[strcspn(why, "\n")] = 0;
        if (popt >= 1 && popt <= pmax) {
            double eps = (t[popt] - best) / best;
            good += eps < 0.05;
            printf("%6lld %8lld %7d %11.4g %6d %11.4g %7.1f%% %8d  %s\n", (long long)n,
                   (long long)(n * n), pbest, best, popt, t[popt], 100 * eps, sampled, why);
        } else {
            printf("%6lld %8lld %7d %11.4g %6s %11s %8s %8d  %s\n", (long long)n, (long long)(n * n),
                   pbest, best, "-", "-", "-", sampled, why);
        }
        printf("#   t(p):");
        for (p = 1; p <= pmax && p <= 64; p++) printf(" %d:%.4g", p, t[p]);
        printf("\n");
        fflush(stdout);
        SILC_FINALIZE();
        free(u);
    }
    printf("# %d of %d cases with eps_rel < 5%%\n", good, nsides);
    first_run_cost();
    remove(wisdom);
    return 0;
}
