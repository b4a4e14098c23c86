/*
 * lis_stationary.c -- the stationary iterations Jacobi, Gauss-Seidel and
 * SOR(omega).
 *
 * Each iteration is one sweep and then a fresh residual b - A x for the
 * convergence test (the test costs as much as the sweep, as in Lis).  The
 * sweeps update x_i += omega (b_i - sum_j a_ij x_j) / a_ii: with x_i inside
 * the sum this is the textbook SOR formula, and it keeps b - A x exact as a
 * fixed point even when 1/a_ii is rounded.  Jacobi runs in parallel; a
 * Gauss-Seidel sweep is sequential by definition.  Under -f quad x and the
 * row sums are double-double.  They take no preconditioner.
 */
#include "lis.h"

#include <stdio.h>

static double *diag_inverse(lis_ctx *c)
{
    const lk_csr *A = c->A;
    double *d = lis_host->alloc((size_t)(c->n > 0 ? c->n : 1) * sizeof(double));
    if (!d) return NULL;
    for (int64_t i = 0; i < c->n; i++) {
        double a = 0;
        for (int64_t k = A->rp[i]; k < A->rp[i + 1]; k++)
            if (A->ci[k] == i) a += A->v[k];
        if (a == 0 || !isfinite(a)) {
            char why[96];
            snprintf(why, sizeof why, "zero diagonal entry in row %lld", (long long)i + 1);
            lis_breakdown(c, why);
            lis_host->free(d);
            return NULL;
        }
        d[i] = 1.0 / a;
    }
    return d;
}

/* x += D^-1 r, all rows at once from the last residual r. */
static void jacobi_sweep(lis_ctx *c, lis_vec *x, const lis_vec *r, const double *dinv, double omega)
{
    int64_t n = c->n, i;
    (void)omega;
    if (c->quad) {
#pragma omp parallel for schedule(static) if (n > 4096)
        for (i = 0; i < n; i++) {
            dd xi = {x->h[i], x->l[i]}, ri = {r->h[i], r->l[i]};
            xi = dd_add(xi, dd_mul_d(ri, dinv[i]));
            x->h[i] = xi.hi;
            x->l[i] = xi.lo;
        }
    } else {
#pragma omp parallel for schedule(static) if (n > 4096)
        for (i = 0; i < n; i++) x->h[i] += dinv[i] * r->h[i];
    }
}

/* x_i += omega (b_i - sum_j a_ij x_j) / a_ii, row after row with the new x. */
static void sor_sweep(lis_ctx *c, lis_vec *x, const lis_vec *r, const double *dinv, double omega)
{
    const lk_csr *A = c->A;
    (void)r;
    for (int64_t i = 0; i < c->n; i++) {
        if (c->quad) {
            dd s = {c->b.h[i], c->b.l ? c->b.l[i] : 0.0}, xi;
            for (int64_t k = A->rp[i]; k < A->rp[i + 1]; k++) {
                int64_t j = A->ci[k];
                dd p = dd_two_prod(A->v[k], x->h[j]);
                p.lo += A->v[k] * x->l[j];
                s = dd_sub(s, p);
            }
            xi.hi = x->h[i];
            xi.lo = x->l[i];
            xi = dd_add(xi, dd_mul_d(s, omega * dinv[i]));
            x->h[i] = xi.hi;
            x->l[i] = xi.lo;
        } else {
            double s = c->b.h[i];
            for (int64_t k = A->rp[i]; k < A->rp[i + 1]; k++) s -= A->v[k] * x->h[A->ci[k]];
            x->h[i] += omega * dinv[i] * s;
        }
    }
}

typedef void (*sweep_fn)(lis_ctx *c, lis_vec *x, const lis_vec *r, const double *dinv, double omega);

/* The loop every stationary method shares: a sweep, then the residual for
 * the convergence test.  A sweep that reads the residual gets it from the
 * start. */
static int stationary(lis_ctx *c, lis_vec *x, sweep_fn sweep, int reads_residual, double omega)
{
    lis_vec r;
    double *dinv;
    int st = LIS_MAXITER;
    if (lv_new(c, &r)) return LIS_NOMEM;
    if (!(dinv = diag_inverse(c))) {
        lv_free(&r);
        return c->why[0] ? LIS_BREAKDOWN : LIS_NOMEM;
    }
    if (reads_residual) lv_residual(c, x, &r);
    while (!lis_limit(c)) {
        sweep(c, x, &r, dinv, omega);
        lv_residual(c, x, &r);
        st = lis_step(c, lv_nrm2(c, &r));
        if (st >= 0) break;
        st = LIS_MAXITER;
    }
    lis_host->free(dinv);
    lv_free(&r);
    return st;
}

int lis_jacobi(lis_ctx *c, lis_vec *x)
{
    return stationary(c, x, jacobi_sweep, 1, 1.0);
}

int lis_gs(lis_ctx *c, lis_vec *x)
{
    return stationary(c, x, sor_sweep, 0, 1.0);
}

int lis_sor(lis_ctx *c, lis_vec *x)
{
    return stationary(c, x, sor_sweep, 0, c->o->omega);
}
