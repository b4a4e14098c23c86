/*
 * ref_matmul_t.h -- template of the matrix product kernels (Gustavson's
 * sparse product, sparse times dense, dense times dense), included by
 * ref_matmul.c once per field (ref_field.h).
 */

/* C = A*B with A, B given by their rows (row-compressed). */
static int FN(gustavson)(silc_call *call, const ref_sp *A, const ref_sp *B, int64_t m, int64_t n)
{
    const ENT *Ax = (const ENT *)A->x, *Bx = (const ENT *)B->x;
    int64_t *mark = ref_alloc((size_t)n, sizeof(int64_t));
    ENT *acc = ref_alloc((size_t)n, sizeof(ENT));
    ref_sp R = {0};
    int64_t cap = 0;
    if (!mark || !acc) goto nomem;
    for (int64_t j = 0; j < n; j++) mark[j] = -1;
    /* first pass: exact size of each row, so the result is allocated once */
    for (int64_t i = 0; i < m; i++)
        for (int64_t ka = A->p[i]; ka < A->p[i + 1]; ka++) {
            int64_t k = A->i[ka];
            for (int64_t kb = B->p[k]; kb < B->p[k + 1]; kb++)
                if (mark[B->i[kb]] != i) {
                    mark[B->i[kb]] = i;
                    cap++;
                }
        }
    if (ref_sp_alloc(&R, n, m, cap, ENT_W)) goto nomem;
    ENT *Rx = (ENT *)R.x;
    for (int64_t j = 0; j < n; j++) mark[j] = -1;
    int64_t nz = 0;
    for (int64_t i = 0; i < m; i++) {
        int64_t start = nz;
        R.p[i] = nz;
        for (int64_t ka = A->p[i]; ka < A->p[i + 1]; ka++) {
            int64_t k = A->i[ka];
            ENT a = Ax[ka];
            for (int64_t kb = B->p[k]; kb < B->p[k + 1]; kb++) {
                int64_t j = B->i[kb];
                if (mark[j] != i) {
                    mark[j] = i;
                    R.i[nz++] = j;
                    acc[j] = a * Bx[kb];
                } else {
                    acc[j] += a * Bx[kb];
                }
            }
        }
        /* sort the row's columns (insertion sort: rows are short; fall back to
         * a shell sort gap sequence for long ones) */
        int64_t len = nz - start, *c = R.i + start;
        for (int64_t gap = len / 2 > 0 ? len / 2 : 1;; gap = gap / 2 > 0 ? gap / 2 : 1) {
            for (int64_t s = gap; s < len; s++) {
                int64_t v = c[s], t = s;
                while (t >= gap && c[t - gap] > v) {
                    c[t] = c[t - gap];
                    t -= gap;
                }
                c[t] = v;
            }
            if (gap == 1) break;
        }
        for (int64_t t = start; t < nz; t++) Rx[t] = acc[R.i[t]];
    }
    R.p[m] = nz;
    ref_free(mark);
    ref_free(acc);
    call->out = ref_value_from_rows_w(&R, ENT_W);
    ref_sp_free(&R);
    return call->out ? 0 : ref_nomem(call);
nomem:
    ref_free(mark);
    ref_free(acc);
    ref_sp_free(&R);
    return ref_nomem(call);
}

static int FN(matmul)(silc_call *call, const silc_view *ap, const silc_view *bp)
{
    silc_view a = *ap, b = *bp;
    int64_t m = a.m, n = b.n, kk = a.n;
    if (a.format != SILC_FMT_DENSE && b.format != SILC_FMT_DENSE) {
        ref_sp A, B;
        if (ref_spt_from_view_w(&a, ENT_W, &A)) return ref_nomem(call);
        if (ref_spt_from_view_w(&b, ENT_W, &B)) {
            ref_sp_free(&A);
            return ref_nomem(call);
        }
        int st = FN(gustavson)(call, &A, &B, m, n);
        ref_sp_free(&A);
        ref_sp_free(&B);
        return st;
    }
    /* Sparse times dense writes every entry of C once: no zeroing pass
     * (a whole extra sweep of the result, ~5 % of a 5-point SpMV). */
    silc_value *out = ENT_W == 2 ? ref_host->dense_new_complex(m, n) /* no uninitialized complex constructor */
                      : a.format != SILC_FMT_DENSE && b.format == SILC_FMT_DENSE ? ref_host->dense_new_uninit(m, n)
                                                                                 : ref_host->dense_new(m, n);
    if (!out) return ref_nomem(call);
    silc_view o;
    ref_host->view(out, &o);
    ENT *C = (ENT *)o.val;
    const ENT *av = (const ENT *)a.val, *bv = (const ENT *)b.val;
    if (a.format == SILC_FMT_DENSE && b.format == SILC_FMT_DENSE) {
        for (int64_t j = 0; j < n; j++)
            for (int64_t k = 0; k < kk; k++) {
                ENT t = bv[k + j * kk];
                const ENT *ak = av + k * m;
                ENT *cj = C + j * m;
                for (int64_t i = 0; i < m; i++) cj[i] += ak[i] * t;
            }
    } else if (a.format != SILC_FMT_DENSE) { /* sparse * dense: rows of A */
        ref_sp A;
        if (ref_spt_from_view_w(&a, ENT_W, &A)) {
            ref_host->release(out);
            return ref_nomem(call);
        }
        for (int64_t j = 0; j < n; j++) {
            const ENT *bj = bv + j * kk;
            const ENT *Ax = (const ENT *)A.x;
            for (int64_t i = 0; i < m; i++) {
                ENT s = 0.0;
                for (int64_t p = A.p[i]; p < A.p[i + 1]; p++) s += Ax[p] * bj[A.i[p]];
                C[i + j * m] = s;
            }
        }
        ref_sp_free(&A);
    } else { /* dense * sparse: C(:,j) += b_kj * A(:,k) over the rows k of B */
        ref_sp B;
        if (ref_spt_from_view_w(&b, ENT_W, &B)) {
            ref_host->release(out);
            return ref_nomem(call);
        }
        for (int64_t k = 0; k < kk; k++)
            for (int64_t p = B.p[k]; p < B.p[k + 1]; p++) {
                ENT t = ((const ENT *)B.x)[p];
                const ENT *ak = av + k * m;
                ENT *cj = C + B.i[p] * m;
                for (int64_t i = 0; i < m; i++) cj[i] += ak[i] * t;
            }
        ref_sp_free(&B);
    }
    call->out = out;
    return 0;
}
