/*
 * envelope.c -- envelopes: the caller-owned matrices that cross the public API.
 *
 * Constructors copy the caller's arrays and normalise them (CSR columns sorted
 * within rows), so that everything past this file can rely on the value
 * invariants of store.h.  Envelopes filled by hand are checked again when they
 * are turned into values (env_to_value).  Failures here have no context to
 * report to; their messages go to a per-thread buffer that silc_errmsg() shows.
 */
#include "store.h"

#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

static int check_fail(char *err, size_t errlen, const char *fmt, ...)
#if defined(__GNUC__)
    __attribute__((format(printf, 3, 4)))
#endif
    ;

static _Thread_local char env_err[1024];
static _Thread_local int env_err_live;

int env_error(const char *fmt, ...)
{
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(env_err, sizeof env_err, fmt, ap);
    va_end(ap);
    env_err_live = 1;
    return -1;
}

const char *env_error_last(void)
{
    return env_err_live ? env_err : NULL;
}

void env_error_forget(void)
{
    env_err_live = 0;
}

/* ---- envelopes that failed to be built ------------------------------------
 * A constructor that fails leaves its envelope marked (format
 * ENV_NOT_CONSTRUCTED, nnz a serial number) rather than as a 0x0 dense
 * value, so that a PUT of it is refused with the constructor's message
 * instead of binding an empty matrix.  The messages of the last few
 * failures of this thread are kept by serial number. */
#define ENV_NOT_CONSTRUCTED 0x4e6f7442 /* no silc_format_t */
#define ENV_FAILED_KEPT 16
static _Thread_local char env_failed_msg[ENV_FAILED_KEPT][512];
static _Thread_local int64_t env_failed_serial;

/* Marks e as not constructed with the thread's last message; returns -1. */
int env_mark_not_constructed(silc_envelope_t *e)
{
    if (!e) return -1;
    memset(e, 0, sizeof *e);
    e->format = (silc_format_t)ENV_NOT_CONSTRUCTED;
    e->nnz = ++env_failed_serial;
    snprintf(env_failed_msg[e->nnz % ENV_FAILED_KEPT], sizeof env_failed_msg[0], "%.500s",
             env_err_live ? env_err : "its constructor failed");
    return -1;
}

/* env_error, then e marked as not constructed. */
static int env_failed(silc_envelope_t *e, const char *fmt, ...)
#if defined(__GNUC__)
    __attribute__((format(printf, 2, 3)))
#endif
    ;

static int env_failed(silc_envelope_t *e, const char *fmt, ...)
{
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(env_err, sizeof env_err, fmt, ap);
    va_end(ap);
    env_err_live = 1;
    return env_mark_not_constructed(e);
}

int env_not_constructed(const silc_envelope_t *e, char *err, size_t errlen)
{
    if (!e || (int)e->format != ENV_NOT_CONSTRUCTED) return 0;
    if (e->nnz > 0 && e->nnz <= env_failed_serial && env_failed_serial - e->nnz < ENV_FAILED_KEPT)
        snprintf(err, errlen, "%s", env_failed_msg[e->nnz % ENV_FAILED_KEPT]);
    else
        snprintf(err, errlen, "its constructor failed (the message is no longer kept)");
    return 1;
}

/* Element count of an m x n array of doubles, or -1 if it cannot be allocated. */
static int64_t dense_count(int64_t m, int64_t n)
{
    if (m < 0 || n < 0) return -1;
    if (m != 0 && n > (int64_t)(SIZE_MAX / sizeof(double) / 2) / m) return -1;
    return m * n;
}

/* Copy of count elements of size bytes, or zeros if src is NULL.  Never asks
 * for zero bytes, so NULL means out of memory. */
static void *copy_array(const void *src, int64_t count, size_t size)
{
    void *p = val_array_alloc(count, size, src == NULL);
    if (p && src && count > 0) memcpy(p, src, (size_t)count * size);
    return p;
}

int env_format_base(int envelope_format)
{
    return envelope_format & ~SILC_COMPLEX;
}

int env_format_field(int envelope_format)
{
    return envelope_format & SILC_COMPLEX ? SILC_FIELD_COMPLEX : SILC_FIELD_REAL;
}

int env_format_code(int format, int field)
{
    return format | (field == SILC_FIELD_COMPLEX ? SILC_COMPLEX : 0);
}

int env_complex_refusal(const char *name, const char *getter, char *err, size_t errlen)
{
    return check_fail(err, errlen, "'%s' is complex: this client did not ask for complex values "
                      "(fetch it with %s, or take real(%s) or abs(%s))", name, getter, name, name);
}

int env_refuse_complex(const char *name, const silc_value *v, const char *getter, char *err, size_t errlen)
{
    if (!v || v->field != SILC_FIELD_COMPLEX) return 0;
    return env_complex_refusal(name, getter, err, errlen);
}

/* Doubles per entry of an envelope's values. */
static int env_width(const silc_envelope_t *e)
{
    return env_format_field((int)e->format) == SILC_FIELD_COMPLEX ? 2 : 1;
}

/* The dense constructors of both fields (fn names the caller). */
static int envelope_dense(silc_envelope_t *e, const char *fn, int field, int64_t m, int64_t n,
                          const double *colmajor)
{
    int64_t count, width = field == SILC_FIELD_COMPLEX ? 2 : 1;
    if (!e) return env_error("%s: NULL envelope", fn);
    memset(e, 0, sizeof *e);
    count = dense_count(m, n);
    if (count < 0)
        return env_failed(e, "%s: invalid size %lldx%lld", fn, (long long)m, (long long)n);
    if (val_claim((double)count * (double)width * sizeof(double), "the envelope"))
        return env_failed(e, "%s: %lldx%lld: %s", fn, (long long)m, (long long)n, val_refusal());
    e->values = copy_array(colmajor, count * width, sizeof(double));
    if (!e->values) return env_failed(e, "%s: out of memory for %lldx%lld", fn, (long long)m, (long long)n);
    e->m = m;
    e->n = n;
    e->format = (silc_format_t)env_format_code(SILC_DENSE, field);
    e->nnz = count;
    return 0;
}

int silc_envelope_dense(silc_envelope_t *e, int64_t m, int64_t n, const double *colmajor)
{
    return envelope_dense(e, "silc_envelope_dense", SILC_FIELD_REAL, m, n, colmajor);
}

int silc_envelope_dense_complex(silc_envelope_t *e, int64_t m, int64_t n, const double *colmajor)
{
    return envelope_dense(e, "silc_envelope_dense_complex", SILC_FIELD_COMPLEX, m, n, colmajor);
}

int silc_envelope_is_complex(const silc_envelope_t *e)
{
    return e && (int)e->format != ENV_NOT_CONSTRUCTED && env_format_field((int)e->format) == SILC_FIELD_COMPLEX;
}

int silc_envelope_scalar(silc_envelope_t *e, double x)
{
    return silc_envelope_dense(e, 1, 1, &x);
}

int silc_envelope_vector(silc_envelope_t *e, int64_t n, const double *x)
{
    return silc_envelope_dense(e, n, 1, x);
}

/* ---- the checked constructor ----------------------------------------------
 * Every value handed to SILC from outside is described as val_parts and
 * passes here: envelopes of silc_put / SILC_PUT (embedded, and checked by the
 * remote client before it sends), PUT descriptors and arrays in silcd, HDF5
 * `load`, Matrix Market files, and the results plugins return.  The claim
 * (format, shape, entry count) is checked first, with overflow-safe
 * arithmetic and against the value limit, so that nothing is allocated or
 * read for a value that cannot be; then the arrays: rowptr starts at 0,
 * never decreases and ends at nnz (so every later read stays inside the
 * nnz entries the caller has), and each row's columns lie in [0, n).
 * Messages print sizes and indices, never an address. */

static int check_fail(char *err, size_t errlen, const char *fmt, ...)
#if defined(__GNUC__)
    __attribute__((format(printf, 3, 4)))
#endif
    ;

static int check_fail(char *err, size_t errlen, const char *fmt, ...)
{
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(err, errlen, fmt, ap);
    va_end(ap);
    return -1;
}

/* Element count of band storage, (kl+ku+1)*n, or -1. */
static int64_t band_count(int64_t n, int64_t kl, int64_t ku)
{
    if (kl < 0 || ku < 0 || kl > INT32_MAX || ku > INT32_MAX) return -1;
    return dense_count(kl + ku + 1, n);
}

double val_parts_bytes(const val_parts *p)
{
    return val_shape_bytes_field(p->format, p->field, p->m, p->n, p->nnz, p->kl, p->ku);
}

int val_parts_claim(const val_parts *p, char *err, size_t errlen)
{
    char what[160];
    if (p->format != SILC_FMT_DENSE && p->format != SILC_FMT_CSR && p->format != SILC_FMT_BAND)
        return check_fail(err, errlen, "unknown format %d", p->format);
    if (p->field != SILC_FIELD_REAL && p->field != SILC_FIELD_COMPLEX)
        return check_fail(err, errlen, "unknown field %d", p->field);
    if (p->m < 0 || p->n < 0)
        return check_fail(err, errlen, "invalid size %lldx%lld", (long long)p->m, (long long)p->n);
    switch (p->format) {
    case SILC_FMT_DENSE:
        if (dense_count(p->m, p->n) < 0)
            return check_fail(err, errlen, "invalid size %lldx%lld: m*n overflows", (long long)p->m,
                              (long long)p->n);
        break;
    case SILC_FMT_CSR:
        if (p->m >= INT64_MAX / 16 || dense_count(p->m + 1, 1) < 0)
            return check_fail(err, errlen, "invalid size %lldx%lld: too many rows", (long long)p->m,
                              (long long)p->n);
        if (p->nnz < 0 || dense_count(p->nnz, 2) < 0)
            return check_fail(err, errlen, "a %lldx%lld csr value cannot have %lld entries",
                              (long long)p->m, (long long)p->n, (long long)p->nnz);
        break;
    default:
        if (band_count(p->n, p->kl, p->ku) < 0)
            return check_fail(err, errlen, "invalid band size %lldx%lld with kl = %lld, ku = %lld",
                              (long long)p->m, (long long)p->n, (long long)p->kl, (long long)p->ku);
        break;
    }
    /* Described only when refused: every plugin result passes here
     * (host_check_result), and formatting the text cost ~1 % of a small
     * SpMV. */
    if (val_parts_bytes(p) <= (double)val_max_bytes()) return val_claim(0, "");
    snprintf(what, sizeof what, "a %lldx%lld %s%s value", (long long)p->m, (long long)p->n,
             p->field == SILC_FIELD_COMPLEX ? "complex " : "", val_format_name(p->format));
    if (p->format == SILC_FMT_CSR)
        snprintf(what + strlen(what), sizeof what - strlen(what), " of %lld entries", (long long)p->nnz);
    if (val_claim(val_parts_bytes(p), what)) return check_fail(err, errlen, "%s", val_refusal());
    return 0;
}

/* The rows of a CSR claim whose rowptr is known good: columns in [0, n)
 * and, when sorted is set, strictly increasing (the constructors sort
 * instead). */
static int csr_check_columns(const val_parts *p, int sorted, char *err, size_t errlen)
{
    int64_t i, k;
    for (i = 0; i < p->m; i++)
        for (k = p->rowptr[i]; k < p->rowptr[i + 1]; k++) {
            if (p->colind[k] < 0 || p->colind[k] >= p->n)
                return check_fail(err, errlen, "column index %lld out of range [0, %lld) in row %lld",
                                  (long long)p->colind[k], (long long)p->n, (long long)i);
            if (sorted && k > p->rowptr[i] && p->colind[k - 1] >= p->colind[k])
                return check_fail(err, errlen, "columns of row %lld are %s (build CSR envelopes "
                                  "with silc_envelope_csr, which sorts them)", (long long)i,
                                  p->colind[k - 1] == p->colind[k] ? "duplicated" : "not sorted");
        }
    return 0;
}

/* The claim, then rowptr: 0 first, never decreasing, nnz last, and the
 * arrays its entries need present. */
static int csr_check_rowptr(const val_parts *p, char *err, size_t errlen)
{
    int64_t i;
    if (val_parts_claim(p, err, errlen)) return -1;
    if (!p->rowptr) return check_fail(err, errlen, "rowptr is NULL");
    if (p->rowptr[0] != 0)
        return check_fail(err, errlen, "rowptr[0] is %lld, must be 0", (long long)p->rowptr[0]);
    for (i = 0; i < p->m; i++)
        if (p->rowptr[i + 1] < p->rowptr[i])
            return check_fail(err, errlen, "rowptr decreases at row %lld (rowptr[%lld] = %lld > rowptr[%lld] = %lld)",
                              (long long)i, (long long)i, (long long)p->rowptr[i], (long long)(i + 1),
                              (long long)p->rowptr[i + 1]);
    if (p->rowptr[p->m] != p->nnz)
        return check_fail(err, errlen, "rowptr[m] = %lld but the value has %lld entries (nnz): "
                          "m or rowptr is wrong", (long long)p->rowptr[p->m], (long long)p->nnz);
    if (p->nnz > 0 && (!p->colind || !p->values))
        return check_fail(err, errlen, "%s is NULL but rowptr[m] = %lld", p->colind ? "values" : "colind",
                          (long long)p->nnz);
    return 0;
}

int val_parts_check(const val_parts *p, char *err, size_t errlen)
{
    if (p->format == SILC_FMT_CSR)
        return csr_check_rowptr(p, err, errlen) ? -1 : csr_check_columns(p, 1, err, errlen);
    if (val_parts_claim(p, err, errlen)) return -1;
    if (!p->values && (p->format == SILC_FMT_DENSE ? p->m * p->n : band_count(p->n, p->kl, p->ku)) > 0)
        return check_fail(err, errlen, "%s value has no values (freed or never built?)",
                          p->format == SILC_FMT_DENSE ? "dense" : "band");
    return 0;
}

int val_parts_fill(silc_value *v, const val_parts *p, char *err, size_t errlen)
{
    if (csr_check_rowptr(p, err, errlen)) return -1;
    if (val_csr_fill_checked(v, p->rowptr, p->colind, p->values) == 0) return 0;
    /* The fast pass only knows that a row failed; the plain check finds it
     * again and says how. */
    if (csr_check_columns(p, 1, err, errlen) == 0)
        check_fail(err, errlen, "CSR arrays refused with no reason found (internal error)");
    return -1;
}

int val_from_parts(const val_parts *p, silc_value **out, char *err, size_t errlen)
{
    silc_value *v;
    *out = NULL;
    if (p->format == SILC_FMT_CSR) {
        /* rowptr first, for the size; the entries are checked while copied,
         * not in a pass of their own (val_parts_fill). */
        if (csr_check_rowptr(p, err, errlen)) return -1;
        v = val_new_unset_field(SILC_FMT_CSR, p->field, p->m, p->n, p->nnz, 0, 0);
        if (v && val_parts_fill(v, p, err, errlen)) {
            val_release(v);
            return -1;
        }
    } else {
        int64_t count;
        if (val_parts_check(p, err, errlen)) return -1;
        count = p->format == SILC_FMT_DENSE ? p->m * p->n : band_count(p->n, p->kl, p->ku);
        v = val_new_unset_field(p->format, p->field, p->m, p->n, 0, p->kl, p->ku);
        if (v && count > 0) memcpy(v->val, p->values, (size_t)count * (size_t)val_width(v) * sizeof(double));
    }
    if (!v)
        return check_fail(err, errlen, "%s", val_refusal()[0] ? val_refusal() : "out of memory");
    *out = v;
    return 0;
}

int val_check_value(const silc_value *v, char *err, size_t errlen)
{
    val_parts p;
    if (!v) return check_fail(err, errlen, "no value");
    if (v->dist) return val_check_value(v->dist->block, err, errlen);
    memset(&p, 0, sizeof p);
    p.format = v->format, p.field = v->field, p.m = v->m, p.n = v->n, p.kl = v->kl, p.ku = v->ku;
    p.rowptr = v->rowptr, p.colind = v->colind, p.values = v->val;
    p.nnz = v->format == SILC_FMT_CSR ? v->nnz : 0;
    if (v->format == SILC_FMT_CSR && v->nnz > v->cap)
        return check_fail(err, errlen, "%lld entries in use but room for %lld", (long long)v->nnz,
                          (long long)v->cap);
    if (v->format == SILC_FMT_BAND && v->ld != v->kl + v->ku + 1)
        return check_fail(err, errlen, "band storage of %lld rows for kl = %lld, ku = %lld", (long long)v->ld,
                          (long long)v->kl, (long long)v->ku);
    return val_parts_check(&p, err, errlen);
}


typedef struct col_val {
    int64_t col;
    double val[2]; /* a complex entry's two parts; [0] only for a real one */
} col_val;

static int cmp_col(const void *a, const void *b)
{
    int64_t x = ((const col_val *)a)->col, y = ((const col_val *)b)->col;
    return (x > y) - (x < y);
}

/* Sorts the columns of every unsorted row in place (values follow) and
 * rejects duplicates.  Most rows arrive sorted; they cost one scan. */
static int csr_sort_rows(int64_t m, const int64_t *rowptr, int64_t *colind, double *values, int width,
                         char *err, size_t errlen)
{
    int64_t i, k;
    col_val *tmp = NULL;
    size_t tmpcap = 0;
    for (i = 0; i < m; i++) {
        int64_t lo = rowptr[i], hi = rowptr[i + 1], len = hi - lo;
        int sorted = 1;
        for (k = lo + 1; k < hi && sorted; k++) sorted = colind[k - 1] <= colind[k];
        if (!sorted) {
            if ((size_t)len > tmpcap) {
                col_val *t = realloc(tmp, (size_t)len * sizeof *t);
                if (!t) {
                    free(tmp);
                    snprintf(err, errlen, "out of memory sorting row %lld", (long long)i);
                    return -1;
                }
                tmp = t;
                tmpcap = (size_t)len;
            }
            for (k = 0; k < len; k++) {
                tmp[k].col = colind[lo + k];
                memcpy(tmp[k].val, values + (lo + k) * width, (size_t)width * sizeof *values);
            }
            qsort(tmp, (size_t)len, sizeof *tmp, cmp_col);
            for (k = 0; k < len; k++) {
                colind[lo + k] = tmp[k].col;
                memcpy(values + (lo + k) * width, tmp[k].val, (size_t)width * sizeof *values);
            }
        }
        for (k = lo + 1; k < hi; k++)
            if (colind[k - 1] == colind[k]) {
                free(tmp);
                snprintf(err, errlen,
                         "duplicate entry at row %lld, column %lld (0-based); "
                         "use sparse(i, j, v, m, n) to sum duplicates",
                         (long long)i, (long long)colind[k]);
                return -1;
            }
    }
    free(tmp);
    return 0;
}

/* The CSR constructor behind both index widths: takes ownership of rowptr
 * and colind (already int64 copies), copies values. */
static int envelope_csr_own(silc_envelope_t *e, const char *fn, int field, int64_t m, int64_t n,
                            int64_t *rowptr, int64_t *colind, const double *values)
{
    int width = field == SILC_FIELD_COMPLEX ? 2 : 1;
    char msg[512];
    int64_t nnz;
    double *vals;
    val_parts p;
    memset(&p, 0, sizeof p);
    p.format = SILC_FMT_CSR, p.field = field, p.m = m, p.n = n, p.nnz = rowptr[m];
    p.rowptr = rowptr, p.colind = colind, p.values = values;
    if (csr_check_rowptr(&p, msg, sizeof msg) || csr_check_columns(&p, 0, msg, sizeof msg)) {
        val_array_free(rowptr), val_array_free(colind);
        return env_failed(e, "%s: %s", fn, msg);
    }
    nnz = rowptr[m];
    vals = copy_array(values, nnz * width, sizeof(double));
    if (!vals) {
        val_array_free(rowptr), val_array_free(colind);
        return env_failed(e, "%s: out of memory for %lld entries", fn, (long long)nnz);
    }
    if (csr_sort_rows(m, rowptr, colind, vals, width, msg, sizeof msg)) {
        val_array_free(rowptr), val_array_free(colind), val_array_free(vals);
        return env_failed(e, "%s: %s", fn, msg);
    }
    e->m = m;
    e->n = n;
    e->format = (silc_format_t)env_format_code(SILC_CSR, field);
    e->rowptr = rowptr;
    e->colind = colind;
    e->values = vals;
    e->nnz = nnz;
    return 0;
}

/* The checks both CSR constructors make before copying: the envelope, the
 * size, and rowptr[m] (read only once rowptr is known to exist) as an entry
 * count with colind present when it is non-zero.  fn names the caller. */
static int csr_args(const char *fn, silc_envelope_t *e, int64_t m, int64_t n, const void *rowptr,
                    int64_t (*last)(const void *rowptr, int64_t m),
                    const void *colind, int64_t *nnz)
{
    if (!e) return env_error("%s: NULL envelope", fn);
    memset(e, 0, sizeof *e);
    if (m < 0 || n < 0 || dense_count(m + 1, 1) < 0)
        return env_failed(e, "%s: invalid size %lldx%lld", fn, (long long)m, (long long)n);
    if (!rowptr) return env_failed(e, "%s: rowptr is NULL", fn);
    /* rowptr[m] is only trusted after the structure check; copying up to it
     * first is safe because a negative or huge count is rejected here. */
    *nnz = last(rowptr, m);
    if (*nnz < 0 || dense_count(*nnz, 2) < 0)
        return env_failed(e, "%s: rowptr[m] = %lld is not a valid entry count", fn, (long long)*nnz);
    if (*nnz > 0 && !colind)
        return env_failed(e, "%s: colind is NULL but rowptr[m] = %lld", fn, (long long)*nnz);
    return 0;
}

static int64_t last64(const void *rowptr, int64_t m)
{
    return ((const int64_t *)rowptr)[m];
}

static int64_t last32(const void *rowptr, int64_t m)
{
    return ((const int32_t *)rowptr)[m];
}

/* The 64-bit CSR constructors of both fields. */
static int envelope_csr64(silc_envelope_t *e, const char *fn, int field, int64_t m, int64_t n,
                          const int64_t *rowptr, const int64_t *colind, const double *values)
{
    int64_t *rp, *ci, nnz;
    if (csr_args(fn, e, m, n, rowptr, last64, colind, &nnz)) return -1;
    rp = copy_array(rowptr, m + 1, sizeof *rp);
    ci = copy_array(colind, nnz, sizeof *ci);
    if (!rp || !ci) {
        val_array_free(rp), val_array_free(ci);
        return env_failed(e, "%s: out of memory for %lld entries", fn, (long long)nnz);
    }
    return envelope_csr_own(e, fn, field, m, n, rp, ci, values);
}

int silc_envelope_csr(silc_envelope_t *e, int64_t m, int64_t n, const int64_t *rowptr,
                      const int64_t *colind, const double *values)
{
    return envelope_csr64(e, "silc_envelope_csr", SILC_FIELD_REAL, m, n, rowptr, colind, values);
}

int silc_envelope_csr_complex(silc_envelope_t *e, int64_t m, int64_t n, const int64_t *rowptr,
                              const int64_t *colind, const double *values)
{
    return envelope_csr64(e, "silc_envelope_csr_complex", SILC_FIELD_COMPLEX, m, n, rowptr, colind, values);
}

int silc_envelope_csr32(silc_envelope_t *e, int64_t m, int64_t n, const int32_t *rowptr,
                        const int32_t *colind, const double *values)
{
    int64_t *rp, *ci, nnz, k;
    if (csr_args("silc_envelope_csr32", e, m, n, rowptr, last32, colind, &nnz))
        return -1;
    rp = copy_array(NULL, m + 1, sizeof *rp);
    ci = copy_array(NULL, nnz, sizeof *ci);
    if (!rp || !ci) {
        val_array_free(rp), val_array_free(ci);
        return env_failed(e, "silc_envelope_csr32: out of memory for %lld entries", (long long)nnz);
    }
    for (k = 0; k <= m; k++) rp[k] = rowptr[k];
    for (k = 0; k < nnz; k++) ci[k] = colind[k];
    return envelope_csr_own(e, "silc_envelope_csr32", SILC_FIELD_REAL, m, n, rp, ci, values);
}

int silc_envelope_band(silc_envelope_t *e, int64_t m, int64_t n, int64_t kl, int64_t ku,
                       const double *band)
{
    int64_t count;
    if (!e) return env_error("silc_envelope_band: NULL envelope");
    memset(e, 0, sizeof *e);
    count = band_count(n, kl, ku);
    if (m < 0 || count < 0)
        return env_failed(e, "silc_envelope_band: invalid size %lldx%lld with kl = %lld, ku = %lld",
                         (long long)m, (long long)n, (long long)kl, (long long)ku);
    if (val_claim((double)count * sizeof(double), "the envelope"))
        return env_failed(e, "silc_envelope_band: %lldx%lld with kl = %lld, ku = %lld: %s",
                         (long long)m, (long long)n, (long long)kl, (long long)ku, val_refusal());
    e->values = copy_array(band, count, sizeof(double));
    if (!e->values) return env_failed(e, "silc_envelope_band: out of memory");
    e->m = m;
    e->n = n;
    e->format = SILC_BAND;
    e->nnz = count;
    e->kl = kl;
    e->ku = ku;
    return 0;
}

int64_t silc_envelope_rows(const silc_envelope_t *e)
{
    return e ? e->m : 0;
}

int64_t silc_envelope_cols(const silc_envelope_t *e)
{
    return e ? e->n : 0;
}

int silc_envelope_to_dense(const silc_envelope_t *e, double *out)
{
    int64_t i, j, k, count, w;
    char why[512];
    if (!e || !out) return env_error("silc_envelope_to_dense: NULL %s", e ? "output array" : "envelope");
    if (env_not_constructed(e, why, sizeof why))
        return env_error("silc_envelope_to_dense: the envelope was not constructed: %s", why);
    count = dense_count(e->m, e->n);
    if (count < 0) return env_error("silc_envelope_to_dense: invalid envelope size");
    if (count > 0 && !e->values)
        return env_error("silc_envelope_to_dense: envelope has no values (freed or never built?)");
    w = env_width(e); /* a complex envelope's entries are two doubles here and in out */
    switch (env_format_base((int)e->format)) {
    case SILC_DENSE:
        memcpy(out, e->values, (size_t)(count * w) * sizeof(double));
        return 0;
    case SILC_CSR:
        if (!e->rowptr) return env_error("silc_envelope_to_dense: CSR envelope has no rowptr");
        memset(out, 0, (size_t)(count * w) * sizeof(double));
        for (i = 0; i < e->m; i++)
            for (k = e->rowptr[i]; k < e->rowptr[i + 1]; k++) {
                if (e->colind[k] < 0 || e->colind[k] >= e->n)
                    return env_error("silc_envelope_to_dense: column index %lld out of range in row %lld",
                                     (long long)e->colind[k], (long long)i);
                memcpy(out + (i + e->colind[k] * e->m) * w, e->values + k * w, (size_t)w * sizeof(double));
            }
        return 0;
    case SILC_BAND: {
        int64_t ld = e->kl + e->ku + 1;
        memset(out, 0, (size_t)(count * w) * sizeof(double));
        for (j = 0; j < e->n; j++) {
            int64_t lo = j - e->ku > 0 ? j - e->ku : 0;
            int64_t hi = j + e->kl < e->m - 1 ? j + e->kl : e->m - 1;
            for (i = lo; i <= hi; i++)
                memcpy(out + (i + j * e->m) * w, e->values + ((e->ku + i - j) + j * ld) * w,
                       (size_t)w * sizeof(double));
        }
        return 0;
    }
    default:
        return env_error("silc_envelope_to_dense: unknown format %d", (int)e->format);
    }
}

void silc_envelope_free(silc_envelope_t *e)
{
    if (!e) return;
    val_array_free(e->values);
    val_array_free(e->rowptr);
    val_array_free(e->colind);
    memset(e, 0, sizeof *e);
}

/* ---- envelopes <-> values ------------------------------------------------- */

/* The parts an envelope claims.  Dense and band envelopes hold exactly
 * m*n and (kl+ku+1)*n values by definition; a CSR envelope's nnz must say
 * how many entries colind and values hold. */
static void env_parts(const silc_envelope_t *e, val_parts *p)
{
    memset(p, 0, sizeof *p);
    p->format = env_format_base((int)e->format);
    p->field = env_format_field((int)e->format);
    p->m = e->m, p->n = e->n;
    p->nnz = p->format == SILC_CSR ? e->nnz : 0;
    p->kl = p->format == SILC_BAND ? e->kl : 0;
    p->ku = p->format == SILC_BAND ? e->ku : 0;
    p->rowptr = e->rowptr, p->colind = e->colind, p->values = e->values;
}

/* NULL and not-constructed envelopes, with the reason in err. */
static int env_usable(const silc_envelope_t *e, char *err, size_t errlen)
{
    char why[512];
    if (!e) return check_fail(err, errlen, "NULL envelope");
    if (env_not_constructed(e, why, sizeof why))
        return check_fail(err, errlen, "envelope was not constructed: %s", why);
    if ((env_format_base((int)e->format) != SILC_DENSE && env_format_base((int)e->format) != SILC_CSR &&
         env_format_base((int)e->format) != SILC_BAND) || ((int)e->format & ~(SILC_COMPLEX | 3)))
        return check_fail(err, errlen, "unknown envelope format %d", (int)e->format);
    return 0;
}

int env_check(const silc_envelope_t *e, char *err, size_t errlen)
{
    val_parts p;
    if (env_usable(e, err, errlen)) return -1;
    env_parts(e, &p);
    return val_parts_check(&p, err, errlen);
}

int env_csr_fill(silc_value *v, const silc_envelope_t *e, char *err, size_t errlen)
{
    val_parts p;
    if (env_usable(e, err, errlen)) return -1;
    env_parts(e, &p);
    return val_parts_fill(v, &p, err, errlen);
}

int env_same_as_value(const silc_envelope_t *e, const silc_value *v)
{
    silc_view x, y;
    if (!e || !v || v->dist || !e->values) return 0;
    val_view(v, &y);
    if ((int)e->format != env_format_code(y.format, v->field) || e->m != y.m || e->n != y.n) return 0;
    x = y;
    x.val = e->values;
    if (y.format == SILC_FMT_CSR) {
        if (!e->rowptr || !e->colind || e->nnz != y.nnz) return 0;
        x.rowptr = e->rowptr;
        x.colind = e->colind;
    } else if (y.format == SILC_FMT_BAND) {
        if (e->kl != y.kl || e->ku != y.ku || y.ld != y.kl + y.ku + 1) return 0;
    }
    return view_same_contents(&x, &y, val_width(v));
}

int env_to_value(const silc_envelope_t *e, silc_value **out, char *err, size_t errlen)
{
    val_parts p;
    *out = NULL;
    if (env_usable(e, err, errlen)) return -1;
    env_parts(e, &p);
    return val_from_parts(&p, out, err, errlen);
}

int env_from_value(const silc_value *v, silc_envelope_t *e)
{
    int64_t count;
    memset(e, 0, sizeof *e);
    if (!v) return -1;
    count = v->nnz; /* dense m*n, band ld*n, csr entries in use */
    e->values = copy_array(v->val, count * val_width(v), sizeof(double));
    if (!e->values) return -1;
    if (v->format == SILC_FMT_CSR) {
        e->rowptr = copy_array(v->rowptr, v->m + 1, sizeof(int64_t));
        e->colind = copy_array(v->colind, count, sizeof(int64_t));
        if (!e->rowptr || !e->colind) {
            silc_envelope_free(e);
            return -1;
        }
    }
    e->m = v->m;
    e->n = v->n;
    e->format = (silc_format_t)env_format_code(v->format, v->field);
    e->nnz = count;
    if (v->format == SILC_FMT_BAND) {
        e->kl = v->kl;
        e->ku = v->ku;
    }
    return 0;
}
