/*
 * ref_sparse_t.h -- template of the numeric sparse direct solvers
 * (triangular substitution, up-looking Cholesky, left-looking LU), included
 * by ref_sparse.c once per field (ref_field.h says why and how).
 *
 * Complex specifics, as CSparse's cs_ci: trans = 1 solves with A^H; the
 * Cholesky factor is of a Hermitian A = L L^H (the row solve yields conj of
 * row k of L, and the entries moved across the diagonal by the symmetric
 * permutation are conjugated); pivots are chosen by modulus.
 */

/* ---- triangular ------------------------------------------------------------------ */

typedef struct FN(sp_tri) {
    ref_sp A;
    int64_t *dpos; /* position of the diagonal entry in each column */
    int lower;
} FN(sp_tri);

static void FN(sp_tri_free)(void *p)
{
    FN(sp_tri) *f = p;
    if (!f) return;
    ref_sp_free(&f->A);
    ref_free(f->dpos);
    ref_free(f);
}

static int FN(sp_tri_solve)(void *p, double *xd, int trans, double *work)
{
    const FN(sp_tri) *f = p;
    const ref_sp *A = &f->A;
    const ENT *Ax = (const ENT *)A->x;
    ENT *x = (ENT *)xd;
    int64_t n = A->n;
    (void)work;
    int forward = f->lower != trans;
    for (int64_t s = 0; s < n; s++) {
        int64_t j = forward ? s : n - 1 - s;
        if (!trans) {
            x[j] /= Ax[f->dpos[j]];
            ENT xj = x[j];
            for (int64_t q = A->p[j]; q < A->p[j + 1]; q++) {
                int64_t i = A->i[q];
                if (f->lower ? i > j : i < j) x[i] -= Ax[q] * xj;
            }
        } else {
            ENT t = x[j];
            for (int64_t q = A->p[j]; q < A->p[j + 1]; q++) {
                int64_t i = A->i[q];
                if (f->lower ? i > j : i < j) t -= CONJ(Ax[q]) * x[i];
            }
            x[j] = t / CONJ(Ax[f->dpos[j]]);
        }
    }
    return 0;
}

int FN(ref_sparse_tri)(const ref_sp *A, int lower, ref_factor *F, char *msg, size_t msglen)
{
    int64_t n = A->n, nz = ref_sp_nnz(A);
    FN(sp_tri) *f = ref_calloc(1, sizeof(FN(sp_tri)));
    if (!f) return SILC_ENOMEM;
    f->lower = lower;
    f->dpos = ref_alloc((size_t)n, sizeof(int64_t));
    if (!f->dpos || ref_sp_alloc(&f->A, n, n, nz, ENT_W)) {
        FN(sp_tri_free)(f);
        return SILC_ENOMEM;
    }
    memcpy(f->A.p, A->p, (size_t)(n + 1) * sizeof(int64_t));
    if (nz) {
        memcpy(f->A.i, A->i, (size_t)nz * sizeof(int64_t));
        memcpy(f->A.x, A->x, (size_t)nz * sizeof(ENT));
    }
    const ENT *Ax = (const ENT *)A->x;
    for (int64_t j = 0; j < n; j++) {
        f->dpos[j] = -1;
        for (int64_t q = A->p[j]; q < A->p[j + 1]; q++)
            if (A->i[q] == j && Ax[q] != 0.0) f->dpos[j] = q;
        if (f->dpos[j] < 0) {
            snprintf(msg, msglen, "singular triangular matrix: zero diagonal entry at row %lld", (long long)j + 1);
            FN(sp_tri_free)(f);
            return SILC_ESINGULAR;
        }
    }
    F->data = f;
    F->solve = FN(sp_tri_solve);
    F->destroy = FN(sp_tri_free);
    F->w = ENT_W;
    snprintf(F->method, sizeof F->method, FIELD_NAME "sparse triangular, %s substitution",
             lower ? "forward" : "back");
    return 0;
}

/* ---- Cholesky ---------------------------------------------------------------------- */

typedef struct FN(sp_chol) {
    int64_t n;
    ref_sp L;
    int64_t *perm;
} FN(sp_chol);

static void FN(sp_chol_free)(void *p)
{
    FN(sp_chol) *f = p;
    if (!f) return;
    ref_sp_free(&f->L);
    ref_free(f->perm);
    ref_free(f);
}

static int FN(sp_chol_solve)(void *p, double *xd, int trans, double *yd)
{
    const FN(sp_chol) *f = p;
    const ref_sp *L = &f->L;
    const ENT *Lx = (const ENT *)L->x;
    ENT *x = (ENT *)xd, *y = (ENT *)yd;
    int64_t n = f->n;
    (void)trans; /* symmetric (Hermitian) */
    for (int64_t k = 0; k < n; k++) y[k] = x[f->perm[k]];
    for (int64_t j = 0; j < n; j++) {
        y[j] /= Lx[L->p[j]];
        ENT t = y[j];
        for (int64_t q = L->p[j] + 1; q < L->p[j + 1]; q++) y[L->i[q]] -= Lx[q] * t;
    }
    for (int64_t j = n - 1; j >= 0; j--) {
        ENT t = y[j];
        for (int64_t q = L->p[j] + 1; q < L->p[j + 1]; q++) t -= CONJ(Lx[q]) * y[L->i[q]];
        y[j] = t / Lx[L->p[j]];
    }
    for (int64_t k = 0; k < n; k++) x[f->perm[k]] = y[k];
    return 0;
}

/* Upper triangle of P A P' (pinv = inverse permutation) from the entries of
 * A on and above its diagonal; an entry the permutation moves below the
 * diagonal is stored as its mirror (conjugated: A is Hermitian). */
static int FN(symperm_upper)(const ref_sp *A, const int64_t *pinv, ref_sp *C)
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
    if (ref_sp_alloc(C, n, n, nz, ENT_W)) {
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
    const ENT *Ax = (const ENT *)A->x;
    ENT *Cx = (ENT *)C->x;
    for (int64_t j = 0; j < n; j++)
        for (int64_t p = A->p[j]; p < A->p[j + 1]; p++) {
            int64_t i = A->i[p];
            if (i > j) continue;
            int64_t a = pinv[i], b = pinv[j];
            int64_t q = cnt[a > b ? a : b]++;
            C->i[q] = a < b ? a : b;
            Cx[q] = a <= b ? Ax[p] : CONJ(Ax[p]);
        }
    ref_free(cnt);
    return 0;
}

int FN(ref_sparse_chol)(const ref_sp *A, ref_factor *F, char *msg, size_t msglen)
{
    int64_t n = A->n;
    FN(sp_chol) *f = ref_calloc(1, sizeof(FN(sp_chol)));
    ref_sp S = {0}, C = {0};
    int64_t *pinv = NULL, *parent = NULL, *s = NULL, *w = NULL, *c = NULL;
    ENT *x = NULL;
    int st = SILC_ENOMEM;
    if (!f) return SILC_ENOMEM;
    f->n = n;
    f->perm = ref_alloc((size_t)n, sizeof(int64_t));
    pinv = ref_alloc((size_t)n, sizeof(int64_t));
    parent = ref_alloc((size_t)n, sizeof(int64_t));
    s = ref_alloc((size_t)n, sizeof(int64_t));
    w = ref_alloc((size_t)n, sizeof(int64_t));
    c = ref_alloc((size_t)n + 1, sizeof(int64_t));
    x = ref_calloc((size_t)n, sizeof(ENT));
    if (!f->perm || !pinv || !parent || !s || !w || !c || !x) goto fail;
    if (ref_pattern_aplusat(A, &S) || ref_amd(&S, f->perm)) goto fail;
    ref_sp_free(&S);
    for (int64_t k = 0; k < n; k++) pinv[f->perm[k]] = k;
    if (FN(symperm_upper)(A, pinv, &C) || ref_etree(&C, parent)) goto fail;
    chol_counts(&C, parent, c, s, w);
    if (ref_sp_alloc(&f->L, n, n, c[n], ENT_W)) goto fail;
    ref_sp *L = &f->L;
    ENT *Lx = (ENT *)L->x;
    const ENT *Cx = (const ENT *)C.x;
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
            if (C.i[p] <= k) x[C.i[p]] += Cx[p];
        double d = RE(x[k]); /* a Hermitian diagonal is real: its imaginary part is not read */
        x[k] = 0.0;
        for (; top < n; top++) {
            int64_t i = s[top];
            ENT lki = x[i] / Lx[L->p[i]]; /* conj(L(k,i)) */
            x[i] = 0.0;
            for (int64_t p = L->p[i] + 1; p < c[i]; p++) x[L->i[p]] -= Lx[p] * lki;
            d -= RE(lki * CONJ(lki));
            int64_t p = c[i]++;
            L->i[p] = k;
            Lx[p] = CONJ(lki);
        }
        if (!(d > 0.0) || !isfinite(d)) {
            snprintf(msg, msglen, FIELD_NAME "sparse Cholesky: not positive definite (pivot %lld, column %lld)",
                     (long long)k + 1, (long long)f->perm[k] + 1);
            st = SILC_ENOTSPD;
            goto fail;
        }
        int64_t p = c[k]++;
        L->i[p] = k;
        Lx[p] = sqrt(d);
    }
    F->data = f;
    F->solve = FN(sp_chol_solve);
    F->destroy = FN(sp_chol_free);
    F->work_len = n * ENT_W;
    F->w = ENT_W;
    snprintf(F->method, sizeof F->method, FIELD_NAME "sparse Cholesky, AMD order");
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
    FN(sp_chol_free)(f);
    return st;
}

/* ---- LU -------------------------------------------------------------------------- */

typedef struct FN(sp_lu) {
    int64_t n;
    ref_sp L, U;        /* L unit lower (diagonal first), U upper (diagonal last) */
    int64_t *pinv, *q;  /* row i of A is row pinv[i] of LU; column k of LU is column q[k] of A */
} FN(sp_lu);

static void FN(sp_lu_free)(void *p)
{
    FN(sp_lu) *f = p;
    if (!f) return;
    ref_sp_free(&f->L);
    ref_sp_free(&f->U);
    ref_free(f->pinv);
    ref_free(f->q);
    ref_free(f);
}

static int FN(sp_lu_solve)(void *p, double *xd, int trans, double *yd)
{
    const FN(sp_lu) *f = p;
    const ref_sp *L = &f->L, *U = &f->U;
    const ENT *Lx = (const ENT *)L->x, *Ux = (const ENT *)U->x;
    ENT *x = (ENT *)xd, *y = (ENT *)yd;
    int64_t n = f->n;
    if (!trans) {
        for (int64_t i = 0; i < n; i++) y[f->pinv[i]] = x[i];
        for (int64_t j = 0; j < n; j++) {
            ENT t = y[j];
            for (int64_t q = L->p[j] + 1; q < L->p[j + 1]; q++) y[L->i[q]] -= Lx[q] * t;
        }
        for (int64_t k = n - 1; k >= 0; k--) {
            y[k] /= Ux[U->p[k + 1] - 1];
            ENT t = y[k];
            for (int64_t q = U->p[k]; q < U->p[k + 1] - 1; q++) y[U->i[q]] -= Ux[q] * t;
        }
        for (int64_t k = 0; k < n; k++) x[f->q[k]] = y[k];
    } else {
        for (int64_t k = 0; k < n; k++) y[k] = x[f->q[k]];
        for (int64_t k = 0; k < n; k++) {
            ENT t = y[k];
            for (int64_t q = U->p[k]; q < U->p[k + 1] - 1; q++) t -= CONJ(Ux[q]) * y[U->i[q]];
            y[k] = t / CONJ(Ux[U->p[k + 1] - 1]);
        }
        for (int64_t j = n - 1; j >= 0; j--) {
            ENT t = y[j];
            for (int64_t q = L->p[j] + 1; q < L->p[j + 1]; q++) t -= CONJ(Lx[q]) * y[L->i[q]];
            y[j] = t;
        }
        for (int64_t i = 0; i < n; i++) x[i] = y[f->pinv[i]];
    }
    return 0;
}

static int FN(grow)(ref_sp *M, int64_t *cap, int64_t need)
{
    if (need <= *cap) return 0;
    int64_t nc = 2 * *cap + need;
    int64_t *i = ref_host->realloc(M->i, (size_t)nc * sizeof(int64_t));
    if (!i) return SILC_ENOMEM;
    M->i = i;
    double *x = ref_host->realloc(M->x, (size_t)nc * sizeof(ENT));
    if (!x) return SILC_ENOMEM;
    M->x = x;
    *cap = nc;
    return 0;
}

/* Fraction of off-diagonal entries whose transpose is also present, and
 * whether every diagonal entry is present and nonzero. */
static double FN(pattern_symmetry)(const ref_sp *A, const ref_sp *T, int *diag_ok)
{
    int64_t n = A->n, both = 0, off = 0;
    const ENT *Ax = (const ENT *)A->x;
    *diag_ok = 1;
    for (int64_t j = 0; j < n; j++) {
        int64_t a = A->p[j], b = T->p[j], has_diag = 0;
        for (; a < A->p[j + 1]; a++) {
            int64_t i = A->i[a];
            if (i == j) {
                has_diag = Ax[a] != 0.0;
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

int FN(ref_sparse_lu)(const ref_sp *A, ref_factor *F, char *msg, size_t msglen)
{
    int64_t n = A->n, anz = ref_sp_nnz(A);
    FN(sp_lu) *f = ref_calloc(1, sizeof(FN(sp_lu)));
    ref_sp S = {0}, T = {0};
    int64_t *xi = NULL, *mark = NULL;
    ENT *x = NULL;
    const ENT *Ax = (const ENT *)A->x;
    int st = SILC_ENOMEM;
    if (!f) return SILC_ENOMEM;
    f->n = n;
    f->pinv = ref_alloc((size_t)n, sizeof(int64_t));
    f->q = ref_alloc((size_t)n, sizeof(int64_t));
    xi = ref_alloc((size_t)(2 * n), sizeof(int64_t));
    mark = ref_alloc((size_t)n, sizeof(int64_t));
    x = ref_calloc((size_t)n, sizeof(ENT));
    if (!f->pinv || !f->q || !xi || !mark || !x) goto fail;
    if (ref_sp_transpose(A, &T)) goto fail;
    int diag_ok;
    int sym = FN(pattern_symmetry)(A, &T, &diag_ok) >= 0.5 && diag_ok;
    ref_sp_free(&T);
    double tol = sym ? 0.1 : 1.0;
    if ((sym ? ref_pattern_aplusat(A, &S) : ref_pattern_ata(A, 1, &S)) || ref_amd(&S, f->q)) goto fail;
    ref_sp_free(&S);
    int64_t lcap = 4 * anz + n, ucap = 4 * anz + n;
    if (ref_sp_alloc(&f->L, n, n, lcap, ENT_W) || ref_sp_alloc(&f->U, n, n, ucap, ENT_W)) goto fail;
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
        if (FN(grow)(L, &lcap, lnz + n) || FN(grow)(U, &ucap, unz + n)) goto fail;
        ENT *Lx = (ENT *)L->x, *Ux = (ENT *)U->x;
        int64_t col = f->q[k], top = n;
        /* x = L \ A(:,col): pattern by DFS, values in topological order */
        for (int64_t p = A->p[col]; p < A->p[col + 1]; p++)
            if (mark[A->i[p]] != k) top = lu_dfs(A->i[p], L, top, xi, xi + n, f->pinv, mark, k);
        for (int64_t p = A->p[col]; p < A->p[col + 1]; p++) x[A->i[p]] += Ax[p];
        for (int64_t px = top; px < n; px++) {
            int64_t j = xi[px], J = f->pinv[j];
            if (J < 0) continue;
            ENT t = x[j];
            for (int64_t p = L->p[J] + 1; p < L->p[J + 1]; p++) x[L->i[p]] -= Lx[p] * t;
        }
        int64_t ipiv = -1;
        double a = -1.0;
        for (int64_t px = top; px < n; px++) {
            int64_t i = xi[px];
            if (f->pinv[i] < 0) {
                if (MOD(x[i]) > a) {
                    a = MOD(x[i]);
                    ipiv = i;
                }
            } else {
                U->i[unz] = f->pinv[i];
                Ux[unz++] = x[i];
            }
        }
        if (ipiv == -1 || !(a > 0.0) || !isfinite(a)) {
            snprintf(msg, msglen, FIELD_NAME "sparse LU: matrix is %ssingular (zero pivot in column %lld)",
                     ipiv == -1 ? "structurally " : "", (long long)col + 1);
            st = SILC_ESINGULAR;
            goto fail;
        }
        if (f->pinv[col] < 0 && mark[col] == k && MOD(x[col]) >= a * tol) ipiv = col;
        ENT piv = x[ipiv];
        U->i[unz] = k;
        Ux[unz++] = piv;
        f->pinv[ipiv] = k;
        L->i[lnz] = ipiv;
        Lx[lnz++] = 1.0;
        for (int64_t px = top; px < n; px++) {
            int64_t i = xi[px];
            if (f->pinv[i] < 0) {
                L->i[lnz] = i;
                Lx[lnz++] = x[i] / piv;
            }
            x[i] = 0.0;
        }
    }
    L->p[n] = lnz;
    U->p[n] = unz;
    for (int64_t p = 0; p < lnz; p++) L->i[p] = f->pinv[L->i[p]];
    F->data = f;
    F->solve = FN(sp_lu_solve);
    F->destroy = FN(sp_lu_free);
    F->work_len = n * ENT_W;
    F->w = ENT_W;
    /* the complex name leaves out " order" to fit the 64 bytes of method */
    snprintf(F->method, sizeof F->method, FIELD_NAME "sparse LU, %s pivoting, AMD(%s)%s",
             sym ? "threshold 0.1 diagonal" : "partial", sym ? "A+A'" : "A'A", ENT_W == 2 ? "" : " order");
    snprintf(F->note, sizeof F->note, "nnz(L) = %lld, nnz(U) = %lld", (long long)lnz, (long long)unz);
    st = 0;
    f = NULL;
fail:
    ref_sp_free(&S);
    ref_sp_free(&T);
    ref_free(xi);
    ref_free(mark);
    ref_free(x);
    FN(sp_lu_free)(f);
    return st;
}
