/*
 * lis_precond_t.h -- the preconditioners' arithmetic, written once over
 * lis_field.h's ENT / MOD / RE / FN and included by lis_precond.c once real
 * (double: the names without suffix) and once complex (double complex,
 * the _z names): the growing CSR rows, the incomplete factorizations
 * (ILU(k), IC(0), ILUT), the diagonal, the setup of Jacobi / SSOR / the
 * factorizations with Manteuffel's shifts, and M^-1 x.  lis_precond.c says
 * what each preconditioner is.  In complex arithmetic pivots and drops are
 * judged by modulus and a shift moves a diagonal entry along its own
 * direction (a_ii / |a_ii|), which for a real a_ii is its sign; IC(0) is
 * built for real matrices only (a complex Hermitian one would need L^H).
 */

/* ---- growing CSR rows ---------------------------------------------------------- */

typedef struct FN(rows) {
    int64_t *p, *i;
    ENT *x;
    int *lev;                   /* ILU(k): level of each entry (U only) */
    int64_t nnz, cap;
} FN(rows);

static int FN(rows_init)(FN(rows) *R, int64_t n, int64_t cap, int levels)
{
    memset(R, 0, sizeof *R);
    R->cap = cap > 16 ? cap : 16;
    R->p = lis_array((size_t)n + 1, sizeof(int64_t));
    R->i = lis_array((size_t)R->cap, sizeof(int64_t));
    R->x = lis_array((size_t)R->cap, sizeof(ENT));
    R->lev = levels ? lis_array((size_t)R->cap, sizeof(int)) : NULL;
    if (!R->p || !R->i || !R->x || (levels && !R->lev)) return -1;
    R->p[0] = 0;
    return 0;
}

static void FN(rows_free)(FN(rows) *R)
{
    xfree(R->p);
    xfree(R->i);
    xfree(R->x);
    xfree(R->lev);
    memset(R, 0, sizeof *R);
}

static int FN(rows_push)(FN(rows) *R, int64_t j, ENT x, int lev)
{
    if (R->nnz == R->cap) {
        int64_t cap = R->cap * 2;
        int64_t *ni = lis_host->realloc(R->i, (size_t)cap * sizeof(int64_t));
        ENT *nx;
        int *nl;
        if (!ni) return -1;
        R->i = ni;
        nx = lis_host->realloc(R->x, (size_t)cap * sizeof(ENT));
        if (!nx) return -1;
        R->x = nx;
        if (R->lev) {
            nl = lis_host->realloc(R->lev, (size_t)cap * sizeof(int));
            if (!nl) return -1;
            R->lev = nl;
        }
        R->cap = cap;
    }
    R->i[R->nnz] = j;
    R->x[R->nnz] = x;
    if (R->lev) R->lev[R->nnz] = lev;
    R->nnz++;
    return 0;
}

/* ---- the incomplete factorizations ---------------------------------------------- */

typedef struct FN(work) {
    ENT *w;                     /* the row being eliminated, dense */
    int *lev;
    int64_t *next, *mark;       /* sorted linked list of the row's columns */
    int64_t *cand;              /* ILUT: candidates for keeping */
} FN(work);

/* The diagonal shift of row i: alpha times |a_ii|, or the largest |a_ij| if
 * the diagonal is zero, in the direction of a_ii (its sign, when real). */
static ENT FN(shift_of)(const lk_csr *A, int64_t i, ENT aii, double alpha)
{
    const ENT *v = (const ENT *)A->v;
    double s = MOD(aii);
    if (alpha == 0) return 0;
    if (s == 0)
        for (int64_t k = A->rp[i]; k < A->rp[i + 1]; k++) {
            double a = MOD(v[k]);
            if (a > s) s = a;
        }
    if (aii == 0) return alpha * s;
    return alpha * s * (aii / MOD(aii));
}

typedef struct FN(cand) {
    int64_t j;
    ENT x;
} FN(cand);

static int FN(by_size)(const void *a, const void *b)
{
    double x = MOD(((const FN(cand) *)a)->x), y = MOD(((const FN(cand) *)b)->x);
    return (x < y) - (x > y);
}

static int FN(by_column)(const void *a, const void *b)
{
    int64_t x = ((const FN(cand) *)a)->j, y = ((const FN(cand) *)b)->j;
    return (x > y) - (x < y);
}

/* Keeps at most p of the c candidates (largest first), in column order. */
static int64_t FN(keep_largest)(FN(cand) *c, int64_t count, int64_t p)
{
    if (count > p) {
        qsort(c, (size_t)count, sizeof *c, FN(by_size));
        count = p;
    }
    qsort(c, (size_t)count, sizeof *c, FN(by_column));
    return count;
}

/* One incomplete factorization with diagonal shift alpha.  kind is ILU (with
 * fill level `fill`), IC (ILU(0) + positive pivots) or ILUT.  On a bad pivot
 * returns FACT_PIVOT with its row in *bad_row. */
static int FN(factor)(const lk_csr *A, int kind, int fill, double drop, double rate, double alpha,
                      lis_pc *P, int64_t *bad_row)
{
    const ENT *av = (const ENT *)A->v;
    int64_t n = A->m, i;
    FN(rows) L, U;
    FN(work) W;
    FN(cand) *cs = NULL;
    int rc = FACT_NOMEM, levels = kind == LIS_PC_ILU && fill > 0;
    ENT *dinv = lis_array((size_t)n, sizeof(ENT));
    memset(&W, 0, sizeof W);
    W.w = lis_array((size_t)n, sizeof(ENT));
    W.lev = lis_array((size_t)n, sizeof(int));
    W.next = lis_array((size_t)n + 1, sizeof(int64_t));
    W.mark = lis_array((size_t)n, sizeof(int64_t));
    cs = lis_array((size_t)n, sizeof(FN(cand)));
    if (FN(rows_init)(&L, n, A->rp[n] / 2 + n, 0) || FN(rows_init)(&U, n, A->rp[n] / 2 + n, levels) ||
        !dinv || !W.w || !W.lev || !W.next || !W.mark || !cs)
        goto done;
    for (i = 0; i < n; i++) W.mark[i] = -1;
    for (i = 0; i < n; i++) {
        /* The list head is the sentinel slot n; columns are 0..n-1. */
        const int64_t head = n;
        int64_t tail = head, k, nrow = A->rp[i + 1] - A->rp[i], count;
        double rownorm = 0, rowmax = 0, tau;
        ENT d;
        int have_diag = 0;
        W.next[head] = -1;
        for (k = A->rp[i]; k < A->rp[i + 1]; k++) {
            int64_t j = A->ci[k];
            ENT a = av[k];
            if (W.mark[j] == i) { W.w[j] += a; continue; } /* duplicate entry */
            W.mark[j] = i;
            W.w[j] = a;
            W.lev[j] = 0;
            W.next[j] = -1;
            W.next[tail] = j;
            tail = j;
            if (j == i) have_diag = 1;
            rownorm += MOD(a) * MOD(a);
            if (MOD(a) > rowmax) rowmax = MOD(a);
        }
        if (!have_diag) {
            W.mark[i] = i;
            W.w[i] = 0;
            W.lev[i] = 0;
            list_insert(W.next, head, i);
        }
        W.w[i] += FN(shift_of)(A, i, W.w[i], alpha);
        tau = drop * sqrt(rownorm);
        /* Eliminate with the rows above, in increasing column order; fill
         * entries are inserted after the current position, so they are
         * eliminated in turn. */
        for (k = W.next[head]; k != -1 && k < i; k = W.next[k]) {
            ENT lik = W.w[k] * dinv[k];
            W.w[k] = lik;
            if (kind == LIS_PC_ILUT && MOD(lik) < tau) {
                W.w[k] = 0;
                continue;
            }
            for (int64_t q = U.p[k]; q < U.p[k + 1]; q++) {
                int64_t j = U.i[q];
                int lev = W.lev[k] + (levels ? U.lev[q] : 0) + 1;
                if (W.mark[j] == i) {
                    W.w[j] -= lik * U.x[q];
                    if (lev < W.lev[j]) W.lev[j] = lev;
                } else if (kind == LIS_PC_ILUT || lev <= fill) {
                    W.mark[j] = i;
                    W.w[j] = -lik * U.x[q];
                    W.lev[j] = lev;
                    list_insert(W.next, k, j);
                }
            }
        }
        /* Gather L, the pivot and U. */
        d = W.w[i];
        count = 0;
        for (k = W.next[head]; k != -1 && k < i; k = W.next[k]) {
            if (kind == LIS_PC_ILUT) {
                if (W.w[k] != 0) cs[count].j = k, cs[count++].x = W.w[k];
            } else if (FN(rows_push)(&L, k, W.w[k], 0)) {
                goto done;
            }
        }
        if (kind == LIS_PC_ILUT) {
            int64_t p = (int64_t)ceil(rate * (double)nrow / 2), c;
            if (p < 1) p = 1;
            count = FN(keep_largest)(cs, count, p);
            for (c = 0; c < count; c++)
                if (FN(rows_push)(&L, cs[c].j, cs[c].x, 0)) goto done;
            count = 0;
            for (; k != -1; k = W.next[k])
                if (k > i && MOD(W.w[k]) >= tau)
                    cs[count].j = k, cs[count++].x = W.w[k];
            count = FN(keep_largest)(cs, count, p);
            for (c = 0; c < count; c++)
                if (FN(rows_push)(&U, cs[c].j, cs[c].x, 0)) goto done;
        } else {
            for (; k != -1; k = W.next[k])
                if (k > i && FN(rows_push)(&U, k, W.w[k], W.lev[k])) goto done;
        }
        L.p[i + 1] = L.nnz;
        U.p[i + 1] = U.nnz;
        if (!isfinite(RE(d)) || !isfinite(MOD(d)) ||
            (kind == LIS_PC_IC ? !(RE(d) > 1e-14 * rowmax) : !(MOD(d) > 1e-14 * rowmax))) {
            *bad_row = i;
            rc = FACT_PIVOT;
            goto done;
        }
        dinv[i] = 1.0 / d;
    }
    if (kind == LIS_PC_IC) {
        /* U = D L': the transpose of L by counting, scaled by the pivots. */
        int64_t *cnt = lis_array((size_t)n + 1, sizeof(int64_t));
        if (!cnt) goto done;
        U.nnz = L.nnz;
        if (U.cap < L.nnz) {
            int64_t *ni = lis_host->realloc(U.i, (size_t)L.nnz * sizeof(int64_t));
            ENT *nx = ni ? lis_host->realloc(U.x, (size_t)L.nnz * sizeof(ENT)) : NULL;
            if (ni) U.i = ni;
            if (nx) U.x = nx;
            if (!ni || !nx) {
                xfree(cnt);
                goto done;
            }
            U.cap = L.nnz;
        }
        memset(cnt, 0, ((size_t)n + 1) * sizeof(int64_t));
        for (i = 0; i < L.nnz; i++) cnt[L.i[i] + 1]++;
        for (i = 0; i < n; i++) cnt[i + 1] += cnt[i];
        memcpy(U.p, cnt, ((size_t)n + 1) * sizeof(int64_t));
        for (i = 0; i < n; i++)
            for (int64_t q = L.p[i]; q < L.p[i + 1]; q++) {
                int64_t j = L.i[q], at = cnt[j]++;
                U.i[at] = i;
                U.x[at] = L.x[q] / dinv[j];
            }
        xfree(cnt);
    }
    P->lp = L.p, P->li = L.i, P->lx = (double *)L.x;
    P->up = U.p, P->ui = U.i, P->ux = (double *)U.x;
    xfree(U.lev);
    P->dinv = (double *)dinv;
    P->nnz = L.nnz + U.nnz + n;
    dinv = NULL;
    memset(&L, 0, sizeof L);
    memset(&U, 0, sizeof U);
    rc = FACT_OK;
done:
    FN(rows_free)(&L);
    FN(rows_free)(&U);
    xfree(dinv);
    xfree(W.w);
    xfree(W.lev);
    xfree(W.next);
    xfree(W.mark);
    xfree(cs);
    return rc;
}

/* ---- building ---------------------------------------------------------------------- */

int FN(lis_diagonal)(const lk_csr *A, ENT *d, const char *what, char *err, size_t errlen)
{
    const ENT *v = (const ENT *)A->v;
    for (int64_t i = 0; i < A->m; i++) {
        d[i] = 0;
        for (int64_t k = A->rp[i]; k < A->rp[i + 1]; k++)
            if (A->ci[k] == i) d[i] += v[k];
        if (d[i] == 0 || !isfinite(MOD(d[i]))) {
            snprintf(err, errlen, "lis-style %s: zero diagonal entry in row %lld", what,
                     (long long)i + 1);
            return -1;
        }
    }
    return 0;
}

/* Jacobi, SSOR and the incomplete factorizations into P (SA-AMG is the
 * real driver's, lis_pc_build). */
static int FN(pc_setup)(const lk_csr *A, const lis_options *o, lis_pc *P, const char *label, char *err,
                        size_t errlen)
{
    static const double shifts[] = {0, 1e-3, 1e-2, 1e-1, 1};
    if (o->precon == LIS_PC_JACOBI || o->precon == LIS_PC_SSOR) {
        ENT *dinv = lis_array((size_t)A->m, sizeof(ENT));
        P->dinv = (double *)dinv;
        if (!dinv) return snprintf(err, errlen, "lis-style: out of memory for the preconditioner"), SILC_ENOMEM;
        if (FN(lis_diagonal)(A, dinv, label, err, errlen)) return SILC_EBREAKDOWN;
        for (int64_t i = 0; i < A->m; i++) dinv[i] = 1.0 / dinv[i];
        P->A = *A;
        P->omega = o->ssor_omega;
        P->nnz = o->precon == LIS_PC_SSOR ? A->rp[A->m] : A->m;
    } else {
        size_t s;
        int64_t bad = -1;
        int rc = FACT_PIVOT;
        for (s = 0; s < sizeof shifts / sizeof *shifts && rc == FACT_PIVOT; s++) {
            int fill = o->precon == LIS_PC_IC ? 0 : o->ilu_fill;
            rc = FN(factor)(A, o->precon, fill, o->ilut_drop, o->ilut_rate, shifts[s], P, &bad);
            P->shift = shifts[s];
        }
        if (rc == FACT_NOMEM) return snprintf(err, errlen, "lis-style %s: out of memory", label), SILC_ENOMEM;
        if (rc == FACT_PIVOT) {
            snprintf(err, errlen, "lis-style %s: %s pivot in row %lld even with diagonal shift %g",
                     label, o->precon == LIS_PC_IC ? "non-positive" : "zero", (long long)bad + 1,
                     shifts[sizeof shifts / sizeof *shifts - 1]);
            return SILC_EBREAKDOWN;
        }
    }
    return SILC_OK;
}

/* ---- applying ----------------------------------------------------------------------- */

/* y = M^-1 x for Jacobi, SSOR and the factorizations. */
static void FN(pc_apply)(const lis_pc *P, const ENT *x, ENT *y)
{
    int64_t n = P->n, i, k;
    const ENT *dinv = (const ENT *)P->dinv;
    if (P->kind == LIS_PC_JACOBI) {
        for (i = 0; i < n; i++) y[i] = x[i] * dinv[i];
    } else if (P->kind == LIS_PC_SSOR) {
        /* M = (D + wL) D^-1 (D + wU) / (w (2 - w)). */
        const lk_csr *A = &P->A;
        const ENT *av = (const ENT *)A->v;
        double w = P->omega, c = w * (2 - w);
        for (i = 0; i < n; i++) {
            ENT s = c * x[i];
            for (k = A->rp[i]; k < A->rp[i + 1] && A->ci[k] < i; k++) s -= w * av[k] * y[A->ci[k]];
            y[i] = s * dinv[i];
        }
        for (i = 0; i < n; i++) y[i] /= dinv[i];
        for (i = n - 1; i >= 0; i--) {
            ENT s = y[i];
            for (k = A->rp[i + 1] - 1; k >= A->rp[i] && A->ci[k] > i; k--) s -= w * av[k] * y[A->ci[k]];
            y[i] = s * dinv[i];
        }
    } else {
        /* (I + L) t = x, then (D + U) y = t. */
        const ENT *lx = (const ENT *)P->lx, *ux = (const ENT *)P->ux;
        for (i = 0; i < n; i++) {
            ENT s = x[i];
            for (k = P->lp[i]; k < P->lp[i + 1]; k++) s -= lx[k] * y[P->li[k]];
            y[i] = s;
        }
        for (i = n - 1; i >= 0; i--) {
            ENT s = y[i];
            for (k = P->up[i]; k < P->up[i + 1]; k++) s -= ux[k] * y[P->ui[k]];
            y[i] = s * dinv[i];
        }
    }
}
