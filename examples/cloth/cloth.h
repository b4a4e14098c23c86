/*
 * cloth.h -- the seeds' mass-spring cloth: one model, three drivers.
 *
 * A rectangular grid of particles joined by structural, shear and bend
 * springs, advanced by linearized implicit Euler as the seeds did:
 *
 *     A dv = b,  A = M - dt^2 DfDx - dt DfDv,  b = dt (f + dt DfDx v)
 *     v += dv (pinned coordinates kept still),  x += dt v
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
 * drivers), frame.c (PNG pictures), cloth.c (the program).
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
/* A's values (on m's pattern) and b = dt (f + dt DfDx v), f from cloth_forces. */
void cloth_system(const cloth_model *m, const double *f, const double *v, double *a_val, double *b);
/* v += dv on free coordinates, x += dt v, then the obstacle's constraint. */
void cloth_update(cloth_model *m, const double *dv);
/* The obstacle: particles inside the sphere (or below the floor) go to its
 * surface and stop (sticky contact). */
void cloth_collide(const cloth_model *m, double *x, double *v);
/* Kinetic and spring energy at (x, v). */
void cloth_energy(const cloth_model *m, const double *x, const double *v, double *kinetic, double *spring);
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
const char *cloth_mode_name(cloth_mode mode);

#endif
