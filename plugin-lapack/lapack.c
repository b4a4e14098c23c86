/*
 * lapack.c -- the lapack plugin: dense and band operations on OpenBLAS + LAPACKE.
 *
 * One backend, "lapack", with two operations:
 *   MATMUL  dense * dense by cblas_dgemm (cblas_dgemv when one side is a vector);
 *   SOLVE   the solve classes the dispatcher sends it, each mapped to the
 *           LAPACK driver users would pick by hand:
 *             solve.dense        dgetrf (dsytrf when A is symmetric: the
 *                                dispatcher sends a symmetric A here when its
 *                                diagonal is not positive or Cholesky failed)
 *             solve.dense.spd    dpotrf, SILC_ENOTSPD when it fails
 *             solve.triangular   dtrtrs
 *             solve.band         dgbtrf / dpbtrf / dgttrf / dpttrf (lapack_band.c)
 *             solve.rect         QR / LQ as dgels, dgelsy when rank deficient
 *           solve.diag and the sparse classes are left to other backends.
 *
 * The factorization is attached to A ("lapack.<kind>"), so repeated solves
 * with an unchanged A factor once.  lapack.precision = mixed sends general
 * and SPD dense solves to dsgesv / dsposv instead (see solve_mixed).  The thread count is OpenBLAS's.
 *
 * Complex values (ABI 1.8): MATMUL by cblas_zgemm / zgemv, and every SOLVE
 * class above by the z routines (lapack.h), .spd meaning Hermitian positive
 * definite (zpotrf) and a complex symmetric A (A = A.') going to zsytrf.
 * lapack.precision = mixed is real only (LAPACK has zcgesv but no complex
 * path here): a complex solve is factored in double and the note says so.
 */
#include "lapack.h"

#include <cblas.h>
#include <float.h>
#include <limits.h>
#include <math.h>
#include <stdio.h>
#include <string.h>

const silc_host_api *lp_host;

/* ---- memory and small helpers ---------------------------------------------- */

void *lp_alloc(size_t count, size_t size)
{
    if (count == 0 || size == 0) return lp_host->alloc(1);
    if (count > SIZE_MAX / size) return NULL;
    return lp_host->alloc(count * size);
}

void lp_free(void *p)
{
    if (p) lp_host->free(p);
}

int lp_con_scratch(lapack_int n, lapack_int nwork, double **work, lapack_int **iwork)
{
    *work = lp_alloc((size_t)LP_LD(nwork), sizeof(double));
    *iwork = lp_alloc((size_t)LP_LD(n), sizeof(lapack_int));
    if (*work && *iwork) return 0;
    lp_free(*work);
    lp_free(*iwork);
    return -1;
}

lp_factor *lp_factor_new(int kind, lapack_int m, lapack_int n)
{
    lp_factor *F = lp_host->calloc(1, sizeof *F);
    if (!F) return NULL;
    F->kind = kind;
    F->m = m;
    F->n = n;
    F->rcond = -1;
    return F;
}

void lp_factor_free(void *p)
{
    lp_factor *F = p;
    if (!F) return;
    lp_free(F->a);
    lp_free(F->tau);
    lp_free(F->ipiv);
    lp_free(F);
}

int lp_nomem(silc_call *call)
{
    return lp_host->error(call, SILC_ENOMEM, "lapack: out of memory");
}

int lp_illegal(silc_call *call, const char *fn, lapack_int info)
{
    return lp_host->error(call, SILC_ELIB, "%s: illegal argument %d (status %d)", fn, (int)-info, (int)info);
}

int lp_illegal_p(silc_call *call, char p, const char *fn, lapack_int info)
{
    return lp_host->error(call, SILC_ELIB, "%c%s: illegal argument %d (status %d)", p, fn, (int)-info,
                          (int)info);
}

double lp_get(const silc_view *A, int64_t i, int64_t j)
{
    if (A->format == SILC_FMT_DENSE) return A->val[i + j * A->m];
    if (i - j > A->kl || j - i > A->ku) return 0.0;
    return A->val[(A->ku + i - j) + j * A->ld];
}

double complex lp_getz(const silc_view *A, int64_t i, int64_t j)
{
    const double complex *z = (const double complex *)A->val;
    if (A->format == SILC_FMT_DENSE) return z[i + j * A->m];
    if (i - j > A->kl || j - i > A->ku) return 0.0;
    return z[(A->ku + i - j) + j * A->ld];
}

double *lp_take_copy(silc_call *call, const silc_value *v)
{
    if (lp_host->struct_size < SILC_HOST_NEEDS(take_dense_copy) || !lp_host->take_dense_copy) return NULL;
    return lp_host->take_dense_copy(call, v);
}

int lp_is_complex(const silc_value *v)
{
    return lp_host->struct_size >= SILC_HOST_NEEDS(field) && lp_host->field(v) == SILC_FIELD_COMPLEX;
}

/* A new zero-filled dense m x n value of the field of the operands. */
static silc_value *dense_out(int cx, int64_t m, int64_t n)
{
    return cx ? lp_host->dense_new_complex(m, n) : lp_host->dense_new(m, n);
}

static int is_class(const silc_call *call, const char *cls)
{
    return call->op_class && strcmp(call->op_class, cls) == 0;
}

static int spd_class(const silc_call *call)
{
    size_t n = call->op_class ? strlen(call->op_class) : 0;
    return n >= 4 && strcmp(call->op_class + n - 4, ".spd") == 0;
}

static int fits(int64_t k)
{
    return k >= 0 && k <= INT_MAX;
}

/* ---- accepts ------------------------------------------------------------------- */

static int accepts_matmul(const silc_call *call, const char **why)
{
    silc_view a, b;
    lp_host->view(call->in[0], &a);
    lp_host->view(call->in[1], &b);
    if (a.format != SILC_FMT_DENSE || b.format != SILC_FMT_DENSE) {
        *why = "needs dense operands";
        return 0;
    }
    if (!fits(a.m) || !fits(a.n) || !fits(b.n)) {
        *why = "dimensions exceed 32-bit BLAS indices";
        return 0;
    }
    return 1;
}

static int accepts_solve(const silc_call *call, const char **why)
{
    silc_view a, b;
    const silc_props *P;
    if (call->nin < 2) {
        *why = "needs a right-hand side";
        return 0;
    }
    lp_host->view(call->in[0], &a);
    lp_host->view(call->in[1], &b);
    if (a.format != SILC_FMT_DENSE && a.format != SILC_FMT_BAND) {
        *why = "needs dense or band storage";
        return 0;
    }
    if (!fits(a.m) || !fits(a.n) || !fits(b.n)) {
        *why = "dimensions exceed 32-bit LAPACK indices";
        return 0;
    }
    if (is_class(call, "solve.diag")) {
        *why = "solve.diag is not provided";
        return 0;
    }
    if (a.format == SILC_FMT_BAND && call->op_class && !is_class(call, "solve.band")) {
        *why = "band storage is solved under solve.band only";
        return 0;
    }
    P = silc_props_of(lp_host, call->in[0], SILC_PROPS_SHAPE | SILC_PROPS_SYMMETRY);
    if (P->has_nonfinite) {
        *why = "matrix has NaN or Inf entries";
        return 0;
    }
    if (a.m != a.n && call->op_class && !is_class(call, "solve.rect")) {
        *why = "needs a square matrix";
        return 0;
    }
    if (is_class(call, "solve.triangular") && !P->lower && !P->upper) {
        *why = "needs a triangular matrix";
        return 0;
    }
    if (lp_is_complex(call->in[0])) {
        if (spd_class(call) && !P->hermitian) {
            *why = "needs a Hermitian matrix";
            return 0;
        }
    } else if (spd_class(call) && !P->symmetric) {
        *why = "needs a symmetric matrix";
        return 0;
    }
    return 1;
}

/* ---- MATMUL -------------------------------------------------------------------- */

static int op_matmul(silc_call *call)
{
    silc_view a, b, c;
    silc_value *out;
    int m, k, n, cx = lp_is_complex(call->in[0]);
    lp_host->view(call->in[0], &a);
    lp_host->view(call->in[1], &b);
    if (a.format != SILC_FMT_DENSE || b.format != SILC_FMT_DENSE)
        return lp_host->error(call, SILC_EDECLINE, "lapack: needs dense operands");
    if (a.n != b.m)
        return lp_host->error(call, SILC_EARG, "lapack: inner dimensions differ (%lldx%lld * %lldx%lld)",
                              (long long)a.m, (long long)a.n, (long long)b.m, (long long)b.n);
    if (cx != lp_is_complex(call->in[1]))
        return lp_host->error(call, SILC_EARG, "lapack: operands of different fields (real and complex)");
    m = (int)a.m;
    k = (int)a.n;
    n = (int)b.n;
    out = dense_out(cx, m, n);
    if (!out) return lp_nomem(call);
    lp_host->view(out, &c);
    /* Empty inner dimension: the zero-filled result is already right, and BLAS
     * would reject the leading dimensions of empty arrays. */
    if (cx && m > 0 && n > 0 && k > 0) {
        const double complex one = 1, zero = 0;
        if (n == 1)
            cblas_zgemv(CblasColMajor, CblasNoTrans, m, k, &one, a.val, m, b.val, 1, &zero, c.val, 1);
        else if (m == 1) /* row vector times matrix: c.' = B.' a.' (no conjugation) */
            cblas_zgemv(CblasColMajor, CblasTrans, k, n, &one, b.val, k, a.val, 1, &zero, c.val, 1);
        else
            cblas_zgemm(CblasColMajor, CblasNoTrans, CblasNoTrans, m, n, k, &one, a.val, m, b.val, k, &zero,
                        c.val, m);
    } else if (m > 0 && n > 0 && k > 0) {
        if (n == 1)
            cblas_dgemv(CblasColMajor, CblasNoTrans, m, k, 1.0, a.val, m, b.val, 1, 0.0, c.val, 1);
        else if (m == 1) /* row vector times matrix: c' = B' a' */
            cblas_dgemv(CblasColMajor, CblasTrans, k, n, 1.0, b.val, k, a.val, 1, 0.0, c.val, 1);
        else
            cblas_dgemm(CblasColMajor, CblasNoTrans, CblasNoTrans, m, n, k, 1.0, a.val, m, b.val, k, 0.0,
                        c.val, m);
    }
    call->out = out;
    return SILC_OK;
}

/* ---- SOLVE --------------------------------------------------------------------- */

enum lp_route { R_LU, R_CHOL, R_LDLT, R_TRI, R_BAND, R_RECT };
static const char *const route_key[] = {"lapack.lu", "lapack.chol", "lapack.ldlt",
                                        "lapack.tri", "lapack.band", "lapack.qr"};

/* ||A||_1 for an estimate or a band factorization.  The solve's other
 * reads of A's properties ask for the shape and the symmetry only, so a
 * dense solve that wants no estimate (accuracy.condest = off) never pays
 * the norms' pass; this asks for it where it is needed. */
static double norm1_of(const silc_call *call)
{
    return silc_props_of(lp_host, call->in[0], SILC_PROPS_NORMS)->norm1;
}

/* Which LAPACK path serves this call.  Without a class (a direct call) the
 * structure decides, as the dispatcher would. */
static int route_of(const silc_call *call, const silc_view *A, const silc_props *P)
{
    if (A->m != A->n) return R_RECT;
    if (A->format == SILC_FMT_BAND || is_class(call, "solve.band")) return R_BAND;
    if (is_class(call, "solve.triangular") || (!call->op_class && (P->lower || P->upper))) return R_TRI;
    if (spd_class(call)) return R_CHOL;
    return P->symmetric ? R_LDLT : R_LU;
}

static int factor(silc_call *call, int route, const silc_view *A, const silc_props *P, double rank_tol,
                  lp_factor **F)
{
    switch (route) {
    case R_LU: return lp_dense_lu(call, A, F);
    case R_CHOL: return lp_dense_chol(call, A, F);
    case R_LDLT: return lp_dense_ldlt(call, A, F);
    case R_TRI: return lp_dense_tri(call, A, P->lower ? 'L' : 'U', F);
    case R_BAND: return lp_band(call, A, P->kl, P->ku, P->symmetric && P->pos_diag, norm1_of(call), F);
    default: return lp_dense_qr(call, A, rank_tol, F);
    }
}

/* Copies the m x k right-hand side b (any format) into X with leading
 * dimension ldx (in entries; complex entries when cx). */
static void rhs_copy(const silc_view *b, double *X, int64_t ldx, int cx)
{
    int64_t i, j, p;
    if (cx) {
        double complex *Z = (double complex *)X;
        const double complex *bz = (const double complex *)b->val;
        for (j = 0; j < b->n; j++)
            for (i = 0; i < b->m; i++) Z[i + j * ldx] = b->format == SILC_FMT_CSR ? 0 : lp_getz(b, i, j);
        if (b->format == SILC_FMT_CSR)
            for (i = 0; i < b->m; i++)
                for (p = b->rowptr[i]; p < b->rowptr[i + 1]; p++) Z[i + b->colind[p] * ldx] += bz[p];
        return;
    }
    if (b->format == SILC_FMT_CSR) {
        for (j = 0; j < b->n; j++) memset(X + j * ldx, 0, (size_t)b->m * sizeof(double));
        for (i = 0; i < b->m; i++)
            for (p = b->rowptr[i]; p < b->rowptr[i + 1]; p++) X[i + b->colind[p] * ldx] += b->val[p];
    } else if (b->format == SILC_FMT_BAND) {
        for (j = 0; j < b->n; j++)
            for (i = 0; i < b->m; i++) X[i + j * ldx] = lp_get(b, i, j);
    } else {
        for (j = 0; j < b->n; j++) memcpy(X + j * ldx, b->val + j * b->m, (size_t)b->m * sizeof(double));
    }
}

static void fill_report(silc_report *r, const lp_factor *F)
{
    snprintf(r->method, sizeof r->method, "%s", F->method);
    if (F->rcond > 0) {
        r->rcond = F->rcond;
        r->cond_est = 1.0 / F->rcond;
    } else if (F->rcond == 0) {
        r->rcond = 0;
        r->cond_est = INFINITY;
    }
    snprintf(r->note, sizeof r->note, "%s", F->note);
}

/* ITER < 0 of dsgesv / dsposv: why the double-precision fallback ran. */
static const char *iter_reason(lapack_int iter)
{
    switch (iter) {
    case -1: return "the matrix is too small for mixed precision to pay";
    case -2: return "an entry overflows single precision";
    case -3: return "the single-precision factorization failed";
    case -31: return "refinement did not converge in 30 steps";
    default: return "LAPACK chose double precision";
    }
}

/* accuracy.condest = off: the host says so in the report (ABI 1.7), and no
 * estimate is made. */
static int condest_off(const silc_call *call)
{
    return lp_host->abi_minor >= 7 && call->report->condest_off;
}

/* lapack.precision = mixed: dsgesv / dsposv factor in single precision and
 * refine in double, falling back to a double factorization themselves when
 * that fails (too ill-conditioned, out of single range).  The single factors
 * live inside the call, so nothing is attached and every solve factors anew;
 * the condition estimate comes from whichever factors the call ended with. */
static int solve_mixed(silc_call *call, int route, const silc_view *A, const silc_view *B)
{
    lapack_int n = (lapack_int)A->n, nrhs = (lapack_int)B->n, iter = 0, info, *ipiv, *iwork;
    double *given = lp_take_copy(call, call->in[0]); /* the host's copy of A, if it made one */
    double *a = given ? given : lp_alloc((size_t)n * (size_t)n, sizeof(double));
    double *b = lp_alloc((size_t)n * (size_t)nrhs, sizeof(double));
    double *work = lp_alloc((size_t)n * (size_t)(nrhs > 4 ? nrhs : 4), sizeof(double));
    float *swork = lp_alloc((size_t)n * (size_t)(n + nrhs), sizeof(float));
    silc_value *out = lp_host->dense_new(A->n, B->n);
    silc_report *r = call->report;
    silc_view X;
    double t0 = lp_host->now(), rcond = -1;
    int rc = SILC_OK, chol = route == R_CHOL;
    ipiv = lp_alloc((size_t)n, sizeof(lapack_int));
    iwork = lp_alloc((size_t)n, sizeof(lapack_int));
    if (!a || !b || !work || !swork || !out || !ipiv || !iwork) {
        rc = lp_nomem(call);
        goto done;
    }
    lp_host->view(out, &X);
    if (!given) memcpy(a, A->val, (size_t)n * (size_t)n * sizeof(double));
    rhs_copy(B, b, n, 0);
    info = chol ? LAPACKE_dsposv_work(LAPACK_COL_MAJOR, 'L', n, nrhs, a, n, b, n, X.val, n, work,
                                      swork, &iter)
                : LAPACKE_dsgesv_work(LAPACK_COL_MAJOR, n, nrhs, a, n, ipiv, b, n, X.val, n, work,
                                      swork, &iter);
    if (info > 0) {
        rc = chol ? lp_host->error(call, SILC_ENOTSPD,
                                   "dsposv: matrix is not positive definite (leading minor %d, status %d)",
                                   (int)info, (int)info)
                  : lp_host->error(call, SILC_ESINGULAR,
                                   "dsgesv: singular matrix (U(%d,%d) is exactly zero, status %d)",
                                   (int)info, (int)info, (int)info);
        goto done;
    }
    if (info < 0) {
        rc = lp_illegal(call, chol ? "dsposv" : "dsgesv", info);
        goto done;
    }
    /* After a fallback a holds the double factors: estimate as the double path
     * does.  Otherwise the single factors are still in swork (dsgesv / dsposv
     * factor their single copy of A in place at its start, with ipiv), and
     * sgecon / spocon estimate from them: as good as single precision, which
     * is all a condition estimate needs, since a matrix too ill-conditioned
     * for single precision makes LAPACK fall back to double anyway. */
    int estimate = !condest_off(call);
    if (estimate && iter < 0) {
        if (chol ? LAPACKE_dpocon_work(LAPACK_COL_MAJOR, 'L', n, a, n, norm1_of(call), &rcond, work, iwork)
                 : LAPACKE_dgecon_work(LAPACK_COL_MAJOR, '1', n, a, n, norm1_of(call), &rcond, work, iwork))
            rcond = -1;
    } else if (estimate) {
        float srcond = -1, *fwork = lp_alloc((size_t)4 * (size_t)n, sizeof(float));
        if (fwork && !(chol ? LAPACKE_spocon_work(LAPACK_COL_MAJOR, 'L', n, swork, n, (float)norm1_of(call),
                                                   &srcond, fwork, iwork)
                            : LAPACKE_sgecon_work(LAPACK_COL_MAJOR, '1', n, swork, n, (float)norm1_of(call),
                                                   &srcond, fwork, iwork)))
            rcond = srcond;
        lp_free(fwork);
    }
    snprintf(r->method, sizeof r->method, "mixed precision %s (%s)", chol ? "Cholesky" : "LU",
             chol ? "dsposv" : "dsgesv");
    if (iter >= 0)
        snprintf(r->note, sizeof r->note,
                 "factored in single precision, %d refinement step%s in double (ITER=%d)", (int)iter,
                 iter == 1 ? "" : "s", (int)iter);
    else
        snprintf(r->note, sizeof r->note, "fell back to double precision (ITER=%d: %s)", (int)iter,
                 iter_reason(iter));
    if (rcond > 0) r->rcond = rcond, r->cond_est = 1.0 / rcond;
    else if (rcond == 0) r->rcond = 0, r->cond_est = INFINITY;
    r->factor_seconds = 0;
    r->solve_seconds = lp_host->now() - t0;
    call->out = out;
    out = NULL;
done:
    if (out) lp_host->release(out);
    lp_free(a);
    lp_free(b);
    lp_free(work);
    lp_free(swork);
    lp_free(ipiv);
    lp_free(iwork);
    return rc;
}

static int op_solve(silc_call *call)
{
    silc_view A, B, X;
    const silc_props *P;
    lp_factor *F, *owned = NULL;
    silc_value *out;
    double rank_tol = 0, t0, t1, te = 0, *work;
    int64_t ldw;
    int route, rc, fresh = 0, cx = lp_is_complex(call->in[0]), mixed_asked = 0;
    size_t w = cx ? 2 : 1; /* doubles per entry */
    lp_host->view(call->in[0], &A);
    lp_host->view(call->in[1], &B);
    if (cx != lp_is_complex(call->in[1]))
        return lp_host->error(call, SILC_EARG, "lapack: A and b of different fields (real and complex)");
    if (A.format != SILC_FMT_DENSE && A.format != SILC_FMT_BAND)
        return lp_host->error(call, SILC_EDECLINE, "lapack: needs dense or band storage");
    if (A.m != A.n && A.format != SILC_FMT_DENSE)
        return lp_host->error(call, SILC_EDECLINE, "lapack: least squares needs dense storage");
    if (B.m != A.m)
        return lp_host->error(call, SILC_EARG, "lapack: A is %lldx%lld but b has %lld rows",
                              (long long)A.m, (long long)A.n, (long long)B.m);
    if (A.m == 0 || A.n == 0 || B.n == 0) { /* nothing to factor: the zero-filled x is the answer */
        if (!(call->out = dense_out(cx, A.n, B.n))) return lp_nomem(call);
        snprintf(call->report->method, sizeof call->report->method, "empty system");
        return SILC_OK;
    }
    P = silc_props_of(lp_host, call->in[0], SILC_PROPS_SHAPE | SILC_PROPS_SYMMETRY);
    route = route_of(call, &A, P);
    if ((route == R_LU || route == R_CHOL) && A.format == SILC_FMT_DENSE) {
        const char *prec = lp_host->option_string(call, "precision", "double");
        mixed_asked = cx && strcmp(prec, "mixed") == 0; /* real only: complex factors in double */
        if (!cx && strcmp(prec, "mixed") == 0) return solve_mixed(call, route, &A, &B);
        if (strcmp(prec, "double") != 0 && !mixed_asked)
            return lp_host->error(call, SILC_EARG,
                                  "option 'lapack.precision' expects double or mixed, got '%s'", prec);
    }
    if (route == R_RECT) {
        if ((rc = lp_host->option_double(call, "rank_tol", 0.0, &rank_tol))) return rc;
        if (!(rank_tol > 0)) rank_tol = (double)(A.m > A.n ? A.m : A.n) * DBL_EPSILON;
    }

    t0 = lp_host->now();
    F = lp_host->attach_get(call->in[0], route_key[route]);
    /* A least-squares factor made with another rank threshold is redone. */
    if (F && route == R_RECT && F->rank_tol != rank_tol) F = NULL;
    if (F && route == R_CHOL && F->bad > 0)
        return lp_host->error(call, SILC_ENOTSPD,
                              "dpotrf: matrix is not positive definite (leading minor %d, found by an "
                              "earlier solve)", (int)F->bad);
    if (!F) {
        rc = factor(call, route, &A, P, rank_tol, &F);
        if (rc != SILC_OK && !(rc == SILC_ENOTSPD && F)) return rc;
        if (lp_host->attach_set(call->in[0], route_key[route], F, lp_factor_free)) owned = F;
        if (rc != SILC_OK) { /* the failed Cholesky is remembered as an attachment */
            lp_factor_free(owned);
            return rc;
        }
        fresh = 1;
    }
    /* The condition estimate, unless accuracy.condest = off: made with a
     * fresh factorization (and timed with it), or by the first solve that
     * wants it from a factor made without. */
    if (F->rcond_owed && !condest_off(call)) {
        te = lp_host->now();
        if ((rc = lp_dense_estimate(call, F, &A, norm1_of(call)))) {
            lp_factor_free(owned);
            return rc;
        }
        te = lp_host->now() - te;
    }
    t1 = lp_host->now();

    out = dense_out(cx, A.n, B.n);
    if (!out) {
        lp_factor_free(owned);
        return lp_nomem(call);
    }
    lp_host->view(out, &X);
    /* Square systems are solved in place in the result; least squares needs
     * max(m, n) rows of room. */
    ldw = A.m > A.n ? A.m : A.n;
    work = A.m == A.n ? X.val : lp_host->calloc((size_t)ldw * (size_t)B.n * w, sizeof(double));
    if (!work) {
        lp_host->release(out);
        lp_factor_free(owned);
        return lp_nomem(call);
    }
    rhs_copy(&B, work, ldw, cx);
    if (route == R_BAND) rc = lp_band_solve(call, F, work, (lapack_int)ldw, (lapack_int)B.n);
    else rc = lp_dense_solve(call, F, &A, work, (lapack_int)ldw, (lapack_int)B.n);
    if (rc == SILC_OK && work != X.val) {
        int64_t j;
        for (j = 0; j < B.n; j++)
            memcpy(X.val + (size_t)j * A.n * w, work + (size_t)j * ldw * w, (size_t)A.n * w * sizeof(double));
    }
    if (work != X.val) lp_free(work);
    if (rc != SILC_OK) {
        lp_host->release(out);
        lp_factor_free(owned);
        return rc;
    }
    fill_report(call->report, F);
    if (mixed_asked)
        snprintf(call->report->note, sizeof call->report->note,
                 "lapack.precision = mixed is real only: factored in double");
    call->report->reused_factor = !fresh && F->kind != LP_TRI && F->kind != LP_LSY;
    call->report->factor_seconds = fresh ? t1 - t0 : 0.0;
    call->report->solve_seconds = lp_host->now() - t1 + (fresh ? 0.0 : te);
    lp_factor_free(owned);
    call->out = out;
    return SILC_OK;
}

/* ---- tables and init ----------------------------------------------------------- */

static void set_threads(int nthreads)
{
    openblas_set_num_threads(nthreads > 0 ? nthreads : 1);
}

static const silc_op_entry lp_ops[SILC_OP_COUNT] = {
    [SILC_OP_MATMUL] = {op_matmul, accepts_matmul},
    [SILC_OP_SOLVE] = {op_solve, accepts_solve},
};

static const silc_backend lp_backends[1] = {
    {NULL, "OpenBLAS + LAPACKE: dense products; dense, SPD, symmetric indefinite, triangular, "
           "band, tridiagonal and least-squares solves",
     SILC_OP_COUNT, lp_ops}};

static const silc_option_spec lp_options[] = {
    {"rank_tol", SILC_OPT_DOUBLE, "0",
     "least squares: rcond below which A counts as rank deficient and dgelsy is used "
     "(0 = max(m,n) * eps)"},
    {"precision", SILC_OPT_STRING, "double",
     "general and SPD dense solves: double (dgetrf / dpotrf) or mixed (dsgesv / dsposv: factor "
     "in single precision, refine in double, fall back to double when that fails)"},
};

static char lp_version[192];

/* Both ops take complex operands (the z routines). */
static const uint32_t lp_complex_ops[1] = {SILC_COMPLEX_OPS(SILC_OP_MATMUL) | SILC_COMPLEX_OPS(SILC_OP_SOLVE)};

static silc_plugin lp_plugin = {
    SILC_ABI_MAJOR, SILC_ABI_MINOR, sizeof(silc_plugin), (int)sizeof(silc_index),
    "lapack", lp_version, 1, lp_backends,
    (int)(sizeof lp_options / sizeof lp_options[0]), lp_options,
    set_threads, NULL, NULL, lp_complex_ops};

SILC_PLUGIN_EXPORT int silc_plugin_init(const silc_host_api *host, const silc_plugin **out,
                                        const char **errmsg)
{
    const char *config;
    if (silc_host_check(host, SILC_HOST_NEEDS(threads), errmsg) || !out) return 1;
    lp_host = host;
    config = openblas_get_config();
    snprintf(lp_version, sizeof lp_version, "1.0 %s", config ? config : "OpenBLAS (unknown version)");
    *out = &lp_plugin;
    return 0;
}
