/*
 * lis_space.c -- the arithmetic the solvers are written in: vectors that are
 * double (h) or double-double (h + l) according to -f, the operator, the
 * preconditioner, and the per-iteration convergence test.
 *
 * In double mode each operation is one lis_kernels.c call; in quad mode the
 * lis_dd.c counterpart.  The preconditioner is always applied in double (as
 * Lis does): in quad mode its input is the high part of the vector and its
 * output is promoted with a zero low part.
 *
 * A complex system (c->cplx) has vectors of n complex entries, 2n doubles
 * interleaved in h (never quad): the operations on vectors alone branch on
 * the field; those with complex scalars are the lvz_* ones at the end,
 * one call each into lis_kernels_t.h's complex instance.
 */
#include "lis.h"

#include <stdio.h>
#include <string.h>

static double *alloc_zero(int64_t n)
{
    return lis_host->calloc(n > 0 ? (size_t)n : 1, sizeof(double));
}

/* Doubles in a vector's h. */
static int64_t doubles(const lis_ctx *c)
{
    return c->cplx ? 2 * c->n : c->n;
}

int lv_new(lis_ctx *c, lis_vec *v)
{
    v->h = alloc_zero(doubles(c));
    v->l = c->quad ? alloc_zero(c->n) : NULL;
    if (!v->h || (c->quad && !v->l)) {
        lv_free(v);
        return LIS_NOMEM;
    }
    return 0;
}

void lv_free(lis_vec *v)
{
    if (v->h) lis_host->free(v->h);
    if (v->l) lis_host->free(v->l);
    v->h = v->l = NULL;
}

int lv_new_many(lis_ctx *c, lis_vec *v, int count)
{
    int i;
    for (i = 0; i < count; i++) v[i].h = v[i].l = NULL;
    for (i = 0; i < count; i++)
        if (lv_new(c, &v[i])) {
            lv_free_many(v, count);
            return LIS_NOMEM;
        }
    return 0;
}

void lv_free_many(lis_vec *v, int count)
{
    int i;
    for (i = 0; i < count; i++) lv_free(&v[i]);
}

void lv_copy(const lis_ctx *c, const lis_vec *x, lis_vec *y)
{
    lk_copy(doubles(c), x->h, y->h);
    if (c->quad) lk_copy(c->n, x->l, y->l);
}

void lv_zero(const lis_ctx *c, lis_vec *y)
{
    lk_zero(doubles(c), y->h);
    if (c->quad) lk_zero(c->n, y->l);
}

void lv_scale(const lis_ctx *c, dd a, lis_vec *x)
{
    if (c->quad) ldd_scale(c->n, a, x->h, x->l);
    else lk_scale(c->n, a.hi, x->h);
}

void lv_axpy(const lis_ctx *c, dd a, const lis_vec *x, lis_vec *y)
{
    if (c->quad) ldd_axpy(c->n, a, x->h, x->l, y->h, y->l);
    else lk_axpy(c->n, a.hi, x->h, y->h);
}

void lv_xpay(const lis_ctx *c, const lis_vec *x, dd a, lis_vec *y)
{
    if (c->quad) ldd_xpay(c->n, x->h, x->l, a, y->h, y->l);
    else lk_xpay(c->n, x->h, a.hi, y->h);
}

void lv_waxpby(const lis_ctx *c, dd a, const lis_vec *x, dd b, const lis_vec *y, lis_vec *w)
{
    if (c->quad) ldd_waxpby(c->n, a, x->h, x->l, b, y->h, y->l, w->h, w->l);
    else lk_waxpby(c->n, a.hi, x->h, b.hi, y->h, w->h);
}

dd lv_dot(const lis_ctx *c, const lis_vec *x, const lis_vec *y)
{
    if (c->quad) return ldd_dot(c->n, x->h, x->l, y->h, y->l);
    return dd_d(lk_dot(c->n, x->h, y->h));
}

/* Scaled in double (lk_nrm2); in double-double, the high parts' scaled norm
 * stands in when the sum of squares leaves the safe range. */
dd lv_nrm2(const lis_ctx *c, const lis_vec *x)
{
    dd s;
    if (!c->quad) return dd_d(lk_nrm2(doubles(c), x->h)); /* complex: sqrt(sum |re|^2 + |im|^2) */
    s = lv_dot(c, x, x);
    if (s.hi >= 1e-290 && s.hi <= 1e290) return s_sqrt(c, s);
    return dd_d(lk_nrm2(c->n, x->h));
}

/* The interleaved doubles of a complex vector as its entries. */
#define Z(v) ((double complex *)(v)->h)
#define CZ(v) ((const double complex *)(v)->h)

void lv_matvec(const lis_ctx *c, const lis_vec *x, lis_vec *y)
{
    if (c->cplx) lk_spmv_z(c->A, CZ(x), Z(y));
    else if (c->quad) ldd_spmv(c->A, x->h, x->l, y->h, y->l);
    else lk_spmv(c->A, x->h, y->h);
}

/* The fused forms of the three CG phases (lis_kernels.c says why); in
 * double-double they are the separate operations. */
dd lv_matvec_dot(const lis_ctx *c, const lis_vec *x, lis_vec *y)
{
    if (c->quad) {
        lv_matvec(c, x, y);
        return lv_dot(c, x, y);
    }
    return dd_d(lk_spmv_dot(c->A, x->h, y->h));
}

dd lv_axpy2_nrm2(const lis_ctx *c, dd a, const lis_vec *p, const lis_vec *q, lis_vec *x, lis_vec *r)
{
    if (c->quad) {
        lv_axpy(c, a, p, x);
        lv_axpy(c, dd_neg(a), q, r);
        return lv_nrm2(c, r);
    }
    return dd_d(lk_nrm2_sumsq(c->n, r->h, lk_axpy2_sumsq(c->n, a.hi, p->h, q->h, x->h, r->h)));
}

dd lv_psolve_dot(lis_ctx *c, const lis_vec *r, lis_vec *z)
{
    if (!c->quad && c->pc && c->pc->kind == LIS_PC_JACOBI) return dd_d(lk_mul_dot(c->n, c->pc->dinv, r->h, z->h));
    lv_psolve(c, r, z);
    return lv_dot(c, r, z);
}

void lv_matvec_t(const lis_ctx *c, const lis_vec *x, lis_vec *y)
{
    if (c->quad) ldd_spmv(c->At, x->h, x->l, y->h, y->l);
    else lk_spmv(c->At, x->h, y->h);
}

void lv_residual(const lis_ctx *c, const lis_vec *x, lis_vec *r)
{
    if (c->cplx) lk_residual_z(c->A, CZ(&c->b), CZ(x), Z(r));
    else if (c->quad) ldd_residual(c->A, c->b.h, c->b.l, x->h, x->l, r->h, r->l);
    else lk_residual(c->A, c->b.h, x->h, r->h);
}

static void psolve(lis_ctx *c, const lis_vec *x, lis_vec *y, int trans)
{
    if (!c->pc) {
        lv_copy(c, x, y);
        return;
    }
    if (!c->quad) {
        if (trans) lis_pc_apply_t(c->pc, x->h, y->h);
        else lis_pc_apply(c->pc, x->h, y->h);
        return;
    }
    /* Quad: precondition the double rounding of x (its high part). */
    if (trans) lis_pc_apply_t(c->pc, x->h, c->w1);
    else lis_pc_apply(c->pc, x->h, c->w1);
    lk_copy(c->n, c->w1, y->h);
    lk_zero(c->n, y->l);
}

void lv_psolve(lis_ctx *c, const lis_vec *x, lis_vec *y)
{
    psolve(c, x, y, 0);
}

void lv_psolve_t(lis_ctx *c, const lis_vec *x, lis_vec *y)
{
    psolve(c, x, y, 1);
}

/* The iteration limit, or a request to stop (an interrupt, silcd's time
 * limit: host->cancelled, ABI 1.7), asked once an iteration: the solver
 * then ends as at -maxiter, and the host reports why it stopped. */
/* ---- complex scalars -------------------------------------------------------- */

double complex lvz_dot(const lis_ctx *c, const lis_vec *x, const lis_vec *y)
{
    return lk_dot_z(c->n, CZ(x), CZ(y));
}

void lvz_scale(const lis_ctx *c, double complex a, lis_vec *x)
{
    lk_scale_z(c->n, a, Z(x));
}

void lvz_axpy(const lis_ctx *c, double complex a, const lis_vec *x, lis_vec *y)
{
    lk_axpy_z(c->n, a, CZ(x), Z(y));
}

void lvz_xpay(const lis_ctx *c, const lis_vec *x, double complex a, lis_vec *y)
{
    lk_xpay_z(c->n, CZ(x), a, Z(y));
}

void lvz_waxpby(const lis_ctx *c, double complex a, const lis_vec *x, double complex b, const lis_vec *y,
                lis_vec *w)
{
    lk_waxpby_z(c->n, a, CZ(x), b, CZ(y), Z(w));
}

double complex lvz_matvec_dot(const lis_ctx *c, const lis_vec *x, lis_vec *y, int hermitian)
{
    return lk_spmv_dot_z(c->A, CZ(x), Z(y), hermitian);
}

dd lvz_axpy2_nrm2(const lis_ctx *c, double complex a, const lis_vec *p, const lis_vec *q, lis_vec *x, lis_vec *r)
{
    return dd_d(lk_nrm2_sumsq(2 * c->n, r->h, lk_axpy2_sumsq_z(c->n, a, CZ(p), CZ(q), Z(x), Z(r))));
}

double complex lvz_psolve_dot(lis_ctx *c, const lis_vec *r, lis_vec *z, int hermitian)
{
    if (c->pc && c->pc->kind == LIS_PC_JACOBI)
        return lk_mul_dot_z(c->n, (const double complex *)c->pc->dinv, CZ(r), Z(z), hermitian);
    lv_psolve(c, r, z);
    return hermitian ? lk_dot_z(c->n, CZ(r), CZ(z)) : lk_dotu_z(c->n, CZ(r), CZ(z));
}

int lis_limit(const lis_ctx *c)
{
    if (c->iter >= c->o->maxiter) return 1;
    return c->call && lis_host->struct_size >= SILC_HOST_NEEDS(cancelled) && lis_host->cancelled(c->call);
}

int lis_check(lis_ctx *c, dd rnorm)
{
    c->resid = rnorm.hi / c->den;
    /* -print out is an explicit request: log at a level that always shows. */
    if (c->o->print)
        lis_host->log(1, "lis-style %s: iteration %lld relative residual %.6e (-print out)", c->label,
                      (long long)c->iter, c->resid);
    if (c->resid != c->resid) return LIS_NAN;
    if (c->resid <= c->o->tol) return LIS_CONVERGED;
    return -1;
}

int lis_step(lis_ctx *c, dd rnorm)
{
    c->iter++;
    return lis_check(c, rnorm);
}

int lis_fail(lis_ctx *c, dd v, const char *why)
{
    if (v.hi != v.hi) {
        c->iter++; /* the iteration that produced it */
        return LIS_NAN;
    }
    return lis_breakdown(c, why);
}

int lis_breakdown(lis_ctx *c, const char *why)
{
    snprintf(c->why, sizeof c->why, "%s", why);
    return LIS_BREAKDOWN;
}

double lis_true_resid(lis_ctx *c, const lis_vec *x, lis_vec *work)
{
    lv_residual(c, x, work);
    return lv_nrm2(c, work).hi / c->den;
}
