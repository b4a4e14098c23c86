/*
 * ref_qr.c -- sparse least squares and minimum-norm solutions for the
 * reference plugin: Q-less QR by Givens rotations, row by row (George and
 * Heath), with corrected semi-normal equations.
 *
 * For m >= n the factored matrix is M = A, for m < n it is M = A'.  Its
 * columns are ordered by AMD on M'M; the pattern of R is that of the Cholesky
 * factor of M'M, known in advance from the elimination tree, so every row of
 * M is rotated into preallocated rows of R and Q is never stored.  Solutions
 * use R only (Bjorck's corrected semi-normal equations):
 *   m >= n:  x = R \ (R' \ (M'b)), then x += R \ (R' \ (M'(b - M x))) twice;
 *   m <  n:  y = R \ (R' \ b), x = M y (the minimum-norm solution), refined
 *            the same way on the residual b - A x.
 * A diagonal entry of R below max(m,n)*eps*max|R_jj| marks a column that is
 * (numerically) a combination of earlier ones: such columns are dropped and
 * the rest refactored, giving the basic solution with zeros there (for m < n
 * the dropped columns of A' are dependent equations).  The kernels live
 * in ref_qr_t.h, instantiated for real and complex entries (ref_field.h);
 * M = A^H for a complex A with m < n.
 */
#include "ref.h"

#include <float.h>
#include <math.h>
#include <stdio.h>
#include <string.h>

#undef REF_COMPLEX
#include "ref_field.h"
#include "ref_qr_t.h"

#define REF_COMPLEX
#include "ref_field.h"
#include "ref_qr_t.h"
#undef REF_COMPLEX
