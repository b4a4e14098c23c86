/*
 * diffusion1d.c -- Crank-Nicolson for u_t = u_xx on [0, pi] with u(x, 0) = sin x
 * and u = 0 at both ends, whose exact solution is e^{-t} sin x.
 *
 *     diffusion1d [N [steps [T]]]      defaults: N = 100 interior points,
 *                                      steps = 500, T = 0.5
 *
 * The tridiagonal matrices A = I - dt/2 L and B = I + dt/2 L are assembled in C
 * as CSR and deposited once; each step runs "b = B * u; u = A \ b" inside SILC
 * (see diff_run in diffusion_common.c).  Prints the maximum error against the
 * exact solution, which is dominated by the spatial error
 * e^{-T} (e^{T h^2/12} - 1) ~ T h^2 e^{-T} / 12: sin x is an eigenvector of the
 * discrete Laplacian with eigenvalue -(4/h^2) sin^2(h/2) = -1 + h^2/12 + O(h^4).
 */
#define _POSIX_C_SOURCE 200809L
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <time.h>

#include "diffusion_common.h"
#include "silc.h"

static int parse_arg(const char *s, double lo, double *out)
{
    char *end;
    double v = strtod(s, &end);
    if (end == s || *end || !(v >= lo) || !isfinite(v)) return 1;
    *out = v;
    return 0;
}

int main(int argc, char **argv)
{
    double nd = 100, stepsd = 500, T = 0.5;
    if (argc > 4 || (argc > 1 && parse_arg(argv[1], 1, &nd)) ||
        (argc > 2 && parse_arg(argv[2], 1, &stepsd)) || (argc > 3 && parse_arg(argv[3], 0, &T)) ||
        nd != floor(nd) || stepsd != floor(stepsd) || nd > 1e8 || stepsd > 1e9) {
        fprintf(stderr, "usage: diffusion1d [N [steps [T]]]   (N, steps positive integers, T >= 0)\n");
        return 2;
    }
    int64_t n = (int64_t)nd;
    int steps = (int)stepsd;
    double dt = T / steps;
    double *u = malloc((size_t)n * sizeof *u);
    if (!u) {
        fprintf(stderr, "diffusion1d: out of memory for N = %lld\n", (long long)n);
        return 1;
    }
    if (SILC_INIT()) {
        fprintf(stderr, "diffusion1d: SILC_INIT failed: %s\n", silc_errmsg());
        free(u);
        return 1;
    }
    diff1d_initial(n, u);
    struct timespec t0, t1;
    clock_gettime(CLOCK_MONOTONIC, &t0);
    int rc = diff_run(1, n, steps, dt, u);
    clock_gettime(CLOCK_MONOTONIC, &t1);
    if (rc) {
        fprintf(stderr, "diffusion1d: %s\n", silc_errmsg());
    } else {
        double secs = (double)(t1.tv_sec - t0.tv_sec) + 1e-9 * (double)(t1.tv_nsec - t0.tv_nsec);
        double h = diff1d_h(n);
        printf("N=%lld steps=%d T=%g dt=%g time=%.3fs\n", (long long)n, steps, T, dt, secs);
        printf("max error=%.3e (spatial error estimate T h^2 e^-T / 12 = %.3e)\n",
               diff1d_max_error(n, T, u), T * h * h * exp(-T) / 12);
    }
    free(u);
    SILC_FINALIZE();
    return rc ? 1 : 0;
}
