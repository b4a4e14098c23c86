/*
 * monitor.c -- the checks that make a wrong cloth run say so (cloth.h,
 * "the monitor").  After every step the program hands the monitor the state
 * (x, v, the positions before the step and before the obstacle's
 * constraint) and the solve's report (backward error, condition estimate);
 * the monitor keeps the energy account and compares each step against the
 * scene's own accuracy:
 *   solve     cond x backward error, the first-order bound on dv's relative
 *             error (docs/accuracy.md), above the accuracy;
 *   tunnel    a particle's straight path within the step passes through the
 *             sphere (enters it deeper than 1% of its radius and leaves it,
 *             or ends past its centre, where the constraint pushes it out
 *             the far side), or reaches deeper than a quarter of the
 *             radius, or crosses the floor by more than 1% of the cloth's
 *             size: the step is too long for the contact to be resolved;
 *   stretch   a spring longer than the scene's max_stretch times its rest
 *             length;
 *   energy    kinetic + spring + gravity rising by more than accuracy x the
 *             energy scale (cloth_energy_scale) in one step: nothing in the
 *             scene adds energy, damping and the contact only take it.
 * A non-finite state is a failure, not a warning.  The first time each kind
 * happens it is reported with its step and a hint; the summary counts them.
 */
#include "cloth.h"

#include <math.h>
#include <string.h>

static const char *const kind_names[CLOTH_CHECKS] = {"solve accuracy", "tunnelling", "stretch", "energy rise"};

const char *cloth_check_name(int kind)
{
    return kind >= 0 && kind < CLOTH_CHECKS ? kind_names[kind] : "?";
}

void cloth_monitor_start(cloth_monitor *mon, const cloth_model *m)
{
    memset(mon, 0, sizeof *mon);
    mon->scale = cloth_energy_scale(m);
    mon->e_start = mon->e_prev = cloth_total_energy(m, m->x, m->v);
    mon->e_max = mon->e_start;
    mon->stretch = cloth_max_stretch(m, m->x);
}

static double dist3(const double *a, const double *b)
{
    double dx = a[0] - b[0], dy = a[1] - b[1], dz = a[2] - b[2];
    return sqrt(dx * dx + dy * dy + dz * dz);
}

/* How a particle's step from p0 to p1 (before the constraint) meets the
 * obstacle: 0 if it does not pass through or too deep; else the depth in m. */
static double crossing(const cloth_scene *s, const double *p0, const double *p1)
{
    if (s->obstacle == OBSTACLE_SPHERE) {
        const double *c = s->center;
        double d[3] = {p1[0] - p0[0], p1[1] - p0[1], p1[2] - p0[2]}, dd = d[0] * d[0] + d[1] * d[1] + d[2] * d[2];
        double t = 0, q[3], dmin, r0 = dist3(p0, c), r1 = dist3(p1, c), depth, past;
        int k;
        if (r0 < s->radius * (1 - 1e-9)) return 0; /* started inside: not this step's crossing */
        if (dd > 0) t = fmin(1, fmax(0, ((c[0] - p0[0]) * d[0] + (c[1] - p0[1]) * d[1] + (c[2] - p0[2]) * d[2]) / dd));
        for (k = 0; k < 3; k++) q[k] = p0[k] + t * d[k];
        dmin = dist3(q, c);
        depth = s->radius - dmin;
        past = (p1[0] - c[0]) * (p0[0] - c[0]) + (p1[1] - c[1]) * (p0[1] - c[1]) + (p1[2] - c[2]) * (p0[2] - c[2]);
        if (depth > 0.01 * s->radius && (r1 >= s->radius || past < 0)) return depth;
        if (depth > 0.25 * s->radius) return depth;
        return 0;
    }
    if (s->obstacle == OBSTACLE_FLOOR) {
        double depth = s->floor_z - p1[2];
        if (p0[2] >= s->floor_z && depth > 0.01 * fmax(s->width, s->height)) return depth;
    }
    return 0;
}

/* Records a problem of `kind` at `step`; the first of its kind gets msg. */
static void flag(cloth_monitor *mon, int kind, int step, const char *msg)
{
    if (mon->count[kind]++ == 0) {
        mon->first_step[kind] = step;
        snprintf(mon->first[kind], sizeof mon->first[kind], "%s", msg);
        mon->fresh |= 1u << kind;
    }
}

int cloth_monitor_step(cloth_monitor *mon, const cloth_model *m, int step, double backward_error, double cond,
                       char *err, size_t errlen)
{
    const cloth_scene *s = m->scene;
    double e = cloth_total_energy(m, m->x, m->v), stretch = cloth_max_stretch(m, m->x), bound, depth = 0;
    char msg[sizeof mon->first[0]];
    int p, worst = -1;
    mon->fresh = 0;
    if (!isfinite(e) || !isfinite(stretch)) {
        snprintf(err, errlen, "step %d: the state is not finite (energy %g J): the simulation blew up; try a smaller dt",
                 step, e);
        return -1;
    }
    /* the solve */
    bound = cond * backward_error;
    mon->worst_bound = fmax(mon->worst_bound, bound);
    mon->cond = fmax(mon->cond, cond);
    mon->backward_error = fmax(mon->backward_error, backward_error);
    if (!(bound <= s->accuracy)) {
        snprintf(msg, sizeof msg,
                 "step %d: the solve's backward error %.2g x condition estimate %.2g = %.2g bounds dv's relative "
                 "error above the scene's accuracy %g (hint: a tighter --tol, or --solver direct)",
                 step, backward_error, cond, bound, s->accuracy);
        flag(mon, CLOTH_CHECK_SOLVE, step, msg);
    }
    /* the obstacle */
    for (p = 0; s->obstacle != OBSTACLE_NONE && p < m->n; p++) {
        double d = crossing(s, m->xprev + 3 * p, m->xfree + 3 * p);
        if (d > depth) depth = d, worst = p;
    }
    if (worst >= 0) {
        snprintf(msg, sizeof msg,
                 "step %d: particle (%d, %d) crossed the %s's surface within one step (%.3g m deep, from z = %.3g "
                 "to z = %.3g) (hint: a smaller dt)",
                 step, worst % s->nx, worst / s->nx, s->obstacle == OBSTACLE_SPHERE ? "sphere" : "floor", depth,
                 m->xprev[3 * worst + 2], m->xfree[3 * worst + 2]);
        flag(mon, CLOTH_CHECK_TUNNEL, step, msg);
    }
    /* the springs */
    mon->stretch = fmax(mon->stretch, stretch);
    if (stretch > s->max_stretch) {
        snprintf(msg, sizeof msg,
                 "step %d: a spring is %.3gx its rest length, beyond max_stretch %g (hint: a smaller dt, stiffer "
                 "springs or a larger max_stretch in the scene)",
                 step, stretch, s->max_stretch);
        flag(mon, CLOTH_CHECK_STRETCH, step, msg);
    }
    /* the energy account */
    mon->max_rise = fmax(mon->max_rise, e - mon->e_prev);
    if (e - mon->e_prev > s->accuracy * mon->scale) {
        snprintf(msg, sizeof msg,
                 "step %d: the energy rose by %.3g J in one step, more than accuracy x energy scale = %.3g J: "
                 "nothing in the scene adds energy (hint: a smaller dt, or a tighter --tol)",
                 step, e - mon->e_prev, s->accuracy * mon->scale);
        flag(mon, CLOTH_CHECK_ENERGY, step, msg);
    }
    mon->e_max = fmax(mon->e_max, e);
    mon->e_prev = e;
    mon->steps = step;
    return 0;
}

int cloth_monitor_problems(const cloth_monitor *mon)
{
    int k, n = 0;
    for (k = 0; k < CLOTH_CHECKS; k++) n += mon->count[k] > 0;
    return n;
}
