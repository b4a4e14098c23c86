/*
 * cloth_c_step.c -- the plain-C cloth step that issue 30 item 1 measures the
 * cmp mode's statements against (cloth_c_step.h).  It does what the
 * statements compute, the way a program written for speed would:
 *
 *   - A = M - dt^2 DfDx - dt DfDv with the pins constrained (S A S + M_pin)
 *     is assembled straight into CSR on a pattern built once, without the
 *     couplings of pinned coordinates (the statements' S * A * S drops them
 *     too); each spring adds to four precomputed slots, a dropped one goes
 *     to a sink entry past the end, so the loop has no branch;
 *   - forces and b = S dt (f + dt DfDx v) in one loop over the springs
 *     (p = x_l - x_r, z = |p|, fij = K (z - L) / z p, DfDx v = -K (v_l - v_r)
 *     per direction: the statements' P, z, fij and -A1 A1' v);
 *   - CG + Jacobi in fused loops (A p with p'Ap; x, r and ||r||; z = D^-1 r
 *     with r'z; p), started from the last step's dv and stopped as
 *     lis-style stops (||r|| <= tol ||b|| on the recursion, then on the
 *     true residual b - A x, restarting from the iterate while that keeps
 *     gaining), so both do the same iterations;
 *   - v += dv .* fixed, x += dt v, with xprev and xfree kept (cloth_update),
 *     as the cmp driver's update keeps xp and xf.
 *
 * Indices are int64_t, as in SILC's CSR values and the model's pattern.
 */
#define _POSIX_C_SOURCE 200809L
#include "cloth_c_step.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

void cloth_c_step_close(cloth_c_step *c)
{
    free(c->rowptr), free(c->colind), free(c->diag), free(c->slot), free(c->a);
    free(c->b), free(c->dv), free(c->dinv), free(c->r), free(c->z), free(c->p), free(c->q);
    memset(c, 0, sizeof *c);
}

int cloth_c_step_open(cloth_c_step *c, cloth_model *m, double tol, char *err, size_t errlen)
{
    int64_t N = 3 * (int64_t)m->n, r, i, at = 0, *renum;
    size_t vec = (size_t)N * sizeof(double);
    int k, d;
    memset(c, 0, sizeof *c);
    c->m = m, c->tol = tol, c->maxiter = 1000, c->N = N;
    c->rowptr = malloc((size_t)(N + 1) * sizeof *c->rowptr);
    c->colind = malloc((size_t)m->nnz * sizeof *c->colind);
    c->diag = malloc((size_t)N * sizeof *c->diag);
    c->slot = malloc((size_t)(12 * (m->ns ? m->ns : 1)) * sizeof *c->slot);
    renum = malloc((size_t)m->nnz * sizeof *renum);
    c->b = malloc(vec), c->dv = calloc((size_t)N, sizeof(double)), c->dinv = malloc(vec);
    c->r = malloc(vec), c->z = malloc(vec), c->p = malloc(vec), c->q = malloc(vec);
    if (!c->rowptr || !c->colind || !c->diag || !c->slot || !renum || !c->b || !c->dv || !c->dinv || !c->r ||
        !c->z || !c->p || !c->q) {
        free(renum);
        cloth_c_step_close(c);
        snprintf(err, errlen, "out of memory for the C step");
        return -1;
    }
    /* The model's pattern less the couplings of a pinned coordinate. */
    c->rowptr[0] = 0;
    for (r = 0; r < N; r++) {
        for (i = m->rowptr[r]; i < m->rowptr[r + 1]; i++) {
            int64_t col = m->colind[i];
            renum[i] = -1;
            if (col != r && (m->fixed[r] == 0 || m->fixed[col] == 0)) continue;
            if (col == r) c->diag[r] = at;
            renum[i] = at;
            c->colind[at++] = col;
        }
        c->rowptr[r + 1] = at;
    }
    c->nnz = at;
    /* Each spring's slots in the new pattern; a pinned row's diagonal keeps
     * only its M_pin, so its spring terms go to the sink too. */
    for (k = 0; k < m->ns; k++)
        for (d = 0; d < 3; d++) {
            const int64_t *old = m->spring_slot + 12 * k + 4 * d;
            int64_t *slot = c->slot + 12 * k + 4 * d, l = 3 * (int64_t)m->sl[k] + d, q = 3 * (int64_t)m->sr[k] + d;
            slot[0] = m->fixed[l] != 0 ? renum[old[0]] : -1;
            slot[1] = m->fixed[q] != 0 ? renum[old[1]] : -1;
            slot[2] = renum[old[2]], slot[3] = renum[old[3]];
            for (i = 0; i < 4; i++)
                if (slot[i] < 0) slot[i] = c->nnz;
        }
    free(renum);
    c->a = malloc((size_t)(c->nnz + 1) * sizeof *c->a);
    if (!c->a) {
        cloth_c_step_close(c);
        snprintf(err, errlen, "out of memory for the C step");
        return -1;
    }
    return 0;
}

/* A's values and b (see the top of the file). */
static void assemble(cloth_c_step *c)
{
    const cloth_model *m = c->m;
    const cloth_scene *s = m->scene;
    const double *x = m->x, *v = m->v;
    double dt = s->dt, dt2 = dt * dt, *a = c->a, *b = c->b;
    int64_t i, N = c->N;
    int k, d;
    memset(a, 0, (size_t)c->nnz * sizeof *a);
    for (i = 0; i < N; i++) {
        a[c->diag[i]] = (1 + dt * s->damping) * m->mass[i];
        b[i] = m->mass[i] * m->gvec[i];
    }
    for (k = 0; k < m->ns; k++) {
        int64_t l = 3 * (int64_t)m->sl[k], q = 3 * (int64_t)m->sr[k];
        const int64_t *slot = c->slot + 12 * k;
        double p0 = x[l] - x[q], p1 = x[l + 1] - x[q + 1], p2 = x[l + 2] - x[q + 2], kk = m->k[k];
        double z = sqrt(p0 * p0 + p1 * p1 + p2 * p2), f = kk * (z - m->rest[k]) / z, ak = dt2 * kk, dk = dt * kk;
        double t0 = f * p0 + dk * (v[l] - v[q]), t1 = f * p1 + dk * (v[l + 1] - v[q + 1]),
               t2 = f * p2 + dk * (v[l + 2] - v[q + 2]);
        b[l] -= t0, b[l + 1] -= t1, b[l + 2] -= t2;
        b[q] += t0, b[q + 1] += t1, b[q + 2] += t2;
        for (d = 0; d < 3; d++, slot += 4) {
            a[slot[0]] += ak, a[slot[1]] += ak;
            a[slot[2]] -= ak, a[slot[3]] -= ak;
        }
    }
    for (i = 0; i < N; i++) b[i] *= dt * m->fixed[i];
}

/* r = b - A x; returns ||r||. */
static double residual(const cloth_c_step *c, const double *x, double *r)
{
    const int64_t *rp = c->rowptr, *ci = c->colind;
    const double *a = c->a, *b = c->b;
    double ss = 0;
    int64_t i, k;
    for (i = 0; i < c->N; i++) {
        double s = b[i];
        for (k = rp[i]; k < rp[i + 1]; k++) s -= a[k] * x[ci[k]];
        r[i] = s;
        ss += s * s;
    }
    return sqrt(ss);
}

/* CG + Jacobi from x (with r = b - A x) until ||r|| <= tol * den or the
 * iteration limit; 1 when the recursion says converged, 0 at the limit,
 * -1 on a breakdown. */
static int cg(cloth_c_step *c, double *x, double den, int *it)
{
    const int64_t *rp = c->rowptr, *ci = c->colind, N = c->N;
    const double *a = c->a, *dinv = c->dinv;
    double *r = c->r, *z = c->z, *p = c->p, *q = c->q, rho = 0, rho1, pq, alpha, ss;
    int64_t i, k;
    for (i = 0; i < N; i++) z[i] = r[i] * dinv[i], rho += r[i] * z[i], p[i] = z[i];
    while (*it < c->maxiter) {
        for (pq = 0, i = 0; i < N; i++) {
            double s = 0;
            for (k = rp[i]; k < rp[i + 1]; k++) s += a[k] * p[ci[k]];
            q[i] = s, pq += p[i] * s;
        }
        if (!(pq > 0)) return -1;
        alpha = rho / pq;
        for (ss = 0, i = 0; i < N; i++) x[i] += alpha * p[i], r[i] -= alpha * q[i], ss += r[i] * r[i];
        ++*it;
        if (sqrt(ss) / den <= c->tol) return 1;
        for (rho1 = 0, i = 0; i < N; i++) z[i] = r[i] * dinv[i], rho1 += r[i] * z[i];
        if (rho1 == 0) return -1;
        for (i = 0; i < N; i++) p[i] = z[i] + (rho1 / rho) * p[i];
        rho = rho1;
    }
    return 0;
}

/* dv = A \ b from the last dv, lis-style's outer loop: the true residual
 * decides, a restart from the iterate while it keeps halving. */
static int solve(cloth_c_step *c, char *err, size_t errlen)
{
    double *x = c->dv, bn = 0, r0n, tr, prev = INFINITY;
    int64_t i;
    int it = 0, restarts = 0, st;
    for (i = 0; i < c->N; i++) c->dinv[i] = 1 / c->a[c->diag[i]], bn += c->b[i] * c->b[i];
    bn = sqrt(bn);
    r0n = residual(c, x, c->r);
    if (c->have_dv && !(r0n < bn)) { /* no better than zero: start from zero */
        memset(x, 0, (size_t)c->N * sizeof *x);
        r0n = residual(c, x, c->r);
    }
    c->have_dv = 1;
    if (r0n == 0) {
        c->last_iterations = 0;
        return 0;
    }
    for (;;) {
        st = cg(c, x, bn, &it);
        tr = residual(c, x, c->r) / bn;
        if (tr <= c->tol) break;
        if (st == 1 && it < c->maxiter && tr < 0.5 * prev && restarts < 50) {
            prev = tr, restarts++;
            continue;
        }
        snprintf(err, errlen, "C step: CG %s after %d iterations (relative residual %.1e)",
                 st < 0 ? "broke down" : "did not converge", it, tr);
        return -1;
    }
    c->last_iterations = it;
    c->iterations += it;
    return 0;
}

static double now(void)
{
    struct timespec t;
    clock_gettime(CLOCK_MONOTONIC, &t);
    return (double)t.tv_sec + 1e-9 * (double)t.tv_nsec;
}

int cloth_c_step_run(cloth_c_step *c, cloth_times *t, char *err, size_t errlen)
{
    double t0 = t ? now() : 0, t1, t2;
    assemble(c);
    t1 = t ? now() : 0;
    if (solve(c, err, errlen)) return -1;
    t2 = t ? now() : 0;
    cloth_update(c->m, c->dv);
    if (t) {
        t->assembly += t1 - t0, t->solve += t2 - t1, t->update += now() - t2;
        t->cg_iterations += c->last_iterations;
    }
    return 0;
}
