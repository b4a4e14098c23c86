/*
 * ref_qr.c -- sparse least squares and minimum-norm solutions for the
 * reference plugin: Q-less QR by Givens rotations, row by row (George and
 * Heath), with corrected semi-normal equations.
 *
 * For m >= n the factored matrix is M = A, for m < n it is M = A'.  Its
 * columns are ordered by AMD on M'M; the pattern of R is that of the Cholesky
 * factor of M'M, known in advance from the elimination tree, so every row of
 * M is rotated into preallocated rows of R and Q is never stored.  Solutions
 * use R only (Bjorck's corrected semi-normal equations):
 *   m >= n:  x = R \ (R' \ (M'b)), then x += R \ (R' \ (M'(b - M x))) twice;
 *   m <  n:  y = R \ (R' \ b), x = M y (the minimum-norm solution), refined
 *            the same way on the residual b - A x.
 * A diagonal entry of R below max(m,n)*eps*max|R_jj| marks a column that is
 * (numerically) a combination of earlier ones: such columns are dropped and
 * the rest refactored, giving the basic solution with zeros there (for m < n
 * the dropped columns of A' are dependent equations).
 */
#include "ref.h"

#include <float.h>
#include <math.h>
#include <stdio.h>
#include <string.h>

typedef struct sp_qr {
    int64_t m, n;   /* of A */
    int under;      /* m < n: M = A' */
    int64_t nk;     /* columns of M kept */
    int64_t *colmap;/* column k of Mp is column colmap[k] of M */
    ref_sp Mp;      /* M(:, colmap) */
    ref_sp L;       /* R' (column j = row j of R, diagonal first) */
} sp_qr;

static void sp_qr_free(void *p)
{
    sp_qr *f = p;
    if (!f) return;
    ref_free(f->colmap);
    ref_sp_free(&f->Mp);
    ref_sp_free(&f->L);
    ref_free(f);
}

/* x := (R'R)^{-1} x */
static void rtr_solve(const ref_sp *L, double *x)
{
    int64_t n = L->n;
    for (int64_t j = 0; j < n; j++) {
        x[j] /= L->x[L->p[j]];
        double t = x[j];
        for (int64_t q = L->p[j] + 1; q < L->p[j + 1]; q++) x[L->i[q]] -= L->x[q] * t;
    }
    for (int64_t j = n - 1; j >= 0; j--) {
        double t = x[j];
        for (int64_t q = L->p[j] + 1; q < L->p[j + 1]; q++) t -= L->x[q] * x[L->i[q]];
        x[j] = t / L->x[L->p[j]];
    }
}

/* R x = b (trans 0) or R' x = b (trans 1), for the condition estimate. */
static int r_apply(void *p, double *x, int trans, double *work)
{
    const ref_sp *L = &((const sp_qr *)p)->L;
    int64_t n = L->n;
    (void)work;
    if (trans) {
        for (int64_t j = 0; j < n; j++) {
            x[j] /= L->x[L->p[j]];
            double t = x[j];
            for (int64_t q = L->p[j] + 1; q < L->p[j + 1]; q++) x[L->i[q]] -= L->x[q] * t;
        }
    } else {
        for (int64_t j = n - 1; j >= 0; j--) {
            double t = x[j];
            for (int64_t q = L->p[j] + 1; q < L->p[j + 1]; q++) t -= L->x[q] * x[L->i[q]];
            x[j] = t / L->x[L->p[j]];
        }
    }
    return 0;
}

static void mul(const ref_sp *M, const double *y, double *out) /* out = M y */
{
    memset(out, 0, (size_t)M->m * sizeof(double));
    for (int64_t k = 0; k < M->n; k++)
        for (int64_t p = M->p[k]; p < M->p[k + 1]; p++) out[M->i[p]] += M->x[p] * y[k];
}

static void mul_t(const ref_sp *M, const double *r, double *out) /* out = M' r */
{
    for (int64_t k = 0; k < M->n; k++) {
        double s = 0.0;
        for (int64_t p = M->p[k]; p < M->p[k + 1]; p++) s += M->x[p] * r[M->i[p]];
        out[k] = s;
    }
}

static int sp_qr_solve(void *p, double *x, int trans, double *w)
{
    const sp_qr *f = p;
    const ref_sp *M = &f->Mp;
    int64_t rows = M->m, nk = f->nk;
    double *b = w, *r = w + rows, *z = r + rows, *t = z + nk, *big = t + nk;
    (void)trans;
    if (!f->under) {
        memcpy(b, x, (size_t)rows * sizeof(double));
        mul_t(M, b, z);
        rtr_solve(&f->L, z);
        for (int it = 0; it < 2; it++) {
            mul(M, z, r);
            for (int64_t i = 0; i < rows; i++) r[i] = b[i] - r[i];
            mul_t(M, r, t);
            rtr_solve(&f->L, t);
            for (int64_t k = 0; k < nk; k++) z[k] += t[k];
        }
        memset(x, 0, (size_t)f->n * sizeof(double));
        for (int64_t k = 0; k < nk; k++) x[f->colmap[k]] = z[k];
    } else {
        for (int64_t k = 0; k < nk; k++) b[k] = x[f->colmap[k]];
        memcpy(z, b, (size_t)nk * sizeof(double));
        rtr_solve(&f->L, z);
        mul(M, z, big);
        for (int it = 0; it < 2; it++) {
            mul_t(M, big, t);
            for (int64_t k = 0; k < nk; k++) t[k] = b[k] - t[k];
            rtr_solve(&f->L, t);
            mul(M, t, r);
            for (int64_t i = 0; i < rows; i++) big[i] += r[i];
        }
        memcpy(x, big, (size_t)rows * sizeof(double));
    }
    return 0;
}

/* Column-subset copy M(:, cols[0..nc-1]). */
static int extract_cols(const ref_sp *M, const int64_t *cols, int64_t nc, ref_sp *out)
{
    int64_t nz = 0;
    for (int64_t k = 0; k < nc; k++) nz += M->p[cols[k] + 1] - M->p[cols[k]];
    if (ref_sp_alloc(out, M->m, nc, nz, 1)) return SILC_ENOMEM;
    nz = 0;
    for (int64_t k = 0; k < nc; k++) {
        out->p[k] = nz;
        for (int64_t p = M->p[cols[k]]; p < M->p[cols[k] + 1]; p++) {
            out->i[nz] = M->i[p];
            out->x[nz++] = M->x[p];
        }
    }
    out->p[nc] = nz;
    return 0;
}

/* Factor M(:, keep): order, symbolic, Givens.  Fills f->colmap, Mp, L. */
static int qr_factor(const ref_sp *M, const int64_t *keep, int64_t nk, sp_qr *f)
{
    ref_sp Ms = {0}, S = {0}, C = {0}, T = {0};
    int64_t *q = ref_alloc((size_t)nk, sizeof(int64_t));
    double *w = ref_calloc((size_t)nk, sizeof(double));
    char *init = ref_calloc((size_t)nk, 1);
    int st = SILC_ENOMEM;
    if (!q || !w || !init) goto done;
    if (extract_cols(M, keep, nk, &Ms) || ref_pattern_ata(&Ms, 1, &S) || ref_amd(&S, q)) goto done;
    ref_sp_free(&S);
    f->nk = nk;
    f->colmap = ref_alloc((size_t)nk, sizeof(int64_t));
    if (!f->colmap) goto done;
    for (int64_t k = 0; k < nk; k++) {
        f->colmap[k] = keep[q[k]];
        q[k] = f->colmap[k];
    }
    if (extract_cols(M, q, nk, &f->Mp) || ref_pattern_ata(&f->Mp, 0, &S)) goto done;
    /* upper triangle plus diagonal of the pattern of Mp'Mp */
    int64_t cz = nk;
    for (int64_t j = 0; j < nk; j++)
        for (int64_t p = S.p[j]; p < S.p[j + 1]; p++) cz += S.i[p] < j;
    if (ref_sp_alloc(&C, nk, nk, cz, 0)) goto done;
    cz = 0;
    for (int64_t j = 0; j < nk; j++) {
        C.p[j] = cz;
        for (int64_t p = S.p[j]; p < S.p[j + 1]; p++)
            if (S.i[p] < j) C.i[cz++] = S.i[p];
        C.i[cz++] = j;
    }
    C.p[nk] = cz;
    ref_sp_free(&S);
    if (ref_symbolic_chol(&C, &f->L)) goto done;
    ref_sp *L = &f->L;
    L->x = ref_calloc((size_t)L->p[nk], sizeof(double));
    if (!L->x || ref_sp_transpose(&f->Mp, &T)) goto done;
    /* rotate each row of Mp into R */
    for (int64_t r = 0; r < T.n; r++) {
        int64_t j = nk;
        for (int64_t p = T.p[r]; p < T.p[r + 1]; p++) {
            w[T.i[p]] += T.x[p];
            if (T.i[p] < j) j = T.i[p];
        }
        while (j < nk) {
            int64_t p0 = L->p[j], p1 = L->p[j + 1];
            if (!init[j]) {
                init[j] = 1;
                for (int64_t p = p0; p < p1; p++) {
                    L->x[p] = w[L->i[p]];
                    w[L->i[p]] = 0.0;
                }
                break;
            }
            double a = L->x[p0], bb = w[j], h = hypot(a, bb), c = a / h, s = bb / h;
            if (h == 0.0) {
                c = 1.0;
                s = 0.0;
            }
            int64_t next = nk;
            L->x[p0] = h;
            w[j] = 0.0;
            for (int64_t p = p0 + 1; p < p1; p++) {
                int64_t col = L->i[p];
                double rv = L->x[p], wv = w[col];
                L->x[p] = c * rv + s * wv;
                w[col] = c * wv - s * rv;
                if (next == nk && w[col] != 0.0) next = col;
            }
            j = next;
        }
    }
    st = 0;
done:
    ref_sp_free(&Ms);
    ref_sp_free(&S);
    ref_sp_free(&C);
    ref_sp_free(&T);
    ref_free(q);
    ref_free(w);
    ref_free(init);
    return st;
}

int ref_sparse_qr(const ref_sp *A, ref_factor *F, char *msg, size_t msglen)
{
    sp_qr *f = ref_calloc(1, sizeof(sp_qr));
    ref_sp At = {0};
    int64_t *keep = NULL;
    int st = SILC_ENOMEM;
    if (!f) return SILC_ENOMEM;
    f->m = A->m;
    f->n = A->n;
    f->under = A->m < A->n;
    if (f->under && ref_sp_transpose(A, &At)) goto fail;
    const ref_sp *M = f->under ? &At : A;
    int64_t N = M->n, rows = M->m, nk = N;
    keep = ref_alloc((size_t)N, sizeof(int64_t));
    if (!keep) goto fail;
    for (int64_t k = 0; k < N; k++) keep[k] = k;
    for (int round = 0;; round++) {
        if (qr_factor(M, keep, nk, f)) goto fail;
        double rmax = 0.0;
        for (int64_t j = 0; j < nk; j++) rmax = fmax(rmax, fabs(f->L.x[f->L.p[j]]));
        double tol = (double)(rows > N ? rows : N) * DBL_EPSILON * rmax;
        int64_t nkeep = 0;
        for (int64_t j = 0; j < nk; j++)
            if (fabs(f->L.x[f->L.p[j]]) > tol) keep[nkeep++] = f->colmap[j];
        if (nkeep == nk) break;
        if (nkeep == 0 || round == 4) {
            snprintf(msg, msglen, "sparse QR: matrix has numerical rank 0 or its rank could not be settled");
            st = SILC_ESINGULAR;
            goto fail;
        }
        /* keep the surviving columns in their original order, then refactor */
        for (int64_t a = 1; a < nkeep; a++) {
            int64_t v = keep[a], b = a;
            while (b > 0 && keep[b - 1] > v) {
                keep[b] = keep[b - 1];
                b--;
            }
            keep[b] = v;
        }
        nk = nkeep;
        ref_free(f->colmap);
        f->colmap = NULL;
        ref_sp_free(&f->Mp);
        ref_sp_free(&f->L);
    }
    ref_sp_free(&At);
    ref_free(keep);
    keep = NULL;
    F->data = f;
    F->solve = sp_qr_solve;
    F->destroy = sp_qr_free;
    F->work_len = 3 * rows + 2 * N + 2;
    snprintf(F->method, sizeof F->method, "sparse Q-less QR (Givens), AMD(M'M), CSNE%s",
             f->under ? ", minimum norm" : "");
    if (f->nk < N)
        snprintf(F->note, sizeof F->note, "rank deficient: rank %lld of %lld", (long long)f->nk, (long long)N);
    /* Out of memory here fails the factorization: without ||R||_1 the
     * estimate would say "singular", without the estimate no warning. */
    double rn = 0.0, est, *rs = ref_calloc((size_t)f->nk + 1, sizeof(double));
    if (!rs) goto fail_factored;
    /* ||R||_1 = largest column sum of R = largest row sum of L */
    for (int64_t j = 0; j < f->nk; j++)
        for (int64_t p = f->L.p[j]; p < f->L.p[j + 1]; p++) rs[f->L.i[p]] += fabs(f->L.x[p]);
    for (int64_t j = 0; j < f->nk; j++) rn = fmax(rn, rs[j]);
    ref_free(rs);
    if ((est = ref_inv_norm1_est(f->nk, r_apply, f, NULL)) < 0) goto fail_factored;
    F->cond = ref_cond_from(rn, est);
    if (f->nk < N && F->cond >= 0) F->cond = INFINITY;
    return 0;
fail_factored:
    F->data = NULL;
    st = SILC_ENOMEM;
fail:
    ref_sp_free(&At);
    ref_free(keep);
    sp_qr_free(f);
    return st;
}
