/*
 * reference.c -- the reference plugin's tables, entry point and shared helpers.
 *
 * The same sources build twice: inside libsilc (SILC_REFERENCE_BUILTIN, entry
 * silc_reference_plugin_init, not exported) and as the loadable module
 * libsilc_plugin_reference.so (entry silc_plugin_init).  Everything talks to
 * the host only through the silc_host_api pointer kept in ref_host.  The
 * helpers below (allocation, format conversion, result construction) are the
 * only places that know the storage layouts of all three formats, so the
 * operation modules stay short.
 */
#include "ref.h"

#include <string.h>

const silc_host_api *ref_host;

static _Thread_local silc_call *cancel_call;

void ref_cancel_scope(silc_call *call)
{
    cancel_call = call;
}

int ref_cancelled(void)
{
    return cancel_call && ref_host->struct_size >= SILC_HOST_NEEDS(cancelled) && ref_host->cancelled(cancel_call);
}

/* ---- memory ----------------------------------------------------------------- */

void *ref_alloc(size_t count, size_t size)
{
    if (count == 0 || size == 0) return ref_host->alloc(1);
    if (count > SIZE_MAX / size) return NULL;
    return ref_host->alloc(count * size);
}

void *ref_calloc(size_t count, size_t size)
{
    if (count == 0 || size == 0) return ref_host->calloc(1, 1);
    return ref_host->calloc(count, size);
}

void ref_free(void *p)
{
    if (p) ref_host->free(p);
}

int ref_nomem(silc_call *call)
{
    return ref_host->error(call, SILC_ENOMEM, "reference: out of memory");
}

int ref_width(const silc_value *v)
{
    if (ref_host->abi_minor < 8 || ref_host->struct_size < SILC_HOST_NEEDS(field) || !ref_host->field)
        return 1;
    return ref_host->field(v) == SILC_FIELD_COMPLEX ? 2 : 1;
}

/* Copies one entry of w doubles: the loops below serve both fields, and
 * inlining with a constant w (the _w wrappers) keeps the real path a plain
 * double copy. */
static inline void copy_entry(double *dst, const double *src, int w)
{
    dst[0] = src[0];
    if (w == 2) dst[1] = src[1];
}

static inline void add_entry(double *dst, const double *src, int w)
{
    dst[0] += src[0];
    if (w == 2) dst[1] += src[1];
}

static inline int entry_is_zero(const double *a, int w)
{
    return a[0] == 0.0 && (w == 1 || a[1] == 0.0);
}

/* ---- compressed-column matrices ---------------------------------------------- */

int ref_sp_alloc(ref_sp *A, int64_t m, int64_t n, int64_t nnz, int values)
{
    A->m = m;
    A->n = n;
    A->owned = 1;
    A->w = values;
    A->p = ref_calloc((size_t)n + 1, sizeof(int64_t));
    A->i = ref_alloc((size_t)nnz, sizeof(int64_t));
    A->x = values ? ref_alloc((size_t)nnz * (size_t)values, sizeof(double)) : NULL;
    if (!A->p || !A->i || (values && !A->x)) {
        ref_sp_free(A);
        return SILC_ENOMEM;
    }
    return 0;
}

void ref_sp_free(ref_sp *A)
{
    if (A->owned) {
        ref_free(A->p);
        ref_free(A->i);
        ref_free(A->x);
    }
    A->p = A->i = NULL;
    A->x = NULL;
    A->owned = 0;
}

int64_t ref_sp_nnz(const ref_sp *A)
{
    return A->p[A->n];
}

int ref_sp_transpose(const ref_sp *A, ref_sp *T)
{
    int64_t m = A->m, n = A->n, nz = ref_sp_nnz(A);
    int vw = A->x ? (A->w ? A->w : 1) : 0;
    if (ref_sp_alloc(T, n, m, nz, vw)) return SILC_ENOMEM;
    int64_t *w = ref_calloc((size_t)m + 1, sizeof(int64_t));
    if (!w) {
        ref_sp_free(T);
        return SILC_ENOMEM;
    }
    for (int64_t k = 0; k < nz; k++) w[A->i[k]]++;
    int64_t s = 0;
    for (int64_t r = 0; r < m; r++) {
        T->p[r] = s;
        s += w[r];
        w[r] = T->p[r];
    }
    T->p[m] = s;
    for (int64_t j = 0; j < n; j++)
        for (int64_t k = A->p[j]; k < A->p[j + 1]; k++) {
            int64_t q = w[A->i[k]]++;
            T->i[q] = j;
            if (vw == 1) T->x[q] = A->x[k];
            else if (vw == 2) copy_entry(T->x + 2 * q, A->x + 2 * k, 2);
        }
    ref_free(w);
    return 0;
}

/* Column-compressed form of a band or dense value, zeros skipped. */
static inline int sp_from_full(const silc_view *v, int w, ref_sp *A)
{
    int64_t m = v->m, n = v->n, nz = 0;
    for (int pass = 0; pass < 2; pass++) {
        nz = 0;
        for (int64_t j = 0; j < n; j++) {
            if (pass) A->p[j] = nz;
            int64_t lo = 0, hi = m;
            if (v->format == SILC_FMT_BAND) {
                lo = j - v->ku > 0 ? j - v->ku : 0;
                hi = j + v->kl + 1 < m ? j + v->kl + 1 : m;
            }
            for (int64_t i = lo; i < hi; i++) {
                const double *a = v->val + w * (v->format == SILC_FMT_BAND ? (v->ku + i - j) + j * v->ld
                                                                           : i + j * m);
                if (entry_is_zero(a, w)) continue;
                if (pass) {
                    A->i[nz] = i;
                    copy_entry(A->x + w * nz, a, w);
                }
                nz++;
            }
        }
        if (pass) {
            A->p[n] = nz;
        } else if (ref_sp_alloc(A, m, n, nz, w)) {
            return SILC_ENOMEM;
        }
    }
    return 0;
}

int ref_spt_from_view_w(const silc_view *v, int w, ref_sp *At)
{
    if (v->format == SILC_FMT_CSR) {
        At->m = v->n;
        At->n = v->m;
        At->p = v->rowptr;
        At->i = v->colind;
        At->x = v->val;
        At->owned = 0;
        At->w = w;
        return 0;
    }
    ref_sp A;
    if ((w == 2 ? sp_from_full(v, 2, &A) : sp_from_full(v, 1, &A))) return SILC_ENOMEM;
    int st = ref_sp_transpose(&A, At);
    ref_sp_free(&A);
    return st;
}

int ref_spt_from_view(const silc_view *v, ref_sp *At)
{
    return ref_spt_from_view_w(v, 1, At);
}

int ref_spt_pair(const silc_view *a, const silc_view *b, ref_sp *At, ref_sp *Bt)
{
    if (ref_spt_from_view(a, At)) return SILC_ENOMEM;
    if (ref_spt_from_view(b, Bt)) {
        ref_sp_free(At);
        return SILC_ENOMEM;
    }
    return 0;
}

int ref_sp_from_view_w(const silc_view *v, int w, ref_sp *A)
{
    if (v->format != SILC_FMT_CSR) return w == 2 ? sp_from_full(v, 2, A) : sp_from_full(v, 1, A);
    ref_sp At;
    ref_spt_from_view_w(v, w, &At);
    return ref_sp_transpose(&At, A);
}

int ref_sp_from_view(const silc_view *v, ref_sp *A)
{
    return ref_sp_from_view_w(v, 1, A);
}

double *ref_dense_from_view_w(const silc_view *v, int w)
{
    double *D = ref_calloc((size_t)v->m * (size_t)v->n * (size_t)w, sizeof(double));
    if (D) ref_dense_fill_w(v, w, D);
    return D;
}

double *ref_dense_from_view(const silc_view *v)
{
    return ref_dense_from_view_w(v, 1);
}

static inline void dense_fill(const silc_view *v, int w, double *D)
{
    int64_t m = v->m, n = v->n;
    if (v->format == SILC_FMT_DENSE) {
        if (m > 0 && n > 0) memcpy(D, v->val, (size_t)(m * n * w) * sizeof(double));
    } else if (v->format == SILC_FMT_CSR) {
        for (int64_t i = 0; i < m; i++)
            for (int64_t k = v->rowptr[i]; k < v->rowptr[i + 1]; k++)
                add_entry(D + w * (i + v->colind[k] * m), v->val + w * k, w);
    } else {
        for (int64_t j = 0; j < n; j++) {
            int64_t lo = j - v->ku > 0 ? j - v->ku : 0;
            int64_t hi = j + v->kl + 1 < m ? j + v->kl + 1 : m;
            for (int64_t i = lo; i < hi; i++)
                copy_entry(D + w * (i + j * m), v->val + w * ((v->ku + i - j) + j * v->ld), w);
        }
    }
}

void ref_dense_fill_w(const silc_view *v, int w, double *D)
{
    if (w == 2) dense_fill(v, 2, D);
    else dense_fill(v, 1, D);
}

void ref_dense_fill(const silc_view *v, double *D)
{
    dense_fill(v, 1, D);
}

void ref_view_get_w(const silc_view *v, int w, int64_t i, int64_t j, double *z)
{
    int64_t at = -1;
    z[0] = 0.0;
    if (w == 2) z[1] = 0.0;
    if (v->format == SILC_FMT_DENSE) {
        at = i + j * v->m;
    } else if (v->format == SILC_FMT_BAND) {
        if (i - j <= v->kl && j - i <= v->ku) at = (v->ku + i - j) + j * v->ld;
    } else {
        int64_t lo = v->rowptr[i], hi = v->rowptr[i + 1];
        while (lo < hi) {
            int64_t mid = lo + (hi - lo) / 2;
            if (v->colind[mid] < j) lo = mid + 1;
            else hi = mid;
        }
        if (lo < v->rowptr[i + 1] && v->colind[lo] == j) at = lo;
    }
    if (at >= 0) copy_entry(z, v->val + w * at, w);
}

double ref_view_get(const silc_view *v, int64_t i, int64_t j)
{
    if (v->format == SILC_FMT_DENSE) return v->val[i + j * v->m];
    if (v->format == SILC_FMT_BAND) {
        if (i - j > v->kl || j - i > v->ku) return 0.0;
        return v->val[(v->ku + i - j) + j * v->ld];
    }
    int64_t lo = v->rowptr[i], hi = v->rowptr[i + 1];
    while (lo < hi) { /* binary search: columns are sorted */
        int64_t mid = lo + (hi - lo) / 2;
        if (v->colind[mid] < j) lo = mid + 1;
        else hi = mid;
    }
    return (lo < v->rowptr[i + 1] && v->colind[lo] == j) ? v->val[lo] : 0.0;
}

silc_value *ref_value_from_rows(const ref_sp *R)
{
    return ref_value_from_rows_w(R, 1);
}

silc_value *ref_value_from_rows_w(const ref_sp *R, int w)
{
    int64_t nz = ref_sp_nnz(R);
    silc_value *out = w == 2 ? ref_host->csr_new_complex(R->n, R->m, nz) : ref_host->csr_new(R->n, R->m, nz);
    if (!out) return NULL;
    silc_view o;
    ref_host->view(out, &o);
    memcpy(o.rowptr, R->p, (size_t)(R->n + 1) * sizeof(silc_index));
    if (nz) {
        memcpy(o.colind, R->i, (size_t)nz * sizeof(silc_index));
        memcpy(o.val, R->x, (size_t)(nz * w) * sizeof(double));
    }
    if (ref_host->csr_set_nnz(out, nz)) {
        ref_host->release(out);
        return NULL;
    }
    return out;
}

silc_value *ref_value_from_dense(int64_t m, int64_t n, const double *x)
{
    return ref_value_from_dense_w(m, n, 1, x);
}

silc_value *ref_value_from_dense_w(int64_t m, int64_t n, int w, const double *x)
{
    silc_value *out = w == 2 ? ref_host->dense_new_complex(m, n) : ref_host->dense_new(m, n);
    if (!out) return NULL;
    silc_view o;
    ref_host->view(out, &o);
    if (m > 0 && n > 0) memcpy(o.val, x, (size_t)(m * n * w) * sizeof(double));
    return out;
}

void ref_factor_free(void *p)
{
    ref_factor *F = p;
    if (!F) return;
    if (F->destroy) F->destroy(F->data);
    ref_free(F->est_start);
    ref_free(F);
}

/* ---- accepts ------------------------------------------------------------------ */

static int ends_with(const char *s, const char *suffix)
{
    size_t a = strlen(s), b = strlen(suffix);
    return a >= b && strcmp(s + a - b, suffix) == 0;
}

/* The reference plugin runs anything, but a class promises structure the
 * kernel relies on (Cholesky reads one triangle), so refuse what would give a
 * silently wrong answer. */
static int accepts_solve(const silc_call *call, const char **why)
{
    const char *cls = call->op_class;
    if (!cls || call->nin < 2) return 1;
    const silc_props *P = ref_host->props(call->in[0]);
    if (ends_with(cls, ".spd") && ref_width(call->in[0]) == 2 && !P->hermitian) {
        *why = "needs a Hermitian matrix"; /* complex Cholesky factors A = L L^H */
        return 0;
    }
    if (ends_with(cls, ".spd") && ref_width(call->in[0]) == 1 && !P->symmetric) {
        *why = "needs a symmetric matrix";
        return 0;
    }
    if (strcmp(cls, "solve.triangular") == 0 && !P->lower && !P->upper) {
        *why = "needs a triangular matrix";
        return 0;
    }
    if (strcmp(cls, "solve.diag") == 0 && !P->diagonal) {
        *why = "needs a diagonal matrix";
        return 0;
    }
    return 1;
}

static const silc_op_entry ref_ops[SILC_OP_COUNT] = {
    [SILC_OP_ADD] = {ref_op_add, NULL},
    [SILC_OP_SCALE] = {ref_op_scale, NULL},
    [SILC_OP_MATMUL] = {ref_op_matmul, NULL},
    [SILC_OP_EWISE] = {ref_op_ewise, NULL},
    [SILC_OP_MAP] = {ref_op_map, NULL},
    [SILC_OP_TRANSPOSE] = {ref_op_transpose, NULL},
    [SILC_OP_SOLVE] = {ref_op_solve, accepts_solve},
    [SILC_OP_REDUCE] = {ref_op_reduce, NULL},
    [SILC_OP_CONVERT] = {ref_op_convert, NULL},
    [SILC_OP_DIAG] = {ref_op_diag, NULL},
};

static const silc_backend ref_backends[1] = {
    {NULL, "plain C11 oracle: every operation, every storage format", SILC_OP_COUNT, ref_ops}};

/* The ops that take complex operands (ABI 1.8): only those whose every
 * sub-operation and format has a complex kernel here. */
static const uint32_t ref_complex_ops[1] = {
    SILC_COMPLEX_OPS(SILC_OP_ADD) | SILC_COMPLEX_OPS(SILC_OP_SCALE) | SILC_COMPLEX_OPS(SILC_OP_MATMUL) |
    SILC_COMPLEX_OPS(SILC_OP_EWISE) | SILC_COMPLEX_OPS(SILC_OP_MAP) | SILC_COMPLEX_OPS(SILC_OP_TRANSPOSE) |
    SILC_COMPLEX_OPS(SILC_OP_SOLVE) | SILC_COMPLEX_OPS(SILC_OP_REDUCE) | SILC_COMPLEX_OPS(SILC_OP_CONVERT) |
    SILC_COMPLEX_OPS(SILC_OP_DIAG)};

static const silc_plugin ref_plugin = {
    SILC_ABI_MAJOR, SILC_ABI_MINOR, sizeof(silc_plugin), (int)sizeof(silc_index),
    "reference", "1.0", 1, ref_backends, 0, NULL, NULL, NULL, NULL, ref_complex_ops};

static int ref_init(const silc_host_api *host, const silc_plugin **out, const char **errmsg)
{
    if (silc_host_check(host, SILC_HOST_NEEDS(threads), errmsg) || !out) return 1;
    ref_host = host;
    *out = &ref_plugin;
    return 0;
}

#if defined(SILC_REFERENCE_BUILTIN)
int silc_reference_plugin_init(const silc_host_api *host, const silc_plugin **out,
                               const char **errmsg);
int silc_reference_plugin_init(const silc_host_api *host, const silc_plugin **out,
                               const char **errmsg)
{
    return ref_init(host, out, errmsg);
}
#else
SILC_PLUGIN_EXPORT int silc_plugin_init(const silc_host_api *host, const silc_plugin **out,
                                        const char **errmsg)
{
    return ref_init(host, out, errmsg);
}
#endif
