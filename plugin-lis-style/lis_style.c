/*
 * lis_style.c -- plugin-lis-style: the plugin table and the SOLVE operation.
 *
 * One backend, "lis-style", providing SOLVE for any square matrix.  CSR is
 * used as it is; a dense or band matrix is converted to CSR once (kept as an
 * attachment), because a user who forces an iterative solver on such a
 * system should get one rather than a refusal; the default dispatch lists
 * never send dense or band systems here.  Iterative solvers never claim a
 * matrix is not positive definite, so under solve.sparse.spd a failure is a
 * failure (SILC_ENOTCONV, SILC_EBREAKDOWN), never SILC_ENOTSPD.
 *
 * Options come from the plugin's one typed option, "options", holding a Lis
 * option string (`lis-style.options = -i cg -p ilu -tol 1e-12`, per call
 * `solve(A, b, "lis-style.options = -i bicg")`); lis_options.c reads it.
 * An empty option string runs CG + IC(0) under an SPD class and BiCGSTAB +
 * ILU(0) otherwise; once any option is written, the rest take Lis's own
 * defaults (-i bicg -p none -tol 1e-12 -maxiter 1000), so a Lis user's
 * option string means what it means in Lis.
 *
 * The preconditioner is an attachment of the matrix value keyed by its full
 * description ("lis-style.pc.ILU(0)"), so it is built once per matrix value
 * and reused by every later solve with it; A' (for BiCG and the BiCR family)
 * likewise.
 *
 * The driver runs the method, then recomputes b - A x: a method whose
 * recursive residual met the tolerance while the true one did not is
 * restarted from its iterate (as long as that keeps gaining), and only the
 * true residual is reported.  Outcomes: converged -> SILC_OK; iteration limit
 * -> SILC_ENOTCONV; breakdown or NaN -> SILC_EBREAKDOWN, each message naming
 * the method, the iteration and the relative residual.  A third operand
 * (ABI 1.6: the host's initial guess, the previous solution of a time loop
 * under solve.initial_guess) is the starting point unless -initx_zeros true
 * says otherwise; the tolerance then applies to ||r|| / ||b|| unless
 * -conv_cond says otherwise, and `info` says so.
 *
 * Complex values (ABI 1.8: complex_ops declares SOLVE): A, b and x hold
 * complex entries and the methods of lis.h's complex list run in complex
 * arithmetic (c.cplx).  The Hermitian-only CG and the complex symmetric
 * COCG look at A's properties first and refuse a matrix that is not of
 * their kind, naming it, so the dispatcher's list moves on to the next
 * backend; a method or preconditioner with no complex form is refused by
 * name.  A real A never comes with a complex b (the host splits such a
 * solve into two real ones); if it did, it is refused too.  Without options a complex system gets CG (Hermitian, under an SPD
 * class), COCG (complex symmetric) or BiCGSTAB, each with ILU(0).
 * Outcomes and messages are the real path's.
 *
 * Norms are scaled (lk_nrm2), but the methods' inner products (r, r),
 * (p, A p) would under- or overflow once entries leave about 1e+-100: systems
 * that far from 1 arrive here already scaled by powers of two by the core
 * (core/accuracy/scale.c), which does it once for every backend.
 */
#include "lis.h"

#include <math.h>
#include <stdio.h>
#include <string.h>

const silc_host_api *lis_host;

/* ---- converted matrices (attachments) ------------------------------------------ */

void lis_matrix_free(void *p)
{
    lis_matrix *M = p;
    if (!M) return;
    if (M->rp) lis_host->free(M->rp);
    if (M->ci) lis_host->free(M->ci);
    if (M->v) lis_host->free(M->v);
    lis_host->free(M);
}

/* w doubles per entry: 1, or 2 for a complex matrix. */
static lis_matrix *matrix_alloc_w(int64_t m, int64_t n, int64_t nnz, int w)
{
    lis_matrix *M = lis_host->calloc(1, sizeof *M);
    if (!M) return NULL;
    M->rp = lis_host->calloc((size_t)m + 1, sizeof(int64_t));
    M->ci = lis_host->alloc((size_t)(nnz > 0 ? nnz : 1) * sizeof(int64_t));
    M->v = lis_host->alloc((size_t)(nnz > 0 ? nnz : 1) * (size_t)w * sizeof(double));
    if (!M->rp || !M->ci || !M->v) {
        lis_matrix_free(M);
        return NULL;
    }
    M->A.m = m;
    M->A.n = n;
    M->A.rp = M->rp;
    M->A.ci = M->ci;
    M->A.v = M->v;
    return M;
}

lis_matrix *lis_matrix_alloc(int64_t m, int64_t n, int64_t nnz)
{
    return matrix_alloc_w(m, n, nnz, 1);
}

/* Entry (i, j) of a dense or band value of sw doubles an entry (1 real, 2
 * complex) into out[0..w), w >= sw (a real entry read as complex gets a
 * zero imaginary part); returns 1 when it is nonzero. */
static int entry(const silc_view *a, int sw, int64_t i, int64_t j, double *out, int w)
{
    const double *e = NULL;
    int nz = 0;
    if (a->format == SILC_FMT_DENSE) e = a->val + sw * (i + j * a->m);
    else if (!(i - j > a->kl || j - i > a->ku)) e = a->val + sw * ((a->ku + i - j) + j * a->ld);
    for (int k = 0; k < w; k++) {
        out[k] = e && k < sw ? e[k] : 0.0;
        nz |= out[k] != 0.0;
    }
    return nz;
}

/* CSR of a dense or band value of w doubles an entry, zeros dropped. */
static lis_matrix *matrix_from_full(const silc_view *a, int w)
{
    int64_t i, j, nnz = 0;
    lis_matrix *M;
    for (int pass = 0; pass < 2; pass++) {
        nnz = 0;
        for (i = 0; i < a->m; i++) {
            int64_t lo = 0, hi = a->n;
            if (a->format == SILC_FMT_BAND) {
                lo = i - a->kl > 0 ? i - a->kl : 0;
                hi = i + a->ku + 1 < a->n ? i + a->ku + 1 : a->n;
            }
            for (j = lo; j < hi; j++) {
                double x[2];
                if (!entry(a, w, i, j, x, w)) continue;
                if (pass) {
                    M->ci[nnz] = j;
                    for (int k = 0; k < w; k++) M->v[w * nnz + k] = x[k];
                }
                nnz++;
            }
            if (pass) M->rp[i + 1] = nnz;
        }
        if (!pass && !(M = matrix_alloc_w(a->m, a->n, nnz, w))) return NULL;
    }
    return M;
}

lis_matrix *lis_matrix_transpose(const lk_csr *A)
{
    int64_t nnz = A->rp[A->m], i, k;
    lis_matrix *T = lis_matrix_alloc(A->n, A->m, nnz);
    int64_t *next;
    if (!T) return NULL;
    next = lis_host->calloc((size_t)A->n + 1, sizeof(int64_t));
    if (!next) {
        lis_matrix_free(T);
        return NULL;
    }
    for (k = 0; k < nnz; k++) T->rp[A->ci[k] + 1]++;
    for (i = 0; i < A->n; i++) T->rp[i + 1] += T->rp[i];
    memcpy(next, T->rp, (size_t)A->n * sizeof(int64_t));
    for (i = 0; i < A->m; i++)
        for (k = A->rp[i]; k < A->rp[i + 1]; k++) {
            int64_t at = next[A->ci[k]]++;
            T->ci[at] = i;
            T->v[at] = A->v[k];
        }
    lis_host->free(next);
    return T;
}

/* 1 when v holds complex values (a host older than ABI 1.8 has none). */
static int is_complex(const silc_value *v)
{
    return v && lis_host->struct_size >= SILC_HOST_NEEDS(field) && lis_host->field(v) == SILC_FIELD_COMPLEX;
}

/* ---- accepts ---------------------------------------------------------------------- */

static int solve_accepts(const silc_call *call, const char **why)
{
    silc_view a;
    if (call->nin < 2 || !call->in[0] || !call->in[1]) {
        *why = "needs a matrix and a right-hand side";
        return 0;
    }
    lis_host->view(call->in[0], &a);
    if (a.m != a.n) {
        *why = "iterative solvers need a square matrix";
        return 0;
    }
    return 1;
}

/* ---- the solve --------------------------------------------------------------------------- */

static lis_solver_fn solver_fn(int id)
{
    switch (id) {
    case LIS_CG: return lis_cg;
    case LIS_CR: return lis_cr;
    case LIS_BICG: case LIS_BICR: return lis_bicg;
    case LIS_CGS: case LIS_CRS: return lis_cgs;
    case LIS_BICGSTAB: case LIS_BICRSTAB: return lis_bicgstab;
    case LIS_BICGSTABL: return lis_bicgstabl;
    case LIS_GPBICG: case LIS_GPBICR: return lis_gpbicg;
    case LIS_TFQMR: return lis_tfqmr;
    case LIS_GMRES: return lis_gmres;
    case LIS_FGMRES: return lis_fgmres;
    case LIS_ORTHOMIN: return lis_orthomin;
    case LIS_MINRES: return lis_minres;
    case LIS_IDRS: case LIS_IDR1: return lis_idrs;
    case LIS_JACOBI: return lis_jacobi;
    case LIS_GS: return lis_gs;
    case LIS_SOR: return lis_sor;
    default: return NULL;
    }
}

/* The complex methods (c.cplx): those with a complex form, NULL for the rest. */
static lis_solver_fn solver_fn_complex(int id)
{
    switch (id) {
    case LIS_CG: return lis_cg_z;
    case LIS_COCG: return lis_cocg_z;
    case LIS_BICGSTAB: return lis_bicgstab_z;
    case LIS_GMRES: return lis_gmres_z;
    case LIS_FGMRES: return lis_fgmres_z;
    default: return NULL;
    }
}

/* Column j of B (any format, sw doubles an entry) into b[0..m) of w >= sw
 * doubles an entry. */
static void column(const silc_view *B, int sw, int64_t j, double *b, int w)
{
    int64_t i;
    if (B->format == SILC_FMT_CSR) {
        for (i = 0; i < B->m; i++) {
            for (int q = 0; q < w; q++) b[w * i + q] = 0;
            for (int64_t k = B->rowptr[i]; k < B->rowptr[i + 1]; k++)
                if (B->colind[k] == j)
                    for (int q = 0; q < sw; q++) b[w * i + q] = B->val[sw * k + q];
        }
    } else {
        for (i = 0; i < B->m; i++) entry(B, sw, i, j, b + w * i, w);
    }
}

static int ends_with(const char *s, const char *suffix)
{
    size_t a = s ? strlen(s) : 0, b = strlen(suffix);
    return a >= b && strcmp(s + a - b, suffix) == 0;
}

/* The outcome of one column, for the report. */
typedef struct col_result {
    int64_t iterations;
    double resid;
    int restarts;
    int from_guess;         /* started from the initial guess (it was better than zero) */
    double backward;        /* -conv_cond backward: the accepted backward error */
} col_result;

/* ||r||inf / (||A||inf ||x||inf + ||b||inf), r = b - A x: the normwise
 * backward error that -conv_cond backward stops on (lis.h). */
static double modulus(const lis_ctx *c, const double *v, int64_t i)
{
    return c->cplx ? hypot(v[2 * i], v[2 * i + 1]) : fabs(v[i]);
}

static double backward_error(const lis_ctx *c, const lis_vec *x, const lis_vec *r, const double *b)
{
    double rn = 0, xn = 0, bn = 0;
    int64_t i;
    for (i = 0; i < c->n; i++) {
        rn = fmax(rn, modulus(c, r->h, i));
        xn = fmax(xn, modulus(c, x->h, i));
        bn = fmax(bn, modulus(c, b, i));
    }
    return rn / (c->anorm * xn + bn);
}

/* Solves column `col` into x (double), driving restarts; returns a SILC status
 * after host->error on failure.  tag is "" or " (column 3)". */
static int solve_column(silc_call *call, lis_ctx *c, lis_solver_fn fn, double *bcol,
                        const double *x0, double *xout, const char *tag, col_result *res)
{
    lis_vec x = {NULL, NULL}, work = {NULL, NULL};
    double r0n, bn, prev = 1.0 / 0.0, tr = 0;
    int st, rc = SILC_OK;
    int64_t nd = c->cplx ? 2 * c->n : c->n; /* doubles of a vector */
    c->b.h = bcol;
    c->b.l = NULL;
    c->iter = 0;
    c->resid = 0;
    c->why[0] = '\0';
    res->restarts = 0;
    if (lv_new(c, &x) || lv_new(c, &work)) {
        lv_free(&x);
        return lis_host->error(call, SILC_ENOMEM, "lis-style: out of memory for %lld-vectors",
                               (long long)c->n);
    }
    if (x0) lk_copy(nd, x0, x.h);
    c->den = 1;
    r0n = lis_true_resid(c, &x, &work);
    bn = lk_nrm2(nd, bcol);
    if (x0 && !(r0n < bn)) {
        /* A guess no better than zero (another system's solution) would
         * only cost iterations, or trip a divergence test: start from 0. */
        lv_zero(c, &x);
        x0 = NULL;
        r0n = lis_true_resid(c, &x, &work);
    }
    res->from_guess = x0 != NULL;
    /* From an initial guess (a warm start) the residual is measured against
     * ||b||, as PETSc does: against ||r0|| a good guess would only demand
     * more iterations. */
    c->den = (c->o->conv_cond == 1 || c->o->conv_cond == LIS_CONV_BACKWARD || (c->o->conv_cond < 0 && x0)) &&
                     bn > 0
                 ? bn
                 : r0n;
    if (r0n == 0) { /* x0 solves it already (b = 0 from x0 = 0) */
        res->iterations = 0;
        res->resid = 0;
        goto copy_out;
    }
    if (r0n != r0n) {
        rc = lis_host->error(call, SILC_EBREAKDOWN, "lis-style %s%s: produced NaN at iteration 0 "
                             "(the matrix or right-hand side holds NaN or Inf)", c->label, tag);
        goto done;
    }
    for (;;) {
        st = fn(c, &x);
        if (st == LIS_NOMEM) {
            rc = lis_host->error(call, SILC_ENOMEM, "lis-style %s: out of memory", c->label);
            goto done;
        }
        if (st == LIS_NAN) {
            rc = lis_host->error(call, SILC_EBREAKDOWN, "lis-style %s%s: produced NaN at iteration %lld",
                                 c->label, tag, (long long)c->iter);
            goto done;
        }
        tr = lis_true_resid(c, &x, &work); /* work = b - A x */
        c->resid = tr;
        if (c->o->conv_cond == LIS_CONV_BACKWARD) {
            res->backward = backward_error(c, &x, &work, bcol);
            if (res->backward <= c->o->tol) break;
        } else if (tr <= c->o->tol) {
            break;
        }
        if (st == LIS_BREAKDOWN) {
            rc = lis_host->error(call, SILC_EBREAKDOWN,
                                 "lis-style %s%s: breakdown at iteration %lld (%s); relative "
                                 "residual %.1e", c->label, tag, (long long)c->iter + 1, c->why, tr);
            goto done;
        }
        if (tr != tr) {
            rc = lis_host->error(call, SILC_EBREAKDOWN, "lis-style %s%s: produced NaN at iteration %lld",
                                 c->label, tag, (long long)c->iter);
            goto done;
        }
        if (st == LIS_CONVERGED && !lis_limit(c) && tr < 0.5 * prev && res->restarts < 50) {
            /* The recursion drifted from b - A x: restart from the iterate. */
            prev = tr;
            res->restarts++;
            continue;
        }
        {
            /* Under -conv_cond backward the number that missed is the backward error. */
            char also[48] = "";
            if (c->o->conv_cond == LIS_CONV_BACKWARD)
                snprintf(also, sizeof also, ", backward error %.1e", res->backward);
            if (st == LIS_CONVERGED)
                rc = lis_host->error(call, SILC_ENOTCONV,
                                     "lis-style %s%s: not converged: the recursive residual met the "
                                     "tolerance but the true relative residual stalled at %.1e%s "
                                     "after %lld iterations", c->label, tag, tr, also, (long long)c->iter);
            else
                rc = lis_host->error(call, SILC_ENOTCONV,
                                     "lis-style %s%s: not converged after %lld iterations (relative "
                                     "residual %.1e%s)", c->label, tag, (long long)c->iter, tr, also);
        }
        goto done;
    }
    res->iterations = c->iter;
    res->resid = tr;
copy_out:
    lk_copy(nd, x.h, xout); /* the double rounding of hi + lo is hi */
done:
    lv_free(&x);
    lv_free(&work);
    return rc;
}

static int solve_run(silc_call *call)
{
    const silc_host_api *H = lis_host;
    silc_report *rep = call->report;
    silc_view a, B, o;
    lis_options opt;
    lis_ctx c;
    lk_csr A;
    const lk_csr *At = NULL;
    lis_pc *pc = NULL;
    silc_value *out = NULL;
    lis_solver_fn fn;
    char err[320], slabel[32], plabel[48], key[96];
    const char *text = H->option_string(call, "options", "");
    double t0 = H->now(), *bcol = NULL, *x0col = NULL;
    int rc = SILC_OK, reused = 0, use_x0 = 0, restarts = 0, guesses = 0;
    int cplx = is_complex(call->in[0]), w = cplx ? 2 : 1; /* doubles an entry */
    int64_t j, max_iter = 0;
    double max_resid = 0, max_backward = 0;

    lis_options_init(&opt);
    if (lis_options_parse(text, &opt, err, sizeof err))
        return H->error(call, SILC_EARG, "lis-style options: %s (in '%s')", err, text);
    lis_options_finish(&opt, ends_with(call->op_class, ".spd"),
                       call->op_class && !strcmp(call->op_class, "solve.sparse.mmatrix.spd"));
    if (cplx && !opt.given) {
        /* the complex defaults: the method A's structure admits, ILU(0) */
        const silc_props *pr = silc_props_of(H, call->in[0], SILC_PROPS_SYMMETRY);
        opt.solver = ends_with(call->op_class, ".spd") && pr->hermitian ? LIS_CG
                     : pr->symmetric                                   ? LIS_COCG
                                                                       : LIS_BICGSTAB;
        opt.precon = LIS_PC_ILU;
        opt.conv_cond = -1;
        opt.maxiter = 1000;
    }
    lis_solver_label(&opt, slabel, sizeof slabel);
    lis_precon_label(&opt, plabel, sizeof plabel);
    if ((opt.solver == LIS_JACOBI || opt.solver == LIS_GS || opt.solver == LIS_SOR) &&
        opt.precon != LIS_PC_NONE)
        return H->error(call, SILC_EARG, "lis-style options: -i %s takes no preconditioner (got -p %s)",
                        lis_solver_name(opt.solver), plabel);
    if (cplx) {
        const silc_props *pr;
        if (!(fn = solver_fn_complex(opt.solver)))
            return H->error(call, SILC_EUNSUP, "lis-style: -i %s does not take complex values (complex: cg for "
                            "Hermitian positive definite, cocg for complex symmetric, bicgstab, gmres, fgmres)",
                            lis_solver_name(opt.solver));
        if (opt.precon != LIS_PC_NONE && opt.precon != LIS_PC_JACOBI && opt.precon != LIS_PC_ILU &&
            opt.precon != LIS_PC_ILUT && opt.precon != LIS_PC_SSOR)
            return H->error(call, SILC_EUNSUP, "lis-style: -p %s does not take complex values (complex: none, "
                            "jacobi, ilu, ilut, ssor)", plabel);
        if (opt.quad)
            return H->error(call, SILC_EUNSUP, "lis-style: -f quad does not take complex values (double only)");
        pr = silc_props_of(H, call->in[0], SILC_PROPS_SYMMETRY);
        /* A method for another kind of matrix would break down or wander:
         * refuse it, so that the list's next backend takes the system. */
        if (opt.solver == LIS_CG && !pr->hermitian)
            return H->error(call, SILC_EUNSUP, "lis-style CG needs a Hermitian matrix (A = A'), and this complex "
                            "one is not%s", pr->symmetric ? " (it is complex symmetric: -i cocg)"
                                                          : " (-i bicgstab or gmres)");
        if (opt.solver == LIS_COCG && !pr->symmetric)
            return H->error(call, SILC_EUNSUP, "lis-style COCG needs a complex symmetric matrix (A = A.'), "
                            "and this one is not%s", pr->hermitian ? " (it is Hermitian: -i cg)"
                                                                   : " (-i bicgstab or gmres)");
    } else if (is_complex(call->in[1]) || (call->nin >= 3 && is_complex(call->in[2]))) {
        return H->error(call, SILC_EARG, "lis-style: a real matrix with a complex right-hand side or initial "
                        "guess (the host splits such a solve into real ones)");
    } else if (opt.solver == LIS_COCG) {
        return H->error(call, SILC_EUNSUP, "lis-style: -i cocg is for complex symmetric matrices, and this one "
                        "is real (-i cg for a symmetric positive definite one)");
    } else {
        fn = solver_fn(opt.solver);
    }
    if (!fn) return H->error(call, SILC_EINTERNAL, "lis-style: no solver %d", opt.solver);

    /* The matrix as CSR. */
    H->view(call->in[0], &a);
    if (a.format == SILC_FMT_CSR) {
        A.m = a.m, A.n = a.n, A.rp = a.rowptr, A.ci = a.colind, A.v = a.val;
    } else {
        lis_matrix *M = H->attach_get(call->in[0], "lis-style.csr");
        if (!M) {
            if (!(M = matrix_from_full(&a, w)))
                return H->error(call, SILC_ENOMEM, "lis-style: out of memory converting A to CSR");
            if (H->attach_set(call->in[0], "lis-style.csr", M, lis_matrix_free)) {
                lis_matrix_free(M);
                return H->error(call, SILC_ENOMEM, "lis-style: cannot attach the CSR copy of A");
            }
        }
        A = M->A;
    }
    if (!cplx && lis_needs_transpose(opt.solver)) {
        if (silc_props_of(H, call->in[0], SILC_PROPS_SYMMETRY)->symmetric) {
            At = &A;
        } else {
            lis_matrix *T = H->attach_get(call->in[0], "lis-style.transpose");
            if (!T) {
                if (!(T = lis_matrix_transpose(&A)))
                    return H->error(call, SILC_ENOMEM, "lis-style: out of memory for A'");
                if (H->attach_set(call->in[0], "lis-style.transpose", T, lis_matrix_free)) {
                    lis_matrix_free(T);
                    return H->error(call, SILC_ENOMEM, "lis-style: cannot attach A'");
                }
            }
            At = &T->A;
        }
    }

    /* The preconditioner, built once per matrix value and description. */
    if (opt.precon == LIS_PC_SAAMG && !silc_props_of(H, call->in[0], SILC_PROPS_SYMMETRY)->symmetric) {
        if (!opt.saamg_unsym)
            return H->error(call, SILC_EARG, "lis-style options: -p saamg is for symmetric matrices; "
                                             "-saamg_unsym true applies it to an unsymmetric one");
        if (lis_needs_transpose(opt.solver))
            return H->error(call, SILC_EARG, "lis-style options: -i %s needs M^-T, which SA-AMG on an "
                                             "unsymmetric matrix does not provide (use -i bicgstab, gmres, ...)",
                            lis_solver_name(opt.solver));
    }
    if (opt.precon != LIS_PC_NONE) {
        snprintf(key, sizeof key, "lis-style.pc.%s", plabel);
        pc = H->attach_get(call->in[0], key);
        if (pc) {
            reused = 1;
        } else {
            rc = cplx ? lis_pc_build_z(&A, &opt, &pc, err, sizeof err) : lis_pc_build(&A, &opt, &pc, err, sizeof err);
            if (rc) return H->error(call, rc, "%s", err);
            if (H->attach_set(call->in[0], key, pc, lis_pc_free)) {
                lis_pc_free(pc);
                return H->error(call, SILC_ENOMEM, "lis-style: cannot attach the preconditioner");
            }
        }
    }

    /* Right-hand sides, one column at a time. */
    H->view(call->in[1], &B);
    use_x0 = opt.initx_zeros != 1 && call->nin >= 3 && call->in[2];
    if (use_x0) {
        silc_view X0;
        H->view(call->in[2], &X0);
        if (X0.m != a.n || X0.n != B.n)
            return H->error(call, SILC_EARG, "lis-style: the initial guess is %lldx%lld, the solution %lldx%lld",
                            (long long)X0.m, (long long)X0.n, (long long)a.n, (long long)B.n);
    }
    out = cplx ? H->dense_new_complex(a.n, B.n) : H->dense_new(a.n, B.n);
    bcol = H->alloc((size_t)(a.n > 0 ? a.n : 1) * (size_t)w * sizeof(double));
    x0col = H->alloc((size_t)(a.n > 0 ? a.n : 1) * (size_t)w * sizeof(double));
    memset(&c, 0, sizeof c);
    c.w1 = H->alloc((size_t)(a.n > 0 ? a.n : 1) * sizeof(double));
    if (!out || !bcol || !x0col || !c.w1) {
        rc = H->error(call, SILC_ENOMEM, "lis-style: out of memory for the %lldx%lld solution",
                      (long long)a.n, (long long)B.n);
        goto done;
    }
    H->view(out, &o);
    c.A = &A;
    c.At = At;
    c.pc = pc;
    c.o = &opt;
    c.n = a.n;
    c.call = call;
    c.cplx = cplx;
    if (opt.conv_cond == LIS_CONV_BACKWARD)
        for (j = 0; j < A.m; j++) {
            double row = 0;
            int64_t k;
            for (k = A.rp[j]; k < A.rp[j + 1]; k++) row += modulus(&c, A.v, k);
            if (row > c.anorm) c.anorm = row;
        }
    c.quad = opt.quad;
    snprintf(c.label, sizeof c.label, "%s", slabel);
    for (j = 0; j < B.n; j++) {
        char tag[32] = "";
        col_result res = {0, 0, 0, 0, 0};
        if (B.n > 1) snprintf(tag, sizeof tag, " (column %lld)", (long long)j + 1);
        column(&B, is_complex(call->in[1]) ? 2 : 1, j, bcol, w);
        if (use_x0) {
            silc_view X0;
            H->view(call->in[2], &X0);
            column(&X0, is_complex(call->in[2]) ? 2 : 1, j, x0col, w);
        }
        rc = solve_column(call, &c, fn, bcol, use_x0 ? x0col : NULL, o.val + j * a.n * w, tag, &res);
        if (rc) goto done;
        if (res.iterations > max_iter) max_iter = res.iterations;
        if (res.resid > max_resid) max_resid = res.resid;
        if (res.backward > max_backward) max_backward = res.backward;
        restarts += res.restarts;
        guesses += res.from_guess;
    }

    /* The report. */
    {
        char m[160];
        if (opt.precon == LIS_PC_NONE)
            snprintf(m, sizeof m, "%s, no preconditioner%s", slabel, opt.quad ? ", double-double" : "");
        else
            snprintf(m, sizeof m, "%s + %s%s", slabel, plabel, opt.quad ? ", double-double" : "");
        snprintf(rep->method, sizeof rep->method, "%.63s", m);
    }
    rep->iterations = max_iter;
    rep->resid = max_resid;
    if (H->abi_minor >= 6) {
        rep->initial_guess = guesses > 0;
        rep->tol = opt.tol; /* the host verifies the result against it */
    }
    rep->reused_factor = reused;
    rep->factor_seconds = pc && !reused ? pc->seconds : 0;
    rep->solve_seconds = H->now() - t0 - rep->factor_seconds;
    {
        int k = opt.conv_cond == LIS_CONV_BACKWARD
                    ? snprintf(rep->note, sizeof rep->note, "converged: backward error %.2e <= tol %.1e",
                               max_backward, opt.tol)
                    : snprintf(rep->note, sizeof rep->note, "converged: ||r||/%s = %.2e <= tol %.1e",
                               opt.conv_cond == 1 || (opt.conv_cond < 0 && guesses) ? "||b||" : "||r0||",
                               max_resid, opt.tol);
        size_t u = k > 0 ? (size_t)k : 0;
        if (pc && u < sizeof rep->note)
            u += (size_t)snprintf(rep->note + u, sizeof rep->note - u, "; preconditioner %s",
                                  reused ? "reused" : "built");
        if (pc && pc->shift > 0 && u < sizeof rep->note)
            u += (size_t)snprintf(rep->note + u, sizeof rep->note - u, " with diagonal shift %g",
                                  pc->shift);
        if (pc && pc->amg && u < sizeof rep->note)
            u += (size_t)snprintf(rep->note + u, sizeof rep->note - u, ", %d levels",
                                  lis_amg_levels(pc->amg));
        if (restarts && u < sizeof rep->note)
            u += (size_t)snprintf(rep->note + u, sizeof rep->note - u,
                                  "; restarted %d time(s) on residual drift", restarts);
        if (use_x0 && u < sizeof rep->note)
            u += (size_t)snprintf(rep->note + u, sizeof rep->note - u, guesses
                                  ? "; started from the initial guess"
                                  : "; the initial guess was no better than 0: started from 0");
        if (opt.initx_zeros == 0 && !use_x0 && u < sizeof rep->note)
            snprintf(rep->note + u, sizeof rep->note - u,
                     "; -initx_zeros false but no initial guess given: started from 0");
    }
    call->out = out;
    out = NULL;
done:
    if (out) H->release(out);
    if (bcol) H->free(bcol);
    if (x0col) H->free(x0col);
    if (c.w1) H->free(c.w1);
    return rc;
}

/* ---- the plugin table ---------------------------------------------------------------------- */

static void lis_set_threads(int nthreads)
{
    lk_set_threads(nthreads);
}

static const silc_op_entry lis_ops[SILC_OP_COUNT] = {
    [SILC_OP_SOLVE] = {solve_run, solve_accepts},
};

static const silc_backend lis_backends[] = {
    {NULL, "in-house Krylov and stationary solvers with Lis option syntax", SILC_OP_COUNT, lis_ops},
};

static const silc_option_spec lis_option_specs[] = {
    {"options", SILC_OPT_STRING, "",
     "Lis option string, e.g. '-i bicgstab -p ilu -ilu_fill 1 -tol 1e-10 -maxiter 2000 -f quad'; complex "
     "systems take -i cg (Hermitian), cocg (complex symmetric), bicgstab, gmres, fgmres with -p none, jacobi, "
     "ilu, ilut, ssor"},
};

/* SOLVE takes complex values (the methods and preconditioners of lis.h's
 * complex list). */
static const uint32_t lis_complex_ops[] = {SILC_COMPLEX_OPS(SILC_OP_SOLVE)};

static const silc_plugin lis_plugin = {
    SILC_ABI_MAJOR, SILC_ABI_MINOR, sizeof(silc_plugin), (int)sizeof(silc_index),
    "lis-style", "1.0 (own implementation of the Lis interface)",
    1, lis_backends,
    1, lis_option_specs,
    lis_set_threads,
    NULL,
    NULL,
    lis_complex_ops,
};

SILC_PLUGIN_EXPORT int silc_plugin_init(const silc_host_api *host, const silc_plugin **out,
                                        const char **errmsg)
{
    if (silc_host_check(host, SILC_HOST_NEEDS(threads), errmsg) || !out) return 1;
    lis_host = host;
    *out = &lis_plugin;
    return 0;
}
