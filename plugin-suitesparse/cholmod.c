/*
 * cholmod.c -- suitesparse.cholmod: symmetric positive definite sparse
 * systems by CHOLMOD's Cholesky factorization.
 *
 *   cholmod_l_analyze    ordering (AMD, METIS when it pays) and the
 *                        supernodal or simplicial structure of L, chosen by
 *                        CHOLMOD's default rule; pattern only, so kept in the
 *                        pattern cache (ss.h) for later values of the pattern;
 *   cholmod_l_factorize  into a copy of that analysis (or into the factor of
 *                        a dead value of the same pattern, given back to the
 *                        cache); the factor is an attachment of A;
 *   the solve            a supernodal LL' factor (what CHOLMOD makes for
 *                        all but the smallest matrices) is solved here by
 *                        ch_super_solve, column by column, without BLAS;
 *                        other factors by cholmod_l_solve.
 * A matrix that is not positive definite (CHOLMOD_NOT_POSDEF) returns
 * SILC_ENOTSPD and the dispatcher retries the list under the LU class.
 *
 * Zero-copy: accepted matrices are symmetric, so the CSR arrays of A (the
 * compressed columns of A') are the compressed columns of A; stype = 1 tells
 * CHOLMOD to read the upper triangle and ignore the rest.  All CHOLMOD calls
 * use the plugin's one cholmod_common, under the plugin lock.
 */
#include "ss.h"

#include <math.h>
#include <stdio.h>
#include <string.h>

#define CH_KEY "suitesparse.cholmod.chol"

typedef struct ch_factor {
    cholmod_factor *L;
    ss_symbolic *entry;         /* the analysis L was copied from, or NULL */
    double *work;               /* 2n doubles for ch_super_solve, used under the lock */
    ss_factor_info info;
} ch_factor;

static void ch_free_L(void *p)
{
    cholmod_factor *L = p;
    ss_lock();
    cholmod_l_free_factor(&L, ss_cholmod_common());
    ss_unlock();
}

static void ch_factor_free(void *p)
{
    ch_factor *F = p;
    if (!F) return;
    if (F->L && F->entry) ss_sym_donate(SS_CHOLMOD, F->entry, F->L, ch_free_L);
    else if (F->L) ch_free_L(F->L);
    ss_sym_release(F->entry);
    ss_host->free(F->work);
    ss_host->free(F);
}

int ss_cholmod_accepts(const silc_call *call, const char **why)
{
    if (!ss_accepts_csr(call, 1, why)) return 0;
    if (!ss_ends_with(call->op_class, ".spd")) {
        *why = "Cholesky only: runs under the solve.*.spd classes";
        return 0;
    }
    if (ss_is_complex(call->in[0])) {
        if (!silc_props_of(ss_host, call->in[0], SILC_PROPS_SYMMETRY)->hermitian) {
            *why = "needs a Hermitian matrix";
            return 0;
        }
    } else if (!silc_props_of(ss_host, call->in[0], SILC_PROPS_SYMMETRY)->symmetric) {
        *why = "needs a symmetric matrix";
        return 0;
    }
    return 1;
}

/* A's CSR arrays as a symmetric CHOLMOD matrix (no copy). */
static void ch_sparse(const silc_view *a, cholmod_sparse *A)
{
    memset(A, 0, sizeof *A);
    A->nrow = (size_t)a->n;
    A->ncol = (size_t)a->m;
    A->nzmax = (size_t)a->rowptr[a->m];
    A->p = a->rowptr;
    A->i = a->colind;
    A->x = a->val;
    A->stype = 1;
    A->itype = CHOLMOD_LONG;
    A->xtype = CHOLMOD_REAL;
    A->dtype = CHOLMOD_DOUBLE;
    A->sorted = 1;
    A->packed = 1;
}

static void ch_dense(int64_t n, int64_t k, double *x, cholmod_dense *D)
{
    memset(D, 0, sizeof *D);
    D->nrow = (size_t)n;
    D->ncol = (size_t)k;
    D->nzmax = (size_t)(n * k);
    D->d = (size_t)n;
    D->x = x;
    D->xtype = CHOLMOD_REAL;
    D->dtype = CHOLMOD_DOUBLE;
}

static int ch_fail(silc_call *call, const char *fn, int status)
{
    if (status == CHOLMOD_OUT_OF_MEMORY)
        return ss_host->error(call, SILC_ENOMEM, "%s: out of memory (status %d)", fn, status);
    if (status == CHOLMOD_TOO_LARGE)
        return ss_host->error(call, SILC_ELIB, "%s: integer overflow (status %d)", fn, status);
    if (status == CHOLMOD_INVALID)
        return ss_host->error(call, SILC_ELIB, "%s: invalid input (status %d)", fn, status);
    return ss_host->error(call, SILC_ELIB, "%s: failed (status %d)", fn, status);
}

/* L is solved by ch_super_solve (below) rather than cholmod_l_solve. */
static int ch_solves_here(const cholmod_factor *L)
{
    return L->is_super && L->is_ll && L->xtype == CHOLMOD_REAL && L->dtype == CHOLMOD_DOUBLE &&
           L->itype == CHOLMOD_LONG && L->Perm != NULL;
}

/*
 * X = A^-1 B for the n x k column-major B (leading dimension n), with
 * A(p, p) = L L' and L supernodal: w = B(p, j), L w = w, L' w = w,
 * X(p, j) = w, one column at a time.  work holds 2n doubles: w, and t for
 * a supernode's rows below its diagonal block.  X may be B.
 *
 * Why not cholmod_l_solve: with one or a few columns CHOLMOD solves each
 * supernode with a dtrsv and a dgemv, two BLAS calls per supernode and
 * sweep (20 000 calls a solve for the 5038 supernodes of the 200 x 200
 * diffusion matrix), and OpenBLAS takes a lock and a buffer in each: in a
 * profile of the diffusion loop 70 % of a step was in OpenBLAS and its
 * mutexes, for a solve that is one pass over L each way.  These loops make
 * the same pass with no call and no lock per supernode.  A supernode's
 * columns are an nsrow x nscol column-major block whose first nscol rows
 * are the diagonal block; the row indices are in L->s.  Its rows below the
 * diagonal block are updated through t, contiguous (the forward sweep sums
 * the columns' contributions into t and scatters t once; the backward sweep
 * gathers t once and takes dot products with it), not through one scattered
 * update per entry: 20-30 % less time than entry by entry, as the BLAS
 * form's dgemv does.  Each column of B is solved alone, so its result does
 * not depend on the columns beside it (docs/backends.md, "The diffusion
 * loop's solve").
 */
static void ch_super_solve(const cholmod_factor *L, const double *B, double *X, int64_t k, double *work)
{
    const SuiteSparse_long *perm = L->Perm, *super = L->super, *pi = L->pi, *px = L->px, *ls = L->s;
    const double *lx = L->x;
    int64_t n = (int64_t)L->n, nsuper = (int64_t)L->nsuper, s, i, j, c;
    double *w = work, *t = work + n;
    for (c = 0; c < k; c++) {
        const double *b = B + c * n;
        double *x = X + c * n;
        for (i = 0; i < n; i++) w[i] = b[perm[i]];
        for (s = 0; s < nsuper; s++) { /* L w = w */
            int64_t k1 = super[s], nscol = super[s + 1] - k1, nsrow = pi[s + 1] - pi[s], below = nsrow - nscol;
            const SuiteSparse_long *rows = ls + pi[s] + nscol;
            const double *blk = lx + px[s];
            for (i = 0; i < below; i++) t[i] = 0;
            for (j = 0; j < nscol; j++) {
                const double *col = blk + j * nsrow, *sub = col + nscol;
                double wj = w[k1 + j] / col[j];
                w[k1 + j] = wj;
                for (i = j + 1; i < nscol; i++) w[k1 + i] -= col[i] * wj;
                for (i = 0; i + 4 <= below; i += 4) { /* unrolled: 10 % less time at -O2 */
                    t[i] += sub[i] * wj;
                    t[i + 1] += sub[i + 1] * wj;
                    t[i + 2] += sub[i + 2] * wj;
                    t[i + 3] += sub[i + 3] * wj;
                }
                for (; i < below; i++) t[i] += sub[i] * wj;
            }
            for (i = 0; i < below; i++) w[rows[i]] -= t[i];
        }
        for (s = nsuper - 1; s >= 0; s--) { /* L' w = w, last column first */
            int64_t k1 = super[s], nscol = super[s + 1] - k1, nsrow = pi[s + 1] - pi[s], below = nsrow - nscol;
            const SuiteSparse_long *rows = ls + pi[s] + nscol;
            const double *blk = lx + px[s];
            for (i = 0; i < below; i++) t[i] = w[rows[i]];
            for (j = nscol - 1; j >= 0; j--) {
                const double *col = blk + j * nsrow, *sub = col + nscol;
                double d0 = 0, d1 = 0, d2 = 0, d3 = 0, wj; /* four sums: independent adds */
                for (i = 0; i + 4 <= below; i += 4) {
                    d0 += sub[i] * t[i];
                    d1 += sub[i + 1] * t[i + 1];
                    d2 += sub[i + 2] * t[i + 2];
                    d3 += sub[i + 3] * t[i + 3];
                }
                for (; i < below; i++) d0 += sub[i] * t[i];
                wj = w[k1 + j] - ((d0 + d1) + (d2 + d3));
                for (i = j + 1; i < nscol; i++) wj -= col[i] * w[k1 + i];
                w[k1 + j] = wj / col[j];
            }
        }
        for (i = 0; i < n; i++) x[perm[i]] = w[i];
    }
}

/* For the condition estimate (A symmetric: A^{-T} = A^{-1}): the solution
 * and CHOLMOD's workspace are kept from one solve to the next
 * (cholmod_l_solve2), where cholmod_l_solve allocated and freed them on
 * every call. */
typedef struct ch_est {
    ch_factor *F;
    cholmod_dense *X, *Y, *E;
} ch_est;

static int ch_apply_inv(void *ctx, double *x, int t, int trans)
{
    ch_est *e = ctx;
    cholmod_common *cc = ss_cholmod_common();
    cholmod_dense B;
    int64_t n = (int64_t)e->F->L->n;
    int ok;
    (void)trans;
    ss_lock();
    if (e->F->work) {
        ch_super_solve(e->F->L, x, x, t, e->F->work);
        ss_unlock();
        return 0;
    }
    ch_dense(n, t, x, &B);
    ok = cholmod_l_solve2(CHOLMOD_A, e->F->L, &B, NULL, &e->X, NULL, &e->Y, &e->E, cc);
    ss_unlock();
    if (ok) memcpy(x, e->X->x, (size_t)(n * t) * sizeof(double));
    return ok ? 0 : -1;
}

static void ch_est_free(ch_est *e)
{
    cholmod_common *cc = ss_cholmod_common();
    ss_lock();
    cholmod_l_free_dense(&e->X, cc);
    cholmod_l_free_dense(&e->Y, cc);
    cholmod_l_free_dense(&e->E, cc);
    ss_unlock();
}

static const char *ch_ordering_name(int ordering)
{
    switch (ordering) {
    case CHOLMOD_NATURAL: return "natural";
    case CHOLMOD_AMD: return "AMD";
    case CHOLMOD_METIS: return "METIS";
    case CHOLMOD_NESDIS: return "NESDIS";
    case CHOLMOD_COLAMD: return "COLAMD";
    case CHOLMOD_POSTORDERED: return "postordered";
    default: return "given";
    }
}

/* Makes the factorization of A (the ss_make_fn that ss_attached_factor calls). */
static int ch_factor_new(silc_call *call, const silc_view *a, void **out)
{
    cholmod_common *cc = ss_cholmod_common();
    cholmod_sparse A;
    cholmod_factor *L = NULL;
    ch_factor *F;
    int sym_reused, status, rc;
    long long minor;
    *out = NULL;
    ch_sparse(a, &A);
    F = ss_host->calloc(1, sizeof *F);
    if (!F) return ss_nomem(call, "CHOLMOD factor");
    F->entry = ss_sym_find(SS_CHOLMOD, a, 0);
    sym_reused = F->entry != NULL;
    if (F->entry) {
        L = ss_sym_take_spare(F->entry);
        if (!L) {
            ss_lock();
            L = cholmod_l_copy_factor(F->entry->obj, cc);
            status = cc->status;
            ss_unlock();
            if (!L) {
                ch_factor_free(F);
                return ch_fail(call, "cholmod_l_copy_factor", status);
            }
        }
    } else {
        cholmod_factor *S, *Lc;
        ss_lock();
        S = cholmod_l_analyze(&A, cc);
        status = cc->status;
        Lc = S ? cholmod_l_copy_factor(S, cc) : NULL;
        ss_unlock();
        if (!S) {
            ch_factor_free(F);
            return ch_fail(call, "cholmod_l_analyze", status);
        }
        F->entry = ss_sym_remember(SS_CHOLMOD, a, 0, S, ch_free_L);
        if (!F->entry) ch_free_L(S); /* not cached: the copy is all we need */
        if (!Lc) {
            ch_factor_free(F);
            return ch_fail(call, "cholmod_l_copy_factor", CHOLMOD_OUT_OF_MEMORY);
        }
        L = Lc;
    }
    ss_lock();
    ss_cholmod_factorize(&A, L, cc);
    status = cc->status;
    minor = (long long)L->minor;
    F->L = L;
    F->info.rcond = status == CHOLMOD_OK ? cholmod_l_rcond(L, cc) : 0;
    ss_unlock();
    if (status == CHOLMOD_NOT_POSDEF) {
        /* The factor is not donated: only complete factorizations refactor. */
        ch_free_L(F->L);
        F->L = NULL;
        ch_factor_free(F);
        return ss_host->error(call, SILC_ENOTSPD,
                              "cholmod_l_factorize: matrix not positive definite (status %d, "
                              "leading minor of order %lld)",
                              status, minor + 1);
    }
    if (status < CHOLMOD_OK) {
        rc = ch_fail(call, "cholmod_l_factorize", status);
        ch_factor_free(F);
        return rc;
    }
    if (ch_solves_here(L) && !(F->work = ss_host->alloc(2 * (size_t)L->n * sizeof(double)))) {
        ch_factor_free(F);
        return ss_nomem(call, "CHOLMOD solve work space");
    }
    ss_pivot_ratio(&F->info);
    snprintf(F->info.method, sizeof F->info.method, "sparse Cholesky (CHOLMOD, %s, %s)",
             L->is_super ? "supernodal" : "simplicial", ch_ordering_name(L->ordering));
    snprintf(F->info.note, sizeof F->info.note, "%s", sym_reused ? "symbolic analysis reused (same pattern)" : "");
    *out = F;
    return SILC_OK;
}

int ss_cholmod_solve(silc_call *call)
{
    cholmod_common *cc = ss_cholmod_common();
    silc_report *r = call->report;
    silc_view a, b;
    ch_factor *F = NULL;
    cholmod_dense Bh, *X = NULL;
    double *B, t0;
    int64_t n, k;
    int owned, rc, condest, status;
    if (ss_is_complex(call->in[0])) return ss_cholmod_solve_complex(call);
    if ((rc = ss_square_solve_begin(call, &a, &b, &condest))) return rc;
    n = a.n;
    k = b.n;
    if (ss_condest_only(call)) { /* the estimate alone, owed by an earlier solve */
        ch_est e = {NULL, NULL, NULL, NULL};
        if (!(F = n > 0 ? ss_host->attach_get(call->in[0], CH_KEY) : NULL)) return ss_no_factor(call, "CHOLMOD");
        e.F = F;
        rc = ss_estimate_alone(call, condest, n, ch_apply_inv, &e, &F->info);
        ch_est_free(&e);
        return rc;
    }

    if (n > 0) {
        void *f;
        if ((rc = ss_attached_factor(call, &a, CH_KEY, ch_factor_new, ch_factor_free,
                                     "attaching the CHOLMOD factor", &f)))
            return rc;
        F = f;
    }

    t0 = ss_host->now();
    if (n == 0 || k == 0) {
        call->out = ss_host->dense_new(n, k);
        return call->out ? SILC_OK : ss_nomem(call, "CHOLMOD result");
    }
    /* The user's columns alone: CHOLMOD's supernodal solve of k + 2
     * columns (the estimator's start riding along, as KLU's does) rounds
     * them otherwise than a solve of k, and the result must not depend on
     * when the estimate is made (tests/test_condest_auto.c).  The start
     * is solved on its own when the estimate is due (A is symmetric, so the
     * transposed solves are the same solves). */
    B = ss_rhs_dense(&b, &owned);
    if (!B) return ss_nomem(call, "CHOLMOD right-hand side");
    if (F->work) { /* straight into the result: no CHOLMOD dense, no copy */
        silc_view o;
        if ((call->out = ss_host->dense_new_uninit(n, k))) {
            ss_host->view(call->out, &o);
            ss_lock();
            ch_super_solve(F->L, B, o.val, k, F->work);
            ss_unlock();
        }
        if (owned) ss_host->free(B);
    } else {
        ch_dense(n, k, B, &Bh);
        ss_lock();
        X = cholmod_l_solve(CHOLMOD_A, F->L, &Bh, cc);
        status = cc->status;
        ss_unlock();
        if (owned) ss_host->free(B);
        if (!X) return ch_fail(call, "cholmod_l_solve", status);
        call->out = ss_dense_value(n, k, X->x, (int64_t)X->d);
    }
    if (ss_cond_due(call, condest, &F->info)) {
        ch_est e = {F, NULL, NULL, NULL};
        ss_square_cond(call, condest, n, ch_apply_inv, &e, &F->info, NULL);
        ch_est_free(&e);
    }
    ss_lock();
    cholmod_l_free_dense(&X, cc);
    ss_unlock();
    if (!call->out) return ss_nomem(call, "CHOLMOD result");
    r->solve_seconds = ss_host->now() - t0;
    ss_report_factor(r, &F->info);
    ss_report_owed(call, condest, &F->info, k);
    /* A = L L' (final_ll), so L_ii^2 <= a_ii <= lambda_max, and L_ii^2, a
     * pivot of Cholesky, is 1 / (A_k^-1)_kk >= lambda_min(A_k) >=
     * lambda_min(A) for the leading block A_k: CHOLMOD's ratio (max L_ii /
     * min L_ii)^2 is at most cond_2(A) <= cond_1(A) (A symmetric), a
     * rigorous lower bound that tells the host whether the owed estimate
     * is urgent (docs/accuracy.md). */
    if (r->condest_deferred == 1 && F->info.pivot_ratio > 0) r->condest_lower = F->info.pivot_ratio;
    return SILC_OK;
}
