/*
 * cloth_drivers.c -- the three ways the seeds ran the cloth (cloth.h):
 * original (plain C with its own CG), ltd (C assembles, SILC solves) and
 * cmp (every step as SILC statements, tests/test_cloth.c's, positions
 * fetched only when asked).
 *
 * Each step is timed in three phases so the summary can say where the time
 * goes: assembly (forces, A and b), solve, update (v, x, the obstacle).  In
 * ltd the solve phase includes the PUTs of A and b and the GET of dv, the
 * price of the mode.  In cmp each phase is one EXEC.
 */
#define _POSIX_C_SOURCE 200809L
#include "cloth.h"

#include <math.h>
#include <stddef.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "silc.h"

struct cloth_driver {
    cloth_mode mode;
    cloth_model *m;
    silc_context *ctx;
    double tol;
    char solve_stmt[1024];   /* ltd and cmp: the solve statement */
    char update_stmt[1024];  /* cmp: v, x and the obstacle */
    char assembly_stmt[1024]; /* cmp: forces, A and b, the pins constrained */
    double cond_bound;       /* cloth_condition_bound, once: A does not change */
    int last_iterations;     /* original: the last step's CG iterations */
    double *f, *a_val, *b, *dv;
    /* ltd: the program's envelopes for A and b, built once; a_val and b
     * point into them, so cloth_system writes each step's values straight
     * into what is PUT, as a PETSc program refills its Mat's values. */
    silc_envelope_t A_env, b_env;
};

static const char cmp_assembly[] =
    "p = Y_L * x - Y_R * x; P = sparse(P_row, P_col, p, 3*s, s); z = sqrt(diagvec(P' * P)); "
    "fij = P * (K_stiff *@ (z - L) /@ z); C1 = diag(X * sqrt(K_stiff)); "
    "A1 = Y_LT * C1 - Y_RT * C1; T1 = -A1 * A1'; "
    "f = Y_RT * fij - Y_LT * fij + M * g; DfDx = T1; DfDv = -damping * M; "
    "A = M - (dt * dt) * DfDx - dt * DfDv; b = dt * (f + dt * (DfDx * v))";
/* The pins constrained inside the solve: S = diag(fixed) keeps the free
 * coordinates' block of A, M_pin = (1 + dt damping) M on the pinned ones
 * alone puts their rows back as a diagonal, and S b = fixed .* b makes their
 * dv 0 (cloth_model.c's cloth_system does the same in C). */
static const char cmp_constrain[] = "; A = S * A * S + M_pin; b = fixed *@ b";

const char *cloth_mode_name(cloth_mode mode)
{
    return mode == CLOTH_ORIGINAL ? "original" : mode == CLOTH_LTD ? "ltd" : "cmp";
}

static double now(void)
{
    struct timespec t;
    clock_gettime(CLOCK_MONOTONIC, &t);
    return (double)t.tv_sec + 1e-9 * (double)t.tv_nsec;
}

static int silc_fail(cloth_driver *d, const char *what, char *err, size_t errlen)
{
    snprintf(err, errlen, "%s: %s", what, d->ctx ? silc_context_errmsg(d->ctx) : silc_errmsg());
    return -1;
}

/* ---- putting the model into SILC ------------------------------------------- */

static int put_vector(silc_context *c, const char *name, int64_t n, const double *x)
{
    silc_envelope_t e;
    int rc;
    if (silc_envelope_dense(&e, n, 1, x)) return -1;
    rc = silc_put(c, name, &e);
    silc_envelope_free(&e);
    return rc;
}

static int put_scalar(silc_context *c, const char *name, double x)
{
    return put_vector(c, name, 1, &x);
}

/* An m x n CSR matrix with at most one entry per row, (row, col[row], val[row]);
 * col[row] < 0 leaves the row empty. */
static int put_selection(silc_context *c, const char *name, int64_t m, int64_t n, const int64_t *col,
                         const double *val)
{
    int64_t *rp = malloc((size_t)(m + 1) * sizeof *rp), *ci = malloc((size_t)(m ? m : 1) * sizeof *ci);
    double *v = malloc((size_t)(m ? m : 1) * sizeof *v);
    int64_t r, nz = 0;
    silc_envelope_t e;
    int rc = -1;
    if (!rp || !ci || !v) goto out;
    rp[0] = 0;
    for (r = 0; r < m; r++) {
        if (col[r] >= 0) ci[nz] = col[r], v[nz++] = val ? val[r] : 1;
        rp[r + 1] = nz;
    }
    if (silc_envelope_csr(&e, m, n, rp, ci, v) == 0) {
        rc = silc_put(c, name, &e);
        silc_envelope_free(&e);
    }
out:
    free(rp), free(ci), free(v);
    return rc;
}

/* The transpose of a selection: n x m, row j holding the rows r with col[r] = j
 * (each column of a spring selection is used by several springs). */
static int put_selection_t(silc_context *c, const char *name, int64_t m, int64_t n, const int64_t *col)
{
    int64_t *rp = calloc((size_t)(n + 1), sizeof *rp), *ci = malloc((size_t)(m ? m : 1) * sizeof *ci);
    int64_t *fill = calloc((size_t)(n ? n : 1), sizeof *fill), r;
    double *v = malloc((size_t)(m ? m : 1) * sizeof *v);
    silc_envelope_t e;
    int rc = -1;
    if (!rp || !ci || !fill || !v) goto out;
    for (r = 0; r < m; r++)
        if (col[r] >= 0) rp[col[r] + 1]++;
    for (r = 0; r < n; r++) rp[r + 1] += rp[r];
    for (r = 0; r < m; r++)
        if (col[r] >= 0) ci[rp[col[r]] + fill[col[r]]] = r, v[rp[col[r]] + fill[col[r]]++] = 1;
    if (silc_envelope_csr(&e, n, m, rp, ci, v) == 0) {
        rc = silc_put(c, name, &e);
        silc_envelope_free(&e);
    }
out:
    free(rp), free(ci), free(fill), free(v);
    return rc;
}

/* Everything the cmp statements read, PUT once (tests/test_cloth.c's names). */
static int cmp_setup(cloth_driver *d)
{
    cloth_model *m = d->m;
    const cloth_scene *s = m->scene;
    int64_t N = 3 * (int64_t)m->n, S3 = 3 * (int64_t)m->ns, k, dd;
    int64_t *colL = malloc((size_t)S3 * sizeof *colL), *colR = malloc((size_t)S3 * sizeof *colR);
    int64_t *colX = malloc((size_t)S3 * sizeof *colX), *diag = malloc((size_t)N * sizeof *diag);
    double *prow = malloc((size_t)S3 * sizeof *prow), *pcol = malloc((size_t)S3 * sizeof *pcol);
    int rc = -1;
    if (!colL || !colR || !colX || !diag || !prow || !pcol) goto out;
    for (k = 0; k < m->ns; k++)
        for (dd = 0; dd < 3; dd++) {
            colL[3 * k + dd] = 3 * (int64_t)m->sl[k] + dd;
            colR[3 * k + dd] = 3 * (int64_t)m->sr[k] + dd;
            colX[3 * k + dd] = k;
            prow[3 * k + dd] = (double)(3 * k + dd + 1);
            pcol[3 * k + dd] = (double)(k + 1);
        }
    for (k = 0; k < N; k++) diag[k] = k;
    {
        int64_t *free_diag = malloc((size_t)N * sizeof *free_diag);
        double *pin_mass = malloc((size_t)N * sizeof *pin_mass);
        rc = !free_diag || !pin_mass;
        for (k = 0; !rc && k < N; k++) {
            free_diag[k] = m->fixed[k] != 0 ? k : -1;
            pin_mass[k] = m->fixed[k] != 0 ? 0 : (1 + s->dt * s->damping) * m->mass[k];
        }
        rc = rc || put_selection(d->ctx, "S", N, N, free_diag, NULL) ||
             put_selection(d->ctx, "M_pin", N, N, diag, pin_mass);
        free(free_diag), free(pin_mass);
        if (rc) goto out;
    }
    rc = put_selection(d->ctx, "Y_L", S3, N, colL, NULL) || put_selection(d->ctx, "Y_R", S3, N, colR, NULL) ||
         put_selection_t(d->ctx, "Y_LT", S3, N, colL) || put_selection_t(d->ctx, "Y_RT", S3, N, colR) ||
         put_selection(d->ctx, "X", S3, m->ns, colX, NULL) || put_selection(d->ctx, "M", N, N, diag, m->mass) ||
         put_vector(d->ctx, "x", N, m->x) || put_vector(d->ctx, "v", N, m->v) ||
         put_vector(d->ctx, "g", N, m->gvec) || put_vector(d->ctx, "fixed", N, m->fixed) ||
         put_vector(d->ctx, "K_stiff", m->ns, m->k) || put_vector(d->ctx, "L", m->ns, m->rest) ||
         put_vector(d->ctx, "P_row", S3, prow) || put_vector(d->ctx, "P_col", S3, pcol) ||
         put_scalar(d->ctx, "s", m->ns) || put_scalar(d->ctx, "dt", s->dt) ||
         put_scalar(d->ctx, "damping", s->damping);
    /* The obstacle as statements: per-particle sums through Q (n x 3n). */
    if (!rc && s->obstacle != OBSTACLE_NONE) {
        int64_t *colQ = malloc((size_t)N * sizeof *colQ);
        double *cvec = malloc((size_t)N * sizeof *cvec);
        if (!colQ || !cvec) rc = -1;
        for (k = 0; !rc && k < N; k++) {
            colQ[k] = k / 3;
            cvec[k] = s->obstacle == OBSTACLE_SPHERE ? s->center[k % 3] : (k % 3 == 2 ? s->floor_z : -INFINITY);
        }
        rc = rc || put_selection_t(d->ctx, "Q", N, m->n, colQ) || put_selection(d->ctx, "QT", N, m->n, colQ, NULL) ||
             put_vector(d->ctx, s->obstacle == OBSTACLE_SPHERE ? "C" : "F", N, cvec) ||
             put_scalar(d->ctx, "R", s->radius);
        free(colQ), free(cvec);
    }
out:
    free(colL), free(colR), free(colX), free(diag), free(prow), free(pcol);
    return rc ? -1 : 0;
}

/* ---- the solvers a run names ------------------------------------------------------ */

typedef struct named_solver {
    const char *name, *label;
    const char *options; /* %g: the tolerance; NULL: the configured dispatch */
} named_solver;

static const named_solver named_solvers[] = {
    {"direct", "direct (configured dispatch)", NULL},
    {"cg", "lis-style CG + Jacobi", "backend = lis-style; lis-style.options = -i cg -p jacobi -tol %g"},
    {"cg-ic", "lis-style CG + IC(0)", "backend = lis-style; lis-style.options = -i cg -p ic -tol %g"},
    {"cg-amg", "lis-style CG + SA-AMG", "backend = lis-style; lis-style.options = -i cg -p saamg -tol %g"},
    {"petsc-cg", "PETSc CG + ICC",
     "backend = petsc; petsc.options = -ksp_type cg -pc_type icc -ksp_rtol %g -ksp_atol 0"},
};
enum { N_NAMED = sizeof named_solvers / sizeof named_solvers[0] };

static const named_solver *find_solver(const char *solver)
{
    int k;
    for (k = 0; k < N_NAMED; k++)
        if (!strcmp(solver ? solver : "direct", named_solvers[k].name)) return &named_solvers[k];
    return NULL;
}

const char *cloth_solver_label(const char *solver)
{
    const named_solver *s = find_solver(solver && *solver ? solver : NULL);
    return s ? s->label : solver;
}

int cloth_solver_options(const char *solver, double tol, char *buf, size_t len, char *err, size_t errlen)
{
    const named_solver *s;
    int k, at;
    buf[0] = '\0';
    if (solver && strchr(solver, '=')) {
        if ((size_t)snprintf(buf, len, "%s", solver) >= len) {
            snprintf(err, errlen, "solver options are longer than %zu characters", len - 1);
            return -1;
        }
        return 0;
    }
    if ((s = find_solver(solver && *solver ? solver : NULL))) {
        if (s->options) snprintf(buf, len, s->options, tol);
        return 0;
    }
    at = snprintf(err, errlen, "unknown solver '%s' (one of", solver);
    for (k = 0; k < N_NAMED && at > 0 && (size_t)at < errlen; k++)
        at += snprintf(err + at, errlen - (size_t)at, "%s %s", k ? "," : "", named_solvers[k].name);
    if (at > 0 && (size_t)at < errlen) snprintf(err + at, errlen - (size_t)at, ", or SILC solve options)");
    return -1;
}

/* ---- the driver ------------------------------------------------------------ */

cloth_driver *cloth_driver_open(cloth_model *m, cloth_mode mode, const char *solver, double tol, char *err,
                                size_t errlen)
{
    cloth_driver *d = calloc(1, sizeof *d);
    int64_t N = 3 * (int64_t)m->n;
    char solve_options[sizeof d->solve_stmt - 64];
    if (cloth_solver_options(solver, tol, solve_options, sizeof solve_options, err, errlen)) {
        free(d);
        return NULL;
    }
    if (!d) goto oom;
    d->mode = mode;
    d->m = m;
    d->tol = tol;
    d->f = malloc((size_t)N * sizeof *d->f);
    d->b = malloc((size_t)N * sizeof *d->b);
    d->dv = malloc((size_t)N * sizeof *d->dv);
    d->a_val = calloc((size_t)m->nnz > 0 ? (size_t)m->nnz : 1, sizeof *d->a_val);
    if (!d->f || !d->b || !d->dv || !d->a_val) goto oom;
    if (mode == CLOTH_LTD) {
        if (silc_envelope_csr(&d->A_env, N, N, m->rowptr, m->colind, d->a_val) ||
            silc_envelope_dense(&d->b_env, N, 1, NULL))
            goto oom;
        free(d->a_val), free(d->b);
        d->a_val = d->A_env.values;
        d->b = d->b_env.values;
    }
    if (*solve_options) {
        if (strchr(solve_options, '"')) {
            snprintf(err, errlen, "solver options may not contain '\"'");
            cloth_driver_close(d);
            return NULL;
        }
        snprintf(d->solve_stmt, sizeof d->solve_stmt, "dv = solve(A, b, \"%s\")", solve_options);
    } else {
        snprintf(d->solve_stmt, sizeof d->solve_stmt, "dv = A \\ b");
    }
    snprintf(d->assembly_stmt, sizeof d->assembly_stmt, "%s%s", cmp_assembly,
             m->pins_after_solve ? "" : cmp_constrain);
    d->cond_bound = cloth_condition_bound(m);
    /* xp and xf: the positions before the step and before the obstacle's
     * constraint, for the tunnelling check (cloth_driver_sync fetches them). */
    snprintf(d->update_stmt, sizeof d->update_stmt, "xp = x; v += dv *@ fixed; x += dt * v; xf = x%s",
             m->scene->obstacle == OBSTACLE_SPHERE
                 ? "; dx = x - C; r = sqrt(Q * (dx *@ dx)); keep = QT * (r >= R); "
                   "x = C + dx *@ (QT * max(ones(rows(r), 1), R /@ r)); v = v *@ keep"
             : m->scene->obstacle == OBSTACLE_FLOOR
                 ? "; keep = QT * (Q * (x >= F)) > 2.5; x = max(x, F); v = v *@ keep"
                 : "");
    if (mode == CLOTH_ORIGINAL) return d;
    if (silc_open(&d->ctx, NULL)) {
        snprintf(err, errlen, "silc_open: %s", silc_errmsg());
        cloth_driver_close(d);
        return NULL;
    }
    if (mode == CLOTH_CMP && cmp_setup(d)) {
        silc_fail(d, "putting the cloth into SILC", err, errlen);
        cloth_driver_close(d);
        return NULL;
    }
    return d;
oom:
    snprintf(err, errlen, "out of memory for the %s driver", cloth_mode_name(mode));
    cloth_driver_close(d);
    return NULL;
}

static int ltd_solve(cloth_driver *d)
{
    cloth_model *m = d->m;
    silc_envelope_t dv;
    int rc;
    if (silc_put(d->ctx, "A", &d->A_env) || silc_put(d->ctx, "b", &d->b_env) || silc_exec(d->ctx, d->solve_stmt) || silc_get(d->ctx, &dv, "dv")) return -1;
    rc = dv.m == 3 * (int64_t)m->n && dv.n == 1 ? silc_envelope_to_dense(&dv, d->dv) : -1;
    silc_envelope_free(&dv);
    return rc;
}

int cloth_driver_step(cloth_driver *d, cloth_times *t, char *err, size_t errlen)
{
    cloth_model *m = d->m;
    double t0 = now(), t1, t2;
    if (d->mode == CLOTH_CMP) {
        if (silc_exec(d->ctx, d->assembly_stmt)) return silc_fail(d, "cmp assembly", err, errlen);
        t1 = now();
        if (silc_exec(d->ctx, d->solve_stmt)) return silc_fail(d, d->solve_stmt, err, errlen);
        t2 = now();
        if (silc_exec(d->ctx, d->update_stmt)) return silc_fail(d, "cmp update", err, errlen);
    } else {
        cloth_forces(m, m->x, d->f);
        cloth_system(m, d->f, m->v, d->a_val, d->b);
        t1 = now();
        if (d->mode == CLOTH_LTD) {
            if (ltd_solve(d)) return silc_fail(d, d->solve_stmt, err, errlen);
        } else {
            int it = cloth_cg(m, d->a_val, d->b, d->dv, d->tol);
            if (it < 0) {
                snprintf(err, errlen, "original: CG did not reach %.1e in %d iterations", d->tol, 30 * m->n);
                return -1;
            }
            t->cg_iterations += it;
            d->last_iterations = it;
        }
        t2 = now();
        cloth_update(m, d->dv);
    }
    t->assembly += t1 - t0;
    t->solve += t2 - t1;
    t->update += now() - t2;
    return 0;
}

int cloth_driver_sync(cloth_driver *d, char *err, size_t errlen)
{
    silc_envelope_t e;
    int k, rc = 0;
    static const char *const names[] = {"x", "v", "xp", "xf"};
    double *into[4];
    if (d->mode != CLOTH_CMP) return 0;
    into[0] = d->m->x, into[1] = d->m->v, into[2] = d->m->xprev, into[3] = d->m->xfree;
    for (k = 0; k < 4 && !rc; k++) {
        if (silc_get(d->ctx, &e, names[k])) {
            if (k >= 2) return 0; /* before the first step there is no xp, xf */
            return silc_fail(d, names[k], err, errlen);
        }
        rc = e.m == 3 * (int64_t)d->m->n && e.n == 1 ? silc_envelope_to_dense(&e, into[k]) : -1;
        silc_envelope_free(&e);
    }
    if (rc) snprintf(err, errlen, "cmp: x, v, xp or xf came back with the wrong shape");
    return rc;
}

void cloth_driver_close(cloth_driver *d)
{
    if (!d) return;
    if (d->ctx) silc_close(&d->ctx);
    if (d->mode == CLOTH_LTD) {
        if (d->a_val != d->A_env.values) free(d->a_val);
        if (d->b != d->b_env.values) free(d->b);
        silc_envelope_free(&d->A_env);
        silc_envelope_free(&d->b_env);
    } else {
        free(d->a_val), free(d->b);
    }
    free(d->f), free(d->dv);
    free(d);
}

int cloth_driver_tune(cloth_driver *d, double accuracy, int steps, char *err, size_t errlen)
{
    char text[160];
    if (d->mode == CLOTH_ORIGINAL) return 0;
    snprintf(text, sizeof text, "set tune.accuracy = %.3g; tune on %d", accuracy, steps);
    return silc_exec(d->ctx, text) ? silc_fail(d, text, err, errlen) : 0;
}

/* Collects `info` output (silc_set_output). */
static void collect(void *user, const char *text)
{
    char *buf = user;
    size_t have = strlen(buf);
    if (have < 2047) snprintf(buf + have, 2048 - have, "%s", text);
}

/* The value of `key: ` in an info text, to the end of its line. */
static void info_field(const char *text, const char *key, char *out, size_t len)
{
    const char *p = strstr(text, key), *e;
    if (!p) return;
    p += strlen(key);
    e = strchr(p, '\n');
    snprintf(out, len, "%.*s", (int)(e ? e - p : (ptrdiff_t)strlen(p)), p);
}

/* The number after `key: ` in an info text; -1 when absent or not a number
 * ("not available"). */
static double info_number(const char *text, const char *key)
{
    char field[64] = "", *end;
    double x;
    info_field(text, key, field, sizeof field);
    x = strtod(field, &end);
    return end != field ? x : -1;
}

int cloth_driver_solve_report(cloth_driver *d, double *backward_error, double *cond, long *iterations, char *err,
                              size_t errlen)
{
    char text[2048] = "";
    *cond = d->cond_bound;
    if (d->mode == CLOTH_ORIGINAL) {
        *backward_error = cloth_backward_error(d->m, d->a_val, d->b, d->dv);
        if (iterations) *iterations = d->last_iterations;
        return 0;
    }
    silc_set_output(d->ctx, collect, text);
    if (silc_exec(d->ctx, "info dv")) {
        silc_set_output(d->ctx, NULL, NULL);
        return silc_fail(d, "info dv", err, errlen);
    }
    silc_set_output(d->ctx, NULL, NULL);
    *backward_error = info_number(text, "  backward error: ");
    if (info_number(text, "  condition estimate: ") >= 0) *cond = info_number(text, "  condition estimate: ");
    if (iterations) *iterations = (long)fmax(0, info_number(text, "  iterations: "));
    if (*backward_error < 0) {
        snprintf(err, errlen, "info dv reports no backward error");
        return -1;
    }
    return 0;
}

void cloth_driver_solver(cloth_driver *d, char *buf, size_t len)
{
    char text[2048] = "", backend[128] = "", method[256] = "";
    buf[0] = '\0';
    if (d->mode == CLOTH_ORIGINAL) return;
    silc_set_output(d->ctx, collect, text);
    if (silc_exec(d->ctx, "info dv") == 0) {
        info_field(text, "  backend: ", backend, sizeof backend);
        info_field(text, "  solve: ", method, sizeof method);
        snprintf(buf, len, "%s, %s", backend, method);
    }
    silc_set_output(d->ctx, NULL, NULL);
}
