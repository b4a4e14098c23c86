/*
 * test_examples.c -- the diffusion examples checked against independent truth,
 * through the same code the examples run (examples/diffusion_common.c).
 *
 * 1-D: Crank-Nicolson for u_t = u_xx on [0, pi], u(x, 0) = sin x, against the
 * exact solution e^{-t} sin x.  2-D: the block of heat on the unit square,
 * against properties every correct answer has (symmetry, decay, maximum
 * principle), since it has no closed form.
 */
#include <math.h>
#include <stdlib.h>

#include "check.h"
#include "diffusion_common.h"
#include "silc.h"

static void test_1d(void)
{
    /* N = 200 (h = pi/201 = 0.01563), dt = 1e-3, T = 0.5.
     * Space: sin x is an exact eigenvector of the discrete Laplacian, with
     * eigenvalue -(4/h^2) sin^2(h/2) = -1 + h^2/12 + O(h^4), so the
     * semi-discrete solution is e^{-t(1 - h^2/12)} sin x and its error is
     * e^{-T} (e^{T h^2/12} - 1) = 0.6065 * 0.5 * 2.443e-4 / 12 = 6.17e-6.
     * Time: CN's amplification (1 - dt/2)/(1 + dt/2) = e^{-dt - dt^3/12 + ...}
     * adds T dt^2 / 12 * e^{-T} = 2.5e-8.  So the max error is 6.2e-6 (SciPy
     * gives 6.148e-6 for the same scheme); the bound 2e-5 leaves a factor 3 for
     * rounding and solver tolerance while still catching an O(h) or O(dt)
     * mistake (first-order time stepping would give ~1.5e-4).  The lower bound
     * 1e-9 fails if something returns the exact solution instead of the
     * scheme's. */
    const int64_t n = 200;
    const int steps = 500;
    const double T = 0.5, dt = T / steps;
    double *u = malloc((size_t)n * sizeof *u);
    CHECK(u != NULL, "out of memory");
    if (!u) return;
    diff1d_initial(n, u);
    int rc = diff_run(1, n, steps, dt, u);
    CHECK(rc == 0, "1-D run failed: %s", silc_errmsg());
    if (rc == 0) {
        double err = diff1d_max_error(n, T, u);
        CHECK(err < 2e-5, "1-D max error %.3e not below 2e-5", err);
        CHECK(err > 1e-9, "1-D max error %.3e suspiciously small (exact solution returned?)", err);
    }
    free(u);
}

static void test_2d(void)
{
    const int64_t n = 30;
    const int steps = 50;
    const double dt = 2e-4;
    double *u = malloc((size_t)(n * n) * sizeof *u);
    CHECK(u != NULL, "out of memory");
    if (!u) return;
    diff2d_initial(n, u);
    double heat0 = diff2d_heat(n, u);
    int rc = diff_run(2, n, steps, dt, u);
    CHECK(rc == 0, "2-D run failed: %s", silc_errmsg());
    if (rc == 0) {
        /* Heat only leaves, through the cold boundary: positive and decaying
         * (SciPy: 0.037461 -> 0.037296 for this run). */
        double heat = diff2d_heat(n, u);
        CHECK(heat > 0, "2-D heat %.6g not positive", heat);
        CHECK(heat < heat0, "2-D heat %.10g did not decay from %.10g", heat, heat0);
        /* The problem is symmetric under x <-> y; the scheme keeps that up to
         * rounding. */
        double asym = 0, umax = -INFINITY;
        for (int64_t j = 0; j < n; j++)
            for (int64_t i = 0; i < n; i++) {
                double d = fabs(u[i + j * n] - u[j + i * n]);
                if (d > asym || d != d) asym = d;
                if (u[i + j * n] > umax || u[i + j * n] != u[i + j * n]) umax = u[i + j * n];
            }
        CHECK(asym <= 1e-12, "2-D field not symmetric in x <-> y: max difference %.3e", asym);
        /* The initial maximum 1 is smoothed away (SciPy: 0.257). */
        CHECK(umax < 1, "2-D max %.6g not below the initial maximum 1", umax);
    }
    free(u);
}

int main(void)
{
    if (SILC_INIT()) {
        CHECK(0, "SILC_INIT failed: %s", silc_errmsg());
        return check_done();
    }
    test_1d();
    test_2d();
    SILC_FINALIZE();
    return check_done();
}
