/*
 * cloth.c -- the cloth example's three drivers timed against each other
 * (examples/cloth, issue 16's bench; bench/cloth.sh runs it embedded and
 * through silcd).
 *
 *     cloth_bench SCENE... [--steps N] [--rounds R] [--label TEXT]
 *     cloth_bench SCENE... --trade [--steps N] [--svg DIR]
 *
 * For each scene it runs original (plain C, its own CG), ltd and cmp from the
 * scene's start for N steps (default 50), R rounds (default 3), the drivers
 * interleaved within a round so that drift of the machine hits all alike,
 * and prints one markdown row per driver and solver: the best per-step time
 * of the rounds, its split into assembly / solve / update, and the ratio to
 * original's best from the same run.  ltd and cmp run twice: with SILC's
 * CG + Jacobi at original's tolerance (the same algorithm and stopping rule,
 * so the ratio is the cost of the mode) and with the configured dispatch
 * (a sparse Cholesky).  The largest position difference to original at the
 * end is printed too, so a fast wrong run shows.  SILC_SERVER, when set,
 * sends ltd and cmp to silcd; --label says so in the rows.
 *
 * --trade: the speed/accuracy trade.  The scene runs N steps with the solve
 * by original's CG, lis-style CG + IC(0) and CG + SA-AMG, PETSc CG + ICC at
 * tolerances 1e-2 ... 1e-12, and a direct solve, each against a direct run
 * of the same steps: ms per step against the largest particle error
 * relative to the cloth size.  It prints a table marking the Pareto front
 * and the point the scene's accuracy selects (the fastest that meets it),
 * and with --svg DIR writes DIR/cloth_trade_SCENE.svg.
 */
#define _POSIX_C_SOURCE 200809L
#include "progress.h"
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "cloth.h"

typedef struct variant {
    cloth_mode mode;
    const char *solver; /* a cloth_solver_options name */
} variant;

/* "cg" is original's algorithm and stopping rule in SILC, so its ratio to
 * original is the cost of the mode; "direct" is what a user gets. */
static const variant variants[] = {
    {CLOTH_ORIGINAL, "cg"}, {CLOTH_LTD, "cg"}, {CLOTH_CMP, "cg"}, {CLOTH_LTD, "direct"}, {CLOTH_CMP, "direct"},
};
enum { NV = sizeof variants / sizeof variants[0] };

static progress bar; /* on stderr while the bench runs, when it is a terminal */

/* One run from the scene's start: per-step times and the final positions
 * (3n, in x).  solver as in variant; tol is also original's CG tolerance.
 * -1 with err on failure. */
static int run(const cloth_scene *s, cloth_mode mode, const char *solver, double tol, int steps, cloth_times *t,
               double *x, char *err, size_t errlen)
{
    cloth_model m;
    cloth_driver *d;
    int k, ok = 1;
    memset(t, 0, sizeof *t);
    if (cloth_model_init(&m, s, err, errlen)) return -1;
    d = cloth_driver_open(&m, mode, solver, tol, err, errlen);
    for (k = 0; d && ok && k < steps; k++) ok = cloth_driver_step(d, t, err, errlen) == 0;
    ok = d && ok && cloth_driver_sync(d, err, errlen) == 0;
    if (ok) memcpy(x, m.x, (size_t)3 * m.n * sizeof *x);
    cloth_driver_close(d);
    cloth_model_free(&m);
    return ok ? 0 : -1;
}

static double max_diff(const double *a, const double *b, int n)
{
    double d = 0;
    int i;
    for (i = 0; i < n; i++) d = fmax(d, fabs(a[i] - b[i]));
    return d;
}

/* ---- --trade: time against accuracy ------------------------------------------ */

/* One solver of the trade study, at each of trade_tols. */
typedef struct trade_solver {
    const char *name;   /* the legend's */
    const char *solver; /* a cloth_solver_options name ("cg" with mode original: its own CG) */
    cloth_mode mode;
    const char *color;
} trade_solver;

static const trade_solver trade_solvers[] = {
    {"original CG + Jacobi", "cg", CLOTH_ORIGINAL, "#444444"},
    {"lis-style CG + IC(0)", "cg-ic", CLOTH_LTD, "#1f77b4"},
    {"lis-style CG + SA-AMG", "cg-amg", CLOTH_LTD, "#2ca02c"},
    {"petsc CG + ICC", "petsc-cg", CLOTH_LTD, "#d62728"},
    {"direct (CHOLMOD)", "direct", CLOTH_LTD, "#9467bd"},
};

/* An iterative point: one per tolerance.  A direct solve has one point. */
static int trade_iterative(const trade_solver *ts)
{
    return strcmp(ts->solver, "direct") != 0;
}
enum { NTS = sizeof trade_solvers / sizeof trade_solvers[0], NTOL = 6 };
static const double trade_tols[NTOL] = {1e-2, 1e-4, 1e-6, 1e-8, 1e-10, 1e-12};

typedef struct trade_point {
    int solver;
    double tol, ms, err; /* err: max particle distance to the direct run / cloth size */
    int pareto;
} trade_point;

static void svg_plot(FILE *f, const cloth_scene *s, const trade_point *p, int np, int chosen)
{
    const double W = 640, H = 420, L = 70, R = 190, T = 30, B = 50;
    double emin = 1e300, emax = 0, tmin = 1e300, tmax = 0;
    int i, k;
    for (i = 0; i < np; i++) {
        double e = fmax(p[i].err, 1e-16);
        emin = fmin(emin, e), emax = fmax(emax, e), tmin = fmin(tmin, p[i].ms), tmax = fmax(tmax, p[i].ms);
    }
    emin = floor(log10(emin)), emax = ceil(log10(emax)), tmin = log10(tmin) - 0.1, tmax = log10(tmax) + 0.1;
    if (emax <= emin) emax = emin + 1;
#define PX(e) (L + (log10(fmax((e), 1e-16)) - emin) / (emax - emin) * (W - L - R))
#define PY(t) (H - B - (log10(t) - tmin) / (tmax - tmin) * (H - T - B))
    fprintf(f, "<svg xmlns='http://www.w3.org/2000/svg' width='%g' height='%g' font-family='sans-serif' "
               "font-size='11'>\n<rect width='100%%' height='100%%' fill='white'/>\n", W, H);
    fprintf(f, "<text x='%g' y='18' font-size='13'>%s %dx%d: time per step against position error "
               "(accuracy %g)</text>\n", L, s->name, s->nx, s->ny, s->accuracy);
    fprintf(f, "<line x1='%g' y1='%g' x2='%g' y2='%g' stroke='black'/><line x1='%g' y1='%g' x2='%g' y2='%g' "
               "stroke='black'/>\n", L, H - B, W - R, H - B, L, T, L, H - B);
    for (k = (int)emin; k <= (int)emax; k++)
        fprintf(f, "<text x='%g' y='%g' text-anchor='middle'>1e%d</text>\n", PX(pow(10, k)), H - B + 15, k);
    fprintf(f, "<text x='%g' y='%g' text-anchor='middle'>max |x - x_direct| / cloth size</text>\n",
            (L + W - R) / 2, H - 12);
    fprintf(f, "<text x='14' y='%g' transform='rotate(-90 14 %g)' text-anchor='middle'>ms per step "
               "(log)</text>\n", (T + H - B) / 2, (T + H - B) / 2);
    for (k = (int)floor(tmin); k <= (int)ceil(tmax); k++)
        if (k >= tmin && k <= tmax)
            fprintf(f, "<text x='%g' y='%g' text-anchor='end'>%g</text>\n", L - 4, PY(pow(10, k)) + 4, pow(10, k));
    /* the scene's accuracy as a vertical line */
    fprintf(f, "<line x1='%g' y1='%g' x2='%g' y2='%g' stroke='#888' stroke-dasharray='4 3'/>\n",
            PX(s->accuracy), T, PX(s->accuracy), H - B);
    /* the Pareto front, joined in order of error */
    fprintf(f, "<polyline fill='none' stroke='#ff7f0e' stroke-width='1.5' points='");
    /* (sorted by error: an insertion sort, the points are few) */
    {
        int order[64], n = 0, a, b;
        for (i = 0; i < np && n < 64; i++)
            if (p[i].pareto) order[n++] = i;
        for (a = 1; a < n; a++)
            for (b = a; b > 0 && p[order[b]].err < p[order[b - 1]].err; b--) {
                int t = order[b];
                order[b] = order[b - 1], order[b - 1] = t;
            }
        for (a = 0; a < n; a++) fprintf(f, "%.1f,%.1f ", PX(p[order[a]].err), PY(p[order[a]].ms));
    }
    fprintf(f, "'/>\n");
    for (i = 0; i < np; i++)
        fprintf(f, "<circle cx='%.1f' cy='%.1f' r='%d' fill='%s'%s><title>%s, tol %g: %.3g ms, error %.2g</title>"
                   "</circle>\n",
                PX(p[i].err), PY(p[i].ms), p[i].pareto ? 5 : 3, trade_solvers[p[i].solver].color,
                i == chosen ? " stroke='black' stroke-width='2.5'" : "", trade_solvers[p[i].solver].name, p[i].tol,
                p[i].ms, p[i].err);
    for (k = 0; k < NTS; k++)
        fprintf(f, "<circle cx='%g' cy='%g' r='4' fill='%s'/><text x='%g' y='%g'>%s</text>\n", W - R + 12,
                T + 10 + 16.0 * k, trade_solvers[k].color, W - R + 20, T + 14 + 16.0 * k, trade_solvers[k].name);
    fprintf(f, "<polyline points='%g,%g %g,%g' stroke='#ff7f0e' stroke-width='1.5'/><text x='%g' y='%g'>Pareto "
               "front</text>\n", W - R + 6, T + 10 + 16.0 * NTS, W - R + 18, T + 10 + 16.0 * NTS, W - R + 20,
            T + 14 + 16.0 * NTS);
    fprintf(f, "<circle cx='%g' cy='%g' r='5' fill='none' stroke='black' stroke-width='2.5'/><text x='%g' y='%g'>"
               "chosen by the accuracy</text>\n</svg>\n", W - R + 12, T + 10 + 16.0 * (NTS + 1), W - R + 20,
            T + 14 + 16.0 * (NTS + 1));
#undef PX
#undef PY
}

/* One run of the trade study: ms per step and the largest particle error
 * against xref. */
static int trade_run(const cloth_scene *s, const trade_solver *ts, double tol, int steps, const double *xref,
                     double *ms, double *err_out, char *err, size_t errlen)
{
    int n3 = 3 * s->nx * s->ny, rc;
    double *x = malloc((size_t)n3 * sizeof *x);
    cloth_times t;
    if (!x) {
        snprintf(err, errlen, "out of memory");
        return -1;
    }
    rc = run(s, ts->mode, ts->solver, tol, steps, &t, x, err, errlen);
    *ms = 1e3 * (t.assembly + t.solve + t.update) / steps;
    *err_out = rc ? NAN : max_diff(x, xref, n3);
    free(x);
    return rc;
}

/* Every solver at every tolerance against a direct run of the same steps. */
static int trade(const char *path, int steps, const char *svg_dir)
{
    cloth_scene s;
    char err[1024];
    trade_point pts[NTS * NTOL];
    double *xref, size;
    int np = 0, i, j, n3, chosen = -1;
    if (scene_read(path, &s, err, sizeof err)) {
        fprintf(stderr, "cloth_bench: %s\n", err);
        return -1;
    }
    n3 = 3 * s.nx * s.ny;
    size = fmax(s.width, s.height);
    xref = calloc((size_t)n3, sizeof *xref);
    if (!xref) return -1;
    {
        cloth_times t;
        if (run(&s, CLOTH_LTD, "direct", 1e-12, steps, &t, xref, err, sizeof err)) {
            fprintf(stderr, "cloth_bench: %s direct reference: %s\n", s.name, err);
            free(xref);
            return -1;
        }
    }
    for (i = 0; i < NTS; i++)
        for (j = 0; j < NTOL; j++) {
            const trade_solver *ts = &trade_solvers[i];
            double ms, ms2, e;
            if (!trade_iterative(ts) && j > 0) break;
            /* Twice, the faster kept: a library's first run pays its start-up
             * (PETSc's is 0.25 s), which is no part of a step. */
            if (trade_run(&s, ts, trade_tols[j], steps, xref, &ms, &e, err, sizeof err) ||
                trade_run(&s, ts, trade_tols[j], steps, xref, &ms2, &e, err, sizeof err)) {
                printf("| %s | %s | %g | failed: %.80s | | |\n", s.name, ts->name, trade_tols[j], err);
                continue;
            }
            pts[np].solver = i;
            pts[np].tol = trade_iterative(ts) ? trade_tols[j] : 0;
            pts[np].ms = fmin(ms, ms2);
            pts[np].err = isfinite(e) ? e / size : INFINITY;
            pts[np].pareto = 0;
            np++;
        }
    /* Pareto: no other point is as fast and as accurate, and better in one.
     * 1: on the front of all points; 2: on the front of the iterative ones
     * (where a direct solve with a reused factorization beats them all, the
     * front of all is that one point). */
    for (i = 0; i < np; i++) {
        int all = isfinite(pts[i].err), iter = all && trade_iterative(&trade_solvers[pts[i].solver]);
        iter = iter || (all && trade_solvers[pts[i].solver].mode == CLOTH_ORIGINAL);
        for (j = 0; j < np; j++)
            if (j != i && pts[j].ms <= pts[i].ms && pts[j].err <= pts[i].err &&
                (pts[j].ms < pts[i].ms || pts[j].err < pts[i].err)) {
                all = 0;
                if (pts[j].tol > 0) iter = 0;
            }
        pts[i].pareto = all ? 1 : iter ? 2 : 0;
        if (pts[i].err <= s.accuracy && (chosen < 0 || pts[i].ms < pts[chosen].ms)) chosen = i;
    }
    printf("\n%s %dx%d, %d steps, accuracy %g (max particle error / cloth size against a direct run):\n\n",
           s.name, s.nx, s.ny, steps, s.accuracy);
    printf("| solver | tolerance | ms/step | error | meets the accuracy | Pareto |\n|---|---:|---:|---:|---|---|\n");
    for (i = 0; i < np; i++)
        printf("| %s | %s | %.3f | %.2g | %s | %s |\n", trade_solvers[pts[i].solver].name,
               pts[i].tol > 0 ? (snprintf(err, sizeof err, "%g", pts[i].tol), err) : "-", pts[i].ms, pts[i].err,
               pts[i].err <= s.accuracy ? (i == chosen ? "yes: chosen (fastest that does)" : "yes") : "no",
               pts[i].pareto == 1 ? "front" : pts[i].pareto == 2 ? "front of the iterative" : "");
    if (svg_dir) {
        char file[1024];
        FILE *f;
        snprintf(file, sizeof file, "%s/cloth_trade_%s.svg", svg_dir, s.name);
        if ((f = fopen(file, "w"))) {
            svg_plot(f, &s, pts, np, chosen);
            fclose(f);
            printf("\n(plot: %s)\n", file);
        }
    }
    free(xref);
    return 0;
}

int main(int argc, char **argv)
{
    int steps = 50, rounds = 3, a, sc, nscenes = 0;
    const char *label = "embedded", *scenes[16], *svg_dir = NULL;
    int trading = 0;
    for (a = 1; a < argc; a++) {
        if (!strcmp(argv[a], "--steps") && a + 1 < argc) steps = atoi(argv[++a]);
        else if (!strcmp(argv[a], "--rounds") && a + 1 < argc) rounds = atoi(argv[++a]);
        else if (!strcmp(argv[a], "--label") && a + 1 < argc) label = argv[++a];
        else if (!strcmp(argv[a], "--trade")) trading = 1;
        else if (!strcmp(argv[a], "--svg") && a + 1 < argc) svg_dir = argv[++a];
        else if (argv[a][0] != '-' && nscenes < 16) scenes[nscenes++] = argv[a];
        else {
            fprintf(stderr, "usage: cloth_bench SCENE... [--steps N] [--rounds R] [--label TEXT] | --trade [--svg DIR]\n");
            return 2;
        }
    }
    if (!nscenes || steps < 1 || rounds < 1) {
        fprintf(stderr, "usage: cloth_bench SCENE... [--steps N] [--rounds R] [--label TEXT] | --trade [--svg DIR]\n");
        return 2;
    }
    if (trading) {
        for (sc = 0; sc < nscenes; sc++)
            if (trade(scenes[sc], steps, svg_dir)) return 1;
        return 0;
    }
    printf("| scene | where | driver, solver | ms/step | assembly | solve | update | ratio to original | "
           "max |x - x_original| |\n|---|---|---|---:|---:|---:|---:|---:|---:|\n");
    for (sc = 0; sc < nscenes; sc++) {
        cloth_scene s;
        char err[1024];
        double best[NV], split[NV][3], diff[NV], *x0, *x, tol;
        int r, v, n3;
        if (scene_read(scenes[sc], &s, err, sizeof err)) {
            fprintf(stderr, "cloth_bench: %s\n", err);
            return 1;
        }
        tol = s.accuracy / 100;
        n3 = 3 * s.nx * s.ny;
        x0 = calloc((size_t)n3, sizeof *x0);
        x = calloc((size_t)n3, sizeof *x);
        if (!x0 || !x) return 1;
        for (v = 0; v < NV; v++) best[v] = INFINITY, diff[v] = NAN;
        for (r = 0; r < rounds; r++)
            for (v = 0; v < NV; v++) {
                cloth_times t;
                double per;
                progress_show(&bar, "cloth bench: %s, round %d of %d, %s", s.name, r + 1, rounds,
                              cloth_mode_name(variants[v].mode));
                if (run(&s, variants[v].mode, variants[v].solver, tol, steps, &t, v == 0 ? x0 : x, err,
                        sizeof err)) {
                    fprintf(stderr, "cloth_bench: %s %s: %s\n", s.name, cloth_mode_name(variants[v].mode), err);
                    continue;
                }
                per = (t.assembly + t.solve + t.update) / steps;
                if (v > 0) diff[v] = max_diff(x, x0, n3);
                if (per < best[v]) {
                    best[v] = per;
                    split[v][0] = t.assembly / steps, split[v][1] = t.solve / steps, split[v][2] = t.update / steps;
                }
            }
        progress_done(&bar);
        for (v = 0; v < NV; v++) {
            char what[128];
            if (!isfinite(best[v])) {
                printf("| %s | %s | %s | failed | | | | | |\n", s.name, label, cloth_mode_name(variants[v].mode));
                continue;
            }
            snprintf(what, sizeof what, "%s, %s", cloth_mode_name(variants[v].mode),
                     variants[v].mode == CLOTH_ORIGINAL ? "own CG + Jacobi" : cloth_solver_label(variants[v].solver));
            {
                char d[32] = "-";
                if (v) snprintf(d, sizeof d, "%.2g", diff[v]);
                printf("| %s %dx%d | %s | %s | %.3f | %.3f | %.3f | %.3f | %.2f | %s |\n", s.name, s.nx, s.ny,
                       variants[v].mode == CLOTH_ORIGINAL ? "-" : label, what, 1e3 * best[v], 1e3 * split[v][0],
                       1e3 * split[v][1], 1e3 * split[v][2], best[v] / best[0], d);
            }
        }
        free(x0);
        free(x);
    }
    printf("(%d steps per run, best of %d rounds; CG tolerance = the scene's accuracy / 100, relative to "
           "||b||)\n", steps, rounds);
    return 0;
}
