/*
 * concat.c -- matrix literals: [1, 2; 3, 4], and concatenation of blocks,
 * [A, b; c', d].
 *
 * Pure structure, so the core builds the result itself (as it does for
 * subscripts) instead of dispatching.  Blocks in a row sit side by side and
 * must have equal row counts; rows are stacked and must have equal widths.
 * Empty (0x0) blocks are skipped, as MATLAB does, so a loop can grow a matrix
 * from [].  The result is CSR when any block is CSR (concatenating sparse
 * matrices must not densify them), else dense.
 */
#include "lang.h"

#include <complex.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

static int is_empty(const silc_value *v)
{
    return v->m == 0 && v->n == 0;
}

/* Evaluates every block of every row, row-major, into vals[]. */
static int eval_blocks(lang_ev *V, const ast_node *n, silc_value **vals)
{
    size_t r, k, at = 0;
    for (r = 0; r < n->nkids; r++)
        for (k = 0; k < n->kids[r]->nkids; k++)
            if (ev_expr(V, n->kids[r]->kids[k], &vals[at++])) return -1;
    return 0;
}

/* Checks shapes: fills rows[r] (height of block-row r, -1 if all empty) and
 * the common width. */
static int check_shapes(lang_ev *V, const ast_node *n, silc_value **vals, int64_t *rows,
                        int64_t *width)
{
    size_t r, k, at = 0;
    int64_t w_seen = -1;
    size_t r_seen = 0;
    for (r = 0; r < n->nkids; r++) {
        const ast_node *row = n->kids[r];
        int64_t h = -1, w = 0;
        size_t first = 0;
        for (k = 0; k < row->nkids; k++, at++) {
            const silc_value *v = vals[at];
            char a[64], b[64], sa[48], sb[48];
            if (is_empty(v)) continue;
            if (h < 0) {
                h = v->m;
                first = k;
            } else if (v->m != h) {
                ev_operand_name(V, row->kids[first], 2, a, sizeof a);
                ev_operand_name(V, row->kids[k], 2, b, sizeof b);
                ev_shape(vals[at - (k - first)], sa, sizeof sa);
                ev_shape(v, sb, sizeof sb);
                return eng_error(V->E,
                                 "'[...]' row %zu: blocks side by side need equal row counts: %s is %s, %s is %s",
                                 r + 1, a, sa, b, sb);
            }
            w += v->n;
        }
        rows[r] = h;
        if (h < 0) continue;
        if (w_seen >= 0 && w != w_seen)
            return eng_error(V->E,
                             "'[...]': stacked rows need equal widths: row %zu is %lld wide, row %zu is %lld wide",
                             r_seen + 1, (long long)w_seen, r + 1, (long long)w);
        w_seen = w;
        r_seen = r;
    }
    *width = w_seen < 0 ? 0 : w_seen;
    return 0;
}

static silc_value *build_dense(const ast_node *n, silc_value **vals, const int64_t *rows,
                               int64_t m, int64_t width, int field)
{
    silc_value *out = val_new_unset_field(SILC_FMT_DENSE, field, m, width, 0, 0, 0);
    size_t r, k, at = 0;
    int64_t i0 = 0;
    if (!out) return NULL;
    for (r = 0; r < n->nkids; r++) {
        int64_t j0 = 0;
        for (k = 0; k < n->kids[r]->nkids; k++, at++) {
            const silc_value *v = vals[at];
            int64_t i, j;
            if (is_empty(v)) continue;
            for (j = 0; j < v->n; j++)
                for (i = 0; i < v->m; i++) {
                    int64_t at_out = (i0 + i) + (j0 + j) * m;
                    if (field == SILC_FIELD_COMPLEX) {
                        double complex z = val_get_complex(v, i, j);
                        out->val[2 * at_out] = creal(z), out->val[2 * at_out + 1] = cimag(z);
                    } else {
                        out->val[at_out] = val_get(v, i, j);
                    }
                }
            j0 += v->n;
        }
        if (rows[r] > 0) i0 += rows[r];
    }
    return out;
}

/* CSR result: each output row is the same row of every block of its block-row,
 * left to right, so columns come out sorted without a sort. */
static silc_value *build_csr(const ast_node *n, silc_value **vals, const int64_t *rows, int64_t m,
                             int64_t width, int field)
{
    int w = field == SILC_FIELD_COMPLEX ? 2 : 1;
    size_t r, k, at, nblocks = 0;
    int64_t nnz = 0, i, p, row_out = 0;
    silc_value *out = NULL;
    for (r = 0; r < n->nkids; r++) nblocks += n->kids[r]->nkids;
    /* every block as CSR (blocks already CSR are used as they are) */
    for (at = 0; at < nblocks; at++) {
        if ((vals[at]->format != SILC_FMT_CSR || vals[at]->field != field) && !is_empty(vals[at])) {
            /* a real block of a complex matrix is promoted first */
            silc_value *src = field == SILC_FIELD_COMPLEX ? val_promote(vals[at]) : val_retain(vals[at]);
            silc_value *c = src ? bi_to_csr(src) : NULL;
            val_release(src);
            if (!c) return NULL;
            val_release(vals[at]);
            vals[at] = c;
        }
        if (!is_empty(vals[at])) nnz += vals[at]->nnz;
    }
    if (!(out = val_new_unset_field(SILC_FMT_CSR, field, m, width, nnz, 0, 0))) return NULL;
    nnz = 0;
    out->rowptr[0] = 0;
    at = 0;
    for (r = 0; r < n->nkids; r++) {
        size_t nk = n->kids[r]->nkids;
        for (i = 0; i < (rows[r] > 0 ? rows[r] : 0); i++) {
            int64_t j0 = 0;
            for (k = 0; k < nk; k++) {
                const silc_value *v = vals[at + k];
                if (is_empty(v)) continue;
                for (p = v->rowptr[i]; p < v->rowptr[i + 1]; p++) {
                    out->colind[nnz] = v->colind[p] + j0;
                    memcpy(out->val + nnz * w, v->val + p * w, (size_t)w * sizeof *out->val);
                    nnz++;
                }
                j0 += v->n;
            }
            out->rowptr[++row_out] = nnz;
        }
        at += nk;
    }
    val_csr_set_nnz(out, nnz);
    return out;
}

int cc_matrix(lang_ev *V, const ast_node *n, silc_value **out)
{
    size_t r, nblocks = 0, at;
    silc_value **vals;
    int64_t *rows, m = 0, width = 0;
    int any_csr = 0, field = SILC_FIELD_REAL, rc = -1;
    *out = NULL;
    if (n->nkids == 0) {
        *out = val_dense_new(0, 0);
        return *out ? 0 : eng_oom(V->E);
    }
    for (r = 0; r < n->nkids; r++) nblocks += n->kids[r]->nkids;
    vals = calloc(nblocks, sizeof *vals);
    rows = calloc(n->nkids, sizeof *rows);
    if (!vals || !rows) {
        free(vals);
        free(rows);
        return eng_oom(V->E);
    }
    if (eval_blocks(V, n, vals) || check_shapes(V, n, vals, rows, &width)) goto done;
    for (r = 0; r < n->nkids; r++)
        if (rows[r] > 0) m += rows[r];
    for (at = 0; at < nblocks; at++)
        if (vals[at]->format == SILC_FMT_CSR) any_csr = 1;
    for (at = 0; at < nblocks; at++) /* one complex block makes the matrix complex */
        if (vals[at]->field == SILC_FIELD_COMPLEX) field = SILC_FIELD_COMPLEX;
    *out = any_csr ? build_csr(n, vals, rows, m, width, field) : build_dense(n, vals, rows, m, width, field);
    rc = *out ? 0 : eng_oom(V->E);
done:
    for (at = 0; at < nblocks; at++) val_release(vals[at]);
    free(vals);
    free(rows);
    return rc;
}
