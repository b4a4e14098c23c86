/*
 * ref_band.c -- band LU with partial pivoting (the algorithm of LAPACK
 * dgbtf2/dgbtrs), the reference plugin's solver for banded systems.
 *
 * Row interchanges widen the upper band from ku to kl+ku, so the factor lives
 * in a widened copy with leading dimension 2*kl+ku+1: A(i,j) is stored at
 * ab[kl+ku+i-j + j*ldab].  Work and storage are O(n*kl*(kl+ku)), independent
 * of the input's format (band, CSR or dense are all read entry by entry).
 * The kernel lives in ref_band_t.h, instantiated here for real and for
 * complex entries (ref_field.h).
 */
#include "ref.h"

#include <math.h>
#include <stdio.h>

#define AB(f, i, j) ((f)->ab[(f)->kl + (f)->ku + (i) - (j) + (j) * (f)->ldab])

#undef REF_COMPLEX
#include "ref_field.h"
#include "ref_band_t.h"

#define REF_COMPLEX
#include "ref_field.h"
#include "ref_band_t.h"
#undef REF_COMPLEX

