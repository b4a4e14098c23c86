/*
 * test_cloth_example.c -- the cloth program's model and its three drivers
 * (examples/cloth) against each other and against physics.
 *
 *   - original (plain C, CG to 1e-13), ltd and cmp (SILC, a direct solve)
 *     agree on every position after 50 steps of a pinned cloth, to a few
 *     times what the CG tolerance allows (1e-9 of the cloth's size);
 *   - pinned particles do not move at all; free ones do (the cloth falls);
 *   - with damping and no forcing (gravity switched off after the cloth
 *     has swung) the energy, kinetic + spring, decays step by step;
 *   - the obstacle: cmp's statements and the C constraint agree on a cloth
 *     dropped onto a sphere and onto a floor, and no particle ends inside;
 *   - the assembled A is symmetric and its product with a vector matches
 *     the springs' Laplacian applied directly.
 * Under SILC_SERVER (tests/remote.cmake) ltd and cmp run against silcd.
 */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "check.h"
#include "cloth.h"

static const char base_scene[] =
    "nx = 8\nny = 7\nwidth = 1\nheight = 0.9\nmass = 0.5\nk_struct = 500\n"
    "damping = 0.5\ndt = 0.01\nsteps = 50\npin = corners_top\naccuracy = 1e-6\n";
/* The springs of most cases (a case that wants others gives its own). */
#define SPRINGS "k_shear = 50\nk_bend = 5\n"

static int scene_of(cloth_scene *s, const char *extra)
{
    char text[2048], err[512];
    snprintf(text, sizeof text, "%s%s", base_scene, extra);
    if (scene_parse(text, "test", s, err, sizeof err)) {
        CHECK(0, "scene: %s", err);
        return -1;
    }
    return 0;
}

/* Runs `steps` steps of `mode` with `solver` at tol from the scene's start;
 * positions into x (3n). */
static int run_with(const cloth_scene *s, cloth_mode mode, const char *solver, double tol, int steps, double *x)
{
    cloth_model m;
    cloth_driver *d;
    cloth_times t = {0, 0, 0, 0};
    char err[1024];
    int k, rc = 0;
    if (cloth_model_init(&m, s, err, sizeof err)) {
        CHECK(0, "model: %s", err);
        return -1;
    }
    d = cloth_driver_open(&m, mode, solver, tol, err, sizeof err);
    CHECK(d != NULL, "%s: %s", cloth_mode_name(mode), err);
    for (k = 0; d && k < steps && !rc; k++) {
        rc = cloth_driver_step(d, &t, err, sizeof err);
        CHECK(rc == 0, "%s step %d: %s", cloth_mode_name(mode), k, err);
    }
    if (d && !rc) {
        rc = cloth_driver_sync(d, err, sizeof err);
        CHECK(rc == 0, "%s sync: %s", cloth_mode_name(mode), err);
    }
    if (!rc && d) memcpy(x, m.x, (size_t)3 * m.n * sizeof *x);
    cloth_driver_close(d);
    cloth_model_free(&m);
    return d && !rc ? 0 : -1;
}

/* The direct solve (and original's CG to 1e-13). */
static int run(const cloth_scene *s, cloth_mode mode, int steps, double *x)
{
    return run_with(s, mode, NULL, 1e-13, steps, x);
}

static double max_diff(const double *a, const double *b, int n)
{
    double d = 0;
    int i;
    for (i = 0; i < n; i++) d = fmax(d, fabs(a[i] - b[i]));
    return d;
}

static void check_three_ways(const char *extra, const char *what)
{
    cloth_scene s;
    double *x[3];
    int mode, n3;
    if (scene_of(&s, extra)) return;
    n3 = 3 * s.nx * s.ny;
    for (mode = 0; mode < 3; mode++) x[mode] = calloc((size_t)n3, sizeof(double));
    for (mode = 0; mode < 3; mode++)
        if (run(&s, (cloth_mode)mode, s.steps, x[mode])) goto out;
    CHECK(max_diff(x[0], x[1], n3) <= 1e-9, "%s: ltd differs from original by %.3g", what,
          max_diff(x[0], x[1], n3));
    CHECK(max_diff(x[0], x[2], n3) <= 1e-9, "%s: cmp differs from original by %.3g", what,
          max_diff(x[0], x[2], n3));
    CHECK(max_diff(x[1], x[2], n3) <= 1e-12, "%s: cmp differs from ltd by %.3g", what, max_diff(x[1], x[2], n3));
    printf("  %s: 3 drivers, %d steps: |ltd - original| %.2g, |cmp - original| %.2g, |cmp - ltd| %.2g\n", what,
           s.steps, max_diff(x[0], x[1], n3), max_diff(x[0], x[2], n3), max_diff(x[1], x[2], n3));
out:
    for (mode = 0; mode < 3; mode++) free(x[mode]);
}

/* A named solver runs at the tolerance it is given: tight, it agrees with
 * the direct solve; loose, it is off by more (so the tolerance reached the
 * solver).  An unknown name is refused with the names a user may give. */
static void check_named_solvers(void)
{
    static const char *const names[] = {"cg", "cg-ic", "cg-amg"};
    cloth_scene s;
    cloth_model m;
    char opts[256], err[512];
    double *xd, *xt, *xl;
    int n3, k, mode;
    CHECK(cloth_solver_options("cg", 1e-7, opts, sizeof opts, err, sizeof err) == 0 &&
              strstr(opts, "-i cg -p jacobi -tol 1e-07"),
          "cg at 1e-7 gives '%s'", opts);
    CHECK(cloth_solver_options("direct", 1e-7, opts, sizeof opts, err, sizeof err) == 0 && !opts[0],
          "direct gives options '%s'", opts);
    CHECK(cloth_solver_options("backend = reference", 1e-7, opts, sizeof opts, err, sizeof err) == 0 &&
              !strcmp(opts, "backend = reference"),
          "options pass as they are: '%s'", opts);
    CHECK(cloth_solver_options("cgg", 1e-7, opts, sizeof opts, err, sizeof err) == -1 &&
              strstr(err, "unknown solver 'cgg' (one of direct, cg, cg-ic, cg-amg, petsc-cg"),
          "unknown solver: '%s'", err);
    if (scene_of(&s, SPRINGS)) return;
    if (cloth_model_init(&m, &s, err, sizeof err) == 0) {
        CHECK(cloth_driver_open(&m, CLOTH_LTD, "cgg", 1e-7, err, sizeof err) == NULL &&
                  strstr(err, "unknown solver 'cgg'"),
              "driver with an unknown solver: '%s'", err);
        cloth_model_free(&m);
    }
    n3 = 3 * s.nx * s.ny;
    xd = calloc((size_t)n3, sizeof *xd), xt = calloc((size_t)n3, sizeof *xt), xl = calloc((size_t)n3, sizeof *xl);
    if (xd && xt && xl && run(&s, CLOTH_LTD, s.steps, xd) == 0)
        for (k = 0; k < 3; k++)
            for (mode = CLOTH_LTD; mode <= CLOTH_CMP; mode++) {
                double tight, loose;
                if (run_with(&s, (cloth_mode)mode, names[k], 1e-11, s.steps, xt) ||
                    run_with(&s, (cloth_mode)mode, names[k], 1e-2, s.steps, xl))
                    continue;
                tight = max_diff(xd, xt, n3), loose = max_diff(xd, xl, n3);
                CHECK(tight <= 1e-8, "%s %s at 1e-11: %.3g from the direct solve", cloth_mode_name(mode), names[k],
                      tight);
                CHECK(loose > 10 * tight, "%s %s at 1e-2 (%.3g) is no further from the direct solve than at "
                      "1e-11 (%.3g): the tolerance did not reach the solver", cloth_mode_name(mode), names[k],
                      loose, tight);
            }
    free(xd), free(xt), free(xl);
}

/* Pins hold exactly; the rest falls. */
static void check_pins(void)
{
    cloth_scene s;
    cloth_model m;
    double *x, fall = 0;
    char err[512];
    int k, p;
    if (scene_of(&s, SPRINGS) || cloth_model_init(&m, &s, err, sizeof err)) return;
    x = calloc((size_t)3 * m.n, sizeof *x);
    if (x && run(&s, CLOTH_CMP, 30, x) == 0) {
        for (k = 0; k < s.npins; k++) {
            p = s.pin_j[k] * s.nx + s.pin_i[k];
            CHECK(x[3 * p] == m.x0[3 * p] && x[3 * p + 1] == m.x0[3 * p + 1] && x[3 * p + 2] == m.x0[3 * p + 2],
                  "pinned particle %d moved", p);
        }
        for (p = 0; p < m.n; p++) fall = fmin(fall, x[3 * p + 2]);
        CHECK(fall < -0.05, "the cloth did not fall (lowest z %.3g)", fall);
    }
    free(x);
    cloth_model_free(&m);
}

/* Damping, no forcing: energy decays. */
static void check_energy(void)
{
    cloth_scene s;
    cloth_model m;
    cloth_driver *d;
    cloth_times t = {0, 0, 0, 0};
    char err[512];
    double ek, es, prev, first;
    int k, rises = 0;
    if (scene_of(&s, SPRINGS) || cloth_model_init(&m, &s, err, sizeof err)) return;
    d = cloth_driver_open(&m, CLOTH_ORIGINAL, NULL, 1e-13, err, sizeof err);
    for (k = 0; d && k < 40; k++) cloth_driver_step(d, &t, err, sizeof err);
    for (k = 0; k < 3 * m.n; k++) m.gvec[k] = 0; /* no forcing from here on */
    cloth_energy(&m, m.x, m.v, &ek, &es);
    first = prev = ek + es;
    for (k = 0; d && k < 200; k++) {
        cloth_driver_step(d, &t, err, sizeof err);
        cloth_energy(&m, m.x, m.v, &ek, &es);
        if (ek + es > prev * (1 + 1e-12)) rises++;
        prev = ek + es;
    }
    CHECK(d != NULL && first > 0, "energy test set-up: %s", err);
    CHECK(rises == 0, "the energy rose in %d of 200 damped steps", rises);
    CHECK(prev < 0.5 * first, "the energy fell only from %.4g to %.4g in 200 damped steps", first, prev);
    printf("  energy with damping, no gravity: %.4g J -> %.4g J in 200 steps\n", first, prev);
    cloth_driver_close(d);
    cloth_model_free(&m);
}

/* No particle inside the obstacle at the end; cmp's statements = C's. */
static void check_obstacle(const char *extra, const char *what)
{
    cloth_scene s;
    double *xo, *xc, worst = 0;
    int p, n3;
    if (scene_of(&s, extra)) return;
    n3 = 3 * s.nx * s.ny;
    xo = calloc((size_t)n3, sizeof *xo);
    xc = calloc((size_t)n3, sizeof *xc);
    if (xo && xc && run(&s, CLOTH_ORIGINAL, 60, xo) == 0 && run(&s, CLOTH_CMP, 60, xc) == 0) {
        CHECK(max_diff(xo, xc, n3) <= 1e-9, "%s: cmp differs from original by %.3g", what, max_diff(xo, xc, n3));
        for (p = 0; p < s.nx * s.ny; p++) {
            double *q = xo + 3 * p, in;
            if (s.obstacle == OBSTACLE_SPHERE) {
                double r = sqrt((q[0] - s.center[0]) * (q[0] - s.center[0]) +
                                (q[1] - s.center[1]) * (q[1] - s.center[1]) +
                                (q[2] - s.center[2]) * (q[2] - s.center[2]));
                in = s.radius - r;
            } else {
                in = s.floor_z - q[2];
            }
            worst = fmax(worst, in);
        }
        CHECK(worst <= 1e-12, "%s: a particle ends %.3g inside the obstacle", what, worst);
        printf("  %s: 60 steps, |cmp - original| %.2g, deepest particle %.2g inside\n", what,
               max_diff(xo, xc, n3), worst);
    }
    free(xo);
    free(xc);
}

/* A is symmetric, and A v = S ((1 + dt c) M + dt^2 Lk) S v + (I - S)(1 + dt c) M v
 * for a random v, S = diag(fixed): the pins constrained. */
static void check_matrix(void)
{
    cloth_scene s;
    cloth_model m;
    char err[512];
    double *a, *f, *b, *v, *y, worst = 0, asym = 0;
    int64_t r, q, q2;
    int k, d;
    if (scene_of(&s, SPRINGS) || cloth_model_init(&m, &s, err, sizeof err)) return;
    a = calloc((size_t)m.nnz, sizeof *a);
    f = calloc((size_t)3 * m.n, sizeof *f);
    b = calloc((size_t)3 * m.n, sizeof *b);
    v = calloc((size_t)3 * m.n, sizeof *v);
    y = calloc((size_t)3 * m.n, sizeof *y);
    if (!a || !f || !b || !v || !y) goto out;
    for (r = 0; r < 3 * m.n; r++) v[r] = sin(1.0 + 3.7 * (double)r);
    cloth_forces(&m, m.x, f);
    cloth_system(&m, f, m.v, a, b);
    for (r = 0; r < 3 * m.n; r++) y[r] = (1 + s.dt * s.damping) * m.mass[r] * v[r];
    for (k = 0; k < m.ns; k++)
        for (d = 0; d < 3; d++) {
            int64_t l = 3 * m.sl[k] + d, o = 3 * m.sr[k] + d;
            double c = s.dt * s.dt * m.k[k] * (m.fixed[l] * v[l] - m.fixed[o] * v[o]);
            y[l] += c * m.fixed[l];
            y[o] -= c * m.fixed[o];
        }
    for (r = 0; r < 3 * m.n; r++) {
        double sum = 0;
        for (q = m.rowptr[r]; q < m.rowptr[r + 1]; q++) {
            sum += a[q] * v[m.colind[q]];
            for (q2 = m.rowptr[m.colind[q]]; q2 < m.rowptr[m.colind[q] + 1]; q2++)
                if (m.colind[q2] == r) asym = fmax(asym, fabs(a[q2] - a[q]));
        }
        worst = fmax(worst, fabs(sum - y[r]));
    }
    CHECK(worst <= 1e-12, "A v differs from the springs' own product by %.3g", worst);
    CHECK(asym == 0, "A is not symmetric (%.3g)", asym);
out:
    free(a), free(f), free(b), free(v), free(y);
    cloth_model_free(&m);
}

int main(void)
{
    check_matrix();
    check_three_ways(SPRINGS, "hanging 8x7");
    check_three_ways("k_bend = 0\nk_shear = 0\ntilt = 30\n", "structural only, tilted");
    check_named_solvers();
    check_pins();
    check_energy();
    check_obstacle(SPRINGS "obstacle = sphere 0.5 0.45 -0.4 0.3\n", "sphere");
    check_obstacle(SPRINGS "obstacle = floor -0.2\n", "floor");
    return check_done();
}
