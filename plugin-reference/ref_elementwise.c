/*
 * ref_elementwise.c -- the reference plugin's entry-by-entry operations: ADD,
 * SCALE, EWISE, MAP, TRANSPOSE, CONVERT, DIAG and REDUCE.
 *
 * Result formats follow the sparsity the operation preserves: a CSR result
 * whenever every implicit zero of the operands maps to zero (f(0,0) == 0 or
 * f(0) == 0), a band result for band-preserving operations, dense otherwise.
 * Explicit zeros produced by arithmetic are kept (the pattern is structural,
 * as in CSparse), so a result's pattern depends only on its operands'
 * patterns.  Norms are computed with scaling so entries near 1e300 never
 * overflow an intermediate sum of squares.
 *
 * Complex operands (ABI 1.8) go to ref_elementwise_z.c, except CONVERT and
 * DIAG, which only move entries and serve both fields here (w doubles per
 * entry).
 */
#include "ref.h"

#include <float.h>
#include <math.h>
#include <string.h>


/* |entry| of the w-double entry at e: w = 1 real, 2 complex (the modulus). */
static double entry_abs(const double *e, int w)
{
    return w == 2 ? hypot(e[0], e[1]) : fabs(e[0]);
}

int ref_sp_norm1_inf(const ref_sp *C, int64_t m, int64_t n, int vec, int by_col, int w, double *r)
{
    int64_t nz = C->p[n];
    const double *x = C->x;
    *r = 0.0;
    if (vec) { /* vector norms: sum |x| and max |x| whatever the orientation */
        for (int64_t k = 0; k < nz; k++)
            *r = by_col ? *r + entry_abs(x + w * k, w) : fmax(*r, entry_abs(x + w * k, w));
    } else if (by_col) {
        for (int64_t j = 0; j < n; j++) {
            double s = 0.0;
            for (int64_t k = C->p[j]; k < C->p[j + 1]; k++) s += entry_abs(x + w * k, w);
            *r = fmax(*r, s);
        }
    } else {
        double *rs = ref_calloc((size_t)m, sizeof(double));
        if (!rs) return SILC_ENOMEM;
        for (int64_t k = 0; k < nz; k++) rs[C->i[k]] += entry_abs(x + w * k, w);
        for (int64_t i = 0; i < m; i++) *r = fmax(*r, rs[i]);
        ref_free(rs);
    }
    return 0;
}

static int is_scalar(const silc_view *v)
{
    return v->m == 1 && v->n == 1;
}

static double scalar_of(const silc_view *v)
{
    return ref_view_get(v, 0, 0);
}

/* Returns the dense value D (m x n) to the host, freeing D. */
static int out_dense(silc_call *call, int64_t m, int64_t n, double *D)
{
    if (!D) return ref_nomem(call);
    call->out = ref_value_from_dense(m, n, D);
    ref_free(D);
    return call->out ? 0 : ref_nomem(call);
}

/* Returns the CSR value whose rows are the columns of R, freeing R. */
static int out_rows(silc_call *call, ref_sp *R)
{
    call->out = ref_value_from_rows(R);
    ref_sp_free(R);
    return call->out ? 0 : ref_nomem(call);
}

silc_value *ref_same_structure(const silc_view *v, int w)
{
    silc_value *out = NULL;
    if (v->format == SILC_FMT_DENSE)
        out = w == 2 ? ref_host->dense_new_complex(v->m, v->n) : ref_host->dense_new(v->m, v->n);
    else if (v->format == SILC_FMT_BAND)
        out = w == 2 ? ref_host->band_new_complex(v->m, v->n, v->kl, v->ku)
                     : ref_host->band_new(v->m, v->n, v->kl, v->ku);
    else {
        out = w == 2 ? ref_host->csr_new_complex(v->m, v->n, v->nnz) : ref_host->csr_new(v->m, v->n, v->nnz);
        if (!out) return NULL;
        silc_view o;
        ref_host->view(out, &o);
        memcpy(o.rowptr, v->rowptr, (size_t)(v->m + 1) * sizeof(silc_index));
        if (v->nnz) memcpy(o.colind, v->colind, (size_t)v->nnz * sizeof(silc_index));
        if (ref_host->csr_set_nnz(out, v->nnz)) {
            ref_host->release(out);
            return NULL;
        }
    }
    return out;
}

static silc_value *same_structure(const silc_view *v)
{
    return ref_same_structure(v, 1);
}

int64_t ref_stored(const silc_view *v)
{
    if (v->format == SILC_FMT_CSR) return v->rowptr[v->m];
    if (v->format == SILC_FMT_BAND) return v->ld * v->n;
    return v->m * v->n;
}

static int scale_copy(silc_call *call, const silc_view *v, double alpha)
{
    silc_value *out = same_structure(v);
    if (!out) return ref_nomem(call);
    silc_view o;
    ref_host->view(out, &o);
    int64_t nz = ref_stored(v);
    for (int64_t k = 0; k < nz; k++) o.val[k] = alpha * v->val[k];
    call->out = out;
    return 0;
}

int ref_op_scale(silc_call *call)
{
    if (ref_width(call->in[0]) == 2) return ref_op_scale_z(call);
    silc_view a;
    ref_host->view(call->in[0], &a);
    return scale_copy(call, &a, call->alpha);
}

/* ---- merging sparse rows ------------------------------------------------------ */

typedef double (*comb_fn)(double a, double b, const void *ctx);

/* Row-wise union (or intersection) of the row-compressed A and B (A->n rows),
 * each result entry c = f(a, b) with absent entries read as 0. */
static int merge_rows(silc_call *call, const ref_sp *A, const ref_sp *B, int intersect, comb_fn f,
                      const void *ctx)
{
    int64_t rows = A->n, cols = A->m;
    ref_sp R;
    int64_t cap = intersect ? ref_sp_nnz(A) : ref_sp_nnz(A) + ref_sp_nnz(B);
    if (ref_sp_alloc(&R, cols, rows, cap, 1)) return ref_nomem(call);
    int64_t nz = 0;
    for (int64_t r = 0; r < rows; r++) {
        R.p[r] = nz;
        int64_t ka = A->p[r], ea = A->p[r + 1], kb = B->p[r], eb = B->p[r + 1];
        while (ka < ea || kb < eb) {
            int64_t ca = ka < ea ? A->i[ka] : INT64_MAX, cb = kb < eb ? B->i[kb] : INT64_MAX;
            double va = 0.0, vb = 0.0;
            int64_t c = ca < cb ? ca : cb;
            if (ca == c) va = A->x[ka++];
            if (cb == c) vb = B->x[kb++];
            if (intersect && ca != cb) continue;
            R.i[nz] = c;
            R.x[nz++] = f(va, vb, ctx);
        }
    }
    R.p[rows] = nz;
    return out_rows(call, &R);
}

/* ---- ADD ------------------------------------------------------------------------ */

typedef struct lin_ctx {
    double alpha, beta;
} lin_ctx;

static double lin(double a, double b, const void *ctx)
{
    const lin_ctx *c = ctx;
    return c->alpha * a + c->beta * b;
}

static void add_into(double *D, const silc_view *v, double coef)
{
    int64_t m = v->m;
    if (v->format == SILC_FMT_DENSE) {
        for (int64_t k = 0; k < m * v->n; k++) D[k] += coef * v->val[k];
    } else if (v->format == SILC_FMT_CSR) {
        for (int64_t i = 0; i < m; i++)
            for (int64_t k = v->rowptr[i]; k < v->rowptr[i + 1]; k++)
                D[i + v->colind[k] * m] += coef * v->val[k];
    } else {
        for (int64_t j = 0; j < v->n; j++) {
            int64_t lo = j - v->ku > 0 ? j - v->ku : 0;
            int64_t hi = j + v->kl + 1 < m ? j + v->kl + 1 : m;
            for (int64_t i = lo; i < hi; i++) D[i + j * m] += coef * v->val[(v->ku + i - j) + j * v->ld];
        }
    }
}

int ref_op_add(silc_call *call)
{
    if (ref_width(call->in[0]) == 2 || ref_width(call->in[1]) == 2) return ref_op_add_z(call);
    silc_view a, b;
    ref_host->view(call->in[0], &a);
    ref_host->view(call->in[1], &b);
    double al = call->alpha, be = call->beta;
    int sa = is_scalar(&a), sb = is_scalar(&b);
    if (sa != sb) {
        const silc_view *X = sa ? &b : &a;
        double cx = sa ? be : al, s = sa ? al * scalar_of(&a) : be * scalar_of(&b);
        if (s == 0.0) return scale_copy(call, X, cx);
        double *D = ref_calloc((size_t)(X->m * X->n), sizeof(double));
        if (!D) return ref_nomem(call);
        add_into(D, X, cx);
        for (int64_t k = 0; k < X->m * X->n; k++) D[k] += s;
        return out_dense(call, X->m, X->n, D);
    }
    if (a.m != b.m || a.n != b.n)
        return ref_host->error(call, SILC_EARG, "add: shapes %lldx%lld and %lldx%lld differ",
                               (long long)a.m, (long long)a.n, (long long)b.m, (long long)b.n);
    if (a.format == SILC_FMT_BAND && b.format == SILC_FMT_BAND) {
        int64_t kl = a.kl > b.kl ? a.kl : b.kl, ku = a.ku > b.ku ? a.ku : b.ku;
        silc_value *out = ref_host->band_new(a.m, a.n, kl, ku);
        if (!out) return ref_nomem(call);
        silc_view o;
        ref_host->view(out, &o);
        for (int64_t j = 0; j < a.n; j++) {
            int64_t lo = j - ku > 0 ? j - ku : 0, hi = j + kl + 1 < a.m ? j + kl + 1 : a.m;
            for (int64_t i = lo; i < hi; i++)
                o.val[(ku + i - j) + j * o.ld] = al * ref_view_get(&a, i, j) + be * ref_view_get(&b, i, j);
        }
        call->out = out;
        return 0;
    }
    if (a.format != SILC_FMT_DENSE && b.format != SILC_FMT_DENSE) {
        ref_sp A, B;
        if (ref_spt_pair(&a, &b, &A, &B)) return ref_nomem(call);
        lin_ctx c = {al, be};
        int st = merge_rows(call, &A, &B, 0, lin, &c);
        ref_sp_free(&A);
        ref_sp_free(&B);
        return st;
    }
    double *D = ref_calloc((size_t)(a.m * a.n), sizeof(double));
    if (!D) return ref_nomem(call);
    add_into(D, &a, al);
    add_into(D, &b, be);
    return out_dense(call, a.m, a.n, D);
}

/* ---- EWISE ---------------------------------------------------------------------- */

static double ew(int sub, double a, double b)
{
    switch (sub) {
    case SILC_EW_MUL: return a * b;
    case SILC_EW_DIV: return a / b;
    case SILC_EW_POW: return pow(a, b);
    case SILC_EW_MAX: return fmax(a, b);
    case SILC_EW_MIN: return fmin(a, b);
    case SILC_EW_EQ: return a == b;
    case SILC_EW_NE: return a != b;
    case SILC_EW_LT: return a < b;
    case SILC_EW_LE: return a <= b;
    case SILC_EW_GT: return a > b;
    case SILC_EW_GE: return a >= b;
    case SILC_EW_AND: return a != 0.0 && b != 0.0;
    default: return a != 0.0 || b != 0.0;
    }
}

static double ew_comb(double a, double b, const void *ctx)
{
    return ew(*(const int *)ctx, a, b);
}

/* CSR operand X with every stored entry combined with the matching entry of
 * Y (a scalar broadcast when Y is 1x1); X on the left when x_left. */
static int ew_on_pattern(silc_call *call, const silc_view *X, const silc_view *Y, int x_left)
{
    silc_value *out = same_structure(X);
    if (!out) return ref_nomem(call);
    silc_view o;
    ref_host->view(out, &o);
    int sy = is_scalar(Y);
    double s = sy ? scalar_of(Y) : 0.0;
    for (int64_t i = 0; i < X->m; i++)
        for (int64_t k = X->rowptr[i]; k < X->rowptr[i + 1]; k++) {
            double y = sy ? s : ref_view_get(Y, i, X->colind[k]);
            o.val[k] = x_left ? ew(call->sub, X->val[k], y) : ew(call->sub, y, X->val[k]);
        }
    call->out = out;
    return 0;
}

int ref_op_ewise(silc_call *call)
{
    if (ref_width(call->in[0]) == 2 || ref_width(call->in[1]) == 2) return ref_op_ewise_z(call);
    silc_view a, b;
    ref_host->view(call->in[0], &a);
    ref_host->view(call->in[1], &b);
    int sub = call->sub;
    if (sub < SILC_EW_MUL || sub > SILC_EW_OR)
        return ref_host->error(call, SILC_EUNSUP, "element-wise operation %d is unknown", sub);
    int sa = is_scalar(&a), sb = is_scalar(&b);
    if (!sa && !sb && (a.m != b.m || a.n != b.n))
        return ref_host->error(call, SILC_EARG, "element-wise: shapes %lldx%lld and %lldx%lld differ",
                               (long long)a.m, (long long)a.n, (long long)b.m, (long long)b.n);
    int ca = !sa && a.format == SILC_FMT_CSR, cb = !sb && b.format == SILC_FMT_CSR;
    if (sub == SILC_EW_MUL && (ca || cb)) {
        if (ca && cb) {
            ref_sp A, B;
            ref_spt_from_view(&a, &A);
            ref_spt_from_view(&b, &B);
            return merge_rows(call, &A, &B, 1, ew_comb, &sub);
        }
        return ca ? ew_on_pattern(call, &a, &b, 1) : ew_on_pattern(call, &b, &a, 0);
    }
    if (ca && cb && ew(sub, 0.0, 0.0) == 0.0) {
        ref_sp A, B;
        ref_spt_from_view(&a, &A);
        ref_spt_from_view(&b, &B);
        return merge_rows(call, &A, &B, 0, ew_comb, &sub);
    }
    if (ca && sb && ew(sub, 0.0, scalar_of(&b)) == 0.0) return ew_on_pattern(call, &a, &b, 1);
    if (cb && sa && ew(sub, scalar_of(&a), 0.0) == 0.0) return ew_on_pattern(call, &b, &a, 0);
    int64_t m = sa ? b.m : a.m, n = sa ? b.n : a.n;
    double *A = ref_dense_from_view(&a), *B = ref_dense_from_view(&b);
    double *D = ref_alloc((size_t)(m * n), sizeof(double));
    if (!A || !B || !D) {
        ref_free(A);
        ref_free(B);
        ref_free(D);
        return ref_nomem(call);
    }
    for (int64_t k = 0; k < m * n; k++) D[k] = ew(sub, A[sa ? 0 : k], B[sb ? 0 : k]);
    ref_free(A);
    ref_free(B);
    return out_dense(call, m, n, D);
}

/* ---- MAP ------------------------------------------------------------------------ */

static double map1(int sub, double x)
{
    switch (sub) {
    case SILC_MAP_NEG: return -x;
    case SILC_MAP_ABS: return fabs(x);
    case SILC_MAP_SQRT: return sqrt(x);
    case SILC_MAP_EXP: return exp(x);
    case SILC_MAP_LOG: return log(x);
    case SILC_MAP_SIN: return sin(x);
    case SILC_MAP_COS: return cos(x);
    case SILC_MAP_REAL: return x;
    case SILC_MAP_IMAG: return 0.0;
    case SILC_MAP_CONJ: return x;
    case SILC_MAP_ANGLE: return atan2(0.0, x); /* pi for x < 0, as carg */
    default: return x == 0.0;
    }
}

int ref_op_map(silc_call *call)
{
    if (ref_width(call->in[0]) == 2) return ref_op_map_z(call);
    silc_view a;
    ref_host->view(call->in[0], &a);
    int sub = call->sub;
    if (sub < SILC_MAP_NEG || sub > SILC_MAP_ANGLE)
        return ref_host->error(call, SILC_EUNSUP, "map function %d is unknown", sub);
    if (a.format == SILC_FMT_DENSE || map1(sub, 0.0) == 0.0) {
        silc_value *out = same_structure(&a);
        if (!out) return ref_nomem(call);
        silc_view o;
        ref_host->view(out, &o);
        int64_t nz = ref_stored(&a);
        for (int64_t k = 0; k < nz; k++) o.val[k] = map1(sub, a.val[k]);
        call->out = out;
        return 0;
    }
    double *D = ref_dense_from_view(&a);
    if (!D) return ref_nomem(call);
    for (int64_t k = 0; k < a.m * a.n; k++) D[k] = map1(sub, D[k]);
    return out_dense(call, a.m, a.n, D);
}

/* ---- TRANSPOSE, CONVERT, DIAG ---------------------------------------------------- */

int ref_op_transpose(silc_call *call)
{
    if (ref_width(call->in[0]) == 2) return ref_op_transpose_z(call);
    silc_view a;
    ref_host->view(call->in[0], &a);
    if (a.format == SILC_FMT_CSR) {
        ref_sp C;
        if (ref_sp_from_view(&a, &C)) return ref_nomem(call);
        return out_rows(call, &C);
    }
    if (a.format == SILC_FMT_BAND) {
        silc_value *out = ref_host->band_new(a.n, a.m, a.ku, a.kl);
        if (!out) return ref_nomem(call);
        silc_view o;
        ref_host->view(out, &o);
        for (int64_t j = 0; j < a.n; j++) {
            int64_t lo = j - a.ku > 0 ? j - a.ku : 0, hi = j + a.kl + 1 < a.m ? j + a.kl + 1 : a.m;
            for (int64_t i = lo; i < hi; i++)
                o.val[(o.ku + j - i) + i * o.ld] = a.val[(a.ku + i - j) + j * a.ld];
        }
        call->out = out;
        return 0;
    }
    double *D = ref_alloc((size_t)(a.m * a.n), sizeof(double));
    if (!D) return ref_nomem(call);
    for (int64_t j = 0; j < a.n; j++)
        for (int64_t i = 0; i < a.m; i++) D[j + i * a.n] = a.val[i + j * a.m];
    return out_dense(call, a.n, a.m, D);
}

/* Entry k of a compressed-column matrix with w doubles per entry is nonzero. */
static int sp_entry_nonzero(const ref_sp *C, int w, int64_t k)
{
    return C->x[w * k] != 0.0 || (w == 2 && C->x[2 * k + 1] != 0.0);
}

int ref_op_convert(silc_call *call)
{
    silc_view a;
    ref_host->view(call->in[0], &a);
    int w = ref_width(call->in[0]);
    if (call->sub == SILC_FMT_DENSE) {
        /* Straight into the result: no second m x n array, and the host's
         * constructor is what checks (and names) the size. */
        silc_view o;
        if (!(call->out = w == 2 ? ref_host->dense_new_complex(a.m, a.n) : ref_host->dense_new(a.m, a.n)))
            return ref_nomem(call);
        ref_host->view(call->out, &o);
        ref_dense_fill_w(&a, w, o.val);
        return 0;
    }
    if (call->sub == SILC_FMT_CSR) {
        ref_sp R;
        if (a.format == SILC_FMT_CSR) {
            call->out = ref_same_structure(&a, w);
            if (!call->out) return ref_nomem(call);
            silc_view o;
            ref_host->view(call->out, &o);
            if (a.nnz) memcpy(o.val, a.val, (size_t)(a.rowptr[a.m] * w) * sizeof(double));
            return 0;
        }
        if (ref_spt_from_view_w(&a, w, &R)) return ref_nomem(call);
        call->out = ref_value_from_rows_w(&R, w);
        ref_sp_free(&R);
        return call->out ? 0 : ref_nomem(call);
    }
    if (call->sub != SILC_FMT_BAND)
        return ref_host->error(call, SILC_EARG, "convert: unknown format %d", call->sub);
    int64_t kl = call->ival[0], ku = call->ival[1];
    if (kl < 0 || ku < 0)
        return ref_host->error(call, SILC_EARG, "band: widths kl=%lld, ku=%lld must be >= 0",
                               (long long)kl, (long long)ku);
    ref_sp C;
    if (ref_sp_from_view_w(&a, w, &C)) return ref_nomem(call);
    for (int64_t j = 0; j < a.n; j++)
        for (int64_t k = C.p[j]; k < C.p[j + 1]; k++) {
            int64_t i = C.i[k];
            if (sp_entry_nonzero(&C, w, k) && (i - j > kl || j - i > ku)) {
                ref_sp_free(&C);
                return ref_host->error(call, SILC_EARG,
                                       "band: entry (%lld,%lld) lies outside the band kl=%lld, ku=%lld",
                                       (long long)i + 1, (long long)j + 1, (long long)kl, (long long)ku);
            }
        }
    silc_value *out = w == 2 ? ref_host->band_new_complex(a.m, a.n, kl, ku) : ref_host->band_new(a.m, a.n, kl, ku);
    if (!out) {
        ref_sp_free(&C);
        return ref_nomem(call);
    }
    silc_view o;
    ref_host->view(out, &o);
    for (int64_t j = 0; j < a.n; j++)
        for (int64_t k = C.p[j]; k < C.p[j + 1]; k++) {
            int64_t i = C.i[k];
            if (i - j <= kl && j - i <= ku)
                for (int c = 0; c < w; c++) o.val[w * ((ku + i - j) + j * o.ld) + c] += C.x[w * k + c];
        }
    ref_sp_free(&C);
    call->out = out;
    return 0;
}

int ref_op_diag(silc_call *call)
{
    silc_view a;
    ref_host->view(call->in[0], &a);
    int w = ref_width(call->in[0]);
    if (call->sub == 1) {
        int64_t k = a.m < a.n ? a.m : a.n;
        double *D = ref_alloc((size_t)(k * w), sizeof(double));
        if (!D) return ref_nomem(call);
        for (int64_t i = 0; i < k; i++) ref_view_get_w(&a, w, i, i, D + w * i);
        call->out = ref_value_from_dense_w(k, 1, w, D);
        ref_free(D);
        return call->out ? 0 : ref_nomem(call);
    }
    if (a.m != 1 && a.n != 1)
        return ref_host->error(call, SILC_EARG, "diag: needs a vector, got a %lldx%lld matrix",
                               (long long)a.m, (long long)a.n);
    int64_t len = a.m * a.n, nz = 0;
    double d[2] = {0.0, 0.0};
    for (int64_t k = 0; k < len; k++) {
        ref_view_get_w(&a, w, a.n == 1 ? k : 0, a.n == 1 ? 0 : k, d);
        if (d[0] != 0.0 || d[1] != 0.0) nz++;
    }
    silc_value *out = w == 2 ? ref_host->csr_new_complex(len, len, nz) : ref_host->csr_new(len, len, nz);
    if (!out) return ref_nomem(call);
    silc_view o;
    ref_host->view(out, &o);
    nz = 0;
    for (int64_t k = 0; k < len; k++) {
        ref_view_get_w(&a, w, a.n == 1 ? k : 0, a.n == 1 ? 0 : k, d);
        o.rowptr[k] = nz;
        if (d[0] != 0.0 || d[1] != 0.0) {
            o.colind[nz] = k;
            memcpy(o.val + w * nz++, d, (size_t)w * sizeof(double));
        }
    }
    o.rowptr[len] = nz;
    if (ref_host->csr_set_nnz(out, nz)) {
        ref_host->release(out);
        return ref_nomem(call);
    }
    call->out = out;
    return 0;
}

/* ---- REDUCE ---------------------------------------------------------------------- */

/* sqrt(sum x_k^2) without overflow or destructive underflow (LAPACK dnrm2). */
double ref_nrm2(int64_t n, const double *x, int64_t inc)
{
    double scale = 0.0, ssq = 1.0;
    for (int64_t k = 0; k < n; k++) {
        double a = fabs(x[k * inc]);
        if (a == 0.0) continue;
        if (isnan(a)) return a;
        if (scale < a) {
            ssq = 1.0 + ssq * (scale / a) * (scale / a);
            scale = a;
        } else {
            ssq += (a / scale) * (a / scale);
        }
    }
    return scale * sqrt(ssq);
}

/* Largest singular value of the m x n compressed-column A.  Small matrices:
 * one-sided Jacobi SVD on a dense copy (accurate to rounding).  Others: power
 * iteration on A'A to a relative change of 1e-12 (at most 5000 steps).  Both
 * run on A scaled by 1/max|a_ij| so 1e300 entries cannot overflow.  Jacobi is
 * used while min(m,n)^2 * max(m,n) <= 2e8 (one sweep stays well under a
 * second); the power iteration converges slowly when the two largest singular
 * values are close, so its answer can be accurate to only ~1e-10 then. */
int ref_norm2(const ref_sp *A, double *out)
{
    int64_t m = A->m, n = A->n, nz = ref_sp_nnz(A);
    double amax = 0.0;
    for (int64_t k = 0; k < nz; k++) amax = fmax(amax, fabs(A->x[k]));
    if (amax == 0.0 || isnan(amax) || isinf(amax)) {
        *out = amax;
        return 0;
    }
    int64_t small = m < n ? m : n, big = m < n ? n : m;
    if ((double)small * (double)small * (double)big <= 2e8) {
        /* columns of W are the columns of A (m >= n) or of A' (m < n) */
        int64_t rows = big, cols = small;
        double *W = ref_calloc((size_t)(rows * cols), sizeof(double));
        if (!W) return SILC_ENOMEM;
        for (int64_t j = 0; j < n; j++)
            for (int64_t k = A->p[j]; k < A->p[j + 1]; k++) {
                int64_t i = A->i[k];
                if (m >= n) W[i + j * rows] = A->x[k] / amax;
                else W[j + i * rows] = A->x[k] / amax;
            }
        for (int sweep = 0; sweep < 80; sweep++) {
            int rotated = 0;
            for (int64_t p = 0; p < cols; p++)
                for (int64_t q = p + 1; q < cols; q++) {
                    double *wp = W + p * rows, *wq = W + q * rows, al = 0, be = 0, ga = 0;
                    for (int64_t i = 0; i < rows; i++) {
                        al += wp[i] * wp[i];
                        be += wq[i] * wq[i];
                        ga += wp[i] * wq[i];
                    }
                    if (ga == 0.0 || fabs(ga) <= DBL_EPSILON * sqrt(al * be)) continue;
                    rotated = 1;
                    double zeta = (be - al) / (2.0 * ga);
                    double t = (zeta >= 0 ? 1.0 : -1.0) / (fabs(zeta) + sqrt(1.0 + zeta * zeta));
                    double c = 1.0 / sqrt(1.0 + t * t), s = c * t;
                    for (int64_t i = 0; i < rows; i++) {
                        double x = wp[i], y = wq[i];
                        wp[i] = c * x - s * y;
                        wq[i] = s * x + c * y;
                    }
                }
            if (!rotated) break;
        }
        double best = 0.0;
        for (int64_t j = 0; j < cols; j++) best = fmax(best, ref_nrm2(rows, W + j * rows, 1));
        ref_free(W);
        *out = best * amax;
        return 0;
    }
    double *x = ref_alloc((size_t)n, sizeof(double)), *y = ref_alloc((size_t)m, sizeof(double));
    if (!x || !y) {
        ref_free(x);
        ref_free(y);
        return SILC_ENOMEM;
    }
    for (int64_t j = 0; j < n; j++) x[j] = 1.0 + (double)j / (double)n; /* not orthogonal to v1 in practice */
    double xn = ref_nrm2(n, x, 1), est = 0.0;
    for (int64_t j = 0; j < n; j++) x[j] /= xn;
    for (int it = 0; it < 5000; it++) {
        memset(y, 0, (size_t)m * sizeof(double));
        for (int64_t j = 0; j < n; j++)
            for (int64_t k = A->p[j]; k < A->p[j + 1]; k++) y[A->i[k]] += (A->x[k] / amax) * x[j];
        for (int64_t j = 0; j < n; j++) {
            double s = 0.0;
            for (int64_t k = A->p[j]; k < A->p[j + 1]; k++) s += (A->x[k] / amax) * y[A->i[k]];
            x[j] = s;
        }
        double zn = ref_nrm2(n, x, 1), prev = est;
        if (zn == 0.0) break;
        est = sqrt(zn);
        for (int64_t j = 0; j < n; j++) x[j] /= zn;
        if (it > 0 && fabs(est - prev) <= 1e-12 * est) break;
    }
    ref_free(x);
    ref_free(y);
    *out = est * amax;
    return 0;
}

int ref_op_reduce(silc_call *call)
{
    if (ref_width(call->in[0]) == 2 || (call->nin > 1 && ref_width(call->in[1]) == 2)) return ref_op_reduce_z(call);
    silc_view a;
    ref_host->view(call->in[0], &a);
    int sub = call->sub;
    int vec = a.m == 1 || a.n == 1;
    double r = 0.0;
    if (sub == SILC_RED_DOT) {
        silc_view b;
        if (call->nin < 2) return ref_host->error(call, SILC_EARG, "dot: needs two operands");
        ref_host->view(call->in[1], &b);
        if (a.m != b.m || a.n != b.n)
            return ref_host->error(call, SILC_EARG, "dot: shapes %lldx%lld and %lldx%lld differ",
                                   (long long)a.m, (long long)a.n, (long long)b.m, (long long)b.n);
        if (a.format == SILC_FMT_DENSE && b.format == SILC_FMT_DENSE) {
            for (int64_t k = 0; k < a.m * a.n; k++) r += a.val[k] * b.val[k];
        } else if (a.format == SILC_FMT_CSR || b.format == SILC_FMT_CSR) {
            const silc_view *S = a.format == SILC_FMT_CSR ? &a : &b, *O = S == &a ? &b : &a;
            for (int64_t i = 0; i < S->m; i++)
                for (int64_t k = S->rowptr[i]; k < S->rowptr[i + 1]; k++)
                    r += S->val[k] * ref_view_get(O, i, S->colind[k]);
        } else {
            for (int64_t j = 0; j < a.n; j++)
                for (int64_t i = 0; i < a.m; i++) r += ref_view_get(&a, i, j) * ref_view_get(&b, i, j);
        }
        double *D = ref_alloc(1, sizeof(double));
        if (!D) return ref_nomem(call);
        D[0] = r;
        return out_dense(call, 1, 1, D);
    }
    if (sub == SILC_RED_SUM && !vec && a.format == SILC_FMT_CSR) {
        /* Column sums of CSR scattered row by row: each column's entries
         * are added in row order from 0, as the compressed-column path
         * below adds them (the same bits), without converting the matrix
         * (the cloth's diagvec(P' * P), eval.c, runs this every step). */
        double *D = ref_alloc((size_t)(a.n ? a.n : 1), sizeof(double));
        if (!D) return ref_nomem(call);
        for (int64_t j = 0; j < a.n; j++) D[j] = 0.0;
        for (int64_t i = 0; i < a.m; i++)
            for (int64_t k = a.rowptr[i]; k < a.rowptr[i + 1]; k++) D[a.colind[k]] += a.val[k];
        return out_dense(call, 1, a.n, D);
    }
    ref_sp C;
    if (ref_sp_from_view(&a, &C)) return ref_nomem(call);
    int64_t nz = ref_sp_nnz(&C), st = 0;
    double *D = NULL;
    int64_t outn = 1;
    if (sub == SILC_RED_SUM || sub == SILC_RED_MAX || sub == SILC_RED_MIN) {
        if ((sub != SILC_RED_SUM) && a.m * a.n == 0) {
            ref_sp_free(&C);
            return ref_host->error(call, SILC_EARG, "%s of an empty %lldx%lld matrix",
                                   sub == SILC_RED_MAX ? "max" : "min", (long long)a.m, (long long)a.n);
        }
        /* a vector is one group of all its entries; a matrix has one per column */
        int64_t groups = vec ? 1 : a.n, glen = vec ? a.m * a.n : a.m;
        outn = groups;
        D = ref_alloc((size_t)groups, sizeof(double));
        if (!D) {
            ref_sp_free(&C);
            return ref_nomem(call);
        }
        for (int64_t g = 0; g < groups; g++) {
            int64_t c0 = vec ? 0 : g, c1 = vec ? a.n : g + 1;
            int64_t cnt = C.p[c1] - C.p[c0];
            double acc = sub == SILC_RED_SUM ? 0.0 : (sub == SILC_RED_MAX ? -INFINITY : INFINITY);
            for (int64_t k = C.p[c0]; k < C.p[c1]; k++) {
                if (sub == SILC_RED_SUM) acc += C.x[k];
                else if (sub == SILC_RED_MAX) acc = fmax(acc, C.x[k]);
                else acc = fmin(acc, C.x[k]);
            }
            if (cnt < glen && sub == SILC_RED_MAX) acc = fmax(acc, 0.0);
            if (cnt < glen && sub == SILC_RED_MIN) acc = fmin(acc, 0.0);
            D[g] = acc;
        }
        ref_sp_free(&C);
        return out_dense(call, 1, outn, D);
    }
    if (sub == SILC_RED_NORMFRO || (sub == SILC_RED_NORM && vec)) {
        r = ref_nrm2(nz, C.x, 1);
    } else if (sub == SILC_RED_NORM) {
        st = ref_norm2(&C, &r);
    } else if (sub == SILC_RED_NORM1 || sub == SILC_RED_NORMINF) {
        st = ref_sp_norm1_inf(&C, a.m, a.n, vec, sub == SILC_RED_NORM1, 1, &r);
    } else {
        ref_sp_free(&C);
        return ref_host->error(call, SILC_EUNSUP, "reduction %d is unknown", sub);
    }
    ref_sp_free(&C);
    if (st) return ref_nomem(call);
    D = ref_alloc(1, sizeof(double));
    if (!D) return ref_nomem(call);
    D[0] = r;
    return out_dense(call, 1, 1, D);
}
