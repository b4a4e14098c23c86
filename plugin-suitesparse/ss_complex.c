/*
 * ss_complex.c -- complex values (ABI 1.8) on UMFPACK, KLU and CHOLMOD.
 *
 * SILC stores a complex value interleaved (re, im per entry), which is the
 * libraries' packed complex form: UMFPACK's umfpack_zl_* with Az = NULL,
 * KLU's klu_zl_*, CHOLMOD's CHOLMOD_COMPLEX xtype.  The zero-copy rule of
 * the real paths (ss.h) holds with one twist: the CSR arrays of A are the
 * compressed columns of M = A.' -- the plain transpose, not A' -- so
 *   A x = b     is  M.' x = b:        UMFPACK_Aat, klu_zl_tsolve(conj 0)
 *               (UMFPACK_A when A = A.', see umz_system);
 *   A^H x = b   is  conj(M) x = b, i.e. M conj(x) = conj(b): conjugate b,
 *               solve with M (UMFPACK_A, klu_zl_solve), conjugate x;
 * and a Hermitian A read by CHOLMOD (stype = 1) is seen as M = A.' =
 * conj(A), Hermitian too: CHOLMOD factors conj(A), and A x = b is solved
 * as conj(A) conj(x) = conj(b).  Conjugating a vector costs O(n); copying
 * A would cost O(nnz).
 *
 * The condition estimate is the host's complex Hager-Higham
 * (host->inv_norm1_est_complex, LAPACK zlacn2's algorithm) through these
 * solves, once per factorization; on a host without it the report says
 * "not estimated".  The symbolic cache of the real paths (ss.h) is not
 * used: a complex factorization analyses its pattern itself.
 */
#include "ss.h"

#include <klu.h>
#include <umfpack.h>

#include <complex.h>
#include <math.h>
#include <stdio.h>
#include <string.h>

#define UMZ_KEY "suitesparse.umfpack.zlu"
#define KLZ_KEY "suitesparse.klu.zlu"
#define CHZ_KEY "suitesparse.cholmod.zchol"

int ss_is_complex(const silc_value *v)
{
    return ss_host->struct_size >= SILC_HOST_NEEDS(field) && ss_host->field(v) == SILC_FIELD_COMPLEX;
}

static void conj_in_place(int64_t n, double *x)
{
    for (int64_t i = 0; i < n; i++) x[2 * i + 1] = -x[2 * i + 1];
}

/* B (m x k, any format) as a dense complex column-major array of n x k
 * entries (2 doubles each), freshly allocated. */
static double *rhs_complex(const silc_view *b)
{
    int64_t m = b->m, k = b->n;
    double complex *x = ss_host->calloc((size_t)(m > 0 ? m : 1) * (size_t)(k > 0 ? k : 1), sizeof *x);
    const double complex *v = (const double complex *)b->val;
    if (!x) return NULL;
    if (b->format == SILC_FMT_DENSE) {
        if (m > 0 && k > 0) memcpy(x, v, (size_t)(m * k) * sizeof *x);
    } else if (b->format == SILC_FMT_CSR) {
        for (int64_t i = 0; i < m; i++)
            for (int64_t p = b->rowptr[i]; p < b->rowptr[i + 1]; p++) x[i + b->colind[p] * m] += v[p];
    } else {
        for (int64_t j = 0; j < k; j++)
            for (int64_t i = j - b->ku > 0 ? j - b->ku : 0; i < m && i <= j + b->kl; i++)
                x[i + j * m] = v[(b->ku + i - j) + j * b->ld];
    }
    return (double *)x;
}

/* A new dense complex m x k value holding x (column-major, m rows). */
static silc_value *complex_value(silc_call *call, int64_t m, int64_t k, const double *x)
{
    silc_value *out = ss_host->dense_new_complex(m, k);
    silc_view o;
    if (!out) return NULL;
    ss_host->view(out, &o);
    if (m > 0 && k > 0) memcpy(o.val, x, (size_t)(m * k) * 2 * sizeof(double));
    (void)call;
    return out;
}

/* The condition estimate of a complex factorization, once, when wanted:
 * apply(ctx, x, trans, work) overwrites the n complex entries of x with
 * A^{-1} x (trans 0) or A^{-H} x (trans 1).  Owed like the real one's
 * (ss.h, ABI 1.8) when the host asks to leave it out and the backend may
 * (z_ops.owed): made by the condest_only call (complex_estimate_alone) when
 * the host finds it urgent or cheap, or when the report is read. */
#define SS_COMPLEX_EST_SOLVES 5 /* zlacn2: the start, two steps (A^-H, A^-1), the alternating vector */

/* The estimator's solves, those of its start vectors (e/n first, the
 * alternating vector last, both with imaginary parts 0: the columns of
 * ss_start_block's complex block X) taken from fi->start_solved when the
 * owed estimate's bound solved them. */
typedef struct z_cached {
    int (*apply)(void *ctx, double *x, int trans, double *work);
    void *ctx;
    ss_factor_info *fi;
    int64_t n;
    const double *X; /* the unsolved start block, 2n doubles a column; NULL: nothing kept */
} z_cached;

static int apply_cached(void *ctx, double *x, int trans, double *work)
{
    z_cached *c = ctx;
    size_t col = (size_t)c->n * 2;
    for (int j = 0; c->X && !trans && j < SS_EST_COLS; j++)
        if (!memcmp(x, c->X + col * (size_t)j, col * sizeof *x)) {
            memcpy(x, c->fi->start_solved + col * (size_t)j, col * sizeof *x);
            return 0;
        }
    return c->apply(c->ctx, x, trans, work);
}

/* The estimator's start block, e/n and the alternating vector, solved (two
 * solves) and kept in fi->start_solved: the owed estimate's rigorous lower
 * bound ||A||_1 max_j ||A^-1 x_j||_1 (ss_start_bound, as the real path's),
 * whose solves the estimate, when made, takes instead of repeating them.
 * Both columns, as for real matrices: e/n alone is 4e5 to 1e7 times weaker
 * where A^-1 e cancels (the Hilbert matrices of order 9-11, real or times
 * 1 + 1i; test_condest_auto), and their warnings came only with `info`.  A
 * solve that reuses the factorization takes the kept block's bound: no
 * solve.  -1 when out of memory or a solve fails. */
static double start_bound(silc_call *call, int64_t n, int (*apply)(void *ctx, double *x, int trans, double *work),
                          void *ctx, ss_factor_info *fi)
{
    size_t col = (size_t)n * 2;
    double *Y;
    if (fi->start_solved) return ss_start_bound(call, n, 2, fi->start_solved);
    if (!(Y = ss_host->alloc(col * SS_EST_COLS * sizeof *Y))) return -1;
    ss_start_block(n, 2, Y);
    for (int j = 0; j < SS_EST_COLS; j++)
        if (apply(ctx, Y + col * (size_t)j, 0, NULL)) {
            ss_host->free(Y);
            return -1;
        }
    fi->start_solved = Y;
    return ss_start_bound(call, n, 2, Y);
}

static void complex_cond(silc_call *call, int mode, int64_t n,
                         int (*apply)(void *ctx, double *x, int trans, double *work), void *ctx,
                         ss_factor_info *fi)
{
    double inv;
    size_t len;
    if (fi->estimated || !ss_condest_wanted(call, mode) || n <= 0) return;
    if (ss_condest_later(call) && !ss_condest_only(call)) return; /* owed (complex_solve) */
    if (ss_host->struct_size < SILC_HOST_NEEDS(inv_norm1_est_complex) || !ss_host->inv_norm1_est_complex)
        return; /* an older host: "not estimated" */
    {
        double *X = fi->start_solved ? ss_host->alloc((size_t)n * 2 * SS_EST_COLS * sizeof *X) : NULL;
        z_cached c = {apply, ctx, fi, n, X};
        if (X) ss_start_block(n, 2, X); /* out of memory: the kept solves are repeated */
        inv = ss_host->inv_norm1_est_complex(n, apply_cached, &c, NULL);
        ss_host->free(X);
    }
    ss_host->free(fi->start_solved);
    fi->start_solved = NULL;
    if (inv < 0) return;
    fi->cond = silc_props_of(ss_host, call->in[0], SILC_PROPS_NORMS)->norm1 * inv;
    fi->estimated = 1;
    len = strlen(fi->note);
    snprintf(fi->note + len, sizeof fi->note - len,
             "%s1-norm condition estimate: complex Hager/Higham through the factors", len ? "; " : "");
}

/* The common frame of the three solves: the factor attached under key (made
 * by make when absent), a complex copy of B solved in place column block by
 * column block by solve(), the estimate, the report. */
typedef struct z_ops {
    const char *key, *what;
    int (*make)(silc_call *call, const silc_view *a, void **out);
    void (*destroy)(void *F);
    ss_factor_info *(*info)(void *F);
    /* x (n x k complex) := A^{-1} x */
    int (*solve)(silc_call *call, void *F, const silc_view *a, double *x, int64_t k);
    int (*apply)(void *ctx, double *x, int trans, double *work); /* ctx = z_apply */
    /* Whether the estimate may be owed, and what tells the host it is
     * urgent (docs/accuracy.md): CHOLMOD's diagonal ratio (max L_ii / min
     * L_ii)^2 is a rigorous lower bound of cond_2 <= cond_1 for Hermitian
     * A = L L^H (condest_lower); UMFPACK's and KLU's pivot ratios, the
     * heuristic of the real path, were below 1e6 on mhd1280b (cond_1
     * 6e12), which lost its warning (tests/test_condest_auto.c), so they
     * solve the estimator's start block for a rigorous bound (start_bound),
     * two solves that the estimate then skips. */
    enum { Z_START_BOUND, Z_DIAG_BOUND } owed;
} z_ops;

typedef struct z_apply {
    void *F;
    const silc_view *a;
    const z_ops *ops;
} z_apply;

/* The condest_only call: the estimate alone with the factorization attached
 * to A (none: a decline, nothing is factored); its note alone in the report. */
static int complex_estimate_alone(silc_call *call, const z_ops *ops, const silc_view *a, int mode)
{
    void *F = a->n > 0 ? ss_host->attach_get(call->in[0], ops->key) : NULL;
    ss_factor_info *fi;
    size_t before;
    if (!F) return ss_no_factor(call, "suitesparse (complex)");
    fi = ops->info(F);
    before = strlen(fi->note);
    {
        z_apply u = {F, a, ops};
        complex_cond(call, mode, a->n, ops->apply, &u, fi);
    }
    call->report->cond_est = fi->estimated ? fi->cond : -1;
    snprintf(call->report->note, sizeof call->report->note, "%s",
             fi->note + before + (before && fi->note[before] == ';' ? 2 : 0));
    return SILC_OK;
}

static int complex_solve(silc_call *call, const z_ops *ops)
{
    silc_report *r = call->report;
    silc_view a, b;
    void *F = NULL;
    double *x, t0;
    int rc, condest;
    if ((rc = ss_square_solve_begin(call, &a, &b, &condest))) return rc;
    if (ss_condest_only(call)) return complex_estimate_alone(call, ops, &a, condest);
    if (!ss_is_complex(call->in[1]))
        return ss_host->error(call, SILC_EARG, "suitesparse: A is complex but b is real");
    if (a.n > 0 && (rc = ss_attached_factor(call, &a, ops->key, ops->make, ops->destroy, ops->what, &F)))
        return rc;
    t0 = ss_host->now();
    if (!(x = rhs_complex(&b))) return ss_nomem(call, "complex right-hand side");
    if (a.n > 0 && b.n > 0 && (rc = ops->solve(call, F, &a, x, b.n))) {
        ss_host->free(x);
        return rc;
    }
    call->out = complex_value(call, a.n, b.n, x);
    ss_host->free(x);
    if (!call->out) return ss_nomem(call, "complex result");
    r->solve_seconds = ss_host->now() - t0;
    if (F) {
        z_apply u = {F, &a, ops};
        ss_factor_info *fi = ops->info(F);
        complex_cond(call, condest, a.n, ops->apply, &u, fi);
        ss_report_factor(r, fi);
        if (!fi->estimated && ss_condest_wanted(call, condest) && ss_condest_later(call)) {
            r->condest_deferred = 1;
            r->condest_solves = (double)SS_COMPLEX_EST_SOLVES / (double)(b.n > 0 ? b.n : 1);
            if (ops->owed == Z_DIAG_BOUND) {
                r->condest_lower = fi->pivot_ratio; /* 0, none: the host's own bound */
            } else if (a.n > 0 && r->condest_later != 2) { /* 2: on_request wants no bound */
                /* without the bound an ill-conditioned matrix could go unwarned */
                if ((r->condest_lower = start_bound(call, a.n, ops->apply, &u, fi)) < 0) {
                    ss_host->release(call->out);
                    call->out = NULL;
                    return ss_nomem(call, "the condition estimate's start");
                }
                r->condest_solves = (double)(SS_COMPLEX_EST_SOLVES - SS_EST_COLS) / (double)(b.n > 0 ? b.n : 1);
            }
        }
    }
    return SILC_OK;
}

/* ---- UMFPACK ------------------------------------------------------------------ */

typedef struct umz_factor {
    void *numeric;
    ss_factor_info info;
} umz_factor;

static void umz_free(void *p)
{
    umz_factor *F = p;
    if (!F) return;
    if (F->numeric) umfpack_zl_free_numeric(&F->numeric);
    ss_host->free(F->info.start_solved);
    ss_host->free(F);
}

static ss_factor_info *umz_info(void *F) { return &((umz_factor *)F)->info; }

static int umz_fail(silc_call *call, const char *fn, int status)
{
    int st = status == UMFPACK_WARNING_singular_matrix ? SILC_ESINGULAR
             : status == UMFPACK_ERROR_out_of_memory  ? SILC_ENOMEM
                                                      : SILC_ELIB;
    return ss_host->error(call, st, "%s: %s (status %d)", fn,
                          status == UMFPACK_WARNING_singular_matrix ? "singular matrix" : "failed", status);
}

static int umz_make(silc_call *call, const silc_view *a, void **out)
{
    double control[UMFPACK_CONTROL], info[UMFPACK_INFO];
    void *symbolic = NULL;
    umz_factor *F = ss_host->calloc(1, sizeof *F);
    int st;
    if (!F) return ss_nomem(call, "UMFPACK complex factor");
    umfpack_zl_defaults(control);
    /* M = A.' in compressed columns: n_row = n_col = n, packed complex (Az = NULL). */
    st = (int)umfpack_zl_symbolic(a->n, a->m, a->rowptr, a->colind, a->val, NULL, &symbolic, control, info);
    if (st != UMFPACK_OK) {
        ss_host->free(F);
        return umz_fail(call, "umfpack_zl_symbolic", st);
    }
    st = (int)umfpack_zl_numeric(a->rowptr, a->colind, a->val, NULL, symbolic, &F->numeric, control, info);
    umfpack_zl_free_symbolic(&symbolic);
    if (st != UMFPACK_OK) {
        umz_free(F);
        return umz_fail(call, "umfpack_zl_numeric", st);
    }
    F->info.rcond = info[UMFPACK_RCOND];
    ss_pivot_ratio(&F->info);
    snprintf(F->info.method, sizeof F->info.method, "complex sparse LU (UMFPACK, umfpack_zl)");
    *out = F;
    return SILC_OK;
}

/* One column: x := (sys solve of M) x, with UMFPACK's refinement (irstep). */
static int umz_column(umz_factor *F, const silc_view *a, long sys, double *x, double *y, int64_t irstep)
{
    double control[UMFPACK_CONTROL], info[UMFPACK_INFO];
    int st;
    umfpack_zl_defaults(control);
    control[UMFPACK_IRSTEP] = (double)(irstep < 0 ? 0 : irstep);
    st = (int)umfpack_zl_solve(sys, a->rowptr, a->colind, a->val, NULL, y, NULL, x, NULL, F->numeric, control,
                               info);
    if (st != UMFPACK_OK) return st;
    memcpy(x, y, (size_t)a->n * 2 * sizeof(double));
    return UMFPACK_OK;
}

/* A x = b is M.' x = b (UMFPACK_Aat), but for a complex symmetric A (A =
 * A.', the Helmholtz operator with an absorbing boundary) M = A, and the
 * same system is M x = b (UMFPACK_A), which is what Octave's `\` solves.
 * The two differ only in UMFPACK's refinement: UMFPACK_A refines the row-
 * scaled system the factorization was made for, UMFPACK_Aat the unscaled
 * transpose, and on the bench's 500 x 500 Helmholtz the first stops after
 * one step (backward error 2.2e-16) where the second takes both (one more
 * triangular solve and residual, about 0.1 s of a 4.4 s solve).  The
 * symmetry walk is O(nnz) once per value (the properties are kept). */
static long umz_system(silc_call *call)
{
    return silc_props_of(ss_host, call->in[0], SILC_PROPS_SYMMETRY)->symmetric ? UMFPACK_A : UMFPACK_Aat;
}

static int umz_solve(silc_call *call, void *f, const silc_view *a, double *x, int64_t k)
{
    int64_t irstep, n = a->n;
    double *y = ss_host->alloc((size_t)n * 2 * sizeof(double));
    int rc = SILC_OK, st;
    long sys;
    if (!y) return ss_nomem(call, "UMFPACK complex solve");
    if ((rc = ss_host->option_int(call, "umfpack_irstep", 2, &irstep))) {
        ss_host->free(y);
        return rc;
    }
    sys = umz_system(call);
    for (int64_t j = 0; j < k && rc == SILC_OK; j++)
        if ((st = umz_column(f, a, sys, x + 2 * j * n, y, irstep)) != UMFPACK_OK)
            rc = umz_fail(call, "umfpack_zl_solve", st);
    ss_host->free(y);
    return rc;
}

static int umz_apply(void *ctx, double *x, int trans, double *work)
{
    z_apply *u = ctx;
    int64_t n = u->a->n;
    double *y = ss_host->alloc((size_t)n * 2 * sizeof(double));
    int st;
    (void)work;
    if (!y) return -1;
    if (trans) conj_in_place(n, x);
    st = umz_column(u->F, u->a, trans ? UMFPACK_A : UMFPACK_Aat, x, y, 0);
    if (trans) conj_in_place(n, x);
    ss_host->free(y);
    return st == UMFPACK_OK ? 0 : -1;
}

static const z_ops umz_ops = {UMZ_KEY, "attaching the UMFPACK complex factors", umz_make, umz_free, umz_info,
                              umz_solve, umz_apply, Z_START_BOUND};

int ss_umfpack_solve_complex(silc_call *call)
{
    return complex_solve(call, &umz_ops);
}

/* ---- KLU ---------------------------------------------------------------------- */

typedef struct klz_factor {
    klu_l_symbolic *S;
    klu_l_numeric *N;
    ss_factor_info info;
} klz_factor;

static void klz_free(void *p)
{
    klz_factor *F = p;
    klu_l_common c;
    if (!F) return;
    klu_l_defaults(&c);
    if (F->N) klu_zl_free_numeric(&F->N, &c);
    if (F->S) klu_l_free_symbolic(&F->S, &c);
    ss_host->free(F->info.start_solved);
    ss_host->free(F);
}

static ss_factor_info *klz_info(void *F) { return &((klz_factor *)F)->info; }

static int klz_fail(silc_call *call, const char *fn, const klu_l_common *c)
{
    int s = (int)c->status;
    return ss_host->error(call, s == KLU_SINGULAR ? SILC_ESINGULAR : s == KLU_OUT_OF_MEMORY ? SILC_ENOMEM : SILC_ELIB,
                          "%s: %s (status %d)", fn, s == KLU_SINGULAR ? "singular matrix" : "failed", s);
}

static int klz_make(silc_call *call, const silc_view *a, void **out)
{
    klu_l_common c;
    klz_factor *F = ss_host->calloc(1, sizeof *F);
    if (!F) return ss_nomem(call, "KLU complex factor");
    klu_l_defaults(&c);
    /* The analysis reads the pattern only: klu_l_analyze serves both fields. */
    if (!(F->S = klu_l_analyze(a->n, a->rowptr, a->colind, &c))) {
        klz_free(F);
        return klz_fail(call, "klu_l_analyze", &c);
    }
    F->N = klu_zl_factor(a->rowptr, a->colind, a->val, F->S, &c);
    if (!F->N || !klu_zl_rcond(F->S, F->N, &c)) {
        int rc = klz_fail(call, F->N ? "klu_zl_rcond" : "klu_zl_factor", &c);
        klz_free(F);
        return rc;
    }
    F->info.rcond = c.rcond;
    ss_pivot_ratio(&F->info);
    snprintf(F->info.method, sizeof F->info.method, "complex sparse LU (KLU, klu_zl, BTF + AMD, %lld block%s)",
             (long long)F->S->nblocks, F->S->nblocks == 1 ? "" : "s");
    *out = F;
    return SILC_OK;
}

static int klz_solve(silc_call *call, void *f, const silc_view *a, double *x, int64_t k)
{
    klz_factor *F = f;
    klu_l_common c;
    klu_l_defaults(&c);
    if (!klu_zl_tsolve(F->S, F->N, a->n, k, x, 0, &c)) return klz_fail(call, "klu_zl_tsolve", &c);
    return SILC_OK;
}

static int klz_apply(void *ctx, double *x, int trans, double *work)
{
    z_apply *u = ctx;
    klz_factor *F = u->F;
    klu_l_common c;
    int ok;
    (void)work;
    klu_l_defaults(&c);
    if (!trans) return klu_zl_tsolve(F->S, F->N, u->a->n, 1, x, 0, &c) ? 0 : -1;
    conj_in_place(u->a->n, x);
    ok = (int)klu_zl_solve(F->S, F->N, u->a->n, 1, x, &c);
    conj_in_place(u->a->n, x);
    return ok ? 0 : -1;
}

static const z_ops klz_ops = {KLZ_KEY, "attaching the KLU complex factors", klz_make, klz_free, klz_info,
                              klz_solve, klz_apply, Z_START_BOUND};

int ss_klu_solve_complex(silc_call *call)
{
    return complex_solve(call, &klz_ops);
}

/* ---- CHOLMOD ------------------------------------------------------------------ */

typedef struct chz_factor {
    cholmod_factor *L;
    ss_factor_info info;
} chz_factor;

static void chz_free(void *p)
{
    chz_factor *F = p;
    if (!F) return;
    ss_lock();
    if (F->L) cholmod_l_free_factor(&F->L, ss_cholmod_common());
    ss_unlock();
    ss_host->free(F);
}

static ss_factor_info *chz_info(void *F) { return &((chz_factor *)F)->info; }

static int chz_make(silc_call *call, const silc_view *a, void **out)
{
    cholmod_common *cc = ss_cholmod_common();
    cholmod_sparse A;
    chz_factor *F = ss_host->calloc(1, sizeof *F);
    int status;
    long long minor = 0;
    if (!F) return ss_nomem(call, "CHOLMOD complex factor");
    memset(&A, 0, sizeof A);
    A.nrow = (size_t)a->n, A.ncol = (size_t)a->m, A.nzmax = (size_t)a->rowptr[a->m];
    A.p = a->rowptr, A.i = a->colind, A.x = a->val;
    A.stype = 1, A.itype = CHOLMOD_LONG, A.xtype = CHOLMOD_COMPLEX, A.dtype = CHOLMOD_DOUBLE;
    A.sorted = 1, A.packed = 1;
    ss_lock();
    F->L = cholmod_l_analyze(&A, cc);
    if (F->L) ss_cholmod_factorize(&A, F->L, cc);
    status = cc->status;
    if (F->L) minor = (long long)F->L->minor;
    F->info.rcond = F->L && status == CHOLMOD_OK ? cholmod_l_rcond(F->L, cc) : 0;
    ss_unlock();
    if (status == CHOLMOD_NOT_POSDEF) {
        chz_free(F);
        return ss_host->error(call, SILC_ENOTSPD,
                              "cholmod_l_factorize: complex matrix not positive definite (status %d, leading "
                              "minor of order %lld)", status, minor + 1);
    }
    if (!F->L || status < CHOLMOD_OK) {
        chz_free(F);
        return ss_host->error(call, status == CHOLMOD_OUT_OF_MEMORY ? SILC_ENOMEM : SILC_ELIB,
                              "cholmod_l_factorize (complex): failed (status %d)", status);
    }
    ss_pivot_ratio(&F->info);
    snprintf(F->info.method, sizeof F->info.method, "complex Hermitian sparse Cholesky (CHOLMOD, %s)",
             F->L->is_super ? "supernodal" : "simplicial");
    *out = F;
    return SILC_OK;
}

/* x := A^{-1} x for k columns: CHOLMOD holds conj(A)'s factor (above). */
static int chz_solve(silc_call *call, void *f, const silc_view *a, double *x, int64_t k)
{
    chz_factor *F = f;
    cholmod_common *cc = ss_cholmod_common();
    cholmod_dense B, *X;
    int64_t n = a->n;
    int status, ok;
    memset(&B, 0, sizeof B);
    B.nrow = (size_t)n, B.ncol = (size_t)k, B.nzmax = (size_t)(n * k), B.d = (size_t)n;
    B.x = x, B.xtype = CHOLMOD_COMPLEX, B.dtype = CHOLMOD_DOUBLE;
    conj_in_place(n * k, x);
    ss_lock();
    X = cholmod_l_solve(CHOLMOD_A, F->L, &B, cc);
    status = cc->status;
    ok = X != NULL;
    if (ok) {
        for (int64_t j = 0; j < k; j++)
            memcpy(x + 2 * j * n, (double *)X->x + 2 * j * (int64_t)X->d, (size_t)n * 2 * sizeof(double));
        cholmod_l_free_dense(&X, cc);
    }
    ss_unlock();
    conj_in_place(n * k, x);
    if (!ok) {
        if (call) return ss_host->error(call, SILC_ELIB, "cholmod_l_solve (complex): failed (status %d)", status);
        return SILC_ELIB;
    }
    return SILC_OK;
}

/* A is Hermitian: A^{-H} = A^{-1}. */
static int chz_apply(void *ctx, double *x, int trans, double *work)
{
    z_apply *u = ctx;
    (void)trans, (void)work;
    return chz_solve(NULL, u->F, u->a, x, 1) ? -1 : 0;
}

static const z_ops chz_ops = {CHZ_KEY, "attaching the CHOLMOD complex factor", chz_make, chz_free, chz_info,
                              chz_solve, chz_apply, Z_DIAG_BOUND};

int ss_cholmod_solve_complex(silc_call *call)
{
    return complex_solve(call, &chz_ops);
}
