/*
 * dist.c -- distributed values and the operations that run on row blocks
 * (dist.h says what moves when and why).
 *
 * Three groups: moving values between layouts (gather, share from rank 0,
 * row blocks in and out), properties computed collectively (so the
 * dispatcher classifies a distributed matrix as it would the whole one),
 * and running operations: block-wise kernels through the ordinary dispatch
 * on each rank's block, collective backends, or the ordinary dispatch on
 * gathered copies.  Every collective goes through the comm table; a
 * failure of the communicator itself ends the job (die), because ranks that
 * disagree on what happened cannot safely meet in the next collective.
 */
#define _POSIX_C_SOURCE 200809L
#include "dist.h"

#include <complex.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#define MSG_WORDS 512 /* E->err travels as 4096 bytes */

static void dist_props_hook(silc_value *v, int parts);
static void dist_scan_hook(silc_value *v);

/* ---- the communicator ------------------------------------------------------ */

static void die(dist_ctx *D, const char *msg)
{
    fprintf(stderr, "silc: rank %d of %d: %s; ending the job (the ranks can no longer agree)\n",
            D->rank, D->size, msg);
    fflush(stderr);
    D->ops->abort(D->ops->impl, 70);
    abort(); /* abort() of the table returned: never go on */
}

#define COMM(D, expr)                                                                              \
    do {                                                                                           \
        char msg_[256] = "";                                                                       \
        if ((D)->ops->expr) die((D), msg_[0] ? msg_ : "communicator failure");                     \
    } while (0)
/* The comm functions take the message buffer last: COMM(D, bcast(impl, ..., MSG)). */
#define MSG msg_, sizeof msg_

static void bcast(dist_ctx *D, void *buf, int64_t words, int root)
{
    COMM(D, bcast(D->ops->impl, buf, words, root, MSG));
}

static void allgather(dist_ctx *D, const void *send, int64_t words, void *recv)
{
    COMM(D, allgather(D->ops->impl, send, words, recv, MSG));
}

/* In place over n doubles, op 0 sum, 1 max, 2 min; the same bits everywhere. */
static void reduce(dist_ctx *D, double *x, int64_t n, int op)
{
    COMM(D, reduce(D->ops->impl, x, n, op, MSG));
}

/* Collective: 1 if any rank passes a non-zero flag. */
static int any_rank(dist_ctx *D, int flag)
{
    double f = flag ? 1 : 0;
    reduce(D, &f, 1, 1);
    return f != 0;
}

int dist_attach(silc_engine *E, silc_comm_ops *ops, dist_run_fn run)
{
    static const val_dist_hooks hooks = {dist_props_hook, dist_scan_hook};
    dist_ctx *D;
    if (!ops || ops->version != SILC_COMM_VERSION || ops->struct_size < sizeof(silc_comm_ops) ||
        ops->size < 1 || ops->rank < 0 || ops->rank >= ops->size)
        return eng_error(E, "invalid communicator table (silc_comm.h version %d expected)",
                         SILC_COMM_VERSION);
    if (!(D = calloc(1, sizeof *D))) return eng_oom(E);
    D->ops = ops;
    D->run = run;
    D->rank = ops->rank;
    D->size = ops->size;
    E->dist = D;
    val_set_dist_hooks(&hooks);
    return 0;
}

void dist_detach(silc_engine *E)
{
    if (!E || !E->dist) return;
    if (E->dist->ops->destroy) E->dist->ops->destroy(E->dist->ops->impl);
    free(E->dist);
    E->dist = NULL;
}

int dist_rank(const silc_engine *E)
{
    return E && E->dist ? E->dist->rank : 0;
}

int dist_size(const silc_engine *E)
{
    return E && E->dist ? E->dist->size : 1;
}

double dist_sum(silc_engine *E, double x)
{
    if (E && E->dist && E->dist->size > 1) reduce(E->dist, &x, 1, 0);
    return x;
}

static uint64_t call_hash(const char *what, const char *text);

/* A failure every rank met with the same message is the statement's, not a
 * rank's (an undefined name, a shape mismatch: every engine evaluates the
 * same text), and reads as it would on one process.  A failure of some
 * ranks, or with messages that differ, names the lowest failing rank, so a
 * user knows where to look. */
int dist_agree(silc_engine *E, int rc)
{
    dist_ctx *D = E->dist;
    int64_t mine[2], *all;
    uint64_t msg[MSG_WORDS];
    int r, first = -1, alike = 1;
    if (!D || D->size == 1) return rc;
    all = calloc((size_t)D->size * 2, sizeof *all);
    if (!all) die(D, "out of memory agreeing on a status");
    mine[0] = rc;
    mine[1] = rc ? (int64_t)call_hash("", E->err) : 0;
    allgather(D, mine, 2, all);
    for (r = 0; r < D->size; r++) {
        if (all[2 * r] && first < 0) first = r;
        if (!all[2 * r] || all[2 * r + 1] != all[1]) alike = 0;
    }
    if (first < 0) {
        free(all);
        return 0;
    }
    rc = (int)all[2 * first];
    free(all);
    if (alike) return rc ? rc : -1; /* E->err already holds the common message */
    memset(msg, 0, sizeof msg);
    if (D->rank == first) memcpy(msg, E->err[0] ? E->err : "failed", strlen(E->err[0] ? E->err : "failed"));
    bcast(D, msg, MSG_WORDS, first);
    ((char *)msg)[sizeof msg - 1] = 0;
    eng_error(E, "rank %d of %d: %.3900s", first, D->size, (const char *)msg);
    return rc ? rc : -1;
}

/* FNV-1a over the call kind and its text. */
static uint64_t call_hash(const char *what, const char *text)
{
    static const unsigned char separator = 0xff;
    uint64_t h = util_fnv1a(UTIL_FNV1A_START, what, strlen(what));
    h = util_fnv1a(h, &separator, 1);
    return text ? util_fnv1a(h, text, strlen(text)) : h;
}

int dist_check_call(silc_engine *E, const char *what, const char *text)
{
    dist_ctx *D = E->dist;
    uint64_t mine[5], *all;
    int r, bad = -1;
    if (!D || D->size == 1) return 0;
    memset(mine, 0, sizeof mine);
    mine[0] = call_hash(what, text);
    /* The call's name travels too, so the message can say what each did. */
    snprintf((char *)(mine + 1), 4 * sizeof(uint64_t), "%s", what);
    all = calloc((size_t)D->size * 5, sizeof *all);
    if (!all) die(D, "out of memory comparing collective calls");
    allgather(D, mine, 5, all);
    for (r = 1; r < D->size && bad < 0; r++)
        if (all[5 * r] != all[0]) bad = r;
    if (bad < 0) {
        free(all);
        return 0;
    }
    {
        char w0[33], wb[33];
        memcpy(w0, all + 1, 32);
        memcpy(wb, all + 5 * bad + 1, 32);
        w0[32] = wb[32] = 0;
        free(all);
        if (strcmp(w0, wb))
            return eng_error(E, "mismatched collective calls: rank 0 called %s, rank %d called %s "
                                "(every rank must make the same SILC calls in the same order)",
                             w0, bad, wb);
        return eng_error(E, "mismatched collective calls: rank %d's %s differs from rank 0's (every "
                            "rank must %s the same %s)", bad, w0, w0,
                         strcmp(w0, "EXEC") ? "name" : "statements");
    }
}

/* ---- partitions ------------------------------------------------------------ */

static dist_part *part_new(int size)
{
    dist_part *p = calloc(1, sizeof *p + (size_t)(size + 1) * sizeof(int64_t));
    if (p) {
        p->refcount = 1;
        p->size = size;
    }
    return p;
}

/* PETSC_DECIDE's split: the first m % size ranks get one row more. */
static dist_part *part_even(int size, int64_t m)
{
    dist_part *p = part_new(size);
    int r;
    if (!p) return NULL;
    for (r = 0; r <= size; r++) p->starts[r] = r * (m / size) + (r < m % size ? r : m % size);
    return p;
}

static int part_same(const dist_part *a, const dist_part *b)
{
    return a == b || (a->size == b->size &&
                      !memcmp(a->starts, b->starts, (size_t)(a->size + 1) * sizeof(int64_t)));
}

static int64_t part_first(const dist_part *p, int rank)
{
    return p->starts[rank];
}

static int64_t part_rows(const dist_part *p, int rank)
{
    return p->starts[rank + 1] - p->starts[rank];
}

/* ---- moving values --------------------------------------------------------- */

/* Counts bytes that arrived from other ranks: counts[r] words from each
 * rank r, received by every rank (all) or by root only. */
static void count_moved(dist_ctx *D, int format, const int64_t *counts, int all, int root)
{
    uint64_t total = 0, own = 0;
    int r;
    for (r = 0; r < D->size; r++) total += (uint64_t)counts[r];
    if (all) {
        for (r = 0; r < D->size; r++) own += (uint64_t)counts[r];
        total = total * (uint64_t)D->size - own;
    } else {
        total -= (uint64_t)counts[root];
    }
    if (format == SILC_FMT_CSR) D->moved_matrix += total * 8;
    else D->moved_vector += total * 8;
}

static void gatherv(dist_ctx *D, const void *send, int64_t words, void *recv, const int64_t *counts,
                    const int64_t *displs, int root)
{
    COMM(D, gatherv(D->ops->impl, send, words, recv, counts, displs, root, MSG));
}

static void scatterv(dist_ctx *D, const void *send, const int64_t *counts, const int64_t *displs,
                     void *recv, int64_t words, int root)
{
    COMM(D, scatterv(D->ops->impl, send, counts, displs, recv, words, root, MSG));
}

/* counts[r] = per_row * rows of rank r; displs the running sum. */
static void layout_counts(const dist_part *P, int64_t per_row, int64_t *counts, int64_t *displs)
{
    int r;
    int64_t at = 0;
    for (r = 0; r < P->size; r++) {
        counts[r] = per_row * (P->starts[r + 1] - P->starts[r]);
        displs[r] = at;
        at += counts[r];
    }
}

/* A zero-filled CSR value of either field. */
static silc_value *csr_new_field(int field, int64_t m, int64_t n, int64_t nnz)
{
    return field == SILC_FIELD_COMPLEX ? val_csr_new_complex(m, n, nnz) : val_csr_new(m, n, nnz);
}

/* Gathers v's blocks into a new whole value on the receiving ranks
 * (root < 0: all).  NULL where nothing was received; on failure every
 * rank returns -1 with E->err. */
static int gather_blocks(silc_engine *E, const silc_value *v, int root, silc_value **out)
{
    dist_ctx *D = E->dist;
    const dist_part *P = v->dist->part;
    const silc_value *blk = v->dist->block;
    int receives = root < 0 || D->rank == root;
    int64_t *counts = calloc((size_t)D->size * 2, sizeof *counts), *displs;
    silc_value *w = NULL;
    double *tmp = NULL;
    int failed = 0, r;
    int64_t wd = val_width(v); /* doubles per entry: a complex entry moves as 2 */
    *out = NULL;
    if (!counts) die(D, "out of memory gathering a value");
    displs = counts + D->size;
    if (v->format == SILC_FMT_DENSE) {
        if (receives) {
            w = val_new_unset_field(SILC_FMT_DENSE, v->field, v->m, v->n, 0, 0, 0);
            if (w && v->n > 1 && !(tmp = malloc((size_t)(v->m * v->n * wd) * sizeof *tmp))) failed = 1;
            if (!w) failed = 1;
        }
        if (any_rank(D, failed)) goto oom;
        layout_counts(P, v->n * wd, counts, displs);
        gatherv(D, blk->val, blk->m * blk->n * wd, receives ? (tmp ? tmp : w->val) : NULL, counts, displs,
                root);
        count_moved(D, SILC_FMT_DENSE, counts, root < 0, root);
        if (tmp) { /* rank blocks, each column-major, into one column-major array */
            for (r = 0; r < D->size; r++) {
                int64_t mr = part_rows(P, r), f = part_first(P, r), j;
                for (j = 0; j < v->n; j++)
                    memcpy(w->val + (f + j * v->m) * wd, tmp + displs[r] + j * mr * wd,
                           (size_t)(mr * wd) * sizeof *tmp);
            }
        }
    } else {
        int64_t nnz = blk->rowptr[blk->m], *nnzs = calloc((size_t)D->size, sizeof *nnzs), total = 0;
        int64_t *ndispls, *vcounts, *vdispls;
        if (!nnzs) die(D, "out of memory gathering a value");
        allgather(D, &nnz, 1, nnzs);
        for (r = 0; r < D->size; r++) total += nnzs[r];
        if (receives && !(w = csr_new_field(v->field, v->m, v->n, total))) failed = 1;
        if (any_rank(D, failed)) {
            free(nnzs);
            goto oom;
        }
        ndispls = calloc((size_t)D->size * 3, sizeof *ndispls);
        if (!ndispls) die(D, "out of memory gathering a value");
        vcounts = ndispls + D->size; /* the values' words: wd per entry */
        vdispls = vcounts + D->size;
        for (r = 1; r < D->size; r++) ndispls[r] = ndispls[r - 1] + nnzs[r - 1];
        for (r = 0; r < D->size; r++) vcounts[r] = nnzs[r] * wd, vdispls[r] = ndispls[r] * wd;
        /* Row lengths into rowptr[1..m], then their running sum. */
        {
            int64_t *len = malloc((size_t)(blk->m ? blk->m : 1) * sizeof *len), i;
            if (!len) die(D, "out of memory gathering a value");
            for (i = 0; i < blk->m; i++) len[i] = blk->rowptr[i + 1] - blk->rowptr[i];
            layout_counts(P, 1, counts, displs);
            gatherv(D, len, blk->m, receives ? w->rowptr + 1 : NULL, counts, displs, root);
            free(len);
            if (receives)
                for (i = 0; i < v->m; i++) w->rowptr[i + 1] += w->rowptr[i];
        }
        gatherv(D, blk->colind, nnz, receives ? w->colind : NULL, nnzs, ndispls, root);
        gatherv(D, blk->val, nnz * wd, receives ? w->val : NULL, vcounts, vdispls, root);
        count_moved(D, SILC_FMT_CSR, counts, root < 0, root < 0 ? 0 : root);
        count_moved(D, SILC_FMT_CSR, nnzs, root < 0, root < 0 ? 0 : root);
        count_moved(D, SILC_FMT_CSR, vcounts, root < 0, root < 0 ? 0 : root);
        if (receives) val_csr_set_nnz(w, total);
        free(nnzs);
        free(ndispls);
    }
    free(counts);
    free(tmp);
    if (w) { /* the properties known of v hold for its whole copy */
        w->props = v->props;
        w->props_have = v->props_have;
    }
    *out = w;
    return 0;
oom:
    free(counts);
    free(tmp);
    val_release(w);
    eng_error(E, "out of memory gathering a %lldx%lld %s value to %s", (long long)v->m, (long long)v->n,
              val_format_name(v->format), root < 0 ? "every rank" : "rank 0");
    return -1;
}

const silc_value *dist_whole(silc_engine *E, const silc_value *cv, int all)
{
    silc_value *v = (silc_value *)cv; /* the whole copy is a cache, not contents */
    val_dist *d;
    silc_value *w;
    if (!dist_is(v)) return v;
    d = v->dist;
    if (d->where == DIST_WHOLE_ALL || (!all && d->where == DIST_WHOLE_ROOT))
        return d->whole; /* NULL on ranks that hold no copy */
    if (gather_blocks(E, v, all ? -1 : 0, &w)) return NULL;
    val_release(d->whole);
    d->whole = w;
    d->where = all ? DIST_WHOLE_ALL : DIST_WHOLE_ROOT;
    return w;
}

int dist_make_whole(silc_engine *E, silc_value **pv)
{
    const silc_value *w;
    if (!dist_is(*pv)) return 0;
    if (!(w = dist_whole(E, *pv, 1))) return -1;
    val_retain((silc_value *)w);
    val_release(*pv);
    *pv = (silc_value *)w;
    return 0;
}

/* Rows [first, first + rows) of a whole value, as a new value. */
static silc_value *rows_of_whole(const silc_value *w, int64_t first, int64_t rows)
{
    silc_value *b;
    int64_t i, j, wd = val_width(w);
    if (w->format == SILC_FMT_DENSE) {
        if (!(b = val_new_unset_field(SILC_FMT_DENSE, w->field, rows, w->n, 0, 0, 0))) return NULL;
        for (j = 0; j < w->n; j++)
            memcpy(b->val + j * rows * wd, w->val + (first + j * w->m) * wd, (size_t)(rows * wd) * sizeof(double));
        return b;
    }
    if (w->format == SILC_FMT_CSR) {
        int64_t lo = w->rowptr[first], hi = w->rowptr[first + rows];
        if (!(b = csr_new_field(w->field, rows, w->n, hi - lo))) return NULL;
        for (i = 0; i <= rows; i++) b->rowptr[i] = w->rowptr[first + i] - lo;
        memcpy(b->colind, w->colind + lo, (size_t)(hi - lo) * sizeof(silc_index));
        memcpy(b->val, w->val + lo * wd, (size_t)((hi - lo) * wd) * sizeof(double));
        val_csr_set_nnz(b, hi - lo);
        return b;
    }
    return NULL; /* band values are never split: their rows are not contiguous */
}

silc_value *dist_promote(silc_engine *E, const silc_value *v)
{
    dist_ctx *D = E->dist;
    silc_value *b = val_promote(v->dist->block), *w;
    if (any_rank(D, !b)) {
        val_release(b);
        return NULL;
    }
    if (!(w = val_dist_new(v->m, v->n, v->format, D, v->dist->part, b))) die(D, "out of memory");
    /* a real value's properties hold for its complex copy (Hermitian when symmetric) */
    w->props = v->props;
    w->props.hermitian = v->props.symmetric;
    w->props_have = v->props_have;
    return w;
}

/* A distributed value with partition P made from a whole value every rank
 * holds: each rank takes its rows, nothing moves. */
static int split_whole(silc_engine *E, const silc_value *w, dist_part *P, silc_value **out)
{
    dist_ctx *D = E->dist;
    silc_value *blk = rows_of_whole(w, part_first(P, D->rank), part_rows(P, D->rank));
    int failed = !blk;
    *out = NULL;
    if (any_rank(D, failed)) {
        val_release(blk);
        return eng_error(E, "out of memory splitting a %lldx%lld value into row blocks",
                         (long long)w->m, (long long)w->n);
    }
    if (!(*out = val_dist_new(w->m, w->n, w->format, D, P, blk))) die(D, "out of memory");
    (*out)->props = w->props;
    (*out)->props_have = w->props_have;
    return 0;
}

int dist_rows_of(silc_engine *E, const silc_value *v, silc_value **block, int64_t *first_row)
{
    dist_ctx *D = E->dist;
    *block = NULL;
    if (dist_is(v)) {
        *block = val_retain(v->dist->block);
        *first_row = part_first(v->dist->part, D->rank);
        return 0;
    }
    if (v->format == SILC_FMT_BAND) {
        *first_row = 0;
        return eng_error(E, "a band value has no row blocks: convert it first (full() or sparse())");
    }
    {
        int64_t f = D ? D->rank * (v->m / D->size) + (D->rank < v->m % D->size ? D->rank : v->m % D->size) : 0;
        int64_t rows = D ? v->m / D->size + (D->rank < v->m % D->size) : v->m;
        *first_row = f;
        if (!(*block = rows_of_whole(v, f, rows))) return eng_oom(E);
    }
    return 0;
}

/* Header of a value every rank must know before moving its arrays. */
enum { H_FORMAT, H_M, H_N, H_NNZ, H_KL, H_KU, H_FIELD, H_WORDS };

int dist_put_rows(silc_engine *E, const char *name, int64_t first_row, silc_value *block)
{
    dist_ctx *D = E->dist;
    int64_t mine[5], *all;
    dist_part *P;
    silc_value *v;
    int r, rc = 0;
    mine[0] = first_row;
    mine[1] = block->m;
    mine[2] = block->n;
    mine[3] = block->format;
    mine[4] = block->field;
    if (!(all = calloc((size_t)D->size * 5, sizeof *all))) die(D, "out of memory");
    allgather(D, mine, 5, all);
    /* Every rank checks the same gathered numbers: the same verdict everywhere. */
    for (r = 0; r < D->size && !rc; r++) {
        const int64_t *a = all + 5 * r;
        if (a[3] != SILC_FMT_DENSE && a[3] != SILC_FMT_CSR)
            rc = eng_error(E, "silc_put_rows '%s': rank %d's block is %s; blocks are dense or CSR", name,
                           r, val_format_name((int)a[3]));
        else if (a[3] != all[3] || a[2] != all[2])
            rc = eng_error(E, "silc_put_rows '%s': rank %d's block is %s with %lld columns, rank 0's %s "
                              "with %lld: every block has the value's columns and format",
                           name, r, val_format_name((int)a[3]), (long long)a[2],
                           val_format_name((int)all[3]), (long long)all[2]);
        else if (a[4] != all[4])
            rc = eng_error(E, "silc_put_rows '%s': rank %d's block is %s, rank 0's %s: every block has the "
                              "value's field",
                           name, r, a[4] == SILC_FIELD_COMPLEX ? "complex" : "real",
                           all[4] == SILC_FIELD_COMPLEX ? "complex" : "real");
        else if (a[0] != (r ? all[5 * (r - 1)] + all[5 * (r - 1) + 1] : 0))
            rc = r ? eng_error(E, "silc_put_rows '%s': rank %d's rows start at %lld, but rank %d's end "
                                  "before row %lld: the blocks must tile the rows in rank order",
                               name, r, (long long)a[0], r - 1,
                               (long long)(all[5 * (r - 1)] + all[5 * (r - 1) + 1]))
                   : eng_error(E, "silc_put_rows '%s': rank 0's rows start at %lld, not 0", name,
                               (long long)a[0]);
    }
    if (rc) {
        free(all);
        val_release(block);
        return -1;
    }
    if (!(P = part_new(D->size))) die(D, "out of memory");
    for (r = 0; r < D->size; r++) P->starts[r] = all[5 * r];
    P->starts[D->size] = all[5 * (D->size - 1)] + all[5 * (D->size - 1) + 1];
    v = val_dist_new(P->starts[D->size], all[2], (int)all[3], D, P, block);
    dist_part_unref(P);
    free(all);
    if (!v) die(D, "out of memory");
    if (store_set(&E->store, name, v)) die(D, "out of memory storing a value"); /* rank-local: no agreement possible */
    val_release(v); /* the store holds it now */
    eng_info_remove(E, name);
    return 0;
}

/* Properties of rank 0's value, sent to every rank with it. */
typedef union props_words {
    struct {
        silc_props p;
        int have, scan_ready, scan_nonfinite;
        double scan_maxabs;
    } s;
    uint64_t w[(sizeof(silc_props) + 4 * sizeof(double) + 7) / 8 + 1];
} props_words;

/* What rank 0 knew of the value it shared, on the new value of every rank. */
static void props_set(silc_value *w, const props_words *pw)
{
    w->props = pw->s.p;
    w->props_have = pw->s.have;
    w->scan_ready = pw->s.scan_ready;
    w->scan_nonfinite = pw->s.scan_nonfinite;
    w->scan_maxabs = pw->s.scan_maxabs;
}

int dist_share(silc_engine *E, silc_value *v, int64_t min_rows, silc_value **out)
{
    dist_ctx *D = E->dist;
    int64_t h[H_WORDS];
    props_words pw;
    silc_value *w = NULL, *blk = NULL;
    dist_part *P;
    int failed = 0;
    int64_t wd;
    *out = NULL;
    memset(h, 0, sizeof h);
    memset(&pw, 0, sizeof pw);
    if (D->rank == 0) {
        h[H_FORMAT] = v->format;
        h[H_M] = v->m;
        h[H_N] = v->n;
        h[H_NNZ] = v->format == SILC_FMT_CSR ? v->rowptr[v->m] : v->nnz;
        h[H_KL] = v->kl;
        h[H_KU] = v->ku;
        h[H_FIELD] = v->field;
        /* What the engine will ask first, computed where the data is. */
        val_props_part(v, SILC_PROPS_ALL);
        val_max_abs(v);
        pw.s.p = v->props;
        pw.s.have = v->props_have;
        pw.s.scan_ready = v->scan_ready;
        pw.s.scan_nonfinite = v->scan_nonfinite;
        pw.s.scan_maxabs = v->scan_maxabs;
    }
    bcast(D, h, H_WORDS, 0);
    bcast(D, pw.w, (int64_t)(sizeof pw.w / 8), 0);
    wd = h[H_FIELD] == SILC_FIELD_COMPLEX ? 2 : 1; /* doubles per entry */
    if (h[H_FORMAT] == SILC_FMT_BAND || h[H_M] < min_rows || h[H_M] < D->size) {
        /* Whole on every rank. */
        if (D->rank)
            failed = !(w = val_new_unset_field((int)h[H_FORMAT], (int)h[H_FIELD], h[H_M], h[H_N], h[H_NNZ],
                                               h[H_KL], h[H_KU]));
        else w = val_retain(v);
        if (any_rank(D, failed)) goto oom;
        bcast(D, w->val, (w->format == SILC_FMT_CSR ? h[H_NNZ] : w->nnz) * wd, 0);
        if (w->format == SILC_FMT_CSR) {
            bcast(D, w->rowptr, h[H_M] + 1, 0);
            bcast(D, w->colind, h[H_NNZ], 0);
            if (D->rank) val_csr_set_nnz(w, h[H_NNZ]);
        }
        {
            int64_t c[1] = {(w->format == SILC_FMT_CSR ? h[H_NNZ] : w->nnz) * wd +
                            (w->format == SILC_FMT_CSR ? h[H_NNZ] + h[H_M] + 1 : 0)};
            int64_t *counts = calloc((size_t)D->size, sizeof *counts);
            if (!counts) die(D, "out of memory");
            counts[0] = c[0];
            count_moved(D, (int)h[H_FORMAT], counts, 1, 0);
            free(counts);
        }
        props_set(w, &pw);
        *out = w;
        return 0;
    }
    if (!(P = part_even(D->size, h[H_M]))) die(D, "out of memory");
    {
        int64_t rows = part_rows(P, D->rank), *counts, *displs, nloc = 0, i;
        int64_t *lens = NULL;
        double *packed = NULL;
        if (!(counts = calloc((size_t)D->size * 2, sizeof *counts))) die(D, "out of memory");
        displs = counts + D->size;
        if (h[H_FORMAT] == SILC_FMT_DENSE) {
            failed = !(blk = val_new_unset_field(SILC_FMT_DENSE, (int)h[H_FIELD], rows, h[H_N], 0, 0, 0));
            if (D->rank == 0 && h[H_N] > 1 && !(packed = malloc((size_t)(h[H_M] * h[H_N] * wd) * sizeof *packed)))
                failed = 1;
            if (any_rank(D, failed)) {
                free(counts);
                dist_part_unref(P);
                goto oom;
            }
            layout_counts(P, h[H_N] * wd, counts, displs);
            if (packed) {
                int r;
                for (r = 0; r < D->size; r++) {
                    int64_t mr = part_rows(P, r), f = part_first(P, r), j;
                    for (j = 0; j < h[H_N]; j++)
                        memcpy(packed + displs[r] + j * mr * wd, v->val + (f + j * h[H_M]) * wd,
                               (size_t)(mr * wd) * sizeof(double));
                }
            }
            scatterv(D, packed ? packed : (D->rank == 0 ? v->val : NULL), counts, displs, blk->val,
                     rows * h[H_N] * wd, 0);
            count_moved(D, SILC_FMT_DENSE, counts, 0, 0);
            free(packed);
        } else {
            int64_t *nnzs = calloc((size_t)D->size * 4, sizeof *nnzs), *ndispls, *vcounts, *vdispls;
            int r;
            if (!nnzs) die(D, "out of memory");
            ndispls = nnzs + D->size;
            vcounts = ndispls + D->size; /* the values' words: wd per entry */
            vdispls = vcounts + D->size;
            if (D->rank == 0)
                for (r = 0; r < D->size; r++) {
                    nnzs[r] = v->rowptr[P->starts[r + 1]] - v->rowptr[P->starts[r]];
                    ndispls[r] = v->rowptr[P->starts[r]];
                }
            bcast(D, nnzs, 2 * D->size, 0);
            for (r = 0; r < D->size; r++) vcounts[r] = nnzs[r] * wd, vdispls[r] = ndispls[r] * wd;
            nloc = nnzs[D->rank];
            failed = !(blk = csr_new_field((int)h[H_FIELD], rows, h[H_N], nloc));
            if (D->rank == 0 && !(lens = malloc((size_t)(h[H_M] ? h[H_M] : 1) * sizeof *lens))) failed = 1;
            if (any_rank(D, failed)) {
                free(nnzs);
                free(counts);
                free(lens);
                dist_part_unref(P);
                goto oom;
            }
            if (D->rank == 0)
                for (i = 0; i < h[H_M]; i++) lens[i] = v->rowptr[i + 1] - v->rowptr[i];
            layout_counts(P, 1, counts, displs);
            scatterv(D, lens, counts, displs, blk->rowptr + 1, rows, 0);
            for (i = 0; i < rows; i++) blk->rowptr[i + 1] += blk->rowptr[i];
            scatterv(D, D->rank == 0 ? v->colind : NULL, nnzs, ndispls, blk->colind, nloc, 0);
            scatterv(D, D->rank == 0 ? v->val : NULL, vcounts, vdispls, blk->val, nloc * wd, 0);
            val_csr_set_nnz(blk, nloc);
            count_moved(D, SILC_FMT_CSR, counts, 0, 0);
            count_moved(D, SILC_FMT_CSR, nnzs, 0, 0);
            count_moved(D, SILC_FMT_CSR, vcounts, 0, 0);
            free(nnzs);
            free(lens);
        }
        free(counts);
    }
    if (!(w = val_dist_new(h[H_M], h[H_N], (int)h[H_FORMAT], D, P, blk))) die(D, "out of memory");
    dist_part_unref(P);
    props_set(w, &pw);
    /* Rank 0 keeps the whole value it was given, so a GET moves nothing.
     * `where` must read the same on every rank (store.h): dist_whole decides
     * from it whether to enter a gather, and a rank that gathered alone
     * would wait there for ever. */
    if (D->rank == 0) w->dist->whole = val_retain(v);
    w->dist->where = DIST_WHOLE_ROOT;
    *out = w;
    return 0;
oom:
    val_release(w);
    val_release(blk);
    return eng_error(E, "out of memory sharing a %lldx%lld value among %d ranks", (long long)h[H_M],
                     (long long)h[H_N], D->size);
}

/* ---- properties, collectively ----------------------------------------------- */

/* Entry k of an array of wd doubles per entry, as value.c's properties read
 * it: its modulus, and whether it is nonzero, finite and positive (real and
 * > 0, what Cholesky needs of a diagonal). */
static inline double entry_mod(const double *val, int64_t k, int64_t wd, int *nonzero, int *finite,
                               int *positive)
{
    double re = val[k * wd], im = wd == 2 ? val[k * wd + 1] : 0;
    *nonzero = re != 0 || im != 0;
    *finite = isfinite(re) && isfinite(im);
    *positive = re > 0 && im == 0;
    return wd == 2 ? hypot(re, im) : fabs(re);
}

/* The shape part of a distributed CSR or dense value from each rank's rows
 * (global row = first + local row), combined. */
static void shape_props(silc_value *v)
{
    dist_ctx *D = v->dist->ctx;
    const silc_value *b = v->dist->block;
    int64_t first = part_first(v->dist->part, D->rank), i, j, wd = val_width(b);
    /* flags: not pos_diag, not diagonal, not lower, not upper, nonfinite (max); kl, ku (max); nnz (sum) */
    double f[7] = {0, 0, 0, 0, 0, 0, 0}, nnz = 0;
    int64_t kl = 0, ku = 0;
    for (i = 0; i < b->m; i++) {
        int64_t g = first + i;
        int diag_positive = 0, nonzero, finite, positive;
        if (b->format == SILC_FMT_CSR) {
            for (j = b->rowptr[i]; j < b->rowptr[i + 1]; j++) {
                int64_t c = b->colind[j];
                entry_mod(b->val, j, wd, &nonzero, &finite, &positive);
                if (!finite) f[4] = 1;
                if (c == g) diag_positive = positive;
                if (!nonzero) continue;
                nnz++;
                if (c < g && g - c > kl) kl = g - c;
                if (c > g && c - g > ku) ku = c - g;
            }
        } else {
            for (j = 0; j < b->n; j++) {
                entry_mod(b->val, i + j * b->m, wd, &nonzero, &finite, &positive);
                if (!finite) f[4] = 1;
                if (j == g) diag_positive = positive;
                if (!nonzero) continue;
                nnz++;
                if (j < g && g - j > kl) kl = g - j;
                if (j > g && j - g > ku) ku = j - g;
            }
        }
        if (g < v->n && !diag_positive) f[0] = 1;
    }
    f[1] = kl > 0 || ku > 0;
    f[2] = ku > 0;
    f[3] = kl > 0;
    f[5] = (double)kl;
    f[6] = (double)ku;
    reduce(D, f, 7, 1);
    reduce(D, &nnz, 1, 0);
    v->props.square = v->m == v->n;
    v->props.pos_diag = v->props.square && !f[0];
    v->props.diagonal = !f[1];
    v->props.lower = !f[2];
    v->props.upper = !f[3];
    v->props.has_nonfinite = f[4] != 0;
    v->props.kl = (int64_t)f[5];
    v->props.ku = (int64_t)f[6];
    v->props.nnz = (int64_t)nnz;
}

/* The norms of a distributed value: ||A||_inf and max|a_ij| from the
 * blocks' own (val_row_norms: one pass over the block's rows, no column
 * sums of its own), Frobenius scaled, and ||A||_1 from column sums over all the
 * ranks -- an array of n sums per rank and a reduction of n doubles, the
 * most expensive property of all -- unless A is known symmetric or
 * hermitian (dist_props_hook asks that first), whose column sums are its
 * row sums (|a_ij| = |a_ji|): then ||A||_1 = ||A||_inf, the same sums in
 * another order.  On a 500^2 one-shot solve on two ranks the column sums
 * were 5 % of the statement. */
static void norm_props(silc_value *v)
{
    dist_ctx *D = v->dist->ctx;
    const silc_value *b = v->dist->block;
    silc_props bp;
    double mx[3], s, fro;
    int mirrored = (v->props_have & SILC_PROPS_SYMMETRY) && (v->props.symmetric || v->props.hermitian);
    double *colsum = mirrored ? NULL : util_large_calloc((size_t)(v->n ? v->n : 1), sizeof *colsum);
    int64_t i, j, wd = val_width(b);
    int nz, fin, pos;
    if (!mirrored && !colsum) die(D, "out of memory computing norms");
    val_row_norms(b, &bp); /* out of memory: norminf is the bound sum|a_ij| */
    mx[0] = bp.norminf;
    mx[1] = bp.maxabs;
    mx[2] = bp.normfro;
    if (colsum && b->format == SILC_FMT_CSR) {
        for (i = 0; i < b->m; i++)
            for (j = b->rowptr[i]; j < b->rowptr[i + 1]; j++)
                colsum[b->colind[j]] += entry_mod(b->val, j, wd, &nz, &fin, &pos);
    } else if (colsum) {
        for (j = 0; j < b->n; j++)
            for (i = 0; i < b->m; i++) colsum[j] += entry_mod(b->val, i + j * b->m, wd, &nz, &fin, &pos);
    }
    if (colsum) reduce(D, colsum, v->n, 0);
    reduce(D, mx, 3, 1);
    v->props.norm1 = mirrored ? mx[0] : 0;
    for (j = 0; colsum && j < v->n; j++)
        if (!(colsum[j] <= v->props.norm1)) v->props.norm1 = colsum[j];
    util_large_free(colsum);
    v->props.norminf = mx[0];
    v->props.maxabs = mx[1];
    /* Frobenius: the largest rank's norm scales the others, so no square overflows. */
    s = mx[2];
    fro = s > 0 && isfinite(s) ? (bp.normfro / s) * (bp.normfro / s) : 0;
    reduce(D, &fro, 1, 0);
    v->props.normfro = s > 0 && isfinite(s) ? s * sqrt(fro) : s;
}

/* Entry (row, col) of the CSR block b (row local, col global; sorted
 * columns) into x[0 .. wd), zeros when it is not stored. */
static void block_entry(const silc_value *b, int64_t row, int64_t col, int64_t wd, double x[2])
{
    int64_t lo = b->rowptr[row], hi = b->rowptr[row + 1] - 1;
    x[0] = x[1] = 0;
    while (lo <= hi) {
        int64_t mid = lo + (hi - lo) / 2;
        if (b->colind[mid] == col) {
            memcpy(x, b->val + mid * wd, (size_t)wd * sizeof *x);
            return;
        }
        if (b->colind[mid] < col) lo = mid + 1;
        else hi = mid - 1;
    }
}

/* An entry x against the entry y its mirror holds: bad[0] when they break
 * A = A.', bad[1] when they break A = A'. */
static void mirror_check(const double x[2], const double *y, int64_t wd, double bad[2])
{
    if (x[0] != y[0] || (wd == 2 && x[1] != y[1])) bad[0] = 1;
    if (x[0] != y[0] || (wd == 2 && x[1] != -y[1])) bad[1] = 1;
}

/* Symmetry of a distributed CSR value: an off-diagonal entry whose mirror
 * this rank owns is compared here; every other one travels to the owner
 * of its mirror, which compares (one exchange of those entries, once per
 * value).  With one rank nothing is packed or sent.  Returns A = A.' (-1
 * when out of memory); *hermitian: A = A' (for a real value the same),
 * which a complex diagonal with an imaginary part already breaks. */
static int symmetric_csr(silc_value *v, int *hermitian)
{
    dist_ctx *D = v->dist->ctx;
    const dist_part *P = v->dist->part;
    const silc_value *b = v->dist->block;
    int64_t first = part_first(P, D->rank), last = first + b->m, i, j, n = 0;
    int64_t *sc = calloc((size_t)D->size * 4, sizeof *sc), *sd, *rc, *rd;
    double *send = NULL, *recv = NULL, bad[2] = {0, 0}; /* not A = A.', not A = A' */
    int64_t *fill = NULL, total = 0, wd = val_width(b), rec = 2 + wd; /* row, column, the entry */
    int r;
    if (!sc) die(D, "out of memory checking symmetry");
    sd = sc + D->size;
    rc = sd + D->size;
    rd = rc + D->size;
    /* Owner of row c: the partition is sorted, so a binary search. */
#define OWNER(c, out)                                                                              \
    do {                                                                                           \
        int lo_ = 0, hi_ = P->size - 1;                                                            \
        while (lo_ < hi_) {                                                                        \
            int mid_ = (lo_ + hi_ + 1) / 2;                                                        \
            if (P->starts[mid_] <= (c)) lo_ = mid_;                                                \
            else hi_ = mid_ - 1;                                                                   \
        }                                                                                          \
        (out) = lo_;                                                                               \
    } while (0)
    for (i = 0; i < b->m; i++)
        for (j = b->rowptr[i]; j < b->rowptr[i + 1]; j++) {
            int64_t c = b->colind[j];
            if (c == first + i) {
                if (wd == 2 && b->val[2 * j + 1] != 0) bad[1] = 1;
                continue;
            }
            if (c >= first && c < last) { /* the mirror is in this block */
                double x[2];
                block_entry(b, c - first, first + i, wd, x);
                mirror_check(x, b->val + j * wd, wd, bad);
                continue;
            }
            OWNER(c, r);
            sc[r] += rec;
            n++;
        }
    for (r = 1; r < D->size; r++) sd[r] = sd[r - 1] + sc[r - 1];
    /* Counts to every rank: an all-to-all of one word each, built from
     * allgather of the whole count row (size^2 words: small). */
    {
        int64_t *allc = calloc((size_t)D->size * D->size, sizeof *allc);
        if (!allc) die(D, "out of memory checking symmetry");
        allgather(D, sc, D->size, allc);
        for (r = 0; r < D->size; r++) {
            rc[r] = allc[r * D->size + D->rank];
            rd[r] = total;
            total += rc[r];
        }
        free(allc);
    }
    send = malloc((size_t)(rec * n + 1) * sizeof *send);
    recv = malloc((size_t)(total + 1) * sizeof *recv);
    fill = calloc((size_t)D->size, sizeof *fill);
    if (any_rank(D, !send || !recv || !fill)) {
        free(send), free(recv), free(fill), free(sc);
        return -1;
    }
    for (i = 0; n && i < b->m; i++)
        for (j = b->rowptr[i]; j < b->rowptr[i + 1]; j++) {
            int64_t c = b->colind[j], at;
            if (c >= first && c < last) continue; /* the diagonal and mirrors in this block: done */
            OWNER(c, r);
            at = sd[r] + fill[r];
            fill[r] += rec;
            send[at] = (double)c;               /* the mirror's row, */
            send[at + 1] = (double)(first + i); /* its column */
            memcpy(send + at + 2, b->val + j * wd, (size_t)wd * sizeof *send); /* and what it must hold */
        }
#undef OWNER
    COMM(D, alltoallv(D->ops->impl, send, sc, sd, recv, rc, rd, MSG));
    {
        double moved = 0;
        for (r = 0; r < D->size; r++)
            if (r != D->rank) moved += (double)rc[r] * 8;
        reduce(D, &moved, 1, 0);
        D->moved_matrix += (uint64_t)moved;
    }
    for (i = 0; i < total && !(bad[0] && bad[1]); i += rec) {
        double x[2]; /* the entry here, against its mirror's recv[i + 2 ..] */
        block_entry(b, (int64_t)recv[i] - first, (int64_t)recv[i + 1], wd, x);
        mirror_check(x, recv + i + 2, wd, bad);
    }
    free(send), free(recv), free(fill), free(sc);
    reduce(D, bad, 2, 1);
    *hermitian = bad[1] == 0;
    return bad[0] == 0;
}

static void dist_props_hook(silc_value *v, int parts)
{
    if (parts & SILC_PROPS_SHAPE) {
        shape_props(v);
        v->props_have |= SILC_PROPS_SHAPE;
    }
    if (parts & SILC_PROPS_SYMMETRY) {
        int sym = 0, herm = 0;
        if (v->m != v->n) sym = 0;
        else if (v->format == SILC_FMT_CSR) sym = symmetric_csr(v, &herm);
        else { /* dense: rare enough to ask the whole copy */
            silc_engine E0;
            const silc_value *w;
            memset(&E0, 0, sizeof E0);
            E0.dist = v->dist->ctx;
            w = dist_whole(&E0, v, 1);
            sym = w ? val_props_part(w, SILC_PROPS_SYMMETRY)->symmetric : -1;
            herm = w ? val_props_part(w, SILC_PROPS_SYMMETRY)->hermitian : 0;
        }
        if (sym >= 0) {
            v->props.symmetric = sym;
            v->props.hermitian = herm;
            v->props_have |= SILC_PROPS_SYMMETRY;
        }
    }
    /* After the symmetry: norm_props uses it. */
    if (parts & SILC_PROPS_NORMS) {
        norm_props(v);
        v->props_have |= SILC_PROPS_NORMS;
    }
}

static void dist_scan_hook(silc_value *v)
{
    const silc_value *b = v->dist->block;
    double m = val_max_abs(b), f[3];
    f[0] = val_has_nonfinite(b);
    f[1] = isnan(m);
    f[2] = isnan(m) ? 0 : m;
    reduce(v->dist->ctx, f, 3, 1);
    v->scan_nonfinite = f[0] != 0;
    v->scan_maxabs = f[1] != 0 ? NAN : f[2];
    v->scan_ready = 2; /* value.c's SCAN_MAXABS */
}

/* ---- running operations ------------------------------------------------------ */

int dist_call_has(const silc_call *call)
{
    int i;
    for (i = 0; i < call->nin; i++)
        if (dist_is(call->in[i])) return 1;
    return 0;
}

/* The partition of the first distributed operand. */
static dist_part *call_part(const silc_call *call)
{
    int i;
    for (i = 0; i < call->nin; i++)
        if (dist_is(call->in[i])) return call->in[i]->dist->part;
    return NULL;
}

/* Runs call (operands replaced by each rank's blocks) through the ordinary
 * dispatch and wraps the block result as distributed like P; the caller
 * agrees on the status. */
static int run_on_blocks(silc_engine *E, silc_call *call, dist_part *P, int64_t m, int64_t n)
{
    dist_ctx *D = E->dist;
    silc_value *out;
    int rc = D->run(E, call);
    if (rc) return rc;
    if (!(out = val_dist_new(m, n, call->out->format, D, P, call->out))) {
        call->out = NULL;
        return eng_oom(E), SILC_ENOMEM;
    }
    call->out = out;
    return 0;
}

/* ADD, SCALE, EWISE, MAP on operands distributed alike (whole operands of the
 * same rows are split, 1x1 ones pass as they are): each rank's rows.  1 if
 * the operands do not allow it (different partitions). */
static int elementwise(silc_engine *E, silc_call *call, int *rc)
{
    dist_part *P = call_part(call);
    silc_call c = *call;
    silc_value *tmp[3] = {NULL, NULL, NULL};
    int64_t m = 0, n = 0;
    int i;
    for (i = 0; i < call->nin; i++) {
        const silc_value *x = call->in[i];
        if (dist_is(x)) {
            if (!part_same(x->dist->part, P)) return 1;
            m = x->m, n = x->n;
        }
    }
    for (i = 0; i < call->nin; i++) {
        const silc_value *x = call->in[i];
        if (dist_is(x)) {
            c.in[i] = x->dist->block;
        } else if (!val_is_scalar(x)) {
            if (x->m != m || x->format == SILC_FMT_BAND) return 1;
            if (split_whole(E, x, P, &tmp[i])) {
                *rc = SILC_ENOMEM;
                goto done;
            }
            c.in[i] = tmp[i]->dist->block;
        }
    }
    c.out = NULL;
    *rc = dist_agree(E, run_on_blocks(E, &c, P, m, n));
    if (*rc) val_release(c.out), c.out = NULL;
    call->out = c.out;
done:
    for (i = 0; i < 3; i++) val_release(tmp[i]);
    return 0;
}

/* ---- the halo exchange of a sparse product ---------------------------------- */

/* y = A x with A and x distributed alike needs, on each rank, x's entries at
 * the columns its rows use: its own rows of x and the "ghosts" other ranks
 * own.  Gathering all of x would move (P-1) n words per product; PETSc's
 * VecScatter moves only the ghosts, and so does this.  The plan is made
 * once per matrix (collectively, kept as an attachment of A's block, so it
 * dies with A on every rank at once): which ghosts this rank needs, which of
 * its entries each other rank needs, and A's block with its columns
 * renumbered into [own rows | ghosts], so that the product is an ordinary
 * local CSR times dense product on [x block; ghosts]. */
#define HALO_KEY "dist.halo"

typedef struct halo_plan {
    silc_value *loc;           /* m_local x (nl + ng): own columns first, then ghosts */
    int64_t nl, ng;            /* own rows of x, ghosts */
    int64_t *sidx;             /* local indices of x to send, by destination rank */
    int64_t *sc, *sd, *rc, *rd; /* words sent to / received from each rank, and offsets */
    int64_t total_ghosts;      /* summed over the ranks: the words one product moves per column */
} halo_plan;

static void halo_free(void *p)
{
    halo_plan *h = p;
    if (!h) return;
    val_release(h->loc);
    free(h->sidx);
    free(h->sc);
    free(h);
}

static int cmp_i64(const void *a, const void *b)
{
    int64_t x = *(const int64_t *)a, y = *(const int64_t *)b;
    return (x > y) - (x < y);
}

/* Position of c in the sorted g[0..n), or -1. */
static int64_t find_i64(const int64_t *g, int64_t n, int64_t c)
{
    int64_t lo = 0, hi = n - 1;
    while (lo <= hi) {
        int64_t mid = lo + (hi - lo) / 2;
        if (g[mid] == c) return mid;
        if (g[mid] < c) lo = mid + 1;
        else hi = mid - 1;
    }
    return -1;
}

/* Builds A's plan (collective).  NULL on every rank when any rank ran out
 * of memory. */
static halo_plan *halo_build(dist_ctx *D, const silc_value *A)
{
    const dist_part *P = A->dist->part;
    const silc_value *b = A->dist->block;
    int64_t first = part_first(P, D->rank), nl = part_rows(P, D->rank), nnz = b->rowptr[b->m];
    int64_t *g = malloc((size_t)(nnz ? nnz : 1) * sizeof *g), ng = 0, i, k, *allc = NULL;
    halo_plan *h = calloc(1, sizeof *h);
    int r, failed;
    if (h) h->sc = calloc((size_t)D->size * 4, sizeof *h->sc);
    failed = !g || !h || !h->sc;
    if (!failed) {
        h->sd = h->sc + D->size, h->rc = h->sd + D->size, h->rd = h->rc + D->size;
        for (k = 0; k < nnz; k++)
            if (b->colind[k] < first || b->colind[k] >= first + nl) g[ng++] = b->colind[k];
        qsort(g, (size_t)ng, sizeof *g, cmp_i64);
        for (i = 0, k = 0; i < ng; i++)
            if (k == 0 || g[i] != g[k - 1]) g[k++] = g[i];
        ng = k;
        /* Sorted ghosts are grouped by owner, owners ascending. */
        for (i = 0, r = 0; i < ng; i++) {
            while (g[i] >= P->starts[r + 1]) r++;
            h->rc[r]++;
        }
        for (r = 1; r < D->size; r++) h->rd[r] = h->rd[r - 1] + h->rc[r - 1];
        allc = calloc((size_t)D->size * (size_t)D->size, sizeof *allc);
        h->loc = csr_new_field(b->field, b->m, nl + ng, nnz);
        failed = !allc || !h->loc;
    }
    if (any_rank(D, failed)) goto fail;
    /* What each rank needs of me: row `rank` of everybody's counts. */
    allgather(D, h->rc, D->size, allc);
    for (r = 0; r < D->size; r++) h->sc[r] = allc[r * D->size + D->rank];
    for (r = 1; r < D->size; r++) h->sd[r] = h->sd[r - 1] + h->sc[r - 1];
    free(allc);
    allc = NULL;
    h->sidx = malloc((size_t)(h->sd[D->size - 1] + h->sc[D->size - 1] + 1) * sizeof *h->sidx);
    if (any_rank(D, !h->sidx)) goto fail;
    COMM(D, alltoallv(D->ops->impl, g, h->rc, h->rd, h->sidx, h->sc, h->sd, MSG));
    for (i = 0; i < h->sd[D->size - 1] + h->sc[D->size - 1]; i++) h->sidx[i] -= first;
    /* The block renumbered; per row: own columns, then ghosts below the
     * own range, then above (each group keeps its sorted order, and that is
     * the order of the new numbers). */
    {
        silc_value *L = h->loc;
        int64_t at = 0, row, pass, wd = val_width(b);
        L->rowptr[0] = 0;
        for (row = 0; row < b->m; row++) {
            for (pass = 0; pass < 3; pass++)
                for (k = b->rowptr[row]; k < b->rowptr[row + 1]; k++) {
                    int64_t c = b->colind[k];
                    int grp = c < first ? 1 : c >= first + nl ? 2 : 0;
                    if (grp != pass) continue;
                    L->colind[at] = grp ? nl + find_i64(g, ng, c) : c - first;
                    memcpy(L->val + at++ * wd, b->val + k * wd, (size_t)wd * sizeof(double));
                }
            L->rowptr[row + 1] = at;
        }
        val_csr_set_nnz(L, at);
    }
    h->nl = nl;
    h->ng = ng;
    {
        double t = (double)ng;
        reduce(D, &t, 1, 0);
        h->total_ghosts = (int64_t)t;
    }
    free(g);
    return h;
fail:
    free(g);
    free(allc);
    halo_free(h);
    return NULL;
}

/* A product the halo exchange serves: A square CSR, x dense, both
 * distributed by the same rows. */
static int halo_applies(const silc_value *A, const silc_value *x)
{
    return dist_is(A) && dist_is(x) && A->format == SILC_FMT_CSR && x->format == SILC_FMT_DENSE &&
           A->m == A->n && x->m == A->n && part_same(A->dist->part, x->dist->part);
}

/* For a product of A with x distributed alike (halo_applies): A's plan and
 * [x's block; the ghosts] as a new dense value, each of x's columns moved
 * once.  1: not this case (the caller gathers); -1: out of memory (every
 * rank); 0: done. */
static int halo_operands(dist_ctx *D, const silc_value *A, const silc_value *x, const halo_plan **plan,
                         silc_value **xbuf)
{
    const silc_value *xb;
    halo_plan *h;
    double *send;
    int64_t j, i, nsend, wd = val_width(x), *wc = NULL; /* a complex x moves 2 words an entry */
    int r;
    *xbuf = NULL;
    if (!halo_applies(A, x)) return 1;
    if (!(h = val_attach_get(A->dist->block, HALO_KEY))) {
        if (!(h = halo_build(D, A))) return -1;
        if (any_rank(D, val_attach_set(A->dist->block, HALO_KEY, h, halo_free) != 0)) {
            if (val_attach_get(A->dist->block, HALO_KEY) != h) halo_free(h);
            return -1;
        }
    }
    xb = x->dist->block;
    nsend = h->sd[D->size - 1] + h->sc[D->size - 1];
    *xbuf = val_new_unset_field(SILC_FMT_DENSE, x->field, h->nl + h->ng, x->n, 0, 0, 0);
    send = malloc((size_t)(nsend ? nsend * wd : 1) * sizeof *send);
    if (wd > 1 && (wc = malloc((size_t)D->size * 4 * sizeof *wc)))
        for (r = 0; r < 4 * D->size; r++) wc[r] = h->sc[r] * wd; /* sc, sd, rc, rd in words */
    if (any_rank(D, !*xbuf || !send || (wd > 1 && !wc))) {
        val_release(*xbuf);
        *xbuf = NULL;
        free(send);
        free(wc);
        return -1;
    }
    for (j = 0; j < x->n; j++) {
        double *col = (*xbuf)->val + j * (h->nl + h->ng) * wd;
        memcpy(col, xb->val + j * h->nl * wd, (size_t)(h->nl * wd) * sizeof *col);
        for (i = 0; i < nsend; i++)
            memcpy(send + i * wd, xb->val + (h->sidx[i] + j * h->nl) * wd, (size_t)wd * sizeof *send);
        if (wc)
            COMM(D, alltoallv(D->ops->impl, send, wc, wc + D->size, col + h->nl * wd, wc + 2 * D->size,
                              wc + 3 * D->size, MSG));
        else
            COMM(D, alltoallv(D->ops->impl, send, h->sc, h->sd, col + h->nl, h->rc, h->rd, MSG));
    }
    free(send);
    free(wc);
    D->moved_vector += (uint64_t)h->total_ghosts * 8u * (uint64_t)x->n * (uint64_t)wd;
    *plan = h;
    return 0;
}

/* A * x with A distributed by rows: each rank multiplies its rows, by
 * [its rows of x; the ghosts] (halo_operands) or by the whole x (gathered
 * once per x value). */
static int matmul(silc_engine *E, silc_call *call, int *rc)
{
    const silc_value *A = call->in[0], *x = call->in[1];
    silc_call c = *call;
    const halo_plan *h = NULL;
    silc_value *xbuf = NULL;
    int halo;
    if (!dist_is(A)) return 1;
    /* x distributed like A: only the ghosts move; else x whole on every rank. */
    halo = halo_operands(E->dist, A, x, &h, &xbuf);
    if (halo < 0) {
        eng_error(E, "out of memory exchanging the entries of a %lldx%lld product's vector",
                  (long long)A->m, (long long)A->n);
        *rc = SILC_ENOMEM;
        return 0;
    }
    if (halo == 0) {
        c.in[0] = h->loc;
        c.in[1] = xbuf;
    } else if (!(c.in[1] = dist_whole(E, x, 1))) {
        *rc = SILC_ENOMEM;
        return 0;
    } else {
        c.in[0] = A->dist->block;
    }
    c.out = NULL;
    *rc = dist_agree(E, run_on_blocks(E, &c, A->dist->part, A->m, x->n));
    val_release(xbuf);
    if (*rc) val_release(c.out), c.out = NULL;
    call->out = c.out;
    return 0;
}

/* Reductions of a distributed vector (sum, max, min, dot, the norms) or of a
 * matrix's columns (sum, max, min) or whole (norm1, norminf, normfro): each
 * rank's part, combined.  1 for what does not split (a matrix's 2-norm). */
static int reduction(silc_engine *E, silc_call *call, int *rc)
{
    dist_ctx *D = E->dist;
    const silc_value *x = call->in[0];
    int vec = x->m == 1 || x->n == 1, sub = call->sub, i;
    silc_call c = *call;
    silc_value *tmp = NULL, *out;
    double *r;
    int64_t k;
    if (!dist_is(x) || (call->nin > 1 && dist_is(call->in[1]) && !part_same(call->in[1]->dist->part, x->dist->part)))
        return 1;
    /* The largest or smallest complex entry is chosen by modulus, then
     * angle (Octave's rule): the ranks' picks are not combined entrywise,
     * so those run on the gathered value. */
    if (x->field == SILC_FIELD_COMPLEX && (sub == SILC_RED_MAX || sub == SILC_RED_MIN)) return 1;
    if (!vec && sub != SILC_RED_SUM && sub != SILC_RED_MAX && sub != SILC_RED_MIN && sub != SILC_RED_NORMINF &&
        sub != SILC_RED_NORMFRO && sub != SILC_RED_NORM1)
        return 1;
    if (sub == SILC_RED_DOT && !dist_is(call->in[1])) {
        if (split_whole(E, call->in[1], x->dist->part, &tmp)) {
            *rc = SILC_ENOMEM;
            return 0;
        }
        c.in[1] = tmp->dist->block;
    } else if (sub == SILC_RED_DOT) {
        c.in[1] = call->in[1]->dist->block;
    }
    c.in[0] = x->dist->block;
    if (!vec && sub == SILC_RED_NORM1) c.sub = SILC_RED_SUM; /* column sums of |x|: below */
    if (sub == SILC_RED_NORM1 && !vec) {
        /* norm1 of a matrix = max over columns of sum |a_ij|: the summed column sums. */
        silc_call a = c;
        silc_value *ab = NULL;
        a.op = SILC_OP_MAP;
        a.sub = SILC_MAP_ABS;
        a.nin = 1;
        a.out = NULL;
        *rc = dist_agree(E, E->dist->run(E, &a));
        if (*rc) {
            val_release(tmp);
            return 0;
        }
        ab = a.out;
        c.in[0] = ab;
        c.out = NULL;
        *rc = dist_agree(E, E->dist->run(E, &c));
        val_release(ab);
    } else {
        /* A block of zero rows reduces to the neutral element the kernels give it. */
        c.out = NULL;
        *rc = dist_agree(E, E->dist->run(E, &c));
    }
    val_release(tmp);
    if (*rc) return 0;
    out = c.out;
    r = out->val;
    k = out->m * out->n;
    switch (sub) {
    case SILC_RED_SUM: case SILC_RED_DOT: /* a complex sum: both parts of each entry */
        reduce(D, r, k * val_width(out), 0);
        break;
    case SILC_RED_NORM1:
        if (vec) reduce(D, r, k, 0);
        else {
            reduce(D, r, k, 0);
            for (i = 1; i < k; i++)
                if (!(r[i] <= r[0])) r[0] = r[i];
            if (k > 1) {
                silc_value *s = val_scalar_new(r[0]);
                val_release(out);
                if (!(out = s)) die(D, "out of memory");
            }
        }
        break;
    case SILC_RED_MAX: case SILC_RED_NORMINF:
        reduce(D, r, k, 1);
        break;
    case SILC_RED_MIN:
        reduce(D, r, k, 2);
        break;
    case SILC_RED_NORM: case SILC_RED_NORMFRO: { /* scaled by the largest part: no overflow */
        double s = r[0], q;
        reduce(D, &s, 1, 1);
        q = s > 0 && isfinite(s) ? (r[0] / s) * (r[0] / s) : 0;
        reduce(D, &q, 1, 0);
        r[0] = s > 0 && isfinite(s) ? s * sqrt(q) : s;
        break;
    }
    default:
        break;
    }
    call->out = out;
    return 0;
}

int dist_run(silc_engine *E, silc_call *call)
{
    int rc = 0, declined = 1;
    if (!dist_call_has(call)) {
        /* Whole operands: every rank computes the same, unless one rank
         * alone ran out of memory; agreeing keeps all on the same path. */
        rc = dist_agree(E, E->dist->run(E, call));
        if (rc) val_release(call->out), call->out = NULL;
        return rc;
    }
    call->out = NULL;
    switch (call->op) {
    case SILC_OP_ADD: case SILC_OP_SCALE: case SILC_OP_EWISE: case SILC_OP_MAP:
        declined = elementwise(E, call, &rc);
        break;
    case SILC_OP_MATMUL:
        declined = matmul(E, call, &rc);
        break;
    case SILC_OP_REDUCE:
        declined = reduction(E, call, &rc);
        break;
    default:
        break;
    }
    if (!declined) return rc;
    /* Solves (collective or gathered, per backend: dist_walk_begin) and the
     * rest (gathered). */
    return E->dist->run(E, call);
}

int dist_walk_begin(silc_engine *E, silc_call *call, int collective, dist_swap *s)
{
    int i;
    memset(s, 0, sizeof *s);
    if (!E->dist || !dist_call_has(call)) return s->mode = DIST_LOCAL;
    for (i = 0; i < call->nin; i++) s->in[i] = call->in[i];
    if (collective && call->op == SILC_OP_SOLVE) {
        const silc_value *A = call->in[0], *B = call->in[1];
        dist_part *P = call_part(call);
        int ok = A->m == A->n && A->format == SILC_FMT_CSR && B->format == SILC_FMT_DENSE &&
                 (!dist_is(A) || part_same(A->dist->part, P)) && (!dist_is(B) || part_same(B->dist->part, P));
        if (ok) {
            for (i = 0; i < 2; i++)
                if (!dist_is(call->in[i])) {
                    if (split_whole(E, call->in[i], P, &s->tmp[i])) return -1;
                    call->in[i] = s->tmp[i];
                }
            return s->mode = DIST_COLLECTIVE;
        }
    }
    for (i = 0; i < call->nin; i++)
        if (dist_is(call->in[i])) {
            const silc_value *w = dist_whole(E, call->in[i], 1);
            if (!w) {
                dist_walk_end(call, s);
                return -1;
            }
            call->in[i] = w;
        }
    return s->mode = DIST_GATHERED;
}

void dist_walk_end(silc_call *call, dist_swap *s)
{
    int i;
    if (s->mode == DIST_LOCAL) return;
    for (i = 0; i < call->nin; i++) {
        if (s->in[i]) call->in[i] = s->in[i];
        val_release(s->tmp[i]);
        s->tmp[i] = NULL;
    }
    s->mode = DIST_LOCAL;
}

/* Entry k of an array of wd doubles per entry as a complex number. */
static double complex entry_c(const double *val, int64_t k, int64_t wd)
{
    return wd == 2 ? util_cmplx(val[2 * k], val[2 * k + 1]) : val[k];
}

double dist_backward_error(const silc_value *A, const silc_value *B, const silc_value *X)
{
    dist_ctx *D = A->dist->ctx;
    silc_engine E0;
    const silc_value *xw, *a = A->dist->block, *b = B->dist->block;
    /* ||A||_inf from the properties when they hold it, else from the
     * residual's pass over the rows (as backward_error_whole does): a
     * distributed solve asks nothing else of A's norms, and their own pass
     * would read the blocks once more (and sum their columns). */
    double nA = (A->props_have & SILC_PROPS_NORMS) ? A->props.norminf : -1, nX, nB, be;
    double red[2] = {0, 0}; /* max_i |r_i| over the columns, max_i sum_k |a_ik| */
    int64_t i, j, k = X->n, wa = val_width(A), wb = val_width(B), wx = val_width(X);
    memset(&E0, 0, sizeof E0);
    E0.dist = D;
    const halo_plan *h = NULL;
    silc_value *xbuf = NULL;
    int halo;
    if (A->format != SILC_FMT_CSR || B->format != SILC_FMT_DENSE || !dist_is(B) || !dist_is(X)) return -1;
    /* X's ghosts only, as in a product; else X whole on every rank. */
    halo = halo_operands(D, A, X, &h, &xbuf);
    if (halo < 0) return -1;
    if (halo == 0) {
        a = h->loc;
        xw = xbuf;
    } else if (!(xw = dist_whole(&E0, X, 1))) {
        return -1;
    }
    for (j = 0; j < k; j++) {
        int rows = nA < 0 && j == 0; /* the row sums: once, and only when not known */
        for (i = 0; i < a->m; i++) {
            double r, ra = 0;
            int64_t p;
            if (wa == 1 && wb == 1 && wx == 1) { /* real: no complex arithmetic in the inner loop */
                double s = b->val[i + j * b->m];
                for (p = a->rowptr[i]; p < a->rowptr[i + 1]; p++) {
                    s -= a->val[p] * xw->val[a->colind[p] + j * xw->m];
                    if (rows) ra += fabs(a->val[p]);
                }
                r = fabs(s);
            } else { /* complex: |r| is the modulus, as backward_error_complex's infinity norm */
                double complex s = entry_c(b->val, i + j * b->m, wb);
                for (p = a->rowptr[i]; p < a->rowptr[i + 1]; p++) {
                    double complex aij = entry_c(a->val, p, wa);
                    s -= aij * entry_c(xw->val, a->colind[p] + j * xw->m, wx);
                    if (rows) ra += cabs(aij);
                }
                r = cabs(s);
            }
            if (!(r <= red[0])) red[0] = r; /* NaN sticks */
            if (!(ra <= red[1])) red[1] = ra;
        }
    }
    val_release(xbuf);
    reduce(D, red, 2, 1);
    /* The same on every rank, so all or none ask the properties (collective):
     * a sum past DBL_MAX needs their scaled pass. */
    if (nA < 0) nA = isfinite(red[1]) ? red[1] : val_props_part(A, SILC_PROPS_NORMS)->norminf;
    nX = val_max_abs(X);
    nB = val_max_abs(B);
    if (isnan(red[0]) || isnan(nX)) be = NAN;
    else if (red[0] == 0) be = 0;
    else be = red[0] / (nA * nX + nB);
    return be;
}

void dist_explain(silc_engine *E, const silc_call *call, strbuf *b)
{
    int i;
    if (!E->dist || !dist_call_has(call)) return;
    sb_printf(b, "distributed on %d ranks:", E->dist->size);
    for (i = 0; i < call->nin; i++) {
        const silc_value *x = call->in[i];
        sb_printf(b, "%s operand %d %s", i ? "," : "", i + 1,
                  dist_is(x) ? "row blocks" : "whole");
    }
    switch (call->op) {
    case SILC_OP_ADD: case SILC_OP_SCALE: case SILC_OP_EWISE: case SILC_OP_MAP:
        sb_puts(b, "; each rank computes its rows (nothing moves)\n");
        break;
    case SILC_OP_MATMUL:
        if (!dist_is(call->in[0]))
            sb_puts(b, "; operands gathered to every rank, run there\n");
        else if (call->nin > 1 && halo_applies(call->in[0], call->in[1]))
            sb_puts(b, "; each rank multiplies its rows, receiving only the right operand's entries "
                       "its rows use (halo exchange, planned once per matrix)\n");
        else
            sb_puts(b, "; each rank multiplies its rows by the whole right operand (gathered once per "
                       "value)\n");
        break;
    case SILC_OP_REDUCE:
        sb_puts(b, "; each rank reduces its rows, the parts are combined\n");
        break;
    case SILC_OP_SOLVE:
        sb_puts(b, "; a backend marked (collective) runs on the row blocks on every rank, any "
                   "other gets the operands gathered to every rank\n");
        break;
    default:
        sb_puts(b, "; no distributed implementation: operands gathered to every rank, run there\n");
        break;
    }
}
