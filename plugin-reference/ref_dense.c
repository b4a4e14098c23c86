/*
 * ref_dense.c -- dense direct solvers of the reference plugin: LU with partial
 * pivoting, Cholesky, triangular solves, and Householder QR with column
 * pivoting for least squares and minimum-norm problems.
 *
 * All matrices are column-major and every loop runs down columns so the
 * innermost access is contiguous (the unblocked LAPACK variants: dgetf2,
 * dpotf2, dgeqp3's inner step).  Each factor is wrapped in a ref_factor whose
 * solve() also handles the transposed system, which the condition estimator
 * needs.
 */
#include "ref.h"

#include <float.h>
#include <math.h>
#include <stdio.h>
#include <string.h>

/* x := op(T)^{-1} x for the n x n triangle of T (leading dimension ld). */
static void tri_solve(int64_t n, const double *T, int64_t ld, int lower, int unit, int trans,
                      double *x)
{
    if (lower != trans) { /* effectively lower: forward */
        for (int64_t j = 0; j < n; j++) {
            if (!trans) {
                if (!unit) x[j] /= T[j + j * ld];
                double xj = x[j];
                const double *c = T + j * ld;
                for (int64_t i = j + 1; i < n; i++) x[i] -= c[i] * xj;
            } else { /* upper', row j of T' = column j of T above the diagonal */
                const double *c = T + j * ld;
                double s = x[j];
                for (int64_t i = 0; i < j; i++) s -= c[i] * x[i];
                x[j] = unit ? s : s / c[j];
            }
        }
    } else {
        for (int64_t j = n - 1; j >= 0; j--) {
            if (!trans) {
                if (!unit) x[j] /= T[j + j * ld];
                double xj = x[j];
                const double *c = T + j * ld;
                for (int64_t i = 0; i < j; i++) x[i] -= c[i] * xj;
            } else { /* lower' */
                const double *c = T + j * ld;
                double s = x[j];
                for (int64_t i = j + 1; i < n; i++) s -= c[i] * x[i];
                x[j] = unit ? s : s / c[j];
            }
        }
    }
}

/* ---- LU -------------------------------------------------------------------------- */

typedef struct dense_lu {
    int64_t n;
    double *LU;
    int64_t *piv;
} dense_lu;

static void dense_lu_free(void *p)
{
    dense_lu *f = p;
    if (!f) return;
    ref_free(f->LU);
    ref_free(f->piv);
    ref_free(f);
}

static int dense_lu_solve(void *p, double *x, int trans, double *work)
{
    const dense_lu *f = p;
    int64_t n = f->n;
    (void)work;
    if (!trans) {
        for (int64_t k = 0; k < n; k++) {
            double t = x[k];
            x[k] = x[f->piv[k]];
            x[f->piv[k]] = t;
        }
        tri_solve(n, f->LU, n, 1, 1, 0, x);
        tri_solve(n, f->LU, n, 0, 0, 0, x);
    } else {
        tri_solve(n, f->LU, n, 0, 0, 1, x);
        tri_solve(n, f->LU, n, 1, 1, 1, x);
        for (int64_t k = n - 1; k >= 0; k--) {
            double t = x[k];
            x[k] = x[f->piv[k]];
            x[f->piv[k]] = t;
        }
    }
    return 0;
}

int ref_dense_lu(int64_t n, const double *A, ref_factor *F, char *msg, size_t msglen)
{
    dense_lu *f = ref_calloc(1, sizeof(dense_lu));
    if (!f) return SILC_ENOMEM;
    f->n = n;
    f->LU = ref_alloc((size_t)(n * n), sizeof(double));
    f->piv = ref_alloc((size_t)n, sizeof(int64_t));
    if (!f->LU || !f->piv) {
        dense_lu_free(f);
        return SILC_ENOMEM;
    }
    if (n) memcpy(f->LU, A, (size_t)(n * n) * sizeof(double));
    double *a = f->LU;
    for (int64_t k = 0; k < n; k++) {
        if (k % REF_CANCEL_EVERY == REF_CANCEL_EVERY - 1 && ref_cancelled()) {
            snprintf(msg, msglen, REF_STOPPED);
            dense_lu_free(f);
            return SILC_ELIB;
        }
        int64_t p = k;
        double big = fabs(a[k + k * n]);
        for (int64_t i = k + 1; i < n; i++)
            if (fabs(a[i + k * n]) > big) {
                big = fabs(a[i + k * n]);
                p = i;
            }
        f->piv[k] = p;
        if (big == 0.0 || isnan(big)) {
            snprintf(msg, msglen, "dense LU: matrix is singular (zero pivot in column %lld)",
                     (long long)k + 1);
            dense_lu_free(f);
            return SILC_ESINGULAR;
        }
        if (p != k)
            for (int64_t j = 0; j < n; j++) {
                double t = a[k + j * n];
                a[k + j * n] = a[p + j * n];
                a[p + j * n] = t;
            }
        double *ck = a + k * n, d = ck[k];
        for (int64_t i = k + 1; i < n; i++) ck[i] /= d;
        for (int64_t j = k + 1; j < n; j++) {
            double *cj = a + j * n, t = cj[k];
            if (t == 0.0) continue;
            for (int64_t i = k + 1; i < n; i++) cj[i] -= ck[i] * t;
        }
    }
    F->data = f;
    F->solve = dense_lu_solve;
    F->destroy = dense_lu_free;
    snprintf(F->method, sizeof F->method, "dense LU, partial pivoting");
    return 0;
}

/* ---- Cholesky and triangular ------------------------------------------------------ */

typedef struct dense_tri {
    int64_t n;
    double *T;
    int lower;
    int chol; /* solve with T T' (T lower) rather than T */
} dense_tri;

static void dense_tri_free(void *p)
{
    dense_tri *f = p;
    if (!f) return;
    ref_free(f->T);
    ref_free(f);
}

static int dense_tri_apply(void *p, double *x, int trans, double *work)
{
    const dense_tri *f = p;
    (void)work;
    if (f->chol) {
        tri_solve(f->n, f->T, f->n, 1, 0, 0, x);
        tri_solve(f->n, f->T, f->n, 1, 0, 1, x);
    } else {
        tri_solve(f->n, f->T, f->n, f->lower, 0, trans, x);
    }
    return 0;
}

static dense_tri *dense_tri_new(int64_t n, const double *A)
{
    dense_tri *f = ref_calloc(1, sizeof(dense_tri));
    if (!f) return NULL;
    f->n = n;
    f->T = ref_alloc((size_t)(n * n), sizeof(double));
    if (!f->T) {
        ref_free(f);
        return NULL;
    }
    if (n) memcpy(f->T, A, (size_t)(n * n) * sizeof(double));
    return f;
}

int ref_dense_chol(int64_t n, const double *A, ref_factor *F, char *msg, size_t msglen)
{
    dense_tri *f = dense_tri_new(n, A);
    if (!f) return SILC_ENOMEM;
    f->chol = 1;
    f->lower = 1;
    double *L = f->T;
    /* left-looking: column j gets the updates of columns k < j, then scales */
    for (int64_t j = 0; j < n; j++) {
        if (j % REF_CANCEL_EVERY == REF_CANCEL_EVERY - 1 && ref_cancelled()) {
            snprintf(msg, msglen, REF_STOPPED);
            dense_tri_free(f);
            return SILC_ELIB;
        }
        double *cj = L + j * n;
        for (int64_t i = 0; i < j; i++) cj[i] = 0.0; /* the upper triangle is not read */
        for (int64_t k = 0; k < j; k++) {
            const double *ck = L + k * n;
            double t = ck[j];
            if (t == 0.0) continue;
            for (int64_t i = j; i < n; i++) cj[i] -= ck[i] * t;
        }
        double d = cj[j];
        if (!(d > 0.0) || !isfinite(d)) {
            snprintf(msg, msglen, "dense Cholesky: not positive definite (pivot %lld)", (long long)j + 1);
            dense_tri_free(f);
            return SILC_ENOTSPD;
        }
        d = sqrt(d);
        cj[j] = d;
        for (int64_t i = j + 1; i < n; i++) cj[i] /= d;
    }
    F->data = f;
    F->solve = dense_tri_apply;
    F->destroy = dense_tri_free;
    snprintf(F->method, sizeof F->method, "dense Cholesky");
    return 0;
}

int ref_dense_tri(int64_t n, const double *A, int lower, ref_factor *F, char *msg, size_t msglen)
{
    for (int64_t k = 0; k < n; k++)
        if (A[k + k * n] == 0.0) {
            snprintf(msg, msglen, "singular triangular matrix: zero diagonal entry at row %lld", (long long)k + 1);
            return SILC_ESINGULAR;
        }
    dense_tri *f = dense_tri_new(n, A);
    if (!f) return SILC_ENOMEM;
    f->lower = lower;
    F->data = f;
    F->solve = dense_tri_apply;
    F->destroy = dense_tri_free;
    snprintf(F->method, sizeof F->method, "dense triangular, %s substitution", lower ? "forward" : "back");
    return 0;
}

/* ---- Householder QR with column pivoting ----------------------------------------- */

typedef struct dense_qr {
    int64_t m, n;       /* of A */
    int64_t rows, cols; /* of the factored matrix: A (m >= n) or A' (m < n) */
    int64_t kmax, rank;
    double *QR, *tau;
    int64_t *jpvt;
} dense_qr;

static void dense_qr_free(void *p)
{
    dense_qr *f = p;
    if (!f) return;
    ref_free(f->QR);
    ref_free(f->tau);
    ref_free(f->jpvt);
    ref_free(f);
}

/* x := H_k x with H_k = I - tau v v', v = [1; QR(k+1:rows, k)]. */
static void apply_h(const dense_qr *f, int64_t k, double *x)
{
    const double *v = f->QR + k * f->rows;
    double w = x[k];
    for (int64_t i = k + 1; i < f->rows; i++) w += v[i] * x[i];
    w *= f->tau[k];
    x[k] -= w;
    for (int64_t i = k + 1; i < f->rows; i++) x[i] -= v[i] * w;
}

/* Least squares (m >= n): x = P [R11^{-1} (Q'b)(1:r); 0].  Minimum norm
 * (m < n, A'P = QR): R11' y = (P'b)(1:r), x = Q [y; 0]. */
static int dense_qr_solve(void *p, double *x, int trans, double *work)
{
    const dense_qr *f = p;
    int64_t r = f->rank;
    (void)trans;
    if (f->m >= f->n) {
        for (int64_t k = 0; k < f->kmax; k++) apply_h(f, k, x);
        tri_solve(r, f->QR, f->rows, 0, 0, 0, x);
        for (int64_t k = 0; k < f->n; k++) work[k] = k < r ? x[k] : 0.0;
        for (int64_t k = 0; k < f->n; k++) x[f->jpvt[k]] = work[k];
    } else {
        for (int64_t k = 0; k < f->m; k++) work[k] = x[f->jpvt[k]];
        tri_solve(r, f->QR, f->rows, 0, 0, 1, work);
        for (int64_t k = 0; k < f->n; k++) x[k] = k < r ? work[k] : 0.0;
        for (int64_t k = f->kmax - 1; k >= 0; k--) apply_h(f, k, x);
    }
    return 0;
}

static int r11_apply(void *p, double *x, int trans, double *work)
{
    const dense_qr *f = p;
    (void)work;
    tri_solve(f->rank, f->QR, f->rows, 0, 0, trans, x);
    return 0;
}

int ref_dense_qr(int64_t m, int64_t n, const double *A, ref_factor *F, char *msg, size_t msglen)
{
    dense_qr *f = ref_calloc(1, sizeof(dense_qr));
    if (!f) return SILC_ENOMEM;
    f->m = m;
    f->n = n;
    f->rows = m >= n ? m : n;
    f->cols = m >= n ? n : m;
    int64_t rows = f->rows, cols = f->cols;
    f->kmax = cols;
    f->QR = ref_alloc((size_t)(rows * cols), sizeof(double));
    f->tau = ref_calloc((size_t)cols, sizeof(double));
    f->jpvt = ref_alloc((size_t)cols, sizeof(int64_t));
    double *vn1 = ref_alloc((size_t)cols, sizeof(double)), *vn2 = ref_alloc((size_t)cols, sizeof(double));
    if (!f->QR || !f->tau || !f->jpvt || !vn1 || !vn2) {
        ref_free(vn1);
        ref_free(vn2);
        dense_qr_free(f);
        return SILC_ENOMEM;
    }
    double *a = f->QR;
    for (int64_t j = 0; j < n; j++)
        for (int64_t i = 0; i < m; i++) {
            if (m >= n) a[i + j * rows] = A[i + j * m];
            else a[j + i * rows] = A[i + j * m];
        }
    for (int64_t j = 0; j < cols; j++) {
        f->jpvt[j] = j;
        vn1[j] = vn2[j] = ref_nrm2(rows, a + j * rows, 1);
    }
    for (int64_t k = 0; k < cols; k++) {
        if (k % REF_CANCEL_EVERY == REF_CANCEL_EVERY - 1 && ref_cancelled()) {
            snprintf(msg, msglen, REF_STOPPED);
            ref_free(vn1);
            ref_free(vn2);
            dense_qr_free(f);
            return SILC_ELIB;
        }
        int64_t p = k;
        for (int64_t j = k + 1; j < cols; j++)
            if (vn1[j] > vn1[p]) p = j;
        if (p != k) {
            for (int64_t i = 0; i < rows; i++) {
                double t = a[i + k * rows];
                a[i + k * rows] = a[i + p * rows];
                a[i + p * rows] = t;
            }
            int64_t t = f->jpvt[k];
            f->jpvt[k] = f->jpvt[p];
            f->jpvt[p] = t;
            vn1[p] = vn1[k];
            vn2[p] = vn2[k];
        }
        double *ck = a + k * rows, alpha = ck[k];
        double xnorm = k + 1 < rows ? ref_nrm2(rows - k - 1, ck + k + 1, 1) : 0.0;
        if (xnorm == 0.0) {
            f->tau[k] = 0.0;
        } else {
            double beta = -copysign(hypot(alpha, xnorm), alpha);
            f->tau[k] = (beta - alpha) / beta;
            double s = 1.0 / (alpha - beta);
            for (int64_t i = k + 1; i < rows; i++) ck[i] *= s;
            ck[k] = beta;
        }
        for (int64_t j = k + 1; j < cols; j++) {
            apply_h(f, k, a + j * rows);
            if (vn1[j] != 0.0) { /* downdate the remaining column norm (LAPACK dlaqp2) */
                double t = fabs(a[k + j * rows]) / vn1[j];
                t = 1.0 - t * t;
                if (t < 0) t = 0;
                double t2 = t * (vn1[j] / vn2[j]) * (vn1[j] / vn2[j]);
                if (t2 <= sqrt(DBL_EPSILON)) {
                    vn1[j] = k + 1 < rows ? ref_nrm2(rows - k - 1, a + k + 1 + j * rows, 1) : 0.0;
                    vn2[j] = vn1[j];
                } else {
                    vn1[j] *= sqrt(t);
                }
            }
        }
    }
    ref_free(vn1);
    ref_free(vn2);
    double r00 = cols ? fabs(a[0]) : 0.0, tol = (double)rows * DBL_EPSILON * r00;
    f->rank = 0;
    while (f->rank < cols && fabs(a[f->rank + f->rank * rows]) > tol) f->rank++;
    F->data = f;
    F->solve = dense_qr_solve;
    F->destroy = dense_qr_free;
    F->work_len = rows;
    snprintf(F->method, sizeof F->method, "dense Householder QR, column pivoting%s",
             m < n ? ", minimum norm" : "");
    if (f->rank < cols)
        snprintf(F->note, sizeof F->note, "rank deficient: rank %lld of %lld", (long long)f->rank,
                 (long long)cols);
    /* cond_2(A) = cond_2(R); estimate it in the 1-norm of R11 */
    double rn = 0.0;
    for (int64_t j = 0; j < f->rank; j++) {
        double s = 0.0;
        for (int64_t i = 0; i <= j; i++) s += fabs(a[i + j * rows]);
        rn = fmax(rn, s);
    }
    double est = f->rank ? ref_inv_norm1_est(f->rank, r11_apply, f, NULL) : 0.0;
    if (est < 0) { /* out of memory: without the estimate no warning of a singular matrix */
        dense_qr_free(f);
        F->data = NULL;
        return SILC_ENOMEM;
    }
    F->cond = f->rank ? ref_cond_from(rn, est) : INFINITY;
    if (f->rank < cols && F->cond >= 0) F->cond = INFINITY;
    (void)msg;
    (void)msglen;
    return 0;
}
