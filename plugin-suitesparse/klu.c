/*
 * klu.c -- suitesparse.klu: sparse LU for circuit-like matrices by KLU.
 *
 * KLU permutes A to block triangular form, orders each block by AMD and
 * factors it with partial pivoting, without BLAS: the fastest choice for the
 * very sparse, unsymmetric matrices of circuit simulation, where the same
 * pattern is factored again and again with new values.  So:
 *   klu_l_analyze   pattern only: kept in the pattern cache (ss.h);
 *   klu_l_factor    the LU factors: an attachment of the value A;
 *   klu_l_refactor  when a value with the cached pattern arrives and the
 *                   factors of a previous value of that pattern have been
 *                   given back (its value died, as in A = A + dt*M), the
 *                   new values are factored into those objects with the old
 *                   pivot order: no pivot search, no allocation.  A refactor
 *                   whose pivots came out much worse than the original's
 *                   (rcond down by 1e3) is redone by klu_l_factor.
 * Zero-copy: the CSR arrays of A are the compressed columns of A', which is
 * what KLU factors; klu_l_tsolve then solves (A')' x = A x = b.
 *
 * Condition: klu_l_rcond (smallest over largest |U(k,k)|) is cheap and
 * crude, reported as the pivot ratio only; the estimate is Hager/Higham's,
 * made on the first solve that wants one (ss.h).  klu_l_condest would estimate the
 * condition of the matrix factored, A', i.e. the infinity-norm condition of
 * A, so the plugin's estimator is run on A instead (klu_l_tsolve for A^{-1},
 * klu_l_solve for A^{-T}), giving the 1-norm figure SILC reports.
 */
#include "ss.h"

#include <klu.h>

#include <float.h>
#include <math.h>
#include <stdio.h>
#include <string.h>

#define KL_KEY "suitesparse.klu.lu"

/* A numeric object with the rcond it had when klu_l_factor made it. */
typedef struct kl_numeric {
    klu_l_numeric *N;
    double rcond0;
} kl_numeric;

typedef struct kl_factor {
    ss_symbolic *entry;         /* cached analysis (holds a reference), or NULL */
    klu_l_symbolic *local;      /* the analysis when it could not be cached */
    kl_numeric *num;
    ss_factor_info info;
} kl_factor;

static void kl_common(klu_l_common *c)
{
    klu_l_defaults(c);
}

static void kl_symbolic_free(void *p)
{
    klu_l_symbolic *S = p;
    klu_l_common c;
    kl_common(&c);
    klu_l_free_symbolic(&S, &c);
}

static void kl_numeric_free(void *p)
{
    kl_numeric *num = p;
    klu_l_common c;
    if (!num) return;
    kl_common(&c);
    klu_l_free_numeric(&num->N, &c);
    ss_host->free(num);
}

/* The attachment's destructor: the numeric object goes back to the cache
 * entry it was made from, for klu_l_refactor of the next value. */
static void kl_factor_free(void *p)
{
    kl_factor *F = p;
    if (!F) return;
    if (F->num && F->entry) ss_sym_donate(SS_KLU, F->entry, F->num, kl_numeric_free);
    else kl_numeric_free(F->num);
    ss_sym_release(F->entry);
    if (F->local) kl_symbolic_free(F->local);
    ss_host->free(F->info.start_solved);
    ss_host->free(F);
}

static klu_l_symbolic *kl_symbolic(const kl_factor *F)
{
    return F->entry ? F->entry->obj : F->local;
}

static int kl_fail(silc_call *call, const char *fn, const klu_l_common *c)
{
    int s = (int)c->status;
    switch (s) {
    case KLU_SINGULAR:
        return ss_host->error(call, SILC_ESINGULAR, "%s: singular matrix (status %d)", fn, s);
    case KLU_OUT_OF_MEMORY:
        return ss_host->error(call, SILC_ENOMEM, "%s: out of memory (status %d)", fn, s);
    case KLU_TOO_LARGE:
        return ss_host->error(call, SILC_ELIB, "%s: integer overflow (status %d)", fn, s);
    case KLU_INVALID:
        return ss_host->error(call, SILC_ELIB, "%s: invalid input (status %d)", fn, s);
    default: return ss_host->error(call, SILC_ELIB, "%s: failed (status %d)", fn, s);
    }
}

int ss_klu_accepts(const silc_call *call, const char **why)
{
    return ss_accepts_csr(call, 1, why);
}

/* For the condition estimate: A^{-1} is the transposed solve of A's factors. */
typedef struct kl_apply {
    kl_factor *F;
    int64_t n;
} kl_apply;

static int kl_apply_inv(void *ctx, double *X, int t, int trans)
{
    kl_apply *u = ctx;
    klu_l_common c;
    kl_common(&c);
    if (trans) return klu_l_solve(kl_symbolic(u->F), u->F->num->N, u->n, t, X, &c) ? 0 : -1;
    return klu_l_tsolve(kl_symbolic(u->F), u->F->num->N, u->n, t, X, &c) ? 0 : -1;
}

/* Refactor into a donated numeric object; 1 if it is good enough to keep. */
static int kl_try_refactor(const silc_view *a, klu_l_symbolic *S, kl_numeric *num, double *rcond)
{
    klu_l_common c;
    kl_common(&c);
    if (!klu_l_refactor(a->rowptr, a->colind, a->val, S, num->N, &c)) return 0;
    if (!klu_l_rcond(S, num->N, &c)) return 0;
    *rcond = c.rcond;
    return c.rcond > DBL_EPSILON && c.rcond >= 1e-3 * num->rcond0;
}

/* Makes the factorization of A (the ss_make_fn that ss_attached_factor calls). */
static int kl_factor_new(silc_call *call, const silc_view *a, void **out)
{
    klu_l_common c;
    klu_l_symbolic *S;
    kl_factor *F;
    kl_numeric *spare = NULL;
    int sym_reused = 0, refactored = 0;
    *out = NULL;
    kl_common(&c);
    F = ss_host->calloc(1, sizeof *F);
    if (!F) return ss_nomem(call, "KLU factor");
    F->entry = ss_sym_find(SS_KLU, a, 0);
    if (F->entry) {
        sym_reused = 1;
    } else {
        S = klu_l_analyze(a->n, a->rowptr, a->colind, &c);
        if (!S) {
            ss_host->free(F);
            return kl_fail(call, "klu_l_analyze", &c);
        }
        F->entry = ss_sym_remember(SS_KLU, a, 0, S, kl_symbolic_free);
        if (!F->entry) F->local = S;
    }
    S = kl_symbolic(F);
    if (F->entry) spare = ss_sym_take_spare(F->entry);
    if (spare && kl_try_refactor(a, S, spare, &F->info.rcond)) {
        F->num = spare;
        refactored = 1;
    } else {
        kl_numeric_free(spare);
        F->num = ss_host->calloc(1, sizeof *F->num);
        if (!F->num) {
            kl_factor_free(F);
            return ss_nomem(call, "KLU factor");
        }
        F->num->N = klu_l_factor(a->rowptr, a->colind, a->val, S, &c);
        if (!F->num->N || !klu_l_rcond(S, F->num->N, &c)) {
            int rc = kl_fail(call, F->num->N ? "klu_l_rcond" : "klu_l_factor", &c);
            kl_numeric_free(F->num); /* failed factors are not donated */
            F->num = NULL;
            kl_factor_free(F);
            return rc;
        }
        F->info.rcond = F->num->rcond0 = c.rcond;
    }
    ss_pivot_ratio(&F->info);
    snprintf(F->info.method, sizeof F->info.method, "sparse LU (KLU, BTF + AMD, %lld block%s)",
             (long long)S->nblocks, S->nblocks == 1 ? "" : "s");
    snprintf(F->info.note, sizeof F->info.note, "%s",
             refactored   ? "numeric refactor (klu_l_refactor, pivot order reused)"
             : sym_reused ? "symbolic analysis reused (same pattern)"
                          : "");
    *out = F;
    return SILC_OK;
}

int ss_klu_solve(silc_call *call)
{
    silc_report *r = call->report;
    silc_view a, b, o;
    kl_factor *F = NULL;
    klu_l_common c;
    silc_value *out;
    double t0, *fold;
    int64_t n, k;
    int rc, condest, start;
    if (ss_is_complex(call->in[0])) return ss_klu_solve_complex(call);
    if ((rc = ss_square_solve_begin(call, &a, &b, &condest))) return rc;
    n = a.n;
    k = b.n;
    if (ss_condest_only(call)) { /* the estimate alone, owed by an earlier solve */
        kl_apply u;
        if (!(F = n > 0 ? ss_host->attach_get(call->in[0], KL_KEY) : NULL)) return ss_no_factor(call, "KLU");
        u.F = F, u.n = n;
        return ss_estimate_alone(call, condest, n, kl_apply_inv, &u, &F->info);
    }

    if (n > 0) {
        void *f;
        if ((rc = ss_attached_factor(call, &a, KL_KEY, kl_factor_new, kl_factor_free,
                                     "attaching the KLU factors", &f)))
            return rc;
        F = f;
    }

    t0 = ss_host->now();
    /* KLU solves in place: straight in the result, as a caller of KLU would;
     * when the estimate is due, in an array with its starting block after B,
     * solved in the same call. */
    if (!(out = ss_host->dense_new_uninit(n, k))) return ss_nomem(call, "KLU result");
    ss_host->view(out, &o);
    /* so does the block for an owed estimate's bound (ss_start_due) */
    start = F && ss_start_due(call, condest, &F->info);
    fold = F && (start || ss_cond_due(call, condest, &F->info)) ? ss_rhs_with_start(&b, n) : NULL;
    if (!fold) ss_rhs_copy(&b, o.val);
    kl_common(&c);
    if (n > 0 && (k > 0 || fold) &&
        !klu_l_tsolve(kl_symbolic(F), F->num->N, n, k + (fold ? SS_EST_COLS : 0), fold ? fold : o.val, &c)) {
        ss_host->release(out);
        ss_host->free(fold);
        return kl_fail(call, "klu_l_tsolve", &c);
    }
    if (fold) {
        kl_apply u;
        memcpy(o.val, fold, (size_t)(n * k) * sizeof(double));
        u.F = F, u.n = n;
        if (start) ss_keep_start(&F->info, n, fold + n * k);
        else ss_square_cond(call, condest, n, kl_apply_inv, &u, &F->info, fold + n * k);
        ss_host->free(fold);
    }
    call->out = out;
    r->solve_seconds = ss_host->now() - t0;
    if (F) {
        ss_report_factor(r, &F->info);
        ss_report_owed(call, condest, &F->info, k);
    }
    return SILC_OK;
}
