/*
 * ref_qr_t.h -- template of the sparse Q-less QR (ref_qr.c says how it
 * works), included once per field (ref_field.h).  In the complex field R is
 * built by complex Givens rotations (LAPACK zlartg's: c real, s complex, R's
 * diagonal keeping the phase of the entry it replaces), L holds R.' so the
 * semi-normal equations solve R^H R x = M^H b, and trans = 1 applies R^H.
 */

typedef struct FN(sp_qr) {
    int64_t m, n;   /* of A */
    int under;      /* m < n: M = A' */
    int64_t nk;     /* columns of M kept */
    int64_t *colmap;/* column k of Mp is column colmap[k] of M */
    ref_sp Mp;      /* M(:, colmap) */
    ref_sp L;       /* R' (column j = row j of R, diagonal first) */
} FN(sp_qr);

static void FN(sp_qr_free)(void *p)
{
    FN(sp_qr) *f = p;
    if (!f) return;
    ref_free(f->colmap);
    ref_sp_free(&f->Mp);
    ref_sp_free(&f->L);
    ref_free(f);
}

/* x := (R'R)^{-1} x (L = R.', so R' is conj(L)) */
static void FN(rtr_solve)(const ref_sp *L, ENT *x)
{
    int64_t n = L->n;
    const ENT *Lx = (const ENT *)L->x;
    for (int64_t j = 0; j < n; j++) {
        x[j] /= CONJ(Lx[L->p[j]]);
        ENT t = x[j];
        for (int64_t q = L->p[j] + 1; q < L->p[j + 1]; q++) x[L->i[q]] -= CONJ(Lx[q]) * t;
    }
    for (int64_t j = n - 1; j >= 0; j--) {
        ENT t = x[j];
        for (int64_t q = L->p[j] + 1; q < L->p[j + 1]; q++) t -= Lx[q] * x[L->i[q]];
        x[j] = t / Lx[L->p[j]];
    }
}

/* R x = b (trans 0) or R' x = b (trans 1), for the condition estimate. */
static int FN(r_apply)(void *p, double *xd, int trans, double *work)
{
    const ref_sp *L = &((const FN(sp_qr) *)p)->L;
    const ENT *Lx = (const ENT *)L->x;
    ENT *x = (ENT *)xd;
    int64_t n = L->n;
    (void)work;
    if (trans) {
        for (int64_t j = 0; j < n; j++) {
            x[j] /= CONJ(Lx[L->p[j]]);
            ENT t = x[j];
            for (int64_t q = L->p[j] + 1; q < L->p[j + 1]; q++) x[L->i[q]] -= CONJ(Lx[q]) * t;
        }
    } else {
        for (int64_t j = n - 1; j >= 0; j--) {
            ENT t = x[j];
            for (int64_t q = L->p[j] + 1; q < L->p[j + 1]; q++) t -= Lx[q] * x[L->i[q]];
            x[j] = t / Lx[L->p[j]];
        }
    }
    return 0;
}

static void FN(mul)(const ref_sp *M, const ENT *y, ENT *out) /* out = M y */
{
    const ENT *Mx = (const ENT *)M->x;
    memset(out, 0, (size_t)M->m * sizeof(ENT));
    for (int64_t k = 0; k < M->n; k++)
        for (int64_t p = M->p[k]; p < M->p[k + 1]; p++) out[M->i[p]] += Mx[p] * y[k];
}

static void FN(mul_t)(const ref_sp *M, const ENT *r, ENT *out) /* out = M' r */
{
    const ENT *Mx = (const ENT *)M->x;
    for (int64_t k = 0; k < M->n; k++) {
        ENT s = 0.0;
        for (int64_t p = M->p[k]; p < M->p[k + 1]; p++) s += CONJ(Mx[p]) * r[M->i[p]];
        out[k] = s;
    }
}

static int FN(sp_qr_solve)(void *p, double *xd, int trans, double *wd)
{
    const FN(sp_qr) *f = p;
    const ref_sp *M = &f->Mp;
    int64_t rows = M->m, nk = f->nk;
    ENT *x = (ENT *)xd, *w = (ENT *)wd;
    ENT *b = w, *r = w + rows, *z = r + rows, *t = z + nk, *big = t + nk;
    (void)trans;
    if (!f->under) {
        memcpy(b, x, (size_t)rows * sizeof(ENT));
        FN(mul_t)(M, b, z);
        FN(rtr_solve)(&f->L, z);
        for (int it = 0; it < 2; it++) {
            FN(mul)(M, z, r);
            for (int64_t i = 0; i < rows; i++) r[i] = b[i] - r[i];
            FN(mul_t)(M, r, t);
            FN(rtr_solve)(&f->L, t);
            for (int64_t k = 0; k < nk; k++) z[k] += t[k];
        }
        memset(x, 0, (size_t)f->n * sizeof(ENT));
        for (int64_t k = 0; k < nk; k++) x[f->colmap[k]] = z[k];
    } else {
        for (int64_t k = 0; k < nk; k++) b[k] = x[f->colmap[k]];
        memcpy(z, b, (size_t)nk * sizeof(ENT));
        FN(rtr_solve)(&f->L, z);
        FN(mul)(M, z, big);
        for (int it = 0; it < 2; it++) {
            FN(mul_t)(M, big, t);
            for (int64_t k = 0; k < nk; k++) t[k] = b[k] - t[k];
            FN(rtr_solve)(&f->L, t);
            FN(mul)(M, t, r);
            for (int64_t i = 0; i < rows; i++) big[i] += r[i];
        }
        memcpy(x, big, (size_t)rows * sizeof(ENT));
    }
    return 0;
}

/* Column-subset copy M(:, cols[0..nc-1]). */
static int FN(extract_cols)(const ref_sp *M, const int64_t *cols, int64_t nc, ref_sp *out)
{
    int64_t nz = 0;
    for (int64_t k = 0; k < nc; k++) nz += M->p[cols[k] + 1] - M->p[cols[k]];
    if (ref_sp_alloc(out, M->m, nc, nz, ENT_W)) return SILC_ENOMEM;
    nz = 0;
    for (int64_t k = 0; k < nc; k++) {
        out->p[k] = nz;
        for (int64_t p = M->p[cols[k]]; p < M->p[cols[k] + 1]; p++) {
            out->i[nz] = M->i[p];
            ((ENT *)out->x)[nz++] = ((const ENT *)M->x)[p];
        }
    }
    out->p[nc] = nz;
    return 0;
}

/* Factor M(:, keep): order, symbolic, Givens.  Fills f->colmap, Mp, L. */
static int FN(qr_factor)(const ref_sp *M, const int64_t *keep, int64_t nk, FN(sp_qr) *f)
{
    ref_sp Ms = {0}, S = {0}, C = {0}, T = {0};
    int64_t *q = ref_alloc((size_t)nk, sizeof(int64_t));
    ENT *w = ref_calloc((size_t)nk, sizeof(ENT));
    char *init = ref_calloc((size_t)nk, 1);
    int st = SILC_ENOMEM;
    if (!q || !w || !init) goto done;
    if (FN(extract_cols)(M, keep, nk, &Ms) || ref_pattern_ata(&Ms, 1, &S) || ref_amd(&S, q)) goto done;
    ref_sp_free(&S);
    f->nk = nk;
    f->colmap = ref_alloc((size_t)nk, sizeof(int64_t));
    if (!f->colmap) goto done;
    for (int64_t k = 0; k < nk; k++) {
        f->colmap[k] = keep[q[k]];
        q[k] = f->colmap[k];
    }
    if (FN(extract_cols)(M, q, nk, &f->Mp) || ref_pattern_ata(&f->Mp, 0, &S)) goto done;
    /* upper triangle plus diagonal of the pattern of Mp'Mp */
    int64_t cz = nk;
    for (int64_t j = 0; j < nk; j++)
        for (int64_t p = S.p[j]; p < S.p[j + 1]; p++) cz += S.i[p] < j;
    if (ref_sp_alloc(&C, nk, nk, cz, 0)) goto done;
    cz = 0;
    for (int64_t j = 0; j < nk; j++) {
        C.p[j] = cz;
        for (int64_t p = S.p[j]; p < S.p[j + 1]; p++)
            if (S.i[p] < j) C.i[cz++] = S.i[p];
        C.i[cz++] = j;
    }
    C.p[nk] = cz;
    ref_sp_free(&S);
    if (ref_symbolic_chol(&C, &f->L)) goto done;
    ref_sp *L = &f->L;
    L->x = ref_calloc((size_t)L->p[nk], sizeof(ENT));
    L->w = ENT_W;
    if (!L->x || ref_sp_transpose(&f->Mp, &T)) goto done;
    ENT *Lx = (ENT *)L->x;
    const ENT *Tx = (const ENT *)T.x;
    /* rotate each row of Mp into R */
    for (int64_t r = 0; r < T.n; r++) {
        int64_t j = nk;
        for (int64_t p = T.p[r]; p < T.p[r + 1]; p++) {
            w[T.i[p]] += Tx[p];
            if (T.i[p] < j) j = T.i[p];
        }
        while (j < nk) {
            int64_t p0 = L->p[j], p1 = L->p[j + 1];
            if (!init[j]) {
                init[j] = 1;
                for (int64_t p = p0; p < p1; p++) {
                    Lx[p] = w[L->i[p]];
                    w[L->i[p]] = 0.0;
                }
                break;
            }
            /* the rotation [c s; -conj(s) c], c real, taking (a, bb) to (rr, 0):
             * the real one (dlartg's, rr = hypot >= 0) or zlartg's (rr keeps a's phase) */
            ENT a = Lx[p0], bb = w[j], s, rr;
            double h = hypot(MOD(a), MOD(bb)), c;
#ifdef REF_COMPLEX
            if (h == 0.0) c = 1.0, s = 0.0, rr = 0.0;
            else if (a == 0.0) c = 0.0, s = CONJ(bb) / h, rr = h;
            else c = MOD(a) / h, s = (a / MOD(a)) * CONJ(bb) / h, rr = (a / MOD(a)) * h;
#else
            c = a / h, s = bb / h, rr = h;
            if (h == 0.0) {
                c = 1.0;
                s = 0.0;
            }
#endif
            int64_t next = nk;
            Lx[p0] = rr;
            w[j] = 0.0;
            for (int64_t p = p0 + 1; p < p1; p++) {
                int64_t col = L->i[p];
                ENT rv = Lx[p], wv = w[col];
                Lx[p] = c * rv + s * wv;
                w[col] = c * wv - CONJ(s) * rv;
                if (next == nk && w[col] != 0.0) next = col;
            }
            j = next;
        }
    }
    st = 0;
done:
    ref_sp_free(&Ms);
    ref_sp_free(&S);
    ref_sp_free(&C);
    ref_sp_free(&T);
    ref_free(q);
    ref_free(w);
    ref_free(init);
    return st;
}

int FN(ref_sparse_qr)(const ref_sp *A, ref_factor *F, char *msg, size_t msglen)
{
    FN(sp_qr) *f = ref_calloc(1, sizeof(FN(sp_qr)));
    ref_sp At = {0};
    int64_t *keep = NULL;
    int st = SILC_ENOMEM;
    if (!f) return SILC_ENOMEM;
    f->m = A->m;
    f->n = A->n;
    f->under = A->m < A->n;
    if (f->under && ref_sp_transpose(A, &At)) goto fail;
#ifdef REF_COMPLEX
    if (f->under) /* M = A^H */
        for (int64_t k = 0; k < ref_sp_nnz(&At); k++) ((ENT *)At.x)[k] = CONJ(((ENT *)At.x)[k]);
#endif
    const ref_sp *M = f->under ? &At : A;
    int64_t N = M->n, rows = M->m, nk = N;
    keep = ref_alloc((size_t)N, sizeof(int64_t));
    if (!keep) goto fail;
    for (int64_t k = 0; k < N; k++) keep[k] = k;
    for (int round = 0;; round++) {
        if (FN(qr_factor)(M, keep, nk, f)) goto fail;
        double rmax = 0.0;
        for (int64_t j = 0; j < nk; j++) rmax = fmax(rmax, MOD(((const ENT *)f->L.x)[f->L.p[j]]));
        double tol = (double)(rows > N ? rows : N) * DBL_EPSILON * rmax;
        int64_t nkeep = 0;
        for (int64_t j = 0; j < nk; j++)
            if (MOD(((const ENT *)f->L.x)[f->L.p[j]]) > tol) keep[nkeep++] = f->colmap[j];
        if (nkeep == nk) break;
        if (nkeep == 0 || round == 4) {
            snprintf(msg, msglen, FIELD_NAME "sparse QR: matrix has numerical rank 0 or its rank could not be settled");
            st = SILC_ESINGULAR;
            goto fail;
        }
        /* keep the surviving columns in their original order, then refactor */
        for (int64_t a = 1; a < nkeep; a++) {
            int64_t v = keep[a], b = a;
            while (b > 0 && keep[b - 1] > v) {
                keep[b] = keep[b - 1];
                b--;
            }
            keep[b] = v;
        }
        nk = nkeep;
        ref_free(f->colmap);
        f->colmap = NULL;
        ref_sp_free(&f->Mp);
        ref_sp_free(&f->L);
    }
    ref_sp_free(&At);
    ref_free(keep);
    keep = NULL;
    F->data = f;
    F->solve = FN(sp_qr_solve);
    F->destroy = FN(sp_qr_free);
    F->work_len = (3 * rows + 2 * N + 2) * ENT_W;
    F->w = ENT_W;
    snprintf(F->method, sizeof F->method, FIELD_NAME "sparse Q-less QR (Givens), AMD(M'M), CSNE%s",
             f->under ? ", minimum norm" : "");
    if (f->nk < N)
        snprintf(F->note, sizeof F->note, "rank deficient: rank %lld of %lld", (long long)f->nk, (long long)N);
    /* Out of memory here fails the factorization: without ||R||_1 the
     * estimate would say "singular", without the estimate no warning. */
    double rn = 0.0, est, *rs = ref_calloc((size_t)f->nk + 1, sizeof(double));
    if (!rs) goto fail_factored;
    /* ||R||_1 = largest column sum of R = largest row sum of L */
    for (int64_t j = 0; j < f->nk; j++)
        for (int64_t p = f->L.p[j]; p < f->L.p[j + 1]; p++) rs[f->L.i[p]] += MOD(((const ENT *)f->L.x)[p]);
    for (int64_t j = 0; j < f->nk; j++) rn = fmax(rn, rs[j]);
    ref_free(rs);
    if ((est = INV_EST(f->nk, FN(r_apply), f, NULL)) < 0) goto fail_factored;
    F->cond = ref_cond_from(rn, est);
    if (f->nk < N && F->cond >= 0) F->cond = INFINITY;
    return 0;
fail_factored:
    F->data = NULL;
    st = SILC_ENOMEM;
fail:
    ref_sp_free(&At);
    ref_free(keep);
    FN(sp_qr_free)(f);
    return st;
}
