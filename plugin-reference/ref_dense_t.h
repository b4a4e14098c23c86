/*
 * ref_dense_t.h -- template of the dense direct solvers (LU with partial
 * pivoting, Cholesky, triangular, Householder QR with column pivoting),
 * included by ref_dense.c once per field (ref_field.h says why and how).
 *
 * In the complex field "transpose" is the conjugate transpose throughout:
 * trans = 1 solves with A^H (what the condition estimator applies),
 * Cholesky factors a Hermitian A = L L^H, and the Householder reflectors are
 * LAPACK's complex ones (zlarfg: H = I - tau v v^H with a complex tau, so
 * H^H = I - conj(tau) v v^H is what Q^H b applies).
 */

/* x := op(T)^{-1} x for the n x n triangle of T (leading dimension ld). */
static void FN(tri_solve)(int64_t n, const ENT *T, int64_t ld, int lower, int unit, int trans, ENT *x)
{
    if (lower != trans) { /* effectively lower: forward */
        for (int64_t j = 0; j < n; j++) {
            if (!trans) {
                if (!unit) x[j] /= T[j + j * ld];
                ENT xj = x[j];
                const ENT *c = T + j * ld;
                for (int64_t i = j + 1; i < n; i++) x[i] -= c[i] * xj;
            } else { /* upper', row j of T' = column j of T above the diagonal */
                const ENT *c = T + j * ld;
                ENT s = x[j];
                for (int64_t i = 0; i < j; i++) s -= CONJ(c[i]) * x[i];
                x[j] = unit ? s : s / CONJ(c[j]);
            }
        }
    } else {
        for (int64_t j = n - 1; j >= 0; j--) {
            if (!trans) {
                if (!unit) x[j] /= T[j + j * ld];
                ENT xj = x[j];
                const ENT *c = T + j * ld;
                for (int64_t i = 0; i < j; i++) x[i] -= c[i] * xj;
            } else { /* lower' */
                const ENT *c = T + j * ld;
                ENT s = x[j];
                for (int64_t i = j + 1; i < n; i++) s -= CONJ(c[i]) * x[i];
                x[j] = unit ? s : s / CONJ(c[j]);
            }
        }
    }
}

/* ---- LU -------------------------------------------------------------------------- */

typedef struct FN(dense_lu) {
    int64_t n;
    ENT *LU;
    int64_t *piv;
} FN(dense_lu);

static void FN(dense_lu_free)(void *p)
{
    FN(dense_lu) *f = p;
    if (!f) return;
    ref_free(f->LU);
    ref_free(f->piv);
    ref_free(f);
}

static int FN(dense_lu_solve)(void *p, double *xd, int trans, double *work)
{
    const FN(dense_lu) *f = p;
    ENT *x = (ENT *)xd;
    int64_t n = f->n;
    (void)work;
    if (!trans) {
        for (int64_t k = 0; k < n; k++) {
            ENT t = x[k];
            x[k] = x[f->piv[k]];
            x[f->piv[k]] = t;
        }
        FN(tri_solve)(n, f->LU, n, 1, 1, 0, x);
        FN(tri_solve)(n, f->LU, n, 0, 0, 0, x);
    } else {
        FN(tri_solve)(n, f->LU, n, 0, 0, 1, x);
        FN(tri_solve)(n, f->LU, n, 1, 1, 1, x);
        for (int64_t k = n - 1; k >= 0; k--) {
            ENT t = x[k];
            x[k] = x[f->piv[k]];
            x[f->piv[k]] = t;
        }
    }
    return 0;
}

int FN(ref_dense_lu)(int64_t n, const double *A, ref_factor *F, char *msg, size_t msglen)
{
    FN(dense_lu) *f = ref_calloc(1, sizeof(FN(dense_lu)));
    if (!f) return SILC_ENOMEM;
    f->n = n;
    f->LU = ref_alloc((size_t)(n * n), sizeof(ENT));
    f->piv = ref_alloc((size_t)n, sizeof(int64_t));
    if (!f->LU || !f->piv) {
        FN(dense_lu_free)(f);
        return SILC_ENOMEM;
    }
    if (n) memcpy(f->LU, A, (size_t)(n * n) * sizeof(ENT));
    ENT *a = f->LU;
    for (int64_t k = 0; k < n; k++) {
        if (k % REF_CANCEL_EVERY == REF_CANCEL_EVERY - 1 && ref_cancelled()) {
            snprintf(msg, msglen, REF_STOPPED);
            FN(dense_lu_free)(f);
            return SILC_ELIB;
        }
        int64_t p = k;
        double big = MOD(a[k + k * n]);
        for (int64_t i = k + 1; i < n; i++)
            if (MOD(a[i + k * n]) > big) {
                big = MOD(a[i + k * n]);
                p = i;
            }
        f->piv[k] = p;
        if (big == 0.0 || isnan(big)) {
            snprintf(msg, msglen, FIELD_NAME "dense LU: matrix is singular (zero pivot in column %lld)",
                     (long long)k + 1);
            FN(dense_lu_free)(f);
            return SILC_ESINGULAR;
        }
        if (p != k)
            for (int64_t j = 0; j < n; j++) {
                ENT t = a[k + j * n];
                a[k + j * n] = a[p + j * n];
                a[p + j * n] = t;
            }
        ENT *ck = a + k * n, d = ck[k];
        for (int64_t i = k + 1; i < n; i++) ck[i] /= d;
        for (int64_t j = k + 1; j < n; j++) {
            ENT *cj = a + j * n, t = cj[k];
            if (t == 0.0) continue;
            for (int64_t i = k + 1; i < n; i++) cj[i] -= ck[i] * t;
        }
    }
    F->data = f;
    F->solve = FN(dense_lu_solve);
    F->destroy = FN(dense_lu_free);
    F->w = ENT_W;
    snprintf(F->method, sizeof F->method, FIELD_NAME "dense LU, partial pivoting");
    return 0;
}

/* ---- Cholesky and triangular ------------------------------------------------------ */

typedef struct FN(dense_tri) {
    int64_t n;
    ENT *T;
    int lower;
    int chol; /* solve with T T' (T lower) rather than T */
} FN(dense_tri);

static void FN(dense_tri_free)(void *p)
{
    FN(dense_tri) *f = p;
    if (!f) return;
    ref_free(f->T);
    ref_free(f);
}

static int FN(dense_tri_apply)(void *p, double *xd, int trans, double *work)
{
    const FN(dense_tri) *f = p;
    ENT *x = (ENT *)xd;
    (void)work;
    if (f->chol) {
        FN(tri_solve)(f->n, f->T, f->n, 1, 0, 0, x);
        FN(tri_solve)(f->n, f->T, f->n, 1, 0, 1, x);
    } else {
        FN(tri_solve)(f->n, f->T, f->n, f->lower, 0, trans, x);
    }
    return 0;
}

static FN(dense_tri) *FN(dense_tri_new)(int64_t n, const double *A)
{
    FN(dense_tri) *f = ref_calloc(1, sizeof(FN(dense_tri)));
    if (!f) return NULL;
    f->n = n;
    f->T = ref_alloc((size_t)(n * n), sizeof(ENT));
    if (!f->T) {
        ref_free(f);
        return NULL;
    }
    if (n) memcpy(f->T, A, (size_t)(n * n) * sizeof(ENT));
    return f;
}

int FN(ref_dense_chol)(int64_t n, const double *A, ref_factor *F, char *msg, size_t msglen)
{
    FN(dense_tri) *f = FN(dense_tri_new)(n, A);
    if (!f) return SILC_ENOMEM;
    f->chol = 1;
    f->lower = 1;
    ENT *L = f->T;
    /* left-looking: column j gets the updates of columns k < j, then scales;
     * the diagonal of a Hermitian matrix is real (its imaginary part is not
     * read, as zpotrf does not) */
    for (int64_t j = 0; j < n; j++) {
        if (j % REF_CANCEL_EVERY == REF_CANCEL_EVERY - 1 && ref_cancelled()) {
            snprintf(msg, msglen, REF_STOPPED);
            FN(dense_tri_free)(f);
            return SILC_ELIB;
        }
        ENT *cj = L + j * n;
        for (int64_t i = 0; i < j; i++) cj[i] = 0.0; /* the upper triangle is not read */
        cj[j] = RE(cj[j]);
        for (int64_t k = 0; k < j; k++) {
            const ENT *ck = L + k * n;
            ENT t = CONJ(ck[j]);
            if (t == 0.0) continue;
            for (int64_t i = j; i < n; i++) cj[i] -= ck[i] * t;
        }
        double d = RE(cj[j]);
        if (!(d > 0.0) || !isfinite(d)) {
            snprintf(msg, msglen, FIELD_NAME "dense Cholesky: not positive definite (pivot %lld)", (long long)j + 1);
            FN(dense_tri_free)(f);
            return SILC_ENOTSPD;
        }
        d = sqrt(d);
        cj[j] = d;
        for (int64_t i = j + 1; i < n; i++) cj[i] /= d;
    }
    F->data = f;
    F->solve = FN(dense_tri_apply);
    F->destroy = FN(dense_tri_free);
    F->w = ENT_W;
    snprintf(F->method, sizeof F->method, FIELD_NAME "dense Cholesky");
    return 0;
}

int FN(ref_dense_tri)(int64_t n, const double *Ad, int lower, ref_factor *F, char *msg, size_t msglen)
{
    const ENT *A = (const ENT *)Ad;
    for (int64_t k = 0; k < n; k++)
        if (A[k + k * n] == 0.0) {
            snprintf(msg, msglen, "singular triangular matrix: zero diagonal entry at row %lld", (long long)k + 1);
            return SILC_ESINGULAR;
        }
    FN(dense_tri) *f = FN(dense_tri_new)(n, Ad);
    if (!f) return SILC_ENOMEM;
    f->lower = lower;
    F->data = f;
    F->solve = FN(dense_tri_apply);
    F->destroy = FN(dense_tri_free);
    F->w = ENT_W;
    snprintf(F->method, sizeof F->method, FIELD_NAME "dense triangular, %s substitution", lower ? "forward" : "back");
    return 0;
}

/* ---- Householder QR with column pivoting ----------------------------------------- */

typedef struct FN(dense_qr) {
    int64_t m, n;       /* of A */
    int64_t rows, cols; /* of the factored matrix: A (m >= n) or A' (m < n) */
    int64_t kmax, rank;
    ENT *QR, *tau;
    int64_t *jpvt;
} FN(dense_qr);

static void FN(dense_qr_free)(void *p)
{
    FN(dense_qr) *f = p;
    if (!f) return;
    ref_free(f->QR);
    ref_free(f->tau);
    ref_free(f->jpvt);
    ref_free(f);
}

/* x := H_k' x (adjoint = 1) or H_k x, with H_k = I - tau v v',
 * v = [1; QR(k+1:rows, k)] (real: H_k' = H_k). */
static void FN(apply_h)(const FN(dense_qr) *f, int64_t k, int adjoint, ENT *x)
{
    const ENT *v = f->QR + k * f->rows;
    ENT w = x[k];
    for (int64_t i = k + 1; i < f->rows; i++) w += CONJ(v[i]) * x[i];
    w *= adjoint ? CONJ(f->tau[k]) : f->tau[k];
    x[k] -= w;
    for (int64_t i = k + 1; i < f->rows; i++) x[i] -= v[i] * w;
}

/* Least squares (m >= n): x = P [R11^{-1} (Q'b)(1:r); 0].  Minimum norm
 * (m < n, A'P = QR): R11' y = (P'b)(1:r), x = Q [y; 0]. */
static int FN(dense_qr_solve)(void *p, double *xd, int trans, double *workd)
{
    const FN(dense_qr) *f = p;
    ENT *x = (ENT *)xd, *work = (ENT *)workd;
    int64_t r = f->rank;
    (void)trans;
    if (f->m >= f->n) {
        for (int64_t k = 0; k < f->kmax; k++) FN(apply_h)(f, k, 1, x);
        FN(tri_solve)(r, f->QR, f->rows, 0, 0, 0, x);
        for (int64_t k = 0; k < f->n; k++) work[k] = k < r ? x[k] : 0.0;
        for (int64_t k = 0; k < f->n; k++) x[f->jpvt[k]] = work[k];
    } else {
        for (int64_t k = 0; k < f->m; k++) work[k] = x[f->jpvt[k]];
        FN(tri_solve)(r, f->QR, f->rows, 0, 0, 1, work);
        for (int64_t k = 0; k < f->n; k++) x[k] = k < r ? work[k] : 0.0;
        for (int64_t k = f->kmax - 1; k >= 0; k--) FN(apply_h)(f, k, 0, x);
    }
    return 0;
}

static int FN(r11_apply)(void *p, double *x, int trans, double *work)
{
    const FN(dense_qr) *f = p;
    (void)work;
    FN(tri_solve)(f->rank, f->QR, f->rows, 0, 0, trans, (ENT *)x);
    return 0;
}

/* Scaled 2-norm of n entries (the moduli, for complex ones). */
static double FN(nrm2)(int64_t n, const ENT *x)
{
    return ref_nrm2(n * ENT_W, (const double *)x, 1);
}

int FN(ref_dense_qr)(int64_t m, int64_t n, const double *Ad, ref_factor *F, char *msg, size_t msglen)
{
    const ENT *A = (const ENT *)Ad;
    FN(dense_qr) *f = ref_calloc(1, sizeof(FN(dense_qr)));
    if (!f) return SILC_ENOMEM;
    f->m = m;
    f->n = n;
    f->rows = m >= n ? m : n;
    f->cols = m >= n ? n : m;
    int64_t rows = f->rows, cols = f->cols;
    f->kmax = cols;
    f->QR = ref_alloc((size_t)(rows * cols), sizeof(ENT));
    f->tau = ref_calloc((size_t)cols, sizeof(ENT));
    f->jpvt = ref_alloc((size_t)cols, sizeof(int64_t));
    double *vn1 = ref_alloc((size_t)cols, sizeof(double)), *vn2 = ref_alloc((size_t)cols, sizeof(double));
    if (!f->QR || !f->tau || !f->jpvt || !vn1 || !vn2) {
        ref_free(vn1);
        ref_free(vn2);
        FN(dense_qr_free)(f);
        return SILC_ENOMEM;
    }
    ENT *a = f->QR;
    for (int64_t j = 0; j < n; j++)
        for (int64_t i = 0; i < m; i++) {
            if (m >= n) a[i + j * rows] = A[i + j * m];
            else a[j + i * rows] = CONJ(A[i + j * m]);
        }
    for (int64_t j = 0; j < cols; j++) {
        f->jpvt[j] = j;
        vn1[j] = vn2[j] = FN(nrm2)(rows, a + j * rows);
    }
    for (int64_t k = 0; k < cols; k++) {
        if (k % REF_CANCEL_EVERY == REF_CANCEL_EVERY - 1 && ref_cancelled()) {
            snprintf(msg, msglen, REF_STOPPED);
            ref_free(vn1);
            ref_free(vn2);
            FN(dense_qr_free)(f);
            return SILC_ELIB;
        }
        int64_t p = k;
        for (int64_t j = k + 1; j < cols; j++)
            if (vn1[j] > vn1[p]) p = j;
        if (p != k) {
            for (int64_t i = 0; i < rows; i++) {
                ENT t = a[i + k * rows];
                a[i + k * rows] = a[i + p * rows];
                a[i + p * rows] = t;
            }
            int64_t t = f->jpvt[k];
            f->jpvt[k] = f->jpvt[p];
            f->jpvt[p] = t;
            vn1[p] = vn1[k];
            vn2[p] = vn2[k];
        }
        ENT *ck = a + k * rows, alpha = ck[k];
        double xnorm = k + 1 < rows ? FN(nrm2)(rows - k - 1, ck + k + 1) : 0.0;
        double alpha_im = MOD(alpha - RE(alpha)); /* 0 in the real field */
        if (xnorm == 0.0 && alpha_im == 0.0) {
            f->tau[k] = 0.0;
        } else { /* zlarfg (dlarfg when real): beta real, H' [alpha; x] = [beta; 0] */
            double beta = -copysign(hypot(MOD(alpha), xnorm), RE(alpha));
            f->tau[k] = (beta - alpha) / beta;
            ENT s = 1.0 / (alpha - beta);
            for (int64_t i = k + 1; i < rows; i++) ck[i] *= s;
            ck[k] = beta;
        }
        for (int64_t j = k + 1; j < cols; j++) {
            FN(apply_h)(f, k, 1, a + j * rows);
            if (vn1[j] != 0.0) { /* downdate the remaining column norm (LAPACK dlaqp2) */
                double t = MOD(a[k + j * rows]) / vn1[j];
                t = 1.0 - t * t;
                if (t < 0) t = 0;
                double t2 = t * (vn1[j] / vn2[j]) * (vn1[j] / vn2[j]);
                if (t2 <= sqrt(DBL_EPSILON)) {
                    vn1[j] = k + 1 < rows ? FN(nrm2)(rows - k - 1, a + k + 1 + j * rows) : 0.0;
                    vn2[j] = vn1[j];
                } else {
                    vn1[j] *= sqrt(t);
                }
            }
        }
    }
    ref_free(vn1);
    ref_free(vn2);
    double r00 = cols ? MOD(a[0]) : 0.0, tol = (double)rows * DBL_EPSILON * r00;
    f->rank = 0;
    while (f->rank < cols && MOD(a[f->rank + f->rank * rows]) > tol) f->rank++;
    F->data = f;
    F->solve = FN(dense_qr_solve);
    F->destroy = FN(dense_qr_free);
    F->work_len = rows * ENT_W;
    F->w = ENT_W;
    snprintf(F->method, sizeof F->method, FIELD_NAME "dense Householder QR, column pivoting%s",
             m < n ? ", minimum norm" : "");
    if (f->rank < cols)
        snprintf(F->note, sizeof F->note, "rank deficient: rank %lld of %lld", (long long)f->rank,
                 (long long)cols);
    /* cond_2(A) = cond_2(R); estimate it in the 1-norm of R11 */
    double rn = 0.0;
    for (int64_t j = 0; j < f->rank; j++) {
        double s = 0.0;
        for (int64_t i = 0; i <= j; i++) s += MOD(a[i + j * rows]);
        rn = fmax(rn, s);
    }
    double est = f->rank ? INV_EST(f->rank, FN(r11_apply), f, NULL) : 0.0;
    if (est < 0) { /* out of memory: without the estimate no warning of a singular matrix */
        FN(dense_qr_free)(f);
        F->data = NULL;
        return SILC_ENOMEM;
    }
    F->cond = f->rank ? ref_cond_from(rn, est) : INFINITY;
    if (f->rank < cols && F->cond >= 0) F->cond = INFINITY;
    (void)msg;
    (void)msglen;
    return 0;
}
