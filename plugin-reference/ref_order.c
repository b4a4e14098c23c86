/*
 * ref_order.c -- fill-reducing orderings for the reference plugin's sparse
 * factorizations: approximate minimum degree (Amestoy, Davis and Duff) on a
 * symmetric pattern, the patterns it is run on (A+A' for Cholesky and
 * symmetric-strategy LU, A'A for unsymmetric LU and QR), and the elimination
 * tree.
 *
 * The AMD here follows the classic quotient-graph formulation: eliminated
 * nodes become elements, each variable's adjacency holds its elements first
 * and then its remaining variables (all in one workspace iw with elbow room
 * and a garbage collector), degrees are the approximate external degrees
 * |Lk| + sum |Le \ Lk|, indistinguishable variables are merged into
 * supervariables by hashing, variables with no external degree are eliminated
 * en masse, and rows denser than 10 sqrt(n) are set aside and ordered last.
 * The result is post-ordered by the assembly tree, so the order groups each
 * supervariable and each subtree.
 */
#include "ref.h"

#include <math.h>
#include <string.h>

#define FLIP(i) (-(i) - 2)

/* Reset the marker array w when the running mark would overflow. */
static int64_t wclear(int64_t mark, int64_t lemax, int64_t *w, int64_t n)
{
    if (mark < 2 || mark + lemax < 0) {
        for (int64_t k = 0; k < n; k++)
            if (w[k] != 0) w[k] = 1;
        mark = 2;
    }
    return mark;
}

/* Non-recursive depth-first postorder of the tree rooted at j. */
static int64_t tdfs(int64_t j, int64_t k, int64_t *head, const int64_t *next, int64_t *post,
                    int64_t *stack)
{
    int64_t top = 0;
    stack[0] = j;
    while (top >= 0) {
        int64_t p = stack[top], i = head[p];
        if (i == -1) {
            top--;
            post[k++] = p;
        } else {
            head[p] = next[i];
            stack[++top] = i;
        }
    }
    return k;
}

int ref_amd(const ref_sp *S, int64_t *perm)
{
    int64_t n = S->n;
    if (n == 0) return 0;
    int64_t t = 0;
    for (int64_t j = 0; j < n; j++)
        for (int64_t p = S->p[j]; p < S->p[j + 1]; p++)
            if (S->i[p] != j) t++;
    int64_t nzmax = t + t / 5 + 2 * n + 1;
    int64_t *iw = ref_alloc((size_t)nzmax, sizeof(int64_t));
    int64_t *ws = ref_alloc((size_t)(10 * (n + 1)), sizeof(int64_t));
    int64_t *post = ref_alloc((size_t)(n + 1), sizeof(int64_t));
    if (!iw || !ws || !post) {
        ref_free(iw);
        ref_free(ws);
        ref_free(post);
        return SILC_ENOMEM;
    }
    int64_t *len = ws, *nv = ws + (n + 1), *next = ws + 2 * (n + 1), *head = ws + 3 * (n + 1);
    int64_t *elen = ws + 4 * (n + 1), *degree = ws + 5 * (n + 1), *w = ws + 6 * (n + 1);
    int64_t *hhead = ws + 7 * (n + 1), *last = ws + 8 * (n + 1), *pe = ws + 9 * (n + 1);
    int64_t cnz = 0;
    for (int64_t j = 0; j < n; j++) {
        pe[j] = cnz;
        for (int64_t p = S->p[j]; p < S->p[j + 1]; p++)
            if (S->i[p] != j) iw[cnz++] = S->i[p];
        len[j] = cnz - pe[j];
    }
    double dd = 10.0 * sqrt((double)n);
    int64_t dense = dd > 16 ? (int64_t)dd : 16;
    if (dense > n - 2) dense = n - 2;
    for (int64_t i = 0; i <= n; i++) {
        head[i] = last[i] = next[i] = hhead[i] = -1;
        nv[i] = 1;
        w[i] = 1;
        elen[i] = 0;
        degree[i] = i < n ? len[i] : 0;
    }
    nv[n] = 0;
    pe[n] = -1;
    len[n] = 0;
    w[n] = 0;
    int64_t mark = wclear(0, 0, w, n), nel = 0, lemax = 0, mindeg = 0;
    for (int64_t i = 0; i < n; i++) {
        int64_t d = degree[i];
        if (d == 0) { /* isolated: an element at once */
            elen[i] = -2;
            nel++;
            pe[i] = -1;
            w[i] = 0;
        } else if (d > dense && dense > 0) { /* dense: ordered last, under node n */
            nv[i] = 0;
            elen[i] = -1;
            nel++;
            pe[i] = FLIP(n);
            nv[n]++;
        } else {
            if (head[d] != -1) last[head[d]] = i;
            next[i] = head[d];
            head[d] = i;
        }
    }
    while (nel < n) {
        int64_t k = -1;
        for (; mindeg < n && (k = head[mindeg]) == -1; mindeg++) {}
        if (k < 0) break; /* cannot happen with a consistent graph; guards the loop */
        if (next[k] != -1) last[next[k]] = -1;
        head[mindeg] = next[k];
        int64_t elenk = elen[k], nvk = nv[k];
        nel += nvk;
        if (elenk > 0 && cnz + mindeg >= nzmax) { /* compact iw */
            for (int64_t j = 0; j < n; j++) {
                int64_t p = pe[j];
                if (p >= 0) {
                    pe[j] = iw[p];
                    iw[p] = FLIP(j);
                }
            }
            int64_t q = 0;
            for (int64_t p = 0; p < cnz;) {
                int64_t j = FLIP(iw[p++]);
                if (j >= 0) {
                    iw[q] = pe[j];
                    pe[j] = q++;
                    for (int64_t k3 = 0; k3 < len[j] - 1; k3++) iw[q++] = iw[p++];
                }
            }
            cnz = q;
        }
        /* the new element Lk: union of k's elements and remaining variables */
        int64_t dk = 0, p = pe[k];
        nv[k] = -nvk;
        int64_t pk1 = elenk == 0 ? p : cnz, pk2 = pk1;
        for (int64_t k1 = 1; k1 <= elenk + 1; k1++) {
            int64_t e, pj, ln;
            if (k1 > elenk) {
                e = k;
                pj = p;
                ln = len[k] - elenk;
            } else {
                e = iw[p++];
                pj = pe[e];
                ln = len[e];
            }
            for (int64_t k2 = 1; k2 <= ln; k2++) {
                int64_t i = iw[pj++], nvi = nv[i];
                if (nvi <= 0) continue;
                dk += nvi;
                nv[i] = -nvi;
                iw[pk2++] = i;
                if (next[i] != -1) last[next[i]] = last[i];
                if (last[i] != -1) next[last[i]] = next[i];
                else head[degree[i]] = next[i];
            }
            if (e != k) {
                pe[e] = FLIP(k);
                w[e] = 0;
            }
        }
        if (elenk != 0) cnz = pk2;
        degree[k] = dk;
        pe[k] = pk1;
        len[k] = pk2 - pk1;
        elen[k] = -2;
        /* |Le \ Lk| for every element e adjacent to Lk, in w[e] - mark */
        mark = wclear(mark, lemax, w, n);
        for (int64_t pk = pk1; pk < pk2; pk++) {
            int64_t i = iw[pk], eln = elen[i];
            if (eln <= 0) continue;
            int64_t nvi = -nv[i], wnvi = mark - nvi;
            for (p = pe[i]; p <= pe[i] + eln - 1; p++) {
                int64_t e = iw[p];
                if (w[e] >= mark) w[e] -= nvi;
                else if (w[e] != 0) w[e] = degree[e] + wnvi;
            }
        }
        /* approximate degrees, element absorption, mass elimination */
        for (int64_t pk = pk1; pk < pk2; pk++) {
            int64_t i = iw[pk], p1 = pe[i], p2 = p1 + elen[i] - 1, pn = p1, h = 0, d = 0;
            for (p = p1; p <= p2; p++) {
                int64_t e = iw[p];
                if (w[e] != 0) {
                    int64_t dext = w[e] - mark;
                    if (dext > 0) {
                        d += dext;
                        iw[pn++] = e;
                        h += e;
                    } else { /* Le is inside Lk: absorb it */
                        pe[e] = FLIP(k);
                        w[e] = 0;
                    }
                }
            }
            elen[i] = pn - p1 + 1;
            int64_t p3 = pn, p4 = p1 + len[i];
            for (p = p2 + 1; p < p4; p++) {
                int64_t j = iw[p], nvj = nv[j];
                if (nvj <= 0) continue;
                d += nvj;
                iw[pn++] = j;
                h += j;
            }
            if (d == 0) {
                pe[i] = FLIP(k);
                int64_t nvi = -nv[i];
                dk -= nvi;
                nvk += nvi;
                nel += nvi;
                nv[i] = 0;
                elen[i] = -1;
            } else {
                if (d < degree[i]) degree[i] = d;
                iw[pn] = iw[p3];
                iw[p3] = iw[p1];
                iw[p1] = k;
                len[i] = pn - p1 + 1;
                h = (h < 0 ? -h : h) % n;
                next[i] = hhead[h];
                hhead[h] = i;
                last[i] = h;
            }
        }
        degree[k] = dk;
        if (dk > lemax) lemax = dk;
        mark = wclear(mark + lemax, lemax, w, n);
        /* supervariables: variables of one hash bucket with equal adjacency */
        for (int64_t pk = pk1; pk < pk2; pk++) {
            int64_t i = iw[pk];
            if (nv[i] >= 0) continue;
            int64_t h = last[i];
            i = hhead[h];
            hhead[h] = -1;
            for (; i != -1 && next[i] != -1; i = next[i], mark++) {
                int64_t ln = len[i], eln = elen[i];
                for (p = pe[i] + 1; p <= pe[i] + ln - 1; p++) w[iw[p]] = mark;
                int64_t jlast = i;
                for (int64_t j = next[i]; j != -1;) {
                    int ok = len[j] == ln && elen[j] == eln;
                    for (p = pe[j] + 1; ok && p <= pe[j] + ln - 1; p++)
                        if (w[iw[p]] != mark) ok = 0;
                    if (ok) {
                        pe[j] = FLIP(i);
                        nv[i] += nv[j];
                        nv[j] = 0;
                        elen[j] = -1;
                        j = next[j];
                        next[jlast] = j;
                    } else {
                        jlast = j;
                        j = next[j];
                    }
                }
            }
        }
        /* finalize Lk and put its variables back in the degree lists */
        p = pk1;
        for (int64_t pk = pk1; pk < pk2; pk++) {
            int64_t i = iw[pk], nvi = -nv[i];
            if (nvi <= 0) continue;
            nv[i] = nvi;
            int64_t d = degree[i] + dk - nvi;
            if (d > n - nel - nvi) d = n - nel - nvi;
            if (d < 0) d = 0;
            if (head[d] != -1) last[head[d]] = i;
            next[i] = head[d];
            last[i] = -1;
            head[d] = i;
            if (d < mindeg) mindeg = d;
            degree[i] = d;
            iw[p++] = i;
        }
        nv[k] = nvk;
        if ((len[k] = p - pk1) == 0) {
            pe[k] = -1;
            w[k] = 0;
        }
        if (elenk != 0) cnz = p;
    }
    /* assembly tree: pe[i] is now the parent of i (or -1 for a root) */
    for (int64_t i = 0; i < n; i++) pe[i] = FLIP(pe[i]);
    pe[n] = -1;
    for (int64_t j = 0; j <= n; j++) head[j] = -1;
    for (int64_t j = n - 1; j >= 0; j--) {
        if (nv[j] > 0 || pe[j] < 0) continue; /* elements next; roots below */
        next[j] = head[pe[j]];
        head[pe[j]] = j;
    }
    for (int64_t e = n - 1; e >= 0; e--) {
        if (nv[e] <= 0 || pe[e] < 0) continue;
        next[e] = head[pe[e]];
        head[pe[e]] = e;
    }
    int64_t k = 0;
    for (int64_t i = 0; i <= n; i++)
        if (pe[i] < 0) k = tdfs(i, k, head, next, post, w);
    int64_t q = 0;
    for (int64_t i = 0; i < k; i++)
        if (post[i] != n) perm[q++] = post[i];
    ref_free(iw);
    ref_free(ws);
    ref_free(post);
    /* every vertex must appear exactly once; if the tree missed one (it cannot
     * for a valid pattern) fall back to the identity rather than crash */
    if (q != n)
        for (int64_t i = 0; i < n; i++) perm[i] = i;
    return 0;
}

int ref_pattern_aplusat(const ref_sp *A, ref_sp *S)
{
    int64_t n = A->n;
    ref_sp T;
    if (ref_sp_transpose(A, &T)) return SILC_ENOMEM;
    int64_t cap = 2 * ref_sp_nnz(A);
    if (ref_sp_alloc(S, n, n, cap, 0)) {
        ref_sp_free(&T);
        return SILC_ENOMEM;
    }
    int64_t nz = 0;
    for (int64_t j = 0; j < n; j++) {
        S->p[j] = nz;
        int64_t a = A->p[j], ea = A->p[j + 1], b = T.p[j], eb = T.p[j + 1];
        while (a < ea || b < eb) {
            int64_t ia = a < ea ? A->i[a] : INT64_MAX, ib = b < eb ? T.i[b] : INT64_MAX;
            int64_t i = ia < ib ? ia : ib;
            if (ia == i) a++;
            if (ib == i) b++;
            if (i != j) S->i[nz++] = i;
        }
    }
    S->p[n] = nz;
    ref_sp_free(&T);
    return 0;
}

int ref_pattern_ata(const ref_sp *A, int skip_dense, ref_sp *S)
{
    int64_t m = A->m, n = A->n;
    ref_sp T;
    if (ref_sp_transpose(A, &T)) return SILC_ENOMEM;
    double dd = 10.0 * sqrt((double)n);
    int64_t dense = dd > 16 ? (int64_t)dd : 16;
    int64_t *mark = ref_alloc((size_t)n, sizeof(int64_t));
    if (!mark) {
        ref_sp_free(&T);
        return SILC_ENOMEM;
    }
    S->p = NULL;
    S->i = NULL;
    S->x = NULL;
    int64_t nz = 0;
    for (int pass = 0; pass < 2; pass++) {
        for (int64_t j = 0; j < n; j++) mark[j] = -1;
        nz = 0;
        for (int64_t j = 0; j < n; j++) {
            if (pass) S->p[j] = nz;
            mark[j] = j;
            for (int64_t p = A->p[j]; p < A->p[j + 1]; p++) {
                int64_t r = A->i[p];
                if (skip_dense && T.p[r + 1] - T.p[r] > dense) continue; /* a dense row would fill A'A */
                for (int64_t q = T.p[r]; q < T.p[r + 1]; q++) {
                    int64_t c = T.i[q];
                    if (mark[c] == j) continue;
                    mark[c] = j;
                    if (pass) S->i[nz] = c;
                    nz++;
                }
            }
        }
        if (pass == 0 && ref_sp_alloc(S, n, n, nz, 0)) {
            ref_free(mark);
            ref_sp_free(&T);
            return SILC_ENOMEM;
        }
    }
    S->p[n] = nz;
    (void)m;
    ref_free(mark);
    ref_sp_free(&T);
    return 0;
}

int ref_etree(const ref_sp *C, int64_t *parent)
{
    int64_t n = C->n;
    int64_t *anc = ref_alloc((size_t)n, sizeof(int64_t));
    if (!anc) return SILC_ENOMEM;
    for (int64_t k = 0; k < n; k++) {
        parent[k] = -1;
        anc[k] = -1;
        for (int64_t p = C->p[k]; p < C->p[k + 1]; p++) {
            int64_t i = C->i[p], inext;
            for (; i != -1 && i < k; i = inext) { /* path compression toward k */
                inext = anc[i];
                anc[i] = k;
                if (inext == -1) parent[i] = k;
            }
        }
    }
    ref_free(anc);
    return 0;
}
