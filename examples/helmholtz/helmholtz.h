/*
 * helmholtz.h -- the complex Helmholtz example's problem (issue 31): its
 * assembly and its solve through SILC, shared by the program (helmholtz.c)
 * and its test (tests/test_complex_ref.c), so the test checks the code the
 * program runs.
 *
 *     -Laplacian(u) - k^2 u = f   on the unit square,
 *     du/dn - i k u = g           on its four sides (first-order absorbing),
 *
 * discretized by the 5-point stencil on the (n+1) x (n+1) vertices (h =
 * 1/n, the unknown (i, j) at i + j (n+1)), the Robin condition by a ghost
 * point per boundary side (central difference: second order).  Boundary
 * rows are scaled by 1/2 (sides) and 1/4 (corners), which makes A complex
 * symmetric (A = A.') and not Hermitian: the absorbing terms put -i k/h on
 * the boundary diagonal.
 *
 * Two problems: HELMHOLTZ_PLANE_WAVE has the exact solution
 * u = exp(i k x) (f = 0; g = du/dn - i k u from it: 0 on x = 1, where the
 * wave leaves, -2 i k on x = 0, -i k u on y = 0 and y = 1), so the error
 * is measurable and falls as h^2; HELMHOLTZ_SOURCE is a Gaussian source at
 * the centre with g = 0, the waves leaving through every side: the picture.
 */
#ifndef HELMHOLTZ_H
#define HELMHOLTZ_H

#include <stddef.h>
#include <stdint.h>

#include "silc.h"

enum helmholtz_problem { HELMHOLTZ_PLANE_WAVE, HELMHOLTZ_SOURCE };

/* The complex CSR matrix (into *A) and right-hand side (2 (n+1)^2 doubles,
 * interleaved, into b) of the problem; 0 or -1 with the message in err. */
int helmholtz_assemble(int n, double k, int problem, silc_envelope_t *A, double *b, char *err, size_t errlen);

/* Assembles, PUTs A and b into c, runs "u = A \ b" and fetches u into u
 * (2 (n+1)^2 doubles, interleaved).  0 or -1 with the message in err. */
int helmholtz_solve(silc_context *c, int n, double k, int problem, double *u, char *err, size_t errlen);

/* max |u - exp(i k x)| over the vertices, for HELMHOLTZ_PLANE_WAVE. */
double helmholtz_plane_wave_error(int n, double k, const double *u);

#endif
