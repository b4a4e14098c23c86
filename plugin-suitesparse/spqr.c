/*
 * spqr.c -- suitesparse.spqr: sparse least squares by SuiteSparseQR.
 *
 * Tall or square A (m >= n): SuiteSparseQR_C_factorize computes A*E = Q*R,
 * with Q kept as Householder vectors and rank detection by the column-norm
 * tolerance (spqr_tol), and each solve is
 *     Y = Q' * B                      SuiteSparseQR_C_qmult (SPQR_QTX)
 *     X = E * (R \ Y)                 SuiteSparseQR_C_solve (SPQR_RETX_EQUALS_B)
 * which is what SuiteSparseQR_C_backslash does in one call: for full rank the
 * least-squares solution.  When a tall A is rank deficient, R \ Y solves with
 * the leading rank x rank block of R and sets the other entries to zero: a
 * *basic* solution (at most rank nonzeros), as MATLAB's backslash gives.  A
 * square matrix of deficient rank is refused as singular, as the LU backends
 * would.
 *
 * Wide A (m < n) is factored transposed, A'*E = Q*R, which is what the CSR
 * arrays already are (A' in compressed columns: no transpose).  Then
 * A = E R' Q', and for full row rank the minimum-norm solution is
 *     Y = R' \ (E' * B)               SuiteSparseQR_C_solve (SPQR_RTX_EQUALS_ETB)
 *     X = Q * Y                       SuiteSparseQR_C_qmult (SPQR_QX)
 * -- the same solution as the reference and LAPACK's dgels, and R has A's
 * singular values, so its condition estimate means what it says.  A wide A of
 * deficient row rank has no such formula: it is factored again as A*E = Q*R
 * and gets the basic solution, with an infinite condition number.
 *
 * SPQR needs the factored matrix in compressed columns, so a tall A is
 * transposed (cholmod_l_transpose, O(nnz)).  All calls use the plugin's
 * cholmod_common, under the plugin lock.
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
    int transposed;     /* QR of A' (wide A of full row rank): minimum-norm solves */
    double tol;
    ss_factor_info info; /* cond: ||A|| * est ||R^-1||_1 for full rank, Inf if deficient */
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
    /* For the factored p x q matrix SPQR's R is rank x q: R \ B takes B with p
     * rows (only the first rank are read) and gives q; R' \ B takes q rows
     * and gives p.  The estimate works on the leading rank x rank block, so
     * x has rank entries. */
    int64_t p = F->transposed ? F->n : F->m, q = F->transposed ? F->m : F->n;
    int64_t rows = trans ? q : p;
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

/* QR of A (transposed = 0: cholmod_l_transpose of the CSR arrays) or of A'
 * (the CSR arrays as they are).  NULL with *status on failure. */
static SuiteSparseQR_C_factorization *qr_of(const silc_view *a, double tol, int transposed,
                                            int *status, const char **fn)
{
    cholmod_common *cc = ss_cholmod_common();
    cholmod_sparse At, *A = NULL;
    SuiteSparseQR_C_factorization *QR;
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
    if (!transposed && !(A = cholmod_l_transpose(&At, 1, cc))) {
        *status = cc->status;
        *fn = "cholmod_l_transpose";
        return NULL;
    }
    QR = SuiteSparseQR_C_factorize(SPQR_ORDERING_DEFAULT, tol, transposed ? &At : A, cc);
    *status = cc->status;
    *fn = "SuiteSparseQR_C_factorize";
    cholmod_l_free_sparse(&A, cc);
    return QR;
}

/* Called under the lock. */
static int qr_factor_new(silc_call *call, const silc_view *a, double tol, qr_factor **out)
{
    cholmod_common *cc = ss_cholmod_common();
    qr_factor *F;
    const char *fn;
    int status, full;
    *out = NULL;
    F = ss_host->calloc(1, sizeof *F);
    if (!F) return ss_nomem(call, "SPQR factor");
    F->m = a->m;
    F->n = a->n;
    F->tol = tol;
    F->transposed = a->m < a->n;
    F->QR = qr_of(a, tol, F->transposed, &status, &fn);
    F->rank = F->QR ? cc->SPQR_istat[4] : 0; /* rank estimate of the factorization */
    if (F->QR && F->transposed && F->rank < a->m) {
        /* Deficient row rank: no minimum-norm formula from A'; basic solution. */
        SuiteSparseQR_C_free(&F->QR, cc);
        F->transposed = 0;
        F->QR = qr_of(a, tol, 0, &status, &fn);
        F->rank = F->QR ? cc->SPQR_istat[4] : 0;
    }
    if (!F->QR) {
        ss_host->free(F);
        return qr_fail(call, fn, status);
    }
    snprintf(F->info.method, sizeof F->info.method, "sparse QR (SuiteSparseQR%s, %s)",
             F->transposed ? " of A'" : "", qr_ordering_name(cc->SPQR_istat[7]));
    /* R has the singular values of the factored matrix, so for full rank
     * ||A|| ||R^-1||_1 estimates cond(A) within modest factors (the 1-norm of
     * the factored matrix: ||A||_1 for A, ||A||_inf for A'); a rank-deficient
     * A has no finite condition number (as the reference plugin reports). */
    full = F->rank == (a->m < a->n ? a->m : a->n);
    F->info.cond = INFINITY;
    if (full && F->rank > 0) {
        const silc_props *p = silc_props_of(ss_host, call->in[0], SILC_PROPS_NORMS);
        double inv = ss_inv_norm1(F->rank, qr_apply_rinv, F);
        F->info.cond = inv >= 0 ? (F->transposed ? p->norminf : p->norm1) * inv : -1;
    }
    F->info.rcond = F->info.cond > 0 ? (isinf(F->info.cond) ? 0 : 1 / F->info.cond) : -1;
    F->info.estimated = F->info.cond >= 0;
    if (!full)
        snprintf(F->info.note, sizeof F->info.note,
                 "rank %lld of %lldx%lld (tol %.3g): basic solution (at most rank nonzeros), "
                 "not minimum norm",
                 (long long)F->rank, (long long)F->m, (long long)F->n, cc->SPQR_tol_used);
    else
        snprintf(F->info.note, sizeof F->info.note, "full rank %lld of %lldx%lld (tol %.3g)%s",
                 (long long)F->rank, (long long)F->m, (long long)F->n, cc->SPQR_tol_used,
                 F->m > F->n   ? ": least-squares solution"
                 : F->m < F->n ? ": minimum-norm solution"
                               : "");
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
    const char *fn;
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
    B = ss_rhs_dense(&b, &owned);
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
    /* Two steps either way: X = Q (R' \ (E' B)) for A', X = E (R \ (Q' B)) for A. */
    fn = F->transposed ? "SuiteSparseQR_C_solve" : "SuiteSparseQR_C_qmult";
    Y = F->transposed ? SuiteSparseQR_C_solve(SPQR_RTX_EQUALS_ETB, F->QR, &Bh, cc)
                      : SuiteSparseQR_C_qmult(SPQR_QTX, F->QR, &Bh, cc);
    status = cc->status;
    if (Y) {
        fn = F->transposed ? "SuiteSparseQR_C_qmult" : "SuiteSparseQR_C_solve";
        X = F->transposed ? SuiteSparseQR_C_qmult(SPQR_QX, F->QR, Y, cc)
                          : SuiteSparseQR_C_solve(SPQR_RETX_EQUALS_B, F->QR, Y, cc);
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
    ss_report_factor(r, &F->info);
    return SILC_OK;
}
