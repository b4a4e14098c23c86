/*
 * lis_kernels.c -- CSR SpMV and vector kernels in double precision, real
 * and complex, each a `#pragma omp parallel for` over rows or entries.  The
 * kernels whose arithmetic depends on the field are written once, in
 * lis_kernels_t.h, and included here twice; the norm, copy and zero work on
 * doubles alone and serve a complex vector as 2n doubles.
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

/* The kernels whose arithmetic depends on the field, once real, once complex. */
#include <complex.h>
#undef LK_COMPLEX
#include "lis_kernels_t.h"
#define LK_COMPLEX
#include "lis_kernels_t.h"
#undef LK_COMPLEX
