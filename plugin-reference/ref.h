/*
 * ref.h -- internal interface of the reference plugin (the oracle backend).
 *
 * The reference plugin implements every operation of silc_plugin.h in plain
 * C11 with no external library.  Its modules share a few things declared here:
 * the host table (every allocation, error and value goes through it), a
 * compressed-column sparse matrix used by all sparse kernels, format
 * conversions, and the "factorization" object every direct solver produces so
 * the solve driver can attach it to A, reuse it, and estimate the condition
 * number through it.
 *
 *   reference.c        tables, init, accepts predicates, shared helpers
 *   ref_elementwise.c  ADD SCALE EWISE MAP TRANSPOSE CONVERT DIAG REDUCE
 *   ref_matmul.c       MATMUL
 *   ref_solve.c        SOLVE: algorithm choice, factor reuse, report
 *   ref_dense.c        dense LU, Cholesky, triangular, Householder QR
 *   ref_band.c         band LU with partial pivoting
 *   ref_sparse.c       sparse triangular, Cholesky, LU
 *   ref_order.c        approximate minimum degree ordering
 *   ref_qr.c           sparse (Q-less) QR least squares
 *   ref_cond.c         Hager/Higham 1-norm condition estimator
 */
#ifndef REF_H
#define REF_H

#include "silc_plugin.h"
#include <stddef.h>
#include <stdint.h>

extern const silc_host_api *ref_host;

/* Doubles per entry of a value: 1 real, 2 complex (interleaved re, im: the
 * layout of C's double complex, so kernels cast x to double complex *). */
int ref_width(const silc_value *v);

/* An interrupt (host->cancelled) reaches the factorizations, which have no
 * call at hand, through the call ref_op_solve factors for (per thread):
 * they ask ref_cancelled() every REF_CANCEL_EVERY columns (a clock read)
 * and then fail with SILC_ELIB and REF_STOPPED. */
void ref_cancel_scope(silc_call *call); /* NULL ends the scope */
int ref_cancelled(void);
#define REF_CANCEL_EVERY 64
#define REF_STOPPED "stopped on request"

/* Compressed-column sparse matrix (m x n).  A CSR value of A read without
 * copying is the compressed-column form of A' (owned = 0). */
typedef struct ref_sp {
    int64_t m, n;
    int64_t *p, *i; /* p[n+1], i[nnz] */
    double *x;      /* w doubles per entry; may be NULL for a pattern */
    int owned;
    int w;          /* doubles per entry of x: 1 real, 2 complex (0: pattern) */
} ref_sp;

/* The 1-norm (by_col) or infinity norm of the compressed-column C (m x n,
 * w doubles per entry: the modulus for complex), or of its entries as a
 * vector when vec; 0 or SILC_ENOMEM.  The reductions of both fields call it. */
int ref_sp_norm1_inf(const ref_sp *C, int64_t m, int64_t n, int vec, int by_col, int w, double *r);

/* ---- reference.c: memory and conversions --------------------------------- */
void *ref_alloc(size_t count, size_t size);   /* NULL on overflow or failure */
void *ref_calloc(size_t count, size_t size);
void ref_free(void *p);
int ref_nomem(silc_call *call);               /* host->error(ENOMEM) */
/* values: doubles per entry (0 pattern only, 1 real, 2 complex). */
int ref_sp_alloc(ref_sp *A, int64_t m, int64_t n, int64_t nnz, int values);
void ref_sp_free(ref_sp *A);
int64_t ref_sp_nnz(const ref_sp *A);
/* Compressed-column form of the matrix in v (any format; dense and band skip
 * zeros, CSR keeps explicit zeros).  Always an owned copy.  The _w forms take
 * the view's doubles per entry (ref_width); the plain ones are real. */
int ref_sp_from_view(const silc_view *v, ref_sp *A);
int ref_sp_from_view_w(const silc_view *v, int w, ref_sp *A);
/* Compressed-column form of v' : borrowed from a CSR value, copied otherwise. */
int ref_spt_from_view(const silc_view *v, ref_sp *At);
int ref_spt_from_view_w(const silc_view *v, int w, ref_sp *At);
/* Both operands of a binary operation that way; on failure neither is held. */
int ref_spt_pair(const silc_view *a, const silc_view *b, ref_sp *At, ref_sp *Bt);
int ref_sp_transpose(const ref_sp *A, ref_sp *T);
/* Dense column-major copy of any format (w doubles per entry). */
double *ref_dense_from_view(const silc_view *v);
double *ref_dense_from_view_w(const silc_view *v, int w);
/* Writes v into the zeroed m x n column-major array D. */
void ref_dense_fill(const silc_view *v, double *D);
void ref_dense_fill_w(const silc_view *v, int w, double *D);
double ref_view_get(const silc_view *v, int64_t i, int64_t j);
/* Entry (i, j) of a complex view, as two doubles into z[0], z[1]. */
void ref_view_get_w(const silc_view *v, int w, int64_t i, int64_t j, double *z);
/* A CSR value from the compressed-column form of its transpose (rows of A). */
silc_value *ref_value_from_rows(const ref_sp *R);
silc_value *ref_value_from_dense(int64_t m, int64_t n, const double *x);
/* The same for a complex result (w = 2) or a real one (w = 1). */
silc_value *ref_value_from_rows_w(const ref_sp *R, int w);
silc_value *ref_value_from_dense_w(int64_t m, int64_t n, int w, const double *x);

/* ---- ref_elementwise.c, ref_matmul.c, ref_solve.c ------------------------ */
int ref_op_add(silc_call *call);
int ref_op_scale(silc_call *call);
int ref_op_ewise(silc_call *call);
int ref_op_map(silc_call *call);
int ref_op_transpose(silc_call *call);
int ref_op_convert(silc_call *call);
int ref_op_diag(silc_call *call);
int ref_op_reduce(silc_call *call);
int ref_op_matmul(silc_call *call);
/* ref_elementwise_z.c: the same ops on complex operands (the real entry
 * points hand them over). */
int ref_op_add_z(silc_call *call);
int ref_op_scale_z(silc_call *call);
int ref_op_ewise_z(silc_call *call);
int ref_op_map_z(silc_call *call);
int ref_op_transpose_z(silc_call *call);
int ref_op_reduce_z(silc_call *call);
/* Shared by both: a value of v's structure (w doubles per entry, CSR
 * pattern copied, values unset), the number of stored entries of v (band
 * padding included), and the 2-norm (largest singular value) of a real A. */
silc_value *ref_same_structure(const silc_view *v, int w);
int64_t ref_stored(const silc_view *v);
int ref_norm2(const ref_sp *A, double *out);
int ref_op_solve(silc_call *call);
double ref_nrm2(int64_t n, const double *x, int64_t inc); /* scaled 2-norm */

/* ---- factorizations ------------------------------------------------------ */
/* solve(): x holds b (length m) on entry and the solution (length n) on exit;
 * its length is max(m, n).  trans = 1 solves with A' (square factors only; the
 * condition estimator uses it).  A complex factor (w = 2) takes x and work
 * as interleaved complex vectors (2 doubles per entry) and trans = 1 means
 * the conjugate transpose A^H.  Kernels report failures as a status plus a
 * message written into msg. */
typedef struct ref_factor {
    int64_t m, n;
    void *data;
    int (*solve)(void *data, double *x, int trans, double *work);
    void (*destroy)(void *data);
    int64_t work_len;       /* doubles of scratch solve() needs */
    int w;                  /* doubles per entry: 1 real, 2 complex */
    double cond, rcond;     /* 1-norm estimate, computed once at factor time */
    double *est_start;      /* ref_solve.c: M^-1 [e/n, alternating] (n x 2, real) solved for an
                               owed estimate's lower bound, which the estimate goes on from;
                               NULL when none is kept */
    char method[64];
    char note[256];
} ref_factor;

void ref_factor_free(void *f);  /* attachment destructor */

/* ref_cond.c: estimate of ||M^{-1}||_1 for an n x n operator given by its
 * inverse applied in place (trans selects M^{-T}).  Returns -1 on failure. */
double ref_inv_norm1_est(int64_t n, int (*apply)(void *ctx, double *x, int trans, double *work),
                         void *ctx, double *work);
/* The same with Y = M^{-1} [e/n, alternating vector] (n x 2, the vectors
 * it starts from and ends with) already solved; NULL solves them. */
double ref_inv_norm1_est_from(int64_t n, int (*apply)(void *ctx, double *x, int trans, double *work),
                              void *ctx, double *work, const double *Y);
/* The block form (silc_plugin.h, ABI 1.3): t columns per solve (t <= 64),
 * at most itmax solves with M^{-1}; Y0, if not NULL, is M^{-1} times the
 * starting block that ref_inv_norm1_start writes. */
void ref_inv_norm1_start(int64_t n, int t, double *X0);
double ref_inv_norm1_est_block(int64_t n, int t, int itmax,
                               int (*apply)(void *ctx, double *X, int t, int trans), void *ctx,
                               const double *Y0);
double ref_cond_from(double anorm, double inv_est); /* guards 0 and non-finite */
/* Complex A (LAPACK zlacn2's method: Higham 1988, Algorithm 4.1): x and work
 * hold n complex entries, trans = 1 applies A^{-H}.  Returns -1 on failure. */
double ref_inv_norm1_est_complex(int64_t n, int (*apply)(void *ctx, double *x, int trans, double *work),
                                 void *ctx, double *work);

/* ref_dense.c: factor an n x n (or m x n for QR) column-major matrix.  On
 * failure return a SILC_E* status with the message in msg.  *F gets solve,
 * destroy, method; the driver fills the condition estimate. */
int ref_dense_lu(int64_t n, const double *A, ref_factor *F, char *msg, size_t msglen);
int ref_dense_chol(int64_t n, const double *A, ref_factor *F, char *msg, size_t msglen);
int ref_dense_tri(int64_t n, const double *A, int lower, ref_factor *F, char *msg, size_t msglen);
int ref_dense_qr(int64_t m, int64_t n, const double *A, ref_factor *F, char *msg, size_t msglen);
/* The complex forms (suffix _z) take interleaved complex arrays; Cholesky
 * takes a Hermitian positive definite A (lower triangle read), QR uses
 * complex Householder reflectors and the minimum-norm form factors A^H. */
int ref_dense_lu_z(int64_t n, const double *A, ref_factor *F, char *msg, size_t msglen);
int ref_dense_chol_z(int64_t n, const double *A, ref_factor *F, char *msg, size_t msglen);
int ref_dense_tri_z(int64_t n, const double *A, int lower, ref_factor *F, char *msg, size_t msglen);
int ref_dense_qr_z(int64_t m, int64_t n, const double *A, ref_factor *F, char *msg, size_t msglen);
/* ref_band.c: A given in any format; kl, ku its bandwidths. */
int ref_band_lu(const silc_view *A, int64_t kl, int64_t ku, ref_factor *F, char *msg, size_t msglen);
int ref_band_lu_z(const silc_view *A, int64_t kl, int64_t ku, ref_factor *F, char *msg, size_t msglen);
/* ref_sparse.c: A square, compressed column (owned copies are taken as needed).
 * The _z forms take A with complex values (A->w == 2). */
int ref_sparse_tri(const ref_sp *A, int lower, ref_factor *F, char *msg, size_t msglen);
int ref_sparse_chol(const ref_sp *A, ref_factor *F, char *msg, size_t msglen);
int ref_sparse_lu(const ref_sp *A, ref_factor *F, char *msg, size_t msglen);
int ref_sparse_tri_z(const ref_sp *A, int lower, ref_factor *F, char *msg, size_t msglen);
int ref_sparse_chol_z(const ref_sp *A, ref_factor *F, char *msg, size_t msglen);
int ref_sparse_lu_z(const ref_sp *A, ref_factor *F, char *msg, size_t msglen);
/* Symbolic Cholesky of a symmetric pattern (upper part of C is used): the
 * column pattern of L, rows ascending with the diagonal first. */
int ref_symbolic_chol(const ref_sp *C, ref_sp *L);
/* ref_qr.c: least squares / minimum norm for a sparse m x n A. */
int ref_sparse_qr(const ref_sp *A, ref_factor *F, char *msg, size_t msglen);
int ref_sparse_qr_z(const ref_sp *A, ref_factor *F, char *msg, size_t msglen);

/* ---- ref_order.c --------------------------------------------------------- */
/* Approximate minimum degree order of the symmetric pattern S (both triangles,
 * diagonal ignored): perm[k] = the k-th vertex eliminated. */
int ref_amd(const ref_sp *S, int64_t *perm);
/* Symmetric patterns (no diagonal, both triangles) of A + A' (A square) and of
 * A'A; for ordering, skip_dense leaves out rows denser than 10 sqrt(n), which
 * would make A'A full. */
int ref_pattern_aplusat(const ref_sp *A, ref_sp *S);
int ref_pattern_ata(const ref_sp *A, int skip_dense, ref_sp *S);
/* Elimination tree of the upper part of symmetric C (parent[-1 = root]). */
int ref_etree(const ref_sp *C, int64_t *parent);

#endif
