/*
 * cloth.h -- the seeds' mass-spring cloth: one model, three drivers.
 *
 * A rectangular grid of particles joined by structural, shear and bend
 * springs, advanced by linearized implicit Euler as the seeds did:
 *
 *     A dv = b,  A = M - dt^2 DfDx - dt DfDv,  b = dt (f + dt DfDx v)
 *     v += dv,  x += dt v
 *
 * with the pinned coordinates constrained inside the solve (S A S on the
 * free ones, dv = 0 on the pins; cloth_model.c),
 *
 * with f the spring forces plus gravity, DfDx = -(Y_L - Y_R)' diag(K) (Y_L -
 * Y_R) (the stiffness of zero-rest-length springs: symmetric negative
 * semidefinite, so A is SPD) and DfDv = -damping M.  tests/test_cloth.c
 * checks these statements one by one against plain C; this folder makes a
 * program of them.
 *
 * Three drivers share the model (cloth_model.c) and differ only in who
 * computes what:
 *   original  plain C: assembles A and b itself and solves with its own CG
 *             (the baseline);
 *   ltd       the seeds' limited mode: C assembles A and b, SILC solves
 *             (PUT A, PUT b, EXEC "dv = A \ b", GET dv);
 *   cmp       the seeds' comprehensive mode: every step is SILC statements;
 *             only positions are fetched, and only when a frame is written.
 *
 * Files: scene.c (the scene files, scenes/NAME.scene), cloth_model.c (mesh,
 * springs, forces, assembly, energy, collisions), cloth_drivers.c (the three
 * drivers), monitor.c (the per-step checks), frame.c (PNG pictures),
 * cloth.c (the program).
 */
#ifndef SILC_CLOTH_H
#define SILC_CLOTH_H

#include <stdint.h>
#include <stdio.h>

/* ---- scenes (scene.c) ---------------------------------------------------- */

enum { CLOTH_MAX_PINS = 16 };

typedef enum { OBSTACLE_NONE = 0, OBSTACLE_SPHERE, OBSTACLE_FLOOR } cloth_obstacle_kind;

typedef struct cloth_scene {
    char name[64];
    int nx, ny;                 /* particles along each side (>= 2) */
    double width, height;       /* cloth size in metres (x along nx, y along ny) */
    double mass;                /* total mass, kg, shared equally */
    double k_struct, k_shear, k_bend; /* spring stiffness, N/m (bend 0: no bend springs) */
    double damping;             /* DfDv = -damping M, 1/s */
    double gravity[3];          /* m/s^2 */
    double dt;                  /* time step, s */
    int steps;                  /* steps to run */
    int frame_every;            /* write a frame every k steps (0: none) */
    int npins;                  /* pinned particles, by grid index (i, j) */
    int pin_i[CLOTH_MAX_PINS], pin_j[CLOTH_MAX_PINS];
    double tilt;                /* the cloth starts in the plane z = 0 rotated by this many degrees about x */
    cloth_obstacle_kind obstacle;
    double center[3], radius;   /* sphere */
    double floor_z;             /* floor plane z = floor_z */
    double accuracy;            /* how far a particle may be off after the run, relative to the cloth size */
    double max_stretch;         /* the longest a spring may get, over its rest length (the monitor's bound) */
} cloth_scene;

/* Reads a scene file: `key = value` lines, `#` comments, blank lines.
 * Unknown keys, bad values and missing required keys are errors naming the
 * file, the line and the key, written to err (never a crash); 0 on success. */
int scene_read(const char *path, cloth_scene *s, char *err, size_t errlen);
/* The same from a string (tests); `origin` names it in messages. */
int scene_parse(const char *text, const char *origin, cloth_scene *s, char *err, size_t errlen);
/* The documented keys with their meaning and default, for --help and docs. */
void scene_print_keys(FILE *out);

/* ---- pictures (frame.c) --------------------------------------------------- */

/* Writes the mesh (nx x ny particles, positions x: 3 per particle, particle
 * (i, j) at index j * nx + i) as a PNG of w x h pixels: the quads projected
 * obliquely, painted back to front and shaded by the angle of their normal
 * to a fixed light; the obstacle (if any) drawn as an outline.  0 on
 * success, else -1 with a message in err. */
int frame_write_png(const char *path, const cloth_scene *s, const double *x, int w, int h, char *err,
                    size_t errlen);

/* ---- the model (cloth_model.c) -------------------------------------------- */

/* The mesh and the state.  Particle (i, j) is p = j * nx + i; its
 * coordinates are x[3p .. 3p+2].  Springs join sl[k] (left) and sr[k]
 * (right) with stiffness k[k] and the rest length of the initial mesh. */
typedef struct cloth_model {
    const cloth_scene *scene;
    int n, ns;                  /* particles, springs */
    int *sl, *sr;
    double *k, *rest;
    double *x, *v, *x0;         /* 3n: positions, velocities, initial positions */
    double *mass;               /* 3n: each coordinate's particle mass (M's diagonal) */
    double *fixed;              /* 3n: 0 for a pinned particle's coordinates, 1 else */
    double *gvec;               /* 3n: gravity per coordinate */
    double *xprev, *xfree;      /* 3n: positions before the last step, and after it but before the
                                 * obstacle's constraint (what the tunnelling check reads) */
    int pins_after_solve;       /* 1: the seeds' (wrong) way, pins solved as free and their dv dropped
                                 * afterwards; only cloth_bench --energy sets it, to measure "before" */
    /* A's pattern, fixed for the mesh: 3n x 3n CSR, sorted columns; and
     * where each entry the assembly adds to lies in it, found once: diag[r]
     * for (r, r), and for spring k and direction d the slots of (l, l),
     * (r, r), (l, r), (r, l) at spring_slot[12 k + 4 d ..]. */
    int64_t *rowptr, *colind;
    int64_t nnz;
    int64_t *diag, *spring_slot;
} cloth_model;

int cloth_model_init(cloth_model *m, const cloth_scene *s, char *err, size_t errlen);
void cloth_model_free(cloth_model *m);
/* f = spring forces + M g at positions x (3n). */
void cloth_forces(const cloth_model *m, const double *x, double *f);
/* A's values (on m's pattern) and b = dt (f + dt DfDx v), f from cloth_forces,
 * with the pinned coordinates constrained: S A S + (I - S)(1 + dt damping) M
 * and S b, S = diag(fixed) (cloth_model.c says why). */
void cloth_system(const cloth_model *m, const double *f, const double *v, double *a_val, double *b);
/* v += dv on free coordinates, x += dt v, then the obstacle's constraint;
 * keeps the positions before (xprev) and before the constraint (xfree). */
void cloth_update(cloth_model *m, const double *dv);
/* The obstacle: particles inside the sphere (or below the floor) go to its
 * surface and stop (sticky contact). */
void cloth_collide(const cloth_model *m, double *x, double *v);
/* Kinetic (0 for v NULL) and spring energy at (x, v). */
void cloth_energy(const cloth_model *m, const double *x, const double *v, double *kinetic, double *spring);
/* Gravity's potential energy, -sum m g . x (0 at z = 0 for g along -z). */
double cloth_gravity_energy(const cloth_model *m, const double *x);
/* Kinetic + spring + gravity: what damping (and the integrator) may only lose. */
double cloth_total_energy(const cloth_model *m, const double *x, const double *v);
/* The run's energy scale: what gravity releases when the whole mass falls
 * by the cloth's size, plus the initial spring energy.  Energy checks are
 * relative to it. */
double cloth_energy_scale(const cloth_model *m);
/* The largest spring length over its rest length at x. */
double cloth_max_stretch(const cloth_model *m, const double *x);
/* A bound on the 2-norm condition number of the constrained A (Gershgorin:
 * A is symmetric and diagonally dominant, its smallest eigenvalue is at
 * least (1 + dt damping) min m): max (a_ii + sum |a_ij|) / min (a_ii - sum
 * |a_ij|).  It depends only on the scene, not on the step. */
double cloth_condition_bound(const cloth_model *m);
/* The tolerance an iterative solve needs for cond x backward error, the
 * bound on dv's relative error, to stay within the scene's accuracy:
 * accuracy / cloth_condition_bound (the backward error is at most the
 * relative residual the tolerance stops at). */
double cloth_default_tol(const cloth_model *m);
/* The normwise backward error ||b - A x|| / (||A|| ||x|| + ||b||), infinity
 * norms, as SILC's `info` reports it (docs/accuracy.md). */
double cloth_backward_error(const cloth_model *m, const double *a_val, const double *b, const double *x);
/* The largest distance of a particle from where it started. */
double cloth_max_displacement(const cloth_model *m, const double *x);
/* Solves A dv = b (A on m's pattern) by CG with a Jacobi preconditioner to
 * ||r|| <= tol ||b||; returns the iterations, -1 if it did not converge in
 * 10 * 3n iterations (the original driver's solver). */
int cloth_cg(const cloth_model *m, const double *a_val, const double *b, double *dv, double tol);

/* ---- the drivers (cloth_drivers.c) ----------------------------------------- */

typedef enum { CLOTH_ORIGINAL = 0, CLOTH_LTD, CLOTH_CMP } cloth_mode;

/* Seconds per phase, summed over the steps run. */
typedef struct cloth_times {
    double assembly, solve, update;
    long cg_iterations;
} cloth_times;

typedef struct cloth_driver cloth_driver;

/* The solvers a run may name, each with its tolerance taken from the
 * scene: "direct" (SILC's configured dispatch: a sparse Cholesky), "cg"
 * (lis-style CG + Jacobi: original's algorithm and stopping rule), "cg-ic"
 * (+ IC(0)), "cg-amg" (+ SA-AMG) and "petsc-cg" (PETSc CG + ICC).  Each
 * iterative one stops at a residual of tol relative to ||b||. */
/* What `solver` sends with every solve at tolerance tol, into buf: a name
 * above gives its options ("" for direct); text holding '=' is SILC solve
 * options already and is passed as it is.  NULL or "" is "direct".  0, or
 * -1 with err for an unknown name. */
int cloth_solver_options(const char *solver, double tol, char *buf, size_t len, char *err, size_t errlen);
/* "lis-style CG + Jacobi" for "cg"; the text itself for anything else. */
const char *cloth_solver_label(const char *solver);

/* A driver for m in `mode`; ltd and cmp open a SILC context (embedded, or
 * the server SILC_SERVER names) and solve with `solver` (a name or options,
 * as cloth_solver_options) at tolerance tol, which is also the original
 * driver's CG tolerance.  NULL with err on failure. */
cloth_driver *cloth_driver_open(cloth_model *m, cloth_mode mode, const char *solver, double tol, char *err,
                                size_t errlen);
/* One step; 0 or -1 with err. */
int cloth_driver_step(cloth_driver *d, cloth_times *t, char *err, size_t errlen);
/* The current positions (and velocities) in m->x, m->v (cmp fetches them). */
int cloth_driver_sync(cloth_driver *d, char *err, size_t errlen);
void cloth_driver_close(cloth_driver *d);
/* ltd and cmp: let SILC's tuner pick the solve's backend (and threads) for a
 * run of `steps` steps, under the backward-error target `accuracy` (tune
 * on, tune.accuracy; docs/tuner.md).  0, or -1 with err. */
int cloth_driver_tune(cloth_driver *d, double accuracy, int steps, char *err, size_t errlen);
/* ltd and cmp: what ran the last solve, from `info dv` ("backend, method"),
 * into buf; "" for original. */
void cloth_driver_solver(cloth_driver *d, char *buf, size_t len);
/* The last solve's normwise backward error and a condition estimate of A:
 * ltd and cmp read them from SILC's report (`info dv`: docs/accuracy.md),
 * the condition estimate falling back to cloth_condition_bound when the
 * solver gives none (iterative ones); original computes the backward error
 * of its CG itself and uses the bound.  cond x backward error bounds the
 * relative error of dv.  iterations (may be NULL): the solve's iterations
 * (0 for a direct one).  0, or -1 with err. */
int cloth_driver_solve_report(cloth_driver *d, double *backward_error, double *cond, long *iterations, char *err,
                              size_t errlen);
const char *cloth_mode_name(cloth_mode mode);

/* ---- the monitor (monitor.c) ---------------------------------------------- */

/* What is checked after every step; monitor.c says exactly how. */
enum { CLOTH_CHECK_SOLVE, CLOTH_CHECK_TUNNEL, CLOTH_CHECK_STRETCH, CLOTH_CHECK_ENERGY, CLOTH_CHECKS };

typedef struct cloth_monitor {
    double scale;                /* cloth_energy_scale, J */
    double e_start, e_prev, e_max; /* total energy at the start, the last step, the largest seen */
    double max_rise;             /* the largest one-step rise of the total energy, J */
    double stretch;              /* the largest spring stretch seen */
    double cond, backward_error, worst_bound; /* the largest of each over the steps */
    int steps;
    long count[CLOTH_CHECKS];    /* steps that failed each check */
    int first_step[CLOTH_CHECKS];
    char first[CLOTH_CHECKS][400]; /* the first failure's message: step, what, a hint */
    unsigned fresh;              /* bit k: check k failed for the first time in the last step */
} cloth_monitor;

void cloth_monitor_start(cloth_monitor *mon, const cloth_model *m);
/* The checks after step `step` on m's state (x, v, xprev, xfree: synced),
 * with the step's solve report.  0, with any new failure's message in
 * mon->first[k] for each bit k of mon->fresh; -1 with err if the state is
 * not finite. */
int cloth_monitor_step(cloth_monitor *mon, const cloth_model *m, int step, double backward_error, double cond,
                       char *err, size_t errlen);
/* How many kinds of check failed at least once. */
int cloth_monitor_problems(const cloth_monitor *mon);
const char *cloth_check_name(int kind);

#endif
