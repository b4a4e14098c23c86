/*
 * lis_precond.c -- the preconditioners: Jacobi, ILU(k), IC(0), SSOR, ILUT,
 * and SA-AMG through lis_amg.c.
 *
 * The incomplete factorizations share one form, M = (I + L)(D + U) with L
 * strictly lower (multipliers), U strictly upper and D diagonal, kept in CSR
 * with 1/D, so one pair of triangular solves (and its transpose, for BiCG)
 * serves them all:
 *   ILU(k)  row-wise IKJ elimination keeping fill of level <= k (level of a
 *           fill entry = lev(i,k) + lev(k,j) + 1, original entries level 0);
 *   IC(0)   the ILU(0) elimination of a symmetric A, with U replaced by D L'
 *           so that M = (I + L) D (I + L)' is exactly symmetric, and every
 *           pivot required positive (an incomplete LDL');
 *   ILUT    Saad's dual threshold: entries below drop * ||a_i||_2 are
 *           dropped, and each row of L and of U keeps at most
 *           ceil(rate * nnz(a_i) / 2) of the largest.
 * An incomplete factorization can meet a zero or (IC) non-positive pivot on
 * a matrix that is nonsingular (or SPD); then it is recomputed for
 * A + alpha diag(|A|) with alpha = 1e-3, 1e-2, 1e-1, 1 (Manteuffel's shift)
 * and the shift used is reported.  SSOR and Jacobi use A's diagonal and need
 * it nonzero.  Triangular solves are sequential by nature.
 *
 * Everything but SA-AMG and M^-T is written once in lis_precond_t.h and
 * included here twice, real and complex (ABI 1.8's complex values: Jacobi,
 * ILU(k), ILUT and SSOR in complex arithmetic, pivots judged by modulus).
 */
#include "lis.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

void *lis_array(size_t count, size_t size)
{
    if (count == 0) count = 1;
    if (count > SIZE_MAX / size) return NULL;
    return lis_host->alloc(count * size);
}

static void xfree(void *p)
{
    if (p) lis_host->free(p);
}

void lis_pc_free(void *p)
{
    lis_pc *P = p;
    if (!P) return;
    xfree(P->dinv);
    xfree(P->lp);
    xfree(P->li);
    xfree(P->lx);
    xfree(P->up);
    xfree(P->ui);
    xfree(P->ux);
    lis_amg_free(P->amg);
    xfree(P);
}

/* Inserts column j after position `from` in the sorted list next (j > from). */
static void list_insert(int64_t *next, int64_t from, int64_t j)
{
    int64_t p = from;
    while (next[p] != -1 && next[p] < j) p = next[p];
    next[j] = next[p];
    next[p] = j;
}

enum { FACT_OK = 0, FACT_NOMEM = -1, FACT_PIVOT = 1 };

#define LIS_COMPLEX
#include "lis_field.h"
#include "lis_precond_t.h"
#undef LIS_COMPLEX
#include "lis_field.h"
#include "lis_precond_t.h"

/* ---- building ---------------------------------------------------------------------- */

/* The driver of both fields: SA-AMG (real only) or pc_setup / pc_setup_z. */
static int pc_build(const lk_csr *A, const lis_options *o, int cplx, lis_pc **out, char *err, size_t errlen)
{
    double t0 = lis_host->now();
    lis_pc *P = lis_host->calloc(1, sizeof *P);
    char label[48];
    int rc;
    *out = NULL;
    lis_precon_label(o, label, sizeof label);
    if (!P) return snprintf(err, errlen, "lis-style: out of memory for the preconditioner"), SILC_ENOMEM;
    P->kind = o->precon;
    P->n = A->m;
    P->cplx = cplx;
    if (o->precon == LIS_PC_SAAMG)
        rc = cplx ? (snprintf(err, errlen, "lis-style %s: not for complex values", label), SILC_EARG)
                  : lis_amg_build(A, o->saamg_theta, &P->amg, &P->nnz, err, errlen);
    else if (cplx && o->precon == LIS_PC_IC)
        rc = (snprintf(err, errlen, "lis-style %s: not for complex values (use -p ilu)", label), SILC_EARG);
    else
        rc = cplx ? pc_setup_z(A, o, P, label, err, errlen) : pc_setup(A, o, P, label, err, errlen);
    if (rc) {
        lis_pc_free(P);
        return rc;
    }
    P->seconds = lis_host->now() - t0;
    *out = P;
    return SILC_OK;
}

int lis_pc_build(const lk_csr *A, const lis_options *o, lis_pc **out, char *err, size_t errlen)
{
    return pc_build(A, o, 0, out, err, errlen);
}

int lis_pc_build_z(const lk_csr *A, const lis_options *o, lis_pc **out, char *err, size_t errlen)
{
    return pc_build(A, o, 1, out, err, errlen);
}

/* ---- applying ----------------------------------------------------------------------- */

void lis_pc_apply(const lis_pc *P, const double *x, double *y)
{
    if (P->kind == LIS_PC_SAAMG) lis_amg_apply(P->amg, x, y);
    else if (P->cplx) pc_apply_z(P, (const double complex *)x, (double complex *)y);
    else pc_apply(P, x, y);
}

void lis_pc_apply_t(const lis_pc *P, const double *x, double *y)
{
    int64_t n = P->n, i, k;
    if (P->kind == LIS_PC_JACOBI || P->kind == LIS_PC_SAAMG) { /* symmetric M */
        lis_pc_apply(P, x, y);
    } else if (P->kind == LIS_PC_SSOR) {
        /* M' = (D + wU') D^-1 (D + wL') / (w (2 - w)): column sweeps over the rows. */
        const lk_csr *A = &P->A;
        double w = P->omega, c = w * (2 - w);
        for (i = 0; i < n; i++) y[i] = c * x[i];
        for (i = 0; i < n; i++) {
            y[i] *= P->dinv[i];
            for (k = A->rp[i + 1] - 1; k >= A->rp[i] && A->ci[k] > i; k--) y[A->ci[k]] -= w * A->v[k] * y[i];
        }
        for (i = 0; i < n; i++) y[i] /= P->dinv[i];
        for (i = n - 1; i >= 0; i--) {
            y[i] *= P->dinv[i];
            for (k = A->rp[i]; k < A->rp[i + 1] && A->ci[k] < i; k++) y[A->ci[k]] -= w * A->v[k] * y[i];
        }
    } else {
        /* M' = (D + U')(I + L'): (D + U') t = x forward, (I + L') y = t backward. */
        for (i = 0; i < n; i++) y[i] = x[i];
        for (i = 0; i < n; i++) {
            y[i] *= P->dinv[i];
            for (k = P->up[i]; k < P->up[i + 1]; k++) y[P->ui[k]] -= P->ux[k] * y[i];
        }
        for (i = n - 1; i >= 0; i--)
            for (k = P->lp[i]; k < P->lp[i + 1]; k++) y[P->li[k]] -= P->lx[k] * y[i];
    }
}
