/*
 * builtins.c -- the language's built-in functions and constants.
 *
 * Functions that only arrange structure are built here by the core (zeros,
 * ones, eye, rand, size, rows, cols, nnz, sparse(i,j,v,m,n)); everything that
 * computes on values is a silc_call for the dispatcher (conversions, diag,
 * reductions, element-wise maps, transposes, solves).
 *
 *   zeros(m[,n]) ones(m[,n])   dense; one argument gives m x m (as MATLAB)
 *   eye(n[,m])                 CSR identity: this is a sparse-solver tool
 *   rand(m[,n])                dense uniform [0,1), xorshift64* seeded per context
 *   size(A) size(A,d) rows cols nnz (numerically nonzero entries)
 *   sparse(i,j,v,m,n)          1-based triplets, duplicates summed, v may be scalar
 *   sparse(A) dense(A) band(A,kl,ku)  format conversions (band refuses entries outside)
 *   diag(v) diagvec(A)         vector -> CSR diagonal; diagonal -> column
 *   sum max min (1 argument: per column, 1x1 for vectors) max min (2: element-wise)
 *   dot(x,y) norm(x[,p])       p = 1, 2, inf or "fro"
 *   abs sqrt exp log sin cos trans(A) solve(A, b[, "options"])
 *   constants pi inf nan eps   (a variable of the same name shadows them)
 */
#include "lang.h"

#include <complex.h>
#include <float.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

typedef int (*bi_fn)(lang_ev *V, const ast_node *call, silc_value **a, int n, silc_value **out);

typedef struct bi_entry {
    const char *name;
    int min, max;
    bi_fn fn;              /* generic handlers tell functions apart by name */
} bi_entry;

/* ---- argument helpers -------------------------------------------------------- */

static int oom(lang_ev *V)
{
    return eng_oom(V->E);
}

/* Argument i as an integer >= lo. */
static int int_arg(lang_ev *V, const ast_node *call, silc_value **a, int i, int64_t lo, int64_t *out)
{
    char shape[48], num[40];
    double x;
    if (!val_is_scalar(a[i])) {
        ev_shape(a[i], shape, sizeof shape);
        return eng_error(V->E, "%s: argument %d must be a scalar, got %s", call->name, i + 1, shape);
    }
    x = val_scalar(a[i]);
    if (!(x == floor(x) && x >= (double)lo && x < 9.0e15)) {
        util_fmt_double(num, sizeof num, x);
        if (x == floor(x) && x >= 9.0e15) /* past every exact index: say where the range ends */
            return eng_error(V->E, "%s: argument %d must be an integer below 9e15, got %s", call->name,
                             i + 1, num);
        return eng_error(V->E, "%s: argument %d must be an integer >= %lld, got %s", call->name,
                         i + 1, (long long)lo, num);
    }
    *out = (int64_t)x;
    return 0;
}

static int vector_arg(lang_ev *V, const ast_node *call, silc_value **a, int i)
{
    char shape[48];
    if (a[i]->m == 1 || a[i]->n == 1) return 0;
    ev_shape(a[i], shape, sizeof shape);
    return eng_error(V->E, "%s: argument %d must be a vector, got %s", call->name, i + 1, shape);
}

static int same_shape_args(lang_ev *V, const ast_node *call, silc_value **a, int allow_scalar)
{
    char n0[64], n1[64], s0[48], s1[48];
    if (a[0]->m == a[1]->m && a[0]->n == a[1]->n) return 0;
    if (allow_scalar && (val_is_scalar(a[0]) || val_is_scalar(a[1]))) return 0;
    ev_operand_name(V, call->kids[0], 0, n0, sizeof n0);
    ev_operand_name(V, call->kids[1], 1, n1, sizeof n1);
    ev_shape(a[0], s0, sizeof s0);
    ev_shape(a[1], s1, sizeof s1);
    return eng_error(V->E, "%s needs operands of the same shape%s: %s is %s, %s is %s", call->name,
                     allow_scalar ? " or a scalar" : "", n0, s0, n1, s1);
}

static void call_text(const lang_ev *V, const ast_node *n, char *out, size_t outlen)
{
    size_t len = n->end - n->start;
    if (len >= outlen) len = outlen - 1;
    memcpy(out, V->src + n->start, len);
    out[len] = 0;
}

/* In explain mode, says that the core built this value itself. */
static void note_core(lang_ev *V, const ast_node *call, const silc_value *r)
{
    char what[128], shape[48];
    if (!V->explain || !r) return;
    call_text(V, call, what, sizeof what);
    ev_shape(r, shape, sizeof shape);
    sb_printf(V->explain_out, "  %d. %s: built by the core -> %s %s\n", ++V->explain_step, what,
              shape, val_format_name(r->format));
}

static int run_call(lang_ev *V, const ast_node *call, int op, int sub, silc_value *a,
                    silc_value *b, silc_value **out)
{
    char what[128];
    call_text(V, call, what, sizeof what);
    return ev_run_op(V, op, sub, a, b, 0, 0, what, out);
}

/* ---- structure built by the core --------------------------------------------- */

static int dims(lang_ev *V, const ast_node *call, silc_value **a, int n, int64_t *m, int64_t *k)
{
    if (int_arg(V, call, a, 0, 0, m)) return -1;
    *k = *m;
    return n > 1 ? int_arg(V, call, a, 1, 0, k) : 0;
}

static int bi_fill(lang_ev *V, const ast_node *call, silc_value **a, int n, silc_value **out)
{
    int64_t m, k, i;
    if (dims(V, call, a, n, &m, &k)) return -1;
    if (!(*out = val_dense_new(m, k))) return oom(V);
    if (call->name[0] == 'o')
        for (i = 0; i < m * k; i++) (*out)->val[i] = 1.0;
    note_core(V, call, *out);
    return 0;
}

static int bi_eye(lang_ev *V, const ast_node *call, silc_value **a, int n, silc_value **out)
{
    int64_t m, k, i, d;
    silc_value *r;
    if (dims(V, call, a, n, &m, &k)) return -1;
    d = m < k ? m : k;
    if (!(r = val_csr_new(m, k, d))) return oom(V);
    for (i = 0; i <= m; i++) r->rowptr[i] = i < d ? i : d;
    for (i = 0; i < d; i++) {
        r->colind[i] = i;
        r->val[i] = 1.0;
    }
    val_csr_set_nnz(r, d);
    *out = r;
    note_core(V, call, r);
    return 0;
}

/* xorshift64*: reproducible per context, independent of the C library. */
static double next_uniform(silc_engine *E)
{
    uint64_t x = E->rand_state ? E->rand_state : 0x9E3779B97F4A7C15ull;
    x ^= x >> 12;
    x ^= x << 25;
    x ^= x >> 27;
    E->rand_state = x;
    return (double)((x * 2685821657736338717ull) >> 11) * (1.0 / 9007199254740992.0);
}

static int bi_rand(lang_ev *V, const ast_node *call, silc_value **a, int n, silc_value **out)
{
    int64_t m, k, i;
    if (dims(V, call, a, n, &m, &k)) return -1;
    if (!(*out = val_dense_new(m, k))) return oom(V);
    for (i = 0; i < m * k; i++) (*out)->val[i] = next_uniform(V->E);
    note_core(V, call, *out);
    return 0;
}

static int bi_size(lang_ev *V, const ast_node *call, silc_value **a, int n, silc_value **out)
{
    int64_t d;
    if (n == 1) {
        if (!(*out = val_dense_new(1, 2))) return oom(V);
        (*out)->val[0] = (double)a[0]->m;
        (*out)->val[1] = (double)a[0]->n;
        return 0;
    }
    if (int_arg(V, call, a, 1, 1, &d)) return -1;
    if (d > 2) return eng_error(V->E, "size: dimension must be 1 or 2, got %lld", (long long)d);
    *out = val_scalar_new((double)(d == 1 ? a[0]->m : a[0]->n));
    return *out ? 0 : oom(V);
}

static int bi_count(lang_ev *V, const ast_node *call, silc_value **a, int n, silc_value **out)
{
    double x;
    (void)n;
    if (!strcmp(call->name, "rows")) x = (double)a[0]->m;
    else if (!strcmp(call->name, "cols")) x = (double)a[0]->n;
    else x = (double)val_props_part(a[0], SILC_PROPS_SHAPE)->nnz;
    *out = val_scalar_new(x);
    return *out ? 0 : oom(V);
}

typedef struct triplet {
    int64_t i, j, k; /* k: the entry's place in the arguments, for a stable order */
} triplet;

static int cmp_triplet(const void *pa, const void *pb)
{
    const triplet *a = pa, *b = pb;
    if (a->i != b->i) return a->i < b->i ? -1 : 1;
    if (a->j != b->j) return a->j < b->j ? -1 : 1;
    return (a->k > b->k) - (a->k < b->k);
}

/* What sparse(i, j, v, m, n) learnt of i and j: where each entry lands in
 * the CSR result, and the result's pattern.  Kept on i (an attachment, so
 * it dies with i) for the next call with the same i, j, m and n -- a time
 * loop that assembles the same pattern with new values every step, as the
 * seeds' cloth does -- which then only scatters v: no index checks, no
 * sort.  Values never change in place without a new id, so equal ids mean
 * equal indices. */
#define SPARSE_PLAN_KEY "core.sparse_plan"

typedef struct sparse_plan {
    uint64_t j_id;
    int64_t m, n, len, nnz;
    int64_t *dest;   /* len: the CSR slot of each entry (duplicates share one) */
    silc_index *rowptr; /* m + 1 */
    silc_index *colind; /* nnz */
} sparse_plan;

static void sparse_plan_free(void *p)
{
    sparse_plan *s = p;
    if (!s) return;
    free(s->dest);
    free(s->rowptr);
    free(s->colind);
    free(s);
}

/* The plan for i, j (checked here, with the messages of sparse()). */
static sparse_plan *sparse_plan_make(lang_ev *V, silc_value **a, int64_t m, int64_t n, int64_t len)
{
    sparse_plan *s = calloc(1, sizeof *s);
    triplet *tr = malloc((size_t)(len ? len : 1) * sizeof *tr);
    int64_t k, nnz = 0;
    if (s) {
        s->dest = malloc((size_t)(len ? len : 1) * sizeof *s->dest);
        s->rowptr = calloc((size_t)m + 1, sizeof *s->rowptr);
        s->colind = malloc((size_t)(len ? len : 1) * sizeof *s->colind);
    }
    if (!s || !tr || !s->dest || !s->rowptr || !s->colind) {
        free(tr);
        sparse_plan_free(s);
        oom(V);
        return NULL;
    }
    for (k = 0; k < len; k++) {
        double ii = val_get(a[0], a[0]->m == 1 ? 0 : k, a[0]->m == 1 ? k : 0);
        double jj = val_get(a[1], a[1]->m == 1 ? 0 : k, a[1]->m == 1 ? k : 0);
        char num[40];
        if (!(ii == floor(ii) && ii >= 1 && ii <= (double)m)) {
            util_fmt_double(num, sizeof num, ii);
            eng_error(V->E, "sparse: row index %s (entry %lld) is out of range 1..%lld", num, (long long)k + 1,
                      (long long)m);
            goto fail;
        }
        if (!(jj == floor(jj) && jj >= 1 && jj <= (double)n)) {
            util_fmt_double(num, sizeof num, jj);
            eng_error(V->E, "sparse: column index %s (entry %lld) is out of range 1..%lld", num,
                      (long long)k + 1, (long long)n);
            goto fail;
        }
        tr[k].i = (int64_t)ii - 1;
        tr[k].j = (int64_t)jj - 1;
        tr[k].k = k;
    }
    qsort(tr, (size_t)len, sizeof *tr, cmp_triplet);
    for (k = 0; k < len; k++) {
        if (!(nnz > 0 && tr[k - 1].i == tr[k].i && tr[k - 1].j == tr[k].j)) {
            s->rowptr[tr[k].i + 1]++;
            s->colind[nnz++] = tr[k].j;
        }
        s->dest[tr[k].k] = nnz - 1;
    }
    for (k = 0; k < m; k++) s->rowptr[k + 1] += s->rowptr[k];
    s->j_id = a[1]->id;
    s->m = m, s->n = n, s->len = len, s->nnz = nnz;
    free(tr);
    return s;
fail:
    free(tr);
    sparse_plan_free(s);
    return NULL;
}

/* sparse(i, j, v, m, n): sorted CSR with duplicates summed (in the order
 * they were given, so a reused plan gives the same bits). */
static int sparse_triplets(lang_ev *V, const ast_node *call, silc_value **a, silc_value **out)
{
    int64_t m, n, k, len;
    sparse_plan *s;
    silc_value *r;
    if (vector_arg(V, call, a, 0) || vector_arg(V, call, a, 1) || int_arg(V, call, a, 3, 0, &m) ||
        int_arg(V, call, a, 4, 0, &n))
        return -1;
    len = a[0]->m * a[0]->n;
    if (a[1]->m * a[1]->n != len)
        return eng_error(V->E, "sparse: i has %lld entries but j has %lld", (long long)len,
                         (long long)(a[1]->m * a[1]->n));
    if (!val_is_scalar(a[2]) && a[2]->m * a[2]->n != len)
        return eng_error(V->E, "sparse: i has %lld entries but v has %lld (v may also be a scalar)",
                         (long long)len, (long long)(a[2]->m * a[2]->n));
    s = val_attach_get(a[0], SPARSE_PLAN_KEY);
    if (!s || s->j_id != a[1]->id || s->m != m || s->n != n || s->len != len) {
        /* The plan is as large as the result: refuse both before allocating. */
        char what[96];
        snprintf(what, sizeof what, "a %lldx%lld csr value", (long long)m, (long long)n);
        if (val_claim(((double)m + 1) * sizeof(silc_index) + (double)len * (sizeof(silc_index) + sizeof(double)),
                      what))
            return oom(V);
        if (!(s = sparse_plan_make(V, a, m, n, len))) return -1;
        /* Without room to keep it, this call still uses it. */
        if (val_attach_set(a[0], SPARSE_PLAN_KEY, s, sparse_plan_free)) {
            sparse_plan_free(s);
            return oom(V);
        }
    }
    if (!(r = a[2]->field == SILC_FIELD_COMPLEX ? val_csr_new_complex(m, n, s->nnz) : val_csr_new(m, n, s->nnz)))
        return oom(V);
    memcpy(r->rowptr, s->rowptr, (size_t)(m + 1) * sizeof *r->rowptr);
    memcpy(r->colind, s->colind, (size_t)s->nnz * sizeof *r->colind);
    if (a[2]->field == SILC_FIELD_COMPLEX) { /* complex v: both parts summed (the array is zeroed) */
        for (k = 0; k < len; k++) {
            double complex c = val_get_complex(a[2], val_is_scalar(a[2]) || a[2]->m == 1 ? 0 : k,
                                               val_is_scalar(a[2]) ? 0 : a[2]->m == 1 ? k : 0);
            r->val[2 * s->dest[k]] += creal(c);
            r->val[2 * s->dest[k] + 1] += cimag(c);
        }
    } else if (val_is_scalar(a[2])) {
        memset(r->val, 0, (size_t)s->nnz * sizeof *r->val);
        double c = val_scalar(a[2]);
        for (k = 0; k < len; k++) r->val[s->dest[k]] += c;
    } else {
        memset(r->val, 0, (size_t)s->nnz * sizeof *r->val);
        for (k = 0; k < len; k++) r->val[s->dest[k]] += val_get(a[2], a[2]->m == 1 ? 0 : k, a[2]->m == 1 ? k : 0);
    }
    val_csr_set_nnz(r, s->nnz);
    *out = r;
    note_core(V, call, r);
    return 0;
}

static int bi_sparse(lang_ev *V, const ast_node *call, silc_value **a, int n, silc_value **out)
{
    if (n == 5) return sparse_triplets(V, call, a, out);
    if (n != 1) return eng_error(V->E, "sparse takes 1 or 5 arguments, got %d", n);
    return run_call(V, call, SILC_OP_CONVERT, SILC_FMT_CSR, a[0], NULL, out);
}

static int bi_dense(lang_ev *V, const ast_node *call, silc_value **a, int n, silc_value **out)
{
    (void)n;
    return run_call(V, call, SILC_OP_CONVERT, SILC_FMT_DENSE, a[0], NULL, out);
}

/* Entry k (counted in entries) of v's array val is nonzero, in either part. */
static int entry_nonzero(const silc_value *v, const double *val, int64_t k)
{
    return v->field == SILC_FIELD_COMPLEX ? val[2 * k] != 0 || val[2 * k + 1] != 0 : val[k] != 0;
}

static int bi_band(lang_ev *V, const ast_node *call, silc_value **a, int n, silc_value **out)
{
    silc_call c;
    char what[128];
    int64_t kl, ku, i, j;
    silc_view w;
    (void)n;
    if (int_arg(V, call, a, 1, 0, &kl) || int_arg(V, call, a, 2, 0, &ku)) return -1;
    call_text(V, call, what, sizeof what);
    /* refuse before dispatch: a band value cannot hold an entry outside its band */
    val_view(a[0], &w);
    for (i = 0; i < w.m; i++) {
        if (w.format == SILC_FMT_CSR) {
            int64_t p;
            for (p = w.rowptr[i]; p < w.rowptr[i + 1]; p++) {
                j = w.colind[p];
                if (entry_nonzero(a[0], w.val, p) && (j < i - kl || j > i + ku)) goto outside;
            }
        } else if (w.format == SILC_FMT_DENSE) {
            for (j = 0; j < w.n; j++)
                if ((j < i - kl || j > i + ku) && entry_nonzero(a[0], w.val, i + j * w.m)) goto outside;
        } else {
            for (j = i - w.kl > 0 ? i - w.kl : 0; j <= i + w.ku && j < w.n; j++)
                if ((j < i - kl || j > i + ku) && val_get_complex(a[0], i, j) != 0) goto outside;
        }
    }
    memset(&c, 0, sizeof c);
    c.op = SILC_OP_CONVERT;
    c.sub = SILC_FMT_BAND;
    c.nin = 1;
    c.in[0] = a[0];
    c.ival[0] = kl;
    c.ival[1] = ku;
    return ev_run(V, &c, what, out);
outside:
    return eng_error(V->E, "%s: entry (%lld,%lld) lies outside the band", what, (long long)i + 1,
                     (long long)j + 1);
}

static int bi_diag(lang_ev *V, const ast_node *call, silc_value **a, int n, silc_value **out)
{
    char shape[48];
    (void)n;
    if (call->name[4] == 0 && a[0]->m != 1 && a[0]->n != 1) {
        ev_shape(a[0], shape, sizeof shape);
        return eng_error(V->E, "diag needs a vector, got %s (diagvec(A) gives the diagonal of a matrix)",
                         shape);
    }
    return run_call(V, call, SILC_OP_DIAG, call->name[4] == 0 ? 0 : 1, a[0], NULL, out);
}

static int bi_reduce(lang_ev *V, const ast_node *call, silc_value **a, int n, silc_value **out)
{
    int sub = call->name[0] == 's' ? SILC_RED_SUM : call->name[1] == 'a' ? SILC_RED_MAX : SILC_RED_MIN;
    if (n == 2) {
        if (same_shape_args(V, call, a, 1)) return -1;
        return run_call(V, call, SILC_OP_EWISE, sub == SILC_RED_MAX ? SILC_EW_MAX : SILC_EW_MIN,
                        a[0], a[1], out);
    }
    return run_call(V, call, SILC_OP_REDUCE, sub, a[0], NULL, out);
}

static int bi_dot(lang_ev *V, const ast_node *call, silc_value **a, int n, silc_value **out)
{
    silc_value *x;
    int rc;
    (void)n;
    if (same_shape_args(V, call, a, 0)) return -1;
    if (a[0]->field != SILC_FIELD_COMPLEX) return run_call(V, call, SILC_OP_REDUCE, SILC_RED_DOT, a[0], a[1], out);
    /* Octave's dot conjugates its first argument: sum(conj(x) .* y) */
    if (run_call(V, call, SILC_OP_MAP, SILC_MAP_CONJ, a[0], NULL, &x)) return -1;
    rc = run_call(V, call, SILC_OP_REDUCE, SILC_RED_DOT, x, a[1], out);
    val_release(x);
    return rc;
}

static int bi_norm(lang_ev *V, const ast_node *call, silc_value **a, int n, silc_value **out)
{
    int sub = SILC_RED_NORM;
    if (n == 2) {
        const ast_node *p = call->kids[1];
        if (p->kind == AST_STRING) {
            if (!strcmp(p->name, "fro")) sub = SILC_RED_NORMFRO;
            else if (!strcmp(p->name, "inf")) sub = SILC_RED_NORMINF;
            else sub = -1;
        } else if (val_is_scalar(a[1])) {
            double x = val_scalar(a[1]);
            sub = x == 1 ? SILC_RED_NORM1 : x == 2 ? SILC_RED_NORM : isinf(x) && x > 0 ? SILC_RED_NORMINF : -1;
        } else {
            sub = -1;
        }
        if (sub < 0) return eng_error(V->E, "norm: p must be 1, 2, inf or \"fro\"");
    }
    return run_call(V, call, SILC_OP_REDUCE, sub, a[0], NULL, out);
}

/* 1 when a stored entry of the real value v is < 0. */
static int has_negative(const silc_value *v)
{
    for (int64_t k = 0; k < v->nnz; k++)
        if (v->val[k] < 0) return 1;
    return 0;
}

/* complex(a, b): a + bi from real a and b of one shape (or a scalar), built
 * by the core: exactly the parts given (no arithmetic, so complex(1, -0)
 * keeps its -0). */
static int bi_complex(lang_ev *V, const ast_node *call, silc_value **a, int n, silc_value **out)
{
    int64_t m, k, i, j;
    (void)n;
    if (a[0]->field == SILC_FIELD_COMPLEX || a[1]->field == SILC_FIELD_COMPLEX)
        return eng_error(V->E, "complex: the arguments must be real (argument %d is complex)",
                         a[0]->field == SILC_FIELD_COMPLEX ? 1 : 2);
    if (same_shape_args(V, call, a, 1)) return -1;
    if ((*out = val_complex_of_parts(a[0], a[1]))) {
        note_core(V, call, *out);
        return 0;
    }
    /* different formats or patterns, or a scalar with a matrix: dense */
    m = val_is_scalar(a[0]) ? a[1]->m : a[0]->m;
    k = val_is_scalar(a[0]) ? a[1]->n : a[0]->n;
    if (!(*out = val_dense_new_complex(m, k))) return oom(V);
    for (j = 0; j < k; j++)
        for (i = 0; i < m; i++) {
            (*out)->val[2 * (i + j * m)] = val_is_scalar(a[0]) ? val_scalar(a[0]) : val_get(a[0], i, j);
            (*out)->val[2 * (i + j * m) + 1] = val_is_scalar(a[1]) ? val_scalar(a[1]) : val_get(a[1], i, j);
        }
    note_core(V, call, *out);
    return 0;
}

/* isreal(x): 1 for a real value.  A complex value stays complex when its
 * imaginary parts are 0 (SILC demotes only on request: real(x)). */
static int bi_isreal(lang_ev *V, const ast_node *call, silc_value **a, int n, silc_value **out)
{
    (void)call;
    (void)n;
    *out = val_scalar_new(a[0]->field == SILC_FIELD_REAL);
    return *out ? 0 : oom(V);
}

static int bi_map(lang_ev *V, const ast_node *call, silc_value **a, int n, silc_value **out)
{
    static const struct { const char *name; int sub; } maps[] = {
        {"abs", SILC_MAP_ABS},   {"sqrt", SILC_MAP_SQRT}, {"exp", SILC_MAP_EXP},   {"log", SILC_MAP_LOG},
        {"sin", SILC_MAP_SIN},   {"cos", SILC_MAP_COS},   {"real", SILC_MAP_REAL}, {"imag", SILC_MAP_IMAG},
        {"conj", SILC_MAP_CONJ}, {"angle", SILC_MAP_ANGLE}};
    size_t i;
    silc_value *z;
    int rc;
    (void)n;
    for (i = 0; i < sizeof maps / sizeof maps[0]; i++)
        if (!strcmp(call->name, maps[i].name)) break;
    /* sqrt(-1) and log(-1) are complex, as in Octave: a real operand with a
     * negative entry is promoted first (the map keeps its operand's field) */
    if ((maps[i].sub == SILC_MAP_SQRT || maps[i].sub == SILC_MAP_LOG) && a[0]->field == SILC_FIELD_REAL &&
        has_negative(a[0])) {
        if (!(z = val_promote(a[0]))) return oom(V);
        rc = run_call(V, call, SILC_OP_MAP, maps[i].sub, z, NULL, out);
        val_release(z);
        return rc;
    }
    return run_call(V, call, SILC_OP_MAP, maps[i].sub, a[0], NULL, out);
}

static int bi_trans(lang_ev *V, const ast_node *call, silc_value **a, int n, silc_value **out)
{
    (void)n;
    return run_call(V, call, SILC_OP_TRANSPOSE, 0, a[0], NULL, out);
}

static int bi_solve(lang_ev *V, const ast_node *call, silc_value **a, int n, silc_value **out)
{
    silc_call c;
    char what[128], n0[64], n1[64], s0[48], s1[48];
    const char *opts = NULL;
    int rc;
    if (a[0]->m != a[1]->m) {
        ev_operand_name(V, call->kids[0], 0, n0, sizeof n0);
        ev_operand_name(V, call->kids[1], 1, n1, sizeof n1);
        ev_shape(a[0], s0, sizeof s0);
        ev_shape(a[1], s1, sizeof s1);
        return eng_error(V->E, "solve needs as many rows in the right-hand side: %s is %s, %s is %s",
                         n0, s0, n1, s1);
    }
    if (n == 3) {
        if (call->kids[2]->kind != AST_STRING)
            return eng_error(V->E, "solve: argument 3 must be an option string such as \"backend = reference\"");
        opts = call->kids[2]->name;
        if (cfg_set_call_options(V->E, opts)) {
            cfg_clear_call_options(V->E);
            return -1;
        }
    }
    memset(&c, 0, sizeof c);
    c.op = SILC_OP_SOLVE;
    c.nin = 2;
    c.in[0] = a[0];
    c.in[1] = a[1];
    c.options = opts;
    call_text(V, call, what, sizeof what);
    V->solve_matrix = call->kids[0];
    rc = ev_run(V, &c, what, out);
    V->solve_matrix = NULL;
    if (opts) cfg_clear_call_options(V->E);
    return rc;
}

static const bi_entry table[] = {
    {"zeros", 1, 2, bi_fill},   {"ones", 1, 2, bi_fill},     {"eye", 1, 2, bi_eye},
    {"rand", 1, 2, bi_rand},    {"size", 1, 2, bi_size},     {"rows", 1, 1, bi_count},
    {"cols", 1, 1, bi_count},   {"nnz", 1, 1, bi_count},     {"sparse", 1, 5, bi_sparse},
    {"dense", 1, 1, bi_dense},  {"band", 3, 3, bi_band},     {"diag", 1, 1, bi_diag},
    {"diagvec", 1, 1, bi_diag}, {"sum", 1, 1, bi_reduce},    {"max", 1, 2, bi_reduce},
    {"min", 1, 2, bi_reduce},   {"dot", 2, 2, bi_dot},       {"norm", 1, 2, bi_norm},
    {"abs", 1, 1, bi_map},      {"sqrt", 1, 1, bi_map},      {"exp", 1, 1, bi_map},
    {"log", 1, 1, bi_map},      {"sin", 1, 1, bi_map},       {"cos", 1, 1, bi_map},
    {"trans", 1, 1, bi_trans},  {"solve", 2, 3, bi_solve},
    {"real", 1, 1, bi_map},     {"imag", 1, 1, bi_map},      {"conj", 1, 1, bi_map},
    {"angle", 1, 1, bi_map},    {"complex", 2, 2, bi_complex}, {"isreal", 1, 1, bi_isreal},
};
#define NTABLE (sizeof table / sizeof table[0])

const char *const bi_names[] = {
    "zeros", "ones", "eye", "rand", "size", "rows", "cols", "nnz", "sparse", "dense", "band",
    "diag", "diagvec", "sum", "max", "min", "dot", "norm", "abs", "sqrt", "exp", "log", "sin",
    "cos", "trans", "solve", "real", "imag", "conj", "angle", "complex", "isreal", "disp", "pi", "inf", "nan",
    "eps", "Inf", "NaN", "i", "j", NULL};

static const bi_entry *lookup(const char *name)
{
    size_t i;
    for (i = 0; i < NTABLE; i++)
        if (!strcmp(table[i].name, name)) return &table[i];
    return NULL;
}

int bi_is_function(const char *name)
{
    return lookup(name) != NULL;
}

int bi_constant(const char *name, double *x)
{
    if (!strcmp(name, "pi")) *x = 3.14159265358979323846;
    else if (!strcmp(name, "inf") || !strcmp(name, "Inf")) *x = INFINITY;   /* Octave spells both */
    else if (!strcmp(name, "nan") || !strcmp(name, "NaN")) *x = NAN;
    else if (!strcmp(name, "eps")) *x = DBL_EPSILON;
    else return 0;
    return 1;
}

static int unknown_function(lang_ev *V, const char *name)
{
    const char *fn[NTABLE], *best;
    size_t i;
    if (!strcmp(name, "disp"))   /* eval.c runs disp(x) as a statement */
        return eng_error(V->E, "disp(x) shows x and has no value: write it as a statement of its own");
    for (i = 0; i < NTABLE; i++) fn[i] = table[i].name;
    best = util_closest(name, fn, NTABLE);
    if (best) return eng_error(V->E, "unknown function '%s' (did you mean '%s'?)", name, best);
    return eng_error(V->E, "unknown function '%s'", name);
}

/* Builtins that only read their arguments' shapes and properties or hand
 * them to ev_run: they take distributed values as they are (dist.h); the
 * others read entries, and get whole copies. */
static int takes_distributed(const char *name)
{
    static const char *const names[] = {"size", "rows", "cols", "nnz", "sum", "max", "min", "dot",
                                        "norm", "abs", "sqrt", "exp", "log", "sin", "cos", "trans",
                                        "solve", NULL};
    int i;
    for (i = 0; names[i]; i++)
        if (!strcmp(names[i], name)) return 1;
    return 0;
}

int bi_call(lang_ev *V, const ast_node *call, silc_value **out)
{
    const bi_entry *f = lookup(call->name);
    silc_value *args[5] = {NULL, NULL, NULL, NULL, NULL};
    int n = (int)call->nkids, i, rc = -1;
    *out = NULL;
    if (!f) return unknown_function(V, call->name);
    if (n < f->min || n > f->max) {
        if (!strcmp(f->name, "sparse"))
            return eng_error(V->E, "sparse takes 1 or 5 arguments, got %d", n);
        if (f->min == f->max)
            return eng_error(V->E, "%s takes %d argument%s, got %d", f->name, f->min,
                             f->min == 1 ? "" : "s", n);
        return eng_error(V->E, "%s takes %d or %d arguments, got %d", f->name, f->min, f->max, n);
    }
    if (f->fn == bi_diag && call->name[4] && !V->E->dist && ev_is_diagvec_of_product(call))
        return ev_diagvec_of_product(V, call, out);
    for (i = 0; i < n; i++) {
        const ast_node *k = call->kids[i];
        if (k->kind == AST_STRING) {
            int option_slot = (!strcmp(f->name, "norm") && i == 1) || (!strcmp(f->name, "solve") && i == 2);
            if (!option_slot) {
                eng_error(V->E, "%s: argument %d must be a matrix, not a string", f->name, i + 1);
                goto done;
            }
            continue;
        }
        if ((takes_distributed(f->name) ? ev_expr_dist : ev_expr)(V, k, &args[i])) goto done;
    }
    /* option strings stay NULL in args: their handlers read them from the node */
    rc = f->fn(V, call, args, n, out);
done:
    for (i = 0; i < n; i++) val_release(args[i]);
    return rc;
}

silc_value *bi_to_csr(const silc_value *a)
{
    silc_value *r;
    int64_t i, j, nnz = 0, cap;
    int w = val_width(a); /* a complex value's entries are 2 doubles */
    if (a->format == SILC_FMT_CSR) {
        r = val_new_unset_field(SILC_FMT_CSR, a->field, a->m, a->n, a->rowptr[a->m], 0, 0);
        if (!r) return NULL;
        memcpy(r->rowptr, a->rowptr, (size_t)(a->m + 1) * sizeof *r->rowptr);
        memcpy(r->colind, a->colind, (size_t)a->rowptr[a->m] * sizeof *r->colind);
        memcpy(r->val, a->val, (size_t)(a->rowptr[a->m] * w) * sizeof *r->val);
        val_csr_set_nnz(r, a->rowptr[a->m]);
        return r;
    }
    cap = (int64_t)val_props_part(a, SILC_PROPS_SHAPE)->nnz;
    r = a->field == SILC_FIELD_COMPLEX ? val_csr_new_complex(a->m, a->n, cap) : val_csr_new(a->m, a->n, cap);
    if (!r) return NULL;
    for (i = 0; i < a->m; i++) {
        int64_t lo = 0, hi = a->n - 1;
        if (a->format == SILC_FMT_BAND) {
            lo = i - a->kl > 0 ? i - a->kl : 0;
            hi = i + a->ku < a->n - 1 ? i + a->ku : a->n - 1;
        }
        r->rowptr[i] = nnz;
        for (j = lo; j <= hi; j++) {
            double complex x = val_get_complex(a, i, j);
            if (x != 0 && nnz < cap) {
                r->colind[nnz] = j;
                r->val[nnz * w] = creal(x);
                if (w == 2) r->val[nnz * w + 1] = cimag(x);
                nnz++;
            }
        }
    }
    r->rowptr[a->m] = nnz;
    val_csr_set_nnz(r, nnz);
    return r;
}
