/*
 * ref_sparse.c -- sparse direct solvers of the reference plugin: triangular
 * substitution, up-looking Cholesky and left-looking LU with partial pivoting,
 * in the spirit of CSparse (Davis, "Direct Methods for Sparse Linear
 * Systems", 2006) but written for this plugin.
 *
 * Cholesky orders P A P' by approximate minimum degree, computes the
 * elimination tree and the exact column counts of L (the row patterns come
 * from walking the tree: "ereach"), then computes L one row at a time.  LU
 * chooses a column order by AMD, on A+A' with a preference for diagonal pivots
 * when A is nearly structurally symmetric with a zero-free diagonal (the
 * UMFPACK symmetric strategy), on A'A with plain partial pivoting otherwise;
 * each column is a sparse triangular solve whose pattern comes from a
 * depth-first search of the graph of L.  A column with no usable pivot is
 * reported as singular, never divided by.
 */
#include "ref.h"

#include <math.h>
#include <stdio.h>
#include <string.h>

/* ---- triangular ------------------------------------------------------------------ */

typedef struct sp_tri {
    ref_sp A;
    int64_t *dpos; /* position of the diagonal entry in each column */
    int lower;
} sp_tri;

static void sp_tri_free(void *p)
{
    sp_tri *f = p;
    if (!f) return;
    ref_sp_free(&f->A);
    ref_free(f->dpos);
    ref_free(f);
}

static int sp_tri_solve(void *p, double *x, int trans, double *work)
{
    const sp_tri *f = p;
    const ref_sp *A = &f->A;
    int64_t n = A->n;
    (void)work;
    int forward = f->lower != trans;
    for (int64_t s = 0; s < n; s++) {
        int64_t j = forward ? s : n - 1 - s;
        if (!trans) {
            x[j] /= A->x[f->dpos[j]];
            double xj = x[j];
            for (int64_t q = A->p[j]; q < A->p[j + 1]; q++) {
                int64_t i = A->i[q];
                if (f->lower ? i > j : i < j) x[i] -= A->x[q] * xj;
            }
        } else {
            double t = x[j];
            for (int64_t q = A->p[j]; q < A->p[j + 1]; q++) {
                int64_t i = A->i[q];
                if (f->lower ? i > j : i < j) t -= A->x[q] * x[i];
            }
            x[j] = t / A->x[f->dpos[j]];
        }
    }
    return 0;
}

int ref_sparse_tri(const ref_sp *A, int lower, ref_factor *F, char *msg, size_t msglen)
{
    int64_t n = A->n, nz = ref_sp_nnz(A);
    sp_tri *f = ref_calloc(1, sizeof(sp_tri));
    if (!f) return SILC_ENOMEM;
    f->lower = lower;
    f->dpos = ref_alloc((size_t)n, sizeof(int64_t));
    if (!f->dpos || ref_sp_alloc(&f->A, n, n, nz, 1)) {
        sp_tri_free(f);
        return SILC_ENOMEM;
    }
    memcpy(f->A.p, A->p, (size_t)(n + 1) * sizeof(int64_t));
    if (nz) {
        memcpy(f->A.i, A->i, (size_t)nz * sizeof(int64_t));
        memcpy(f->A.x, A->x, (size_t)nz * sizeof(double));
    }
    for (int64_t j = 0; j < n; j++) {
        f->dpos[j] = -1;
        for (int64_t q = A->p[j]; q < A->p[j + 1]; q++)
            if (A->i[q] == j && A->x[q] != 0.0) f->dpos[j] = q;
        if (f->dpos[j] < 0) {
            snprintf(msg, msglen, "singular triangular matrix: zero diagonal entry at row %lld", (long long)j + 1);
            sp_tri_free(f);
            return SILC_ESINGULAR;
        }
    }
    F->data = f;
    F->solve = sp_tri_solve;
    F->destroy = sp_tri_free;
    snprintf(F->method, sizeof F->method, "sparse triangular, %s substitution",
             lower ? "forward" : "back");
    return 0;
}

/* ---- Cholesky ---------------------------------------------------------------------- */

/* Pattern of row k of L (columns < k), topologically ordered, in s[top..n-1]. */
static int64_t ereach(const ref_sp *C, int64_t k, const int64_t *parent, int64_t *s, int64_t *w)
{
    int64_t n = C->n, top = n;
    w[k] = k;
    for (int64_t p = C->p[k]; p < C->p[k + 1]; p++) {
        int64_t i = C->i[p], len = 0;
        if (i > k) continue;
        for (; w[i] != k; i = parent[i]) {
            s[len++] = i;
            w[i] = k;
        }
        while (len > 0) s[--top] = s[--len];
    }
    return top;
}

/* Column pointers of L (diagonal included) from the row patterns. */
static int chol_counts(const ref_sp *C, const int64_t *parent, int64_t *Lp, int64_t *s, int64_t *w)
{
    int64_t n = C->n;
    for (int64_t j = 0; j <= n; j++) Lp[j] = 0;
    for (int64_t j = 0; j < n; j++) w[j] = -1;
    for (int64_t k = 0; k < n; k++) {
        for (int64_t top = ereach(C, k, parent, s, w); top < n; top++) Lp[s[top]]++;
        Lp[k]++;
    }
    int64_t sum = 0;
    for (int64_t j = 0; j < n; j++) {
        int64_t c = Lp[j];
        Lp[j] = sum;
        sum += c;
    }
    Lp[n] = sum;
    return 0;
}

int ref_symbolic_chol(const ref_sp *C, ref_sp *L)
{
    int64_t n = C->n;
    int64_t *parent = ref_alloc((size_t)n, sizeof(int64_t)), *s = ref_alloc((size_t)n, sizeof(int64_t));
    int64_t *w = ref_alloc((size_t)n, sizeof(int64_t)), *Lp = ref_alloc((size_t)n + 1, sizeof(int64_t));
    int st = SILC_ENOMEM;
    L->p = L->i = NULL;
    L->x = NULL;
    L->owned = 0;
    if (!parent || !s || !w || !Lp || ref_etree(C, parent)) goto done;
    chol_counts(C, parent, Lp, s, w);
    if (ref_sp_alloc(L, n, n, Lp[n], 0)) goto done;
    memcpy(L->p, Lp, (size_t)(n + 1) * sizeof(int64_t));
    for (int64_t j = 0; j < n; j++) {
        Lp[j] = L->p[j];
        w[j] = -1;
    }
    for (int64_t k = 0; k < n; k++) {
        for (int64_t top = ereach(C, k, parent, s, w); top < n; top++) L->i[Lp[s[top]]++] = k;
        L->i[Lp[k]++] = k;
    }
    st = 0;
done:
    ref_free(parent);
    ref_free(s);
    ref_free(w);
    ref_free(Lp);
    return st;
}

typedef struct sp_chol {
    int64_t n;
    ref_sp L;
    int64_t *perm;
} sp_chol;

static void sp_chol_free(void *p)
{
    sp_chol *f = p;
    if (!f) return;
    ref_sp_free(&f->L);
    ref_free(f->perm);
    ref_free(f);
}

static int sp_chol_solve(void *p, double *x, int trans, double *y)
{
    const sp_chol *f = p;
    const ref_sp *L = &f->L;
    int64_t n = f->n;
    (void)trans; /* symmetric */
    for (int64_t k = 0; k < n; k++) y[k] = x[f->perm[k]];
    for (int64_t j = 0; j < n; j++) {
        y[j] /= L->x[L->p[j]];
        double t = y[j];
        for (int64_t q = L->p[j] + 1; q < L->p[j + 1]; q++) y[L->i[q]] -= L->x[q] * t;
    }
    for (int64_t j = n - 1; j >= 0; j--) {
        double t = y[j];
        for (int64_t q = L->p[j] + 1; q < L->p[j + 1]; q++) t -= L->x[q] * y[L->i[q]];
        y[j] = t / L->x[L->p[j]];
    }
    for (int64_t k = 0; k < n; k++) x[f->perm[k]] = y[k];
    return 0;
}

/* Upper triangle of P A P' (pinv = inverse permutation) from the entries of
 * A on and above its diagonal. */
static int symperm_upper(const ref_sp *A, const int64_t *pinv, ref_sp *C)
{
    int64_t n = A->n, *cnt = ref_calloc((size_t)n + 1, sizeof(int64_t));
    if (!cnt) return SILC_ENOMEM;
    int64_t nz = 0;
    for (int64_t j = 0; j < n; j++)
        for (int64_t p = A->p[j]; p < A->p[j + 1]; p++) {
            int64_t i = A->i[p];
            if (i > j) continue;
            int64_t a = pinv[i], b = pinv[j];
            cnt[a > b ? a : b]++;
            nz++;
        }
    if (ref_sp_alloc(C, n, n, nz, 1)) {
        ref_free(cnt);
        return SILC_ENOMEM;
    }
    int64_t sum = 0;
    for (int64_t j = 0; j < n; j++) {
        C->p[j] = sum;
        sum += cnt[j];
        cnt[j] = C->p[j];
    }
    C->p[n] = sum;
    for (int64_t j = 0; j < n; j++)
        for (int64_t p = A->p[j]; p < A->p[j + 1]; p++) {
            int64_t i = A->i[p];
            if (i > j) continue;
            int64_t a = pinv[i], b = pinv[j];
            int64_t q = cnt[a > b ? a : b]++;
            C->i[q] = a < b ? a : b;
            C->x[q] = A->x[p];
        }
    ref_free(cnt);
    return 0;
}

int ref_sparse_chol(const ref_sp *A, ref_factor *F, char *msg, size_t msglen)
{
    int64_t n = A->n;
    sp_chol *f = ref_calloc(1, sizeof(sp_chol));
    ref_sp S = {0}, C = {0};
    int64_t *pinv = NULL, *parent = NULL, *s = NULL, *w = NULL, *c = NULL;
    double *x = NULL;
    int st = SILC_ENOMEM;
    if (!f) return SILC_ENOMEM;
    f->n = n;
    f->perm = ref_alloc((size_t)n, sizeof(int64_t));
    pinv = ref_alloc((size_t)n, sizeof(int64_t));
    parent = ref_alloc((size_t)n, sizeof(int64_t));
    s = ref_alloc((size_t)n, sizeof(int64_t));
    w = ref_alloc((size_t)n, sizeof(int64_t));
    c = ref_alloc((size_t)n + 1, sizeof(int64_t));
    x = ref_calloc((size_t)n, sizeof(double));
    if (!f->perm || !pinv || !parent || !s || !w || !c || !x) goto fail;
    if (ref_pattern_aplusat(A, &S) || ref_amd(&S, f->perm)) goto fail;
    ref_sp_free(&S);
    for (int64_t k = 0; k < n; k++) pinv[f->perm[k]] = k;
    if (symperm_upper(A, pinv, &C) || ref_etree(&C, parent)) goto fail;
    chol_counts(&C, parent, c, s, w);
    if (ref_sp_alloc(&f->L, n, n, c[n], 1)) goto fail;
    ref_sp *L = &f->L;
    memcpy(L->p, c, (size_t)(n + 1) * sizeof(int64_t));
    for (int64_t j = 0; j < n; j++) w[j] = -1;
    for (int64_t k = 0; k < n; k++) {
        if (k % REF_CANCEL_EVERY == REF_CANCEL_EVERY - 1 && ref_cancelled()) {
            snprintf(msg, msglen, REF_STOPPED);
            st = SILC_ELIB;
            goto fail;
        }
        int64_t top = ereach(&C, k, parent, s, w);
        for (int64_t p = C.p[k]; p < C.p[k + 1]; p++)
            if (C.i[p] <= k) x[C.i[p]] += C.x[p];
        double d = x[k];
        x[k] = 0.0;
        for (; top < n; top++) {
            int64_t i = s[top];
            double lki = x[i] / L->x[L->p[i]];
            x[i] = 0.0;
            for (int64_t p = L->p[i] + 1; p < c[i]; p++) x[L->i[p]] -= L->x[p] * lki;
            d -= lki * lki;
            int64_t p = c[i]++;
            L->i[p] = k;
            L->x[p] = lki;
        }
        if (!(d > 0.0) || !isfinite(d)) {
            snprintf(msg, msglen, "sparse Cholesky: not positive definite (pivot %lld, column %lld)",
                     (long long)k + 1, (long long)f->perm[k] + 1);
            st = SILC_ENOTSPD;
            goto fail;
        }
        int64_t p = c[k]++;
        L->i[p] = k;
        L->x[p] = sqrt(d);
    }
    F->data = f;
    F->solve = sp_chol_solve;
    F->destroy = sp_chol_free;
    F->work_len = n;
    snprintf(F->method, sizeof F->method, "sparse Cholesky, AMD order");
    snprintf(F->note, sizeof F->note, "nnz(L) = %lld", (long long)L->p[n]);
    st = 0;
    f = NULL;
fail:
    ref_sp_free(&S);
    ref_sp_free(&C);
    ref_free(pinv);
    ref_free(parent);
    ref_free(s);
    ref_free(w);
    ref_free(c);
    ref_free(x);
    sp_chol_free(f);
    return st;
}

/* ---- LU -------------------------------------------------------------------------- */

typedef struct sp_lu {
    int64_t n;
    ref_sp L, U;        /* L unit lower (diagonal first), U upper (diagonal last) */
    int64_t *pinv, *q;  /* row i of A is row pinv[i] of LU; column k of LU is column q[k] of A */
} sp_lu;

static void sp_lu_free(void *p)
{
    sp_lu *f = p;
    if (!f) return;
    ref_sp_free(&f->L);
    ref_sp_free(&f->U);
    ref_free(f->pinv);
    ref_free(f->q);
    ref_free(f);
}

static int sp_lu_solve(void *p, double *x, int trans, double *y)
{
    const sp_lu *f = p;
    const ref_sp *L = &f->L, *U = &f->U;
    int64_t n = f->n;
    if (!trans) {
        for (int64_t i = 0; i < n; i++) y[f->pinv[i]] = x[i];
        for (int64_t j = 0; j < n; j++) {
            double t = y[j];
            for (int64_t q = L->p[j] + 1; q < L->p[j + 1]; q++) y[L->i[q]] -= L->x[q] * t;
        }
        for (int64_t k = n - 1; k >= 0; k--) {
            y[k] /= U->x[U->p[k + 1] - 1];
            double t = y[k];
            for (int64_t q = U->p[k]; q < U->p[k + 1] - 1; q++) y[U->i[q]] -= U->x[q] * t;
        }
        for (int64_t k = 0; k < n; k++) x[f->q[k]] = y[k];
    } else {
        for (int64_t k = 0; k < n; k++) y[k] = x[f->q[k]];
        for (int64_t k = 0; k < n; k++) {
            double t = y[k];
            for (int64_t q = U->p[k]; q < U->p[k + 1] - 1; q++) t -= U->x[q] * y[U->i[q]];
            y[k] = t / U->x[U->p[k + 1] - 1];
        }
        for (int64_t j = n - 1; j >= 0; j--) {
            double t = y[j];
            for (int64_t q = L->p[j] + 1; q < L->p[j + 1]; q++) t -= L->x[q] * y[L->i[q]];
            y[j] = t;
        }
        for (int64_t i = 0; i < n; i++) x[i] = y[f->pinv[i]];
    }
    return 0;
}

/* Depth-first search from row j in the graph of L (columns known by pinv);
 * finished nodes are pushed onto xi[top-1], xi[top-2], ...  xi[0..] doubles
 * as the recursion stack and pstack holds each frame's position. */
static int64_t lu_dfs(int64_t j, const ref_sp *L, int64_t top, int64_t *xi, int64_t *pstack,
                      const int64_t *pinv, int64_t *mark, int64_t stamp)
{
    int64_t head = 0;
    xi[0] = j;
    while (head >= 0) {
        j = xi[head];
        int64_t jnew = pinv[j];
        if (mark[j] != stamp) {
            mark[j] = stamp;
            pstack[head] = jnew < 0 ? 0 : L->p[jnew];
        }
        int done = 1;
        int64_t p2 = jnew < 0 ? 0 : L->p[jnew + 1];
        for (int64_t p = pstack[head]; p < p2; p++) {
            int64_t i = L->i[p];
            if (mark[i] == stamp) continue;
            pstack[head] = p + 1;
            xi[++head] = i;
            done = 0;
            break;
        }
        if (done) {
            head--;
            xi[--top] = j;
        }
    }
    return top;
}

static int grow(ref_sp *M, int64_t *cap, int64_t need)
{
    if (need <= *cap) return 0;
    int64_t nc = 2 * *cap + need;
    int64_t *i = ref_host->realloc(M->i, (size_t)nc * sizeof(int64_t));
    if (!i) return SILC_ENOMEM;
    M->i = i;
    double *x = ref_host->realloc(M->x, (size_t)nc * sizeof(double));
    if (!x) return SILC_ENOMEM;
    M->x = x;
    *cap = nc;
    return 0;
}

/* Fraction of off-diagonal entries whose transpose is also present, and
 * whether every diagonal entry is present and nonzero. */
static double pattern_symmetry(const ref_sp *A, const ref_sp *T, int *diag_ok)
{
    int64_t n = A->n, both = 0, off = 0;
    *diag_ok = 1;
    for (int64_t j = 0; j < n; j++) {
        int64_t a = A->p[j], b = T->p[j], has_diag = 0;
        for (; a < A->p[j + 1]; a++) {
            int64_t i = A->i[a];
            if (i == j) {
                has_diag = A->x[a] != 0.0;
                continue;
            }
            off++;
            while (b < T->p[j + 1] && T->i[b] < i) b++;
            if (b < T->p[j + 1] && T->i[b] == i) both++;
        }
        if (!has_diag) *diag_ok = 0;
    }
    return off ? (double)both / (double)off : 1.0;
}

int ref_sparse_lu(const ref_sp *A, ref_factor *F, char *msg, size_t msglen)
{
    int64_t n = A->n, anz = ref_sp_nnz(A);
    sp_lu *f = ref_calloc(1, sizeof(sp_lu));
    ref_sp S = {0}, T = {0};
    int64_t *xi = NULL, *mark = NULL;
    double *x = NULL;
    int st = SILC_ENOMEM;
    if (!f) return SILC_ENOMEM;
    f->n = n;
    f->pinv = ref_alloc((size_t)n, sizeof(int64_t));
    f->q = ref_alloc((size_t)n, sizeof(int64_t));
    xi = ref_alloc((size_t)(2 * n), sizeof(int64_t));
    mark = ref_alloc((size_t)n, sizeof(int64_t));
    x = ref_calloc((size_t)n, sizeof(double));
    if (!f->pinv || !f->q || !xi || !mark || !x) goto fail;
    if (ref_sp_transpose(A, &T)) goto fail;
    int diag_ok;
    int sym = pattern_symmetry(A, &T, &diag_ok) >= 0.5 && diag_ok;
    ref_sp_free(&T);
    double tol = sym ? 0.1 : 1.0;
    if ((sym ? ref_pattern_aplusat(A, &S) : ref_pattern_ata(A, 1, &S)) || ref_amd(&S, f->q)) goto fail;
    ref_sp_free(&S);
    int64_t lcap = 4 * anz + n, ucap = 4 * anz + n;
    if (ref_sp_alloc(&f->L, n, n, lcap, 1) || ref_sp_alloc(&f->U, n, n, ucap, 1)) goto fail;
    ref_sp *L = &f->L, *U = &f->U;
    int64_t lnz = 0, unz = 0;
    for (int64_t i = 0; i < n; i++) {
        f->pinv[i] = -1;
        mark[i] = -1;
    }
    for (int64_t k = 0; k < n; k++) {
        if (k % REF_CANCEL_EVERY == REF_CANCEL_EVERY - 1 && ref_cancelled()) {
            snprintf(msg, msglen, REF_STOPPED);
            st = SILC_ELIB;
            goto fail;
        }
        L->p[k] = lnz;
        U->p[k] = unz;
        if (grow(L, &lcap, lnz + n) || grow(U, &ucap, unz + n)) goto fail;
        int64_t col = f->q[k], top = n;
        /* x = L \ A(:,col): pattern by DFS, values in topological order */
        for (int64_t p = A->p[col]; p < A->p[col + 1]; p++)
            if (mark[A->i[p]] != k) top = lu_dfs(A->i[p], L, top, xi, xi + n, f->pinv, mark, k);
        for (int64_t p = A->p[col]; p < A->p[col + 1]; p++) x[A->i[p]] += A->x[p];
        for (int64_t px = top; px < n; px++) {
            int64_t j = xi[px], J = f->pinv[j];
            if (J < 0) continue;
            double t = x[j];
            for (int64_t p = L->p[J] + 1; p < L->p[J + 1]; p++) x[L->i[p]] -= L->x[p] * t;
        }
        int64_t ipiv = -1;
        double a = -1.0;
        for (int64_t px = top; px < n; px++) {
            int64_t i = xi[px];
            if (f->pinv[i] < 0) {
                if (fabs(x[i]) > a) {
                    a = fabs(x[i]);
                    ipiv = i;
                }
            } else {
                U->i[unz] = f->pinv[i];
                U->x[unz++] = x[i];
            }
        }
        if (ipiv == -1 || !(a > 0.0) || !isfinite(a)) {
            snprintf(msg, msglen, "sparse LU: matrix is %ssingular (zero pivot in column %lld)",
                     ipiv == -1 ? "structurally " : "", (long long)col + 1);
            st = SILC_ESINGULAR;
            goto fail;
        }
        if (f->pinv[col] < 0 && mark[col] == k && fabs(x[col]) >= a * tol) ipiv = col;
        double piv = x[ipiv];
        U->i[unz] = k;
        U->x[unz++] = piv;
        f->pinv[ipiv] = k;
        L->i[lnz] = ipiv;
        L->x[lnz++] = 1.0;
        for (int64_t px = top; px < n; px++) {
            int64_t i = xi[px];
            if (f->pinv[i] < 0) {
                L->i[lnz] = i;
                L->x[lnz++] = x[i] / piv;
            }
            x[i] = 0.0;
        }
    }
    L->p[n] = lnz;
    U->p[n] = unz;
    for (int64_t p = 0; p < lnz; p++) L->i[p] = f->pinv[L->i[p]];
    F->data = f;
    F->solve = sp_lu_solve;
    F->destroy = sp_lu_free;
    F->work_len = n;
    snprintf(F->method, sizeof F->method, "sparse LU, %s pivoting, AMD(%s) order",
             sym ? "threshold 0.1 diagonal" : "partial", sym ? "A+A'" : "A'A");
    snprintf(F->note, sizeof F->note, "nnz(L) = %lld, nnz(U) = %lld", (long long)lnz, (long long)unz);
    st = 0;
    f = NULL;
fail:
    ref_sp_free(&S);
    ref_sp_free(&T);
    ref_free(xi);
    ref_free(mark);
    ref_free(x);
    sp_lu_free(f);
    return st;
}
