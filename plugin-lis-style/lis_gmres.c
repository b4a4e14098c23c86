/*
 * lis_gmres.c -- the long-recurrence solvers: GMRES(m) and FGMRES(m),
 * restarted every m iterations, and Orthomin(m), truncated to the last m
 * directions.
 *
 * Arnoldi with modified Gram-Schmidt on the right-preconditioned operator
 * A M^-1; the Hessenberg least-squares problem is reduced by Givens rotations
 * as it grows, so |g_{j+1}| is the residual norm of the current iterate
 * without forming it.  GMRES keeps the Krylov basis V and forms the update as
 * M^-1 (V y); FGMRES keeps the preconditioned vectors Z = M^-1 V as well,
 * which is what lets the preconditioner change from step to step.  The small
 * dense problem is computed in the solver's precision (double-double under
 * -f quad), like everything else.
 *
 * Orthomin(m) (Vinsome 1976; GCR truncated) keeps the last m directions p_j
 * with A p_j orthogonal to each other: each new direction is M^-1 r made
 * A'A-orthogonal to them, and the step along it minimises ||r||_2.  No
 * Hessenberg system, no restart: the memory is 2(m + 1) vectors, and with
 * m >= the iteration count it is GCR, which cannot stagnate unless the
 * symmetric part of A M^-1 is indefinite (then (A p, r) may vanish: a
 * breakdown, reported).
 */
#include "lis.h"

#include <stdlib.h>

static int arnoldi(lis_ctx *c, lis_vec *x, int flexible)
{
    int m = c->o->restart, nv = (m + 1) + (flexible ? m : 1) + 1, i, j, k, st = LIS_MAXITER;
    lis_vec *v = lis_host->calloc((size_t)nv, sizeof *v), *V, *Z, *w;
    dd *H = lis_host->calloc((size_t)(m + 1) * (size_t)m, sizeof(dd));
    dd *cs = lis_host->calloc((size_t)m, sizeof(dd)), *sn = lis_host->calloc((size_t)m, sizeof(dd));
    dd *g = lis_host->calloc((size_t)m + 1, sizeof(dd)), *y = lis_host->calloc((size_t)m, sizeof(dd));
#define Hij(i, j) H[(size_t)(j) * (size_t)(m + 1) + (size_t)(i)]
    if (!v || !H || !cs || !sn || !g || !y || lv_new_many(c, v, nv)) {
        st = LIS_NOMEM;
        goto free_all;
    }
    V = v, Z = v + m + 1, w = v + nv - 1;
    while (!lis_limit(c)) {
        dd beta;
        int happy = 0;
        lv_residual(c, x, &V[0]);
        beta = lv_nrm2(c, &V[0]);
        if (beta.hi != beta.hi) {
            st = lis_fail(c, beta, "");
            goto done;
        }
        if (beta.hi / c->den <= c->o->tol) {
            c->resid = beta.hi / c->den;
            st = LIS_CONVERGED;
            goto done;
        }
        lv_scale(c, s_div(c, dd_d(1), beta), &V[0]);
        g[0] = beta;
        for (i = 1; i <= m; i++) g[i] = dd_d(0);
        for (j = 0; j < m && !lis_limit(c); j++) {
            lis_vec *z = flexible ? &Z[j] : &Z[0];
            dd h, r;
            lv_psolve(c, &V[j], z);
            lv_matvec(c, z, w);
            for (i = 0; i <= j; i++) {
                Hij(i, j) = lv_dot(c, w, &V[i]);
                lv_axpy(c, dd_neg(Hij(i, j)), &V[i], w);
            }
            h = lv_nrm2(c, w);
            Hij(j + 1, j) = h;
            if (!s_zero(h)) {
                lv_copy(c, w, &V[j + 1]);
                lv_scale(c, s_div(c, dd_d(1), h), &V[j + 1]);
            }
            /* Apply the earlier rotations to the new column, then make its own. */
            for (i = 0; i < j; i++) {
                dd a = Hij(i, j), b = Hij(i + 1, j);
                Hij(i, j) = s_add(c, s_mul(c, cs[i], a), s_mul(c, sn[i], b));
                Hij(i + 1, j) = s_sub(c, s_mul(c, cs[i], b), s_mul(c, sn[i], a));
            }
            r = s_sqrt(c, s_add(c, s_mul(c, Hij(j, j), Hij(j, j)), s_mul(c, h, h)));
            if (s_zero(r) || r.hi != r.hi) {
                st = lis_fail(c, r, "the Hessenberg matrix is singular");
                goto done; /* nothing of this cycle can be used */
            }
            cs[j] = s_div(c, Hij(j, j), r);
            sn[j] = s_div(c, h, r);
            Hij(j, j) = r;
            Hij(j + 1, j) = dd_d(0);
            g[j + 1] = dd_neg(s_mul(c, sn[j], g[j]));
            g[j] = s_mul(c, cs[j], g[j]);
            st = lis_step(c, dd_d(fabs(g[j + 1].hi)));
            if (st == LIS_NAN) goto done;
            happy = s_zero(h); /* the Krylov space is invariant: the solution is in it */
            if (st == LIS_CONVERGED || happy) {
                j++;
                break;
            }
            st = LIS_MAXITER;
        }
        /* x += M^-1 V y (GMRES) or Z y (FGMRES), y from the triangular H y = g. */
        k = j;
        for (i = k - 1; i >= 0; i--) {
            dd s = g[i];
            for (int q = i + 1; q < k; q++) s = s_sub(c, s, s_mul(c, Hij(i, q), y[q]));
            y[i] = s_div(c, s, Hij(i, i));
        }
        if (flexible) {
            for (i = 0; i < k; i++) lv_axpy(c, y[i], &Z[i], x);
        } else {
            lv_zero(c, w);
            for (i = 0; i < k; i++) lv_axpy(c, y[i], &V[i], w);
            lv_psolve(c, w, &Z[0]);
            lv_axpy(c, dd_d(1), &Z[0], x);
        }
        if (st == LIS_CONVERGED || happy) {
            st = LIS_CONVERGED;
            goto done;
        }
    }
done:
    lv_free_many(v, nv);
free_all:
    if (v) lis_host->free(v);
    if (H) lis_host->free(H);
    if (cs) lis_host->free(cs);
    if (sn) lis_host->free(sn);
    if (g) lis_host->free(g);
    if (y) lis_host->free(y);
#undef Hij
    return st;
}

int lis_gmres(lis_ctx *c, lis_vec *x)
{
    return arnoldi(c, x, 0);
}

int lis_fgmres(lis_ctx *c, lis_vec *x)
{
    return arnoldi(c, x, 1);
}

int lis_orthomin(lis_ctx *c, lis_vec *x)
{
    int m = c->o->restart, nv = 2 * (m + 1) + 1, k = 0, have = 0, j, st = LIS_MAXITER;
    lis_vec *v = lis_host->calloc((size_t)nv, sizeof *v), *P, *AP, *r;
    dd *apap = lis_host->calloc((size_t)m + 1, sizeof(dd)), alpha;
    if (!v || !apap || lv_new_many(c, v, nv)) {
        if (v) lis_host->free(v);
        if (apap) lis_host->free(apap);
        return LIS_NOMEM;
    }
    /* A ring of m + 1 slots: the new direction k and the m before it. */
    P = v, AP = v + m + 1, r = v + nv - 1;
    lv_residual(c, x, r);
    while (!lis_limit(c)) {
        lv_psolve(c, r, &P[k]);
        lv_matvec(c, &P[k], &AP[k]);
        for (j = 1; j <= have; j++) {
            int i = (k + m + 1 - j) % (m + 1);
            dd beta = s_div(c, lv_dot(c, &AP[k], &AP[i]), apap[i]);
            lv_axpy(c, dd_neg(beta), &P[i], &P[k]);
            lv_axpy(c, dd_neg(beta), &AP[i], &AP[k]);
        }
        apap[k] = lv_dot(c, &AP[k], &AP[k]);
        if (s_zero(apap[k]) || apap[k].hi != apap[k].hi) {
            st = lis_fail(c, apap[k], "(A p, A p) = 0: the new direction is in the span of the old");
            break;
        }
        alpha = s_div(c, lv_dot(c, r, &AP[k]), apap[k]);
        lv_axpy(c, alpha, &P[k], x);
        lv_axpy(c, dd_neg(alpha), &AP[k], r);
        st = lis_step(c, lv_nrm2(c, r));
        if (st >= 0) break;
        st = LIS_MAXITER;
        if (s_zero(alpha)) {
            st = lis_fail(c, alpha, "(r, A p) = 0: Orthomin stagnates");
            break;
        }
        k = (k + 1) % (m + 1);
        if (have < m) have++;
    }
    lv_free_many(v, nv);
    lis_host->free(v);
    lis_host->free(apap);
    return st;
}
