/*
 * index.c -- subscripts: A[i, j], v[k] (linear, column-major, on any matrix),
 * and the same as Octave writes them, A(i, j), v(k), on a variable (eval.c
 * tells them from calls); ranges a:b, ':' alone, `end`, index vectors and
 * masks (a comparison or logical expression: v(v > 0)); extraction and
 * assignment into a block.  A bad subscript is reported in Octave's words
 * ("v(7): out of bound 5 (dimensions are 1x5)").
 *
 * Subscripts are 1-based in the language and 0-based here once resolved.
 * Extraction keeps the storage family: dense gives dense, CSR gives CSR (with
 * a row-wise fast path), band gives dense (a block of a band matrix is rarely
 * banded about its own diagonal); a 1x1 result is always a dense scalar.
 * Assignment builds a new value and never touches the old one, which may be
 * shared: dense stays dense, CSR is rebuilt as CSR (assigned zeros are not
 * stored), band stays band while the new entries fit, else becomes CSR.
 */
#include "lang.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

typedef struct ix_list {
    int64_t *ix;           /* 0-based */
    int64_t n;
    int row;               /* the subscript is row-shaped (a range, a 1xk value or mask) */
} ix_list;

static int oom(lang_ev *V)
{
    return eng_oom(V->E);
}

/* Octave's wording of a bad subscript: "v(7): out of bound 5 (dimensions
 * are 1x5)", "A(4,_): ..." for a row, "A(_,7): ..." for a column.  pos: 0
 * a linear subscript, 1 a row, 2 a column; what is the operand's quoted
 * name or text ('v'), or a phrase. */
static int bad_index(lang_ev *V, double x, int64_t extent, int pos, const char *what,
                     const silc_value *base)
{
    char num[40], shape[48], name[64], at[48];
    size_t len = strlen(what);
    util_fmt_double(num, sizeof num, x);
    ev_shape(base, shape, sizeof shape);
    if (len >= 2 && what[0] == '\'' && what[len - 1] == '\'')
        snprintf(name, sizeof name, "%.*s", (int)(len - 2), what + 1);
    else
        snprintf(name, sizeof name, "index ");
    snprintf(at, sizeof at, "%s%s%s", pos == 2 ? "_," : "", num, pos == 1 ? ",_" : "");
    if (x != floor(x) || !(x >= 1))
        return eng_error(V->E, "%s(%s): subscripts must be integers from 1 up (%s is %s)", name, at, what,
                         shape);
    return eng_error(V->E, "%s(%s): out of bound %lld (dimensions are %s)", name, at, (long long)extent,
                     shape);
}

/* limit: the largest index taken -- the extent, or for an assignment that
 * may grow its target (Octave's v(end+1) = x), GROW_LIMIT. */
static int push_index(lang_ev *V, ix_list *l, double x, int64_t extent, int64_t limit, int pos,
                      const char *what, const silc_value *base)
{
    if (!(x >= 1 && x <= (double)limit) || x != floor(x)) return bad_index(V, x, extent, pos, what, base);
    l->ix[l->n++] = (int64_t)x - 1;
    return 0;
}

/* A subscript whose value is a mask rather than a list of indices: a
 * comparison or a logical operation (v(v > 0), A(:, !(c == 0))).  Values
 * have no logical type, so the form of the expression decides. */
static int is_mask(const ast_node *sub)
{
    if (sub->kind == AST_UNARY) return sub->op == TK_NOT;
    if (sub->kind != AST_BINARY) return 0;
    switch (sub->op) {
    case TK_EQ: case TK_NE: case TK_LT: case TK_LE: case TK_GT: case TK_GE: case TK_AND: case TK_OR:
        return 1;
    default:
        return 0;
    }
}

static int range_end(lang_ev *V, const ast_node *n, double *x)
{
    silc_value *v;
    char shape[48];
    if (ev_expr(V, n, &v)) return -1;
    if (!val_is_scalar(v)) {
        ev_shape(v, shape, sizeof shape);
        val_release(v);
        return eng_error(V->E, "a range a:b needs scalar ends, got %s", shape);
    }
    *x = val_scalar(v);
    val_release(v);
    if (!isfinite(*x)) return eng_error(V->E, "a range a:b needs finite ends");
    return 0;
}

/* The list of count indices of one subscript, held to the limit of one
 * value: `:` over a wide sparse value (eye(2, 1e12)[1, :]) or a sparse
 * subscript (S[S]) would otherwise ask malloc for terabytes (found by
 * fuzz_lang).  NULL with E->err set. */
static int64_t *ix_alloc(lang_ev *V, int64_t count)
{
    int64_t *ix = NULL;
    if (count < 1) count = 1;
    if (val_claim((double)count * sizeof *ix, "the subscript's index list") ||
        !(ix = malloc((size_t)count * sizeof *ix)))
        oom(V);
    return ix;
}

/* The largest index an assignment may grow its target to: far past any
 * value the limits allow (the grown value is claimed like any other, and
 * refused with the limit's message), and small enough that index + 1 and
 * the product of two dimensions stay exact in a double. */
#define GROW_LIMIT ((int64_t)1 << 48)

/* Resolves one subscript against a dimension of the given extent (pos as
 * bad_index's).  grow: indices past the extent are taken (an assignment
 * that grows its target), except from a mask, which selects among the
 * entries there are. */
static int resolve(lang_ev *V, const ast_node *sub, int64_t extent, int grow, int pos, const char *what,
                   const silc_value *base, ix_list *out)
{
    int64_t saved_end = V->end_value, k, limit = grow && !is_mask(sub) ? GROW_LIMIT : extent;
    int rc = 0;
    out->ix = NULL;
    out->n = 0;
    out->row = sub->kind == AST_RANGE;
    V->end_value = extent;
    V->in_subscript++;
    if (sub->kind == AST_COLON_ALL) {
        if (!(out->ix = ix_alloc(V, extent))) rc = -1;
        for (k = 0; !rc && k < extent; k++) out->ix[out->n++] = k;
    } else if (sub->kind == AST_RANGE && sub->nkids == 2) {   /* a:s:b is a value like any other */
        double a, b, x;
        if (range_end(V, sub->kids[0], &a) || range_end(V, sub->kids[1], &b)) {
            rc = -1;
        } else {
            /* counted as a double: the count of 1:1e84 does not fit int64_t */
            double span = b >= a ? floor(b - a) + 1 : 0;
            int64_t cnt = span > (double)limit ? limit + 1 : (int64_t)span;
            if (cnt > limit) {
                /* some index must be out of range: report the first without
                 * allocating for a range that may be huge */
                double bad = a < 1 || a != floor(a) || a > (double)limit ? a : (double)limit + 1;
                int64_t one;
                out->ix = &one;
                rc = push_index(V, out, bad, extent, limit, pos, what, base);
                out->ix = NULL;
            } else {
                if (!(out->ix = ix_alloc(V, cnt))) rc = -1;
                for (x = a, k = 0; !rc && k < cnt; k++, x += 1.0)
                    rc = push_index(V, out, x, extent, limit, pos, what, base);
            }
        }
    } else {
        silc_value *v;
        if (ev_expr(V, sub, &v)) {
            rc = -1;
        } else if ((out->row = v->m == 1 && v->n != 1), is_mask(sub)) {
            /* the positions of its nonzeros; a mask longer than the
             * dimension may only hold zeros past it, as in Octave */
            int64_t cnt = v->m * v->n;
            if (!(out->ix = ix_alloc(V, cnt < extent ? cnt : extent))) rc = -1;
            for (k = 0; !rc && k < cnt; k++)
                if (val_get(v, k % v->m, k / v->m) != 0)
                    rc = push_index(V, out, (double)k + 1, extent, limit, pos, what, base);
            val_release(v);
        } else {
            int64_t cnt = v->m * v->n;
            if (!(out->ix = ix_alloc(V, cnt))) rc = -1;
            for (k = 0; !rc && k < cnt; k++)
                rc = push_index(V, out, val_get(v, k % v->m, k / v->m), extent, limit, pos, what, base);
            val_release(v);
        }
    }
    V->in_subscript--;
    V->end_value = saved_end;
    if (rc) {
        free(out->ix);
        out->ix = NULL;
    }
    return rc;
}

/* Resolves the subscripts: one (linear) or two (row, column); grow as
 * resolve's. */
static int resolve_all(lang_ev *V, ast_node *const *subs, size_t nsubs, int grow, const char *what,
                       const silc_value *base, ix_list *I, ix_list *J)
{
    I->ix = J->ix = NULL;
    I->n = J->n = 0;
    if (nsubs == 0 || nsubs > 2)
        return eng_error(V->E, "%s takes 1 or 2 subscripts, got %zu", what, nsubs);
    if (nsubs == 1) return resolve(V, subs[0], base->m * base->n, grow, 0, what, base, I);
    if (resolve(V, subs[0], base->m, grow, 1, what, base, I)) return -1;
    if (resolve(V, subs[1], base->n, grow, 2, what, base, J)) {
        free(I->ix);
        I->ix = NULL;
        return -1;
    }
    return 0;
}

/* Position of column j in CSR row i, or -1. */
static int64_t csr_find(const silc_value *a, int64_t i, int64_t j)
{
    int64_t lo = a->rowptr[i], hi = a->rowptr[i + 1] - 1;
    while (lo <= hi) {
        int64_t mid = lo + (hi - lo) / 2;
        if (a->colind[mid] == j) return mid;
        if (a->colind[mid] < j) lo = mid + 1;
        else hi = mid - 1;
    }
    return -1;
}

static silc_value *extract_csr(const silc_value *a, const ix_list *I, const ix_list *J)
{
    int64_t r, k, nnz = 0, cap = 0;
    int all = J->n == a->n;
    silc_value *out;
    for (k = 0; all && k < J->n; k++) all = J->ix[k] == k;
    for (r = 0; r < I->n; r++) {
        int64_t i = I->ix[r], len = a->rowptr[i + 1] - a->rowptr[i];
        cap += all ? len : (len < J->n ? len : J->n);
    }
    out = val_csr_new(I->n, J->n, cap);
    if (!out) return NULL;
    for (r = 0; r < I->n; r++) {
        int64_t i = I->ix[r], p;
        out->rowptr[r] = nnz;
        if (all) {
            for (p = a->rowptr[i]; p < a->rowptr[i + 1]; p++) {
                out->colind[nnz] = a->colind[p];
                out->val[nnz++] = a->val[p];
            }
        } else {
            for (k = 0; k < J->n && nnz < cap; k++) {
                p = csr_find(a, i, J->ix[k]);
                if (p >= 0) {
                    out->colind[nnz] = k;
                    out->val[nnz++] = a->val[p];
                }
            }
        }
    }
    out->rowptr[I->n] = nnz;
    val_csr_set_nnz(out, nnz);
    return out;
}

/* Complex values are subscripted part by part: the real parts, then the
 * imaginary parts, by the same real code, and the two results joined (one
 * format and shape; a sparse assignment may leave the parts different
 * patterns, joined as their union).  A failed join is reported, never a
 * half value. */
static int ix_extract_real(lang_ev *V, ast_node *const *subs, size_t nsubs, const char *what,
                           const silc_value *base, silc_value **out);
static int ix_assign_real(lang_ev *V, ast_node *const *subs, size_t nsubs, const char *what,
                          const silc_value *target, const silc_value *rhs, silc_value **out);

static int join_parts(lang_ev *V, const char *what, silc_value *re, silc_value *im, silc_value **out)
{
    *out = val_complex_of_parts(re, im);
    val_release(re);
    val_release(im);
    if (*out) return 0;
    if (*val_refusal()) return eng_error(V->E, "%s", val_refusal());
    return eng_error(V->E, "%s: out of memory joining the parts of a subscripted complex value", what);
}

int ix_extract(lang_ev *V, ast_node *const *subs, size_t nsubs, const char *what,
               const silc_value *base, silc_value **out)
{
    silc_value *part[2] = {NULL, NULL}, *got[2] = {NULL, NULL};
    int k, rc = 0;
    if (base->field != SILC_FIELD_COMPLEX) return ix_extract_real(V, subs, nsubs, what, base, out);
    *out = NULL;
    for (k = 0; k < 2 && !rc; k++) {
        if (!(part[k] = val_part(base, k))) rc = eng_oom(V->E);
        else rc = ix_extract_real(V, subs, nsubs, what, part[k], &got[k]);
    }
    val_release(part[0]);
    val_release(part[1]);
    if (rc) {
        val_release(got[0]);
        val_release(got[1]);
        return -1;
    }
    return join_parts(V, what, got[0], got[1], out);
}

int ix_assign(lang_ev *V, ast_node *const *subs, size_t nsubs, const char *what,
              const silc_value *target, const silc_value *rhs, silc_value **out)
{
    silc_value *tp[2] = {NULL, NULL}, *rp[2] = {NULL, NULL}, *got[2] = {NULL, NULL};
    int k, rc = 0;
    if (target->field != SILC_FIELD_COMPLEX && rhs->field != SILC_FIELD_COMPLEX)
        return ix_assign_real(V, subs, nsubs, what, target, rhs, out);
    /* a complex right-hand side makes the target complex (promoted) */
    *out = NULL;
    for (k = 0; k < 2 && !rc; k++) {
        if (!(tp[k] = val_part(target, k)) || !(rp[k] = val_part(rhs, k))) rc = eng_oom(V->E);
        else rc = ix_assign_real(V, subs, nsubs, what, tp[k], rp[k], &got[k]);
    }
    for (k = 0; k < 2; k++) val_release(tp[k]), val_release(rp[k]);
    if (rc) {
        val_release(got[0]);
        val_release(got[1]);
        return -1;
    }
    return join_parts(V, what, got[0], got[1], out);
}

static int ix_extract_real(lang_ev *V, ast_node *const *subs, size_t nsubs, const char *what,
                           const silc_value *base, silc_value **out)
{
    ix_list I, J;
    silc_value *r = NULL;
    int64_t a, b, m = base->m;
    *out = NULL;
    if (resolve_all(V, subs, nsubs, 0, what, base, &I, &J)) return -1;
    if (nsubs == 1) {
        /* linear, as Octave: v(:) is a column, a vector keeps its
         * orientation, a matrix takes the subscript's (a column for a
         * matrix of indices) */
        int vector = base->m == 1 || base->n == 1;
        int row = subs[0]->kind == AST_COLON_ALL ? 0 : vector ? base->m == 1 && base->n != 1 : I.row;
        r = val_dense_new(row ? 1 : I.n, row ? I.n : 1);
        if (r)
            for (a = 0; a < I.n; a++) r->val[a] = val_get(base, I.ix[a] % m, I.ix[a] / m);
        if (r && base->format == SILC_FMT_CSR && r->m * r->n != 1) {
            silc_value *c = bi_to_csr(r);
            val_release(r);
            r = c;
        }
    } else if (base->format == SILC_FMT_CSR && !(I.n == 1 && J.n == 1)) {
        r = extract_csr(base, &I, &J);
    } else {
        r = val_dense_new(I.n, J.n);
        if (r && base->format == SILC_FMT_DENSE) {
            for (b = 0; b < J.n; b++) {
                const double *col = base->val + J.ix[b] * m;
                for (a = 0; a < I.n; a++) r->val[a + b * I.n] = col[I.ix[a]];
            }
        } else if (r) {
            for (b = 0; b < J.n; b++)
                for (a = 0; a < I.n; a++) r->val[a + b * I.n] = val_get(base, I.ix[a], J.ix[b]);
        }
    }
    free(I.ix);
    free(J.ix);
    if (!r) return oom(V);
    *out = r;
    return 0;
}

/* ---- assignment ----------------------------------------------------------------- */

typedef struct ix_entry {
    int64_t i, j, order;
    double v;
} ix_entry;

static int cmp_entry(const void *pa, const void *pb)
{
    const ix_entry *a = pa, *b = pb;
    if (a->i != b->i) return a->i < b->i ? -1 : 1;
    if (a->j != b->j) return a->j < b->j ? -1 : 1;
    return a->order < b->order ? -1 : a->order > b->order;
}

/* Merges sorted, deduplicated entries into a CSR copy of c. */
static silc_value *csr_merge(const silc_value *c, const ix_entry *e, int64_t ne)
{
    int64_t i, q = 0, nnz = 0, cap = c->rowptr[c->m] + ne;
    silc_value *r = val_csr_new(c->m, c->n, cap);
    if (!r) return NULL;
    for (i = 0; i < c->m; i++) {
        int64_t p = c->rowptr[i], pe = c->rowptr[i + 1];
        r->rowptr[i] = nnz;
        while (p < pe || (q < ne && e[q].i == i)) {
            int take_new = q < ne && e[q].i == i && (p >= pe || e[q].j <= c->colind[p]);
            if (take_new) {
                if (p < pe && c->colind[p] == e[q].j) p++;   /* replaced */
                if (e[q].v != 0) {
                    r->colind[nnz] = e[q].j;
                    r->val[nnz++] = e[q].v;
                }
                q++;
            } else {
                r->colind[nnz] = c->colind[p];
                r->val[nnz++] = c->val[p++];
            }
        }
    }
    r->rowptr[c->m] = nnz;
    val_csr_set_nnz(r, nnz);
    return r;
}

static silc_value *copy_value(const silc_value *t)
{
    silc_value *r;
    if (t->format == SILC_FMT_DENSE) r = val_dense_new(t->m, t->n);
    else r = val_band_new(t->m, t->n, t->kl, t->ku);
    if (r) memcpy(r->val, t->val, (size_t)t->nnz * sizeof *r->val);
    return r;
}

/* t with m rows and n columns, its entries where they were and zeros in
 * the new places: dense stays dense, CSR and band become CSR (a grown band
 * is rarely banded about its new diagonal).  NULL when out of memory or
 * past the limits (val_refusal says which). */
static silc_value *resized(const silc_value *t, int64_t m, int64_t n)
{
    int64_t i, j, rows = t->m < m ? t->m : m, cols = t->n < n ? t->n : n;
    silc_value *r, *c;
    if (t->format == SILC_FMT_DENSE) {
        if (!(r = val_dense_new(m, n))) return NULL;
        for (j = 0; j < cols; j++)
            for (i = 0; i < rows; i++) r->val[i + j * m] = t->val[i + j * t->m];
        return r;
    }
    c = t->format == SILC_FMT_CSR ? NULL : bi_to_csr(t);
    if (t->format != SILC_FMT_CSR && !c) return NULL;
    if (c) t = c;
    /* rows past the old ones are empty; the old columns all fit, since a
     * grown CSR never loses columns that hold entries (a 0xN one has none) */
    r = val_csr_new(m, n, t->rowptr[t->m]);
    if (r) {
        for (i = 0; i <= m; i++) r->rowptr[i] = t->rowptr[i < t->m ? i : t->m];
        for (i = 0; i < t->rowptr[t->m]; i++) r->colind[i] = t->colind[i], r->val[i] = t->val[i];
        val_csr_set_nnz(r, t->rowptr[t->m]);
    }
    val_release(c);
    return r;
}

/* Octave's growth by assignment: a subscript past the end grows the
 * target, zero-filled -- both dimensions as far as the largest row and
 * column subscripts reach; with one (linear) subscript, a 0x0, 1x1, row or
 * 0xN value becomes a row and a column stays a column, while a matrix is
 * refused (which way it should grow is ambiguous, as Octave says).
 * *grown: the grown copy, or NULL when every subscript is inside. */
static int grow_target(lang_ev *V, size_t nsubs, const ix_list *I, const ix_list *J, const char *what,
                       const silc_value *t, silc_value **grown)
{
    int64_t k, mi = -1, mj = -1, m = t->m, n = t->n;
    size_t len = strlen(what);
    *grown = NULL;
    for (k = 0; k < I->n; k++)
        if (I->ix[k] > mi) mi = I->ix[k];
    if (nsubs == 1) {
        if (mi < m * n) return 0;
        if (m == 0 || m == 1) {
            m = 1;
            n = mi + 1;
        } else if (n == 1) {
            m = mi + 1;
        } else {
            int quoted = len >= 2 && what[0] == '\'' && what[len - 1] == '\'';
            return eng_error(V->E,
                             "%.*s(%lld): out of bound %lld (dimensions are %lldx%lld): a matrix grows by "
                             "assignment only with two subscripts, A(i, j) = x (Octave: invalid resizing "
                             "operation or ambiguous assignment to an out-of-bounds array element)",
                             quoted ? (int)len - 2 : (int)len, what + quoted, (long long)mi + 1,
                             (long long)(m * n), (long long)m, (long long)n);
        }
    } else {
        for (k = 0; k < J->n; k++)
            if (J->ix[k] > mj) mj = J->ix[k];
        if (mi < m && mj < n) return 0;
        if (mi >= m) m = mi + 1;
        if (mj >= n) n = mj + 1;
    }
    if (!(*grown = resized(t, m, n))) return oom(V);
    return 0;
}

static int ix_assign_real(lang_ev *V, ast_node *const *subs, size_t nsubs, const char *what,
                          const silc_value *target, const silc_value *rhs, silc_value **out)
{
    ix_list I, J;
    ix_entry *e = NULL;
    int64_t ne, k, a, b, m;
    int scalar = val_is_scalar(rhs), inband = 1;
    silc_value *r = NULL, *grown = NULL;
    char s0[48], s1[48];
    *out = NULL;
    if (resolve_all(V, subs, nsubs, 1, what, target, &I, &J)) return -1;
    ne = nsubs == 1 ? I.n : I.n * J.n;
    if (!scalar) {
        int ok = nsubs == 1 ? rhs->m * rhs->n == I.n && (rhs->m == 1 || rhs->n == 1)
                            : rhs->m == I.n && rhs->n == J.n;
        if (!ok) {
            ev_shape(rhs, s0, sizeof s0);
            if (nsubs == 1)
                snprintf(s1, sizeof s1, "%lld elements", (long long)I.n);
            else
                snprintf(s1, sizeof s1, "a %lldx%lld block", (long long)I.n, (long long)J.n);
            free(I.ix);
            free(J.ix);
            return eng_error(V->E, "cannot assign a %s value to %s of %s", s0, s1, what);
        }
    }
    if (grow_target(V, nsubs, &I, &J, what, target, &grown)) {
        free(I.ix);
        free(J.ix);
        return -1;
    }
    if (grown) target = grown;
    m = target->m;
    /* I.n * J.n entries: each list fits (ix_alloc), their product may not */
    if (val_claim((double)(ne ? ne : 1) * sizeof *e, "the assigned block")) goto nomem;
    e = malloc((size_t)(ne ? ne : 1) * sizeof *e);
    if (!e) goto nomem;
    for (k = 0; k < ne; k++) {
        if (nsubs == 1) {
            a = I.ix[k] % m;
            b = I.ix[k] / m;
            e[k].v = scalar ? val_scalar(rhs) : val_get(rhs, rhs->m == 1 ? 0 : k, rhs->m == 1 ? k : 0);
        } else {
            int64_t ra = k % I.n, rb = k / I.n;
            a = I.ix[ra];
            b = J.ix[rb];
            e[k].v = scalar ? val_scalar(rhs) : val_get(rhs, ra, rb);
        }
        e[k].i = a;
        e[k].j = b;
        e[k].order = k;
        if (b - a > target->ku || a - b > target->kl) inband = 0;
    }
    if (target->format == SILC_FMT_DENSE) {
        r = copy_value(target);
        if (!r) goto nomem;
        for (k = 0; k < ne; k++) r->val[e[k].i + e[k].j * m] = e[k].v;
    } else if (target->format == SILC_FMT_BAND && inband) {
        r = copy_value(target);
        if (!r) goto nomem;
        for (k = 0; k < ne; k++) r->val[(r->ku + e[k].i - e[k].j) + e[k].j * r->ld] = e[k].v;
    } else {
        /* CSR, or a band whose new entries leave the band: rebuild as CSR */
        int64_t w = 0;
        silc_value *c = target->format == SILC_FMT_CSR ? NULL : bi_to_csr(target);
        if (target->format != SILC_FMT_CSR && !c) goto nomem;
        qsort(e, (size_t)ne, sizeof *e, cmp_entry);
        for (k = 0; k < ne; k++) {   /* the last assignment to a position wins */
            if (w > 0 && e[w - 1].i == e[k].i && e[w - 1].j == e[k].j) e[w - 1] = e[k];
            else e[w++] = e[k];
        }
        r = csr_merge(c ? c : target, e, w);
        val_release(c);
        if (!r) goto nomem;
    }
    free(e);
    free(I.ix);
    free(J.ix);
    val_release(grown);
    *out = r;
    return 0;
nomem:
    free(e);
    free(I.ix);
    free(J.ix);
    val_release(grown);
    return oom(V);
}
