/*
 * test_cloth_c_step.c -- the plain-C step that cloth_bench --seed-statements
 * measures the cmp statements against (bench/cloth_c_step.c) does the
 * statements' work, so the baseline cannot silently do less:
 *
 *   - its A and b, entry by entry, are the model's own assembly
 *     (cloth_forces + cloth_system, written independently in
 *     examples/cloth/cloth_model.c), the pinned couplings it leaves out of
 *     its pattern being zeros there;
 *   - after 15 steps of hanging with CG + Jacobi at 1e-10 it ends where the
 *     cmp mode's statements end, to the solver's tolerance, after the same
 *     iterations (lis-style's stopping test, warm-started from the last dv);
 *   - the comparison can fail: at tolerance 1e-3 the C step lands visibly
 *     elsewhere and takes fewer iterations.
 * Scenes come from SILC_CLOTH_SCENES (examples/cloth/scenes).
 */
#define _POSIX_C_SOURCE 200809L
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "check.h"
#include "cloth.h"
#include "cloth_c_step.h"

enum { STEPS = 15 };

static const char cg_1e10[] = "backend = lis-style; lis-style.options = -i cg -p jacobi -tol 1e-10 -maxiter 5000";

static int load(const char *name, cloth_scene *s)
{
    char path[1024], err[1024];
    const char *dir = getenv("SILC_CLOTH_SCENES");
    snprintf(path, sizeof path, "%s/%s.scene", dir ? dir : "examples/cloth/scenes", name);
    if (scene_read(path, s, err, sizeof err)) {
        CHECK(0, "%s: %s", name, err);
        return -1;
    }
    return 0;
}

/* The C step's first A and b against cloth_forces + cloth_system. */
static void test_assembly_matches_model(const cloth_scene *s)
{
    cloth_model m;
    cloth_c_step c;
    char err[1024];
    double *x0, *v0, *f, *a, *b, worst_a = 0, worst_b = 0, scale_a = 0, scale_b = 0;
    int64_t N, r, i, j;
    int missing = 0;
    if (cloth_model_init(&m, s, err, sizeof err) || cloth_c_step_open(&c, &m, 1e-10, err, sizeof err)) {
        CHECK(0, "%s", err);
        return;
    }
    N = c.N;
    x0 = malloc((size_t)N * sizeof *x0), v0 = malloc((size_t)N * sizeof *v0), f = malloc((size_t)N * sizeof *f);
    a = calloc((size_t)m.nnz, sizeof *a), b = malloc((size_t)N * sizeof *b);
    if (!x0 || !v0 || !f || !a || !b) {
        CHECK(0, "out of memory");
        goto out;
    }
    /* Two steps, so that v is not zero and the damping term counts. */
    CHECK(cloth_c_step_run(&c, NULL, err, sizeof err) == 0, "%s", err);
    memcpy(x0, m.x, (size_t)N * sizeof *x0), memcpy(v0, m.v, (size_t)N * sizeof *v0);
    CHECK(cloth_c_step_run(&c, NULL, err, sizeof err) == 0, "%s", err);
    cloth_forces(&m, x0, f);
    cloth_system(&m, f, v0, a, b);
    for (r = 0; r < N; r++) {
        scale_b = fmax(scale_b, fabs(b[r]));
        worst_b = fmax(worst_b, fabs(b[r] - c.b[r]));
        for (i = m.rowptr[r], j = c.rowptr[r]; i < m.rowptr[r + 1]; i++) {
            double mine = 0;
            if (j < c.rowptr[r + 1] && c.colind[j] == m.colind[i]) mine = c.a[j++];
            else missing += a[i] != 0; /* left out of the C pattern: must be a zero */
            scale_a = fmax(scale_a, fabs(a[i]));
            worst_a = fmax(worst_a, fabs(a[i] - mine));
        }
        CHECK(j == c.rowptr[r + 1], "row %lld: the C pattern has columns the model's lacks", (long long)r);
    }
    CHECK(missing == 0, "%d nonzero entries of the model's A are missing from the C step's", missing);
    CHECK(worst_a <= 1e-14 * scale_a, "A: the C step's differs from cloth_system's by %.3g (scale %.3g)", worst_a,
          scale_a);
    CHECK(worst_b <= 1e-12 * scale_b, "b: the C step's differs from cloth_system's by %.3g (scale %.3g)", worst_b,
          scale_b);
    CHECK(c.nnz < m.nnz, "the C pattern (%lld entries) should leave out the pins' couplings (%lld in the model's)",
          (long long)c.nnz, (long long)m.nnz);
out:
    free(x0), free(v0), free(f), free(a), free(b);
    cloth_c_step_close(&c);
    cloth_model_free(&m);
}

/* STEPS steps by the C step at tol: the final positions into x, the iterations. */
static long run_c(const cloth_scene *s, double tol, double *x)
{
    cloth_model m;
    cloth_c_step c;
    char err[1024];
    long it = -1;
    int k, rc = 0;
    if (cloth_model_init(&m, s, err, sizeof err)) {
        CHECK(0, "%s", err);
        return -1;
    }
    rc = cloth_c_step_open(&c, &m, tol, err, sizeof err);
    if (!rc) c.maxiter = 5000;
    for (k = 0; k < STEPS && !rc; k++) rc = cloth_c_step_run(&c, NULL, err, sizeof err);
    CHECK(rc == 0, "C step: %s", err);
    if (!rc) {
        memcpy(x, m.x, (size_t)3 * m.n * sizeof *x);
        it = c.iterations;
    }
    if (c.m) cloth_c_step_close(&c);
    cloth_model_free(&m);
    return it;
}

/* STEPS steps of the cmp statements with CG + Jacobi at 1e-10. */
static long run_cmp(const cloth_scene *s, double *x)
{
    cloth_model m;
    cloth_driver *d;
    cloth_times t = {0, 0, 0, 0};
    char err[1024] = "";
    long it = 0;
    int k, rc = 0;
    if (cloth_model_init(&m, s, err, sizeof err)) {
        CHECK(0, "%s", err);
        return -1;
    }
    d = cloth_driver_open(&m, CLOTH_CMP, cg_1e10, 1e-10, err, sizeof err);
    rc = !d;
    for (k = 0; k < STEPS && !rc; k++) {
        double berr, cond;
        long i = 0;
        rc = cloth_driver_step(d, &t, err, sizeof err) || cloth_driver_solve_report(d, &berr, &cond, &i, err, sizeof err);
        it += i;
    }
    rc = rc || cloth_driver_sync(d, err, sizeof err);
    CHECK(rc == 0, "cmp: %s", err);
    if (!rc) memcpy(x, m.x, (size_t)3 * m.n * sizeof *x);
    cloth_driver_close(d);
    cloth_model_free(&m);
    return rc ? -1 : it;
}

static double max_diff(const double *a, const double *b, int n)
{
    double d = 0;
    int i;
    for (i = 0; i < n; i++) d = fmax(d, fabs(a[i] - b[i]));
    return d;
}

int main(void)
{
    cloth_scene s;
    double *xc, *xs, *xl, moved = 0;
    long itc, its, itl;
    int n3, i;
    if (load("hanging", &s)) return check_done();
    test_assembly_matches_model(&s);
    n3 = 3 * s.nx * s.ny;
    xc = malloc((size_t)n3 * sizeof *xc), xs = malloc((size_t)n3 * sizeof *xs), xl = malloc((size_t)n3 * sizeof *xl);
    if (!xc || !xs || !xl) return 1;
    itc = run_c(&s, 1e-10, xc);
    its = run_cmp(&s, xs);
    itl = run_c(&s, 1e-3, xl);
    if (itc >= 0 && its >= 0 && itl >= 0) {
        cloth_model m;
        char err[256];
        double d = max_diff(xc, xs, n3), dl = max_diff(xl, xs, n3);
        if (cloth_model_init(&m, &s, err, sizeof err) == 0) {
            for (i = 0; i < n3; i++) moved = fmax(moved, fabs(xs[i] - m.x[i]));
            cloth_model_free(&m);
        }
        /* The cloth falls by centimetres in 15 steps: a run that does not
         * move would agree with anything. */
        CHECK(moved > 1e-3, "the cloth moved only %.3g m in %d steps", moved, STEPS);
        CHECK(d <= 1e-9, "C step and statements end %.3g m apart (tolerance 1e-10)", d);
        CHECK(labs(itc - its) <= STEPS / 5, "iterations: C step %ld, statements %ld over %d steps", itc, its, STEPS);
        CHECK(itc > 20 * STEPS, "only %ld iterations in %d steps at 1e-10", itc, STEPS);
        /* The check tells a lazier baseline apart. */
        CHECK(dl > 100 * d && dl > 1e-7, "at tolerance 1e-3 the C step should land elsewhere (%.3g m, against %.3g)",
              dl, d);
        CHECK(itl < itc / 2, "at tolerance 1e-3 the C step took %ld iterations (%ld at 1e-10)", itl, itc);
        printf("C step %ld iterations, statements %ld; positions %.2g m apart (%.2g at tol 1e-3), moved %.3g m\n", itc,
               its, d, dl, moved);
    }
    free(xc), free(xs), free(xl);
    return check_done();
}
