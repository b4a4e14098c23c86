/*
 * lapack_band.c -- band and tridiagonal factorizations of the lapack plugin.
 *
 * A matrix under solve.band (band storage, or dense storage whose nonzeros
 * lie in a narrow band) is copied into the layout its LAPACK routine wants,
 * using the bandwidths of its nonzeros rather than of its storage:
 *
 *   kl = ku = 1, symmetric, positive diagonal   dpttrf / dpttrs, dptcon
 *   kl, ku <= 1                                 dgttrf / dgttrs, dgtcon
 *   symmetric, positive diagonal                dpbtrf / dpbtrs
 *   otherwise                                   dgbtrf / dgbtrs
 *
 * The band classes have no general class after them in the dispatcher's
 * chain, so a Cholesky that finds A not positive definite falls back to LU
 * here and says so in the report's note.
 *
 * The band condition estimate does not use dgbcon / dpbcon: both go through
 * dlatbs, whose scaled "careful" solve (taken once the growth bound underflows,
 * i.e. for any long band) calls idamax over the whole vector at every column,
 * which makes them O(n^2): 13 s for n = 200000, kl = ku = 2, against 12 ms for
 * dgbtrf.  band_rcond() runs the same Hager/Higham estimator (dlacn2) through
 * dgbtrs / dpbtrs instead, O(n kd) per step.
 *
 * A complex band matrix always takes the general band LU, zgbtrf / zgbtrs
 * (tridiagonal and Hermitian positive definite ones too: the complex
 * variants of the special cases are not wired), with the complex estimator
 * zlacn2 through zgbtrs ('N' for A^{-1}, 'C' for A^{-H}).
 */
#include "lapack.h"

#include <stdio.h>
#include <string.h>

#define LZ(p) ((lapack_complex_double *)(p))

/* 1 / (||A||_1 * est ||A^{-1}||_1) for a GB or PB factor; -1 if it fails.
 * work holds 2n doubles, iwork n integers. */
static double band_rcond(const lp_factor *F, double norm1, double *work, lapack_int *iwork)
{
    lapack_int n = F->n, kase = 0, isave[3] = {0, 0, 0}, info = 0;
    double est = 0, *v = work, *x = work + n;
    if (n == 0) return -1;
    if (norm1 == 0) return 0;
    if (F->cplx) { /* work holds 2n complex entries here */
        lapack_complex_double *zv = LZ(work), *zx = LZ(work) + n;
        for (;;) {
            LAPACK_zlacn2(&n, zv, zx, &est, &kase, isave);
            if (kase == 0) break;
            info = LAPACKE_zgbtrs_work(LAPACK_COL_MAJOR, kase == 1 ? 'N' : 'C', n, F->kl, F->ku, 1, LZ(F->a),
                                       F->ld, F->ipiv, zx, n);
            if (info) return -1;
        }
        return est > 0 ? 1.0 / (norm1 * est) : -1;
    }
    for (;;) {
        LAPACK_dlacn2(&n, v, x, iwork, &est, &kase, isave);
        if (kase == 0) break;
        /* kase 1 asks for A^{-1} x, kase 2 for A^{-T} x (the same for PB). */
        if (F->kind == LP_GB)
            info = LAPACKE_dgbtrs_work(LAPACK_COL_MAJOR, kase == 1 ? 'N' : 'T', n, F->kl, F->ku, 1, F->a,
                                       F->ld, F->ipiv, x, n);
        else
            info = LAPACKE_dpbtrs_work(LAPACK_COL_MAJOR, 'U', n, F->ku, 1, F->a, F->ld, x, n);
        if (info) return -1;
    }
    return est > 0 ? 1.0 / (norm1 * est) : -1;
}

static int singular(silc_call *call, lp_factor *F, const char *fn, lapack_int info)
{
    lp_factor_free(F);
    if (info > 0)
        return lp_host->error(call, SILC_ESINGULAR,
                              "%s: singular matrix (U(%d,%d) is exactly zero, status %d)", fn, (int)info,
                              (int)info, (int)info);
    return lp_illegal(call, fn, info);
}

/* dpttrf: d | e.  Returns 1 (and keeps F) when A is positive definite, 0 when
 * it is not, negative on an error already reported. */
static int try_pt(silc_call *call, const silc_view *A, double norm1, lp_factor *F)
{
    lapack_int n = F->n, i, info;
    double *d, *e, *work;
    F->a = lp_alloc((size_t)2 * (size_t)LP_LD(n), sizeof(double));
    if (!F->a) return -lp_nomem(call);
    d = F->a;
    e = F->a + LP_LD(n);
    for (i = 0; i < n; i++) {
        d[i] = lp_get(A, i, i);
        if (i + 1 < n) e[i] = lp_get(A, i + 1, i);
    }
    info = LAPACKE_dpttrf_work(n, d, e);
    if (info < 0) return -lp_illegal(call, "dpttrf", info);
    if (info > 0) {
        lp_free(F->a);
        F->a = NULL;
        snprintf(F->note, sizeof F->note, "dpttrf: not positive definite (leading minor %d); used dgttrf",
                 (int)info);
        return 0;
    }
    work = lp_alloc((size_t)LP_LD(n), sizeof(double));
    if (!work) return -lp_nomem(call);
    if (LAPACKE_dptcon_work(n, d, e, norm1, &F->rcond, work)) F->rcond = -1;
    lp_free(work);
    F->kind = LP_PT;
    snprintf(F->method, sizeof F->method, "tridiagonal LDL' (dpttrf)");
    return 1;
}

static int factor_gt(silc_call *call, const silc_view *A, double norm1, lp_factor *F)
{
    lapack_int n = F->n, i, info, *iwork;
    double *dl, *d, *du, *du2, *work;
    size_t ln = (size_t)LP_LD(n);
    F->a = lp_alloc(4 * ln, sizeof(double));
    F->ipiv = lp_alloc(ln, sizeof(lapack_int));
    if (!F->a || !F->ipiv) {
        lp_factor_free(F);
        return lp_nomem(call);
    }
    dl = F->a;
    d = dl + ln;
    du = d + ln;
    du2 = du + ln;
    for (i = 0; i < n; i++) {
        d[i] = lp_get(A, i, i);
        if (i + 1 < n) {
            dl[i] = lp_get(A, i + 1, i);
            du[i] = lp_get(A, i, i + 1);
        }
    }
    info = LAPACKE_dgttrf_work(n, dl, d, du, du2, F->ipiv);
    if (info) return singular(call, F, "dgttrf", info);
    if (lp_con_scratch(n, 2 * n, &work, &iwork)) {
        lp_factor_free(F);
        return lp_nomem(call);
    }
    if (LAPACKE_dgtcon_work('1', n, dl, d, du, du2, F->ipiv, norm1, &F->rcond, work, iwork)) F->rcond = -1;
    lp_free(work);
    lp_free(iwork);
    F->kind = LP_GT;
    snprintf(F->method, sizeof F->method, "tridiagonal LU (dgttrf)");
    return SILC_OK;
}

/* dpbtrf on the upper band, ld = ku + 1; the same contract as try_pt. */
static int try_pb(silc_call *call, const silc_view *A, double norm1, lp_factor *F)
{
    lapack_int n = F->n, kd = F->ku, ld = kd + 1, i, j, info, *iwork;
    double *work;
    F->a = lp_alloc((size_t)ld * (size_t)LP_LD(n), sizeof(double));
    if (!F->a) return -lp_nomem(call);
    for (j = 0; j < n; j++)
        for (i = j - kd > 0 ? j - kd : 0; i <= j; i++) F->a[(kd + i - j) + (size_t)j * ld] = lp_get(A, i, j);
    info = LAPACKE_dpbtrf_work(LAPACK_COL_MAJOR, 'U', n, kd, F->a, ld);
    if (info < 0) return -lp_illegal(call, "dpbtrf", info);
    if (info > 0) {
        lp_free(F->a);
        F->a = NULL;
        snprintf(F->note, sizeof F->note, "dpbtrf: not positive definite (leading minor %d); used dgbtrf",
                 (int)info);
        return 0;
    }
    F->kind = LP_PB;
    F->ld = ld;
    if (lp_con_scratch(n, 2 * n, &work, &iwork)) return -lp_nomem(call);
    F->rcond = band_rcond(F, norm1, work, iwork);
    lp_free(work);
    lp_free(iwork);
    snprintf(F->method, sizeof F->method, "band Cholesky (dpbtrf, kd=%d)", (int)kd);
    return 1;
}

static int factor_gb(silc_call *call, const silc_view *A, double norm1, lp_factor *F)
{
    lapack_int n = F->n, kl = F->kl, ku = F->ku, ld = 2 * kl + ku + 1, i, j, info, *iwork;
    double *work;
    F->a = lp_host->calloc((size_t)ld * (size_t)LP_LD(n) * (size_t)LP_W(F), sizeof(double));
    F->ipiv = lp_alloc((size_t)LP_LD(n), sizeof(lapack_int));
    if (!F->a || !F->ipiv) {
        lp_factor_free(F);
        return lp_nomem(call);
    }
    /* Rows 0..kl-1 of each column are room for the fill-in of pivoting. */
    for (j = 0; j < n; j++) {
        lapack_int lo = j - ku > 0 ? j - ku : 0, hi = j + kl < n - 1 ? j + kl : n - 1;
        for (i = lo; i <= hi; i++) {
            size_t at = (kl + ku + i - j) + (size_t)j * ld;
            if (F->cplx) LZ(F->a)[at] = lp_getz(A, i, j);
            else F->a[at] = lp_get(A, i, j);
        }
    }
    info = F->cplx ? LAPACKE_zgbtrf_work(LAPACK_COL_MAJOR, n, n, kl, ku, LZ(F->a), ld, F->ipiv)
                   : LAPACKE_dgbtrf_work(LAPACK_COL_MAJOR, n, n, kl, ku, F->a, ld, F->ipiv);
    if (info) return singular(call, F, F->cplx ? "zgbtrf" : "dgbtrf", info);
    F->kind = LP_GB;
    F->ld = ld;
    if (lp_con_scratch(n, 2 * n * LP_W(F), &work, &iwork)) {
        lp_factor_free(F);
        return lp_nomem(call);
    }
    F->rcond = band_rcond(F, norm1, work, iwork);
    lp_free(work);
    lp_free(iwork);
    snprintf(F->method, sizeof F->method, "band LU (%cgbtrf, kl=%d, ku=%d)", LP_P(F), (int)kl, (int)ku);
    return SILC_OK;
}

int lp_band(silc_call *call, const silc_view *A, int64_t kl, int64_t ku, int spd_first, double norm1,
            lp_factor **out)
{
    lapack_int n = (lapack_int)A->n;
    int cx = lp_is_complex(call->in[0]), tri = !cx && kl <= 1 && ku <= 1, rc;
    lp_factor *F = lp_factor_new(tri ? LP_GT : LP_GB, n, n);
    if (!F) return lp_nomem(call);
    F->cplx = cx;
    F->kl = (lapack_int)kl;
    F->ku = (lapack_int)ku;
    if (spd_first && kl == ku && !cx) {
        rc = tri ? try_pt(call, A, norm1, F) : try_pb(call, A, norm1, F);
        if (rc < 0) {
            lp_factor_free(F);
            return -rc;
        }
        if (rc == 1) {
            *out = F;
            return SILC_OK;
        }
    }
    rc = tri ? factor_gt(call, A, norm1, F) : factor_gb(call, A, norm1, F);
    if (rc == SILC_OK) *out = F;
    return rc;
}

int lp_band_solve(silc_call *call, const lp_factor *F, double *B, lapack_int ldb, lapack_int nrhs)
{
    lapack_int n = F->n, info;
    size_t ln = (size_t)LP_LD(n);
    const char *fn;
    switch (F->kind) {
    case LP_GB:
        fn = F->cplx ? "zgbtrs" : "dgbtrs";
        info = F->cplx ? LAPACKE_zgbtrs_work(LAPACK_COL_MAJOR, 'N', n, F->kl, F->ku, nrhs, LZ(F->a), F->ld,
                                             F->ipiv, LZ(B), ldb)
                       : LAPACKE_dgbtrs_work(LAPACK_COL_MAJOR, 'N', n, F->kl, F->ku, nrhs, F->a, F->ld,
                                             F->ipiv, B, ldb);
        break;
    case LP_PB:
        fn = "dpbtrs";
        info = LAPACKE_dpbtrs_work(LAPACK_COL_MAJOR, 'U', n, F->ku, nrhs, F->a, F->ld, B, ldb);
        break;
    case LP_GT:
        fn = "dgttrs";
        info = LAPACKE_dgttrs_work(LAPACK_COL_MAJOR, 'N', n, nrhs, F->a, F->a + ln, F->a + 2 * ln,
                                   F->a + 3 * ln, F->ipiv, B, ldb);
        break;
    case LP_PT:
        fn = "dpttrs";
        info = LAPACKE_dpttrs_work(LAPACK_COL_MAJOR, n, nrhs, F->a, F->a + ln, B, ldb);
        break;
    default:
        return lp_host->error(call, SILC_EINTERNAL, "lapack: unknown band factor kind %d", F->kind);
    }
    if (info) return lp_illegal(call, fn, info);
    return SILC_OK;
}
