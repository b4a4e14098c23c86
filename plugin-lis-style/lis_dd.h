/*
 * lis_dd.h -- double-double arithmetic for `-f quad`: a number is the
 * unevaluated sum hi + lo of two doubles with |lo| <= ulp(hi)/2, about 32
 * significant digits.
 *
 * The building blocks are the error-free transformations: Knuth's two-sum
 * (a + b = s + e exactly) and two-prod (a * b = p + e exactly, by one fused
 * multiply-add when the machine has one, else by Dekker's splitting, which is
 * exact without it).  On them sit the scalar operations (inline here) and the
 * vector kernels (lis_dd.c) used when the solver's vectors are double-double:
 * SpMV with a double matrix and double-double x accumulated in double-double,
 * dot products, axpy-type updates.
 */
#ifndef LIS_DD_H
#define LIS_DD_H

#include <math.h>
#include <stdint.h>

#include "lis_kernels.h"

typedef struct dd {
    double hi, lo;
} dd;

static inline dd dd_d(double a)
{
    dd r = {a, 0.0};
    return r;
}

/* s + e = a + b exactly (Knuth). */
static inline dd dd_two_sum(double a, double b)
{
    dd r;
    double bb;
    r.hi = a + b;
    bb = r.hi - a;
    r.lo = (a - (r.hi - bb)) + (b - bb);
    return r;
}

/* s + e = a + b exactly, given |a| >= |b| (Dekker). */
static inline dd dd_quick_two_sum(double a, double b)
{
    dd r;
    r.hi = a + b;
    r.lo = b - (r.hi - a);
    return r;
}

/* p + e = a * b exactly. */
static inline dd dd_two_prod(double a, double b)
{
    dd r;
    r.hi = a * b;
#ifdef FP_FAST_FMA
    r.lo = fma(a, b, -r.hi);
#else
    {   /* Dekker's product: split each factor into two 26-bit halves. */
        const double split = 134217729.0; /* 2^27 + 1 */
        double t = split * a, ah = t - (t - a), al = a - ah;
        double u = split * b, bh = u - (u - b), bl = b - bh;
        r.lo = ((ah * bh - r.hi) + ah * bl + al * bh) + al * bl;
    }
#endif
    return r;
}

static inline dd dd_add(dd a, dd b)
{
    dd s = dd_two_sum(a.hi, b.hi), t = dd_two_sum(a.lo, b.lo);
    s.lo += t.hi;
    s = dd_quick_two_sum(s.hi, s.lo);
    s.lo += t.lo;
    return dd_quick_two_sum(s.hi, s.lo);
}

static inline dd dd_neg(dd a)
{
    dd r = {-a.hi, -a.lo};
    return r;
}

static inline dd dd_sub(dd a, dd b)
{
    return dd_add(a, dd_neg(b));
}

static inline dd dd_mul(dd a, dd b)
{
    dd p = dd_two_prod(a.hi, b.hi);
    p.lo += a.hi * b.lo + a.lo * b.hi;
    return dd_quick_two_sum(p.hi, p.lo);
}

static inline dd dd_mul_d(dd a, double b)
{
    dd p = dd_two_prod(a.hi, b);
    p.lo += a.lo * b;
    return dd_quick_two_sum(p.hi, p.lo);
}

/* Long division: three quotient digits, each correcting the remainder. */
static inline dd dd_div(dd a, dd b)
{
    double q1 = a.hi / b.hi, q2, q3;
    dd r = dd_sub(a, dd_mul_d(b, q1));
    q2 = r.hi / b.hi;
    r = dd_sub(r, dd_mul_d(b, q2));
    q3 = r.hi / b.hi;
    r = dd_quick_two_sum(q1, q2);
    return dd_add(r, dd_d(q3));
}

/* Karp's trick: one Newton step on the double square root. */
static inline dd dd_sqrt(dd a)
{
    double x, ax;
    dd e;
    if (!(a.hi > 0)) return dd_d(sqrt(a.hi)); /* 0, or NaN for negatives and NaN */
    x = 1.0 / sqrt(a.hi);
    ax = a.hi * x;
    e = dd_sub(a, dd_two_prod(ax, ax));
    return dd_two_sum(ax, e.hi * (x * 0.5));
}

/* Vectors are pairs of arrays (h, l). */
void ldd_spmv(const lk_csr *A, const double *xh, const double *xl, double *yh, double *yl);
void ldd_residual(const lk_csr *A, const double *bh, const double *bl, const double *xh,
                  const double *xl, double *rh, double *rl);
dd ldd_dot(int64_t n, const double *xh, const double *xl, const double *yh, const double *yl);
void ldd_axpy(int64_t n, dd a, const double *xh, const double *xl, double *yh, double *yl);
void ldd_xpay(int64_t n, const double *xh, const double *xl, dd a, double *yh, double *yl);
void ldd_waxpby(int64_t n, dd a, const double *xh, const double *xl, dd b, const double *yh,
                const double *yl, double *wh, double *wl);
void ldd_scale(int64_t n, dd a, double *xh, double *xl);

#endif
