/*
 * value.c -- values and the store.
 *
 * A value is created mutable by one of the constructors, filled by its
 * creator, and frozen from then on (see store.h).  What lives here is the
 * bookkeeping around that: unique ids, reference counts, attachments, the
 * structural properties the dispatcher asks about (computed once, on demand,
 * with scaled norms so that entries near the overflow threshold give finite
 * answers), and the per-context store mapping names to values.
 */
#define _DEFAULT_SOURCE   /* sysconf(_SC_PHYS_PAGES) */
#include "store.h"

#include <complex.h>
#include <float.h>
#include <math.h>
#include <stdatomic.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>
#if defined(__SSE2__)
#include <emmintrin.h>
#endif

#include "util.h"

/* Ids are unique for the process lifetime, across every context and thread. */
static _Atomic uint64_t next_id = 1;

/* a*b as a non-negative element count, or -1 on overflow or negative input. */
static int64_t count_mul(int64_t a, int64_t b)
{
    if (a < 0 || b < 0) return -1;
    if (a != 0 && b > (INT64_MAX / (int64_t)sizeof(double)) / a) return -1;
    return a * b;
}

/* The array pool (val_set_array_pool); NULL: plain calloc/malloc and free.
 * Set once before the threads that use values start. */
static void *(*pool_take)(size_t bytes);
static int (*pool_give)(void *p);

void val_set_array_pool(void *(*take)(size_t bytes), int (*give)(void *p))
{
    pool_take = take;
    pool_give = give;
}

/* A pooled array is already mapped: zeroing it in place is far cheaper than
 * faulting in fresh pages, and an unset one costs nothing. */
void *val_array_alloc(int64_t count, size_t size, int zero)
{
    size_t bytes = (count > 0 ? (size_t)count : 1) * size;
    void *p = pool_take ? pool_take(bytes) : NULL;
    if (p) {
        if (zero) memset(p, 0, bytes);
        return p;
    }
    return zero ? calloc(bytes / size, size) : malloc(bytes);
}

void val_array_free(void *p)
{
    if (p && !(pool_give && pool_give(p))) free(p);
}

/* The largest value this process makes (val_set_max_bytes).  Every size a
 * statement, a file or a client claims passes here before anything is
 * allocated, so `zeros(1e6)` is refused with its size instead of reaching
 * malloc (which on Linux may say yes and let the OOM killer answer later).
 * 0 = not set: the machine's physical memory. */
static uint64_t max_value_bytes;
static const char *max_value_source = "the machine's memory";
/* Why the last constructor of this thread returned NULL when it was a size,
 * not malloc: "" otherwise (val_refusal). */
static _Thread_local char refusal[384];

void val_set_max_bytes(uint64_t bytes, const char *source)
{
    max_value_bytes = bytes;
    max_value_source = source ? source : "the machine's memory";
}

uint64_t val_max_bytes(void)
{
    /* Read once: every constructor asks, and sysconf(_SC_PHYS_PAGES) is a
     * system call.  Threads that race here store the same number. */
    static _Atomic uint64_t phys_bytes;
    uint64_t phys;
    if (max_value_bytes) return max_value_bytes;
    if (!(phys = phys_bytes)) {
        long pages = sysconf(_SC_PHYS_PAGES), size = sysconf(_SC_PAGESIZE);
        phys = pages > 0 && size > 0 ? (uint64_t)pages * (uint64_t)size : UINT64_MAX;
        phys_bytes = phys;
    }
    return phys;
}

const char *val_refusal(void)
{
    return refusal;
}

int val_claim(double bytes, const char *what)
{
    char over[200];
    double limit = (double)val_max_bytes();
    refusal[0] = '\0';
    if (bytes <= limit) return 0;
    util_fmt_over_limit(over, sizeof over, bytes, limit);
    snprintf(refusal, sizeof refusal, "%s needs %s: the most one value may hold (%s)", what, over,
             max_value_source);
    return -1;
}

double val_shape_bytes(int format, int64_t m, int64_t n, int64_t nnz, int64_t kl, int64_t ku)
{
    return val_shape_bytes_field(format, SILC_FIELD_REAL, m, n, nnz, kl, ku);
}

double val_shape_bytes_field(int format, int field, int64_t m, int64_t n, int64_t nnz, int64_t kl,
                             int64_t ku)
{
    double entry = field == SILC_FIELD_COMPLEX ? 2 * sizeof(double) : sizeof(double);
    switch (format) {
    case SILC_FMT_DENSE:
        return (double)m * (double)n * entry;
    case SILC_FMT_CSR:
        return ((double)m + 1) * sizeof(silc_index) + (double)nnz * (sizeof(silc_index) + entry);
    default:
        /* Band storage holds (kl+ku+1) x n, but the value still has m rows:
         * its norms sum by row, a product with it makes m entries.  A
         * 250000000 x 1 band value stores one double and needs 2 GB the
         * moment anyone asks for its infinity norm, so the rows are charged
         * here, where every limit looks. */
        return ((double)kl + (double)ku + 1) * (double)n * entry + ((double)m + (double)n) * entry;
    }
}

/* val_claim for a value of this format and shape.  bytes is a double: a
 * claimed size may not fit in 64 bits (sparse(1, 1, 1, 1e10, 1e10) asks
 * for 80 GB of row pointers; zeros(1e10) for 8e20 bytes). */
static int size_allowed(int format, int64_t m, int64_t n, double bytes)
{
    char what[96];
    if (bytes <= (double)val_max_bytes()) {
        refusal[0] = '\0';
        return 0;
    }
    snprintf(what, sizeof what, "a %lldx%lld %s value", (long long)m, (long long)n,
             val_format_name(format));
    return val_claim(bytes, what);
}

/* The memory a request's values may hold at once (val_budget_set).  Every
 * value array alive in this process is counted in live_value_bytes (an
 * atomic add per value made or freed); while a budget is set, a constructor
 * whose arrays would bring the count, less what was exempt, over the limit
 * is refused before it allocates, as an oversized value is. */
static _Atomic int64_t live_value_bytes;
/* The charges of the attachments alive (val_attach_live_bytes), and the
 * clock that orders their uses (val_attach_last_use). */
static _Atomic int64_t live_attach_bytes;
static _Atomic uint64_t attach_clock;
static int64_t budget_exempt;
static uint64_t budget_limit;   /* 0: no budget */
static const char *budget_source = "";
static _Atomic int budget_refusals;   /* since the budget was set */

void val_budget_set(int64_t exempt, uint64_t limit, const char *source)
{
    budget_refusals = 0;
    budget_exempt = exempt;
    budget_limit = limit;
    budget_source = source ? source : "";
}

int val_budget_refused(void)
{
    return budget_refusals > 0;
}

int64_t val_live_bytes(void)
{
    return live_value_bytes;
}

int64_t val_budget_room(void)
{
    return budget_limit ? (int64_t)budget_limit - (live_value_bytes - budget_exempt) : INT64_MAX;
}

int val_budget_claim(double bytes, const char *what)
{
    double held = (double)(live_value_bytes - budget_exempt);
    char over[200];
    if (!budget_limit || held + bytes <= (double)budget_limit) return 0;
    util_fmt_over_limit(over, sizeof over, held + bytes, (double)budget_limit);
    snprintf(refusal, sizeof refusal, "%s would bring the values held at once (bound and "
             "temporary) to %s (%s)", what, over, budget_source);
    budget_refusals++;
    return -1;
}

static int budget_refuses(int format, int64_t m, int64_t n, double bytes)
{
    char what[96];
    if (!budget_limit) return 0;
    snprintf(what, sizeof what, "a %lldx%lld %s value", (long long)m, (long long)n,
             val_format_name(format));
    return val_budget_claim(bytes, what);
}

/* Counts a value's arrays as alive (budget above), once they are made. */
static silc_value *counted(silc_value *v)
{
    atomic_fetch_add(&live_value_bytes, (int64_t)val_bytes(v));
    return v;
}

static silc_value *val_alloc(int64_t m, int64_t n, int format, int field)
{
    silc_value *v;
    if (m < 0 || n < 0) return NULL;
    v = calloc(1, sizeof *v);
    if (!v) return NULL;
    v->refcount = 1;
    v->id = atomic_fetch_add(&next_id, 1);
    v->m = m;
    v->n = n;
    v->format = format;
    v->field = field == SILC_FIELD_COMPLEX ? SILC_FIELD_COMPLEX : SILC_FIELD_REAL;
    return v;
}

/* Frees the arrays and the struct of a value that has no attachments yet. */
static void val_free_arrays(silc_value *v)
{
    val_array_free(v->val);
    val_array_free(v->rowptr);
    val_array_free(v->colind);
    free(v);
}

/* Doubles per entry of a field. */
static int field_width(int field)
{
    return field == SILC_FIELD_COMPLEX ? 2 : 1;
}

static silc_value *dense_make(int64_t m, int64_t n, int field, int zero)
{
    int64_t count = count_mul(m, n);
    silc_value *v;
    double bytes = val_shape_bytes_field(SILC_FMT_DENSE, field, m, n, 0, 0, 0);
    if (size_allowed(SILC_FMT_DENSE, m, n, bytes) || budget_refuses(SILC_FMT_DENSE, m, n, bytes))
        return NULL;
    if (count < 0 || count_mul(count, field_width(field)) < 0 ||
        !(v = val_alloc(m, n, SILC_FMT_DENSE, field)))
        return NULL;
    v->val = val_array_alloc(count * field_width(field), sizeof(double), zero);
    if (!v->val) {
        val_free_arrays(v);
        return NULL;
    }
    v->nnz = v->cap = count;
    return counted(v);
}

static silc_value *csr_make(int64_t m, int64_t n, int64_t nnz_capacity, int field, int zero)
{
    silc_value *v;
    double bytes = val_shape_bytes_field(SILC_FMT_CSR, field, m, n, nnz_capacity, 0, 0);
    if (size_allowed(SILC_FMT_CSR, m, n, bytes) || budget_refuses(SILC_FMT_CSR, m, n, bytes))
        return NULL;
    if (count_mul(m, 1) < 0 || count_mul(nnz_capacity, field_width(field)) < 0) return NULL;
    if (!(v = val_alloc(m, n, SILC_FMT_CSR, field))) return NULL;
    v->rowptr = val_array_alloc(m + 1, sizeof(silc_index), zero);
    v->colind = val_array_alloc(nnz_capacity, sizeof(silc_index), zero);
    v->val = val_array_alloc(nnz_capacity * field_width(field), sizeof(double), zero);
    if (!v->rowptr || !v->colind || !v->val) {
        val_free_arrays(v);
        return NULL;
    }
    v->cap = nnz_capacity;
    return counted(v);
}

static silc_value *band_make(int64_t m, int64_t n, int64_t kl, int64_t ku, int field, int zero)
{
    int64_t ld, count;
    silc_value *v;
    double bytes = val_shape_bytes_field(SILC_FMT_BAND, field, m, n, 0, kl, ku);
    if (size_allowed(SILC_FMT_BAND, m, n, bytes) || budget_refuses(SILC_FMT_BAND, m, n, bytes))
        return NULL;
    if (kl < 0 || ku < 0 || kl > INT64_MAX / 4 || ku > INT64_MAX / 4) return NULL;
    ld = kl + ku + 1;
    count = count_mul(ld, n);
    if (count < 0 || count_mul(count, field_width(field)) < 0 ||
        !(v = val_alloc(m, n, SILC_FMT_BAND, field)))
        return NULL;
    v->val = val_array_alloc(count * field_width(field), sizeof(double), zero);
    if (!v->val) {
        val_free_arrays(v);
        return NULL;
    }
    v->kl = kl;
    v->ku = ku;
    v->ld = ld;
    v->nnz = v->cap = count;
    return counted(v);
}

silc_value *val_dense_new(int64_t m, int64_t n)
{
    return dense_make(m, n, SILC_FIELD_REAL, 1);
}

silc_value *val_csr_new(int64_t m, int64_t n, int64_t nnz_capacity)
{
    return csr_make(m, n, nnz_capacity, SILC_FIELD_REAL, 1);
}

silc_value *val_band_new(int64_t m, int64_t n, int64_t kl, int64_t ku)
{
    return band_make(m, n, kl, ku, SILC_FIELD_REAL, 1);
}

silc_value *val_dense_new_complex(int64_t m, int64_t n)
{
    return dense_make(m, n, SILC_FIELD_COMPLEX, 1);
}

silc_value *val_csr_new_complex(int64_t m, int64_t n, int64_t nnz_capacity)
{
    return csr_make(m, n, nnz_capacity, SILC_FIELD_COMPLEX, 1);
}

silc_value *val_band_new_complex(int64_t m, int64_t n, int64_t kl, int64_t ku)
{
    return band_make(m, n, kl, ku, SILC_FIELD_COMPLEX, 1);
}

silc_value *val_new_unset_field(int format, int field, int64_t m, int64_t n, int64_t nnz, int64_t kl,
                                int64_t ku)
{
    switch (format) {
    case SILC_FMT_DENSE: return dense_make(m, n, field, 0);
    case SILC_FMT_CSR: return csr_make(m, n, nnz, field, 0);
    case SILC_FMT_BAND: return band_make(m, n, kl, ku, field, 0);
    default: return NULL;
    }
}

silc_value *val_new_unset(int format, int64_t m, int64_t n, int64_t nnz, int64_t kl, int64_t ku)
{
    return val_new_unset_field(format, SILC_FIELD_REAL, m, n, nnz, kl, ku);
}

silc_value *val_scalar_new(double x)
{
    silc_value *v = val_dense_new(1, 1);
    if (v) v->val[0] = x;
    return v;
}

silc_value *val_scalar_new_complex(double re, double im)
{
    silc_value *v = val_dense_new_complex(1, 1);
    if (v) v->val[0] = re, v->val[1] = im;
    return v;
}

/* A value of v's format, shape and pattern in field, entries unset (CSR:
 * rowptr and colind copied). */
static silc_value *same_pattern(const silc_value *v, int field)
{
    silc_value *w = val_new_unset_field(v->format, field, v->m, v->n, v->nnz, v->kl, v->ku);
    if (w && v->format == SILC_FMT_CSR) {
        memcpy(w->rowptr, v->rowptr, (size_t)(v->m + 1) * sizeof *v->rowptr);
        if (v->nnz) memcpy(w->colind, v->colind, (size_t)v->nnz * sizeof *v->colind);
        w->nnz = v->nnz;
    }
    return w;
}

silc_value *val_promote(const silc_value *v)
{
    silc_value *w;
    if (!v || v->dist) return NULL; /* the evaluator gathers first (dist.h) */
    if (v->field == SILC_FIELD_COMPLEX) return val_retain((silc_value *)v);
    if (!(w = same_pattern(v, SILC_FIELD_COMPLEX))) return NULL;
    for (int64_t k = 0; k < v->nnz; k++) w->val[2 * k] = v->val[k], w->val[2 * k + 1] = 0;
    return w;
}

silc_value *val_part(const silc_value *v, int imag)
{
    silc_value *w;
    if (!v || v->dist || !(w = same_pattern(v, SILC_FIELD_REAL))) return NULL;
    for (int64_t k = 0; k < v->nnz; k++)
        w->val[k] = v->field == SILC_FIELD_COMPLEX ? v->val[2 * k + (imag ? 1 : 0)] : imag ? 0 : v->val[k];
    return w;
}

/* re + i*im for CSR parts of one shape whose patterns differ: the union,
 * row by row (an entry missing from one part is 0 there). */
static silc_value *csr_union_of_parts(const silc_value *re, const silc_value *im)
{
    silc_value *w = val_csr_new_complex(re->m, re->n, re->nnz + im->nnz);
    int64_t i, p, q, k = 0;
    if (!w) return NULL;
    for (i = 0; i < re->m; i++) {
        p = re->rowptr[i], q = im->rowptr[i];
        while (p < re->rowptr[i + 1] || q < im->rowptr[i + 1]) {
            int64_t cp = p < re->rowptr[i + 1] ? re->colind[p] : INT64_MAX;
            int64_t cq = q < im->rowptr[i + 1] ? im->colind[q] : INT64_MAX;
            w->colind[k] = cp < cq ? cp : cq;
            w->val[2 * k] = cp <= cq ? re->val[p++] : 0;
            w->val[2 * k + 1] = cq <= cp ? im->val[q++] : 0;
            k++;
        }
        w->rowptr[i + 1] = k;
    }
    val_csr_set_nnz(w, k);
    return w;
}

silc_value *val_complex_of_parts(const silc_value *re, const silc_value *im)
{
    silc_value *w;
    if (!re || !im || re->dist || im->dist || re->field || im->field || re->format != im->format ||
        re->m != im->m || re->n != im->n || re->kl != im->kl || re->ku != im->ku)
        return NULL;
    if (re->format == SILC_FMT_CSR &&
        (re->nnz != im->nnz || memcmp(re->rowptr, im->rowptr, (size_t)(re->m + 1) * sizeof *re->rowptr) ||
         (re->nnz && memcmp(re->colind, im->colind, (size_t)re->nnz * sizeof *re->colind))))
        return csr_union_of_parts(re, im);
    if (re->nnz != im->nnz) return NULL;
    if (!(w = same_pattern(re, SILC_FIELD_COMPLEX))) return NULL;
    for (int64_t k = 0; k < re->nnz; k++) w->val[2 * k] = re->val[k], w->val[2 * k + 1] = im->val[k];
    return w;
}

int val_imag_is_zero(const silc_value *v)
{
    if (v && v->dist) v = v->dist->whole ? v->dist->whole : v->dist->block;
    if (!v || v->field != SILC_FIELD_COMPLEX) return 1;
    for (int64_t k = 0; k < v->nnz; k++)
        if (v->val[2 * k + 1] != 0) return 0;
    return 1;
}

int val_csr_set_nnz(silc_value *v, int64_t nnz)
{
    if (!v || v->format != SILC_FMT_CSR || nnz < 0 || nnz > v->cap) return -1;
    v->nnz = nnz;
    return 0;
}

silc_value *val_retain(silc_value *v)
{
    if (v) v->refcount++;
    return v;
}

void val_release(silc_value *v)
{
    val_attachment *a, *next;
    if (!v || --v->refcount > 0) return;
    /* Attachments first: a factorization may still point into the arrays. */
    for (a = v->attach; a; a = next) {
        next = a->next;
        atomic_fetch_sub(&live_attach_bytes, a->bytes);
        if (a->destroy) a->destroy(a->data);
        free(a->key);
        free(a);
    }
    v->attach = NULL;
    if (v->dist) {
        val_release(v->dist->block);
        val_release(v->dist->whole);
        dist_part_unref(v->dist->part);
        free(v->dist);
    } else {
        atomic_fetch_sub(&live_value_bytes, (int64_t)val_bytes(v));
    }
    val_free_arrays(v);
}

static val_dist_hooks dist_hooks;

void val_set_dist_hooks(const val_dist_hooks *h)
{
    dist_hooks = *h;
}

dist_part *dist_part_ref(dist_part *p)
{
    if (p) p->refcount++;
    return p;
}

void dist_part_unref(dist_part *p)
{
    if (p && --p->refcount == 0) free(p);
}

silc_value *val_dist_new(int64_t m, int64_t n, int format, struct dist_ctx *ctx, dist_part *part,
                         silc_value *block)
{
    silc_value *v = val_alloc(m, n, format, block ? block->field : SILC_FIELD_REAL);
    if (!v || !(v->dist = calloc(1, sizeof *v->dist))) {
        free(v);
        val_release(block);
        return NULL;
    }
    v->dist->ctx = ctx;
    v->dist->part = dist_part_ref(part);
    v->dist->block = block;
    return v;
}

void val_view(const silc_value *v, silc_view *out)
{
    if (v->dist) { /* a distributed value shows this rank's rows (silc_plugin.h, ABI 1.5) */
        val_view(v->dist->block, out);
        return;
    }
    out->m = v->m;
    out->n = v->n;
    out->format = v->format;
    out->val = v->val;
    out->rowptr = v->rowptr;
    out->colind = v->colind;
    out->nnz = v->nnz;
    out->kl = v->kl;
    out->ku = v->ku;
    out->ld = v->ld;
}

int val_is_scalar(const silc_value *v)
{
    return v && v->m == 1 && v->n == 1;
}

double val_scalar(const silc_value *v)
{
    return val_get(v, 0, 0);
}

/* The position in val (in entries) of (i, j) of a whole value, -1 when it
 * is not stored. */
static int64_t entry_index(const silc_value *v, int64_t i, int64_t j)
{
    switch (v->format) {
    case SILC_FMT_DENSE:
        return i + j * v->m;
    case SILC_FMT_CSR: {
        int64_t lo = v->rowptr[i], hi = v->rowptr[i + 1] - 1;
        while (lo <= hi) {
            int64_t mid = lo + (hi - lo) / 2;
            if (v->colind[mid] == j) return mid;
            if (v->colind[mid] < j) lo = mid + 1;
            else hi = mid - 1;
        }
        return -1;
    }
    case SILC_FMT_BAND:
        if (i - j > v->kl || j - i > v->ku) return -1;
        return (v->ku + i - j) + j * v->ld;
    default:
        return -1;
    }
}

double complex val_get_complex(const silc_value *v, int64_t i, int64_t j)
{
    int64_t k;
    if (v && v->dist) /* the evaluator gathers before reading entries (dist.h) */
        return v->dist->whole ? val_get_complex(v->dist->whole, i, j) : NAN;
    if (!v || i < 0 || j < 0 || i >= v->m || j >= v->n || (k = entry_index(v, i, j)) < 0) return 0;
    if (v->field != SILC_FIELD_COMPLEX) return v->val[k];
    return util_cmplx(v->val[2 * k], v->val[2 * k + 1]);
}

double val_get(const silc_value *v, int64_t i, int64_t j)
{
    int64_t k;
    if (v && v->dist) /* the evaluator gathers before reading entries (dist.h) */
        return v->dist->whole ? val_get(v->dist->whole, i, j) : NAN;
    if (!v || i < 0 || j < 0 || i >= v->m || j >= v->n || (k = entry_index(v, i, j)) < 0) return 0.0;
    return v->val[k * val_width(v)];
}

int val_same_contents(const silc_value *a, const silc_value *b)
{
    silc_view x, y;
    if (!a || !b || a->dist || b->dist) return 0;
    if (a == b) return 1;
    if (a->field != b->field) return 0;
    val_view(a, &x);
    val_view(b, &y);
    return view_same_contents(&x, &y, val_width(a));
}

int view_same_contents(const silc_view *x, const silc_view *y, int width)
{
    if (x->format != y->format || x->m != y->m || x->n != y->n || x->nnz != y->nnz || x->kl != y->kl ||
        x->ku != y->ku)
        return 0;
    /* rowptr first: when it matches, nnz entries of colind are there to read. */
    if (x->format == SILC_FMT_CSR &&
        (memcmp(x->rowptr, y->rowptr, (size_t)(x->m + 1) * sizeof *x->rowptr) ||
         memcmp(x->colind, y->colind, (size_t)x->nnz * sizeof *x->colind)))
        return 0;
    return x->nnz == 0 || !memcmp(x->val, y->val, (size_t)x->nnz * (size_t)width * sizeof *x->val);
}

size_t val_bytes(const silc_value *v)
{
    size_t b;
    if (!v) return 0;
    if (v->dist) return val_bytes(v->dist->block) + val_bytes(v->dist->whole);
    b = (size_t)v->cap * (size_t)val_width(v) * sizeof(double);
    if (v->format == SILC_FMT_CSR)
        b += (size_t)(v->m + 1) * sizeof(silc_index) + (size_t)v->cap * sizeof(silc_index);
    return b;
}

const char *val_format_name(int format)
{
    switch (format) {
    case SILC_FMT_DENSE: return "dense";
    case SILC_FMT_CSR: return "csr";
    case SILC_FMT_BAND: return "band";
    default: return "unknown";
    }
}

/* ---- attachments --------------------------------------------------------- */

void *val_attach_get(const silc_value *v, const char *key)
{
    val_attachment *a;
    if (!v || !key) return NULL;
    for (a = v->attach; a; a = a->next)
        if (strcmp(a->key, key) == 0) {
            a->used = atomic_fetch_add(&attach_clock, 1) + 1; /* derived data: see val_attach_set */
            return a->data;
        }
    return NULL;
}

/* Attachments are derived data, not part of the value's contents, so hanging
 * one on a frozen value is allowed (hence the cast).  On failure the caller
 * keeps ownership of data. */
int val_attach_set(const silc_value *cv, const char *key, void *data, void (*destroy)(void *))
{
    silc_value *v = (silc_value *)cv;
    val_attachment *a;
    if (!v || !key) return -1;
    for (a = v->attach; a; a = a->next) {
        if (strcmp(a->key, key) == 0) {
            if (a->data != data && a->destroy) a->destroy(a->data);
            a->data = data;
            a->destroy = destroy;
            a->used = atomic_fetch_add(&attach_clock, 1) + 1;
            return 0;
        }
    }
    a = malloc(sizeof *a);
    if (!a) return -1;
    a->key = util_strdup(key);
    if (!a->key) {
        free(a);
        return -1;
    }
    a->data = data;
    a->destroy = destroy;
    a->bytes = 0;
    a->charged = 0;
    a->used = atomic_fetch_add(&attach_clock, 1) + 1;
    a->next = v->attach;
    v->attach = a;
    return 0;
}

int val_attach_charge(const silc_value *cv, const char *key, int64_t bytes)
{
    val_attachment *a;
    if (!cv || !key) return -1;
    for (a = cv->attach; a; a = a->next)
        if (strcmp(a->key, key) == 0) {
            atomic_fetch_sub(&live_attach_bytes, a->bytes);
            a->bytes = bytes > 0 ? bytes : 0;
            a->charged = 1;
            atomic_fetch_add(&live_attach_bytes, a->bytes);
            return 0;
        }
    return -1;
}

int64_t val_attach_release(const silc_value *cv)
{
    silc_value *v = (silc_value *)cv; /* derived data, as in val_attach_set */
    val_attachment **pa, *a;
    int64_t freed = 0;
    if (!v) return 0;
    for (pa = &v->attach; (a = *pa) != NULL;) {
        if (!a->charged) {
            pa = &a->next;
            continue;
        }
        *pa = a->next; /* out of the list before its destructor runs */
        freed += a->bytes;
        atomic_fetch_sub(&live_attach_bytes, a->bytes);
        if (a->destroy) a->destroy(a->data);
        free(a->key);
        free(a);
    }
    return freed;
}

uint64_t val_attach_last_use(const silc_value *v)
{
    const val_attachment *a;
    uint64_t last = 0;
    for (a = v ? v->attach : NULL; a; a = a->next)
        if (a->charged && a->used > last) last = a->used;
    return last;
}

int64_t val_attach_live_bytes(void)
{
    return live_attach_bytes;
}

int64_t val_attach_bytes(const silc_value *v)
{
    const val_attachment *a;
    int64_t total = 0;
    for (a = v ? v->attach : NULL; a; a = a->next) total += a->bytes;
    return total;
}

/* ---- structural properties ------------------------------------------------ */

/* The properties come in three parts, each computed when first asked for
 * (val_props_part): the shape (what classifies a solve: triangles, band,
 * nonzeros, positive diagonal, NaN/Inf), the exact symmetry, and the norms.
 * A solve needs the shape of its matrix, its symmetry only when the shape
 * leaves the question open, and of the norms only ||A||_inf, which the
 * backward error's residual pass sums as it goes; so a KLU solve of memplus
 * no longer pays for column sums it never reads (the properties took 4% of
 * it).  Plugins ask for the parts they read (host->props_part); a CSR value
 * made by silc_put has its shape from the copy (val_csr_fill_checked), and
 * a dense one solved bare may get its shape in the pass that copies it for
 * the backend's factorization (val_shape_into).
 *
 * The norms are first summed unscaled, which is exact enough and cannot
 * overflow or underflow harmfully while every |a| lies in
 * [2^-NORM_SAFE_EXP, 2^NORM_SAFE_EXP] (squares stay normal, and 2^63 of them
 * stay finite); only a value with entries beyond that gets a second pass on
 * entries multiplied by a power of two chosen from maxabs (the idea of
 * LAPACK's dlassq; a power of two keeps the scaling itself exact). */
#define NORM_SAFE_EXP 450

typedef struct props_acc {
    silc_props *p;
    int64_t pos_diag_count;
    int structure;           /* this pass also gathers the shape */
    double scale;
    double *colsum, *rowsum; /* NULL if they could not be allocated */
    double total, sumsq, maxabs;
} props_acc;

/* What a nonzero at (i, j) off the diagonal says of the shape: not
 * diagonal, not the triangle it lies outside, and a band at least that
 * wide. */
static inline void shape_off_diagonal(silc_props *p, int64_t i, int64_t j)
{
    p->diagonal = 0;
    if (j > i) {
        p->lower = 0;
        if (j - i > p->ku) p->ku = j - i;
    } else {
        p->upper = 0;
        if (i - j > p->kl) p->kl = i - j;
    }
}

/* One entry of modulus x at (i, j): nonzero, finite and positive (real
 * and > 0) as the entry is. */
static inline void props_entry_mod(props_acc *acc, int64_t i, int64_t j, double x, int nonzero,
                                   int finite, int positive)
{
    double xs = x * acc->scale;
    if (x != x) acc->maxabs = x; /* NaN is sticky: x > NaN is false from then on */
    else if (x > acc->maxabs) acc->maxabs = x;
    if (acc->structure) {
        silc_props *p = acc->p;
        if (!finite) p->has_nonfinite = 1;
        if (i == j && positive) acc->pos_diag_count++;
        if (nonzero) {
            p->nnz++;
            if (i != j) shape_off_diagonal(p, i, j);
        }
    }
    acc->total += xs;
    acc->sumsq += xs * xs;
    if (acc->colsum) acc->colsum[j] += xs;
    if (acc->rowsum) acc->rowsum[i] += xs;
}

static inline void props_entry(props_acc *acc, int64_t i, int64_t j, double a)
{
    props_entry_mod(acc, i, j, fabs(a), a != 0, isfinite(a), a > 0);
}

/* A complex entry: its modulus (hypot: no overflow of the squares), and
 * positive only when real and > 0 (what Cholesky needs of a diagonal). */
static void props_entry_complex(props_acc *acc, int64_t i, int64_t j, const double *z)
{
    double re = z[0], im = z[1];
    props_entry_mod(acc, i, j, hypot(re, im), re != 0 || im != 0, isfinite(re) && isfinite(im),
                    re > 0 && im == 0);
}

/* Calls fn on every stored entry (i, j) of a whole value, k its position in
 * val counted in entries (explicit zeros included; band corners outside the
 * matrix skipped).  For the complex passes, which need no inlined loops. */
static void each_entry(const silc_value *v, void (*fn)(void *ctx, int64_t i, int64_t j, int64_t k),
                       void *ctx)
{
    int64_t i, j, k;
    switch (v->format) {
    case SILC_FMT_DENSE:
        for (j = 0; j < v->n; j++)
            for (i = 0; i < v->m; i++) fn(ctx, i, j, i + j * v->m);
        break;
    case SILC_FMT_CSR:
        for (i = 0; i < v->m; i++)
            for (k = v->rowptr[i]; k < v->rowptr[i + 1]; k++) fn(ctx, i, v->colind[k], k);
        break;
    case SILC_FMT_BAND:
        for (j = 0; j < v->n; j++) {
            int64_t lo = j - v->ku > 0 ? j - v->ku : 0;
            int64_t hi = j + v->kl < v->m - 1 ? j + v->kl : v->m - 1;
            for (i = lo; i <= hi; i++) fn(ctx, i, j, (v->ku + i - j) + j * v->ld);
        }
        break;
    default:
        break;
    }
}

typedef struct complex_pass {
    const silc_value *v;
    props_acc *acc;
    int symmetric, hermitian;  /* symmetry walk: still possible */
} complex_pass;

static void complex_props_entry(void *ctx, int64_t i, int64_t j, int64_t k)
{
    complex_pass *c = ctx;
    props_entry_complex(c->acc, i, j, c->v->val + 2 * k);
}

/* A complex value's entry against its mirror: A = A.' and A = A' hold when
 * every stored entry equals its mirror, resp. its mirror's conjugate (an
 * entry whose mirror is not stored meets 0 there). */
static void complex_symmetry_entry(void *ctx, int64_t i, int64_t j, int64_t k)
{
    complex_pass *c = ctx;
    double complex a = util_cmplx(c->v->val[2 * k], c->v->val[2 * k + 1]), b;
    if (!c->symmetric && !c->hermitian) return;
    b = i == j ? a : val_get_complex(c->v, j, i);
    if (a != b) c->symmetric = 0;
    if (a != conj(b)) c->hermitian = 0;
}

/* props_entry on every stored entry (explicit zeros included); called
 * directly, not through a pointer, so that it inlines into each loop. */
static void props_pass(const silc_value *v, props_acc *acc)
{
    int64_t i, j, k;
    if (v->field == SILC_FIELD_COMPLEX) {
        complex_pass c = {v, acc, 0, 0};
        each_entry(v, complex_props_entry, &c);
        return;
    }
    switch (v->format) {
    case SILC_FMT_DENSE:
        for (j = 0; j < v->n; j++)
            for (i = 0; i < v->m; i++) props_entry(acc, i, j, v->val[i + j * v->m]);
        break;
    case SILC_FMT_CSR:
        for (i = 0; i < v->m; i++)
            for (k = v->rowptr[i]; k < v->rowptr[i + 1]; k++) props_entry(acc, i, v->colind[k], v->val[k]);
        break;
    case SILC_FMT_BAND:
        for (j = 0; j < v->n; j++) {
            int64_t lo = j - v->ku > 0 ? j - v->ku : 0;
            int64_t hi = j + v->kl < v->m - 1 ? j + v->kl : v->m - 1;
            for (i = lo; i <= hi; i++) props_entry(acc, i, j, v->val[(v->ku + i - j) + j * v->ld]);
        }
        break;
    default:
        break;
    }
}

/* |*x| as its bit pattern (the sign bit cleared). */
static inline uint64_t magnitude_bits(const double *x)
{
    uint64_t b;
    memcpy(&b, x, sizeof b);
    return b & 0x7fffffffffffffffULL;
}

/* Two doubles as one SSE2 register (GCC's and Clang's vector extension: the
 * build already requires a GCC-compatible compiler, CMakeLists.txt's flags).
 * GCC 12 -O2 vectorizes neither a 64-bit integer maximum (no such
 * instruction before SSE4.2) nor a floating-point one (IEEE compare-and-
 * select is not a MAX_EXPR without -ffinite-math-only), so the kernel below
 * says in pairs what it wants. */
typedef double double_pair __attribute__((vector_size(16)));
typedef int64_t int64_pair __attribute__((vector_size(16)));

static inline double_pair load_pair(const double *x)
{
    double_pair v;
    memcpy(&v, x, sizeof v); /* unaligned: a column starts anywhere */
    return v;
}

/* The larger of each lane of m and a, for lanes that are not NaN (the
 * caller detects NaN apart).  maxpd where SSE2 is the baseline; elsewhere a
 * compare and a select, which the compiler lowers to what it has. */
static inline double_pair pair_max(double_pair m, double_pair a)
{
#if defined(__SSE2__)
    return (double_pair)_mm_max_pd((__m128d)m, (__m128d)a);
#else
    int64_pair up = (int64_pair)(a > m);
    return (double_pair)(((int64_pair)a & up) | ((int64_pair)m & ~up));
#endif
}

/* The largest |x_i| as its bit pattern, and with count_zeros also the
 * number of stored zeros (-0.0 is one), in one branch-free pass.  Inf is
 * the largest magnitude it is; any NaN makes the answer a NaN pattern (above
 * Inf's), which is all scan_from_bits asks.  Eight entries a step in four
 * register pairs, two accumulators of each kind: the magnitude by masking
 * the sign, a maxpd, a sum of the magnitudes (NaN exactly when one of them
 * is: they are never negative, so Inf - Inf cannot occur, and an overflow
 * gives Inf, not NaN), and (x == 0) counted by subtracting its all-ones
 * mask.  4.0 instructions an entry of shape_pass_dense where the 64-bit
 * integer maximum it replaced took 7.9 (callgrind, docs/overhead.md).
 * Inlined with a constant count_zeros, so each caller gets the loop it
 * needs. */
static inline uint64_t max_abs_bits(const double *x, int64_t n, int count_zeros, int64_t *zeros)
{
    const int64_pair magnitude = {INT64_MAX, INT64_MAX};
    const double_pair zero = {0, 0};
    double_pair m0 = zero, m1 = zero, s0 = zero, s1 = zero;
    int64_pair z0 = {0, 0}, z1 = z0;
    int64_t i = 0;
    for (; i + 8 <= n; i += 8) {
        double_pair a0 = (double_pair)((int64_pair)load_pair(x + i) & magnitude);
        double_pair a1 = (double_pair)((int64_pair)load_pair(x + i + 2) & magnitude);
        double_pair a2 = (double_pair)((int64_pair)load_pair(x + i + 4) & magnitude);
        double_pair a3 = (double_pair)((int64_pair)load_pair(x + i + 6) & magnitude);
        m0 = pair_max(m0, pair_max(a0, a1)), m1 = pair_max(m1, pair_max(a2, a3));
        s0 += a0 + a1, s1 += a2 + a3;
        /* (the casts: Clang types a comparison's lanes long long, not int64_t) */
        if (count_zeros)
            z0 -= (int64_pair)(a0 == zero) + (int64_pair)(a1 == zero),
                z1 -= (int64_pair)(a2 == zero) + (int64_pair)(a3 == zero);
    }
    m0 = pair_max(m0, m1);
    s0 += s1;
    z0 += z1;
    double top = m0[1] > m0[0] ? m0[1] : m0[0], total = s0[0] + s0[1];
    int64_t z = z0[0] + z0[1];
    for (; i < n; i++) {
        double a = fabs(x[i]);
        top = a > top ? a : top;
        total += a;
        z += a == 0;
    }
    if (count_zeros) *zeros = z;
    if (total != total) return 0x7ff8000000000000ULL; /* a NaN */
    uint64_t bits;
    memcpy(&bits, &top, sizeof bits);
    return bits;
}

/* The shape and the norms of a dense value in one pass of short loops a
 * compiler vectorizes, where props_pass's entry-by-entry bookkeeping (a
 * dozen branches an entry) cost a tenth of a dgetrf at n = 2000.  A column
 * is summed, then its first and last nonzero found from either end (one
 * step each in a full column).  The sums see a NaN or an Inf (and an
 * overflow) as a non-finite total: then 1 is returned and the caller takes
 * the entry-by-entry path, which says which. */
static int norms_shape_pass_dense(const silc_value *v, props_acc *acc)
{
    silc_props *p = acc->p;
    const int64_t m = v->m, n = v->n;
    double total = 0, sumsq = 0, maxabs = 0;
    int64_t nnz = 0, pos = 0;
    for (int64_t j = 0; j < n; j++) {
        const double *c = v->val + j * m;
        double cs = 0, sq = 0, mx = 0;
        int64_t nz = 0, first, last;
        for (int64_t i = 0; i < m; i++) {
            double x = fabs(c[i]);
            cs += x;
            sq += x * x;
            mx = x > mx ? x : mx;
            nz += c[i] != 0;
            acc->rowsum[i] += x;
        }
        acc->colsum[j] = cs;
        total += cs;
        sumsq += sq;
        maxabs = mx > maxabs ? mx : maxabs;
        if (j < m && c[j] > 0) pos++;
        if (!nz) continue;
        nnz += nz;
        for (first = 0; c[first] == 0; first++) {}
        for (last = m - 1; c[last] == 0; last--) {}
        /* the column's outermost nonzeros bound everything between */
        if (first != j) shape_off_diagonal(p, first, j);
        if (last != j && last != first) shape_off_diagonal(p, last, j);
    }
    if (!isfinite(total) || !isfinite(sumsq)) return 1;
    p->nnz = nnz;
    acc->pos_diag_count = pos;
    acc->total = total;
    acc->sumsq = sumsq;
    acc->maxabs = maxabs;
    return 0;
}

static void scan_from_bits(silc_value *v, uint64_t maxbits);

/* The shape's starting answers, before any entry disproves them. */
static void shape_start(const silc_value *v, silc_props *p)
{
    p->square = v->m == v->n;
    p->diagonal = p->lower = p->upper = 1;
    p->kl = p->ku = p->nnz = 0;
    p->has_nonfinite = 0;
}

/* The shape of a real dense value alone, for a solve that reports neither a
 * condition estimate nor a backward error (the dispatcher's solve_parts):
 * the answers norms_shape_pass_dense gives, without its ordered sums, which
 * GCC does not vectorize (a third of a dgesv's time at n = 1000 went to
 * them).  A column is one branch-free pass of max_abs_bits (its zeros, and
 * Inf or NaN as a magnitude at or above Inf's), then its outermost nonzeros
 * from either end.  A NaN counts as a nonzero, as c[i] != 0 says.  The
 * largest magnitude it finds on the way fills the scan cache too (as
 * shape_store does for CSR): the scaling hook's val_max_abs, asked right
 * after, would otherwise read A a second time.
 *
 * With copy, each column is first copied there and read from the copy,
 * which the copy has just put in L1: one read of v from memory serves both
 * (val_shape_into). */
static void shape_pass_dense(silc_value *v, silc_props *p, double *copy)
{
    const int64_t m = v->m, n = v->n;
    int64_t nnz = 0, pos = 0;
    uint64_t top = 0;
    shape_start(v, p);
    for (int64_t j = 0; j < n; j++) {
        const double *c = v->val + j * m;
        if (copy) c = memcpy(copy + j * m, c, (size_t)m * sizeof *c);
        int64_t zeros = 0, first, last;
        uint64_t mx = max_abs_bits(c, m, 1, &zeros);
        top = mx > top ? mx : top;
        if (j < m && c[j] > 0) pos++;
        if (zeros == m) continue;
        nnz += m - zeros;
        for (first = 0; c[first] == 0; first++) {}
        for (last = m - 1; c[last] == 0; last--) {}
        if (first != j) shape_off_diagonal(p, first, j);
        if (last != j && last != first) shape_off_diagonal(p, last, j);
    }
    p->nnz = nnz;
    scan_from_bits(v, top);
    p->has_nonfinite = v->scan_nonfinite;
    p->pos_diag = p->square && n > 0 && pos == n;
}

/* What a pass over a CSR value's rows gathers for the shape.  A local of
 * that pass: p's int64_t fields could alias colind, and the compiler would
 * reload them on every row. */
typedef struct shape_rows {
    int64_t kl, ku, pos_diag;
    int diagonal, lower, upper;
} shape_rows;

/* Row i (entries begin..end-1) of a CSR value with sorted rows: its first
 * and last nonzero give the band and triangle flags, and its diagonal entry
 * is found by bisection, so the row's other column indices are not read. */
static inline void shape_row(shape_rows *s, int64_t i, const silc_index *ci, const double *x,
                             int64_t begin, int64_t end)
{
    int64_t f, l;
    for (f = begin; f < end && x[f] == 0; f++) {}
    if (f == end) return;
    for (l = end - 1; x[l] == 0; l--) {}
    s->diagonal &= ci[f] == i && ci[l] == i;
    s->lower &= ci[l] <= i;
    s->upper &= ci[f] >= i;
    s->ku = ci[l] - i > s->ku ? ci[l] - i : s->ku;
    s->kl = i - ci[f] > s->kl ? i - ci[f] : s->kl;
    if (ci[f] <= i && ci[l] >= i) {
        while (f < l) { /* first position in [f, l] with column >= i */
            int64_t mid = f + (l - f) / 2;
            if (ci[mid] < i) f = mid + 1;
            else l = mid;
        }
        s->pos_diag += ci[f] == i && x[f] > 0;
    }
}

/* Stores the shape of a CSR value from its rows' pass and its values'
 * largest magnitude (as bits, max_abs_bits) and zero count.  The same pass
 * answers the scan (largest entry, NaN/Inf) the scaling hook asks of the
 * matrix next. */
static void shape_store(silc_value *v, const shape_rows *s, uint64_t maxbits, int64_t zeros)
{
    silc_props *p = &v->props;
    shape_start(v, p);
    scan_from_bits(v, maxbits);
    p->has_nonfinite = v->scan_nonfinite;
    p->nnz = v->nnz - zeros;
    p->diagonal = s->diagonal, p->lower = s->lower, p->upper = s->upper;
    p->kl = s->kl, p->ku = s->ku;
    p->pos_diag = p->square && v->n > 0 && s->pos_diag == v->n;
    v->props_have |= SILC_PROPS_SHAPE;
}

/* The shape of a CSR value: one branch-free pass over the values for the
 * zero count, NaN/Inf and the largest entry, and shape_row on every row.
 * 0.12 ms on memplus, where all the properties took 0.44. */
static void shape_csr(silc_value *v)
{
    shape_rows s = {0, 0, 0, 1, 1, 1};
    int64_t i, zeros = 0;
    uint64_t maxbits = max_abs_bits(v->val, v->nnz, 1, &zeros);
    for (i = 0; i < v->m; i++) shape_row(&s, i, v->colind, v->val, v->rowptr[i], v->rowptr[i + 1]);
    shape_store(v, &s, maxbits, zeros);
}

int val_csr_fill_checked(silc_value *v, const silc_index *rowptr, const silc_index *colind,
                         const double *values)
{
    shape_rows s = {0, 0, 0, 1, 1, 1};
    silc_index *ci = v->colind;
    double *x = v->val;
    int64_t n = v->n, i, k, zeros = 0;
    uint64_t maxbits = 0;
    if (rowptr != v->rowptr) memcpy(v->rowptr, rowptr, (size_t)(v->m + 1) * sizeof *rowptr);
    if (v->field == SILC_FIELD_COMPLEX) {
        /* Columns checked and entries copied; the shape is left to the
         * properties' complex pass, when asked for. */
        for (i = 0; i < v->m; i++) {
            int64_t prev = -1;
            for (k = rowptr[i]; k < rowptr[i + 1]; k++) {
                if (colind[k] <= prev || colind[k] >= n) return -1;
                prev = ci[k] = colind[k];
            }
        }
        if (values != x && rowptr[v->m] > 0) memcpy(x, values, (size_t)rowptr[v->m] * 2 * sizeof *x);
        v->nnz = rowptr[v->m];
        val_forget_caches(v);
        return 0;
    }
    for (i = 0; i < v->m; i++) {
        int64_t begin = rowptr[i], end = rowptr[i + 1], prev = -1, bad = 0;
        for (k = begin; k < end; k++) {
            int64_t c = colind[k];
            uint64_t b = magnitude_bits(values + k); /* max_abs_bits' scan, entry by entry */
            bad |= (c <= prev) | (c >= n); /* out of [0, n), or not increasing */
            prev = c;
            ci[k] = c;
            x[k] = values[k];
            zeros += b == 0;
            maxbits = b > maxbits ? b : maxbits;
        }
        if (bad) return -1;
        shape_row(&s, i, ci, x, begin, end); /* while the row is in cache */
    }
    v->nnz = rowptr[v->m];
    shape_store(v, &s, maxbits, zeros);
    return 0;
}

/* The norms' sums over a CSR value without the shape's per-entry work: the
 * row sum is a local, and a NaN or Inf shows up as a non-finite total (the
 * caller then redoes the value entry by entry, which also tells a huge
 * finite sum from an Inf). */
static void norms_pass_csr(const silc_value *v, props_acc *acc)
{
    double total = 0, sumsq = 0, maxabs = 0;
    int64_t i, k;
    for (i = 0; i < v->m; i++) {
        double rs = 0;
        for (k = v->rowptr[i]; k < v->rowptr[i + 1]; k++) {
            double x = fabs(v->val[k]);
            rs += x;
            sumsq += x * x;
            maxabs = x > maxabs ? x : maxabs;
            if (acc->colsum) acc->colsum[v->colind[k]] += x;
        }
        if (acc->rowsum) acc->rowsum[i] = rs;
        total += rs;
    }
    acc->maxabs = maxabs;
    acc->total = total;
    acc->sumsq = sumsq;
}

static double max_of(const double *x, int64_t n)
{
    double best = 0.0;
    int64_t k;
    for (k = 0; k < n; k++) {
        if (x[k] != x[k]) return x[k];
        if (x[k] > best) best = x[k];
    }
    return best;
}

/* The stored value at (i, j) of a CSR matrix with sorted rows, 0 if absent. */
static double csr_at(const silc_value *v, int64_t i, int64_t j)
{
    int64_t lo = v->rowptr[i], hi = v->rowptr[i + 1];
    while (lo < hi) {
        int64_t mid = lo + (hi - lo) / 2;
        if (v->colind[mid] < j) lo = mid + 1;
        else hi = mid;
    }
    return lo < v->rowptr[i + 1] && v->colind[lo] == j ? v->val[lo] : 0;
}

/* A matrix that is unsymmetric is usually so all over (memplus: its walk
 * below met the first mismatch only after a third of the rows, 0.9% of a
 * KLU solve): 64 rows spread over the matrix, each entry compared with its
 * mirror by bisection, settle most of them in microseconds.  0 when a
 * mismatch was found, 1 when none was (which proves nothing). */
static int csr_symmetric_probe(const silc_value *v)
{
    int64_t n = v->n, r, k, step = n / 64 > 0 ? n / 64 : 1;
    for (r = step / 2; r < n; r += step)
        for (k = v->rowptr[r]; k < v->rowptr[r + 1]; k++)
            if (v->colind[k] != r && v->val[k] != csr_at(v, v->colind[k], r)) return 0;
    return 1;
}

/* Exact value symmetry of a CSR matrix: the numerically nonzero entries of A
 * and of A' must coincide.  Rows are sorted, so walking the rows in order
 * meets the entries (j, i), i > j, of row j in increasing i: next[j] is the
 * next such entry row i must find as the mirror of its (i, j).  Row j's own
 * walk stops where its upper part begins, which is where next[j] starts, so
 * one pass sets and uses it.
 *
 * The common case, no stored zeros, gets a walk without their skipping
 * loops, whose entries' tests only decide whether to leave: 0.18 ms on
 * bcsstk16 where the walk below takes 0.30.  It returns 1 when every lower
 * entry met its equal mirror at the very next position and every upper entry
 * was met (a proof), and 0 at the first thing it cannot settle: a mismatch,
 * a zero or NaN.  next has n entries. */
static int csr_symmetric_plain(const silc_value *v, int64_t *next)
{
    const silc_index *rp = v->rowptr, *ci = v->colind;
    const double *x = v->val;
    int64_t n = v->n, i, j, k, q, end;
    for (i = 0; i < n; i++) {
        end = rp[i + 1];
        for (k = rp[i]; k < end && ci[k] < i; k++) {
            j = ci[k];
            q = next[j]++;
            if (q >= rp[j + 1] || ci[q] != i || x[q] != x[k] || x[k] == 0) return 0;
        }
        next[i] = k + (k < end && ci[k] == i); /* the diagonal mirrors itself */
    }
    for (j = 0; j < n; j++)
        if (next[j] != rp[j + 1]) return 0;
    return 1;
}

/* The same walk skipping stored zeros, for what the plain walk left open;
 * an unsymmetric matrix costs only the rows before its first mismatch. */
static int csr_symmetric_zeros(const silc_value *v, int64_t *next)
{
    int64_t n = v->n, i, j, k, q;
    for (i = 0; i < n; i++) {
        for (k = v->rowptr[i]; k < v->rowptr[i + 1] && v->colind[k] < i; k++) {
            if (v->val[k] == 0) continue;
            j = v->colind[k];
            for (q = next[j]; q < v->rowptr[j + 1] && v->val[q] == 0; q++) {}
            if (q >= v->rowptr[j + 1] || v->colind[q] != i || v->val[q] != v->val[k]) return 0;
            next[j] = q + 1;
        }
        if (k < v->rowptr[i + 1] && v->colind[k] == i) k++;
        next[i] = k;
    }
    /* Every nonzero above the diagonal must have been met as a mirror. */
    for (j = 0; j < n; j++)
        for (q = next[j]; q < v->rowptr[j + 1]; q++)
            if (v->val[q] != 0) return 0;
    return 1;
}

/* 1 or 0, after csr_symmetric_probe found no mismatch; -1 when out of
 * memory. */
static int csr_symmetric(const silc_value *v)
{
    int64_t *next;
    int sym;
    if (!csr_symmetric_probe(v)) return 0;
    next = util_large_malloc((size_t)(v->n ? v->n : 1) * sizeof *next); /* large: huge pages (compute_norms) */
    if (!next) return -1;
    sym = csr_symmetric_plain(v, next) || csr_symmetric_zeros(v, next);
    util_large_free(next);
    return sym;
}

/* A = A' for a dense n x n column-major array, compared tile by tile: the
 * plain loop reads a row of A with a stride of n doubles, one cache miss an
 * entry, and on a 2000 x 2000 SPD matrix took a tenth of the time dpotrf
 * takes to factor it.  A tile pair (I, J) and (J, I) fits in the cache. */
#define SYM_TILE 32

static int dense_symmetric(const double *a, int64_t n)
{
    for (int64_t tj = 0; tj < n; tj += SYM_TILE) {
        int64_t jend = tj + SYM_TILE < n ? tj + SYM_TILE : n;
        for (int64_t ti = tj; ti < n; ti += SYM_TILE) {
            int64_t iend = ti + SYM_TILE < n ? ti + SYM_TILE : n;
            for (int64_t j = tj; j < jend; j++)
                for (int64_t i = ti > j + 1 ? ti : j + 1; i < iend; i++)
                    if (a[i + j * n] != a[j + i * n]) return 0;
        }
    }
    return 1;
}

/* Symmetry of dense and band values through element access; -1 if unknown. */
static int value_symmetric(const silc_value *v)
{
    int64_t i, j;
    if (v->m != v->n) return 0;
    switch (v->format) {
    case SILC_FMT_CSR:
        return csr_symmetric(v);
    case SILC_FMT_DENSE:
        return dense_symmetric(v->val, v->n);
    case SILC_FMT_BAND:
        for (j = 0; j < v->n; j++) {
            int64_t hi = j + v->kl < v->m - 1 ? j + v->kl : v->m - 1;
            for (i = j + 1; i <= hi; i++)
                if (val_get(v, i, j) != val_get(v, j, i)) return 0;
            hi = j + v->ku < v->m - 1 ? j + v->ku : v->m - 1;
            for (i = j + 1; i <= hi; i++)
                if (val_get(v, j, i) != val_get(v, i, j)) return 0;
        }
        return 1;
    default:
        return 0;
    }
}

/* Readies acc for a pass: zero sums, and for a pass that also gathers the
 * shape, its starting answers. */
static void props_start(const silc_value *v, props_acc *acc, int structure, double scale)
{
    if (structure) {
        shape_start(v, acc->p);
        acc->pos_diag_count = 0;
    }
    acc->structure = structure;
    acc->scale = scale;
    acc->total = acc->sumsq = acc->maxabs = 0;
    if (acc->colsum) memset(acc->colsum, 0, (size_t)v->n * sizeof(double));
    if (acc->rowsum) memset(acc->rowsum, 0, (size_t)v->m * sizeof(double));
}

/* Fills the norms, and the shape with them when shape is set (a format
 * other than CSR has no cheaper way to its shape).  cols = 0: no column
 * sums, and norm1 = NaN (val_row_norms).  Returns 0, or -1 when memory ran
 * short: then both operator norms are replaced by the upper bound
 * sum|a_ij| and the caller does not mark them known. */
static int compute_norms(const silc_value *v, silc_props *p, int shape, int cols)
{
    props_acc acc;
    int exp2 = 0, rc = 0;
    memset(&acc, 0, sizeof acc);
    acc.p = p;
    /* One sum per column and per row: 12 MB at a million unknowns, which on
     * 4 KiB pages cost ~33 ms of first-touch faults on this VM.  Work arrays
     * freed before the call returns, like a library's work space
     * (util_large_malloc); values' own arrays stay malloc's (docs/overhead.md,
     * "Values' arrays on huge pages"). */
    acc.colsum = cols ? util_large_malloc((size_t)(v->n ? v->n : 1) * sizeof(double)) : NULL;
    acc.rowsum = util_large_malloc((size_t)(v->m ? v->m : 1) * sizeof(double));
    props_start(v, &acc, shape, 1.0);
    int fast = 0; /* a fast pass gathered everything asked for */
    if (v->field == SILC_FIELD_COMPLEX) {
        /* entry by entry below */
    } else if (!shape && v->format == SILC_FMT_CSR && !p->has_nonfinite) {
        norms_pass_csr(v, &acc);
        fast = isfinite(acc.total) && isfinite(acc.sumsq);
    } else if (v->format == SILC_FMT_DENSE && acc.colsum && acc.rowsum) {
        /* without shape, its shape answers are the ones already known */
        fast = norms_shape_pass_dense(v, &acc) == 0;
    }
    if (!fast) {
        /* Other formats, and the rare CSR value with a NaN, an Inf or a sum
         * beyond DBL_MAX: entry by entry. */
        props_start(v, &acc, shape, 1.0);
        props_pass(v, &acc);
    }
    if (shape) p->pos_diag = p->square && v->n > 0 && acc.pos_diag_count == v->n;
    p->maxabs = acc.maxabs;
    if (isfinite(p->maxabs) && p->maxabs > 0) {
        frexp(p->maxabs, &exp2);
        if (exp2 > -NORM_SAFE_EXP && exp2 < NORM_SAFE_EXP) {
            exp2 = 0;
        } else {
            /* Clamped so that the scale itself and its inverse are finite normals. */
            if (exp2 > 1021) exp2 = 1021;
            if (exp2 < -1021) exp2 = -1021;
            props_start(v, &acc, 0, ldexp(1.0, -exp2));
            props_pass(v, &acc);
        }
    }
    if ((acc.colsum || !cols) && acc.rowsum) {
        p->norm1 = cols ? ldexp(max_of(acc.colsum, v->n), exp2) : NAN;
        p->norminf = ldexp(max_of(acc.rowsum, v->m), exp2);
    } else {
        p->norm1 = p->norminf = ldexp(acc.total, exp2);
        rc = -1;
    }
    p->normfro = ldexp(sqrt(acc.sumsq), exp2);
    util_large_free(acc.colsum);
    util_large_free(acc.rowsum);
    return rc;
}

const silc_props *val_props_part(const silc_value *cv, int parts)
{
    /* The cache is not part of the value's contents (see val_attach_set). */
    silc_value *v = (silc_value *)cv;
    silc_props *p;
    if (!v) return NULL;
    p = &v->props;
    if (v->dist) {
        if ((parts & ~v->props_have) && dist_hooks.props) dist_hooks.props(v, parts & ~v->props_have);
        /* the hook finds both for a complex value; a real one is Hermitian when symmetric */
        if (v->field != SILC_FIELD_COMPLEX) p->hermitian = p->symmetric;
        return p;
    }
    if ((parts & SILC_PROPS_SHAPE) && !(v->props_have & SILC_PROPS_SHAPE) && v->format == SILC_FMT_CSR &&
        v->field == SILC_FIELD_REAL)
        shape_csr(v);
    if ((parts & SILC_PROPS_SHAPE) && !(parts & SILC_PROPS_NORMS))
        val_shape_into(v, NULL); /* a real dense value's shape alone; nothing for others or when known */
    if ((parts & (SILC_PROPS_SHAPE | SILC_PROPS_NORMS)) & ~v->props_have) {
        int shape = !(v->props_have & SILC_PROPS_SHAPE);
        if (compute_norms(v, p, shape, 1) == 0) v->props_have |= SILC_PROPS_NORMS;
        v->props_have |= shape ? SILC_PROPS_SHAPE : 0;
    }
    if ((parts & SILC_PROPS_SYMMETRY) && !(v->props_have & SILC_PROPS_SYMMETRY)) {
        if (v->field == SILC_FIELD_COMPLEX) {
            complex_pass c = {v, NULL, v->m == v->n, v->m == v->n};
            if (v->m == v->n) each_entry(v, complex_symmetry_entry, &c);
            p->symmetric = c.symmetric;
            p->hermitian = c.hermitian;
            v->props_have |= SILC_PROPS_SYMMETRY;
        } else {
            int sym = value_symmetric(v);
            p->symmetric = p->hermitian = sym > 0;
            if (sym >= 0) v->props_have |= SILC_PROPS_SYMMETRY;
        }
    }
    return p;
}

int val_row_norms(const silc_value *v, silc_props *p)
{
    memset(p, 0, sizeof *p); /* a NaN or Inf: the fast pass's sums see it and fall back */
    return compute_norms(v, p, 0, 0);
}

int val_shape_into(silc_value *v, double *copy)
{
    if (v->dist || v->format != SILC_FMT_DENSE || v->field != SILC_FIELD_REAL || (v->props_have & SILC_PROPS_SHAPE))
        return -1;
    shape_pass_dense(v, &v->props, copy);
    v->props_have |= SILC_PROPS_SHAPE;
    return 0;
}

const silc_props *val_props(const silc_value *v)
{
    return val_props_part(v, SILC_PROPS_ALL);
}

/* What val_scan has cached (store.h's scan_ready). */
enum { SCAN_FINITE = 1, SCAN_MAXABS = 2 };

/* Non-zero when an entry of x is NaN or Inf: x - x is +0 for every finite x
 * and NaN otherwise, and four independent sums of it keep the loop free of
 * branches and of one long dependency chain.  2.6 us on 17758 entries where
 * a compare-and-branch loop took 8.2 (-O2): this runs on every solve's
 * result, next to a back-substitution of ~120 us. */
static int any_nonfinite(const double *x, int64_t n)
{
    double s0 = 0, s1 = 0, s2 = 0, s3 = 0;
    int64_t i = 0;
    for (; i + 4 <= n; i += 4) {
        s0 += x[i] - x[i];
        s1 += x[i + 1] - x[i + 1];
        s2 += x[i + 2] - x[i + 2];
        s3 += x[i + 3] - x[i + 3];
    }
    for (; i < n; i++) s0 += x[i] - x[i];
    return s0 + s1 + s2 + s3 != 0;
}

/* Fills the scan cache up to level (SCAN_FINITE or SCAN_MAXABS).  A band
 * array's corners outside the matrix are not entries (LAPACK leaves them
 * unreferenced), so band values ask the properties, whose pass skips them. */
static void val_scan(const silc_value *cv, int level)
{
    silc_value *v = (silc_value *)cv; /* the cache is not part of the contents */
    if (v->scan_ready >= level) return;
    if (v->dist) {
        if (dist_hooks.scan) dist_hooks.scan(v);
        return;
    }
    if ((v->props_have & SILC_PROPS_NORMS) || v->format == SILC_FMT_BAND) {
        const silc_props *p = val_props(v);
        v->scan_maxabs = p->maxabs;
        v->scan_nonfinite = p->has_nonfinite;
        v->scan_ready = SCAN_MAXABS;
    } else if (level == SCAN_FINITE) {
        /* both parts of a complex entry: a NaN imaginary part counts */
        v->scan_nonfinite = any_nonfinite(v->val, v->nnz * val_width(v));
        v->scan_ready = SCAN_FINITE;
    } else if (v->field == SILC_FIELD_COMPLEX) {
        double maxabs = 0;
        int nonfinite = 0;
        for (int64_t k = 0; k < v->nnz; k++) {
            double re = v->val[2 * k], im = v->val[2 * k + 1], x = hypot(re, im);
            nonfinite |= !isfinite(re) || !isfinite(im);
            if (x != x) maxabs = x;
            else if (x > maxabs && maxabs == maxabs) maxabs = x;
        }
        v->scan_maxabs = maxabs;
        v->scan_nonfinite = nonfinite;
        v->scan_ready = SCAN_MAXABS;
    } else {
        scan_from_bits(v, max_abs_bits(v->val, v->nnz, 0, NULL));
    }
}

/* Fills the scan cache from the largest magnitude's bit pattern. */
static void scan_from_bits(silc_value *v, uint64_t maxbits)
{
    const uint64_t inf = 0x7ff0000000000000ULL;
    memcpy(&v->scan_maxabs, &maxbits, sizeof maxbits);
    if (maxbits > inf) v->scan_maxabs = NAN; /* one NaN's payload, not a max */
    v->scan_nonfinite = maxbits >= inf;
    v->scan_ready = SCAN_MAXABS;
}

int val_has_nonfinite(const silc_value *v)
{
    val_scan(v, SCAN_FINITE);
    return v->scan_nonfinite;
}

double val_max_abs(const silc_value *v)
{
    val_scan(v, SCAN_MAXABS);
    return v->scan_maxabs;
}

void val_mutated(silc_value *v)
{
    val_forget_caches(v);
    v->id = atomic_fetch_add(&next_id, 1);
}

void val_forget_caches(silc_value *v)
{
    v->props_have = 0;
    v->scan_ready = 0;
}

/* ---- the store ------------------------------------------------------------ */

static size_t hash_name(const char *s)
{
    /* FNV-1a: short keys, good spread, no table. */
    uint64_t h = 1469598103934665603ull;
    while (*s) {
        h ^= (unsigned char)*s++;
        h *= 1099511628211ull;
    }
    return (size_t)h;
}

int store_init(silc_store *s)
{
    s->nbuckets = 16;
    s->count = 0;
    s->buckets = calloc(s->nbuckets, sizeof *s->buckets);
    return s->buckets ? 0 : -1;
}

void store_clear(silc_store *s)
{
    size_t b;
    if (!s->buckets) return;
    for (b = 0; b < s->nbuckets; b++) {
        store_entry *e = s->buckets[b], *next;
        for (; e; e = next) {
            next = e->next;
            e->value->bindings--;
            val_release(e->value);
            free(e);
        }
        s->buckets[b] = NULL;
    }
    s->count = 0;
}

void store_free(silc_store *s)
{
    if (!s) return;
    store_clear(s);
    free(s->buckets);
    s->buckets = NULL;
    s->nbuckets = 0;
}

/* Where name's entry is, or would go, in the chain of its hash.  An entry
 * of another name in the chain is passed on its hash alone, without
 * reading its name. */
static store_entry **store_slot(const silc_store *s, const char *name, size_t hash)
{
    store_entry **pe = &s->buckets[hash % s->nbuckets];
    while (*pe && ((*pe)->hash != hash || strcmp((*pe)->name, name) != 0)) pe = &(*pe)->next;
    return pe;
}

silc_value *store_get(const silc_store *s, const char *name)
{
    store_entry **pe;
    if (!s || !s->buckets || !name) return NULL;
    pe = store_slot(s, name, hash_name(name));
    return *pe ? (*pe)->value : NULL;
}

/* Doubles the bucket array; on allocation failure the store keeps working
 * with longer chains. */
static void store_grow(silc_store *s)
{
    size_t nb = s->nbuckets * 2, b;
    store_entry **nbk = calloc(nb, sizeof *nbk);
    if (!nbk) return;
    for (b = 0; b < s->nbuckets; b++) {
        store_entry *e = s->buckets[b], *next;
        for (; e; e = next) {
            size_t h = e->hash % nb;
            next = e->next;
            e->next = nbk[h];
            nbk[h] = e;
        }
    }
    free(s->buckets);
    s->buckets = nbk;
    s->nbuckets = nb;
}

int store_set(silc_store *s, const char *name, silc_value *v)
{
    store_entry **pe, *e;
    size_t hash, len;
    if (!s || !s->buckets || !name || !v) return -1;
    hash = hash_name(name);
    pe = store_slot(s, name, hash);
    if (*pe) {
        silc_value *old = (*pe)->value;
        (*pe)->value = val_retain(v);
        v->bindings++;
        old->bindings--;
        val_release(old);
        return 0;
    }
    len = strlen(name);
    e = malloc(sizeof *e + len + 1);
    if (!e) return -1;
    memcpy(e->name, name, len + 1);
    e->hash = hash;
    e->value = val_retain(v);
    v->bindings++;
    e->next = NULL;
    *pe = e;
    if (++s->count > s->nbuckets) store_grow(s);
    return 0;
}

int store_remove(silc_store *s, const char *name)
{
    store_entry **pe, *e;
    if (!s || !s->buckets || !name) return 1;
    pe = store_slot(s, name, hash_name(name));
    if (!*pe) return 1;
    e = *pe;
    *pe = e->next;
    e->value->bindings--;
    val_release(e->value);
    free(e);
    s->count--;
    return 0;
}

static int cmp_names(const void *a, const void *b)
{
    return strcmp(*(const char *const *)a, *(const char *const *)b);
}

size_t store_names(const silc_store *s, const char ***names)
{
    size_t b, k = 0;
    const char **out;
    *names = NULL;
    if (!s || !s->buckets || s->count == 0) return 0;
    out = malloc(s->count * sizeof *out);
    if (!out) return 0;
    for (b = 0; b < s->nbuckets; b++) {
        const store_entry *e;
        for (e = s->buckets[b]; e; e = e->next) out[k++] = e->name;
    }
    qsort(out, k, sizeof *out, cmp_names);
    *names = out;
    return k;
}
