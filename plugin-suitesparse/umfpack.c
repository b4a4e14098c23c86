/*
 * umfpack.c -- suitesparse.umfpack: general square sparse systems by UMFPACK.
 *
 * The analyze / factor / solve split of UMFPACK maps onto SILC's reuse rules:
 *   umfpack_dl_symbolic  ordering and symbolic analysis, pattern only: kept in
 *                        the pattern cache, so a new value with the same
 *                        pattern (A = K + dt*M each step) skips it;
 *   umfpack_dl_numeric   the LU factors: an attachment of the value A, so
 *                        u = A \ b in a loop factors once;
 *   umfpack_dl_wsolve    per right-hand side, with UMFPACK's iterative
 *                        refinement.
 * Zero-copy: the CSR arrays of A are the compressed columns of A', which is
 * what UMFPACK factors; umfpack_dl_wsolve(UMFPACK_At) then solves
 * (A')' x = A x = b, and its refinement reads the same arrays.
 *
 * The condition estimate is Hager/Higham's through the factors (UMFPACK_At
 * and UMFPACK_A solves, no refinement), made on the first solve that wants
 * one (ss.h).  1 / Info[UMFPACK_RCOND], UMFPACK's ratio of the largest to
 * the smallest pivot, is free but crude (it can miss ill-conditioning by
 * orders of magnitude): it is reported as the pivot ratio only.
 */
#include "ss.h"

#include <umfpack.h>

#include <math.h>
#include <stdio.h>
#include <string.h>

#define UM_KEY "suitesparse.umfpack.lu"

/* The cached symbolic object with the description of the method it chose. */
typedef struct um_symbolic {
    void *symbolic;
    char method[64];
} um_symbolic;

typedef struct um_factor {
    void *numeric;
    ss_factor_info info;
} um_factor;

static void um_symbolic_free(void *p)
{
    um_symbolic *s = p;
    if (!s) return;
    umfpack_dl_free_symbolic(&s->symbolic);
    ss_host->free(s);
}

static void um_factor_free(void *p)
{
    um_factor *F = p;
    if (!F) return;
    if (F->numeric) umfpack_dl_free_numeric(&F->numeric);
    ss_host->free(F->info.start_solved);
    ss_host->free(F);
}

static const char *um_status_text(int status)
{
    switch (status) {
    case UMFPACK_WARNING_singular_matrix: return "singular matrix";
    case UMFPACK_ERROR_out_of_memory: return "out of memory";
    case UMFPACK_ERROR_invalid_matrix: return "invalid matrix";
    case UMFPACK_ERROR_different_pattern: return "pattern differs from the symbolic analysis";
    case UMFPACK_ERROR_ordering_failed: return "ordering failed";
    case UMFPACK_ERROR_internal_error: return "internal error";
    default: return "failed";
    }
}

static int um_fail(silc_call *call, const char *fn, int status)
{
    int st = status == UMFPACK_WARNING_singular_matrix ? SILC_ESINGULAR
             : status == UMFPACK_ERROR_out_of_memory  ? SILC_ENOMEM
                                                      : SILC_ELIB;
    return ss_host->error(call, st, "%s: %s (status %d)", fn, um_status_text(status), status);
}

int ss_umfpack_accepts(const silc_call *call, const char **why)
{
    return ss_accepts_csr(call, 1, why);
}

/* For the condition estimate: x := A^{-1} x or A^{-T} x, without refinement;
 * the workspace is allocated by the first solve, so a factorization that
 * makes no estimate allocates none. */
typedef struct um_apply {
    const silc_view *a;
    void *numeric;
    double *y, *w;
    SuiteSparse_long *wi;
    double control[UMFPACK_CONTROL];
} um_apply;

static int um_apply_inv(void *ctx, double *x, int trans)
{
    um_apply *u = ctx;
    double info[UMFPACK_INFO];
    int64_t n = u->a->n;
    /* The factors are of A', so A^{-1} is the UMFPACK_At system. */
    int sys = trans ? UMFPACK_A : UMFPACK_At, st;
    if (!u->w) {
        if (!u->y) u->y = ss_host->alloc((size_t)n * 2 * sizeof(double));
        if (!u->wi) u->wi = ss_host->alloc((size_t)n * sizeof(SuiteSparse_long));
        if (!u->y || !u->wi) return -1;
        u->w = u->y + n;
        umfpack_dl_defaults(u->control);
        u->control[UMFPACK_IRSTEP] = 0;
    }
    st = (int)umfpack_dl_wsolve(sys, u->a->rowptr, u->a->colind, u->a->val, u->y, x, u->numeric,
                                u->control, info, u->wi, u->w);
    if (st < 0) return -1;
    memcpy(x, u->y, (size_t)n * sizeof(double));
    return 0;
}

/* The block estimator's apply: UMFPACK solves one column at a time, so a
 * block costs its columns (and folding the first one into the user's solve
 * would save nothing). */
static int um_apply_block(void *ctx, double *X, int t, int trans)
{
    um_apply *u = ctx;
    for (int j = 0; j < t; j++)
        if (um_apply_inv(u, X + (int64_t)j * u->a->n, trans)) return -1;
    return 0;
}

static const char *um_ordering_name(double strategy, double ordering)
{
    int sym = (int)strategy == UMFPACK_STRATEGY_SYMMETRIC;
    switch ((int)ordering) {
    case UMFPACK_ORDERING_AMD: return sym ? "AMD" : "COLAMD";
    case UMFPACK_ORDERING_METIS: return "METIS";
    case UMFPACK_ORDERING_CHOLMOD: return sym ? "AMD/METIS" : "COLAMD/METIS";
    case UMFPACK_ORDERING_NONE: return "natural";
    default: return "given";
    }
}

/* Symbolic analysis: from the cache, or made and remembered. */
static int um_analyze(silc_call *call, const silc_view *a, int tag, const double *control,
                      ss_symbolic **entry, um_symbolic **local, int *reused)
{
    double info[UMFPACK_INFO];
    um_symbolic *s;
    int st;
    *entry = ss_sym_find(SS_UMFPACK, a, tag);
    *local = NULL;
    *reused = *entry != NULL;
    if (*entry) return SILC_OK;
    s = ss_host->calloc(1, sizeof *s);
    if (!s) return ss_nomem(call, "UMFPACK symbolic");
    /* The values go in too: UMFPACK uses them to choose its strategy and to
     * prefer large diagonal pivots (pattern-only analysis made memplus 3x
     * slower to factor than the library called directly).  The analysis stays
     * valid for any values on the same pattern, so the cache may still hand it
     * to other matrices. */
    st = (int)umfpack_dl_symbolic(a->n, a->m, a->rowptr, a->colind, a->val, &s->symbolic, control,
                                  info);
    if (st != UMFPACK_OK) {
        ss_host->free(s);
        return um_fail(call, "umfpack_dl_symbolic", st);
    }
    snprintf(s->method, sizeof s->method, "sparse LU (UMFPACK, %s strategy, %s)",
             (int)info[UMFPACK_STRATEGY_USED] == UMFPACK_STRATEGY_SYMMETRIC ? "symmetric"
                                                                           : "unsymmetric",
             um_ordering_name(info[UMFPACK_STRATEGY_USED], info[UMFPACK_ORDERING_USED]));
    *entry = ss_sym_remember(SS_UMFPACK, a, tag, s, um_symbolic_free);
    if (!*entry) *local = s; /* not cached: used once and freed by the caller */
    return SILC_OK;
}

static int um_factor_new(silc_call *call, const silc_view *a, int tag, um_factor **out)
{
    double control[UMFPACK_CONTROL], info[UMFPACK_INFO];
    ss_symbolic *entry;
    um_symbolic *local, *s;
    um_factor *F;
    int reused, st, rc;
    *out = NULL;
    umfpack_dl_defaults(control);
    control[UMFPACK_STRATEGY] = tag;
    rc = um_analyze(call, a, tag, control, &entry, &local, &reused);
    if (rc) return rc;
    s = entry ? entry->obj : local;
    F = ss_host->calloc(1, sizeof *F);
    if (!F) {
        rc = ss_nomem(call, "UMFPACK factor");
        goto done;
    }
    st = (int)umfpack_dl_numeric(a->rowptr, a->colind, a->val, s->symbolic, &F->numeric, control,
                                 info);
    if (st != UMFPACK_OK) {
        /* UMFPACK_WARNING_singular_matrix still returns factors (with a zero
         * pivot); a solve with them divides by zero, so it is an error here. */
        rc = um_fail(call, "umfpack_dl_numeric", st);
        um_factor_free(F);
        goto done;
    }
    F->info.rcond = info[UMFPACK_RCOND];
    ss_pivot_ratio(&F->info);
    snprintf(F->info.method, sizeof F->info.method, "%s", s->method);
    snprintf(F->info.note, sizeof F->info.note, "%s",
             reused ? "symbolic analysis reused (same pattern)" : "");
    *out = F;
done:
    if (local) um_symbolic_free(local);
    ss_sym_release(entry);
    return rc;
}

int ss_umfpack_solve(silc_call *call)
{
    silc_report *r = call->report;
    silc_view a, b, o;
    silc_value *out = NULL;
    um_factor *F;
    double control[UMFPACK_CONTROL], info[UMFPACK_INFO], *B = NULL, *X = NULL, *W = NULL, t0;
    SuiteSparse_long *Wi = NULL;
    int64_t n, k, j, irstep;
    int owned = 0, rc, condest, st;
    if (ss_is_complex(call->in[0])) return ss_umfpack_solve_complex(call);
    if ((rc = ss_square_solve_begin(call, &a, &b, &condest))) return rc;
    n = a.n;
    k = b.n;
    if ((rc = ss_host->option_int(call, "umfpack_irstep", 2, &irstep))) return rc;
    if (ss_condest_only(call)) { /* the estimate alone, owed by an earlier solve */
        um_apply u = {0};
        if (!(F = n > 0 ? ss_host->attach_get(call->in[0], UM_KEY) : NULL)) return ss_no_factor(call, "UMFPACK");
        u.a = &a, u.numeric = F->numeric;
        rc = ss_estimate_alone(call, condest, n, um_apply_block, &u, &F->info);
        ss_host->free(u.y);
        ss_host->free(u.wi);
        return rc;
    }

    t0 = ss_host->now();
    F = n > 0 ? ss_host->attach_get(call->in[0], UM_KEY) : NULL;
    if (F) {
        r->reused_factor = 1;
    } else if (n > 0) {
        /* Under a .spd class the matrix is symmetric with a positive
         * diagonal: UMFPACK's symmetric strategy (AMD on A+A', diagonal
         * pivots preferred) fits it. */
        int tag = ss_ends_with(call->op_class, ".spd") ? UMFPACK_STRATEGY_SYMMETRIC
                                                       : UMFPACK_STRATEGY_AUTO;
        if ((rc = um_factor_new(call, &a, tag, &F))) return rc;
        if (ss_host->attach_set(call->in[0], UM_KEY, F, um_factor_free)) {
            um_factor_free(F);
            return ss_nomem(call, "attaching the UMFPACK factors");
        }
    }
    r->factor_seconds = ss_host->now() - t0;
    if (F && ss_cond_due(call, condest, &F->info)) {
        um_apply u = {0};
        u.a = &a, u.numeric = F->numeric;
        ss_square_cond(call, condest, n, um_apply_block, &u, &F->info, NULL);
        ss_host->free(u.y);
        ss_host->free(u.wi);
    }

    t0 = ss_host->now();
    B = ss_rhs_dense(&b, &owned);
    out = ss_host->dense_new_uninit(n, k); /* umfpack_dl_wsolve writes every column */
    W = ss_host->alloc((size_t)(n > 0 ? n : 1) * 5 * sizeof(double));
    Wi = ss_host->alloc((size_t)(n > 0 ? n : 1) * sizeof(SuiteSparse_long));
    if (!B || !out || !W || !Wi) {
        rc = ss_nomem(call, "UMFPACK solve");
        goto done;
    }
    ss_host->view(out, &o);
    X = o.val;
    umfpack_dl_defaults(control);
    control[UMFPACK_IRSTEP] = (double)(irstep < 0 ? 0 : irstep);
    for (j = 0; j < k && n > 0; j++) {
        st = (int)umfpack_dl_wsolve(UMFPACK_At, a.rowptr, a.colind, a.val, X + j * n, B + j * n,
                                    F->numeric, control, info, Wi, W);
        if (st != UMFPACK_OK) {
            rc = um_fail(call, "umfpack_dl_wsolve", st);
            goto done;
        }
    }
    call->out = out;
    out = NULL;
    r->solve_seconds = ss_host->now() - t0;
    if (F && ss_start_due(call, condest, &F->info)) { /* an owed estimate's bound (ss.h) */
        um_apply u = {0};
        u.a = &a, u.numeric = F->numeric;
        ss_solve_start(&F->info, n, um_apply_block, &u);
        ss_host->free(u.y);
        ss_host->free(u.wi);
    }
    if (F) {
        ss_report_factor(r, &F->info);
        ss_report_owed(call, condest, &F->info, k);
    }
    rc = SILC_OK;
done:
    if (out) ss_host->release(out);
    if (owned) ss_host->free(B);
    ss_host->free(W);
    ss_host->free(Wi);
    return rc;
}
