/*
 * lis_kernels.h -- the double-precision kernels of plugin-lis-style: CSR
 * matrix-vector product and the BLAS-1 vector operations the Krylov solvers
 * are made of, parallel with OpenMP, real and (the _z names) complex.
 *
 * The kernels know nothing of SILC (plain arrays and an int64 CSR), so
 * bench/iterative.c compiles this file on its own to time the very kernel the
 * plugin runs.  Without OpenMP they compile to serial loops.
 */
#ifndef LIS_KERNELS_H
#define LIS_KERNELS_H

#include <complex.h>
#include <stdint.h>

/* A borrowed CSR matrix: rp[m+1], ci[nnz] (0-based, sorted per row), v[nnz]
 * (2 nnz doubles, re and im interleaved, for the complex kernels). */
typedef struct lk_csr {
    int64_t m, n;
    const int64_t *rp;
    const int64_t *ci;
    const double *v;
} lk_csr;

void lk_set_threads(int nthreads);
int lk_threads(void);

void lk_spmv(const lk_csr *A, const double *x, double *y);              /* y = A x        */
void lk_residual(const lk_csr *A, const double *b, const double *x, double *r); /* r = b - A x */
double lk_dot(int64_t n, const double *x, const double *y);
double lk_nrm2(int64_t n, const double *x);                             /* ||x||_2, scaled */
double lk_nrm2_sumsq(int64_t n, const double *x, double sumsq); /* the same, given x'x */
void lk_copy(int64_t n, const double *x, double *y);                    /* y = x          */
void lk_zero(int64_t n, double *y);
void lk_scale(int64_t n, double a, double *x);                          /* x = a x        */
void lk_axpy(int64_t n, double a, const double *x, double *y);          /* y = y + a x    */
void lk_xpay(int64_t n, const double *x, double a, double *y);          /* y = x + a y    */
void lk_waxpby(int64_t n, double a, const double *x, double b, const double *y, double *w); /* w = a x + b y */

/* Fused passes for CG-like loops: each is two or three of the above in one
 * sweep over memory, with the same arithmetic per entry. */
double lk_spmv_dot(const lk_csr *A, const double *x, double *y);        /* y = A x; x'y   */
double lk_axpy2_sumsq(int64_t n, double a, const double *p, const double *q, double *x,
                      double *r);                       /* x += a p, r -= a q; r'r */
double lk_mul_dot(int64_t n, const double *d, const double *r, double *z); /* z = d.*r; r'z */

/* The complex twins (lis_kernels_t.h), vectors of n complex entries: the
 * inner products conjugate their first operand (x^H y) except lk_dotu_z
 * (x.' y) and the fused ones with conjugate = 0.  Norms, copies and zeroing
 * are the real kernels over 2n doubles. */
void lk_spmv_z(const lk_csr *A, const double complex *x, double complex *y);
void lk_residual_z(const lk_csr *A, const double complex *b, const double complex *x, double complex *r);
double complex lk_dot_z(int64_t n, const double complex *x, const double complex *y);
double complex lk_dotu_z(int64_t n, const double complex *x, const double complex *y);
void lk_scale_z(int64_t n, double complex a, double complex *x);
void lk_axpy_z(int64_t n, double complex a, const double complex *x, double complex *y);
void lk_xpay_z(int64_t n, const double complex *x, double complex a, double complex *y);
void lk_waxpby_z(int64_t n, double complex a, const double complex *x, double complex b, const double complex *y,
                 double complex *w);
double complex lk_spmv_dot_z(const lk_csr *A, const double complex *x, double complex *y, int conjugate);
double lk_axpy2_sumsq_z(int64_t n, double complex a, const double complex *p, const double complex *q,
                        double complex *x, double complex *r);
double complex lk_mul_dot_z(int64_t n, const double complex *d, const double complex *r, double complex *z,
                            int conjugate);

#endif
