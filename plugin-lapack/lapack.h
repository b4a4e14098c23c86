/*
 * lapack.h -- internal interface of the lapack plugin (dense and band
 * operations on OpenBLAS + LAPACKE).
 *
 * Every direct solve of the plugin produces one lp_factor: the LAPACK factors
 * of A (LU, Cholesky, LDL', band and tridiagonal variants, QR / LQ) together
 * with the reciprocal condition number LAPACK estimated for them.  The solve
 * driver hangs it on A as an attachment, so a time loop `u = A \ b` factors
 * once, and applies it to a dense copy of the right-hand sides.
 *
 *   lapack.c        tables, init, accepts, threads, MATMUL, the SOLVE driver
 *   lapack_dense.c  square dense: dgetrf, dpotrf, dsytrf, dtrtrs; and
 *                   least squares: dgeqrf / dgelqf, dgelsy when rank deficient
 *   lapack_band.c   band: dgbtrf, dpbtrf; tridiagonal: dgttrf, dpttrf
 *
 * LAPACK indices are 32-bit (lapack_int); accepts() refuses larger operands.
 *
 * Complex values (ABI 1.8, interleaved re/im: LAPACK's complex*16) take the
 * same paths with the z routines: a factor made from a complex A has cplx
 * set, its a holds 2 doubles per entry, and every factor and solve function
 * below calls the z routine where it would call the d one (zgetrf, zpotrf
 * for a Hermitian A, zsytrf for a complex symmetric one, ztrtrs, zgbtrf,
 * zgeqrf / zgelqf with zunmqr / zunmlq, zgelsy).  The condition estimates
 * are LAPACK's own (zgecon, zpocon, zsycon, ztrcon; zlacn2 for band).  The
 * mixed-precision path stays real.
 */
#ifndef LAPACK_PLUGIN_H
#define LAPACK_PLUGIN_H

#include "silc_plugin.h"

#include <complex.h>
#include <lapacke.h>

extern const silc_host_api *lp_host;

enum lp_kind {
    LP_LU,    /* dgetrf: a = L\U (n x n), ipiv */
    LP_CHOL,  /* dpotrf: a = L (lower); bad > 0 remembers a failure */
    LP_LDLT,  /* dsytrf: a = L, D (lower), ipiv (complex: zsytrf, A = A.', not Hermitian) */
    LP_TRI,   /* triangular: no factor, only the dtrcon estimate (A itself is the factor) */
    LP_GB,    /* dgbtrf: a = band LU, ld = 2 kl + ku + 1, ipiv */
    LP_PB,    /* dpbtrf: a = upper band Cholesky, ld = ku + 1 */
    LP_GT,    /* dgttrf: a = dl | d | du | du2 (n each), ipiv */
    LP_PT,    /* dpttrf: a = d | e (n each) */
    LP_QR,    /* dgeqrf, m >= n: a = R and Householder vectors (m x n), tau */
    LP_LQ,    /* dgelqf, m < n:  a = L and Householder vectors (m x n), tau */
    LP_LSY    /* rank deficient: every solve runs dgelsy on a copy of A */
};

typedef struct lp_factor {
    int kind;                /* enum lp_kind */
    int cplx;                /* complex factors (z routines, 2 doubles per entry in a, tau) */
    lapack_int m, n;         /* shape of A */
    lapack_int kl, ku;       /* band widths (GB, PB) */
    lapack_int ld;           /* leading dimension of a */
    char uplo;               /* LP_TRI: 'L' or 'U' */
    double *a;               /* the factors */
    double *tau;             /* LP_QR, LP_LQ */
    lapack_int *ipiv;
    double rcond;            /* LAPACK's reciprocal 1-norm condition estimate, -1 = unknown */
    int rcond_owed;          /* LU, CHOL, LDLT, TRI: rcond not made yet (lp_dense_estimate) */
    lapack_int bad;          /* LP_CHOL: leading minor that was not positive (kept to skip a retry) */
    lapack_int rank;         /* LP_LSY: numerical rank found by the last dgelsy */
    double rank_tol;         /* LP_QR, LP_LQ, LP_LSY: the rank threshold it was made with */
    char method[64];
    char note[160];
} lp_factor;

/* The host's copy of the real dense operand v, made in the read of v its
 * checks did anyway (ABI 1.10, host->take_dense_copy), the caller's to
 * factor in place and lp_free; NULL when there is none (or an older host):
 * then copy v yourself. */
double *lp_take_copy(silc_call *call, const silc_value *v);
/* Memory through the host, with overflow checks.  NULL on failure. */
void *lp_alloc(size_t count, size_t size);
void lp_free(void *p);
/* A leading dimension (or count) LAPACK accepts: at least 1. */
#define LP_LD(n) ((n) > 1 ? (n) : 1)
/* Scratch for the *con estimators: nwork doubles and n integers; -1 when out
 * of memory (nothing left allocated). */
int lp_con_scratch(lapack_int n, lapack_int nwork, double **work, lapack_int **iwork);
lp_factor *lp_factor_new(int kind, lapack_int m, lapack_int n);
/* Doubles per entry: 2 for complex factors, else 1. */
#define LP_W(F) ((F)->cplx ? 2 : 1)
/* LAPACK's precision letter of F's routines, for messages ("%cgetrf"). */
#define LP_P(F) ((F)->cplx ? 'z' : 'd')
void lp_factor_free(void *F);   /* attachment destructor; NULL is fine */
int lp_nomem(silc_call *call);  /* host->error(SILC_ENOMEM, ...) */
/* A negative LAPACK info: "fn: illegal argument i (status -i)", SILC_ELIB. */
int lp_illegal(silc_call *call, const char *fn, lapack_int info);
/* The same with the precision letter p before fn ("getrf"). */
int lp_illegal_p(silc_call *call, char p, const char *fn, lapack_int info);

/* Entry A(i,j) of a dense or band view (0 outside the stored band); lp_getz
 * of a complex one. */
double lp_get(const silc_view *A, int64_t i, int64_t j);
double complex lp_getz(const silc_view *A, int64_t i, int64_t j);
/* 1 when v is a complex value (always 0 on a host older than ABI 1.8). */
int lp_is_complex(const silc_value *v);

/* Factorizations.  On success *F is a new factor; on failure the status is
 * returned after host->error (LP_CHOL: a factor with bad > 0 is still returned
 * in *F with SILC_ENOTSPD, so the driver can remember the failure).  norm1 is
 * ||A||_1 from host->props.  The dense LU, Cholesky, LDL' and triangular
 * factors come without their condition estimate (rcond_owed): the driver
 * asks lp_dense_estimate for it when the session wants one. */
int lp_dense_lu(silc_call *call, const silc_view *A, lp_factor **F);
int lp_dense_chol(silc_call *call, const silc_view *A, lp_factor **F);
int lp_dense_ldlt(silc_call *call, const silc_view *A, lp_factor **F);
int lp_dense_tri(silc_call *call, const silc_view *A, char uplo, lp_factor **F);
/* F->rcond of such a factor (A: the matrix it was made from); 0, or the
 * status after host->error when out of memory. */
int lp_dense_estimate(silc_call *call, lp_factor *F, const silc_view *A, double norm1);
int lp_dense_qr(silc_call *call, const silc_view *A, double rank_tol, lp_factor **F);
/* Band or tridiagonal LU, or their Cholesky variants when spd_first is set
 * (falling back to LU, with a note, if A is not positive definite). */
int lp_band(silc_call *call, const silc_view *A, int64_t kl, int64_t ku, int spd_first,
            double norm1, lp_factor **F);

/* X = A \ B in place: B holds the right-hand sides (ldb >= max(m, n), nrhs
 * columns) on entry and the solution in its first n rows on exit.  A is the
 * matrix F was made from (LP_TRI and LP_LSY read it). */
int lp_dense_solve(silc_call *call, lp_factor *F, const silc_view *A, double *B, lapack_int ldb,
                   lapack_int nrhs);
int lp_band_solve(silc_call *call, const lp_factor *F, double *B, lapack_int ldb, lapack_int nrhs);

#endif
