/*
 * lis_kernels.c -- CSR SpMV and vector kernels in double precision, each a
 * `#pragma omp parallel for` over rows or entries.
 *
 * Static scheduling with the same row split in every kernel keeps each
 * thread on the same part of every vector (first-touch locality); a 2-D
 * Laplacian has equal work per row, so static is also balanced.  Loops below
 * a few thousand entries stay serial, because a fork costs more than the
 * work.  Dot products reduce with OpenMP's reduction clause, so their
 * rounding differs between thread counts in the last bits only.
 *
 * A loop that runs on one thread -- short, or the budget is one thread --
 * runs as a plain loop, not as a parallel region of one: even that region
 * is a call into libgomp and an outlined function per kernel, and a CG
 * iteration calls six kernels.  On the 3072-unknown cloth that was a third
 * of CG's time (docs/cloth.md).  One thread's reduction adds in the same
 * order as the plain loop, so the bits do not change.
 */
#include "lis_kernels.h"

#include <math.h>

#ifdef _OPENMP
#include <omp.h>
#endif

/* Below this many entries a loop is not worth a parallel region. */
#define LK_PAR_MIN 4096

static int lk_serial(int64_t n)
{
#ifdef _OPENMP
    return n <= LK_PAR_MIN || omp_get_max_threads() == 1;
#else
    (void)n;
    return 1;
#endif
}

/* for (i = 0; i < n; i++) BODY, in parallel only when worth it. */
#define LK_FOR(n, i, BODY)                                                                         \
    do {                                                                                           \
        if (lk_serial(n)) {                                                                        \
            for (i = 0; i < (n); i++) { BODY; }                                                    \
        } else {                                                                                   \
            _Pragma("omp parallel for schedule(static)") for (i = 0; i < (n); i++) { BODY; }      \
        }                                                                                          \
    } while (0)

/* for (i = 0; i < n; i++) STEP, a reduction: in parallel (OPCLAUSE, the
 * pragma's text with its reduction clause) only when worth it. */
#define LK_REDUCE(n, i, OPCLAUSE, STEP)                                                         \
    do {                                                                                           \
        if (lk_serial(n)) {                                                                        \
            for (i = 0; i < (n); i++) { STEP; }                                                    \
        } else {                                                                                   \
            _Pragma(OPCLAUSE) for (i = 0; i < (n); i++) { STEP; }                                 \
        }                                                                                          \
    } while (0)

void lk_set_threads(int nthreads)
{
#ifdef _OPENMP
    if (nthreads > 0) omp_set_num_threads(nthreads);
#else
    (void)nthreads;
#endif
}

int lk_threads(void)
{
#ifdef _OPENMP
    return omp_get_max_threads();
#else
    return 1;
#endif
}

void lk_spmv(const lk_csr *A, const double *x, double *y)
{
    const int64_t *rp = A->rp, *ci = A->ci;
    const double *v = A->v;
    int64_t i, m = A->m;
    LK_FOR(m, i, double s = 0.0; for (int64_t k = rp[i]; k < rp[i + 1]; k++) s += v[k] * x[ci[k]];
           y[i] = s);
}

void lk_residual(const lk_csr *A, const double *b, const double *x, double *r)
{
    const int64_t *rp = A->rp, *ci = A->ci;
    const double *v = A->v;
    int64_t i, m = A->m;
    LK_FOR(m, i, double s = b[i]; for (int64_t k = rp[i]; k < rp[i + 1]; k++) s -= v[k] * x[ci[k]];
           r[i] = s);
}

double lk_dot(int64_t n, const double *x, const double *y)
{
    double s = 0.0;
    int64_t i;
    LK_REDUCE(n, i, "omp parallel for schedule(static) reduction(+ : s)", s += x[i] * y[i]);
    return s;
}

/* ||x||_2 that neither overflows nor underflows (as LAPACK's dnrm2).  The
 * plain sum of squares is exact enough whenever it lands in [1e-290, 1e290]:
 * squares that underflowed were then below 1e-18 of it.  Outside that range
 * (entries beyond 1e145 or below 1e-145) the entries are scaled by a power
 * of two that brings the largest near 1, which rounds nothing. */
double lk_nrm2(int64_t n, const double *x)
{
    return lk_nrm2_sumsq(n, x, lk_dot(n, x, x));
}

double lk_nrm2_sumsq(int64_t n, const double *x, double s)
{
    double mx = 0;
    int64_t i;
    int e;
    if (s >= 1e-290 && s <= 1e290) return sqrt(s);
    if (s != s) return s;
    LK_REDUCE(n, i, "omp parallel for schedule(static) reduction(max : mx)", mx = fmax(mx, fabs(x[i])));
    if (mx == 0 || isinf(mx)) return mx;
    frexp(mx, &e);
    s = 0;
    LK_REDUCE(n, i, "omp parallel for schedule(static) reduction(+ : s)", double t = ldexp(x[i], -e);
              s += t * t);
    return ldexp(sqrt(s), e);
}

void lk_copy(int64_t n, const double *x, double *y)
{
    int64_t i;
    LK_FOR(n, i, y[i] = x[i]);
}

void lk_zero(int64_t n, double *y)
{
    int64_t i;
    LK_FOR(n, i, y[i] = 0.0);
}

void lk_scale(int64_t n, double a, double *x)
{
    int64_t i;
    LK_FOR(n, i, x[i] *= a);
}

void lk_axpy(int64_t n, double a, const double *x, double *y)
{
    int64_t i;
    LK_FOR(n, i, y[i] += a * x[i]);
}

void lk_xpay(int64_t n, const double *x, double a, double *y)
{
    int64_t i;
    LK_FOR(n, i, y[i] = x[i] + a * y[i]);
}

void lk_waxpby(int64_t n, double a, const double *x, double b, const double *y, double *w)
{
    int64_t i;
    LK_FOR(n, i, w[i] = a * x[i] + b * y[i]);
}

/* The fused kernels.  A CG iteration with Jacobi made of the single
 * kernels above sweeps its vectors eight times; these make it four, which
 * is what a hand-written CG does (docs/cloth.md measured the difference on
 * the cloth: 1.3x). */
double lk_spmv_dot(const lk_csr *A, const double *x, double *y)
{
    const int64_t *rp = A->rp, *ci = A->ci;
    const double *v = A->v;
    int64_t i, m = A->m;
    double d = 0.0;
    LK_REDUCE(m, i, "omp parallel for schedule(static) reduction(+ : d)", double s = 0.0;
              for (int64_t k = rp[i]; k < rp[i + 1]; k++) s += v[k] * x[ci[k]];
              y[i] = s; d += x[i] * s);
    return d;
}

double lk_axpy2_sumsq(int64_t n, double a, const double *p, const double *q, double *x, double *r)
{
    double s = 0.0;
    int64_t i;
    LK_REDUCE(n, i, "omp parallel for schedule(static) reduction(+ : s)", x[i] += a * p[i];
              r[i] -= a * q[i]; s += r[i] * r[i]);
    return s;
}

double lk_mul_dot(int64_t n, const double *d, const double *r, double *z)
{
    double s = 0.0;
    int64_t i;
    LK_REDUCE(n, i, "omp parallel for schedule(static) reduction(+ : s)", z[i] = d[i] * r[i];
              s += r[i] * z[i]);
    return s;
}
