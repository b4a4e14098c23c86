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
 * -f quad), like everything else.  GMRES and FGMRES are lis_gmres_t.h,
 * included here once real and once complex.
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

#define LIS_COMPLEX
#include "lis_field.h"
#include "lis_gmres_t.h"
#undef LIS_COMPLEX
#include "lis_field.h"
#include "lis_gmres_t.h"

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
