/*
 * ref_solve_t.h -- the field-dependent parts of SOLVE (the diagonal
 * "factorization", y = A x for any format, the backward error), included by
 * ref_solve.c once per field (ref_field.h); the driver itself is one for
 * both fields.
 */

/* ---- diagonal ------------------------------------------------------------------- */

typedef struct FN(diag_f) {
    int64_t n;
    ENT *d;
} FN(diag_f);

static void FN(diag_free)(void *p)
{
    FN(diag_f) *f = p;
    if (!f) return;
    ref_free(f->d);
    ref_free(f);
}

static int FN(diag_solve)(void *p, double *xd, int trans, double *work)
{
    const FN(diag_f) *f = p;
    ENT *x = (ENT *)xd;
    (void)work;
    for (int64_t i = 0; i < f->n; i++) x[i] /= trans ? CONJ(f->d[i]) : f->d[i];
    return 0;
}

static int FN(diag_factor)(const silc_view *a, ref_factor *F, char *msg, size_t msglen)
{
    int64_t n = a->n;
    FN(diag_f) *f = ref_calloc(1, sizeof(FN(diag_f)));
    if (!f) return SILC_ENOMEM;
    f->n = n;
    f->d = ref_alloc((size_t)n, sizeof(ENT));
    if (!f->d) {
        FN(diag_free)(f);
        return SILC_ENOMEM;
    }
    double big = 0.0, small = INFINITY;
    for (int64_t i = 0; i < n; i++) {
        ref_view_get_w(a, ENT_W, i, i, (double *)&f->d[i]);
        if (f->d[i] == 0.0) {
            snprintf(msg, msglen, "singular diagonal matrix: zero diagonal entry at row %lld", (long long)i + 1);
            FN(diag_free)(f);
            return SILC_ESINGULAR;
        }
        big = fmax(big, MOD(f->d[i]));
        small = fmin(small, MOD(f->d[i]));
    }
    F->data = f;
    F->solve = FN(diag_solve);
    F->destroy = FN(diag_free);
    F->w = ENT_W;
    F->cond = n ? big / small : 1.0; /* exact for a diagonal matrix */
    snprintf(F->method, sizeof F->method, FIELD_NAME "diagonal, division");
    return 0;
}

/* ---- residual ---------------------------------------------------------------------- */

/* y = A x for any format. */
static void FN(matvec)(const silc_view *a, const ENT *x, ENT *y)
{
    int64_t m = a->m, n = a->n;
    const ENT *val = (const ENT *)a->val;
    memset(y, 0, (size_t)m * sizeof(ENT));
    if (a->format == SILC_FMT_DENSE) {
        for (int64_t j = 0; j < n; j++) {
            const ENT *c = val + j * m;
            for (int64_t i = 0; i < m; i++) y[i] += c[i] * x[j];
        }
    } else if (a->format == SILC_FMT_CSR) {
        for (int64_t i = 0; i < m; i++) {
            ENT s = 0.0;
            for (int64_t k = a->rowptr[i]; k < a->rowptr[i + 1]; k++) s += val[k] * x[a->colind[k]];
            y[i] = s;
        }
    } else {
        for (int64_t j = 0; j < n; j++) {
            int64_t lo = j - a->ku > 0 ? j - a->ku : 0, hi = j + a->kl + 1 < m ? j + a->kl + 1 : m;
            for (int64_t i = lo; i < hi; i++) y[i] += val[(a->ku + i - j) + j * a->ld] * x[j];
        }
    }
}

static double FN(norm_inf)(int64_t n, const ENT *x)
{
    double s = 0.0;
    for (int64_t i = 0; i < n; i++) s = fmax(s, MOD(x[i]));
    return s;
}

/* r = b - A x; returns the normwise backward error. */
static double FN(residual)(const silc_view *a, double anorm, const double *bd, const double *xd, double *rd)
{
    const ENT *b = (const ENT *)bd, *x = (const ENT *)xd;
    ENT *r = (ENT *)rd;
    FN(matvec)(a, x, r);
    for (int64_t i = 0; i < a->m; i++) r[i] = b[i] - r[i];
    double den = anorm * FN(norm_inf)(a->n, x) + FN(norm_inf)(a->m, b);
    double num = FN(norm_inf)(a->m, r);
    return den > 0 ? num / den : num;
}

