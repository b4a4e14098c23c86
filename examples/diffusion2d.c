/*
 * diffusion2d.c -- the main job: Crank-Nicolson for the heat equation on the
 * unit square, through SILC's PUT/EXEC/GET.
 *
 *     diffusion2d [-n N] [-s steps] [-dt dt] [-o out.pgm]
 *         defaults: N = 100 interior points per side (N^2 unknowns), 50 steps,
 *         dt = 2e-4, output diffusion2d.pgm
 *
 * The initial field is 1 on the block (0.4, 0.6)^2 and 0 elsewhere, the boundary
 * is held at 0.  The 5-point Laplacian L is assembled in C as CSR, and the loop
 * is the seeds' one (diff_run in diffusion_common.c):
 *
 *     SILC_PUT("A", &A); SILC_PUT("B", &B); SILC_PUT("u", &u);
 *     for each step: SILC_EXEC("u = A \\ (B * u)");
 *     SILC_GET(&u, "u");
 *
 * with A = I - dt/2 L and B = I + dt/2 L.  The final field is written as a
 * binary 8-bit PGM scaled by its maximum (y up), and a summary line is printed.
 * The heat total (the integral of u) decays because heat leaves through the
 * cold boundary.
 */
#define _POSIX_C_SOURCE 200809L
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "diffusion_common.h"
#include "silc.h"

static const char usage[] =
    "usage: diffusion2d [-n N] [-s steps] [-dt dt] [-o out.pgm]\n"
    "  -n N       interior points per side (default 100, N^2 unknowns)\n"
    "  -s steps   Crank-Nicolson steps (default 50)\n"
    "  -dt dt     time step (default 2e-4)\n"
    "  -o FILE    output image, binary PGM (default diffusion2d.pgm)\n";

static int parse_num(const char *opt, const char *s, double lo, double hi, int integer, double *out)
{
    char *end;
    double v = s ? strtod(s, &end) : 0;
    if (!s || end == s || *end || !(v >= lo && v <= hi) || (integer && v != floor(v))) {
        fprintf(stderr, "diffusion2d: %s needs %s in [%g, %g], got '%s'\n", opt,
                integer ? "an integer" : "a number", lo, hi, s ? s : "");
        return 1;
    }
    *out = v;
    return 0;
}

int main(int argc, char **argv)
{
    double nd = 100, stepsd = 50, dt = 2e-4;
    const char *out = "diffusion2d.pgm";
    for (int a = 1; a < argc; a++) {
        const char *opt = argv[a], *arg = a + 1 < argc ? argv[a + 1] : NULL;
        int bad;
        if (!strcmp(opt, "-h") || !strcmp(opt, "--help")) {
            fputs(usage, stdout);
            return 0;
        } else if (!strcmp(opt, "-n")) {
            bad = parse_num(opt, arg, 1, 20000, 1, &nd);
        } else if (!strcmp(opt, "-s")) {
            bad = parse_num(opt, arg, 0, 1e9, 1, &stepsd);
        } else if (!strcmp(opt, "-dt")) {
            bad = parse_num(opt, arg, 0, 1e6, 0, &dt);
        } else if (!strcmp(opt, "-o") && arg) {
            out = arg, bad = 0;
        } else {
            fprintf(stderr, "diffusion2d: unknown or incomplete option '%s'\n%s", opt, usage);
            return 2;
        }
        if (bad) return 2;
        a++;
    }
    int64_t n = (int64_t)nd;
    int steps = (int)stepsd;
    double *u = malloc((size_t)(n * n) * sizeof *u);
    if (!u) {
        fprintf(stderr, "diffusion2d: out of memory for N = %lld\n", (long long)n);
        return 1;
    }
    if (SILC_INIT()) {
        fprintf(stderr, "diffusion2d: SILC_INIT failed: %s\n", silc_errmsg());
        free(u);
        return 1;
    }
    diff2d_initial(n, u);
    double heat0 = diff2d_heat(n, u);
    struct timespec t0, t1;
    clock_gettime(CLOCK_MONOTONIC, &t0);
    int rc = diff_run(2, n, steps, dt, u);
    clock_gettime(CLOCK_MONOTONIC, &t1);
    if (rc) {
        fprintf(stderr, "diffusion2d: %s\n", silc_errmsg());
    } else {
        double secs = (double)(t1.tv_sec - t0.tv_sec) + 1e-9 * (double)(t1.tv_nsec - t0.tv_nsec);
        double umax = -INFINITY, sum = 0;
        for (int64_t k = 0; k < n * n; k++) {
            sum += u[k];
            if (u[k] > umax) umax = u[k];
        }
        printf("steps=%d N=%lld unknowns=%lld time=%.2fs max=%.6g sum=%.6g\n", steps,
               (long long)n, (long long)(n * n), secs, umax, sum);
        printf("heat=%.10g (initially %.10g, t=%g)\n", diff2d_heat(n, u), heat0, steps * dt);
        rc = diff2d_write_pgm("diffusion2d", out, n, u, umax);
        if (!rc) printf("wrote %s (%lldx%lld PGM)\n", out, (long long)n, (long long)n);
    }
    free(u);
    SILC_FINALIZE();
    return rc ? 1 : 0;
}
