/*
 * accuracy.c -- bench/accuracy: the measured trade of speed against accuracy.
 *
 * For generated families (2-D / 3-D Laplacians, convection-diffusion with a
 * rising Peclet number, Hilbert and Kahan matrices) with the true solution
 * x = ones, every backend and knob is run: direct double, + refinement
 * (double and double-double residual), mixed single/double (lapack),
 * iterative solvers at tolerances 1e-4 ... 1e-14, double-double iterations
 * (lis-style -f quad).  For each it prints wall time (best of 3), forward
 * error ||x - 1||_inf and backward error (A is put anew before every run,
 * so direct times include the factorization), marks the Pareto front of (time,
 * forward error) with '*', and writes docs/accuracy/<problem>.svg.
 *
 *   ./bench/accuracy [output-dir]      (default: docs/accuracy in the source tree)
 *
 * b = A * ones is formed with a compensated dot product, so the truth is
 * exact up to b's final rounding (relative eps, i.e. cond * eps in x: the
 * Hilbert rows show that floor).  Configurations a backend cannot run (not
 * built, declines) are left out.
 */
#define _POSIX_C_SOURCE 200809L
#include "progress.h"
#include "testlib.h"

#include <float.h>

#ifndef SILC_SOURCE_DIR
#define SILC_SOURCE_DIR "."
#endif

typedef struct problem {
    char name[48];
    int64_t n;
    int dense;
    double *a;              /* column-major n x n */
} problem;

typedef struct result {
    char label[96];
    double t, ferr, berr;
} result;

static silc_context *ctx;
static tl_capture cap;

static void gen(problem *p, const char *kind, int64_t k, double param)
{
    int64_t n, i, j, d;
    if (!strcmp(kind, "lap3d")) n = k * k * k;
    else if (!strcmp(kind, "lap2d") || !strcmp(kind, "convdiff")) n = k * k;
    else n = k;
    p->n = n;
    p->a = calloc((size_t)(n * n), sizeof *p->a);
    p->dense = !strcmp(kind, "hilbert") || !strcmp(kind, "kahan");
#define A(i, j) p->a[(i) + (j) * n]
    if (!strcmp(kind, "hilbert")) {
        snprintf(p->name, sizeof p->name, "hilbert%lld", (long long)n);
        for (j = 0; j < n; j++)
            for (i = 0; i < n; i++) A(i, j) = 1.0 / (double)(i + j + 1);
    } else if (!strcmp(kind, "kahan")) {
        /* Kahan's upper triangular matrix: diag s^(i), above -c s^(i). */
        double th = param, s = sin(th), c = cos(th);
        snprintf(p->name, sizeof p->name, "kahan%lld", (long long)n);
        for (i = 0; i < n; i++) {
            double si = pow(s, (double)i);
            A(i, i) = si;
            for (j = i + 1; j < n; j++) A(i, j) = -c * si;
        }
    } else {
        int dims = !strcmp(kind, "lap3d") ? 3 : 2;
        double h = 1.0 / (double)(k + 1), pe = !strcmp(kind, "convdiff") ? param : 0;
        if (pe > 0) snprintf(p->name, sizeof p->name, "convdiff%lld_pe%g", (long long)k, pe);
        else snprintf(p->name, sizeof p->name, "lap%dd_%lld", dims, (long long)k);
        for (i = 0; i < n; i++) {
            int64_t stride = 1;
            A(i, i) = 2.0 * dims;
            for (d = 0; d < dims; d++, stride *= k) {
                int64_t coord = (i / stride) % k;
                /* central convection in x: -1 - pe h / 2 upwind, -1 + pe h / 2 downwind */
                double up = d == 0 ? pe * h / 2 : 0;
                if (coord > 0) A(i, i - stride) = -1.0 - up;
                if (coord < k - 1) A(i, i + stride) = -1.0 + up;
            }
        }
    }
#undef A
}

static int put_problem(const problem *p)
{
    silc_envelope_t e;
    int rc;
    if (p->dense) {
        rc = silc_envelope_dense(&e, p->n, p->n, p->a);
    } else {
        int64_t *rp = malloc((size_t)(p->n + 1) * sizeof *rp), *ci = malloc((size_t)(p->n * 7 + 1) * sizeof *ci);
        double *v = malloc((size_t)(p->n * 7 + 1) * sizeof *v);
        int64_t i, j, nz = 0;
        rp[0] = 0;
        for (i = 0; i < p->n; i++) {
            for (j = 0; j < p->n; j++)
                if (p->a[i + j * p->n] != 0) ci[nz] = j, v[nz++] = p->a[i + j * p->n];
            rp[i + 1] = nz;
        }
        rc = silc_envelope_csr(&e, p->n, p->n, rp, ci, v);
        free(rp);
        free(ci);
        free(v);
    }
    if (rc) return rc;
    rc = silc_put(ctx, "A", &e);
    silc_envelope_free(&e);
    return rc;
}

/* b = A * ones, each row summed with TwoSum compensation. */
static void rhs(const problem *p, double *b)
{
    int64_t i, j;
    for (i = 0; i < p->n; i++) {
        double s = 0, c = 0;
        for (j = 0; j < p->n; j++) {
            double y = p->a[i + j * p->n], t = s + y, bb = t - s;
            c += (s - (t - bb)) + (y - bb);
            s = t;
        }
        b[i] = s + c;
    }
}

static int put_problem(const problem *p);

static int run(const problem *p, const char *opts, result *r)
{
    char stmt[600];
    double best = INFINITY, *x;
    int rep, i;
    snprintf(stmt, sizeof stmt, "x = solve(A, b, \"%s\")", opts);
    for (rep = 0; rep < 3; rep++) {
        double t0;
        put_problem(p); /* a fresh value: no factorization attached, every run factors */
        t0 = tl_now();
        if (silc_exec(ctx, stmt)) return -1;
        if (tl_now() - t0 < best) best = tl_now() - t0;
    }
    x = tl_get_dense(ctx, "x", NULL, NULL);
    if (!x) return -1;
    r->ferr = 0;
    for (i = 0; i < p->n; i++)
        if (!(fabs(x[i] - 1) <= r->ferr)) r->ferr = fabs(x[i] - 1);
    free(x);
    r->berr = tl_field(tl_info(ctx, &cap, "x"), "backward error");
    r->t = best;
    return 0;
}

/* Runs one configuration into the next free slot of R, if there is one. */
#define MAX_RESULTS 64
static progress bar; /* on stderr while a run is going, when it is a terminal */

static void add_run(const problem *p, const char *opts, const char *label, result *R, int *nr)
{
    if (*nr >= MAX_RESULTS) return;
    snprintf(R[*nr].label, sizeof R[*nr].label, "%s", label);
    progress_show(&bar, "accuracy: %s: %s", p->name, label);
    if (run(p, opts, &R[*nr]) == 0) (*nr)++;
    progress_done(&bar);
}

static void svg(const char *dir, const problem *p, const result *R, int nr, const int *front)
{
    char path[1024];
    FILE *f;
    double tmin = INFINITY, tmax = 0, emin = INFINITY, emax = 0;
    int i;
    snprintf(path, sizeof path, "%s/%s.svg", dir, p->name);
    if (!(f = fopen(path, "w"))) return;
    for (i = 0; i < nr; i++) {
        double e = R[i].ferr > 1e-17 ? R[i].ferr : 1e-17;
        if (R[i].t < tmin) tmin = R[i].t;
        if (R[i].t > tmax) tmax = R[i].t;
        if (e < emin) emin = e;
        if (e > emax) emax = e;
    }
    tmin = log10(tmin) - 0.2, tmax = log10(tmax) + 0.2, emin = log10(emin) - 0.5, emax = log10(emax) + 0.5;
    fprintf(f, "<svg xmlns='http://www.w3.org/2000/svg' width='720' height='480' font-family='sans-serif' font-size='10'>\n"
               "<rect width='720' height='480' fill='white'/>\n<text x='360' y='16' text-anchor='middle' font-size='13'>%s (n = %lld): time vs forward error, * = Pareto front</text>\n"
               "<line x1='60' y1='440' x2='700' y2='440' stroke='black'/><line x1='60' y1='30' x2='60' y2='440' stroke='black'/>\n"
               "<text x='380' y='470' text-anchor='middle'>log10 wall time [s] (%.1f .. %.1f)</text>\n"
               "<text x='14' y='240' transform='rotate(-90 14 240)' text-anchor='middle'>log10 ||x - 1||_inf (%.1f .. %.1f)</text>\n",
            p->name, (long long)p->n, tmin, tmax, emin, emax);
    for (i = 0; i < nr; i++) {
        double e = R[i].ferr > 1e-17 ? R[i].ferr : 1e-17;
        double X = 60 + 640 * (log10(R[i].t) - tmin) / (tmax - tmin);
        double Y = 440 - 410 * (log10(e) - emin) / (emax - emin);
        fprintf(f, "<circle cx='%.1f' cy='%.1f' r='4' fill='%s'/><text x='%.1f' y='%.1f'>%s</text>\n", X, Y,
                front[i] ? "crimson" : "steelblue", X + 6, Y + 3, R[i].label);
    }
    fputs("</svg>\n", f);
    fclose(f);
}

int main(int argc, char **argv)
{
    static const char *const direct[] = {"reference", "lapack", "suitesparse.umfpack", "suitesparse.klu",
                                         "suitesparse.cholmod", "mumps"};
    static const struct { const char *kind; int64_t k; double param; } fam[] = {
        {"lap2d", 30, 0}, {"lap3d", 10, 0}, {"convdiff", 30, 10}, {"convdiff", 30, 1000},
        {"convdiff", 30, 100000}, {"hilbert", 8, 0}, {"hilbert", 12, 0}, {"kahan", 60, 1.2}};
    const char *dir = argc > 1 ? argv[1] : SILC_SOURCE_DIR "/docs/accuracy";
    size_t fi, d;
    if (silc_open(&ctx, NULL)) {
        fprintf(stderr, "silc_open: %s\n", silc_errmsg());
        return 1;
    }
    tl_capture_attach(ctx, &cap);
    for (fi = 0; fi < sizeof fam / sizeof fam[0]; fi++) {
        problem p;
        result R[MAX_RESULTS];
        int front[MAX_RESULTS], nr = 0, i, j;
        double *b;
        char opts[300];
        gen(&p, fam[fi].kind, fam[fi].k, fam[fi].param);
        b = malloc((size_t)p.n * sizeof *b);
        rhs(&p, b);
        put_problem(&p);
        tl_put_vector(ctx, "b", p.n, b);
        for (d = 0; d < sizeof direct / sizeof direct[0]; d++) {
            static const char *const knob[] = {"", "; refine = 3", "; refine = 5; refine_residual = extended",
                                               "; lapack.precision = mixed"};
            static const char *const kname[] = {"", "+refine", "+refine dd", " mixed"};
            int kk;
            for (kk = 0; kk < 4; kk++) {
                char label[64];
                if (kk == 3 && strcmp(direct[d], "lapack") != 0) continue;
                snprintf(opts, sizeof opts, "backend = %s%s", direct[d], knob[kk]);
                snprintf(label, sizeof label, "%s%s", direct[d], kname[kk]);
                add_run(&p, opts, label, R, &nr);
            }
        }
        for (i = 4; i <= 14; i += 2) {
            char label[64];
            snprintf(opts, sizeof opts, "backend = lis-style; lis-style.options = -i %s -p ilu -tol 1e-%d -maxiter 5000",
                     p.dense ? "gmres" : "bicgstab", i);
            snprintf(label, sizeof label, "lis-style tol 1e-%d", i);
            add_run(&p, opts, label, R, &nr);
            snprintf(opts, sizeof opts, "backend = petsc; petsc.options = -ksp_type gmres -pc_type ilu -ksp_rtol 1e-%d -ksp_max_it 5000", i);
            snprintf(label, sizeof label, "petsc tol 1e-%d", i);
            add_run(&p, opts, label, R, &nr);
        }
        add_run(&p, "backend = lis-style; lis-style.options = -i gmres -p ilu -tol 1e-14 -maxiter 5000 -f quad",
                "lis-style quad 1e-14", R, &nr);
        /* Pareto front: nothing else is both faster and more accurate. */
        for (i = 0; i < nr; i++) {
            front[i] = 1;
            for (j = 0; j < nr; j++)
                if (j != i && R[j].t <= R[i].t && R[j].ferr <= R[i].ferr &&
                    (R[j].t < R[i].t || R[j].ferr < R[i].ferr))
                    front[i] = 0;
        }
        printf("\n%s (n = %lld, %s)\n  %-36s %11s %11s %11s\n", p.name, (long long)p.n,
               p.dense ? "dense" : "csr", "backend / knob", "time [s]", "fwd error", "bwd error");
        for (i = 0; i < nr; i++)
            printf("%c %-36s %11.3g %11.3g %11.3g\n", front[i] ? '*' : ' ', R[i].label, R[i].t, R[i].ferr,
                   R[i].berr);
        svg(dir, &p, R, nr, front);
        free(p.a);
        free(b);
    }
    silc_close(&ctx);
    tl_capture_free(&cap);
    return 0;
}
