/*
 * ref_sparse.c -- sparse direct solvers of the reference plugin: triangular
 * substitution, up-looking Cholesky and left-looking LU with partial pivoting,
 * in the spirit of CSparse (Davis, "Direct Methods for Sparse Linear
 * Systems", 2006) but written for this plugin.
 *
 * Cholesky orders P A P' by approximate minimum degree, computes the
 * elimination tree and the exact column counts of L (the row patterns come
 * from walking the tree: "ereach"), then computes L one row at a time.  LU
 * chooses a column order by AMD, on A+A' with a preference for diagonal pivots
 * when A is nearly structurally symmetric with a zero-free diagonal (the
 * UMFPACK symmetric strategy), on A'A with plain partial pivoting otherwise;
 * each column is a sparse triangular solve whose pattern comes from a
 * depth-first search of the graph of L.  A column with no usable pivot is
 * reported as singular, never divided by.
 *
 * The symbolic steps (reach, elimination tree, column counts, depth-first
 * search) are the same in both fields and live here; the numeric kernels are
 * in ref_sparse_t.h, instantiated below for real and for complex entries
 * (ref_field.h), the complex Cholesky factoring a Hermitian A = L L^H.
 */
#include "ref.h"

#include <math.h>
#include <stdio.h>
#include <string.h>

/* ---- Cholesky ---------------------------------------------------------------------- */

/* Pattern of row k of L (columns < k), topologically ordered, in s[top..n-1]. */
static int64_t ereach(const ref_sp *C, int64_t k, const int64_t *parent, int64_t *s, int64_t *w)
{
    int64_t n = C->n, top = n;
    w[k] = k;
    for (int64_t p = C->p[k]; p < C->p[k + 1]; p++) {
        int64_t i = C->i[p], len = 0;
        if (i > k) continue;
        for (; w[i] != k; i = parent[i]) {
            s[len++] = i;
            w[i] = k;
        }
        while (len > 0) s[--top] = s[--len];
    }
    return top;
}

/* Column pointers of L (diagonal included) from the row patterns. */
static int chol_counts(const ref_sp *C, const int64_t *parent, int64_t *Lp, int64_t *s, int64_t *w)
{
    int64_t n = C->n;
    for (int64_t j = 0; j <= n; j++) Lp[j] = 0;
    for (int64_t j = 0; j < n; j++) w[j] = -1;
    for (int64_t k = 0; k < n; k++) {
        for (int64_t top = ereach(C, k, parent, s, w); top < n; top++) Lp[s[top]]++;
        Lp[k]++;
    }
    int64_t sum = 0;
    for (int64_t j = 0; j < n; j++) {
        int64_t c = Lp[j];
        Lp[j] = sum;
        sum += c;
    }
    Lp[n] = sum;
    return 0;
}

int ref_symbolic_chol(const ref_sp *C, ref_sp *L)
{
    int64_t n = C->n;
    int64_t *parent = ref_alloc((size_t)n, sizeof(int64_t)), *s = ref_alloc((size_t)n, sizeof(int64_t));
    int64_t *w = ref_alloc((size_t)n, sizeof(int64_t)), *Lp = ref_alloc((size_t)n + 1, sizeof(int64_t));
    int st = SILC_ENOMEM;
    L->p = L->i = NULL;
    L->x = NULL;
    L->owned = 0;
    if (!parent || !s || !w || !Lp || ref_etree(C, parent)) goto done;
    chol_counts(C, parent, Lp, s, w);
    if (ref_sp_alloc(L, n, n, Lp[n], 0)) goto done;
    memcpy(L->p, Lp, (size_t)(n + 1) * sizeof(int64_t));
    for (int64_t j = 0; j < n; j++) {
        Lp[j] = L->p[j];
        w[j] = -1;
    }
    for (int64_t k = 0; k < n; k++) {
        for (int64_t top = ereach(C, k, parent, s, w); top < n; top++) L->i[Lp[s[top]]++] = k;
        L->i[Lp[k]++] = k;
    }
    st = 0;
done:
    ref_free(parent);
    ref_free(s);
    ref_free(w);
    ref_free(Lp);
    return st;
}

/* Depth-first search from row j in the graph of L (columns known by pinv);
 * finished nodes are pushed onto xi[top-1], xi[top-2], ...  xi[0..] doubles
 * as the recursion stack and pstack holds each frame's position. */
static int64_t lu_dfs(int64_t j, const ref_sp *L, int64_t top, int64_t *xi, int64_t *pstack,
                      const int64_t *pinv, int64_t *mark, int64_t stamp)
{
    int64_t head = 0;
    xi[0] = j;
    while (head >= 0) {
        j = xi[head];
        int64_t jnew = pinv[j];
        if (mark[j] != stamp) {
            mark[j] = stamp;
            pstack[head] = jnew < 0 ? 0 : L->p[jnew];
        }
        int done = 1;
        int64_t p2 = jnew < 0 ? 0 : L->p[jnew + 1];
        for (int64_t p = pstack[head]; p < p2; p++) {
            int64_t i = L->i[p];
            if (mark[i] == stamp) continue;
            pstack[head] = p + 1;
            xi[++head] = i;
            done = 0;
            break;
        }
        if (done) {
            head--;
            xi[--top] = j;
        }
    }
    return top;
}

#undef REF_COMPLEX
#include "ref_field.h"
#include "ref_sparse_t.h"

#define REF_COMPLEX
#include "ref_field.h"
#include "ref_sparse_t.h"
#undef REF_COMPLEX
