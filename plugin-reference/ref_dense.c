/*
 * ref_dense.c -- dense direct solvers of the reference plugin: LU with partial
 * pivoting, Cholesky, triangular solves, and Householder QR with column
 * pivoting for least squares and minimum-norm problems.
 *
 * All matrices are column-major and every loop runs down columns so the
 * innermost access is contiguous (the unblocked LAPACK variants: dgetf2,
 * dpotf2, dgeqp3's inner step).  Each factor is wrapped in a ref_factor whose
 * solve() also handles the transposed system, which the condition estimator
 * needs.  The kernels live in ref_dense_t.h, instantiated here for real
 * and for complex entries (ref_field.h).
 */
#include "ref.h"

#include <float.h>
#include <math.h>
#include <stdio.h>
#include <string.h>

#undef REF_COMPLEX
#include "ref_field.h"
#include "ref_dense_t.h"

#define REF_COMPLEX
#include "ref_field.h"
#include "ref_dense_t.h"
#undef REF_COMPLEX
