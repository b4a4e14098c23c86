/*
 * lis_dd.c -- double-double vector kernels for `-f quad` (see lis_dd.h).
 *
 * The matrix stays double; every product a_ij * x_j is formed exactly by
 * two-prod and summed in double-double, so SpMV and dot products carry about
 * 32 digits.  That is what keeps BiCG's short recurrences from losing the
 * biorthogonality that double rounding destroys on hard non-normal matrices.
 * Reductions keep one partial sum per thread and add them in thread order,
 * so a result does not depend on which thread finishes first.
 */
#include "lis_dd.h"

#ifdef _OPENMP
#include <omp.h>
#endif

#define LDD_PAR_MIN 2048
#define LDD_MAX_THREADS 256

/* The exact product a * (xh + xl) rounded to double-double. */
static inline dd mul_dx(double a, double xh, double xl)
{
    dd p = dd_two_prod(a, xh);
    p.lo += a * xl;
    return p;
}

void ldd_spmv(const lk_csr *A, const double *xh, const double *xl, double *yh, double *yl)
{
    int64_t i, m = A->m;
#pragma omp parallel for schedule(static) if (m > LDD_PAR_MIN)
    for (i = 0; i < m; i++) {
        dd s = dd_d(0.0);
        for (int64_t k = A->rp[i]; k < A->rp[i + 1]; k++)
            s = dd_add(s, mul_dx(A->v[k], xh[A->ci[k]], xl[A->ci[k]]));
        yh[i] = s.hi;
        yl[i] = s.lo;
    }
}

void ldd_residual(const lk_csr *A, const double *bh, const double *bl, const double *xh,
                  const double *xl, double *rh, double *rl)
{
    int64_t i, m = A->m;
#pragma omp parallel for schedule(static) if (m > LDD_PAR_MIN)
    for (i = 0; i < m; i++) {
        dd s = {bh[i], bl ? bl[i] : 0.0};
        for (int64_t k = A->rp[i]; k < A->rp[i + 1]; k++)
            s = dd_sub(s, mul_dx(A->v[k], xh[A->ci[k]], xl[A->ci[k]]));
        rh[i] = s.hi;
        rl[i] = s.lo;
    }
}

dd ldd_dot(int64_t n, const double *xh, const double *xl, const double *yh, const double *yl)
{
    dd part[LDD_MAX_THREADS], s = dd_d(0.0);
    int nt = 1, t;
#pragma omp parallel if (n > LDD_PAR_MIN)
    {
        int me = 0;
        int64_t i;
        dd loc = dd_d(0.0);
#ifdef _OPENMP
        me = omp_get_thread_num();
#pragma omp single
        nt = omp_get_num_threads();
#endif
#pragma omp for schedule(static)
        for (i = 0; i < n; i++) {
            /* (xh + xl)(yh + yl) = xh yh exactly, plus the cross terms in double. */
            dd p = dd_two_prod(xh[i], yh[i]);
            p.lo += xh[i] * yl[i] + xl[i] * yh[i];
            loc = dd_add(loc, p);
        }
        if (me < LDD_MAX_THREADS) part[me] = loc;
    }
    if (nt > LDD_MAX_THREADS) nt = LDD_MAX_THREADS;
    for (t = 0; t < nt; t++) s = dd_add(s, part[t]);
    return s;
}

void ldd_axpy(int64_t n, dd a, const double *xh, const double *xl, double *yh, double *yl)
{
    int64_t i;
#pragma omp parallel for schedule(static) if (n > LDD_PAR_MIN)
    for (i = 0; i < n; i++) {
        dd x = {xh[i], xl[i]}, y = {yh[i], yl[i]};
        y = dd_add(y, dd_mul(a, x));
        yh[i] = y.hi;
        yl[i] = y.lo;
    }
}

void ldd_xpay(int64_t n, const double *xh, const double *xl, dd a, double *yh, double *yl)
{
    int64_t i;
#pragma omp parallel for schedule(static) if (n > LDD_PAR_MIN)
    for (i = 0; i < n; i++) {
        dd x = {xh[i], xl[i]}, y = {yh[i], yl[i]};
        y = dd_add(x, dd_mul(a, y));
        yh[i] = y.hi;
        yl[i] = y.lo;
    }
}

void ldd_waxpby(int64_t n, dd a, const double *xh, const double *xl, dd b, const double *yh,
                const double *yl, double *wh, double *wl)
{
    int64_t i;
#pragma omp parallel for schedule(static) if (n > LDD_PAR_MIN)
    for (i = 0; i < n; i++) {
        dd x = {xh[i], xl[i]}, y = {yh[i], yl[i]};
        dd w = dd_add(dd_mul(a, x), dd_mul(b, y));
        wh[i] = w.hi;
        wl[i] = w.lo;
    }
}

void ldd_scale(int64_t n, dd a, double *xh, double *xl)
{
    int64_t i;
#pragma omp parallel for schedule(static) if (n > LDD_PAR_MIN)
    for (i = 0; i < n; i++) {
        dd x = {xh[i], xl[i]};
        x = dd_mul(a, x);
        xh[i] = x.hi;
        xl[i] = x.lo;
    }
}
