/*
 * spqr.c -- suitesparse.spqr: sparse least squares by SuiteSparseQR.
 *
 * SuiteSparseQR_C_factorize computes A*E = Q*R, with Q kept as Householder
 * vectors and rank detection by the column-norm tolerance (spqr_tol).  The
 * factorization is an attachment of A, so each solve is
 *     Y = Q' * B                      SuiteSparseQR_C_qmult (SPQR_QTX)
 *     X = E * (R \ Y)                 SuiteSparseQR_C_solve (SPQR_RETX_EQUALS_B)
 * which is what SuiteSparseQR_C_backslash does in one call.  For m >= n of
 * full rank this is the least-squares solution.  When A is rank deficient or
 * underdetermined (m < n), R \ Y solves with the leading rank x rank block of
 * R and sets the other entries to zero: a *basic* solution (at most rank
 * nonzeros), as MATLAB's backslash gives, not the minimum-norm one.  A
 * square matrix of deficient rank is refused as singular instead, as the LU
 * backends would.
 *
 * SPQR needs A itself in compressed columns, so unlike the other backends it
 * transposes the CSR arrays (cholmod_l_transpose, O(nnz)).  All calls use the
 * plugin's cholmod_common, under the plugin lock.
 */
#include "ss.h"

#include <SuiteSparseQR_C.h>

#include <math.h>
#include <stdio.h>
#include <string.h>

#define QR_KEY "suitesparse.spqr.qr"

typedef struct qr_factor {
    SuiteSparseQR_C_factorization *QR;
    int64_t m, n, rank;
    double tol;
    double cond;        /* ||A||_1 * est ||R^-1||_1, full-rank tall/square only; -1 = none */
    char method[64];
    char note[160];
} qr_factor;

static void qr_factor_free(void *p)
{
    qr_factor *F = p;
    if (!F) return;
    ss_lock();
    if (F->QR) SuiteSparseQR_C_free(&F->QR, ss_cholmod_common());
    ss_unlock();
    ss_host->free(F);
}

int ss_spqr_accepts(const silc_call *call, const char **why)
{
    return ss_accepts_csr(call, 0, why);
}

static const char *qr_ordering_name(int64_t ordering)
{
    switch (ordering) {
    case SPQR_ORDERING_FIXED: return "natural";
    case SPQR_ORDERING_NATURAL: return "natural";
    case SPQR_ORDERING_COLAMD: return "COLAMD";
    case SPQR_ORDERING_CHOLMOD: return "AMD/COLAMD/METIS";
    case SPQR_ORDERING_AMD: return "AMD";
    case SPQR_ORDERING_METIS: return "METIS";
    default: return "given";
    }
}

static int qr_fail(silc_call *call, const char *fn, int status)
{
    int st = status == CHOLMOD_OUT_OF_MEMORY ? SILC_ENOMEM : SILC_ELIB;
    return ss_host->error(call, st, "%s: %s (status %d)", fn,
                          status == CHOLMOD_OUT_OF_MEMORY ? "out of memory"
                          : status == CHOLMOD_INVALID     ? "invalid input"
                                                          : "failed",
                          status);
}

/* R x = b or R' x = b in place, for the Hager-Higham estimate of ||R^-1||_1
 * (called under the lock, by the host's estimator). */
static int qr_apply_rinv(void *ctx, double *x, int trans)
{
    qr_factor *F = ctx;
    cholmod_common *cc = ss_cholmod_common();
    cholmod_dense *bh, *y;
    /* SPQR's R is rank x n: R \ B takes B with m rows (only the first rank
     * are read) and gives n; R' \ B takes n rows and gives m.  The estimate
     * works on the leading rank x rank block, so x has rank entries. */
    int64_t rows = trans ? F->n : F->m;
    bh = cholmod_l_zeros((size_t)rows, 1, CHOLMOD_REAL, cc);
    if (!bh) return -1;
    memcpy(bh->x, x, (size_t)F->rank * sizeof *x);
    y = SuiteSparseQR_C_solve(trans ? SPQR_RTX_EQUALS_B : SPQR_RX_EQUALS_B, F->QR, bh, cc);
    cholmod_l_free_dense(&bh, cc);
    if (!y) return -1;
    memcpy(x, y->x, (size_t)F->rank * sizeof *x);
    cholmod_l_free_dense(&y, cc);
    return 0;
}

/* Called under the lock. */
static int qr_factor_new(silc_call *call, const silc_view *a, double tol, qr_factor **out)
{
    cholmod_common *cc = ss_cholmod_common();
    cholmod_sparse At, *A;
    qr_factor *F;
    int status;
    *out = NULL;
    F = ss_host->calloc(1, sizeof *F);
    if (!F) return ss_nomem(call, "SPQR factor");
    /* The CSR arrays are A' in compressed columns; SPQR wants A. */
    memset(&At, 0, sizeof At);
    At.nrow = (size_t)a->n;
    At.ncol = (size_t)a->m;
    At.nzmax = (size_t)a->rowptr[a->m];
    At.p = a->rowptr;
    At.i = a->colind;
    At.x = a->val;
    At.itype = CHOLMOD_LONG;
    At.xtype = CHOLMOD_REAL;
    At.dtype = CHOLMOD_DOUBLE;
    At.sorted = 1;
    At.packed = 1;
    A = cholmod_l_transpose(&At, 1, cc);
    if (!A) {
        ss_host->free(F);
        return qr_fail(call, "cholmod_l_transpose", cc->status);
    }
    F->QR = SuiteSparseQR_C_factorize(SPQR_ORDERING_DEFAULT, tol, A, cc);
    status = cc->status;
    cholmod_l_free_sparse(&A, cc);
    if (!F->QR) {
        ss_host->free(F);
        return qr_fail(call, "SuiteSparseQR_C_factorize", status);
    }
    F->m = a->m;
    F->n = a->n;
    F->tol = tol;
    F->rank = cc->SPQR_istat[4]; /* rank estimate of the factorization */
    snprintf(F->method, sizeof F->method, "sparse QR (SuiteSparseQR, %s)",
             qr_ordering_name(cc->SPQR_istat[7]));
    /* A = Q R E' with the same singular values in R as in A, so for a tall
     * or square A of full rank ||A||_1 ||R^-1||_1 estimates cond(A) within
     * modest factors; a rank-deficient A has no finite condition number (as
     * the reference plugin reports it).  A wide A gets none: its R's leading
     * block is ordered for sparsity, not conditioning, and measures only the
     * basic solution's sensitivity (gemat1: 8.7e18 against cond 1.2e8). */
    F->cond = -1;
    if (F->rank < (F->m < F->n ? F->m : F->n)) {
        F->cond = INFINITY;
    } else if (F->rank > 0 && F->m >= F->n) {
        double inv = ss_inv_norm1(F->rank, qr_apply_rinv, F);
        if (inv >= 0) F->cond = ss_host->props(call->in[0])->norm1 * inv;
    }
    if (F->rank < (F->m < F->n ? F->m : F->n) || F->m < F->n)
        snprintf(F->note, sizeof F->note,
                 "rank %lld of %lldx%lld (tol %.3g): basic solution (at most rank nonzeros), "
                 "not minimum norm",
                 (long long)F->rank, (long long)F->m, (long long)F->n, cc->SPQR_tol_used);
    else
        snprintf(F->note, sizeof F->note, "full rank %lld of %lldx%lld (tol %.3g)%s",
                 (long long)F->rank, (long long)F->m, (long long)F->n, cc->SPQR_tol_used,
                 F->m > F->n ? ": least-squares solution" : "");
    *out = F;
    return SILC_OK;
}

int ss_spqr_solve(silc_call *call)
{
    cholmod_common *cc = ss_cholmod_common();
    silc_report *r = call->report;
    silc_view a, b;
    qr_factor *F;
    cholmod_dense Bh, *Y = NULL, *X = NULL;
    double *B, tol, t0;
    int64_t m, n, k;
    const char *fn = "SuiteSparseQR_C_qmult";
    int owned, rc, status, fresh = 0;
    ss_host->view(call->in[0], &a);
    ss_host->view(call->in[1], &b);
    if (a.format != SILC_FMT_CSR) return SILC_EDECLINE;
    m = a.m;
    n = a.n;
    k = b.n;
    if ((rc = ss_host->option_double(call, "spqr_tol", SPQR_DEFAULT_TOL, &tol))) return rc;
    if (m == 0 || n == 0 || k == 0) {
        /* Nothing to factor: the basic solution of an empty system is 0. */
        call->out = ss_host->dense_new(n, k);
        return call->out ? SILC_OK : ss_nomem(call, "SPQR result");
    }

    t0 = ss_host->now();
    F = ss_host->attach_get(call->in[0], QR_KEY);
    if (F && F->tol != tol) F = NULL; /* made for another rank tolerance */
    if (F) {
        r->reused_factor = 1;
    } else {
        ss_lock();
        rc = qr_factor_new(call, &a, tol, &F);
        ss_unlock();
        if (rc) return rc;
        fresh = 1;
    }
    if (m == n && F->rank < n) {
        /* A square system has no least-squares reading: singular, as for LU. */
        rc = ss_host->error(call, SILC_ESINGULAR,
                            "SuiteSparseQR_C_factorize: singular matrix (rank %lld < %lld)",
                            (long long)F->rank, (long long)n);
        if (fresh) qr_factor_free(F);
        return rc;
    }
    /* Outside the lock: attach_set destroys a replaced attachment, which locks. */
    if (fresh && ss_host->attach_set(call->in[0], QR_KEY, F, qr_factor_free)) {
        qr_factor_free(F);
        return ss_nomem(call, "attaching the SPQR factorization");
    }
    r->factor_seconds = ss_host->now() - t0;

    t0 = ss_host->now();
    B = ss_rhs_dense(&b, 0, &owned);
    if (!B) return ss_nomem(call, "SPQR right-hand side");
    memset(&Bh, 0, sizeof Bh);
    Bh.nrow = (size_t)m;
    Bh.ncol = (size_t)k;
    Bh.nzmax = (size_t)(m * k);
    Bh.d = (size_t)m;
    Bh.x = B;
    Bh.xtype = CHOLMOD_REAL;
    Bh.dtype = CHOLMOD_DOUBLE;
    ss_lock();
    Y = SuiteSparseQR_C_qmult(SPQR_QTX, F->QR, &Bh, cc);
    status = cc->status;
    if (Y) {
        fn = "SuiteSparseQR_C_solve";
        X = SuiteSparseQR_C_solve(SPQR_RETX_EQUALS_B, F->QR, Y, cc);
        status = cc->status;
    }
    cholmod_l_free_dense(&Y, cc);
    ss_unlock();
    if (owned) ss_host->free(B);
    if (!X) return qr_fail(call, fn, status);
    call->out = ss_dense_value(n, k, X->x, (int64_t)X->d);
    ss_lock();
    cholmod_l_free_dense(&X, cc);
    ss_unlock();
    if (!call->out) return ss_nomem(call, "SPQR result");
    r->solve_seconds = ss_host->now() - t0;
    snprintf(r->method, sizeof r->method, "%s", F->method);
    snprintf(r->note, sizeof r->note, "%s", F->note);
    r->cond_est = F->cond;
    if (F->cond > 0) r->rcond = isinf(F->cond) ? 0 : 1 / F->cond;
    return SILC_OK;
}
