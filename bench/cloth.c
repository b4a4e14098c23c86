/*
 * cloth.c -- the cloth example's three drivers timed against each other
 * (examples/cloth, issue 16's bench; bench/cloth.sh runs it embedded and
 * through silcd).
 *
 *     cloth_bench SCENE... [--steps N] [--rounds R] [--label TEXT]
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
 */
#define _POSIX_C_SOURCE 200809L
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "cloth.h"

typedef struct variant {
    cloth_mode mode;
    const char *solver; /* NULL: configured dispatch; "cg": CG + Jacobi at the tolerance */
} variant;

static const variant variants[] = {
    {CLOTH_ORIGINAL, NULL}, {CLOTH_LTD, "cg"}, {CLOTH_CMP, "cg"}, {CLOTH_LTD, NULL}, {CLOTH_CMP, NULL},
};
enum { NV = sizeof variants / sizeof variants[0] };

/* One run: per-step times and the final positions (3n, in x). */
static int run(const cloth_scene *s, const variant *v, int steps, double tol, cloth_times *t, double *x)
{
    cloth_model m;
    cloth_driver *d;
    char err[1024], opts[256];
    int k;
    memset(t, 0, sizeof *t);
    if (cloth_model_init(&m, s, err, sizeof err)) {
        fprintf(stderr, "cloth_bench: %s\n", err);
        return -1;
    }
    snprintf(opts, sizeof opts, "backend = lis-style; lis-style.options = -i cg -p jacobi -tol %.3g", tol);
    if (!(d = cloth_driver_open(&m, v->mode, v->solver ? opts : NULL, tol, err, sizeof err))) {
        fprintf(stderr, "cloth_bench: %s\n", err);
        cloth_model_free(&m);
        return -1;
    }
    for (k = 0; k < steps; k++)
        if (cloth_driver_step(d, t, err, sizeof err)) {
            fprintf(stderr, "cloth_bench: %s %s step %d: %s\n", s->name, cloth_mode_name(v->mode), k, err);
            break;
        }
    if (k == steps && cloth_driver_sync(d, err, sizeof err) == 0) memcpy(x, m.x, (size_t)3 * m.n * sizeof *x);
    else k = -1;
    cloth_driver_close(d);
    cloth_model_free(&m);
    return k == steps ? 0 : -1;
}

int main(int argc, char **argv)
{
    int steps = 50, rounds = 3, a, sc, nscenes = 0;
    const char *label = "embedded", *scenes[16];
    for (a = 1; a < argc; a++) {
        if (!strcmp(argv[a], "--steps") && a + 1 < argc) steps = atoi(argv[++a]);
        else if (!strcmp(argv[a], "--rounds") && a + 1 < argc) rounds = atoi(argv[++a]);
        else if (!strcmp(argv[a], "--label") && a + 1 < argc) label = argv[++a];
        else if (argv[a][0] != '-' && nscenes < 16) scenes[nscenes++] = argv[a];
        else {
            fprintf(stderr, "usage: cloth_bench SCENE... [--steps N] [--rounds R] [--label TEXT]\n");
            return 2;
        }
    }
    if (!nscenes || steps < 1 || rounds < 1) {
        fprintf(stderr, "usage: cloth_bench SCENE... [--steps N] [--rounds R] [--label TEXT]\n");
        return 2;
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
                if (run(&s, &variants[v], steps, tol, &t, v == 0 ? x0 : x)) continue;
                per = (t.assembly + t.solve + t.update) / steps;
                if (v > 0) diff[v] = 0;
                for (a = 0; v > 0 && a < n3; a++) diff[v] = fmax(diff[v], fabs(x[a] - x0[a]));
                if (per < best[v]) {
                    best[v] = per;
                    split[v][0] = t.assembly / steps, split[v][1] = t.solve / steps, split[v][2] = t.update / steps;
                }
            }
        for (v = 0; v < NV; v++) {
            char what[128];
            if (!isfinite(best[v])) {
                printf("| %s | %s | %s | failed | | | | | |\n", s.name, label, cloth_mode_name(variants[v].mode));
                continue;
            }
            snprintf(what, sizeof what, "%s, %s", cloth_mode_name(variants[v].mode),
                     variants[v].mode == CLOTH_ORIGINAL ? "own CG + Jacobi"
                     : variants[v].solver             ? "lis-style CG + Jacobi"
                                                      : "default (CHOLMOD)");
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
