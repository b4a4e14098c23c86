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

int silc_envelope_dense(silc_envelope_t *e, int64_t m, int64_t n, const double *colmajor)
{
    int64_t count;
    if (!e) return env_error("silc_envelope_dense: NULL envelope");
    memset(e, 0, sizeof *e);
    count = dense_count(m, n);
    if (count < 0)
        return env_error("silc_envelope_dense: invalid size %lldx%lld", (long long)m, (long long)n);
    if (val_claim((double)count * sizeof(double), "the envelope"))
        return env_error("silc_envelope_dense: %lldx%lld: %s", (long long)m, (long long)n,
                         val_refusal());
    e->values = copy_array(colmajor, count, sizeof(double));
    if (!e->values) return env_error("silc_envelope_dense: out of memory for %lldx%lld",
                                     (long long)m, (long long)n);
    e->m = m;
    e->n = n;
    e->format = SILC_DENSE;
    e->nnz = count;
    return 0;
}

int silc_envelope_scalar(silc_envelope_t *e, double x)
{
    return silc_envelope_dense(e, 1, 1, &x);
}

int silc_envelope_vector(silc_envelope_t *e, int64_t n, const double *x)
{
    return silc_envelope_dense(e, n, 1, x);
}

/* Checks the size, rowptr, and that the arrays its last entry counts exist. */
static int csr_check_rowptr(int64_t m, int64_t n, const int64_t *rowptr, const int64_t *colind,
                            const double *values, char *err, size_t errlen)
{
    int64_t i, nnz;
    if (m < 0 || n < 0) {
        snprintf(err, errlen, "invalid size %lldx%lld", (long long)m, (long long)n);
        return -1;
    }
    if (!rowptr) {
        snprintf(err, errlen, "rowptr is NULL");
        return -1;
    }
    if (rowptr[0] != 0) {
        snprintf(err, errlen, "rowptr[0] is %lld, must be 0", (long long)rowptr[0]);
        return -1;
    }
    for (i = 0; i < m; i++) {
        if (rowptr[i + 1] < rowptr[i]) {
            snprintf(err, errlen, "rowptr decreases at row %lld (rowptr[%lld] = %lld > rowptr[%lld] = %lld)",
                     (long long)i, (long long)i, (long long)rowptr[i], (long long)(i + 1),
                     (long long)rowptr[i + 1]);
            return -1;
        }
    }
    nnz = rowptr[m];
    if (nnz > 0 && (!colind || !values)) {
        snprintf(err, errlen, "%s is NULL but rowptr[m] = %lld", colind ? "values" : "colind",
                 (long long)nnz);
        return -1;
    }
    if (dense_count(nnz, 1) < 0) {
        snprintf(err, errlen, "too many entries (%lld)", (long long)nnz);
        return -1;
    }
    return 0;
}

/* Checks rowptr and column range.  Sortedness is checked by the callers,
 * which differ: the constructor sorts, env_to_value insists. */
static int csr_check_structure(int64_t m, int64_t n, const int64_t *rowptr,
                               const int64_t *colind, const double *values,
                               char *err, size_t errlen)
{
    int64_t i, k;
    if (csr_check_rowptr(m, n, rowptr, colind, values, err, errlen)) return -1;
    for (i = 0; i < m; i++)
        for (k = rowptr[i]; k < rowptr[i + 1]; k++)
            if (colind[k] < 0 || colind[k] >= n) {
                snprintf(err, errlen, "column index %lld out of range [0, %lld) in row %lld",
                         (long long)colind[k], (long long)n, (long long)i);
                return -1;
            }
    return 0;
}

typedef struct col_val {
    int64_t col;
    double val;
} col_val;

static int cmp_col(const void *a, const void *b)
{
    int64_t x = ((const col_val *)a)->col, y = ((const col_val *)b)->col;
    return (x > y) - (x < y);
}

/* Sorts the columns of every unsorted row in place (values follow) and
 * rejects duplicates.  Most rows arrive sorted; they cost one scan. */
static int csr_sort_rows(int64_t m, const int64_t *rowptr, int64_t *colind, double *values,
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
                tmp[k].val = values[lo + k];
            }
            qsort(tmp, (size_t)len, sizeof *tmp, cmp_col);
            for (k = 0; k < len; k++) {
                colind[lo + k] = tmp[k].col;
                values[lo + k] = tmp[k].val;
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
static int envelope_csr_own(silc_envelope_t *e, const char *fn, int64_t m, int64_t n,
                            int64_t *rowptr, int64_t *colind, const double *values)
{
    char msg[512];
    int64_t nnz;
    double *vals;
    if (csr_check_structure(m, n, rowptr, colind, values, msg, sizeof msg)) {
        free(rowptr), free(colind);
        return env_error("%s: %s", fn, msg);
    }
    nnz = rowptr[m];
    vals = copy_array(values, nnz, sizeof(double));
    if (!vals) {
        free(rowptr), free(colind);
        return env_error("%s: out of memory for %lld entries", fn, (long long)nnz);
    }
    if (csr_sort_rows(m, rowptr, colind, vals, msg, sizeof msg)) {
        free(rowptr), free(colind), free(vals);
        return env_error("%s: %s", fn, msg);
    }
    e->m = m;
    e->n = n;
    e->format = SILC_CSR;
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
        return env_error("%s: invalid size %lldx%lld", fn, (long long)m, (long long)n);
    if (!rowptr) return env_error("%s: rowptr is NULL", fn);
    /* rowptr[m] is only trusted after the structure check; copying up to it
     * first is safe because a negative or huge count is rejected here. */
    *nnz = last(rowptr, m);
    if (*nnz < 0 || dense_count(*nnz, 1) < 0)
        return env_error("%s: rowptr[m] = %lld is not a valid entry count", fn, (long long)*nnz);
    if (*nnz > 0 && !colind)
        return env_error("%s: colind is NULL but rowptr[m] = %lld", fn, (long long)*nnz);
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

int silc_envelope_csr(silc_envelope_t *e, int64_t m, int64_t n, const int64_t *rowptr,
                      const int64_t *colind, const double *values)
{
    int64_t *rp, *ci, nnz;
    if (csr_args("silc_envelope_csr", e, m, n, rowptr, last64, colind, &nnz)) return -1;
    rp = copy_array(rowptr, m + 1, sizeof *rp);
    ci = copy_array(colind, nnz, sizeof *ci);
    if (!rp || !ci) {
        free(rp), free(ci);
        return env_error("silc_envelope_csr: out of memory for %lld entries", (long long)nnz);
    }
    return envelope_csr_own(e, "silc_envelope_csr", m, n, rp, ci, values);
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
        free(rp), free(ci);
        return env_error("silc_envelope_csr32: out of memory for %lld entries", (long long)nnz);
    }
    for (k = 0; k <= m; k++) rp[k] = rowptr[k];
    for (k = 0; k < nnz; k++) ci[k] = colind[k];
    return envelope_csr_own(e, "silc_envelope_csr32", m, n, rp, ci, values);
}

/* Band storage size ld*n, or -1. */
static int64_t band_count(int64_t n, int64_t kl, int64_t ku)
{
    if (kl < 0 || ku < 0 || kl > INT32_MAX || ku > INT32_MAX) return -1;
    return dense_count(kl + ku + 1, n);
}

int silc_envelope_band(silc_envelope_t *e, int64_t m, int64_t n, int64_t kl, int64_t ku,
                       const double *band)
{
    int64_t count;
    if (!e) return env_error("silc_envelope_band: NULL envelope");
    memset(e, 0, sizeof *e);
    count = band_count(n, kl, ku);
    if (m < 0 || count < 0)
        return env_error("silc_envelope_band: invalid size %lldx%lld with kl = %lld, ku = %lld",
                         (long long)m, (long long)n, (long long)kl, (long long)ku);
    if (val_claim((double)count * sizeof(double), "the envelope"))
        return env_error("silc_envelope_band: %lldx%lld with kl = %lld, ku = %lld: %s",
                         (long long)m, (long long)n, (long long)kl, (long long)ku, val_refusal());
    e->values = copy_array(band, count, sizeof(double));
    if (!e->values) return env_error("silc_envelope_band: out of memory");
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
    int64_t i, j, k, count;
    if (!e || !out) return env_error("silc_envelope_to_dense: NULL %s", e ? "output array" : "envelope");
    count = dense_count(e->m, e->n);
    if (count < 0) return env_error("silc_envelope_to_dense: invalid envelope size");
    if (count > 0 && !e->values)
        return env_error("silc_envelope_to_dense: envelope has no values (freed or never built?)");
    switch (e->format) {
    case SILC_DENSE:
        memcpy(out, e->values, (size_t)count * sizeof(double));
        return 0;
    case SILC_CSR:
        if (!e->rowptr) return env_error("silc_envelope_to_dense: CSR envelope has no rowptr");
        memset(out, 0, (size_t)count * sizeof(double));
        for (i = 0; i < e->m; i++)
            for (k = e->rowptr[i]; k < e->rowptr[i + 1]; k++) {
                if (e->colind[k] < 0 || e->colind[k] >= e->n)
                    return env_error("silc_envelope_to_dense: column index %lld out of range in row %lld",
                                     (long long)e->colind[k], (long long)i);
                out[i + e->colind[k] * e->m] = e->values[k];
            }
        return 0;
    case SILC_BAND: {
        int64_t ld = e->kl + e->ku + 1;
        memset(out, 0, (size_t)count * sizeof(double));
        for (j = 0; j < e->n; j++) {
            int64_t lo = j - e->ku > 0 ? j - e->ku : 0;
            int64_t hi = j + e->kl < e->m - 1 ? j + e->kl : e->m - 1;
            for (i = lo; i <= hi; i++) out[i + j * e->m] = e->values[(e->ku + i - j) + j * ld];
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

int env_check(const silc_envelope_t *e, char *err, size_t errlen)
{
    int64_t count, i, k;
    if (!e) {
        snprintf(err, errlen, "NULL envelope");
        return -1;
    }
    switch (e->format) {
    case SILC_DENSE:
        count = dense_count(e->m, e->n);
        if (count < 0) {
            snprintf(err, errlen, "invalid size %lldx%lld", (long long)e->m, (long long)e->n);
            return -1;
        }
        if (count > 0 && !e->values) {
            snprintf(err, errlen, "dense envelope has no values (freed or never built?)");
            return -1;
        }
        return 0;
    case SILC_CSR:
        if (csr_check_structure(e->m, e->n, e->rowptr, e->colind, e->values, err, errlen)) return -1;
        for (i = 0; i < e->m; i++)
            for (k = e->rowptr[i] + 1; k < e->rowptr[i + 1]; k++)
                if (e->colind[k - 1] >= e->colind[k]) {
                    snprintf(err, errlen, "columns of row %lld are %s (build CSR envelopes "
                             "with silc_envelope_csr, which sorts them)", (long long)i,
                             e->colind[k - 1] == e->colind[k] ? "duplicated" : "not sorted");
                    return -1;
                }
        return 0;
    case SILC_BAND:
        count = band_count(e->n, e->kl, e->ku);
        if (e->m < 0 || count < 0) {
            snprintf(err, errlen, "invalid band size %lldx%lld with kl = %lld, ku = %lld",
                     (long long)e->m, (long long)e->n, (long long)e->kl, (long long)e->ku);
            return -1;
        }
        if (count > 0 && !e->values) {
            snprintf(err, errlen, "band envelope has no values (freed or never built?)");
            return -1;
        }
        return 0;
    default:
        snprintf(err, errlen, "unknown envelope format %d", (int)e->format);
        return -1;
    }
}

/* env_csr_fill after its rowptr check. */
static int csr_fill(silc_value *v, const silc_envelope_t *e, char *err, size_t errlen)
{
    if (val_csr_fill_checked(v, e->rowptr, e->colind, e->values) == 0) return 0;
    /* The fast pass only knows that a row failed; env_check finds it again
     * and says how. */
    if (env_check(e, err, errlen) == 0)
        snprintf(err, errlen, "CSR arrays refused with no reason found (internal error)");
    return -1;
}

int env_csr_fill(silc_value *v, const silc_envelope_t *e, char *err, size_t errlen)
{
    if (csr_check_rowptr(e->m, e->n, e->rowptr, e->colind, e->values, err, errlen)) return -1;
    return csr_fill(v, e, err, errlen);
}

int env_same_as_value(const silc_envelope_t *e, const silc_value *v)
{
    silc_view x, y;
    if (!e || !v || v->dist || !e->values) return 0;
    val_view(v, &y);
    if ((int)e->format != y.format || e->m != y.m || e->n != y.n) return 0;
    x = y;
    x.val = e->values;
    if (y.format == SILC_FMT_CSR) {
        if (!e->rowptr || !e->colind || e->nnz != y.nnz) return 0;
        x.rowptr = e->rowptr;
        x.colind = e->colind;
    } else if (y.format == SILC_FMT_BAND) {
        if (e->kl != y.kl || e->ku != y.ku || y.ld != y.kl + y.ku + 1) return 0;
    }
    return view_same_contents(&x, &y);
}

int env_to_value(const silc_envelope_t *e, silc_value **out, char *err, size_t errlen)
{
    silc_value *v;
    int64_t count;
    *out = NULL;
    if (e && e->format == SILC_CSR) {
        /* rowptr first, for the size; the entries are checked while copied,
         * not in a pass of their own (csr_fill). */
        if (csr_check_rowptr(e->m, e->n, e->rowptr, e->colind, e->values, err, errlen)) return -1;
        v = val_new_unset(SILC_FMT_CSR, e->m, e->n, e->rowptr[e->m], 0, 0);
        if (v && csr_fill(v, e, err, errlen)) {
            val_release(v);
            return -1;
        }
    } else {
        if (env_check(e, err, errlen)) return -1;
        /* Dense or band (env_check refused every other format): one array,
         * copied whole. */
        count = e->format == SILC_DENSE ? e->m * e->n : band_count(e->n, e->kl, e->ku);
        v = val_new_unset((int)e->format, e->m, e->n, 0, e->kl, e->ku);
        if (v && count > 0) memcpy(v->val, e->values, (size_t)count * sizeof(double));
    }
    if (!v) {
        snprintf(err, errlen, "out of memory copying a %lldx%lld %s matrix", (long long)e->m,
                 (long long)e->n, val_format_name((int)e->format));
        return -1;
    }
    *out = v;
    return 0;
}

int env_from_value(const silc_value *v, silc_envelope_t *e)
{
    int64_t count;
    memset(e, 0, sizeof *e);
    if (!v) return -1;
    count = v->nnz; /* dense m*n, band ld*n, csr entries in use */
    e->values = copy_array(v->val, count, sizeof(double));
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
    e->format = (silc_format_t)v->format;
    e->nnz = count;
    if (v->format == SILC_FMT_BAND) {
        e->kl = v->kl;
        e->ku = v->ku;
    }
    return 0;
}
