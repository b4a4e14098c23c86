/*
 * cloth.c -- the cloth example's three drivers timed against each other
 * (examples/cloth, issue 16's bench; bench/cloth.sh runs it embedded and
 * through silcd).
 *
 *     cloth_bench SCENE... [--steps N] [--rounds R] [--label TEXT]
 *     cloth_bench SCENE... --trade [--steps N] [--svg DIR]
 *     cloth_bench SCENE... --energy [--steps N] [--svg DIR]
 *     cloth_bench SCENE... --seed-statements [--steps N] [--rounds R] [--label TEXT]
 *
 * For each scene it runs original (plain C, its own CG), ltd and cmp from the
 * scene's start for N steps (default 50), R rounds (default 3), the drivers
 * interleaved within a round so that drift of the machine hits all alike,
 * and prints one markdown row per driver and solver: the best per-step time
 * of the rounds, its split into assembly / solve / update, and the ratio to
 * original's best from the same run.  ltd and cmp run twice: with SILC's
 * CG + Jacobi at original's tolerance (meant as the same algorithm and
 * stopping rule, so the ratio is the cost of the mode: a first, untimed
 * round counts every solve's iterations so the table shows whether it is)
 * and with the configured dispatch (a sparse Cholesky).  The tolerance is
 * the scene's default (cloth_default_tol).  The largest position difference
 * to original at the end is printed too, so a fast wrong run shows.
 * SILC_SERVER, when set, sends ltd and cmp to silcd; --label says so.
 *
 * --trade: the speed/accuracy trade over the whole scene (its own steps
 * unless --steps says otherwise), with the solve by original's CG,
 * lis-style CG + IC(0) and CG + SA-AMG, PETSc CG + ICC at tolerances 1e-2
 * ... 1e-12, and the direct solve, each against a direct run of the same
 * steps: ms per step against the largest particle error relative to the
 * cloth size.  It prints a table marking the Pareto front (the points no
 * other is both as fast and as accurate as, and better in one) and the
 * point the scene's accuracy selects (the fastest that meets it), and with
 * --svg DIR writes DIR/cloth_trade_SCENE.svg.
 *
 * --energy: each scene (hanging and large in docs/cloth.md) for N steps
 * (default 200) twice, with the seeds' pin handling (a free solve, the
 * pins' dv dropped after: cloth_model.pins_after_solve, reachable only
 * here) and with the pins constrained in the solve: the largest spring
 * stretch and the total energy, a table and DIR/cloth_energy.svg.
 *
 * --seed-statements (issue 30 item 1): the cmp mode's statements against a
 * plain-C step doing the same arithmetic written for speed
 * (cloth_c_step.c), both with CG + Jacobi at 1e-10 from the last step's dv:
 * N steps (default 50) per run, R timed rounds (default 5), C and SILC
 * alternating, after a first round that checks the two end at the same
 * positions (to the solver's tolerance) after the same iterations.  One row
 * per scene: best and median ms per step of each, their ratios, and the
 * phases of SILC's best run.
 */
#define _POSIX_C_SOURCE 200809L
#include "progress.h"
#include "timing.h"
#include <dirent.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "cloth.h"
#include "cloth_c_step.h"

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

/* What one run gives back. */
typedef struct run_out {
    cloth_times t;
    double *x;          /* 3n: the final positions, or NULL */
    double *energy;     /* steps + 1: the total energy before each step and at the end, or NULL */
    double stretch;     /* the largest spring stretch of the run (with energy) */
    long iterations;    /* the solves' iterations summed (with count_iterations) */
    char used[256];     /* ltd, cmp: what ran the solve (`info dv`) */
} run_out;

/* One run from the scene's start.  tol <= 0: cloth_default_tol.  old: the
 * seeds' pins (dropped after a free solve).  count_iterations asks every
 * solve's report, outside the timed phases.  -1 with err on failure. */
static int run(const cloth_scene *s, cloth_mode mode, const char *solver, double tol, int steps, int old,
               int count_iterations, run_out *o, char *err, size_t errlen)
{
    cloth_model m;
    cloth_driver *d;
    int k, ok = 1;
    memset(&o->t, 0, sizeof o->t);
    o->stretch = 0, o->iterations = 0, o->used[0] = '\0';
    if (cloth_model_init(&m, s, err, errlen)) return -1;
    m.pins_after_solve = old;
    d = cloth_driver_open(&m, mode, solver, tol > 0 ? tol : cloth_default_tol(&m), err, errlen);
    if (d && o->energy) o->energy[0] = cloth_total_energy(&m, m.x, m.v);
    for (k = 0; d && ok && k < steps; k++) {
        ok = cloth_driver_step(d, &o->t, err, errlen) == 0;
        if (ok && count_iterations) {
            double berr, cond;
            long it = 0;
            ok = cloth_driver_solve_report(d, &berr, &cond, &it, err, errlen) == 0;
            o->iterations += it;
        }
        if (ok && o->energy) {
            ok = cloth_driver_sync(d, err, errlen) == 0;
            o->energy[k + 1] = cloth_total_energy(&m, m.x, m.v);
            o->stretch = fmax(o->stretch, cloth_max_stretch(&m, m.x));
        }
    }
    ok = d && ok && cloth_driver_sync(d, err, errlen) == 0;
    if (ok && o->x) memcpy(o->x, m.x, (size_t)3 * m.n * sizeof *o->x);
    if (ok) cloth_driver_solver(d, o->used, sizeof o->used);
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

/* ---- SVG axes ---------------------------------------------------------------- */

/* Ticks of a log axis over [lo, hi] (log10 units): 1-2-5 per decade, or
 * every decade, or every k-th decade, whichever keeps labels at least
 * `room` pixels apart on an axis of `px` pixels.  Values into v, their
 * count returned. */
static int log_ticks(double lo, double hi, double px, double room, double *v, int cap)
{
    static const double mant[3] = {1, 2, 5};
    double per_decade = px / fmax(hi - lo, 1e-9);
    int n = 0, e, j, fine = per_decade >= 3 * room, stride = fine ? 1 : (int)ceil(room / per_decade);
    for (e = (int)floor(lo); e <= (int)ceil(hi) && n < cap; e++) {
        if (((e % stride) + stride) % stride) continue;
        for (j = 0; j < (fine ? 3 : 1) && n < cap; j++) {
            double x = mant[j] * pow(10, e);
            if (log10(x) >= lo - 1e-9 && log10(x) <= hi + 1e-9) v[n++] = x;
        }
    }
    return n;
}

/* A tick label: 1e-6 style for decades beyond 1e+-3, plain otherwise. */
static void tick_label(double x, char *buf, size_t len)
{
    double e = log10(x);
    if ((e < -3 || e > 4) && fabs(e - round(e)) < 1e-9) snprintf(buf, len, "1e%d", (int)round(e));
    else snprintf(buf, len, "%g", x);
}

/* Linear ticks over [lo, hi]: a 1-2-5 step giving 4 to 10 ticks. */
static int lin_ticks(double lo, double hi, double *v, int cap)
{
    double span = hi - lo, step = pow(10, floor(log10(span > 0 ? span : 1))), x;
    int n = 0;
    if (span / step < 4) step /= 2;
    if (span / step < 4) step /= 2.5;
    for (x = ceil(lo / step) * step; x <= hi + 1e-9 * step && n < cap; x += step) v[n++] = fabs(x) < 1e-12 * step ? 0 : x;
    return n;
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
    {"direct", "direct", CLOTH_LTD, "#9467bd"},
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
    int pareto;          /* no other point is as fast and as accurate, and better in one */
} trade_point;

/* The plot: x = error (log), y = ms per step (log).  The direct solve is
 * the reference, so its error is 0 by definition: it sits in a column of
 * its own left of a break in the x axis, labelled so, not at a made-up
 * small error.  The Pareto front joins the non-dominated points only, in
 * order of error, as a staircase (between two front points nothing is
 * attainable below the step). */
static void svg_plot(FILE *f, const cloth_scene *s, const trade_point *p, int np, int chosen, const char *direct)
{
    const double W = 720, H = 440, L = 130, R = 200, T = 34, B = 56, ZERO = 78;
    double emin = 1e300, emax = 0, tmin = 1e300, tmax = 0, ticks[64], axis = W - L - R;
    char lab[32];
    int i, k, nt, order[64], n = 0;
    for (i = 0; i < np; i++) {
        if (p[i].err > 0 && isfinite(p[i].err)) emin = fmin(emin, p[i].err), emax = fmax(emax, p[i].err);
        tmin = fmin(tmin, p[i].ms), tmax = fmax(tmax, p[i].ms);
    }
    if (emax == 0) emin = 1e-16, emax = 1;
    /* a decade beyond the accuracy, so its line stands clear of the edge */
    emin = floor(log10(fmin(emin, s->accuracy))), emax = fmax(ceil(log10(emax)), floor(log10(s->accuracy)) + 1);
    if (emax <= emin) emax = emin + 1;
    tmin = log10(tmin) - 0.08, tmax = log10(tmax) + 0.08;
#define PX(e) ((e) > 0 ? L + (log10(e) - emin) / (emax - emin) * axis : ZERO)
#define PY(t) (H - B - (log10(t) - tmin) / (tmax - tmin) * (H - T - B))
    fprintf(f, "<svg xmlns='http://www.w3.org/2000/svg' width='%g' height='%g' font-family='sans-serif' "
               "font-size='11'>\n<rect width='100%%' height='100%%' fill='white'/>\n", W, H);
    fprintf(f, "<text x='%g' y='18' font-size='13'>%s %dx%d, %d steps: time per step against position error "
               "(accuracy %g)</text>\n", 14.0, s->name, s->nx, s->ny, s->steps, s->accuracy);
    /* axes, with a break between the error-0 column and the log axis */
    fprintf(f, "<line x1='%g' y1='%g' x2='%g' y2='%g' stroke='black'/>\n", ZERO - 22, H - B, ZERO + 22, H - B);
    fprintf(f, "<line x1='%g' y1='%g' x2='%g' y2='%g' stroke='black'/>\n", L - 8, H - B, W - R, H - B);
    fprintf(f, "<text x='%g' y='%g' text-anchor='middle'>//</text>\n", (ZERO + 22 + L - 8) / 2, H - B + 4);
    fprintf(f, "<line x1='%g' y1='%g' x2='%g' y2='%g' stroke='black'/>\n", ZERO - 22, T, ZERO - 22, H - B);
    fprintf(f, "<text x='%g' y='%g' text-anchor='middle'>0 (the</text><text x='%g' y='%g' text-anchor='middle'>"
               "reference)</text>\n", ZERO, H - B + 15, ZERO, H - B + 27);
    nt = log_ticks(emin, emax, axis, 44, ticks, 64);
    for (k = 0; k < nt; k++) {
        tick_label(ticks[k], lab, sizeof lab);
        fprintf(f, "<line x1='%.1f' y1='%g' x2='%.1f' y2='%g' stroke='black'/><text x='%.1f' y='%g' "
                   "text-anchor='middle'>%s</text>\n", PX(ticks[k]), H - B, PX(ticks[k]), H - B + 4, PX(ticks[k]),
                H - B + 15, lab);
    }
    fprintf(f, "<text x='%g' y='%g' text-anchor='middle'>max |x - x_direct| / cloth size (log)</text>\n",
            L + axis / 2, H - 14);
    nt = log_ticks(tmin, tmax, H - T - B, 16, ticks, 64);
    for (k = 0; k < nt; k++) {
        tick_label(ticks[k], lab, sizeof lab);
        fprintf(f, "<line x1='%g' y1='%.1f' x2='%g' y2='%.1f' stroke='#ddd'/><text x='%g' y='%.1f' "
                   "text-anchor='end'>%s</text>\n", ZERO - 22, PY(ticks[k]), W - R, PY(ticks[k]), ZERO - 26,
                PY(ticks[k]) + 4, lab);
    }
    fprintf(f, "<text x='14' y='%g' transform='rotate(-90 14 %g)' text-anchor='middle'>ms per step (log)</text>\n",
            (T + H - B) / 2, (T + H - B) / 2);
    fprintf(f, "<line x1='%.1f' y1='%g' x2='%.1f' y2='%g' stroke='#888' stroke-dasharray='4 3'/><text x='%.1f' "
               "y='%g' fill='#555' text-anchor='middle'>accuracy</text>\n", PX(s->accuracy), T, PX(s->accuracy),
            H - B, PX(s->accuracy), T - 4);
    /* the front */
    for (i = 0; i < np && n < 64; i++)
        if (p[i].pareto) order[n++] = i;
    for (i = 1; i < n; i++)
        for (k = i; k > 0 && p[order[k]].err < p[order[k - 1]].err; k--) {
            int t = order[k];
            order[k] = order[k - 1], order[k - 1] = t;
        }
    fprintf(f, "<polyline fill='none' stroke='#ff7f0e' stroke-width='1.5' points='");
    for (i = 0; i < n; i++) {
        if (i) fprintf(f, "%.1f,%.1f ", PX(p[order[i]].err), PY(p[order[i - 1]].ms));
        fprintf(f, "%.1f,%.1f ", PX(p[order[i]].err), PY(p[order[i]].ms));
    }
    fprintf(f, "'/>\n");
    if (n == 1) /* a front of one point: ringed, so that it shows */
        fprintf(f, "<circle cx='%.1f' cy='%.1f' r='9' fill='none' stroke='#ff7f0e' stroke-width='1.5'/>\n",
                PX(p[order[0]].err), PY(p[order[0]].ms));
    for (i = 0; i < np; i++)
        if (isfinite(p[i].err))
            fprintf(f, "<circle cx='%.1f' cy='%.1f' r='%d' fill='%s'%s><title>%s, tol %g: %.3g ms, error %.2g</title>"
                       "</circle>\n", PX(p[i].err), PY(p[i].ms), p[i].pareto ? 5 : 3, trade_solvers[p[i].solver].color,
                    i == chosen ? " stroke='black' stroke-width='2.5'" : "", trade_solvers[p[i].solver].name, p[i].tol,
                    p[i].ms, p[i].err);
    for (k = 0; k < NTS; k++)
        fprintf(f, "<circle cx='%g' cy='%g' r='4' fill='%s'/><text x='%g' y='%g'>%s</text>\n", W - R + 12,
                T + 10 + 16.0 * k, trade_solvers[k].color, W - R + 20, T + 14 + 16.0 * k,
                trade_iterative(&trade_solvers[k]) ? trade_solvers[k].name : "direct: the reference");
    fprintf(f, "<text x='%g' y='%g' font-size='9' fill='#555'>(%.*s)</text>\n", W - R + 20, T + 14 + 16.0 * NTS - 4,
            (int)strcspn(direct, ","), direct);
    fprintf(f, "<polyline points='%g,%g %g,%g' stroke='#ff7f0e' stroke-width='1.5'/><text x='%g' y='%g'>Pareto "
               "front%s</text>\n", W - R + 6, T + 10 + 16.0 * (NTS + 1), W - R + 18, T + 10 + 16.0 * (NTS + 1),
            W - R + 20, T + 14 + 16.0 * (NTS + 1), n == 1 ? ": one point" : "");
    fprintf(f, "<circle cx='%g' cy='%g' r='5' fill='none' stroke='black' stroke-width='2.5'/><text x='%g' y='%g'>"
               "fastest within the accuracy</text>\n", W - R + 12, T + 10 + 16.0 * (NTS + 2), W - R + 20,
            T + 14 + 16.0 * (NTS + 2));
    fprintf(f, "<text x='%g' y='%g' font-size='10' fill='#555'>each iterative solver at</text><text x='%g' y='%g' "
               "font-size='10' fill='#555'>tolerance 1e-2 ... 1e-12</text>\n</svg>\n", W - R + 8,
            T + 14 + 16.0 * (NTS + 3.5), W - R + 8, T + 14 + 16.0 * (NTS + 4.5));
#undef PX
#undef PY
}

/* Every solver at every tolerance against a direct run of the whole scene. */
static int trade(const char *path, int steps, const char *svg_dir)
{
    cloth_scene s;
    char err[1024], direct[256] = "";
    trade_point pts[NTS * NTOL];
    double *xref, *x, size;
    int np = 0, i, j, n3, chosen = -1;
    run_out o;
    if (scene_read(path, &s, err, sizeof err)) {
        fprintf(stderr, "cloth_bench: %s\n", err);
        return -1;
    }
    if (steps > 0) s.steps = steps;
    n3 = 3 * s.nx * s.ny;
    size = fmax(s.width, s.height);
    xref = calloc((size_t)n3, sizeof *xref);
    x = calloc((size_t)n3, sizeof *x);
    if (!xref || !x) return -1;
    memset(&o, 0, sizeof o);
    o.x = xref;
    if (run(&s, CLOTH_LTD, "direct", 1e-12, s.steps, 0, 0, &o, err, sizeof err)) {
        fprintf(stderr, "cloth_bench: %s direct reference: %s\n", s.name, err);
        free(xref), free(x);
        return -1;
    }
    snprintf(direct, sizeof direct, "%s", o.used);
    o.x = x;
    for (i = 0; i < NTS; i++)
        for (j = 0; j < NTOL; j++) {
            const trade_solver *ts = &trade_solvers[i];
            double ms = INFINITY;
            int r, ok = 1;
            if (!trade_iterative(ts) && j > 0) break;
            progress_show(&bar, "cloth bench --trade: %s, %s, tolerance %g", s.name, ts->name, trade_tols[j]);
            /* Twice, the faster kept: a library's first run pays its start-up
             * (PETSc's is 0.25 s), which is no part of a step. */
            for (r = 0; r < 2 && ok; r++) {
                ok = run(&s, ts->mode, ts->solver, trade_tols[j], s.steps, 0, 0, &o, err, sizeof err) == 0;
                ms = fmin(ms, 1e3 * (o.t.assembly + o.t.solve + o.t.update) / s.steps);
            }
            if (!ok) {
                progress_done(&bar);
                printf("| %s | %g | failed: %.80s | | | |\n", ts->name, trade_tols[j], err);
                continue;
            }
            pts[np].solver = i;
            pts[np].tol = trade_iterative(ts) ? trade_tols[j] : 0;
            pts[np].ms = ms;
            pts[np].err = max_diff(x, xref, n3) / size;
            if (!isfinite(pts[np].err)) pts[np].err = INFINITY;
            np++;
        }
    progress_done(&bar);
    for (i = 0; i < np; i++) {
        pts[i].pareto = isfinite(pts[i].err);
        for (j = 0; j < np; j++)
            if (j != i && pts[j].ms <= pts[i].ms && pts[j].err <= pts[i].err &&
                (pts[j].ms < pts[i].ms || pts[j].err < pts[i].err))
                pts[i].pareto = 0;
        if (pts[i].err <= s.accuracy && (chosen < 0 || pts[i].ms < pts[chosen].ms)) chosen = i;
    }
    printf("\n%s %dx%d, the whole run (%d steps), accuracy %g; error = max particle distance to the direct run "
           "(%s) / cloth size:\n\n", s.name, s.nx, s.ny, s.steps, s.accuracy, direct);
    printf("| solver | tolerance | ms/step | error | meets the accuracy | Pareto front |\n"
           "|---|---:|---:|---:|---|---|\n");
    for (i = 0; i < np; i++) {
        char tol[32] = "-", e[32] = "0 (the reference)";
        if (pts[i].tol > 0) snprintf(tol, sizeof tol, "%g", pts[i].tol);
        if (pts[i].tol > 0 || pts[i].err > 0) snprintf(e, sizeof e, "%.2g", pts[i].err);
        printf("| %s | %s | %.3f | %s | %s | %s |\n", trade_solvers[pts[i].solver].name, tol, pts[i].ms, e,
               pts[i].err <= s.accuracy ? (i == chosen ? "yes: the fastest that does" : "yes") : "no",
               pts[i].pareto ? "yes" : "");
    }
    if (svg_dir) {
        char file[1024];
        FILE *f;
        snprintf(file, sizeof file, "%s/cloth_trade_%s.svg", svg_dir, s.name);
        if ((f = fopen(file, "w"))) {
            svg_plot(f, &s, pts, np, chosen, direct);
            fclose(f);
            printf("\n(plot: %s)\n", file);
        }
    }
    free(xref), free(x);
    return 0;
}

/* ---- --energy: the pins before and after ---------------------------------------- */

enum { ENERGY_SCENES = 4 };

typedef struct energy_run {
    const cloth_scene *s;
    double *e[2];       /* [0]: the seeds' pins, [1]: constrained; steps + 1 values */
    double stretch[2];
} energy_run;

/* One panel per scene: total energy against time, before and after. */
static void energy_svg(FILE *f, const energy_run *r, int nr, int steps)
{
    const double PW = 380, H = 350, L = 70, T = 60, B = 50, R = 20;
    int i, k, b, nt;
    double ticks[64];
    char lab[32];
    fprintf(f, "<svg xmlns='http://www.w3.org/2000/svg' width='%g' height='%g' font-family='sans-serif' "
               "font-size='11'>\n<rect width='100%%' height='100%%' fill='white'/>\n", PW * nr, H);
    for (i = 0; i < nr; i++) {
        double x0 = PW * i, lo = 0, hi = 0, tend = steps * r[i].s->dt;
        for (b = 0; b < 2; b++)
            for (k = 0; k <= steps; k++) lo = fmin(lo, r[i].e[b][k]), hi = fmax(hi, r[i].e[b][k]);
        if (hi - lo <= 0) hi = lo + 1;
        lo -= 0.04 * (hi - lo), hi += 0.04 * (hi - lo);
#define EX(t) (x0 + L + (t) / tend * (PW - L - R))
#define EY(e) (H - B - ((e) - lo) / (hi - lo) * (H - T - B))
        fprintf(f, "<text x='%g' y='18' font-size='13'>%s %dx%d: total energy (kinetic + spring + gravity)</text>\n",
                x0 + 10, r[i].s->name, r[i].s->nx, r[i].s->ny);
        fprintf(f, "<line x1='%g' y1='%g' x2='%g' y2='%g' stroke='black'/><line x1='%g' y1='%g' x2='%g' y2='%g' "
                   "stroke='black'/>\n", EX(0), H - B, EX(tend), H - B, EX(0), T, EX(0), H - B);
        nt = lin_ticks(lo, hi, ticks, 64);
        for (k = 0; k < nt; k++)
            fprintf(f, "<line x1='%g' y1='%.1f' x2='%g' y2='%.1f' stroke='#ddd'/><text x='%g' y='%.1f' "
                       "text-anchor='end'>%g</text>\n", EX(0), EY(ticks[k]), EX(tend), EY(ticks[k]), EX(0) - 4,
                    EY(ticks[k]) + 4, ticks[k]);
        nt = lin_ticks(0, tend, ticks, 64);
        for (k = 0; k < nt; k++) {
            snprintf(lab, sizeof lab, "%g", ticks[k]);
            fprintf(f, "<text x='%.1f' y='%g' text-anchor='middle'>%s</text>\n", EX(ticks[k]), H - B + 15, lab);
        }
        fprintf(f, "<text x='%g' y='%g' text-anchor='middle'>time, s</text>\n", EX(tend / 2), H - 18);
        fprintf(f, "<text x='%g' y='%g' transform='rotate(-90 %g %g)' text-anchor='middle'>J</text>\n", x0 + 16,
                (T + H - B) / 2, x0 + 16, (T + H - B) / 2);
        for (b = 0; b < 2; b++) {
            fprintf(f, "<polyline fill='none' stroke='%s' stroke-width='1.5' points='", b ? "#1f77b4" : "#d62728");
            for (k = 0; k <= steps; k++) fprintf(f, "%.1f,%.1f ", EX(k * r[i].s->dt), EY(r[i].e[b][k]));
            fprintf(f, "'/>\n");
        }
        fprintf(f, "<text x='%g' y='%g' fill='#d62728'>before: pins dropped after a free solve (stretch %.3gx)</text>\n",
                x0 + 10, 36.0, r[i].stretch[0]);
        fprintf(f, "<text x='%g' y='%g' fill='#1f77b4'>after: pins constrained in the solve (stretch %.3gx)</text>\n",
                x0 + 10, 50.0, r[i].stretch[1]);
#undef EX
#undef EY
    }
    fprintf(f, "</svg>\n");
}

/* hanging and large (or the scenes given) before and after the pin fix:
 * ltd with the direct solve, `steps` steps. */
static int energy(const char *const *paths, int np, int steps, const char *svg_dir)
{
    cloth_scene s[ENERGY_SCENES];
    energy_run r[ENERGY_SCENES];
    char err[1024];
    int i, b, rc = 0;
    run_out o;
    if (steps <= 0) steps = 200;
    memset(r, 0, sizeof r);
    memset(&o, 0, sizeof o);
    printf("| scene | pins | steps | max spring stretch | largest energy above the start | energy at the end |\n"
           "|---|---|---:|---:|---:|---:|\n");
    for (i = 0; i < np && i < ENERGY_SCENES && !rc; i++) {
        if (scene_read(paths[i], &s[i], err, sizeof err)) {
            fprintf(stderr, "cloth_bench: %s\n", err);
            rc = -1;
            break;
        }
        r[i].s = &s[i];
        for (b = 0; b < 2 && !rc; b++) {
            double top = 0;
            int k;
            progress_show(&bar, "cloth bench --energy: %s, %s", s[i].name, b ? "after" : "before");
            if (!(r[i].e[b] = malloc((size_t)(steps + 1) * sizeof(double)))) return -1;
            o.energy = r[i].e[b];
            if (run(&s[i], CLOTH_LTD, "direct", 1e-12, steps, !b, 0, &o, err, sizeof err)) {
                fprintf(stderr, "cloth_bench: %s: %s\n", s[i].name, err);
                rc = -1;
                break;
            }
            r[i].stretch[b] = o.stretch;
            for (k = 0; k <= steps; k++) top = fmax(top, r[i].e[b][k] - r[i].e[b][0]);
            progress_done(&bar);
            printf("| %s %dx%d | %s | %d | %.3gx | %+.4g J | %+.4g J |\n", s[i].name, s[i].nx, s[i].ny,
                   b ? "after: constrained in the solve" : "before: dropped after a free solve", steps, o.stretch, top,
                   r[i].e[b][steps] - r[i].e[b][0]);
        }
    }
    if (!rc && svg_dir) {
        char file[1024];
        FILE *f;
        snprintf(file, sizeof file, "%s/cloth_energy.svg", svg_dir);
        if ((f = fopen(file, "w"))) {
            energy_svg(f, r, i, steps);
            fclose(f);
            printf("\n(plot: %s)\n", file);
        }
    }
    for (i = 0; i < ENERGY_SCENES; i++) free(r[i].e[0]), free(r[i].e[1]);
    return rc;
}

/* ---- --seed-statements: the statements against plain C ---------------------- */

/* CG + Jacobi at the tolerance, with room for its iterations. */
#define SEED_TOL 1e-10
#define SEED_MAXITER 20000
static const char seed_solver[] = "backend = lis-style; lis-style.options = -i cg -p jacobi -tol 1e-10 -maxiter 20000";

/* The silcd session serving this process: silcd forks one per connection,
 * so it is the youngest child of CLOTH_BENCH_SERVER_PID (found once per
 * run, after the connection is made, outside the timed steps); 0 when
 * there is none or the variable is not set. */
static long session_pid;

static void find_session(void)
{
    const char *server = getenv("CLOTH_BENCH_SERVER_PID");
    unsigned long long newest = 0;
    DIR *dir;
    struct dirent *e;
    session_pid = 0;
    if (!server || !*server || !(dir = opendir("/proc"))) return;
    while ((e = readdir(dir))) {
        char path[300], buf[1024], *close_paren;
        long ppid = 0;
        unsigned long long start = 0;
        FILE *f;
        size_t got;
        if (e->d_name[0] < '1' || e->d_name[0] > '9') continue;
        snprintf(path, sizeof path, "/proc/%s/stat", e->d_name);
        if (!(f = fopen(path, "r"))) continue;
        got = fread(buf, 1, sizeof buf - 1, f);
        fclose(f);
        buf[got] = '\0';
        /* pid (comm) state ppid ... field 22 starttime; comm may hold spaces */
        if (!(close_paren = strrchr(buf, ')'))) continue;
        if (sscanf(close_paren + 2, "%*c %ld %*s %*s %*s %*s %*s %*s %*s %*s %*s %*s %*s %*s %*s %*s %*s %*s %*s %llu",
                   &ppid, &start) != 2)
            continue;
        if (ppid == atol(server) && start >= newest) newest = start, session_pid = atol(e->d_name);
    }
    closedir(dir);
}

/* CPU seconds of this process and of the silcd session serving it
 * (/proc/PID/task/T/schedstat, nanoseconds, over its threads): on a
 * shared machine the wall clock measures the load as much as the work,
 * the CPU time only the work.  Read before and after a run's steps, not
 * around each: the ~30 system calls of reading /proc would be SILC's
 * alone (the C step's run has no session to read), and between two steps
 * they would keep the session waiting for the next request. */
static double cpu_seconds(void)
{
    struct timespec t;
    double sum;
    clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &t);
    sum = (double)t.tv_sec + 1e-9 * (double)t.tv_nsec;
    if (session_pid > 0) {
        char path[256];
        DIR *dir;
        struct dirent *e;
        snprintf(path, sizeof path, "/proc/%ld/task", session_pid);
        if ((dir = opendir(path))) {
            while ((e = readdir(dir))) {
                char file[1024];
                unsigned long long ns;
                FILE *f;
                if (e->d_name[0] == '.') continue;
                snprintf(file, sizeof file, "%s/%s/schedstat", path, e->d_name);
                if ((f = fopen(file, "r"))) {
                    if (fscanf(f, "%llu", &ns) == 1) sum += 1e-9 * (double)ns;
                    fclose(f);
                }
            }
            closedir(dir);
        }
    }
    return sum;
}

/* What a timed run of either side gives back: per-step wall and CPU
 * seconds, the phases (wall), the iterations, the final positions. */
typedef struct seed_run {
    double wall, cpu;
    cloth_times t;
    long iterations;
    double *x;
} seed_run;

/* `steps` steps from the scene's start, by the C step (c_step) or the cmp
 * statements; only the steps are timed (not the set-up).  count asks every
 * SILC solve's iterations (outside the timed phases: a checking run). */
static int seed_run_one(const cloth_scene *s, int c_step, int steps, int count, seed_run *o, char *err, size_t errlen)
{
    cloth_model m;
    cloth_c_step c;
    cloth_driver *d = NULL;
    double w0 = 0, c0 = 0;
    int k, rc = 0;
    memset(&o->t, 0, sizeof o->t);
    o->iterations = 0;
    if (cloth_model_init(&m, s, err, errlen)) return -1;
    if (c_step) {
        rc = cloth_c_step_open(&c, &m, SEED_TOL, err, errlen);
        c.maxiter = SEED_MAXITER;
    } else {
        rc = !(d = cloth_driver_open(&m, CLOTH_CMP, seed_solver, SEED_TOL, err, errlen));
        if (!rc) find_session();
    }
    /* A counting run's times (its steps interleaved with `info dv`) are
     * not reported. */
    if (!rc) w0 = bench_now(), c0 = cpu_seconds();
    for (k = 0; k < steps && !rc; k++) {
        rc = c_step ? cloth_c_step_run(&c, &o->t, err, errlen) : cloth_driver_step(d, &o->t, err, errlen);
        if (!rc && count && !c_step) {
            double berr, cond;
            long it = 0;
            rc = cloth_driver_solve_report(d, &berr, &cond, &it, err, errlen);
            o->iterations += it;
        }
    }
    o->cpu = (cpu_seconds() - c0) / steps, o->wall = (bench_now() - w0) / steps;
    if (c_step && !rc) o->iterations = c.iterations;
    if (!c_step && !rc) rc = cloth_driver_sync(d, err, errlen);
    if (!rc && o->x) memcpy(o->x, m.x, (size_t)3 * m.n * sizeof *o->x);
    if (c_step) {
        if (c.m) cloth_c_step_close(&c);
    } else {
        cloth_driver_close(d);
        session_pid = 0;
    }
    cloth_model_free(&m);
    return rc ? -1 : 0;
}

static double min_of(const double *v, int n)
{
    double b = INFINITY;
    int i;
    for (i = 0; i < n; i++) b = fmin(b, v[i]);
    return b;
}

static int seed_statements(const char *const *paths, int np, int steps, int rounds, const char *label)
{
    int i, r, rc = 0;
    printf("| scene | where | clock | C step ms/step best | median | statements best | median | ratio best | "
           "ratio median | statements: assembly | solve | update | iterations/step C, SILC | max |x_C - x_SILC| |\n"
           "|---|---|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|\n");
    for (i = 0; i < np && !rc; i++) {
        cloth_scene s;
        char err[1024];
        double *xc = NULL, *xs = NULL, *t[4] = {NULL, NULL, NULL, NULL}, split[3] = {0, 0, 0}, diff, best = INFINITY;
        long itc = 0, its = 0;
        seed_run o;
        int n3, k;
        if (scene_read(paths[i], &s, err, sizeof err)) {
            fprintf(stderr, "cloth_bench: %s\n", err);
            return -1;
        }
        n3 = 3 * s.nx * s.ny;
        xc = malloc((size_t)n3 * sizeof *xc), xs = malloc((size_t)n3 * sizeof *xs);
        for (k = 0; k < 4; k++) t[k] = malloc((size_t)rounds * sizeof(double)); /* C wall, C cpu, SILC wall, cpu */
        if (!xc || !xs || !t[0] || !t[1] || !t[2] || !t[3]) rc = -1;
        /* Round 0: the same work?  Positions and iterations, untimed. */
        progress_show(&bar, "cloth bench --seed-statements: %s, checking", s.name);
        o.x = xc;
        rc = rc || seed_run_one(&s, 1, steps, 0, &o, err, sizeof err);
        itc = o.iterations;
        o.x = xs;
        rc = rc || seed_run_one(&s, 0, steps, 1, &o, err, sizeof err);
        its = o.iterations;
        diff = rc ? NAN : max_diff(xc, xs, n3);
        o.x = NULL;
        for (r = 0; r < rounds && !rc; r++) {
            progress_show(&bar, "cloth bench --seed-statements: %s, round %d of %d", s.name, r + 1, rounds);
            rc = seed_run_one(&s, 1, steps, 0, &o, err, sizeof err);
            t[0][r] = o.wall, t[1][r] = o.cpu;
            rc = rc || seed_run_one(&s, 0, steps, 0, &o, err, sizeof err);
            t[2][r] = o.wall, t[3][r] = o.cpu;
            if (!rc && o.cpu < best) {
                best = o.cpu;
                split[0] = o.t.assembly / steps, split[1] = o.t.solve / steps, split[2] = o.t.update / steps;
            }
        }
        progress_done(&bar);
        if (rc) {
            fprintf(stderr, "cloth_bench: %s: %s\n", s.name, err);
        } else {
            for (k = 0; k < 2; k++) {
                double bc = min_of(t[k], rounds), bs = min_of(t[k + 2], rounds);
                double mc = bench_median(t[k], rounds), ms = bench_median(t[k + 2], rounds);
                printf("| %s %dx%d | %s | %s | %.3f | %.3f | %.3f | %.3f | %.2f | %.2f |", s.name, s.nx, s.ny, label,
                       k ? "CPU" : "wall", 1e3 * bc, 1e3 * mc, 1e3 * bs, 1e3 * ms, bs / bc, ms / mc);
                if (k) printf(" %.3f | %.3f | %.3f | %.1f, %.1f | %.2g |\n", 1e3 * split[0], 1e3 * split[1],
                              1e3 * split[2], (double)itc / steps, (double)its / steps, diff);
                else printf(" | | | | |\n");
            }
            /* The baseline must do the statements' work: the same positions
             * to the solver's tolerance, the same iterations. */
            if (!(diff <= 1e-6 * fmax(s.width, s.height)) || labs(itc - its) > steps) {
                fprintf(stderr, "cloth_bench: %s: the C step and the statements disagree (positions %.2g m apart, "
                                "%ld against %ld iterations)\n", s.name, diff, itc, its);
                rc = -1;
            }
        }
        free(xc), free(xs);
        for (k = 0; k < 4; k++) free(t[k]);
    }
    printf("(%d steps per run, %d timed rounds, C and SILC alternating; CG + Jacobi at %g from the last step's dv, "
           "lis-style's stopping test in both; CPU: this process%s; phases: wall, SILC's run of least CPU)\n",
           steps, rounds, SEED_TOL, getenv("CLOTH_BENCH_SERVER_PID") ? " + its silcd session's" : "");
    return rc;
}

static const char usage_text[] = "usage: cloth_bench SCENE... [--steps N] [--rounds R] [--label TEXT]\n"
                                 "       cloth_bench SCENE... --trade [--steps N] [--svg DIR]\n"
                                 "       cloth_bench SCENE... --energy [--steps N] [--svg DIR]\n"
                                 "       cloth_bench SCENE... --seed-statements [--steps N] [--rounds R] [--label TEXT]\n";

int main(int argc, char **argv)
{
    int steps = 0, rounds = 0, a, sc, nscenes = 0, trading = 0, energies = 0, seeds = 0;
    const char *label = "embedded", *scenes[16], *svg_dir = NULL;
    for (a = 1; a < argc; a++) {
        if (!strcmp(argv[a], "--steps") && a + 1 < argc) steps = atoi(argv[++a]);
        else if (!strcmp(argv[a], "--rounds") && a + 1 < argc) rounds = atoi(argv[++a]);
        else if (!strcmp(argv[a], "--label") && a + 1 < argc) label = argv[++a];
        else if (!strcmp(argv[a], "--trade")) trading = 1;
        else if (!strcmp(argv[a], "--energy")) energies = 1;
        else if (!strcmp(argv[a], "--seed-statements")) seeds = 1;
        else if (!strcmp(argv[a], "--svg") && a + 1 < argc) svg_dir = argv[++a];
        else if (argv[a][0] != '-' && nscenes < 16) scenes[nscenes++] = argv[a];
        else {
            fputs(usage_text, stderr);
            return 2;
        }
    }
    if (!nscenes || steps < 0 || rounds < 0) {
        fputs(usage_text, stderr);
        return 2;
    }
    if (energies) return energy(scenes, nscenes, steps, svg_dir) ? 1 : 0;
    if (seeds) return seed_statements(scenes, nscenes, steps ? steps : 50, rounds ? rounds : 5, label) ? 1 : 0;
    if (!rounds) rounds = 3;
    if (trading) {
        for (sc = 0; sc < nscenes; sc++)
            if (trade(scenes[sc], steps, svg_dir)) return 1;
        return 0;
    }
    if (!steps) steps = 50;
    printf("| scene | where | driver, solver | ms/step | assembly | solve | update | ratio to original | "
           "iterations/step | max |x - x_original| |\n|---|---|---|---:|---:|---:|---:|---:|---:|---:|\n");
    for (sc = 0; sc < nscenes; sc++) {
        cloth_scene s;
        char err[1024];
        double best[NV], split[NV][3], diff[NV], its[NV], *x0, *x;
        int r, v, n3;
        run_out o;
        if (scene_read(scenes[sc], &s, err, sizeof err)) {
            fprintf(stderr, "cloth_bench: %s\n", err);
            return 1;
        }
        n3 = 3 * s.nx * s.ny;
        x0 = calloc((size_t)n3, sizeof *x0);
        x = calloc((size_t)n3, sizeof *x);
        if (!x0 || !x) return 1;
        memset(&o, 0, sizeof o);
        for (v = 0; v < NV; v++) best[v] = INFINITY, diff[v] = NAN, its[v] = NAN;
        /* Round 0 also counts every solve's iterations (outside the timed
         * phases), so "the same CG" is shown, not assumed. */
        for (r = 0; r <= rounds; r++)
            for (v = 0; v < NV; v++) {
                double per;
                progress_show(&bar, "cloth bench: %s, round %d of %d, %s", s.name, r, rounds,
                              cloth_mode_name(variants[v].mode));
                o.x = v == 0 ? x0 : x;
                if (run(&s, variants[v].mode, variants[v].solver, 0, steps, 0, r == 0, &o, err, sizeof err)) {
                    fprintf(stderr, "cloth_bench: %s %s: %s\n", s.name, cloth_mode_name(variants[v].mode), err);
                    continue;
                }
                if (r == 0) {
                    its[v] = (double)o.iterations / steps;
                    if (v > 0) diff[v] = max_diff(x, x0, n3);
                    continue;
                }
                per = (o.t.assembly + o.t.solve + o.t.update) / steps;
                if (per < best[v]) {
                    best[v] = per;
                    split[v][0] = o.t.assembly / steps, split[v][1] = o.t.solve / steps, split[v][2] = o.t.update / steps;
                }
            }
        progress_done(&bar);
        for (v = 0; v < NV; v++) {
            char what[128], d[32] = "-";
            if (!isfinite(best[v])) {
                printf("| %s | %s | %s | failed | | | | | | |\n", s.name, label, cloth_mode_name(variants[v].mode));
                continue;
            }
            snprintf(what, sizeof what, "%s, %s", cloth_mode_name(variants[v].mode),
                     variants[v].mode == CLOTH_ORIGINAL ? "own CG + Jacobi" : cloth_solver_label(variants[v].solver));
            if (v) snprintf(d, sizeof d, "%.2g", diff[v]);
            printf("| %s %dx%d | %s | %s | %.3f | %.3f | %.3f | %.3f | %.2f | %.1f | %s |\n", s.name, s.nx, s.ny,
                   variants[v].mode == CLOTH_ORIGINAL ? "-" : label, what, 1e3 * best[v], 1e3 * split[v][0],
                   1e3 * split[v][1], 1e3 * split[v][2], best[v] / best[0], its[v], d);
        }
        free(x0);
        free(x);
    }
    printf("(%d steps per run, best of %d timed rounds after one that counts iterations; CG tolerance = the "
           "scene's default, accuracy / condition bound, relative to ||b||)\n", steps, rounds);
    return 0;
}
