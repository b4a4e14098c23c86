/*
 * lis.h -- internal interfaces of plugin-lis-style, our own implementation
 * of the Lis user experience (no Lis code): the Lis option string, Krylov and
 * stationary solvers, preconditioners, and double-double `-f quad`.
 *
 * The pieces, one file each:
 *   lis_options.c     the option string -> lis_options (Lis names and numbers)
 *   lis_kernels.c     double SpMV and vector kernels (OpenMP), host-free,
 *                     real and complex from one text (lis_kernels_t.h)
 *   lis_dd.c          double-double scalars and vector kernels
 *   lis_space.c       the solver's arithmetic: scalars and vectors that are
 *                     double or double-double depending on -f, convergence test
 *   lis_precond.c     Jacobi, ILU(k), IC(0), SSOR, ILUT
 *   lis_krylov.c      CG, BiCG, CGS, BiCGSTAB, BiCGSTAB(l), GPBiCG, TFQMR,
 *                     MINRES, IDR(s)
 *   lis_gmres.c       GMRES(m), FGMRES(m)
 *   lis_stationary.c  Jacobi, Gauss-Seidel, SOR
 *   lis_style.c       the plugin table, the SOLVE op, attachments, reports
 * Every solver is written once against the lis_space.c operations declared
 * here, so each one runs in double and in double-double.
 *
 * Complex values (ABI 1.8): CG (Hermitian positive definite), COCG (complex
 * symmetric), BiCGSTAB, GMRES(m) and FGMRES(m), with no preconditioner,
 * Jacobi, ILU(k), ILUT or SSOR, in double.  Those methods and the
 * preconditioners are written once over lis_field.h's names
 * (lis_krylov_t.h, lis_gmres_t.h, lis_precond_t.h) and included once per
 * field; a complex vector is a lis_vec whose h holds n complex entries
 * (2n doubles, interleaved) and the lvz_* operations below.
 */
#ifndef LIS_H
#define LIS_H

#include <stddef.h>
#include <stdint.h>

#include "lis_dd.h"
#include "lis_kernels.h"
#include "silc_plugin.h"

extern const silc_host_api *lis_host;

/* ---- options ------------------------------------------------------------------ */

/* Solver numbers are Lis's own (`-i 2` is BiCG), from the Lis 2.x option
 * table (lis_solver_set_option(3), the Lis User Guide): cg 1, bicg 2, cgs 3,
 * bicgstab 4, bicgstabl 5, gpbicg 6, tfqmr 7, orthomin 8, gmres 9, jacobi 10,
 * gs 11, sor 12, bicgsafe 13, cr 14, bicr 15, crs 16, bicrstab 17, gpbicr 18,
 * bicrsafe 19, fgmres 20, idrs 21, idr1 22, minres 23, cocg 24, cocr 25.
 * Not implemented here, and refused by name: bicgsafe, bicrsafe and cocr.
 * cocg (complex symmetric matrices) runs on complex values only. */
enum lis_solver_id {
    LIS_CG = 1, LIS_BICG = 2, LIS_CGS = 3, LIS_BICGSTAB = 4, LIS_BICGSTABL = 5,
    LIS_GPBICG = 6, LIS_TFQMR = 7, LIS_ORTHOMIN = 8, LIS_GMRES = 9, LIS_JACOBI = 10,
    LIS_GS = 11, LIS_SOR = 12, LIS_CR = 14, LIS_BICR = 15, LIS_CRS = 16, LIS_BICRSTAB = 17,
    LIS_GPBICR = 18, LIS_FGMRES = 20, LIS_IDRS = 21, LIS_IDR1 = 22, LIS_MINRES = 23, LIS_COCG = 24
};

/* The BiCR family (BiCR, CRS, BiCRSTAB, GPBiCR) runs the code of BiCG, CGS,
 * BiCGSTAB and GPBiCG from another shadow residual (lis_krylov.c), for which
 * it needs A' as BiCG does. */
int lis_bicr_family(int solver);
int lis_needs_transpose(int solver);

/* Preconditioner numbers as in Lis (-p): none 0, jacobi 1, ilu 2, ssor 3,
 * hybrid 4, is 5, sainv 6, saamg 7, iluc 8, ilut 9 (hybrid, is, sainv and
 * iluc are refused by name).  IC(0) is not among Lis's, so it has a name
 * only (and an internal number outside Lis's range). */
enum lis_precon_id {
    LIS_PC_NONE = 0, LIS_PC_JACOBI = 1, LIS_PC_ILU = 2, LIS_PC_SSOR = 3, LIS_PC_SAAMG = 7, LIS_PC_ILUT = 9,
    LIS_PC_IC = 100
};

/* -conv_cond backward (SILC's, not Lis's): the method iterates as under
 * nrm2_b, and its result is accepted as soon as the normwise backward
 * error ||b - A x||inf / (||A||inf ||x||inf + ||b||inf) -- the yardstick of
 * SILC's accuracy report -- is at most -tol.  ||r|| / ||b|| <= tol implies
 * it; the converse does not hold, which is the point: on a large grid
 * ||r|| / ||b|| stalls near eps ||A|| ||x|| / ||b|| (3e-12 on the 500 x 500
 * Laplacian with b = 1), far above a backward error already at 1e-16. */
#define LIS_CONV_BACKWARD 2
/* The iteration limit of the M-matrix default: SA-AMG + CG takes 10-30
 * iterations on the M-matrices it suits; one that needs more is cheaper
 * handed to the factorization that follows it in the list. */
#define LIS_MMATRIX_MAXITER 100

typedef struct lis_options {
    int solver, precon;         /* 0 / -1 = not given (lis_options_finish) */
    int ilu_fill;               /* -ilu_fill k: ILU(k) */
    int ell;                    /* -ell l: BiCGSTAB(l) */
    int idrs_s;                 /* -idrs_s / -irestart s: IDR(s) */
    int restart;                /* -restart m: GMRES(m), FGMRES(m) */
    int64_t maxiter;
    double tol;
    double omega;               /* -omega: SOR */
    double ssor_omega;          /* -ssor_omega: SSOR preconditioner */
    double ilut_drop, ilut_rate;
    double saamg_theta;         /* -saamg_theta: SA-AMG strength threshold */
    int saamg_unsym;            /* -saamg_unsym true: SA-AMG accepts an unsymmetric A */
    int conv_cond;              /* 0: ||r|| / ||r0||, 1: ||r|| / ||b|| (2-norms); -1 not given:
                                   ||b|| when starting from an initial guess, else ||r0|| (= ||b||);
                                   LIS_CONV_BACKWARD: see there */
    int initx_zeros;            /* 1: x0 = 0; 0: x0 = in[2] when given; -1 not given: as 0 */
    int print;                  /* 1: residual history through host->log */
    int quad;                   /* 1: -f quad (double-double) */
    int given;                  /* options the string set */
} lis_options;

void lis_options_init(lis_options *o);
/* Parses a Lis option string into o (on top of the defaults).  On error
 * returns -1 with a message in err naming the option and the closest valid. */
int lis_options_parse(const char *text, lis_options *o, char *err, size_t errlen);
/* Fills the solver and preconditioner left unset.  An empty option string
 * gets a method for the class: under solve.sparse.mmatrix.spd (mmatrix_class)
 * CG + SA-AMG to a backward error of -tol within LIS_MMATRIX_MAXITER
 * iterations, under another SPD class CG + IC(0), else BiCGSTAB + ILU(0).
 * Once any option is written, Lis's defaults apply to the rest: -i bicg,
 * -p none. */
void lis_options_finish(lis_options *o, int spd_class, int mmatrix_class);
const char *lis_solver_name(int solver);
/* "BiCGSTAB(2)", "GMRES(40)", "IDR(4)", "CG". */
void lis_solver_label(const lis_options *o, char *buf, size_t len);
/* "ILU(0)", "ILUT(drop 0.05, rate 5)", "SSOR(omega 1)", "none": also the
 * preconditioner's attachment key suffix. */
void lis_precon_label(const lis_options *o, char *buf, size_t len);

/* ---- preconditioners ---------------------------------------------------------------- */

/* An array of count elements of size bytes from the host (never a request
 * for zero bytes, so NULL always means no memory), and A's diagonal into d,
 * refusing a zero or non-finite entry with "lis-style <what>: zero diagonal
 * entry in row r" in err (lis_precond.c). */
void *lis_array(size_t count, size_t size);
int lis_diagonal(const lk_csr *A, double *d, const char *what, char *err, size_t errlen);
int lis_diagonal_z(const lk_csr *A, double complex *d, const char *what, char *err, size_t errlen);

/* The SA-AMG hierarchy (lis_amg.c): symmetric A, or any with -saamg_unsym. */
typedef struct lis_amg lis_amg;
/* Builds it for A (borrowed: it must outlive the hierarchy) with strength
 * threshold theta; *nnz counts the entries of every level's matrix.
 * SILC_OK, SILC_ENOMEM, or SILC_EBREAKDOWN with err (zero diagonal,
 * coarsening that stalls, a singular coarsest level). */
int lis_amg_build(const lk_csr *A, double theta, lis_amg **out, int64_t *nnz, char *err, size_t errlen);
/* y = one V-cycle on x.  For a symmetric A, M is symmetric, so this is also
 * M'; for an unsymmetric one (-saamg_unsym) there is no M' here. */
void lis_amg_apply(const lis_amg *G, const double *x, double *y);
int lis_amg_levels(const lis_amg *G);
void lis_amg_free(lis_amg *G);

typedef struct lis_pc {
    int kind;                   /* enum lis_precon_id */
    int cplx;                   /* 1: every value array below holds complex entries (2 doubles each) */
    int64_t n;
    double *dinv;               /* Jacobi: 1/a_ii; factors: 1/u_ii; SSOR: 1/a_ii */
    /* Factors of ILU(k), ILUT, IC(0): M = (I + L) D (I + D^-1 U) with L strictly
     * lower and U strictly upper in CSR, D = diag(1/dinv). */
    int64_t *lp, *li, *up, *ui;
    double *lx, *ux;
    lk_csr A;                   /* SSOR: the matrix itself (borrowed) */
    double omega;               /* SSOR */
    lis_amg *amg;               /* SA-AMG */
    double shift;               /* diagonal shift that made the factorization work */
    int64_t nnz;                /* entries of L + U + D */
    double seconds;             /* setup time */
} lis_pc;

/* A CSR matrix the plugin owns (a converted A, A', the multigrid's levels). */
typedef struct lis_matrix {
    lk_csr A;                   /* views rp, ci, v */
    int64_t *rp, *ci;
    double *v;
} lis_matrix;
lis_matrix *lis_matrix_alloc(int64_t m, int64_t n, int64_t nnz); /* rp zeroed; NULL: no memory */
void lis_matrix_free(void *M);
lis_matrix *lis_matrix_transpose(const lk_csr *A);

/* Builds the preconditioner of o for A.  Returns SILC_OK, SILC_ENOMEM, or
 * SILC_EBREAKDOWN with a message in err (zero diagonal; pivots that stay bad
 * even after diagonal shifts). */
int lis_pc_build(const lk_csr *A, const lis_options *o, lis_pc **out, char *err, size_t errlen);
/* The same for a complex A (values interleaved): Jacobi, ILU(k), ILUT, SSOR
 * in complex arithmetic. */
int lis_pc_build_z(const lk_csr *A, const lis_options *o, lis_pc **out, char *err, size_t errlen);
void lis_pc_free(void *pc);
/* y = M^-1 x, y = M^-T x; for a complex P (P->cplx) x and y hold complex
 * entries, and only lis_pc_apply is defined (the complex methods need no M^-T). */
void lis_pc_apply(const lis_pc *P, const double *x, double *y);
void lis_pc_apply_t(const lis_pc *P, const double *x, double *y);

/* ---- the solver's arithmetic (lis_space.c) ------------------------------------ */

/* A vector of the solver: h alone in double, h + l in double-double. */
typedef struct lis_vec {
    double *h, *l;
} lis_vec;

enum lis_outcome { LIS_CONVERGED = 0, LIS_MAXITER, LIS_BREAKDOWN, LIS_NAN, LIS_NOMEM };

typedef struct lis_ctx {
    const lk_csr *A;
    const lk_csr *At;           /* A' (lis_needs_transpose), else NULL */
    const lis_pc *pc;           /* NULL = none */
    const lis_options *o;
    int64_t n;
    int quad;
    int cplx;                   /* 1: complex system (vectors of n complex entries; quad is 0) */
    lis_vec b;
    double den;                 /* denominator of the relative residual */
    double anorm;               /* ||A||inf, for -conv_cond backward */
    int64_t iter;               /* iterations so far (all restarts together) */
    double resid;               /* latest relative residual the solver saw */
    char label[32];             /* "BiCG" for messages */
    char why[160];              /* what broke down */
    double *w1, *w2;            /* double scratch for preconditioning in quad */
    silc_call *call;            /* the solve, for host->cancelled() (lis_limit); may be NULL */
} lis_ctx;

/* Scalars are double-double numbers; in double mode each operation rounds
 * its result to double, so a solver is written once for both precisions. */
static inline dd s_add(const lis_ctx *c, dd a, dd b) { return c->quad ? dd_add(a, b) : dd_d(a.hi + b.hi); }
static inline dd s_sub(const lis_ctx *c, dd a, dd b) { return c->quad ? dd_sub(a, b) : dd_d(a.hi - b.hi); }
static inline dd s_mul(const lis_ctx *c, dd a, dd b) { return c->quad ? dd_mul(a, b) : dd_d(a.hi * b.hi); }
static inline dd s_div(const lis_ctx *c, dd a, dd b) { return c->quad ? dd_div(a, b) : dd_d(a.hi / b.hi); }
static inline dd s_sqrt(const lis_ctx *c, dd a) { return c->quad ? dd_sqrt(a) : dd_d(sqrt(a.hi)); }
static inline int s_zero(dd a) { return a.hi == 0.0; }

int lv_new(lis_ctx *c, lis_vec *v);                    /* zero-filled; LIS_NOMEM */
void lv_free(lis_vec *v);
int lv_new_many(lis_ctx *c, lis_vec *v, int count);
void lv_free_many(lis_vec *v, int count);
void lv_copy(const lis_ctx *c, const lis_vec *x, lis_vec *y);           /* y = x */
void lv_zero(const lis_ctx *c, lis_vec *y);
void lv_scale(const lis_ctx *c, dd a, lis_vec *x);                      /* x = a x */
void lv_axpy(const lis_ctx *c, dd a, const lis_vec *x, lis_vec *y);     /* y += a x */
void lv_xpay(const lis_ctx *c, const lis_vec *x, dd a, lis_vec *y);     /* y = x + a y */
void lv_waxpby(const lis_ctx *c, dd a, const lis_vec *x, dd b, const lis_vec *y, lis_vec *w);
dd lv_dot(const lis_ctx *c, const lis_vec *x, const lis_vec *y);
dd lv_nrm2(const lis_ctx *c, const lis_vec *x);
void lv_matvec(const lis_ctx *c, const lis_vec *x, lis_vec *y);         /* y = A x */
void lv_matvec_t(const lis_ctx *c, const lis_vec *x, lis_vec *y);       /* y = A' x */
void lv_psolve(lis_ctx *c, const lis_vec *x, lis_vec *y);               /* y = M^-1 x */
void lv_psolve_t(lis_ctx *c, const lis_vec *x, lis_vec *y);             /* y = M^-T x */
void lv_residual(const lis_ctx *c, const lis_vec *x, lis_vec *r);       /* r = b - A x */
dd lv_matvec_dot(const lis_ctx *c, const lis_vec *x, lis_vec *y);         /* y = A x; x'y */
dd lv_axpy2_nrm2(const lis_ctx *c, dd a, const lis_vec *p, const lis_vec *q, lis_vec *x,
                 lis_vec *r);                                 /* x += a p, r -= a q; ||r|| */
dd lv_psolve_dot(lis_ctx *c, const lis_vec *r, lis_vec *z);             /* z = M^-1 r; r'z */

/* The complex operations (lis_field.h's complex instance): scalars double
 * complex; the dots conjugate x, or not when hermitian is 0 (COCG).  The
 * vector-only operations above (new, copy, zero, nrm2, matvec, residual,
 * psolve) serve both fields, by c->cplx. */
double complex lvz_dot(const lis_ctx *c, const lis_vec *x, const lis_vec *y);        /* x^H y */
void lvz_scale(const lis_ctx *c, double complex a, lis_vec *x);
void lvz_axpy(const lis_ctx *c, double complex a, const lis_vec *x, lis_vec *y);
void lvz_xpay(const lis_ctx *c, const lis_vec *x, double complex a, lis_vec *y);
void lvz_waxpby(const lis_ctx *c, double complex a, const lis_vec *x, double complex b, const lis_vec *y,
                lis_vec *w);
double complex lvz_matvec_dot(const lis_ctx *c, const lis_vec *x, lis_vec *y, int hermitian);
dd lvz_axpy2_nrm2(const lis_ctx *c, double complex a, const lis_vec *p, const lis_vec *q, lis_vec *x,
                  lis_vec *r);
double complex lvz_psolve_dot(lis_ctx *c, const lis_vec *r, lis_vec *z, int hermitian);

/* One iteration finished with residual norm rnorm (absolute, 2-norm):
 * counts it, logs it under -print out, and returns LIS_CONVERGED, LIS_NAN or
 * -1 (go on).  lis_limit() says whether the iteration budget is spent. */
int lis_step(lis_ctx *c, dd rnorm);
int lis_check(lis_ctx *c, dd rnorm);    /* the same test, not counted as an iteration */
int lis_limit(const lis_ctx *c);
/* Records why the method broke down and returns LIS_BREAKDOWN. */
int lis_breakdown(lis_ctx *c, const char *why);
/* A scalar the method divides by is zero (breakdown) or NaN (LIS_NAN). */
int lis_fail(lis_ctx *c, dd v, const char *why);
/* The relative residual of x, computed afresh (b - A x). */
double lis_true_resid(lis_ctx *c, const lis_vec *x, lis_vec *work);

/* ---- solvers: x holds the initial guess on entry, the iterate on return ---- */

typedef int (*lis_solver_fn)(lis_ctx *c, lis_vec *x);
int lis_cg(lis_ctx *c, lis_vec *x);
int lis_cr(lis_ctx *c, lis_vec *x);
int lis_bicg(lis_ctx *c, lis_vec *x);
int lis_cgs(lis_ctx *c, lis_vec *x);
int lis_bicgstab(lis_ctx *c, lis_vec *x);
int lis_bicgstabl(lis_ctx *c, lis_vec *x);
int lis_gpbicg(lis_ctx *c, lis_vec *x);
int lis_tfqmr(lis_ctx *c, lis_vec *x);
int lis_minres(lis_ctx *c, lis_vec *x);
int lis_idrs(lis_ctx *c, lis_vec *x);
int lis_gmres(lis_ctx *c, lis_vec *x);
int lis_fgmres(lis_ctx *c, lis_vec *x);
int lis_orthomin(lis_ctx *c, lis_vec *x);
int lis_jacobi(lis_ctx *c, lis_vec *x);
int lis_gs(lis_ctx *c, lis_vec *x);
int lis_sor(lis_ctx *c, lis_vec *x);
/* The complex instances (c->cplx): CG needs A Hermitian positive definite,
 * COCG complex symmetric (A = A.'). */
int lis_cg_z(lis_ctx *c, lis_vec *x);
int lis_cocg_z(lis_ctx *c, lis_vec *x);
int lis_bicgstab_z(lis_ctx *c, lis_vec *x);
int lis_gmres_z(lis_ctx *c, lis_vec *x);
int lis_fgmres_z(lis_ctx *c, lis_vec *x);

#endif
