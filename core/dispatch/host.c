/*
 * host.c -- the silc_host_api table: everything a plugin may ask of SILC.
 *
 * Plugins never link against libsilc; they reach values, options, errors and
 * the clock only through this table, which is why the same plugin source can
 * be compiled into libsilc (the reference) or loaded as a module.  Calls that
 * concern one operation (error, option_*) find the engine and the running
 * backend through call->host_private, which the dispatcher points at a
 * host_call_ctx for every attempt.
 */
#define _POSIX_C_SOURCE 200809L
#include "dispatch.h"
#include "dist.h"

#include <errno.h>
#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

static int host_threads_budget = 1;

void host_set_threads(int nthreads)
{
    if (nthreads >= 1) host_threads_budget = nthreads;
}

static int h_threads(void)
{
    return host_threads_budget;
}

/* One array a plugin asks for is held to the limit of one value
 * (val_max_bytes): work arrays grow with their operands' shapes, and a small
 * but wide operand (eye(2, 1e12): 48 bytes as CSR, 8 TB of column pointers
 * as CSC) must be refused with its size, which the dispatcher reports (found
 * by fuzz_lang), not handed to calloc.  Arrays under 64 MiB are not checked:
 * the small work arrays of every operation skip the check and its double
 * arithmetic. */
static int h_too_big(double bytes)
{
    return bytes >= (double)(64u << 20) && val_claim(bytes, "a plugin's work array");
}

/* Plugins' arrays come from the array pool like values' arrays
 * (val_array_alloc): a factorization's copy of a dense matrix is as large as
 * the matrix, and from fresh pages each solve it paid ~1 % of a dgetrf in
 * page faults.  Pooled arrays are plain malloc blocks, so realloc and free
 * of either kind stay correct. */
static void *h_alloc(size_t bytes)
{
    if (h_too_big((double)bytes)) return NULL;
    return val_array_alloc(1, bytes ? bytes : 1, 0);
}

static void *h_calloc(size_t count, size_t size)
{
    if (h_too_big((double)count * (double)size)) return NULL;
    if (size && count > SIZE_MAX / size) return NULL;
    return val_array_alloc(1, count && size ? count * size : 1, 1);
}

static void *h_realloc(void *p, size_t bytes)
{
    if (h_too_big((double)bytes)) return NULL;
    return realloc(p, bytes ? bytes : 1);
}

static void h_free(void *p)
{
    val_array_free(p);
}

static int h_error(silc_call *call, int status, const char *fmt, ...)
{
    host_call_ctx *ctx = call ? call->host_private : NULL;
    va_list ap;
    va_start(ap, fmt);
    if (ctx) {
        vsnprintf(ctx->err, sizeof ctx->err, fmt, ap);
        ctx->status = status;
    } else {
        /* A plugin reporting outside a dispatched call: nowhere to keep it. */
        fputs("silc: plugin error: ", stderr);
        vfprintf(stderr, fmt, ap);
        fputc('\n', stderr);
    }
    va_end(ap);
    return status;
}

/* Levels 0 (error) and 1 (warning) always show; SILC_VERBOSE=2 or 3 shows
 * info and debug messages too. */
static void h_log(int level, const char *fmt, ...)
{
    static const char *const names[] = {"error", "warning", "info", "debug"};
    const char *env = getenv("SILC_VERBOSE");
    int verbose = env ? atoi(env) : 1;
    va_list ap;
    if (level > verbose) return;
    if (level < 0) level = 0;
    if (level > 3) level = 3;
    fprintf(stderr, "silc: %s: ", names[level]);
    va_start(ap, fmt);
    vfprintf(stderr, fmt, ap);
    va_end(ap);
    fputc('\n', stderr);
}

/* The text of <plugin>.<key> in the narrowest scope that sets it, or NULL. */
static const char *option_text(silc_call *call, const char *key, char *full, size_t fulllen)
{
    host_call_ctx *ctx = call ? call->host_private : NULL;
    if (!ctx || !ctx->E || !ctx->backend || !key) return NULL;
    snprintf(full, fulllen, "%s.%s", ctx->backend->plugin->table->name, key);
    return cfg_get(ctx->E, full);
}

static int h_option_int(silc_call *call, const char *key, int64_t def, int64_t *out)
{
    char full[256], *end;
    const char *t = option_text(call, key, full, sizeof full);
    long long v;
    *out = def;
    if (!t) return 0;
    if (strcmp(t, "true") == 0 || strcmp(t, "yes") == 0 || strcmp(t, "on") == 0) return *out = 1, 0;
    if (strcmp(t, "false") == 0 || strcmp(t, "no") == 0 || strcmp(t, "off") == 0) return *out = 0, 0;
    errno = 0;
    v = strtoll(t, &end, 10);
    if (end == t || *end != '\0' || errno == ERANGE)
        return h_error(call, SILC_EARG, "option '%s' expects an integer, got '%s'", full, t);
    *out = (int64_t)v;
    return 0;
}

static int h_option_double(silc_call *call, const char *key, double def, double *out)
{
    char full[256], *end;
    const char *t = option_text(call, key, full, sizeof full);
    double v;
    *out = def;
    if (!t) return 0;
    errno = 0;
    v = strtod(t, &end);
    if (end == t || *end != '\0' || errno == ERANGE || !isfinite(v))
        return h_error(call, SILC_EARG, "option '%s' expects a number, got '%s'", full, t);
    *out = v;
    return 0;
}

static const char *h_option_string(silc_call *call, const char *key, const char *def)
{
    char full[256];
    const char *t = option_text(call, key, full, sizeof full);
    return t ? t : def;
}

static silc_value *h_dense_new(int64_t m, int64_t n)
{
    return val_dense_new(m, n);
}

static silc_value *h_dense_new_uninit(int64_t m, int64_t n)
{
    return val_new_unset(SILC_FMT_DENSE, m, n, 0, 0, 0);
}

static silc_value *h_csr_new(int64_t m, int64_t n, int64_t cap)
{
    return val_csr_new(m, n, cap);
}

static silc_value *h_band_new(int64_t m, int64_t n, int64_t kl, int64_t ku)
{
    return val_band_new(m, n, kl, ku);
}

/* ---- ABI 1.8: complex values ---- */

static int h_field(const silc_value *v)
{
    return v ? v->field : SILC_FIELD_REAL;
}

static silc_value *h_dense_new_complex(int64_t m, int64_t n)
{
    return val_dense_new_complex(m, n);
}

static silc_value *h_csr_new_complex(int64_t m, int64_t n, int64_t cap)
{
    return val_csr_new_complex(m, n, cap);
}

static silc_value *h_band_new_complex(int64_t m, int64_t n, int64_t kl, int64_t ku)
{
    return val_band_new_complex(m, n, kl, ku);
}

static int h_csr_set_nnz(silc_value *v, int64_t nnz)
{
    return val_csr_set_nnz(v, nnz);
}

static void h_release(silc_value *v)
{
    val_release(v);
}

static void h_view(const silc_value *v, silc_view *out)
{
    val_view(v, out);
}

static const silc_props *h_props(const silc_value *v)
{
    return val_props(v);
}

static const silc_props *h_props_part(const silc_value *v, int parts)
{
    return val_props_part(v, parts & SILC_PROPS_ALL);
}

static uint64_t h_id(const silc_value *v)
{
    return v ? v->id : 0;
}

static void *h_attach_get(const silc_value *v, const char *key)
{
    return val_attach_get(v, key);
}

static int h_attach_set(const silc_value *v, const char *key, void *data, void (*destroy)(void *))
{
    return val_attach_set(v, key, data, destroy);
}

/* ---- ABI 1.5: distributed calls (dist.h) ---- */

static const void *h_comm(const silc_call *call, int *rank, int *size)
{
    const host_call_ctx *ctx = call ? call->host_private : NULL;
    int collective = ctx && ctx->collective && ctx->E->dist;
    if (rank) *rank = collective ? ctx->E->dist->rank : 0;
    if (size) *size = collective ? ctx->E->dist->size : 1;
    return collective ? ctx->E->dist->ops->handle : NULL;
}

static int h_layout(const silc_value *v, silc_layout *out)
{
    const val_dist *d = v ? v->dist : NULL;
    if (!d) return 0;
    out->m_global = v->m;
    out->rank = d->ctx->rank;
    out->size = d->ctx->size;
    out->first_row = d->part->starts[out->rank];
    out->m_local = d->part->starts[out->rank + 1] - out->first_row;
    out->starts = d->part->starts;
    return 1;
}

static silc_value *h_dist_dense_new(const silc_value *like, int64_t n)
{
    silc_value *blk;
    if (!like || !like->dist) return NULL;
    /* ABI 1.8: of like's field */
    blk = like->field == SILC_FIELD_COMPLEX ? val_dense_new_complex(like->dist->block->m, n)
                                            : val_dense_new(like->dist->block->m, n);
    if (!blk) return NULL;
    return val_dist_new(like->m, n, SILC_FMT_DENSE, like->dist->ctx, like->dist->part, blk);
}

/* Bytes a collective backend moved itself, summed over the ranks by it. */
static void h_dist_moved(silc_call *call, int matrix, uint64_t bytes)
{
    const host_call_ctx *ctx = call ? call->host_private : NULL;
    if (!ctx || !ctx->collective || !ctx->E->dist) return;
    if (matrix) ctx->E->dist->moved_matrix += bytes;
    else ctx->E->dist->moved_vector += bytes;
}

/* The estimator lives in the built-in reference plugin (plugin-reference/
 * ref_cond.c); lending it through the host keeps one implementation for every
 * backend that needs it. */
extern double ref_inv_norm1_est(int64_t n, int (*apply)(void *ctx, double *x, int trans, double *work),
                                void *ctx, double *work);
extern void ref_inv_norm1_start(int64_t n, int t, double *X0);
extern double ref_inv_norm1_est_block(int64_t n, int t, int itmax,
                                      int (*apply)(void *ctx, double *X, int t, int trans), void *ctx,
                                      const double *Y0);
/* Its complex counterpart (zlacn2's method, issue 31), also in ref_cond.c. */
extern double ref_inv_norm1_est_complex(int64_t n, int (*apply)(void *ctx, double *x, int trans, double *work),
                                        void *ctx, double *work);

static int h_cancelled(silc_call *call)
{
    host_call_ctx *ctx = call ? call->host_private : NULL;
    char why[256];
    /* Not during a collective call or on a communicator: one rank leaving
     * a collective alone would leave the others waiting in it. */
    if (!ctx || !ctx->E || ctx->collective || ctx->E->dist) return 0;
    return eng_cancel_pending(ctx->E, why, sizeof why);
}

/* The dispatcher's copy of v, if it made one for this call and no backend
 * took it yet: the caller owns it from here (frees it with h_free). */
static double *h_take_dense_copy(silc_call *call, const silc_value *v)
{
    host_call_ctx *ctx = call ? call->host_private : NULL;
    double *array;
    if (!ctx || !ctx->copy || ctx->copy->of != v) return NULL;
    array = ctx->copy->array;
    ctx->copy->array = NULL;
    return array;
}

static const silc_host_api host_table = {
    SILC_ABI_MAJOR,
    SILC_ABI_MINOR,
    sizeof(silc_host_api),
    (int)sizeof(silc_index),
    h_alloc,
    h_calloc,
    h_realloc,
    h_free,
    h_error,
    h_log,
    h_option_int,
    h_option_double,
    h_option_string,
    h_dense_new,
    h_csr_new,
    h_band_new,
    h_csr_set_nnz,
    h_release,
    h_view,
    h_props,
    h_id,
    h_attach_get,
    h_attach_set,
    util_now,
    h_threads,
    ref_inv_norm1_est,
    ref_inv_norm1_start,
    ref_inv_norm1_est_block,
    h_dense_new_uninit,
    h_props_part,
    h_comm,
    h_layout,
    h_dist_dense_new,
    h_cancelled,
    h_field,
    h_dense_new_complex,
    h_csr_new_complex,
    h_band_new_complex,
    ref_inv_norm1_est_complex,
    h_dist_moved,
    util_large_malloc,
    util_large_calloc,
    util_large_realloc,
    util_large_free,
    h_take_dense_copy,
};

int host_check_result(silc_call *call)
{
    host_call_ctx *ctx = call->host_private;
    char why[512];
    /* A plugin builds its result with the host's constructors but fills
     * the arrays itself: what it returns is checked as a PUT is
     * (val_check_value), so a broken backend cannot bind a CSR value whose
     * rowptr runs past its entries. */
    if (!call->out || val_check_value(call->out, why, sizeof why) == 0) return SILC_OK;
    if (ctx) snprintf(ctx->err, sizeof ctx->err, "returned a malformed result: %s", why);
    return SILC_EINTERNAL;
}

const silc_host_api *host_api(void)
{
    return &host_table;
}
