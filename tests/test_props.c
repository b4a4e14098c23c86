/*
 * test_props.c -- a value's structural properties (value.c), computed in
 * parts on demand, against a brute-force answer computed here from the
 * list of the same matrix's stored entries.
 *
 * For every real shared matrix, in CSR and (when small) dense storage, and
 * for hand-made edge cases, in CSR and dense storage (explicit zeros at the ends of rows and on the
 * diagonal, empty rows, one asymmetric entry at the very end, a mirror with
 * a different value, an asymmetric entry in rows the symmetry probe samples
 * and in rows it does not, a rectangular matrix, NaN and Inf in the last entry, a
 * 1x1 and a 0x0 matrix, entries near 1e+-300 that need the scaled norms):
 *   - asking for the shape alone fills exactly the shape (nnz, triangles,
 *     band widths, positive diagonal, NaN/Inf) and, for CSR, marks only it
 *     known (dense values get the norms with it, as value.c says), and
 *     its pass leaves the right answers in the scan cache (largest entry,
 *     NaN/Inf);
 *   - symmetry alone, then the norms, each agree with brute force, and so
 *     does val_props on a fresh copy that computes everything at once;
 *   - val_row_norms (a distributed block's norms) gives the same
 *     infinity and Frobenius norms and largest entry, no 1-norm, and
 *     caches nothing;
 *   - the backward error's ||A||_inf, taken from the residual's pass when
 *     the norms are not known, equals the one from the properties;
 *   - silc_put's one-pass check refuses exactly what env_check refuses, with
 *     its message, on 3000 random small envelopes, and gives the accepted
 *     ones their brute-force shape;
 *   - a plugin asking silc_props_of() for the symmetry gets the right answer
 *     and (for CSR) no norms computed; on a host table of ABI 1.3, without
 *     props_part, it gets every part.
 */
#include "check.h"

#include <float.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "accuracy.h"
#include "dispatch.h"
#include "engine.h"
#include "store.h"
#include "silc.h"
#include "testlib.h"

typedef struct truth {
    int symmetric, pos_diag, diagonal, lower, upper, has_nonfinite;
    int64_t kl, ku, nnz;
    double norm1, norminf, normfro, maxabs;
} truth;

typedef struct entry {
    int64_t i, j;
    double a;
} entry;

static int by_position(const void *x, const void *y)
{
    const entry *p = x, *q = y;
    if (p->i != q->i) return p->i < q->i ? -1 : 1;
    return p->j < q->j ? -1 : p->j > q->j;
}

/* Everything by the definitions, from the list of stored entries (long
 * double sums, so the reference is more accurate than what it checks):
 * symmetry by sorting the nonzeros and their mirror images and comparing
 * the two lists, which shares nothing with value.c's row walk. */
static truth brute(const silc_value *v)
{
    truth t;
    int64_t m = v->m, n = v->n, i, j, k, ne = 0, nz = 0;
    int64_t stored = v->format == SILC_FMT_CSR ? v->rowptr[m] : m * n;
    entry *e = malloc((size_t)(stored ? stored : 1) * sizeof *e);
    entry *mir = malloc((size_t)(stored ? stored : 1) * sizeof *mir);
    long double *row = calloc((size_t)(m ? m : 1), sizeof *row), *col = calloc((size_t)(n ? n : 1), sizeof *col);
    long double fro = 0;
    int64_t pos = 0;
    memset(&t, 0, sizeof t);
    if (!e || !mir || !row || !col) {
        CHECK(0, "out of memory");
        goto out;
    }
    for (i = 0; i < m; i++)
        if (v->format == SILC_FMT_CSR)
            for (k = v->rowptr[i]; k < v->rowptr[i + 1]; k++) e[ne++] = (entry){i, v->colind[k], v->val[k]};
        else
            for (j = 0; j < n; j++) e[ne++] = (entry){i, j, v->val[i + j * m]};
    t.diagonal = t.lower = t.upper = 1;
    for (k = 0; k < ne; k++) {
        double a = e[k].a;
        i = e[k].i, j = e[k].j;
        row[i] += fabsl((long double)a);
        col[j] += fabsl((long double)a);
        fro += (long double)a * a;
        if (!isfinite(a)) t.has_nonfinite = 1;
        if (fabs(a) > t.maxabs) t.maxabs = fabs(a);
        if (i == j && a > 0) pos++;
        if (a == 0) continue;
        mir[nz] = (entry){j, i, a};
        e[nz++] = e[k]; /* compacts the nonzeros in place (nz <= k) */
        if (i != j) t.diagonal = 0;
        if (j > i) t.lower = 0, t.ku = j - i > t.ku ? j - i : t.ku;
        if (i > j) t.upper = 0, t.kl = i - j > t.kl ? i - j : t.kl;
    }
    t.nnz = nz;
    t.pos_diag = m == n && n > 0 && pos == n;
    for (i = 0; i < m; i++) t.norminf = (double)row[i] > t.norminf ? (double)row[i] : t.norminf;
    for (j = 0; j < n; j++) t.norm1 = (double)col[j] > t.norm1 ? (double)col[j] : t.norm1;
    t.normfro = (double)sqrtl(fro);
    qsort(e, (size_t)nz, sizeof *e, by_position);
    qsort(mir, (size_t)nz, sizeof *mir, by_position);
    t.symmetric = m == n;
    for (k = 0; k < nz && t.symmetric; k++)
        if (e[k].i != mir[k].i || e[k].j != mir[k].j || !(e[k].a == mir[k].a)) t.symmetric = 0;
out:
    free(e);
    free(mir);
    free(row);
    free(col);
    return t;
}

/* Sums of k non-negative terms in double are within k eps of the exact sum
 * (recursive summation, Higham 4.2), so that is the tolerance, with k the
 * stored entries; the brute-force sums are long double. */
static int close_to(double got, double want, double k)
{
    return got == want || fabs(got - want) <= (k + 2) * DBL_EPSILON * fabs(want);
}

static void check_shape(const char *what, const silc_props *p, const truth *t)
{
    CHECK(p->nnz == t->nnz && p->diagonal == t->diagonal && p->lower == t->lower &&
              p->upper == t->upper && p->kl == t->kl && p->ku == t->ku && p->pos_diag == t->pos_diag &&
              p->has_nonfinite == t->has_nonfinite,
          "%s: shape nnz %lld/%lld diag %d/%d lower %d/%d upper %d/%d kl %lld/%lld ku %lld/%lld "
          "posdiag %d/%d nonfinite %d/%d",
          what, (long long)p->nnz, (long long)t->nnz, p->diagonal, t->diagonal, p->lower, t->lower,
          p->upper, t->upper, (long long)p->kl, (long long)t->kl, (long long)p->ku, (long long)t->ku,
          p->pos_diag, t->pos_diag, p->has_nonfinite, t->has_nonfinite);
}

static void check_norms(const char *what, const silc_props *p, const truth *t, double k)
{
    if (t->has_nonfinite) return; /* the norms of a NaN matrix are not a contract */
    CHECK(close_to(p->norm1, t->norm1, k) && close_to(p->norminf, t->norminf, k) &&
              close_to(p->normfro, t->normfro, k) && p->maxabs == t->maxabs,
          "%s: norms 1 %.17g/%.17g inf %.17g/%.17g fro %.17g/%.17g max %.17g/%.17g", what, p->norm1,
          t->norm1, p->norminf, t->norminf, p->normfro, t->normfro, p->maxabs, t->maxabs);
}

/* The value silc_put makes of e: a CSR one has its shape from the copy. */
static silc_value *value_of(const silc_envelope_t *e)
{
    silc_value *v = NULL;
    char err[256];
    if (env_to_value(e, &v, err, sizeof err)) {
        CHECK(0, "env_to_value: %s", err);
        return NULL;
    }
    return v;
}

/* The same matrix as a value an operation builds: nothing known of it. */
static silc_value *value_built(const silc_envelope_t *e)
{
    silc_value *v;
    if (e->format != SILC_CSR) return value_of(e);
    v = val_csr_new(e->m, e->n, e->rowptr[e->m]);
    CHECK(v != NULL, "val_csr_new");
    if (!v) return NULL;
    memcpy(v->rowptr, e->rowptr, (size_t)(e->m + 1) * sizeof *v->rowptr);
    if (e->rowptr[e->m] > 0) {
        memcpy(v->colind, e->colind, (size_t)e->rowptr[e->m] * sizeof *v->colind);
        memcpy(v->val, e->values, (size_t)e->rowptr[e->m] * sizeof *v->val);
    }
    val_csr_set_nnz(v, e->rowptr[e->m]);
    return v;
}

/* All the checks on one matrix given as an envelope. */
/* What a plugin sees through the host table (silc_plugin.h's silc_props_of). */
static void check_plugin_view(const char *what, const silc_envelope_t *e, const truth *t)
{
    silc_host_api old = *host_api();
    silc_value *u = value_built(e), *o = value_built(e);
    const silc_props *p;
    if (!u || !o) goto out;
    p = silc_props_of(host_api(), u, SILC_PROPS_SYMMETRY);
    CHECK(p->symmetric == t->symmetric, "%s: plugin's symmetric %d, truth %d", what, p->symmetric,
          t->symmetric);
    CHECK(u->format != SILC_FMT_CSR || u->props_have == SILC_PROPS_SYMMETRY,
          "%s: a plugin asking for the symmetry got parts %d", what, u->props_have);
    old.struct_size = SILC_HOST_NEEDS(dense_new_uninit); /* a 1.3 host */
    p = silc_props_of(&old, o, SILC_PROPS_SYMMETRY);
    CHECK(p->symmetric == t->symmetric && o->props_have == SILC_PROPS_ALL,
          "%s: on a 1.3 host symmetric %d (truth %d), parts %d", what, p->symmetric, t->symmetric,
          o->props_have);
out:
    val_release(u);
    val_release(o);
}

static void check_matrix(const char *what, const silc_envelope_t *e)
{
    silc_value *v = value_built(e), *w = value_built(e), *put = value_of(e);
    truth t;
    double k;
    const silc_props *p;
    if (!v || !w || !put) goto out;
    t = brute(v);
    check_plugin_view(what, e, &t);
    if (put->format == SILC_FMT_CSR) {
        /* silc_put's copy computed the shape (val_csr_fill_checked), and the
         * scan with it. */
        CHECK(put->props_have == SILC_PROPS_SHAPE, "%s: put's value knows parts %d, not the shape",
              what, put->props_have);
        check_shape(what, &put->props, &t);
        CHECK(val_has_nonfinite(put) == t.has_nonfinite &&
                  (t.has_nonfinite ? !(val_max_abs(put) < INFINITY) : val_max_abs(put) == t.maxabs),
              "%s: put's scan max %.17g nonfinite %d, truth %.17g %d", what, val_max_abs(put),
              val_has_nonfinite(put), t.maxabs, t.has_nonfinite);
    }
    k = (double)(v->format == SILC_FMT_CSR ? v->rowptr[v->m] : v->m * v->n);
    if (!t.has_nonfinite) { /* a distributed block's norms: no column sums, nothing cached */
        silc_props rp;
        int have = w->props_have, rc = val_row_norms(w, &rp); /* before CHECK reads rp */
        CHECK(rc == 0 && isnan(rp.norm1) && close_to(rp.norminf, t.norminf, k) &&
                  close_to(rp.normfro, t.normfro, k) && rp.maxabs == t.maxabs && w->props_have == have,
              "%s: row norms 1 %.17g (NaN) inf %.17g/%.17g fro %.17g/%.17g max %.17g/%.17g, parts %d/%d", what,
              rp.norm1, rp.norminf, t.norminf, rp.normfro, t.normfro, rp.maxabs, t.maxabs, w->props_have, have);
    }
    p = val_props_part(v, SILC_PROPS_SHAPE);
    check_shape(what, p, &t);
    CHECK(v->format != SILC_FMT_CSR || v->props_have == SILC_PROPS_SHAPE,
          "%s: asking for the shape computed more (%d)", what, v->props_have);
    /* The shape's pass also filled the scan a right-hand side or the scaling
     * hook asks for. */
    CHECK(val_has_nonfinite(v) == t.has_nonfinite &&
              (t.has_nonfinite ? !(val_max_abs(v) < INFINITY) : val_max_abs(v) == t.maxabs),
          "%s: scan max %.17g nonfinite %d, truth %.17g %d", what, val_max_abs(v), val_has_nonfinite(v),
          t.maxabs, t.has_nonfinite);
    p = val_props_part(v, SILC_PROPS_SYMMETRY);
    CHECK(p->symmetric == t.symmetric, "%s: symmetric %d, truth %d", what, p->symmetric, t.symmetric);
    /* The backward error before the norms are known (||A||_inf from the
     * residual's pass) and after (from the properties) must agree. */
    if (v->m == v->n && v->m > 0 && !t.has_nonfinite) {
        silc_value *x = val_dense_new(v->n, 1), *b = val_dense_new(v->n, 1);
        if (x && b) {
            double be1, be2;
            int64_t i;
            for (i = 0; i < v->n; i++) x->val[i] = 1 + (double)(i % 7) / 8, b->val[i] = (double)(i % 3);
            be1 = acc_backward_error(v, b, x);
            CHECK(!(v->props_have & SILC_PROPS_NORMS) || v->format != SILC_FMT_CSR,
                  "%s: the backward error computed the norms", what);
            p = val_props(v);
            be2 = acc_backward_error(v, b, x);
            CHECK(close_to(be1, be2, k), "%s: backward error %.17g with the residual's ||A||, %.17g with "
                                      "the properties'", what, be1, be2);
        }
        val_release(x);
        val_release(b);
    }
    p = val_props(v);
    check_shape(what, p, &t);
    check_norms(what, p, &t, k);
    CHECK(v->props_have == SILC_PROPS_ALL, "%s: not all parts known (%d)", what, v->props_have);
    p = val_props(w); /* everything at once, in the other order */
    check_shape(what, p, &t);
    check_norms(what, p, &t, k);
    CHECK(p->symmetric == t.symmetric, "%s: symmetric (all at once) %d, truth %d", what, p->symmetric,
          t.symmetric);
out:
    val_release(v);
    val_release(w);
    val_release(put);
}

static void check_csr(const char *what, int64_t m, int64_t n, const int64_t *rp, const int64_t *ci,
                      const double *x)
{
    silc_envelope_t e;
    if (silc_envelope_csr(&e, m, n, rp, ci, x)) {
        CHECK(0, "%s: envelope", what);
        return;
    }
    check_matrix(what, &e);
    {   /* the same entries dense: value.c has its own pass for dense */
        silc_envelope_t d;
        double *a = malloc((size_t)(m * n > 0 ? m * n : 1) * sizeof *a);
        char label[200];
        snprintf(label, sizeof label, "%s (dense)", what);
        if (a && !silc_envelope_to_dense(&e, a) && !silc_envelope_dense(&d, m, n, a)) {
            check_matrix(label, &d);
            silc_envelope_free(&d);
        } else {
            CHECK(0, "%s: no dense envelope", label);
        }
        free(a);
    }
    silc_envelope_free(&e);
}

/* A 200 x 200 tridiagonal matrix, symmetric, then with one entry off in
 * rows (98, 99) that the symmetry probe's sample (every third row from 1)
 * does not visit, so the full walk must find it; then one it does visit;
 * then with (99, 98) left out of the pattern, so that its mirror (98, 99)
 * is the only entry no lower entry meets. */
static void tridiagonal(void)
{
    enum { N = 200 };
    static int64_t rp[N + 1], ci[3 * N], rp2[N + 1], ci2[3 * N];
    static double x[3 * N], x2[3 * N];
    int64_t i, k = 0, at = -1, probed = -1;
    for (i = 0; i < N; i++) {
        rp[i] = k;
        if (i > 0) ci[k] = i - 1, x[k++] = -1 - 0.01 * (double)i;
        ci[k] = i, x[k++] = 4;
        if (i < N - 1) ci[k] = i + 1, x[k++] = -1 - 0.01 * (double)(i + 1);
        if (i == 99) at = k - 3;     /* (99, 98) */
        if (i == 100) probed = k - 3; /* (100, 99) */
    }
    rp[N] = k;
    check_csr("tridiagonal 200, symmetric", N, N, rp, ci, x);
    x[at] = -5;
    check_csr("tridiagonal 200, (99, 98) off (not in the probe's rows)", N, N, rp, ci, x);
    x[at] = -1 - 0.01 * 99, x[probed] = -5;
    check_csr("tridiagonal 200, (100, 99) off (in the probe's rows)", N, N, rp, ci, x);
    x[probed] = -1 - 0.01 * 100;
    for (i = 0; i <= N; i++) rp2[i] = rp[i] - (i > 99);
    memcpy(ci2, ci, (size_t)at * sizeof *ci), memcpy(ci2 + at, ci + at + 1, (size_t)(k - at - 1) * sizeof *ci);
    memcpy(x2, x, (size_t)at * sizeof *x), memcpy(x2 + at, x + at + 1, (size_t)(k - at - 1) * sizeof *x);
    check_csr("tridiagonal 200 without (99, 98): (98, 99) unmet", N, N, rp2, ci2, x2);
}

/* silc_put's one-pass check (val_csr_fill_checked) against env_check, which
 * checks the same rules in passes of their own: on random small CSR arrays
 * with columns out of range, repeated or out of order, both must refuse the
 * same envelopes with the same message, and an accepted one must get the
 * brute-force shape. */
static void random_envelopes(void)
{
    uint64_t state = 12345;
    int t, refused = 0, accepted = 0;
    for (t = 0; t < 3000; t++) {
        int64_t rp[7], ci[16], m, n, i, k;
        double x[16];
        silc_envelope_t e;
        silc_value *v = NULL;
        char e1[256] = "", e2[256] = "";
        int r1, r2;
#define RND(k) ((int64_t)((state = state * 6364136223846793005ULL + 1442695040888963407ULL) >> 33) % (k))
        m = 1 + RND(6), n = 1 + RND(6);
        rp[0] = 0;
        for (i = 0; i < m; i++) rp[i + 1] = rp[i] + RND(16 / m + 1);
        for (k = 0; k < rp[m]; k++) {
            /* Mostly sorted and in range; a few of each kind of fault. */
            int64_t f = RND(40);
            ci[k] = f == 0 ? -1 : f == 1 ? n : f == 2 && k > 0 ? ci[k - 1] : RND(n);
            x[k] = RND(5) == 0 ? 0 : (double)(RND(7) - 3);
        }
        for (i = 0; i < m && RND(3); i++) /* sort most rows */
            for (k = rp[i] + 1; k < rp[i + 1]; k++)
                for (int64_t q = k; q > rp[i] && ci[q - 1] > ci[q]; q--) {
                    int64_t tc = ci[q];
                    double tx = x[q];
                    ci[q] = ci[q - 1], x[q] = x[q - 1];
                    ci[q - 1] = tc, x[q - 1] = tx;
                }
#undef RND
        memset(&e, 0, sizeof e);
        e.m = m, e.n = n, e.format = SILC_CSR, e.rowptr = rp, e.colind = ci, e.values = x, e.nnz = rp[m];
        r1 = env_check(&e, e1, sizeof e1);
        r2 = env_to_value(&e, &v, e2, sizeof e2);
        CHECK(r1 == r2 && !strcmp(e1, e2), "envelope %d: env_check %d '%s', put's check %d '%s'", t, r1, e1, r2,
              e2);
        if (v) {
            truth tr = brute(v);
            check_shape("random envelope", &v->props, &tr);
            accepted++;
        } else {
            refused++;
        }
        val_release(v);
    }
    printf("random envelopes: %d refused, %d accepted, the same by both checks\n", refused, accepted);
    CHECK(refused > 300 && accepted > 300, "random envelopes: %d refused, %d accepted", refused, accepted);
}

static void edge_cases(void)
{
    /* 4x4, symmetric, with explicit zeros first and last in rows and a
     * stored zero on row 2's diagonal; empty row 3. */
    static const int64_t rp[] = {0, 3, 7, 7, 9}, ci[] = {0, 1, 3, 0, 1, 2, 3, 0, 1};
    double x[] = {2, 1, 0, 1, 3, 0, 0, 0, 0};
    static const int64_t rp2[] = {0, 2, 4, 6}, ci2[] = {0, 2, 1, 2, 0, 2};
    double y[] = {1, 2, 4, 5, 2, 7};
    static const int64_t rp3[] = {0, 1, 3}, ci3[] = {1, 0, 2};
    static const double z[] = {1, 2, 3};
    static const int64_t rp1[] = {0, 1}, ci1[] = {0}, rp0[] = {0};
    static const double one[] = {-1};
    check_csr("zeros at row ends and on the diagonal", 4, 4, rp, ci, x);
    x[2] = 0.5; /* (0, 3) now nonzero, its mirror (3, 0) is 0 */
    check_csr("unmatched upper entry", 4, 4, rp, ci, x);
    x[2] = 0, x[7] = 0.5; /* (3, 0) nonzero, mirror (0, 3) is a stored zero */
    check_csr("unmatched lower entry", 4, 4, rp, ci, x);
    x[7] = 0;
    x[4] = 5; /* positive diagonal on rows 0, 1 */
    check_csr("symmetric again", 4, 4, rp, ci, x);
    check_csr("3x3 symmetric, pos diag", 3, 3, rp2, ci2, y);
    y[5] = -7;
    check_csr("3x3, negative last diagonal", 3, 3, rp2, ci2, y);
    y[5] = 7, y[4] = 2.5;
    check_csr("3x3, mirror differs in value only", 3, 3, rp2, ci2, y);
    y[4] = 2, y[5] = NAN;
    check_csr("NaN as the last entry", 3, 3, rp2, ci2, y);
    y[5] = INFINITY;
    check_csr("Inf as the last entry", 3, 3, rp2, ci2, y);
    y[0] = 1e300, y[5] = 1e-300;
    check_csr("entries near 1e+-300 (scaled norms)", 3, 3, rp2, ci2, y);
    check_csr("rectangular 2x3", 2, 3, rp3, ci3, z);
    check_csr("1x1 negative", 1, 1, rp1, ci1, one);
    tridiagonal();
    check_csr("0x0", 0, 0, rp0, ci1, one);
}

static void shared_matrices(void)
{
    char path[1024];
    tl_index_row r;
    FILE *f = tl_index_open(NULL, path, sizeof path);
    int count = 0;
    if (!f) return;
    while (tl_index_next(f, &r)) {
        const char *name = r.file;
        silc_envelope_t e;
        /* Complex files are refused elsewhere; any other file that does not
         * read is a failure (tl_read_shared). */
        if (!strcmp(r.field, "complex") || tl_read_shared(name, &e)) continue;
        check_matrix(name, &e);
        if (e.m * e.n <= 250000) { /* and dense, where that is small */
            silc_envelope_t d;
            double *a = malloc((size_t)(e.m * e.n > 0 ? e.m * e.n : 1) * sizeof *a);
            if (a && !silc_envelope_to_dense(&e, a) && !silc_envelope_dense(&d, e.m, e.n, a)) {
                char label[300];
                snprintf(label, sizeof label, "%s (dense)", name);
                check_matrix(label, &d);
                silc_envelope_free(&d);
            }
            free(a);
        }
        count++;
        silc_envelope_free(&e);
    }
    fclose(f);
    CHECK(count >= 20, "only %d shared matrices checked", count);
}

int main(void)
{
    edge_cases();
    random_envelopes();
    shared_matrices();
    return check_done();
}
