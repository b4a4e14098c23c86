/*
 * ss_common.c -- helpers the four SuiteSparse backends share.
 *
 * Operands (accept tests, right-hand sides, results), the one cholmod_common
 * of the plugin and the lock that guards it, the pattern-keyed cache of
 * symbolic analyses (see ss.h for why it exists), and a Hager/Higham 1-norm
 * condition estimator for the "condest" option.  The plugin state is per
 * process, while SILC calls a context from one thread at a time: two
 * contexts in two threads may call in together, hence the lock.
 */
#include "ss.h"

#include <math.h>
#ifdef _OPENMP
#include <omp.h>
#endif
#include <pthread.h>
#include <stdio.h>
#include <stddef.h>
#include <stdlib.h>
#include <string.h>

static pthread_mutex_t ss_mutex = PTHREAD_MUTEX_INITIALIZER;
static cholmod_common ss_cc;
static ss_symbolic *ss_cache[SS_NCACHE];
/* The estimator's start block of the last size (ss_start_block). */
static double *ss_start_kept;
static int64_t ss_start_kept_n = -1;

void ss_lock(void)
{
    pthread_mutex_lock(&ss_mutex);
}

void ss_unlock(void)
{
    pthread_mutex_unlock(&ss_mutex);
}

cholmod_common *ss_cholmod_common(void)
{
    return &ss_cc;
}

int ss_start(void)
{
    if (!cholmod_l_start(&ss_cc)) return -1;
    /* CHOLMOD prints its errors and warnings (print level 3) by default; SILC
     * reports them as statuses instead, so keep it quiet. */
    ss_cc.print = 0;
    ss_cc.error_handler = NULL;
    /* Keep L in LL' form, also when CHOLMOD picks a simplicial factorization:
     * its LDL' would go through an indefinite matrix without a complaint,
     * and the .spd classes rely on Cholesky failing there. */
    ss_cc.final_ll = 1;
    return 0;
}

/* SILC's thread count for this plugin's libraries (set_threads). */
static volatile int ss_threads = 1;

void ss_set_omp_threads(int nthreads)
{
    ss_threads = nthreads;
}

/*
 * CHOLMOD's supernodal factorization clears and fills its supernodes in
 * OpenMP regions of CHOLMOD_OMP_NUM_THREADS threads, a constant of its build
 * (4 in Debian's), whatever omp_set_num_threads or OMP_NUM_THREADS say.  So
 * with SILC's thread count at 1 a factorization still woke three more
 * threads, on this 2-core VM about 70 ms of the 200 x 200 diffusion
 * matrix's first solve (220-330 ms) in CPU time (docs/backends.md).
 * max-active-levels 0 makes every region run on the calling thread alone;
 * the previous value is given back at the end.  The setting is the
 * process's: a region that another thread of the program opens during the
 * factorization runs on one thread too (slower, for that while).
 */
void ss_cholmod_factorize(cholmod_sparse *A, cholmod_factor *L, cholmod_common *cc)
{
#ifdef _OPENMP
    int was = omp_get_max_active_levels();
    if (ss_threads <= 1) omp_set_max_active_levels(0);
    cholmod_l_factorize(A, L, cc);
    omp_set_max_active_levels(was);
#else
    cholmod_l_factorize(A, L, cc);
#endif
}

void ss_finish(void)
{
    int s;
    ss_lock();
    for (s = 0; s < SS_NCACHE; s++) {
        ss_symbolic *e = ss_cache[s];
        ss_cache[s] = NULL;
        if (e) {
            ss_unlock();
            ss_sym_release(e);
            ss_lock();
        }
    }
    cholmod_l_finish(&ss_cc);
    free(ss_start_kept);
    ss_start_kept = NULL;
    ss_start_kept_n = -1;
    ss_unlock();
}

int ss_nomem(silc_call *call, const char *what)
{
    return ss_host->error(call, SILC_ENOMEM, "suitesparse: out of memory (%s)", what);
}

int ss_ends_with(const char *s, const char *suffix)
{
    size_t a, b;
    if (!s) return 0;
    a = strlen(s);
    b = strlen(suffix);
    return a >= b && strcmp(s + a - b, suffix) == 0;
}

int ss_accepts_csr(const silc_call *call, int square, const char **why)
{
    silc_view a;
    if (call->nin < 2) {
        *why = "needs a matrix and a right-hand side";
        return 0;
    }
    ss_host->view(call->in[0], &a);
    if (a.format != SILC_FMT_CSR) {
        *why = "needs a sparse (CSR) matrix";
        return 0;
    }
    if (square && a.m != a.n) {
        *why = "needs a square matrix";
        return 0;
    }
    return 1;
}

/* ---- operands --------------------------------------------------------------- */

void ss_rhs_copy(const silc_view *b, double *x)
{
    int64_t m = b->m, k = b->n, i, j;
    if (b->format == SILC_FMT_DENSE) {
        if (m > 0 && k > 0) memcpy(x, b->val, (size_t)(m * k) * sizeof(double));
    } else if (b->format == SILC_FMT_CSR) {
        memset(x, 0, (size_t)(m * k) * sizeof(double));
        for (i = 0; i < m; i++)
            for (j = b->rowptr[i]; j < b->rowptr[i + 1]; j++) x[i + b->colind[j] * m] += b->val[j];
    } else {
        memset(x, 0, (size_t)(m * k) * sizeof(double));
        for (j = 0; j < k; j++) {
            int64_t lo = j - b->ku > 0 ? j - b->ku : 0;
            int64_t hi = j + b->kl + 1 < m ? j + b->kl + 1 : m;
            for (i = lo; i < hi; i++) x[i + j * m] = b->val[(b->ku + i - j) + j * b->ld];
        }
    }
}

double *ss_rhs_dense(const silc_view *b, int *owned)
{
    size_t len = (size_t)(b->m > 0 ? b->m : 1) * (size_t)(b->n > 0 ? b->n : 1);
    double *x;
    *owned = 0;
    if (b->format == SILC_FMT_DENSE) return b->val;
    if (!(x = ss_host->alloc(len * sizeof(double)))) return NULL;
    *owned = 1;
    ss_rhs_copy(b, x);
    return x;
}

silc_value *ss_dense_value(int64_t m, int64_t k, const double *x, int64_t ld)
{
    silc_value *out = ss_host->dense_new_uninit(m, k); /* every column is copied below */
    silc_view o;
    int64_t j;
    if (!out) return NULL;
    ss_host->view(out, &o);
    for (j = 0; j < k && m > 0; j++) memcpy(o.val + j * m, x + j * ld, (size_t)m * sizeof(double));
    return out;
}

int ss_condest_mode(silc_call *call, int *mode)
{
    const char *v = ss_host->option_string(call, "condest", "auto");
    /* auto once kept the pivot ratio below 1e6; now it is true */
    if (!strcmp(v, "auto") || !strcmp(v, "true") || !strcmp(v, "on") || !strcmp(v, "yes") || !strcmp(v, "1"))
        *mode = SS_CONDEST_ALWAYS;
    else if (!strcmp(v, "false") || !strcmp(v, "off") || !strcmp(v, "no") || !strcmp(v, "0"))
        *mode = SS_CONDEST_NEVER;
    else
        return ss_host->error(call, SILC_EARG,
                              "option 'suitesparse.condest' expects auto, true or false, got '%s'", v);
    return SILC_OK;
}

/* ---- condition estimate ------------------------------------------------------ */

/* The host lends the Hager-Higham estimator (ABI 1.1); this adapter lets the
 * backends keep their in-place solve callbacks. */
typedef struct ss_est {
    int (*solve)(void *ctx, double *x, int trans);
    void *ctx;
} ss_est;

static int ss_apply(void *ctx, double *x, int trans, double *work)
{
    const ss_est *e = ctx;
    (void)work;
    return e->solve(e->ctx, x, trans);
}

double ss_inv_norm1(int64_t n, int (*solve)(void *ctx, double *x, int trans), void *ctx)
{
    ss_est e = {solve, ctx};
    return ss_host->inv_norm1_est(n, ss_apply, &e, NULL);
}

int ss_condest_wanted(const silc_call *call, int mode)
{
    /* accuracy.condest = off reaches a plugin through the report (ABI 1.7) */
    int off = ss_host->abi_minor >= 7 && call->report->condest_off;
    return mode != SS_CONDEST_NEVER && !off;
}

int ss_condest_later(const silc_call *call)
{
    return ss_host->abi_minor >= 8 && call->report->condest_later;
}

int ss_condest_only(const silc_call *call)
{
    return ss_host->abi_minor >= 8 && call->report->condest_only;
}

int ss_cond_due(const silc_call *call, int mode, const ss_factor_info *fi)
{
    return !fi->estimated && ss_condest_wanted(call, mode) && !ss_condest_later(call);
}

/* The start block depends on n alone, and Higham's alternating vector costs
 * two divisions an entry: 4 % of a KLU refactorization of west0479, as much
 * as a tenth of a column solve.  A time loop factors one size again and
 * again, so the last size's block is kept (under the lock: contexts in two
 * threads may estimate at once) and copied. */
void ss_start_block(int64_t n, int width, double *X)
{
    size_t bytes = (size_t)(n > 0 ? n : 0) * SS_EST_COLS * sizeof *X;
    ss_lock();
    if (n == ss_start_kept_n && ss_start_kept) {
        if (bytes) memcpy(X, ss_start_kept, bytes);
    } else {
        ss_host->inv_norm1_start(n, SS_EST_COLS, X);
        free(ss_start_kept);
        ss_start_kept_n = -1;
        if ((ss_start_kept = malloc(bytes ? bytes : 1))) { /* else computed again next time */
            if (bytes) memcpy(ss_start_kept, X, bytes);
            ss_start_kept_n = n;
        }
    }
    ss_unlock();
    /* complex: spread the real values to the real parts from the last entry
     * down, so that no entry is read after its slot is overwritten */
    if (width == 2)
        for (int64_t i = n * SS_EST_COLS - 1; i >= 0; i--) X[2 * i] = X[i], X[2 * i + 1] = 0;
}

double ss_start_bound(silc_call *call, int64_t n, int width, const double *Y)
{
    double best = 0;
    for (int j = 0; j < SS_EST_COLS; j++) {
        const double *y = Y + (int64_t)width * n * j;
        double sy = 0;
        for (int64_t i = 0; i < n; i++) sy += width == 2 ? hypot(y[2 * i], y[2 * i + 1]) : fabs(y[i]);
        if (sy > best || isnan(sy)) best = sy;
    }
    return silc_props_of(ss_host, call->in[0], SILC_PROPS_NORMS)->norm1 * best;
}

void ss_report_owed(silc_call *call, int mode, const ss_factor_info *fi, int64_t k)
{
    silc_view a;
    if (fi->estimated || !ss_condest_wanted(call, mode) || !ss_condest_later(call)) return;
    call->report->condest_deferred = 1;
    /* per column: KLU's and CHOLMOD's solves cost their columns' passes
     * over the factors, UMFPACK's solve one column a call; a kept start
     * saves its two */
    call->report->condest_solves = (double)(SS_EST_COLUMN_SOLVES - (fi->start_solved ? SS_EST_COLS : 0)) /
                                   (double)(k > 0 ? k : 1);
    if (!fi->start_solved) return;
    ss_host->view(call->in[0], &a);
    call->report->condest_lower = ss_start_bound(call, a.n, 1, fi->start_solved);
}

int ss_start_due(const silc_call *call, int mode, const ss_factor_info *fi)
{
    /* condest_later 2: on_request wants no bound */
    return !fi->estimated && !fi->start_solved && ss_condest_wanted(call, mode) && ss_condest_later(call) &&
           call->report->condest_later != 2 && !ss_condest_only(call) && fi->pivot_ratio > SILC_CONDEST_PIVOT_HINT;
}

void ss_keep_start(ss_factor_info *fi, int64_t n, const double *Y)
{
    ss_host->free(fi->start_solved);
    if ((fi->start_solved = ss_host->alloc((size_t)(n > 0 ? n : 1) * SS_EST_COLS * sizeof *Y)))
        memcpy(fi->start_solved, Y, (size_t)n * SS_EST_COLS * sizeof *Y);
}

void ss_solve_start(ss_factor_info *fi, int64_t n, ss_block_fn apply, void *ctx)
{
    double *y = ss_host->alloc((size_t)(n > 0 ? n : 1) * SS_EST_COLS * sizeof *y);
    if (!y) return;
    ss_start_block(n, 1, y);
    if (apply(ctx, y, SS_EST_COLS, 0)) { /* a solve failed: no bound, the ratio decides */
        ss_host->free(y);
        return;
    }
    ss_host->free(fi->start_solved);
    fi->start_solved = y;
}

int ss_estimate_alone(silc_call *call, int mode, int64_t n, ss_block_fn apply, void *ctx, ss_factor_info *fi)
{
    size_t before = strlen(fi->note);
    ss_square_cond(call, mode, n, apply, ctx, fi, NULL);
    call->report->cond_est = fi->estimated ? fi->cond : -1;
    /* the note says how the estimate was made, and only that */
    snprintf(call->report->note, sizeof call->report->note, "%s",
             fi->note + before + (before && fi->note[before] == ';' ? 2 : 0));
    return SILC_OK;
}

int ss_no_factor(silc_call *call, const char *library)
{
    return ss_host->error(call, SILC_EDECLINE, "%s: no factorization attached to A for the condition estimate",
                          library);
}

/* The column of the solved starting block Y (n x SS_EST_COLS) with the
 * largest 1-norm (a NaN or Inf one wins: the estimate then says so). */
static const double *best_start(int64_t n, const double *Y)
{
    const double *best = Y;
    double s_best = 0;
    for (int j = 0; j < SS_EST_COLS; j++) {
        double s = 0;
        for (int64_t i = 0; i < n; i++) s += fabs(Y[i + j * n]);
        if (j == 0 || (!(s <= s_best) && !isnan(s_best))) best = Y + j * n, s_best = s;
    }
    return best;
}

void ss_square_cond(silc_call *call, int mode, int64_t n, ss_block_fn apply, void *ctx, ss_factor_info *fi,
                    const double *Y0)
{
    double inv = -1, *start = NULL;
    size_t len;
    if (!ss_cond_due(call, mode, fi)) return;
    if (!Y0 && fi->start_solved) { /* solved for the bound (ss_start_due) */
        start = fi->start_solved;
        fi->start_solved = NULL;
    } else if (!Y0) { /* not folded into the user's solve: the start is solved here */
        if (!(start = ss_host->alloc((size_t)n * SS_EST_COLS * sizeof *start))) return;
        ss_start_block(n, 1, start);
        if (apply(ctx, start, SS_EST_COLS, 0)) {
            ss_host->free(start);
            return; /* a solve failed: no estimate */
        }
    }
    ss_host->free(fi->start_solved);
    fi->start_solved = NULL;
    /* The better start goes on alone: one column per solve from here. */
    inv = ss_host->inv_norm1_est_block(n, 1, SS_EST_STEPS, apply, ctx, best_start(n, Y0 ? Y0 : start));
    ss_host->free(start);
    if (inv < 0) return; /* a solve failed: no estimate */
    fi->cond = silc_props_of(ss_host, call->in[0], SILC_PROPS_NORMS)->norm1 * inv;
    fi->estimated = 1;
    len = strlen(fi->note);
    snprintf(fi->note + len, sizeof fi->note - len,
             "%s1-norm condition estimate: Hager/Higham through the factors (e/n and alternating start%s, %d steps)",
             len ? "; " : "", Y0 ? " with this solve" : "", SS_EST_STEPS);
}

double *ss_rhs_with_start(const silc_view *b, int64_t n)
{
    double *x = ss_host->alloc((size_t)(n * (b->n + SS_EST_COLS) + 1) * sizeof *x);
    if (!x) return NULL;
    ss_rhs_copy(b, x);
    ss_start_block(n, 1, x + n * b->n);
    return x;
}

int ss_attached_factor(silc_call *call, const silc_view *a, const char *key, ss_make_fn make,
                       void (*destroy)(void *), const char *what, void **out)
{
    double t0 = ss_host->now();
    int rc;
    *out = ss_host->attach_get(call->in[0], key);
    if (*out) {
        call->report->reused_factor = 1;
    } else {
        if ((rc = make(call, a, out))) return rc;
        if (ss_host->attach_set(call->in[0], key, *out, destroy)) {
            destroy(*out);
            *out = NULL;
            return ss_nomem(call, what);
        }
    }
    call->report->factor_seconds = ss_host->now() - t0;
    return SILC_OK;
}

int ss_square_solve_begin(silc_call *call, silc_view *a, silc_view *b, int *condest)
{
    ss_host->view(call->in[0], a);
    ss_host->view(call->in[1], b);
    if (a->format != SILC_FMT_CSR || a->m != a->n) return SILC_EDECLINE;
    return ss_condest_mode(call, condest);
}

void ss_report_factor(silc_report *r, const ss_factor_info *fi)
{
    snprintf(r->method, sizeof r->method, "%s", fi->method);
    snprintf(r->note, sizeof r->note, "%s", fi->note);
    r->rcond = fi->rcond;
    r->cond_est = fi->estimated ? fi->cond : -1;
    /* The libraries' own cheap number is shown, labelled, never trusted:
     * the ratio of the factor's extreme diagonal entries (UMFPACK's and
     * KLU's pivots, CHOLMOD's diagonal of L) is 5.07 / 3.8 on the 1-D
     * Laplacian of cond_1 840. */
    if (ss_host->abi_minor >= 7) r->pivot_ratio = fi->pivot_ratio;
}

void ss_pivot_ratio(ss_factor_info *fi)
{
    fi->pivot_ratio = fi->rcond > 0 ? 1.0 / fi->rcond : fi->rcond == 0 ? INFINITY : 0;
}

/* ---- the symbolic cache ------------------------------------------------------ */

/* Each slot holds one pattern, so there is nothing to look up: the sizes
 * reject most strangers and memcmp, which stops at the first difference and
 * runs at memory speed, settles the rest (a hash of the arrays cost more than
 * the compare, on every miss). */
static int same_pattern(const ss_symbolic *e, const silc_view *a, int tag)
{
    int64_t nnz = a->rowptr[a->m];
    return e->tag == tag && e->m == a->m && e->n == a->n && e->nnz == nnz &&
           memcmp(e->rowptr, a->rowptr, (size_t)(a->m + 1) * sizeof(silc_index)) == 0 &&
           (nnz == 0 || memcmp(e->colind, a->colind, (size_t)nnz * sizeof(silc_index)) == 0);
}

static void sym_free(ss_symbolic *e)
{
    if (e->spare) e->spare_destroy(e->spare);
    if (e->obj) e->destroy(e->obj);
    ss_host->free(e->rowptr);
    ss_host->free(e->colind);
    ss_host->free(e);
}

ss_symbolic *ss_sym_find(int slot, const silc_view *a, int tag)
{
    ss_symbolic *e;
    ss_lock();
    e = ss_cache[slot];
    if (e && same_pattern(e, a, tag)) e->refs++;
    else e = NULL;
    ss_unlock();
    return e;
}

ss_symbolic *ss_sym_remember(int slot, const silc_view *a, int tag, void *obj,
                             void (*destroy)(void *obj))
{
    int64_t nnz = a->rowptr[a->m];
    ss_symbolic *e = ss_host->calloc(1, sizeof *e), *old;
    if (!e) return NULL;
    e->rowptr = ss_host->alloc((size_t)(a->m + 1) * sizeof(silc_index));
    e->colind = ss_host->alloc((size_t)(nnz > 0 ? nnz : 1) * sizeof(silc_index));
    if (!e->rowptr || !e->colind) {
        ss_host->free(e->rowptr);
        ss_host->free(e->colind);
        ss_host->free(e);
        return NULL;
    }
    memcpy(e->rowptr, a->rowptr, (size_t)(a->m + 1) * sizeof(silc_index));
    if (nnz) memcpy(e->colind, a->colind, (size_t)nnz * sizeof(silc_index));
    e->tag = tag;
    e->m = a->m;
    e->n = a->n;
    e->nnz = nnz;
    e->obj = obj;
    e->destroy = destroy;
    e->refs = 2; /* the cache's and the caller's */
    ss_lock();
    old = ss_cache[slot];
    ss_cache[slot] = e;
    ss_unlock();
    if (old) ss_sym_release(old);
    return e;
}

void ss_sym_release(ss_symbolic *e)
{
    int last;
    if (!e) return;
    ss_lock();
    last = --e->refs == 0;
    ss_unlock();
    if (last) sym_free(e);
}

void *ss_sym_take_spare(ss_symbolic *e)
{
    void *s;
    ss_lock();
    s = e->spare;
    e->spare = NULL;
    ss_unlock();
    return s;
}

void ss_sym_donate(int slot, ss_symbolic *e, void *spare, void (*spare_destroy)(void *))
{
    int kept = 0;
    ss_lock();
    if (ss_cache[slot] == e && !e->spare) {
        e->spare = spare;
        e->spare_destroy = spare_destroy;
        kept = 1;
    }
    ss_unlock();
    if (!kept) spare_destroy(spare);
}
