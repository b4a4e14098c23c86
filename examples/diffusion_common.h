/*
 * diffusion_common.h -- the parts of the diffusion examples that the examples
 * and their test share: assembly of the Crank-Nicolson matrices in C, the
 * initial fields, and the PUT/EXEC/GET time loops.  Keeping them here means the
 * test (tests/test_examples.c) checks exactly the code the examples run.
 *
 * The model problem is u_t = Laplacian(u) with zero Dirichlet boundary values on
 * a uniform grid of n interior points per side (spacing h).  Crank-Nicolson
 * advances u by solving (I - dt/2 L) u_new = (I + dt/2 L) u_old, with L the
 * second-difference Laplacian (3-point in 1-D, 5-point in 2-D).
 *
 * Every function returns 0 on success; on failure the message is in
 * silc_errmsg() (SILC failures) or names the problem on stderr (allocation).
 * The run functions use the default context: call SILC_INIT() first.
 */
#ifndef DIFFUSION_COMMON_H
#define DIFFUSION_COMMON_H

#include <stdint.h>

#include "silc.h"

/* Builds the CSR matrix I + c*L for the Laplacian L in `dim` (1 or 2)
 * dimensions on n points per side with spacing h; the unknown (i, j) is
 * i + j*n.  With c = -dt/2 this is Crank-Nicolson's A, with c = +dt/2 its B. */
int diff_shifted_laplacian(int dim, int64_t n, double h, double c, silc_envelope_t *out);
/* Rows [r0, r1) of that matrix, as an (r1 - r0) x n^dim CSR block with global
 * column indices: what one rank of an MPI program puts with silc_put_rows.
 * diff_shifted_laplacian is this for all the rows. */
int diff_shifted_laplacian_rows(int dim, int64_t n, double h, double c, int64_t r0, int64_t r1,
                                silc_envelope_t *out);

/* Advances u (n^dim entries, in/out) by `steps` Crank-Nicolson steps of size dt
 * inside SILC: the matrices are PUT once, u stays in SILC between steps, and is
 * fetched once at the end. */
int diff_run(int dim, int64_t n, int steps, double dt, double *u);

/* 1-D problem on [0, pi]: u(x, 0) = sin x, exact solution e^{-t} sin x. */
double diff1d_h(int64_t n);
void diff1d_initial(int64_t n, double *u);
double diff1d_max_error(int64_t n, double t, const double *u);

/* 2-D problem on the unit square: 1 on the block (0.4, 0.6)^2, 0 elsewhere. */
double diff2d_h(int64_t n);
void diff2d_initial(int64_t n, double *u);
/* Entries [r0, r1) of that field (unknown k = i + j*n) into u[0 .. r1-r0). */
void diff2d_initial_rows(int64_t n, int64_t r0, int64_t r1, double *u);
/* Total heat sum(u) * h^2 (the midpoint rule for the integral of u). */
double diff2d_heat(int64_t n, const double *u);

/* Command-line and output helpers of the 2-D programs; their messages start
 * with prog.  diff_parse_num: *out = the number s given for option opt, which
 * must lie in [lo, hi] (and be an integer if `integer`); 1 with a message on
 * stderr otherwise.  diff2d_write_pgm: the field as a binary 8-bit PGM scaled
 * by umax, rows from the top (largest y) down so that y points up. */
int diff_parse_num(const char *prog, const char *opt, const char *s, double lo, double hi,
                   int integer, double *out);
int diff2d_write_pgm(const char *prog, const char *path, int64_t n, const double *u, double umax);

#endif
