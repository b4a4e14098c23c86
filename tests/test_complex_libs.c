/*
 * test_complex_libs.c -- the harness of test_complex_libs.py: runs one
 * complex SOLVE of one library plugin (lapack, suitesparse, mumps) through
 * a host of its own, so the plugins' complex paths are tested on their own,
 * apart from the engine (issue 31: the engine's complex store is built in
 * parallel on another branch).
 *
 *   test_complex_libs PLUGIN.so BACKEND CLASS A.bin B.bin X.out [SOLVES]
 *
 * A.bin and B.bin are written by the Python driver: an int64 header
 * {0x51c, format (0 dense, 1 CSR), field (0 real, 1 complex), m, n, nnz},
 * then for CSR rowptr[m+1] and colind[nnz] (int64), then the values
 * (column-major for dense; 2 doubles per complex entry).  The harness loads
 * the plugin, checks that the backend lists SOLVE in complex_ops, asks its
 * accepts() and runs the op SOLVES times (default 1; the second must reuse
 * the factorization), writes x to X.out in the same format and prints
 *   status S / reused R / cond_est C / method M / note N / message E.
 * The Python side checks the numbers against NumPy and SciPy.
 *
 * The host is the part of silc_host_api the plugins call: memory, errors,
 * default options, dense / CSR values of both fields, properties computed
 * by brute force over the stored entries, attachments, clocks, and the
 * complex Hager-Higham estimator (LAPACK zlacn2's algorithm, written out
 * here as the truth the engine's estimator must also meet).
 */
#define _POSIX_C_SOURCE 200809L
#include <complex.h>
#include <dlfcn.h>
#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "silc_plugin.h"

#define MAGIC 0x51c
#define MAX_ATTACH 8

struct silc_value {
    silc_view v;
    int field;
    silc_props props;
    int props_done;
    uint64_t id;
    struct {
        char key[64];
        void *data;
        void (*destroy)(void *);
    } att[MAX_ATTACH];
};

static char errbuf[1024];
static uint64_t next_id = 1;

/* ---- memory, errors, options ------------------------------------------------ */

static void *h_alloc(size_t n) { return malloc(n ? n : 1); }
static void *h_calloc(size_t c, size_t s) { return calloc(c ? c : 1, s ? s : 1); }
static void *h_realloc(void *p, size_t n) { return realloc(p, n ? n : 1); }
static void h_free(void *p) { free(p); }

static int h_error(silc_call *call, int status, const char *fmt, ...)
{
    va_list ap;
    (void)call;
    va_start(ap, fmt);
    vsnprintf(errbuf, sizeof errbuf, fmt, ap);
    va_end(ap);
    return status;
}

static void h_log(int level, const char *fmt, ...)
{
    (void)level, (void)fmt;
}

static int h_option_int(silc_call *c, const char *k, int64_t def, int64_t *out)
{
    (void)c, (void)k;
    *out = def;
    return 0;
}

static int h_option_double(silc_call *c, const char *k, double def, double *out)
{
    (void)c, (void)k;
    *out = def;
    return 0;
}

static const char *h_option_string(silc_call *c, const char *k, const char *def)
{
    (void)c, (void)k;
    return def;
}

/* ---- values ------------------------------------------------------------------- */

static silc_value *value_new(int format, int field, int64_t m, int64_t n, int64_t nnz)
{
    silc_value *x = calloc(1, sizeof *x);
    size_t w = field == SILC_FIELD_COMPLEX ? 2 : 1;
    if (!x) return NULL;
    x->v.m = m, x->v.n = n, x->v.format = format, x->field = field, x->id = next_id++;
    x->v.nnz = format == SILC_FMT_DENSE ? m * n : nnz;
    x->v.val = calloc((size_t)(x->v.nnz > 0 ? x->v.nnz : 1) * w, sizeof(double));
    if (format == SILC_FMT_CSR) {
        x->v.rowptr = calloc((size_t)m + 1, sizeof(silc_index));
        x->v.colind = calloc((size_t)(nnz > 0 ? nnz : 1), sizeof(silc_index));
    }
    return x;
}

static silc_value *h_dense_new(int64_t m, int64_t n) { return value_new(SILC_FMT_DENSE, 0, m, n, 0); }
static silc_value *h_dense_new_complex(int64_t m, int64_t n) { return value_new(SILC_FMT_DENSE, 1, m, n, 0); }
static silc_value *h_csr_new(int64_t m, int64_t n, int64_t cap) { return value_new(SILC_FMT_CSR, 0, m, n, cap); }
static silc_value *h_csr_new_complex(int64_t m, int64_t n, int64_t cap)
{
    return value_new(SILC_FMT_CSR, 1, m, n, cap);
}
static silc_value *h_band_new(int64_t m, int64_t n, int64_t kl, int64_t ku)
{
    (void)m, (void)n, (void)kl, (void)ku;
    return NULL; /* no plugin's solve makes a band value */
}

static int h_csr_set_nnz(silc_value *v, int64_t nnz)
{
    v->v.nnz = nnz;
    return 0;
}

static void h_release(silc_value *x)
{
    if (!x) return;
    for (int i = 0; i < MAX_ATTACH; i++)
        if (x->att[i].data) x->att[i].destroy(x->att[i].data);
    free(x->v.val);
    free(x->v.rowptr);
    free(x->v.colind);
    free(x);
}

static void h_view(const silc_value *v, silc_view *out) { *out = v->v; }
static uint64_t h_id(const silc_value *v) { return v->id; }
static int h_field(const silc_value *v) { return v->field; }

static double complex entry(const silc_value *x, int64_t p)
{
    return x->field ? ((const double complex *)x->v.val)[p] : x->v.val[p];
}

/* The stored entry (i, j) of a CSR value, 0 when absent (colind is sorted). */
static double complex csr_at(const silc_value *x, int64_t i, int64_t j)
{
    int64_t lo = x->v.rowptr[i], hi = x->v.rowptr[i + 1] - 1;
    while (lo <= hi) {
        int64_t mid = (lo + hi) / 2;
        if (x->v.colind[mid] == j) return entry(x, mid);
        if (x->v.colind[mid] < j) lo = mid + 1;
        else hi = mid - 1;
    }
    return 0;
}

static double complex at(const silc_value *x, int64_t i, int64_t j)
{
    return x->v.format == SILC_FMT_CSR ? csr_at(x, i, j) : entry(x, i + j * x->v.m);
}

/* Every property by brute force over the stored entries. */
static const silc_props *h_props(const silc_value *cv)
{
    silc_value *x = (silc_value *)cv;
    silc_props *P = &x->props;
    const silc_view *v = &x->v;
    double *colsum;
    if (x->props_done) return P;
    memset(P, 0, sizeof *P);
    P->square = v->m == v->n;
    P->symmetric = P->hermitian = P->square;
    P->pos_diag = P->square;
    P->diagonal = P->lower = P->upper = 1;
    colsum = calloc((size_t)(v->n > 0 ? v->n : 1), sizeof *colsum);
    for (int64_t i = 0; i < v->m; i++) {
        int64_t p0 = v->format == SILC_FMT_CSR ? v->rowptr[i] : 0;
        int64_t p1 = v->format == SILC_FMT_CSR ? v->rowptr[i + 1] : v->n;
        double rowsum = 0;
        for (int64_t p = p0; p < p1; p++) {
            int64_t j = v->format == SILC_FMT_CSR ? v->colind[p] : p;
            double complex a = at(x, i, j);
            double m = cabs(a);
            if (a == 0) continue;
            P->nnz++;
            if (!isfinite(creal(a)) || !isfinite(cimag(a))) P->has_nonfinite = 1;
            if (i != j) P->diagonal = 0;
            if (j > i) P->lower = 0, P->ku = j - i > P->ku ? j - i : P->ku;
            if (i > j) P->upper = 0, P->kl = i - j > P->kl ? i - j : P->kl;
            if (P->square) {
                double complex t = at(x, j, i);
                if (t != a) P->symmetric = 0;
                if (t != conj(a)) P->hermitian = 0;
            }
            colsum[j] += m;
            rowsum += m;
            P->normfro += m * m;
            if (m > P->maxabs) P->maxabs = m;
        }
        if (rowsum > P->norminf) P->norminf = rowsum;
    }
    for (int64_t i = 0; P->square && i < v->n; i++) {
        double complex d = at(x, i, i);
        if (!(creal(d) > 0) || cimag(d) != 0) P->pos_diag = 0;
    }
    for (int64_t j = 0; j < v->n; j++)
        if (colsum[j] > P->norm1) P->norm1 = colsum[j];
    P->normfro = sqrt(P->normfro);
    free(colsum);
    x->props_done = 1;
    return P;
}

static const silc_props *h_props_part(const silc_value *v, int parts)
{
    (void)parts;
    return h_props(v);
}

static void *h_attach_get(const silc_value *v, const char *key)
{
    for (int i = 0; i < MAX_ATTACH; i++)
        if (v->att[i].data && strcmp(v->att[i].key, key) == 0) return v->att[i].data;
    return NULL;
}

static int h_attach_set(const silc_value *cv, const char *key, void *data, void (*destroy)(void *))
{
    silc_value *v = (silc_value *)cv;
    int free_slot = -1;
    for (int i = 0; i < MAX_ATTACH; i++) {
        if (v->att[i].data && strcmp(v->att[i].key, key) == 0) {
            v->att[i].destroy(v->att[i].data);
            v->att[i].data = data, v->att[i].destroy = destroy;
            return 0;
        }
        if (!v->att[i].data && free_slot < 0) free_slot = i;
    }
    if (free_slot < 0) return -1;
    snprintf(v->att[free_slot].key, sizeof v->att[free_slot].key, "%s", key);
    v->att[free_slot].data = data, v->att[free_slot].destroy = destroy;
    return 0;
}

static double h_now(void)
{
    struct timespec t;
    clock_gettime(CLOCK_MONOTONIC, &t);
    return (double)t.tv_sec + 1e-9 * (double)t.tv_nsec;
}

static int h_threads(void) { return 1; }
static const void *h_comm(const silc_call *c, int *rank, int *size)
{
    (void)c;
    *rank = 0, *size = 1;
    return NULL;
}
static int h_layout(const silc_value *v, silc_layout *out)
{
    (void)v, (void)out;
    return 0;
}
static int h_cancelled(silc_call *c)
{
    (void)c;
    return 0;
}

/* ---- the complex estimator: Hager-Higham as LAPACK's zlacn2 ------------------ */

static double norm1z(int64_t n, const double complex *x)
{
    double s = 0;
    for (int64_t i = 0; i < n; i++) s += cabs(x[i]);
    return s;
}

static void sign_of(int64_t n, double complex *x)
{
    for (int64_t i = 0; i < n; i++) {
        double a = cabs(x[i]);
        x[i] = a > 0 ? x[i] / a : 1;
    }
}

static int64_t argmax_abs(int64_t n, const double complex *x)
{
    int64_t j = 0;
    for (int64_t i = 1; i < n; i++)
        if (cabs(x[i]) > cabs(x[j])) j = i;
    return j;
}

static double h_inv_norm1_est_complex(int64_t n, int (*apply)(void *, double *, int, double *), void *ctx,
                                      double *work)
{
    double complex *x = calloc((size_t)(n > 0 ? n : 1), sizeof *x);
    double est = -1, old;
    int64_t j, jlast;
    if (!x || n <= 0) goto done;
    for (int64_t i = 0; i < n; i++) x[i] = 1.0 / (double)n;
    if (apply(ctx, (double *)x, 0, work)) goto done;
    est = norm1z(n, x);
    if (n == 1) goto done;
    sign_of(n, x);
    if (apply(ctx, (double *)x, 1, work)) goto fail;
    j = argmax_abs(n, x);
    for (int it = 2; it <= 5; it++) {
        memset(x, 0, (size_t)n * sizeof *x);
        x[j] = 1;
        if (apply(ctx, (double *)x, 0, work)) goto fail;
        old = est;
        est = norm1z(n, x);
        if (est <= old) {
            est = old;
            break;
        }
        sign_of(n, x);
        if (apply(ctx, (double *)x, 1, work)) goto fail;
        jlast = j;
        j = argmax_abs(n, x);
        if (cabs(x[jlast]) == cabs(x[j])) break;
    }
    for (int64_t i = 0; i < n; i++) x[i] = (i % 2 ? -1.0 : 1.0) * (1.0 + (double)i / (double)(n - 1));
    if (apply(ctx, (double *)x, 0, work)) goto fail;
    old = 2 * norm1z(n, x) / (3.0 * (double)n);
    if (old > est) est = old;
    goto done;
fail:
    est = -1;
done:
    free(x);
    return est;
}

static const silc_host_api host = {
    .abi_major = SILC_ABI_MAJOR, .abi_minor = SILC_ABI_MINOR, .struct_size = sizeof(silc_host_api),
    .index_bytes = (int)sizeof(silc_index),
    .alloc = h_alloc, .calloc = h_calloc, .realloc = h_realloc, .free = h_free,
    .error = h_error, .log = h_log,
    .option_int = h_option_int, .option_double = h_option_double, .option_string = h_option_string,
    .dense_new = h_dense_new, .csr_new = h_csr_new, .band_new = h_band_new, .csr_set_nnz = h_csr_set_nnz,
    .release = h_release, .view = h_view, .props = h_props, .id = h_id,
    .attach_get = h_attach_get, .attach_set = h_attach_set, .now = h_now, .threads = h_threads,
    .dense_new_uninit = h_dense_new, .props_part = h_props_part,
    .comm = h_comm, .layout = h_layout, .cancelled = h_cancelled,
    .field = h_field, .dense_new_complex = h_dense_new_complex, .csr_new_complex = h_csr_new_complex,
    .inv_norm1_est_complex = h_inv_norm1_est_complex,
    /* the real estimators and band_new_complex are left NULL: no complex
     * solve may call them (a call would crash the harness, failing the test) */
};

/* ---- files -------------------------------------------------------------------- */

static silc_value *read_value(const char *path)
{
    FILE *f = fopen(path, "rb");
    int64_t h[6];
    silc_value *x = NULL;
    size_t w;
    if (!f || fread(h, sizeof h, 1, f) != 1 || h[0] != MAGIC) goto done;
    x = value_new((int)h[1], (int)h[2], h[3], h[4], h[5]);
    if (!x) goto done;
    w = x->field ? 2 : 1;
    if (x->v.format == SILC_FMT_CSR &&
        (fread(x->v.rowptr, sizeof(silc_index), (size_t)h[3] + 1, f) != (size_t)h[3] + 1 ||
         fread(x->v.colind, sizeof(silc_index), (size_t)h[5], f) != (size_t)h[5])) {
        h_release(x);
        x = NULL;
        goto done;
    }
    if (fread(x->v.val, sizeof(double) * w, (size_t)x->v.nnz, f) != (size_t)x->v.nnz) {
        h_release(x);
        x = NULL;
    }
done:
    if (f) fclose(f);
    return x;
}

static int write_value(const char *path, const silc_value *x)
{
    FILE *f = fopen(path, "wb");
    int64_t h[6] = {MAGIC, x->v.format, x->field, x->v.m, x->v.n, x->v.nnz};
    size_t w = x->field ? 2 : 1;
    int ok;
    if (!f) return -1;
    ok = fwrite(h, sizeof h, 1, f) == 1 &&
         fwrite(x->v.val, sizeof(double) * w, (size_t)x->v.nnz, f) == (size_t)x->v.nnz;
    return fclose(f) == 0 && ok ? 0 : -1;
}

int main(int argc, char **argv)
{
    void *so;
    silc_plugin_init_fn init;
    const silc_plugin *pl = NULL;
    const silc_backend *be = NULL;
    const char *errmsg = "";
    const char *why = "";
    silc_value *A, *B;
    int b, rc = 0, solves = argc > 7 ? atoi(argv[7]) : 1;
    if (argc < 7) {
        fprintf(stderr, "usage: %s PLUGIN.so BACKEND CLASS A.bin B.bin X.out [SOLVES]\n", argv[0]);
        return 2;
    }
    if (!(so = dlopen(argv[1], RTLD_NOW | RTLD_LOCAL))) {
        fprintf(stderr, "dlopen: %s\n", dlerror());
        return 2;
    }
    init = (silc_plugin_init_fn)(uintptr_t)dlsym(so, SILC_PLUGIN_INIT_SYMBOL);
    if (!init || init(&host, &pl, &errmsg)) {
        fprintf(stderr, "silc_plugin_init: %s\n", errmsg ? errmsg : "failed");
        return 2;
    }
    for (b = 0; b < pl->n_backends; b++) {
        const char *name = pl->backends[b].name ? pl->backends[b].name : pl->name;
        if (strcmp(name, argv[2]) == 0) be = &pl->backends[b];
        if (be) break;
    }
    if (!be || be->n_ops <= SILC_OP_SOLVE || !be->ops[SILC_OP_SOLVE].run) {
        fprintf(stderr, "backend %s of %s has no SOLVE\n", argv[2], pl->name);
        return 2;
    }
    printf("complex_ops %d\n", pl->struct_size >= offsetof(silc_plugin, complex_ops) + sizeof(void *) &&
                                       pl->complex_ops &&
                                       (pl->complex_ops[b] & SILC_COMPLEX_OPS(SILC_OP_SOLVE)) != 0);
    A = read_value(argv[4]);
    B = read_value(argv[5]);
    if (!A || !B) {
        fprintf(stderr, "cannot read %s or %s\n", argv[4], argv[5]);
        return 2;
    }
    for (int s = 0; s < solves && rc == 0; s++) {
        silc_report r;
        silc_call call;
        memset(&r, 0, sizeof r);
        r.cond_est = -1, r.rcond = -1;
        memset(&call, 0, sizeof call);
        call.op = SILC_OP_SOLVE, call.nin = 2, call.in[0] = A, call.in[1] = B;
        call.report = &r, call.op_class = argv[3];
        errbuf[0] = 0;
        if (be->ops[SILC_OP_SOLVE].accepts && !be->ops[SILC_OP_SOLVE].accepts(&call, &why)) {
            printf("declined %s\n", why);
            rc = SILC_EDECLINE;
            break;
        }
        rc = be->ops[SILC_OP_SOLVE].run(&call);
        printf("status %d\nreused %d\ncond_est %.17g\nmethod %s\nnote %s\nmessage %s\n", rc, r.reused_factor,
               r.cond_est, r.method, r.note, errbuf);
        if (rc == 0 && call.out) {
            if (write_value(argv[6], call.out)) {
                fprintf(stderr, "cannot write %s\n", argv[6]);
                rc = 2;
            }
            h_release(call.out);
        }
    }
    h_release(A);
    h_release(B);
    if (pl->shutdown) pl->shutdown();
    return 0;
}
