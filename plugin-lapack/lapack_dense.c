/*
 * lapack_dense.c -- dense factorizations and solves of the lapack plugin.
 *
 * Square systems: LU with partial pivoting (dgetrf/dgetrs, dgecon), Cholesky
 * (dpotrf/dpotrs, dpocon), symmetric indefinite Bunch-Kaufman LDL'
 * (dsytrf/dsytrs, dsycon) and triangular solves (dtrtrs, dtrcon).  Rectangular
 * systems follow dgels -- QR (dgeqrf, dormqr) for m >= n, LQ (dgelqf, dormlq)
 * and a minimum-norm solution for m < n -- but keep the factors so they can be
 * reused; when the triangular factor is numerically singular A is rank
 * deficient and every solve runs dgelsy (QR with column pivoting) instead,
 * reporting the rank it found.
 *
 * The *_work LAPACKE entry points are used throughout: they call LAPACK on
 * column-major data directly, with scratch the plugin allocates through the
 * host, and skip LAPACKE's O(n^2) NaN scan (accepts() already refused
 * non-finite matrices).
 *
 * A complex A (lapack.h) takes each path with the z routine in place of the
 * d one: zgetrf / zgecon, zpotrf / zpocon (A Hermitian), zsytrf / zsycon
 * (A complex symmetric, A = A.'), ztrtrs / ztrcon, zgeqrf / zgelqf with
 * zunmqr / zunmlq ('C': Q^H) and zgelsy.  LZ() casts a factor's doubles to
 * LAPACK's complex*16, whose layout they share.
 */
#include "lapack.h"

#include <stdio.h>
#include <string.h>

#define LZ(p) ((lapack_complex_double *)(p))
/* Scratch of the z*con estimators: 2n complex work then 2n doubles rwork. */
#define LP_ZCON_DOUBLES(n) (6 * (n))

/* A new factor of kind with a copy of the dense m x n matrix A (the view
 * of call->in[0]) in F->a: the host's copy when it made one (lp_take_copy),
 * else a memcpy. */
static lp_factor *factor_with_copy(silc_call *call, int kind, const silc_view *A, int pivots)
{
    lapack_int m = (lapack_int)A->m, n = (lapack_int)A->n;
    lp_factor *F = lp_factor_new(kind, m, n);
    double *given;
    if (!F) return NULL;
    F->cplx = lp_is_complex(call->in[0]);
    F->ld = LP_LD(m);
    given = F->cplx ? NULL : lp_take_copy(call, call->in[0]);
    F->a = given ? given : lp_alloc((size_t)m * (size_t)n * (size_t)LP_W(F), sizeof(double));
    F->ipiv = pivots ? lp_alloc((size_t)LP_LD(n), sizeof(lapack_int)) : NULL;
    if (!F->a || (pivots && !F->ipiv)) {
        lp_factor_free(F);
        return NULL;
    }
    if (!given && m > 0 && n > 0)
        memcpy(F->a, A->val, (size_t)m * (size_t)n * (size_t)LP_W(F) * sizeof(double));
    return F;
}

/* Workspace size from a LAPACK query (work[0]). */
static lapack_int lwork_of(double w)
{
    return w < 1.0 ? 1 : (lapack_int)w;
}

int lp_dense_lu(silc_call *call, const silc_view *A, lp_factor **out)
{
    lp_factor *F = factor_with_copy(call, LP_LU, A, 1);
    lapack_int n = (lapack_int)A->n, info;
    char p;
    if (!F) return lp_nomem(call);
    p = LP_P(F);
    info = F->cplx ? LAPACKE_zgetrf_work(LAPACK_COL_MAJOR, n, n, LZ(F->a), F->ld, F->ipiv)
                   : LAPACKE_dgetrf_work(LAPACK_COL_MAJOR, n, n, F->a, F->ld, F->ipiv);
    if (info != 0) {
        lp_factor_free(F);
        if (info > 0)
            return lp_host->error(call, SILC_ESINGULAR,
                                  "%cgetrf: singular matrix (U(%d,%d) is exactly zero, status %d)", p,
                                  (int)info, (int)info, (int)info);
        return lp_illegal_p(call, p, "getrf", info);
    }
    F->rcond_owed = 1;
    snprintf(F->method, sizeof F->method, "LU, partial pivoting (%cgetrf)", p);
    *out = F;
    return SILC_OK;
}

int lp_dense_chol(silc_call *call, const silc_view *A, lp_factor **out)
{
    lp_factor *F = factor_with_copy(call, LP_CHOL, A, 0);
    lapack_int n = (lapack_int)A->n, info;
    char p;
    if (!F) return lp_nomem(call);
    p = LP_P(F);
    info = F->cplx ? LAPACKE_zpotrf_work(LAPACK_COL_MAJOR, 'L', n, LZ(F->a), F->ld)
                   : LAPACKE_dpotrf_work(LAPACK_COL_MAJOR, 'L', n, F->a, F->ld);
    if (info > 0) {
        /* Keep only the verdict: the driver attaches it so a repeated solve
         * with the same A goes straight to the LU fallback. */
        lp_free(F->a);
        F->a = NULL;
        F->bad = info;
        *out = F;
        return lp_host->error(call, SILC_ENOTSPD,
                              "%cpotrf: matrix is not positive definite (leading minor %d, status %d)",
                              p, (int)info, (int)info);
    }
    if (info < 0) {
        lp_factor_free(F);
        return lp_illegal_p(call, p, "potrf", info);
    }
    F->rcond_owed = 1;
    snprintf(F->method, sizeof F->method, "%s (%cpotrf)", F->cplx ? "Hermitian Cholesky" : "Cholesky", p);
    *out = F;
    return SILC_OK;
}

int lp_dense_ldlt(silc_call *call, const silc_view *A, lp_factor **out)
{
    lp_factor *F = factor_with_copy(call, LP_LDLT, A, 1);
    double q[2] = {0, 0}, *work;
    lapack_int n = (lapack_int)A->n, info, lwork;
    char p;
    if (!F) return lp_nomem(call);
    p = LP_P(F);
    /* The workspace query answers in work[0], a complex number for zsytrf. */
    info = F->cplx ? LAPACKE_zsytrf_work(LAPACK_COL_MAJOR, 'L', n, LZ(F->a), F->ld, F->ipiv, LZ(q), -1)
                   : LAPACKE_dsytrf_work(LAPACK_COL_MAJOR, 'L', n, F->a, F->ld, F->ipiv, q, -1);
    lwork = lwork_of(q[0]);
    work = lp_alloc((size_t)lwork * (size_t)LP_W(F), sizeof(double));
    if (info != 0 || !work) {
        lp_free(work);
        lp_factor_free(F);
        if (info) return lp_illegal_p(call, p, "sytrf", info);
        return lp_nomem(call);
    }
    info = F->cplx ? LAPACKE_zsytrf_work(LAPACK_COL_MAJOR, 'L', n, LZ(F->a), F->ld, F->ipiv, LZ(work), lwork)
                   : LAPACKE_dsytrf_work(LAPACK_COL_MAJOR, 'L', n, F->a, F->ld, F->ipiv, work, lwork);
    lp_free(work);
    if (info != 0) {
        lp_factor_free(F);
        if (info > 0)
            return lp_host->error(call, SILC_ESINGULAR,
                                  "%csytrf: singular matrix (D(%d,%d) is exactly zero, status %d)", p,
                                  (int)info, (int)info, (int)info);
        return lp_illegal_p(call, p, "sytrf", info);
    }
    F->rcond_owed = 1;
    snprintf(F->method, sizeof F->method, "%s LDL', Bunch-Kaufman (%csytrf)",
             F->cplx ? "complex symmetric (A = A.')" : "symmetric indefinite", p);
    *out = F;
    return SILC_OK;
}

/* A triangular A is its own factor: only the condition estimate is kept. */
int lp_dense_tri(silc_call *call, const silc_view *A, char uplo, lp_factor **out)
{
    lapack_int n = (lapack_int)A->n;
    lp_factor *F = lp_factor_new(LP_TRI, n, n);
    if (!F) return lp_nomem(call);
    F->cplx = lp_is_complex(call->in[0]);
    F->uplo = uplo;
    F->ld = LP_LD(n);
    F->rcond_owed = 1;
    snprintf(F->method, sizeof F->method, "%s triangular (%ctrtrs)", uplo == 'L' ? "lower" : "upper",
             LP_P(F));
    *out = F;
    return SILC_OK;
}

/* The condition estimate of an LU, Cholesky, LDL' or triangular factor,
 * made apart from the factorization so that accuracy.condest = off skips it:
 * it reads the factors some ten times (Hager-Higham through ?latrs), 8-13 %
 * of a dgetrf at n = 1000-3000 (bench/limit), which the solve need not pay
 * when nobody wants the number.  A factor made without it keeps it owed
 * (rcond_owed) and a later solve that wants it makes it then, from the same
 * factors, so it is the number the factorization would have given. */
int lp_dense_estimate(silc_call *call, lp_factor *F, const silc_view *A, double norm1)
{
    lapack_int n = F->n, *iwork, *ipiv = F->ipiv, info = 0;
    double *work, *rcond = &F->rcond;
    const double *a = F->kind == LP_TRI ? A->val : F->a; /* a triangular A is its own factor */
    int cx = F->cplx;
    /* ?gecon wants 4n doubles of work (the z routines 2n complex and 2n
     * doubles of rwork after them: LP_ZCON_DOUBLES), the others fewer */
    if (lp_con_scratch(n, cx ? LP_ZCON_DOUBLES(n) : 4 * n, &work, &iwork)) return lp_nomem(call);
    switch (F->kind) {
    case LP_LU:
        info = cx ? LAPACKE_zgecon_work(LAPACK_COL_MAJOR, '1', n, LZ(a), F->ld, norm1, rcond, LZ(work), work + 4 * n)
                  : LAPACKE_dgecon_work(LAPACK_COL_MAJOR, '1', n, a, F->ld, norm1, rcond, work, iwork);
        break;
    case LP_CHOL:
        info = cx ? LAPACKE_zpocon_work(LAPACK_COL_MAJOR, 'L', n, LZ(a), F->ld, norm1, rcond, LZ(work), work + 4 * n)
                  : LAPACKE_dpocon_work(LAPACK_COL_MAJOR, 'L', n, a, F->ld, norm1, rcond, work, iwork);
        break;
    case LP_LDLT:
        info = cx ? LAPACKE_zsycon_work(LAPACK_COL_MAJOR, 'L', n, LZ(a), F->ld, ipiv, norm1, rcond, LZ(work))
                  : LAPACKE_dsycon_work(LAPACK_COL_MAJOR, 'L', n, a, F->ld, ipiv, norm1, rcond, work, iwork);
        break;
    case LP_TRI:
        info = cx ? LAPACKE_ztrcon_work(LAPACK_COL_MAJOR, '1', F->uplo, 'N', n, LZ(a), F->ld, rcond, LZ(work),
                                        work + 4 * n)
                  : LAPACKE_dtrcon_work(LAPACK_COL_MAJOR, '1', F->uplo, 'N', n, a, F->ld, rcond, work, iwork);
        break;
    default: /* band and least-squares factors estimate as they factor */
        break;
    }
    if (info) F->rcond = -1;
    F->rcond_owed = 0;
    lp_free(work);
    lp_free(iwork);
    return SILC_OK;
}

/* QR (m >= n) or LQ (m < n) of A.  If the triangular factor's condition
 * estimate says A is numerically rank deficient (rcond <= rank_tol; the
 * driver's default is max(m,n) eps), the factors are dropped and solves go
 * through dgelsy with the same threshold. */
int lp_dense_qr(silc_call *call, const silc_view *A, double rank_tol, lp_factor **out)
{
    lapack_int m = (lapack_int)A->m, n = (lapack_int)A->n, k = m < n ? m : n, info, lwork;
    int tall = m >= n;
    lp_factor *F = factor_with_copy(call, tall ? LP_QR : LP_LQ, A, 0);
    double q[2] = {0, 0}, *work;
    lapack_int *iwork;
    const char *fn = tall ? "geqrf" : "gelqf";
    char p;
    int cx;
    if (!F) return lp_nomem(call);
    p = LP_P(F);
    cx = F->cplx;
    F->tau = lp_alloc((size_t)LP_LD(k) * (size_t)LP_W(F), sizeof(double));
    if (!F->tau) {
        lp_factor_free(F);
        return lp_nomem(call);
    }
    if (cx)
        info = tall ? LAPACKE_zgeqrf_work(LAPACK_COL_MAJOR, m, n, LZ(F->a), F->ld, LZ(F->tau), LZ(q), -1)
                    : LAPACKE_zgelqf_work(LAPACK_COL_MAJOR, m, n, LZ(F->a), F->ld, LZ(F->tau), LZ(q), -1);
    else
        info = tall ? LAPACKE_dgeqrf_work(LAPACK_COL_MAJOR, m, n, F->a, F->ld, F->tau, q, -1)
                    : LAPACKE_dgelqf_work(LAPACK_COL_MAJOR, m, n, F->a, F->ld, F->tau, q, -1);
    lwork = lwork_of(q[0]);
    if (lwork < 3 * k) lwork = LP_LD(3 * k); /* the same array serves ?trcon below */
    work = lp_alloc((size_t)lwork * (size_t)LP_W(F), sizeof(double));
    iwork = lp_alloc((size_t)LP_LD(k), sizeof(lapack_int));
    if (info == 0 && work && iwork) {
        if (cx)
            info = tall ? LAPACKE_zgeqrf_work(LAPACK_COL_MAJOR, m, n, LZ(F->a), F->ld, LZ(F->tau), LZ(work), lwork)
                        : LAPACKE_zgelqf_work(LAPACK_COL_MAJOR, m, n, LZ(F->a), F->ld, LZ(F->tau), LZ(work), lwork);
        else
            info = tall ? LAPACKE_dgeqrf_work(LAPACK_COL_MAJOR, m, n, F->a, F->ld, F->tau, work, lwork)
                        : LAPACKE_dgelqf_work(LAPACK_COL_MAJOR, m, n, F->a, F->ld, F->tau, work, lwork);
    }
    if (info != 0 || !work || !iwork) {
        lp_free(work);
        lp_free(iwork);
        lp_factor_free(F);
        if (info) return lp_illegal_p(call, p, fn, info);
        return lp_nomem(call);
    }
    /* ztrcon: 2k complex work (4k doubles of the 6k here) and k doubles of rwork after it */
    if (cx ? LAPACKE_ztrcon_work(LAPACK_COL_MAJOR, '1', tall ? 'U' : 'L', 'N', k, LZ(F->a), F->ld,
                                 &F->rcond, LZ(work), work + 4 * k)
           : LAPACKE_dtrcon_work(LAPACK_COL_MAJOR, '1', tall ? 'U' : 'L', 'N', k, F->a, F->ld, &F->rcond,
                                 work, iwork))
        F->rcond = -1;
    lp_free(work);
    lp_free(iwork);
    F->rank_tol = rank_tol;
    if (F->rcond >= 0 && F->rcond <= F->rank_tol) {
        /* Numerically rank deficient: a plain QR solution would be garbage. */
        double rc = F->rcond;
        lp_free(F->a);
        lp_free(F->tau);
        F->a = F->tau = NULL;
        F->kind = LP_LSY;
        F->rcond = -1;
        snprintf(F->method, sizeof F->method, "complete orthogonal, column pivoting (%cgelsy)", p);
        snprintf(F->note, sizeof F->note, "rank deficient: %c%s gave rcond %.2g <= %.2g", p, fn, rc,
                 F->rank_tol);
    } else {
        snprintf(F->method, sizeof F->method,
                 tall ? "least squares by QR (%cgeqrf, as %cgels)" : "minimum norm by LQ (%cgelqf, as %cgels)",
                 p, p);
    }
    *out = F;
    return SILC_OK;
}

/* ---- solves ------------------------------------------------------------------ */

/* Applies Q' (QR) or Q' (LQ) to B with dormqr / dormlq (zunmqr / zunmlq with
 * Q^H for complex factors). */
static int apply_q(silc_call *call, const lp_factor *F, double *B, lapack_int ldb, lapack_int nrhs)
{
    lapack_int m = F->m, n = F->n, info, lwork;
    double q[2] = {0, 0}, *work;
    int tall = F->kind == LP_QR, cx = F->cplx;
    const char *fn = cx ? (tall ? "zunmqr" : "zunmlq") : (tall ? "dormqr" : "dormlq");
    for (int pass = 0; pass < 2; pass++) { /* the workspace query, then the product */
        lwork = pass ? lwork_of(q[0]) : -1;
        work = pass ? lp_alloc((size_t)lwork * (size_t)LP_W(F), sizeof(double)) : q;
        if (!work) return lp_nomem(call);
        if (cx)
            info = tall ? LAPACKE_zunmqr_work(LAPACK_COL_MAJOR, 'L', 'C', m, nrhs, n, LZ(F->a), F->ld,
                                              LZ(F->tau), LZ(B), ldb, LZ(work), lwork)
                        : LAPACKE_zunmlq_work(LAPACK_COL_MAJOR, 'L', 'C', n, nrhs, m, LZ(F->a), F->ld,
                                              LZ(F->tau), LZ(B), ldb, LZ(work), lwork);
        else
            info = tall ? LAPACKE_dormqr_work(LAPACK_COL_MAJOR, 'L', 'T', m, nrhs, n, F->a, F->ld, F->tau,
                                              B, ldb, work, lwork)
                        : LAPACKE_dormlq_work(LAPACK_COL_MAJOR, 'L', 'T', n, nrhs, m, F->a, F->ld, F->tau,
                                              B, ldb, work, lwork);
        if (pass) lp_free(work);
        if (info) return lp_illegal(call, fn, info);
    }
    return SILC_OK;
}

static int solve_lsy(silc_call *call, lp_factor *F, const silc_view *A, double *B, lapack_int ldb,
                     lapack_int nrhs)
{
    lapack_int m = F->m, n = F->n, info, lwork, rank = 0;
    size_t w = (size_t)LP_W(F);
    double q[2] = {0, 0}, *a = lp_alloc((size_t)m * (size_t)n * w, sizeof(double)), *work = NULL;
    double *rwork = F->cplx ? lp_alloc((size_t)LP_LD(2 * n), sizeof(double)) : NULL;
    lapack_int *jpvt = lp_alloc((size_t)LP_LD(n), sizeof(lapack_int));
    int rc = SILC_OK;
    if (!a || !jpvt || (F->cplx && !rwork)) {
        lp_free(a);
        lp_free(jpvt);
        lp_free(rwork);
        return lp_nomem(call);
    }
    if (m > 0 && n > 0) memcpy(a, A->val, (size_t)m * (size_t)n * w * sizeof(double));
    memset(jpvt, 0, (size_t)LP_LD(n) * sizeof(lapack_int)); /* all columns free to move */
    info = F->cplx ? LAPACKE_zgelsy_work(LAPACK_COL_MAJOR, m, n, nrhs, LZ(a), LP_LD(m), LZ(B), ldb, jpvt,
                                         F->rank_tol, &rank, LZ(q), -1, rwork)
                   : LAPACKE_dgelsy_work(LAPACK_COL_MAJOR, m, n, nrhs, a, LP_LD(m), B, ldb, jpvt,
                                         F->rank_tol, &rank, q, -1);
    lwork = lwork_of(q[0]);
    if (info == 0 && (work = lp_alloc((size_t)lwork * w, sizeof(double))) != NULL)
        info = F->cplx ? LAPACKE_zgelsy_work(LAPACK_COL_MAJOR, m, n, nrhs, LZ(a), LP_LD(m), LZ(B), ldb, jpvt,
                                             F->rank_tol, &rank, LZ(work), lwork, rwork)
                       : LAPACKE_dgelsy_work(LAPACK_COL_MAJOR, m, n, nrhs, a, LP_LD(m), B, ldb, jpvt,
                                             F->rank_tol, &rank, work, lwork);
    if (info) rc = lp_illegal_p(call, LP_P(F), "gelsy", info);
    else if (!work) rc = lp_nomem(call);
    else {
        F->rank = rank;
        snprintf(F->note, sizeof F->note, "rank %d of %d (%cgelsy, rcond threshold %.2g)", (int)rank,
                 (int)(m < n ? m : n), LP_P(F), F->rank_tol);
    }
    lp_free(work);
    lp_free(a);
    lp_free(jpvt);
    lp_free(rwork);
    return rc;
}

/* ?trtrs on n x n triangular T (leading dimension ldt) in F's field. */
static lapack_int trtrs(const lp_factor *F, char uplo, lapack_int n, lapack_int nrhs, const double *T,
                        lapack_int ldt, double *B, lapack_int ldb)
{
    return F->cplx ? LAPACKE_ztrtrs_work(LAPACK_COL_MAJOR, uplo, 'N', 'N', n, nrhs, LZ(T), ldt, LZ(B), ldb)
                   : LAPACKE_dtrtrs_work(LAPACK_COL_MAJOR, uplo, 'N', 'N', n, nrhs, T, ldt, B, ldb);
}

int lp_dense_solve(silc_call *call, lp_factor *F, const silc_view *A, double *B, lapack_int ldb,
                   lapack_int nrhs)
{
    lapack_int n = F->n, info = 0;
    const char *fn = "";
    int rc, cx = F->cplx;
    char p = LP_P(F);
    switch (F->kind) {
    case LP_LU:
        fn = "getrs";
        info = cx ? LAPACKE_zgetrs_work(LAPACK_COL_MAJOR, 'N', n, nrhs, LZ(F->a), F->ld, F->ipiv, LZ(B), ldb)
                  : LAPACKE_dgetrs_work(LAPACK_COL_MAJOR, 'N', n, nrhs, F->a, F->ld, F->ipiv, B, ldb);
        break;
    case LP_CHOL:
        fn = "potrs";
        info = cx ? LAPACKE_zpotrs_work(LAPACK_COL_MAJOR, 'L', n, nrhs, LZ(F->a), F->ld, LZ(B), ldb)
                  : LAPACKE_dpotrs_work(LAPACK_COL_MAJOR, 'L', n, nrhs, F->a, F->ld, B, ldb);
        break;
    case LP_LDLT:
        fn = "sytrs";
        info = cx ? LAPACKE_zsytrs_work(LAPACK_COL_MAJOR, 'L', n, nrhs, LZ(F->a), F->ld, F->ipiv, LZ(B), ldb)
                  : LAPACKE_dsytrs_work(LAPACK_COL_MAJOR, 'L', n, nrhs, F->a, F->ld, F->ipiv, B, ldb);
        break;
    case LP_TRI:
        info = trtrs(F, F->uplo, n, nrhs, A->val, F->ld, B, ldb);
        if (info > 0)
            return lp_host->error(call, SILC_ESINGULAR,
                                  "%ctrtrs: singular matrix (A(%d,%d) is exactly zero, status %d)", p,
                                  (int)info, (int)info, (int)info);
        fn = "trtrs";
        break;
    case LP_QR:
        if ((rc = apply_q(call, F, B, ldb, nrhs))) return rc;
        fn = "trtrs";
        info = trtrs(F, 'U', n, nrhs, F->a, F->ld, B, ldb);
        break;
    case LP_LQ: {
        lapack_int m = F->m, j;
        info = trtrs(F, 'L', m, nrhs, F->a, F->ld, B, ldb);
        if (info) {
            fn = "trtrs";
            break;
        }
        for (j = 0; j < nrhs; j++)
            memset(B + ((size_t)j * ldb + m) * LP_W(F), 0, (size_t)(n - m) * LP_W(F) * sizeof(double));
        return apply_q(call, F, B, ldb, nrhs);
    }
    case LP_LSY:
        return solve_lsy(call, F, A, B, ldb, nrhs);
    default:
        return lp_host->error(call, SILC_EINTERNAL, "lapack: unknown dense factor kind %d", F->kind);
    }
    if (info > 0)
        return lp_host->error(call, SILC_ESINGULAR,
                              "%c%s: singular triangular factor (diagonal %d is zero, status %d)", p, fn,
                              (int)info, (int)info);
    if (info < 0)
        return lp_illegal_p(call, p, fn, info);
    return SILC_OK;
}
