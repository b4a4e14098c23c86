/*
 * ref_solve.c -- SOLVE for the reference plugin: X = A \ B.
 *
 * The operation class the dispatcher is trying (call->op_class) names the
 * algorithm; without one (or an unknown one) the structure of A decides, the
 * way MATLAB's backslash does: diagonal, triangular, band, symmetric with a
 * positive diagonal (Cholesky, falling back to LU if it fails), dense LU,
 * sparse LU, and QR for a rectangular A.  Every factorization is attached to A
 * under a key per algorithm, so the next solve with the same value reuses it;
 * its 1-norm condition estimate is computed once, at factor time.  Each
 * solution of a square system gets up to two steps of iterative refinement in
 * working precision, kept only while they reduce the backward error, which
 * makes the oracle's answers as accurate as the factorization allows.
 */
#include "ref.h"

#include <float.h>
#include <math.h>
#include <stdio.h>
#include <string.h>

enum alg { ALG_DIAG, ALG_TRI, ALG_BAND, ALG_DENSE_SPD, ALG_DENSE, ALG_SPARSE_SPD, ALG_SPARSE, ALG_RECT };

static const char *const alg_class[] = {"solve.diag",  "solve.triangular", "solve.band",
                                        "solve.dense.spd", "solve.dense", "solve.sparse.spd",
                                        "solve.sparse", "solve.rect"};
static const char *const alg_key[] = {"reference.diag", "reference.tri", "reference.band_lu",
                                      "reference.dense_chol", "reference.dense_lu",
                                      "reference.sparse_chol", "reference.sparse_lu", "reference.qr"};

#undef REF_COMPLEX
#include "ref_field.h"
#include "ref_solve_t.h"

#define REF_COMPLEX
#include "ref_field.h"
#include "ref_solve_t.h"
#undef REF_COMPLEX

/* spd: the class Cholesky takes, symmetric (real) or Hermitian (complex)
 * with a positive real diagonal. */
static int pick_auto(const silc_view *a, const silc_props *P, int w)
{
    if (a->m != a->n) return ALG_RECT;
    if (P->diagonal) return ALG_DIAG;
    if (P->lower || P->upper) return ALG_TRI;
    if (a->format == SILC_FMT_BAND) return ALG_BAND;
    int spd = (w == 2 ? P->hermitian : P->symmetric) && P->pos_diag;
    if (a->format == SILC_FMT_DENSE) return spd ? ALG_DENSE_SPD : ALG_DENSE;
    return spd ? ALG_SPARSE_SPD : ALG_SPARSE;
}

static int factor(int alg, const silc_view *a, const silc_props *P, int w, ref_factor *F, char *msg, size_t ml)
{
    int st, z = w == 2;
    if (alg == ALG_DIAG) return z ? diag_factor_z(a, F, msg, ml) : diag_factor(a, F, msg, ml);
    if (alg == ALG_BAND) return (z ? ref_band_lu_z : ref_band_lu)(a, P->kl, P->ku, F, msg, ml);
    int dense = alg == ALG_DENSE || alg == ALG_DENSE_SPD ||
                ((alg == ALG_TRI || alg == ALG_RECT) && a->format == SILC_FMT_DENSE);
    if (dense) {
        double *D = ref_dense_from_view_w(a, w);
        if (!D) return SILC_ENOMEM;
        if (alg == ALG_DENSE) st = (z ? ref_dense_lu_z : ref_dense_lu)(a->n, D, F, msg, ml);
        else if (alg == ALG_DENSE_SPD) st = (z ? ref_dense_chol_z : ref_dense_chol)(a->n, D, F, msg, ml);
        else if (alg == ALG_TRI) st = (z ? ref_dense_tri_z : ref_dense_tri)(a->n, D, P->lower, F, msg, ml);
        else st = (z ? ref_dense_qr_z : ref_dense_qr)(a->m, a->n, D, F, msg, ml);
        ref_free(D);
        return st;
    }
    ref_sp C;
    if (ref_sp_from_view_w(a, w, &C)) return SILC_ENOMEM;
    if (alg == ALG_TRI) st = (z ? ref_sparse_tri_z : ref_sparse_tri)(&C, P->lower, F, msg, ml);
    else if (alg == ALG_SPARSE_SPD) st = (z ? ref_sparse_chol_z : ref_sparse_chol)(&C, F, msg, ml);
    else if (alg == ALG_SPARSE) st = (z ? ref_sparse_lu_z : ref_sparse_lu)(&C, F, msg, ml);
    else st = (z ? ref_sparse_qr_z : ref_sparse_qr)(&C, F, msg, ml);
    ref_sp_free(&C);
    return st;
}

/* F->rcond from F->cond (positive, or Inf for a singular factor). */
static void set_rcond(ref_factor *F)
{
    F->rcond = F->cond > 0 ? 1.0 / F->cond : -1.0;
    if (isinf(F->cond)) F->rcond = 0.0;
}

/* A square factor's estimate ||A||_1 * est ||A^{-1}||_1 into F->cond, by
 * dlacon's method (zlacn2's for complex, w = 2) with F's solves: about
 * REF_EST_SOLVES column solves, next to which a solve of this plugin (with
 * its refinement steps) costs at least one.  -1 when out of memory (the
 * estimator's only failure: the solve of a factor does not fail). */
#define REF_EST_SOLVES 5
static int make_estimate(ref_factor *F, int64_t n, int w, double norm1)
{
    double *work = ref_alloc((size_t)(F->work_len + w * n + 1), sizeof(double)), est = -1;
    /* an owed estimate goes on from the start its lower bound solved */
    if (work && w == 2) est = ref_inv_norm1_est_complex(n, F->solve, F->data, work);
    else if (work) est = ref_inv_norm1_est_from(n, F->solve, F->data, work, F->est_start);
    ref_free(work);
    ref_free(F->est_start);
    F->est_start = NULL;
    if (est < 0) return -1;
    F->cond = ref_cond_from(norm1, est);
    set_rcond(F);
    return 0;
}

/* ||A||_1 max_j ||A^-1 x_j||_1 / ||x_j||_1 over the estimator's two start
 * vectors (e/n and the alternating one; complex: with imaginary parts 0,
 * norms by modulus): a lower bound of cond_1(A) for two column solves, a
 * fraction of the estimate's, that tells the host whether an owed estimate
 * must be made at once (condest_lower); -1 when out of memory.  A real
 * factor keeps the solved vectors (F->est_start), which the estimate, when
 * made, starts from instead of solving them again.  work: F's solve
 * workspace. */
static double start_bound(ref_factor *F, int64_t n, int w, double norm1, double *work)
{
    double *X = ref_alloc((size_t)(2 * n * w), sizeof(double)), best = 0;
    int solved = 0;
    if (!X || n == 0) {
        ref_free(X);
        return n ? -1 : 0;
    }
    ref_inv_norm1_start(n, 2, X);
    if (w == 2)
        for (int64_t i = 2 * n - 1; i >= 0; i--) X[2 * i] = X[i], X[2 * i + 1] = 0;
    for (int j = 0; j < 2 && n > 1; j++) {
        double *x = X + j * n * w, sx = 0, sy = 0;
        for (int64_t i = 0; i < n; i++) sx += w == 2 ? hypot(x[2 * i], x[2 * i + 1]) : fabs(x[i]);
        if (F->solve(F->data, x, 0, work)) break;
        solved++;
        for (int64_t i = 0; i < n; i++) sy += w == 2 ? hypot(x[2 * i], x[2 * i + 1]) : fabs(x[i]);
        if (sy / sx > best) best = sy / sx;
    }
    ref_free(F->est_start);
    F->est_start = NULL;
    if (w == 1 && solved == 2) F->est_start = X;
    else ref_free(X);
    return best * norm1;
}

int ref_op_solve(silc_call *call)
{
    silc_view a, b;
    ref_host->view(call->in[0], &a);
    ref_host->view(call->in[1], &b);
    silc_report *rep = call->report;
    if (a.m != b.m)
        return ref_host->error(call, SILC_EARG, "solve: A is %lldx%lld but the right-hand side has %lld rows",
                               (long long)a.m, (long long)a.n, (long long)b.m);
    int w = ref_width(call->in[0]);
    if (ref_width(call->in[1]) != w) /* the host promotes before calling (silc_plugin.h) */
        return ref_host->error(call, SILC_EARG, "solve: A is %s but the right-hand side is %s",
                               w == 2 ? "complex" : "real", w == 2 ? "real" : "complex");
    const silc_props *P = ref_host->props(call->in[0]);
    int alg = -1, by_structure = 0;
    for (int k = 0; call->op_class && k < 8; k++)
        if (strcmp(call->op_class, alg_class[k]) == 0) alg = k;
    if (alg < 0) {
        alg = pick_auto(&a, P, w);
        by_structure = 1;
    }
    if (a.m != a.n) alg = ALG_RECT;
    if (alg == ALG_TRI && !P->lower && !P->upper)
        return ref_host->error(call, SILC_EDECLINE, "triangular solve: the matrix is not triangular");

    /* accuracy.condest = off skips the estimate (ABI 1.7); condest_later
     * leaves it owed, condest_only makes it alone (ABI 1.8, see
     * make_estimate), real or complex alike. */
    int wanted = !(ref_host->abi_minor >= 7 && rep->condest_off);
    int later = ref_host->abi_minor >= 8 && rep->condest_later;
    if (ref_host->abi_minor >= 8 && rep->condest_only) {
        ref_factor *F = ref_host->attach_get(call->in[0], alg_key[alg]);
        if (!F && by_structure && (alg == ALG_DENSE_SPD || alg == ALG_SPARSE_SPD)) /* Cholesky had failed */
            F = ref_host->attach_get(call->in[0], alg_key[alg == ALG_DENSE_SPD ? ALG_DENSE : ALG_SPARSE]);
        if (!F) return ref_host->error(call, SILC_EDECLINE, "no factorization attached to A for the condition estimate");
        if (F->cond == 0.0 && wanted && make_estimate(F, a.n, w, P->norm1)) return ref_nomem(call);
        rep->cond_est = F->cond == 0.0 ? -1 : F->cond;
        rep->rcond = F->cond == 0.0 ? -1 : F->rcond;
        return SILC_OK;
    }

    double t0 = ref_host->now();
    ref_factor *F = ref_host->attach_get(call->in[0], alg_key[alg]);
    int reused = F != NULL, attached = 1;
    while (!F) {
        char msg[256] = "";
        F = ref_calloc(1, sizeof(ref_factor));
        if (!F) return ref_nomem(call);
        F->m = a.m;
        F->n = a.n;
        ref_cancel_scope(call);
        int st = factor(alg, &a, P, w, F, msg, sizeof msg);
        ref_cancel_scope(NULL);
        if (st) {
            ref_free(F);
            F = NULL;
            if (st == SILC_ENOTSPD && by_structure) { /* Cholesky failed: LU, as backslash does */
                alg = alg == ALG_DENSE_SPD ? ALG_DENSE : ALG_SPARSE;
                F = ref_host->attach_get(call->in[0], alg_key[alg]);
                reused = F != NULL;
                continue;
            }
            if (st == SILC_ENOMEM) return ref_nomem(call);
            return ref_host->error(call, st, "%s", msg);
        }
        if (F->cond != 0.0) set_rcond(F); /* the factorization's own (diagonal, QR) */
        attached = ref_host->attach_set(call->in[0], alg_key[alg], F, ref_factor_free) == 0;
    }
    double t1 = ref_host->now();
    /* A square factor's estimate (F->cond == 0: none yet), on the first
     * solve that wants one: a later solve with the setting on makes it.
     * Owed (later) only by a factorization kept on A, where the
     * condest_only call will find it. */
    if (F->cond == 0.0 && wanted && later && !attached) { /* owed, but nothing keeps the factorization */
        ref_factor_free(F);
        return ref_nomem(call);
    }
    if (F->cond == 0.0 && wanted && !later && make_estimate(F, a.n, w, P->norm1)) {
        /* no estimate would mean no warning of an ill-conditioned matrix */
        if (!attached) ref_factor_free(F);
        return ref_nomem(call);
    }

    /* vectors below hold w doubles per entry; the refinement's own
     * arithmetic (copies, d += x) is the same on interleaved doubles */
    int64_t m = a.m, n = a.n, nrhs = b.n, len = (m > n ? m : n) * w;
    double (*residual_fn)(const silc_view *, double, const double *, const double *, double *) =
        w == 2 ? residual_z : residual;
    silc_value *out = w == 2 ? ref_host->dense_new_complex(n, nrhs) : ref_host->dense_new(n, nrhs);
    double *B = ref_dense_from_view_w(&b, w);
    double *x = ref_alloc((size_t)len, sizeof(double)), *r = ref_alloc((size_t)len, sizeof(double));
    double *d = ref_alloc((size_t)len, sizeof(double));
    double *work = ref_alloc((size_t)(F->work_len + len + 1), sizeof(double));
    int st = 0, refined = 0;
    if (!out || !B || !x || !r || !d || !work) {
        st = ref_nomem(call);
        goto done;
    }
    silc_view o;
    ref_host->view(out, &o);
    double anorm = P->norminf;
    for (int64_t j = 0; j < nrhs; j++) {
        const double *bj = B + j * m * w;
        memcpy(x, bj, (size_t)(m * w) * sizeof(double));
        if (F->solve(F->data, x, 0, work)) {
            st = ref_host->error(call, SILC_EINTERNAL, "%s: solve failed", F->method);
            goto done;
        }
        if (m == n && alg != ALG_DIAG) {
            double berr = residual_fn(&a, anorm, bj, x, r);
            for (int it = 0; it < 2 && berr > DBL_EPSILON && isfinite(berr); it++) {
                memcpy(d, r, (size_t)(n * w) * sizeof(double));
                F->solve(F->data, d, 0, work);
                for (int64_t i = 0; i < n * w; i++) d[i] += x[i];
                double nb = residual_fn(&a, anorm, bj, d, r);
                if (!(nb < berr)) break;
                memcpy(x, d, (size_t)(n * w) * sizeof(double));
                berr = nb;
                refined = 1;
            }
        }
        memcpy(o.val + j * n * w, x, (size_t)(n * w) * sizeof(double));
    }
    snprintf(rep->method, sizeof rep->method, "%s", F->method);
    if (refined) {
        static const char tag[] = " + refinement";
        size_t l = strlen(rep->method);
        if (l + sizeof tag <= sizeof rep->method) memcpy(rep->method + l, tag, sizeof tag);
    }
    rep->cond_est = F->cond == 0.0 ? -1 : F->cond;
    rep->rcond = F->cond == 0.0 ? -1 : F->rcond;
    rep->reused_factor = reused;
    rep->factor_seconds = reused ? 0.0 : t1 - t0;
    rep->solve_seconds = ref_host->now() - t1;
    rep->iterations = 0;
    if (F->cond == 0.0 && wanted && later && attached) {
        rep->condest_deferred = 1;
        rep->condest_solves = (double)REF_EST_SOLVES / (double)(nrhs > 0 ? nrhs : 1);
        if (rep->condest_later != 2 && /* on_request wants no bound */
            (rep->condest_lower = start_bound(F, n, w, P->norm1, work)) < 0) {
            st = ref_nomem(call); /* without the hint an ill-conditioned matrix could go unwarned */
            goto done;
        }
    }
    snprintf(rep->note, sizeof rep->note, "%s", F->note);
    call->out = out;
    out = NULL;
done:
    if (out) ref_host->release(out);
    ref_free(B);
    ref_free(x);
    ref_free(r);
    ref_free(d);
    ref_free(work);
    if (!attached) ref_factor_free(F);
    return st;
}
