/*
 * cloth.c -- the seeds' cloth simulation as a program: a scene file, one of
 * three drivers, PNG frames and a summary (cloth.h, README.md here).
 *
 *     cloth SCENE [--mode original|ltd|cmp] [--steps N] [--frames DIR]
 *                 [--solver NAME|OPTIONS | --tune] [--tol T] [--size WxH] [--strict]
 *     cloth --keys                      the scene keys with their defaults
 *
 * The scene's accuracy sets the tolerance T of every iterative solve: the
 * original driver's CG and, in ltd and cmp, the solver --solver names
 * (direct, cg, cg-ic, cg-amg, petsc-cg: cloth.h) stop at a residual of T
 * relative to ||b||, T = accuracy / (a bound on A's condition number:
 * cloth_default_tol) unless --tol says otherwise.
 * Without --solver, ltd and cmp use SILC's configured dispatch (a sparse
 * Cholesky by default); --solver also takes SILC solve options as they
 * are ("backend = lis-style; lis-style.options = -i cg -p ic -tol 1e-8").
 * --tune lets SILC's tuner choose the backend (and threads) for the run,
 * under a backward-error target of T, and the summary says what it chose.
 *
 * After every step the monitor (monitor.c) checks the solve's accuracy
 * bound, the obstacle (tunnelling), the springs' stretch and the energy
 * account against the scene; the first failure of each kind is a warning
 * on stderr naming the step, with a hint, and the summary counts them.
 * --strict makes the first one an error.  In cmp this fetches x, v and two
 * more position vectors every step.
 * The exit status is 1 on any failure (and, with --strict, on a failed
 * check), with the message on stderr, 2 on a usage error or a scene that is
 * wrong or cannot be simulated (scene.c says which values).
 */
#define _POSIX_C_SOURCE 200809L
#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>

#include "cloth.h"
#include "progress.h"

static const char usage[] =
    "usage: cloth SCENE [--mode original|ltd|cmp] [--steps N] [--frames DIR] [--solver NAME|OPTIONS | --tune]\n"
    "                   [--tol T] [--size WxH] [--strict]\n"
    "       cloth --keys\n";

static int bad_usage(const char *why)
{
    fprintf(stderr, "cloth: %s\n%s", why, usage);
    return 2;
}

static int write_frame(const char *dir, const cloth_scene *s, cloth_mode mode, int step, const double *x,
                       int w, int h)
{
    char path[4096], err[512];
    snprintf(path, sizeof path, "%s/%s_%s_%05d.png", dir, s->name, cloth_mode_name(mode), step);
    if (frame_write_png(path, s, x, w, h, err, sizeof err)) {
        fprintf(stderr, "cloth: %s\n", err);
        return -1;
    }
    return 0;
}

int main(int argc, char **argv)
{
    const char *scene_path = NULL, *frames = NULL, *solver = NULL;
    cloth_mode mode = CLOTH_ORIGINAL;
    int steps = -1, w = 640, h = 480, a, step, tune = 0, strict = 0, k;
    double tol = -1, ek0, es0, ek, es, pinned = 0, berr, cond;
    cloth_monitor mon;
    cloth_scene scene;
    progress bar = {0, 0, 0, 0};
    cloth_model m;
    cloth_driver *d;
    cloth_times t = {0, 0, 0, 0};
    char err[1024];
    for (a = 1; a < argc; a++) {
        const char *opt = argv[a], *arg = a + 1 < argc ? argv[a + 1] : NULL;
        char *end = NULL;
        if (!strcmp(opt, "--keys")) {
            scene_print_keys(stdout);
            return 0;
        } else if (!strcmp(opt, "-h") || !strcmp(opt, "--help")) {
            fputs(usage, stdout);
            return 0;
        } else if (!strcmp(opt, "--tune")) {
            tune = 1;
            continue;
        } else if (!strcmp(opt, "--strict")) {
            strict = 1;
            continue;
        } else if (opt[0] != '-') {
            if (scene_path) return bad_usage("more than one scene given");
            scene_path = opt;
            continue;
        }
        if (!arg) return bad_usage("an option is missing its value");
        a++;
        errno = 0;
        if (!strcmp(opt, "--mode")) {
            if (!strcmp(arg, "original")) mode = CLOTH_ORIGINAL;
            else if (!strcmp(arg, "ltd")) mode = CLOTH_LTD;
            else if (!strcmp(arg, "cmp")) mode = CLOTH_CMP;
            else return bad_usage("--mode is original, ltd or cmp");
        } else if (!strcmp(opt, "--steps")) {
            long v = strtol(arg, &end, 10);
            if (*end || errno || v < 1 || v > 10000000) return bad_usage("--steps takes an integer >= 1");
            steps = (int)v;
        } else if (!strcmp(opt, "--tol")) {
            tol = strtod(arg, &end);
            if (*end || errno || !(tol > 0 && tol < 1)) return bad_usage("--tol takes a number in (0, 1)");
        } else if (!strcmp(opt, "--size")) {
            if (sscanf(arg, "%dx%d", &w, &h) != 2 || w < 16 || h < 16 || w > 4096 || h > 4096)
                return bad_usage("--size takes WxH, each 16..4096");
        } else if (!strcmp(opt, "--frames")) {
            frames = arg;
        } else if (!strcmp(opt, "--solver")) {
            solver = arg;
        } else {
            return bad_usage("unknown option");
        }
    }
    if (!scene_path) return bad_usage("no scene file given");
    if (scene_read(scene_path, &scene, err, sizeof err)) {
        fprintf(stderr, "cloth: %s\n", err);
        return 2;
    }
    if (steps > 0) scene.steps = steps;
    if (frames && mkdir(frames, 0777) && errno != EEXIST) {
        fprintf(stderr, "cloth: cannot create '%s': %s\n", frames, strerror(errno));
        return 1;
    }
    if (cloth_model_init(&m, &scene, err, sizeof err)) {
        fprintf(stderr, "cloth: %s\n", err);
        return 1;
    }
    if (tol < 0) tol = cloth_default_tol(&m);
    if (!(d = cloth_driver_open(&m, mode, solver, tol, err, sizeof err))) {
        fprintf(stderr, "cloth: %s\n", err);
        cloth_model_free(&m);
        return 1;
    }
    if (tune && solver) {
        cloth_driver_close(d);
        cloth_model_free(&m);
        return bad_usage("--tune and --solver both choose the solver: give one");
    }
    if (tune && cloth_driver_tune(d, scene.accuracy / 100, scene.steps, err, sizeof err)) {
        fprintf(stderr, "cloth: %s\n", err);
        goto fail;
    }
    cloth_energy(&m, m.x, m.v, &ek0, &es0);
    cloth_monitor_start(&mon, &m);
    if (frames && scene.frame_every > 0 && write_frame(frames, &scene, mode, 0, m.x, w, h)) goto fail;
    progress_start(&bar);
    for (step = 1; step <= scene.steps; step++) {
        progress_show(&bar, "cloth: step %d of %d", step, scene.steps);
        if (cloth_driver_step(d, &t, err, sizeof err)) {
            progress_done(&bar);
            fprintf(stderr, "cloth: step %d: %s\n", step, err);
            goto fail;
        }
        if (cloth_driver_solve_report(d, &berr, &cond, NULL, err, sizeof err) || cloth_driver_sync(d, err, sizeof err) ||
            cloth_monitor_step(&mon, &m, step, berr, cond, err, sizeof err)) {
            progress_done(&bar);
            fprintf(stderr, "cloth: %s\n", err);
            goto fail;
        }
        for (k = 0; mon.fresh && k < CLOTH_CHECKS; k++)
            if (mon.fresh & (1u << k)) {
                progress_done(&bar);
                fprintf(stderr, "cloth: %s: %s\n", strict ? "error (--strict)" : "warning", mon.first[k]);
                if (strict) goto fail;
            }
        if (frames && scene.frame_every > 0 && step % scene.frame_every == 0) {
            progress_done(&bar); /* a failure's message gets a clean line */
            if (cloth_driver_sync(d, err, sizeof err)) {
                fprintf(stderr, "cloth: %s\n", err);
                goto fail;
            }
            if (write_frame(frames, &scene, mode, step, m.x, w, h)) goto fail;
        }
    }
    progress_done(&bar);
    if (cloth_driver_sync(d, err, sizeof err)) {
        fprintf(stderr, "cloth: %s\n", err);
        goto fail;
    }
    cloth_energy(&m, m.x, m.v, &ek, &es);
    for (a = 0; a < scene.npins; a++) {
        int p = scene.pin_j[a] * scene.nx + scene.pin_i[a], k;
        for (k = 0; k < 3; k++) pinned = fmax(pinned, fabs(m.x[3 * p + k] - m.x0[3 * p + k]));
    }
    printf("scene %s: %dx%d particles, %d springs, mode %s, %d steps of %g s\n", scene.name, scene.nx,
           scene.ny, m.ns, cloth_mode_name(mode), scene.steps, scene.dt);
    printf("time per step: %.3f ms (assembly %.3f, solve %.3f, update %.3f)\n",
           1e3 * (t.assembly + t.solve + t.update) / scene.steps, 1e3 * t.assembly / scene.steps,
           1e3 * t.solve / scene.steps, 1e3 * t.update / scene.steps);
    if (mode == CLOTH_ORIGINAL)
        printf("CG: tolerance %.1e, %.1f iterations per step\n", tol, (double)t.cg_iterations / scene.steps);
    if (mode != CLOTH_ORIGINAL) {
        char used[400];
        cloth_driver_solver(d, used, sizeof used);
        printf("solve%s: %s\n", tune ? " (chosen by the tuner, backward error <= accuracy / 100)" : "", used);
        if (solver && strcmp(solver, "direct") && !strchr(solver, '='))
            printf("tolerance %.1e relative to ||b|| (%s)\n", tol, cloth_solver_label(solver));
    }
    printf("max displacement %.6g m; pinned particles moved %.3g m\n", cloth_max_displacement(&m, m.x), pinned);
    printf("energy: kinetic %.6g J, spring %.6g J (at start %.6g, %.6g), gravity %.6g J\n", ek, es, ek0, es0,
           cloth_gravity_energy(&m, m.x));
    printf("energy account: total %.6g J at the start, %.6g J at the end: %.6g J taken by damping and contact; "
           "largest one-step rise %.3g J (allowed: accuracy x energy scale %.3g J = %.3g J)\n",
           mon.e_start, mon.e_prev, mon.e_start - mon.e_prev, mon.max_rise, mon.scale, scene.accuracy * mon.scale);
    printf("max spring stretch %.4gx rest length (max_stretch %g)\n", mon.stretch, scene.max_stretch);
    printf("solves: largest backward error %.2g, condition estimate %.3g, forward error bound %.2g (accuracy %g)\n",
           mon.backward_error, mon.cond, mon.worst_bound, scene.accuracy);
    if (!cloth_monitor_problems(&mon)) printf("checks: every step passed (solve accuracy, tunnelling, stretch, energy)\n");
    for (k = 0; k < CLOTH_CHECKS; k++)
        if (mon.count[k])
            printf("checks: %s failed at %ld of %d steps, first at step %d\n", cloth_check_name(k), mon.count[k],
                   scene.steps, mon.first_step[k]);
    cloth_driver_close(d);
    cloth_model_free(&m);
    return isfinite(ek + es) ? 0 : 1;
fail:
    cloth_driver_close(d);
    cloth_model_free(&m);
    return 1;
}
