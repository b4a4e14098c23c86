/*
 * ref_band_t.h -- template of the band LU with partial pivoting (LAPACK
 * dgbtf2/zgbtf2 and their solves), included by ref_band.c once per field
 * (ref_field.h).  trans = 1 solves with A^H in the complex field; pivots are
 * chosen by modulus.
 */
typedef struct FN(band_lu) {
    int64_t n, kl, ku, ldab;
    ENT *ab;
    int64_t *piv;
} FN(band_lu);

static void FN(band_lu_free)(void *p)
{
    FN(band_lu) *f = p;
    if (!f) return;
    ref_free(f->ab);
    ref_free(f->piv);
    ref_free(f);
}

static int FN(band_lu_solve)(void *p, double *xd, int trans, double *work)
{
    const FN(band_lu) *f = p;
    ENT *x = (ENT *)xd;
    int64_t n = f->n, kl = f->kl, kv = f->kl + f->ku;
    (void)work;
    if (!trans) {
        for (int64_t j = 0; j < n; j++) {
            int64_t q = f->piv[j];
            ENT t = x[q];
            x[q] = x[j];
            x[j] = t;
            int64_t hi = j + kl < n - 1 ? j + kl : n - 1;
            for (int64_t i = j + 1; i <= hi; i++) x[i] -= AB(f, i, j) * t;
        }
        for (int64_t j = n - 1; j >= 0; j--) {
            x[j] /= AB(f, j, j);
            ENT t = x[j];
            for (int64_t i = j - kv > 0 ? j - kv : 0; i < j; i++) x[i] -= AB(f, i, j) * t;
        }
    } else {
        for (int64_t j = 0; j < n; j++) {
            ENT s = x[j];
            for (int64_t i = j - kv > 0 ? j - kv : 0; i < j; i++) s -= CONJ(AB(f, i, j)) * x[i];
            x[j] = s / CONJ(AB(f, j, j));
        }
        for (int64_t j = n - 1; j >= 0; j--) {
            int64_t hi = j + kl < n - 1 ? j + kl : n - 1;
            ENT s = x[j];
            for (int64_t i = j + 1; i <= hi; i++) s -= CONJ(AB(f, i, j)) * x[i];
            x[j] = s;
            int64_t q = f->piv[j];
            ENT t = x[q];
            x[q] = x[j];
            x[j] = t;
        }
    }
    return 0;
}

int FN(ref_band_lu)(const silc_view *A, int64_t kl, int64_t ku, ref_factor *F, char *msg, size_t msglen)
{
    int64_t n = A->n;
    FN(band_lu) *f = ref_calloc(1, sizeof(FN(band_lu)));
    if (!f) return SILC_ENOMEM;
    f->n = n;
    f->kl = kl;
    f->ku = ku;
    f->ldab = 2 * kl + ku + 1;
    f->ab = ref_calloc((size_t)(f->ldab * n), sizeof(ENT));
    f->piv = ref_alloc((size_t)n, sizeof(int64_t));
    if (!f->ab || !f->piv) {
        FN(band_lu_free)(f);
        return SILC_ENOMEM;
    }
    if (A->format == SILC_FMT_CSR) {
        for (int64_t i = 0; i < n; i++)
            for (int64_t k = A->rowptr[i]; k < A->rowptr[i + 1]; k++) {
                int64_t j = A->colind[k];
                if (i - j <= kl && j - i <= ku) AB(f, i, j) += ((const ENT *)A->val)[k];
            }
    } else {
        for (int64_t j = 0; j < n; j++) {
            int64_t lo = j - ku > 0 ? j - ku : 0, hi = j + kl < n - 1 ? j + kl : n - 1;
            for (int64_t i = lo; i <= hi; i++) ref_view_get_w(A, ENT_W, i, j, (double *)&AB(f, i, j));
        }
    }
    int64_t ju = 0; /* last column touched by the pivot rows so far */
    for (int64_t j = 0; j < n; j++) {
        int64_t km = kl < n - 1 - j ? kl : n - 1 - j, jp = 0;
        double big = MOD(AB(f, j, j));
        for (int64_t i = 1; i <= km; i++)
            if (MOD(AB(f, j + i, j)) > big) {
                big = MOD(AB(f, j + i, j));
                jp = i;
            }
        f->piv[j] = j + jp;
        if (big == 0.0 || isnan(big)) {
            snprintf(msg, msglen, FIELD_NAME "band LU: matrix is singular (zero pivot in column %lld)", (long long)j + 1);
            FN(band_lu_free)(f);
            return SILC_ESINGULAR;
        }
        int64_t reach = j + ku + jp < n - 1 ? j + ku + jp : n - 1;
        if (reach > ju) ju = reach;
        if (jp)
            for (int64_t c = j; c <= ju; c++) {
                ENT t = AB(f, j, c);
                AB(f, j, c) = AB(f, j + jp, c);
                AB(f, j + jp, c) = t;
            }
        ENT d = AB(f, j, j);
        for (int64_t i = 1; i <= km; i++) AB(f, j + i, j) /= d;
        for (int64_t c = j + 1; c <= ju; c++) {
            ENT t = AB(f, j, c);
            if (t == 0.0) continue;
            for (int64_t i = 1; i <= km; i++) AB(f, j + i, c) -= AB(f, j + i, j) * t;
        }
    }
    F->data = f;
    F->solve = FN(band_lu_solve);
    F->destroy = FN(band_lu_free);
    F->w = ENT_W;
    snprintf(F->method, sizeof F->method, FIELD_NAME "band LU, partial pivoting (kl=%lld, ku=%lld)", (long long)kl,
             (long long)ku);
    return 0;
}
