/*
 * test_plugin_order.c -- all plugins in one process, loaded in two different
 * orders, and every backend still solves correctly.
 *
 * Libraries behind plugins carry same-named symbols (Debian's sequential
 * MUMPS and its stub MPI, PETSc's own MUMPS and real MPI, two BLAS users):
 * loaded RTLD_LOCAL and linked as the ABI requires, none may bind to another's
 * copy, whichever was opened first.  Plugins belong to the process and are
 * opened once, so each order runs in a child process of its own: the child
 * opens the plugin files with the engine's ld_load_file (an internal
 * interface, as in tests/abi/test_abi.c) in the chosen order, before any
 * context exists; the contexts it then opens find the plugins already loaded
 * and use them in that order.  In each child every backend (and PETSc's LU
 * through its MUMPS, the pairing that breaks first if symbols leak) solves
 * three systems -- the 2-D Laplacian (SPD), sherman1 (symmetric indefinite
 * sign), west0479 (unsymmetric) -- and must agree with the reference plugin
 * within 10 n eps cond, with backward error <= 1e-12.
 *
 * SILC_PLUGIN_DIR is the build tree's plugin directory; plugins not built are
 * left out of both orders with a message.
 */
#define _POSIX_C_SOURCE 200809L
#include <float.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/wait.h>
#include <unistd.h>

#include "check.h"
#include "dispatch.h"
#include "engine.h"
#include "testlib.h"

#ifndef SILC_PLUGIN_DIR
#error "SILC_PLUGIN_DIR must name the directory of the built plugins"
#endif

/* Plugin file stems, in the first order; the second is the reverse, so that
 * PETSc comes before MUMPS in one and after it in the other. */
static const char *const plugins[] = {"petsc", "mumps", "suitesparse", "lapack", "lis-style"};
#define NP ((int)(sizeof plugins / sizeof plugins[0]))

/* A backend, the per-call options that force it, and its label. */
static const struct {
    const char *label;
    const char *plugin;
    const char *options;
    int dense;      /* solve dense(A) */
    int spd_only;
} solvers[] = {
    {"lapack", "lapack", "backend = lapack", 1, 0},
    {"umfpack", "suitesparse", "backend = suitesparse.umfpack", 0, 0},
    {"klu", "suitesparse", "backend = suitesparse.klu", 0, 0},
    {"cholmod", "suitesparse", "backend = suitesparse.cholmod", 0, 1},
    {"mumps", "mumps", "backend = mumps", 0, 0},
    {"petsc lu (its mumps)", "petsc", "backend = petsc; petsc.options = -ksp_type preonly -pc_type lu "
              "-pc_factor_mat_solver_type mumps", 0, 0},
};
#define NS ((int)(sizeof solvers / sizeof solvers[0]))

static int have[NP];

static int plugin_index(const char *name)
{
    int i;
    for (i = 0; i < NP; i++)
        if (!strcmp(plugins[i], name)) return i;
    return -1;
}

static void plugin_file(char *out, size_t len, const char *stem)
{
    snprintf(out, len, "%s/libsilc_plugin_%s.so", SILC_PLUGIN_DIR, stem);
}

/* Opens the plugins in this order through a bare engine (no configuration, no
 * directory scan), then checks the engine saw them in that order. */
static void preload(const int *order, int n)
{
    silc_engine *E = calloc(1, sizeof *E);
    char path[1024];
    int i;
    if (!E) return;
    sb_init(&E->warnings);
    E->threads = 1;
    CHECK(store_init(&E->store) == 0 && cfg_create(E) == 0 && ld_create(E) == 0,
          "bare engine: %s", E->err);
    for (i = 0; i < n; i++) {
        plugin_file(path, sizeof path, plugins[order[i]]);
        CHECK(ld_load_file(E, path) == 0, "ld_load_file(%s): %s", path, E->err);
    }
    /* Slot 0 is the built-in reference. */
    for (i = 0; i < n; i++) {
        const ld_plugin *p = ld_plugin_at(E, (size_t)i + 1);
        const char *want = plugins[order[i]];
        CHECK(p && !strcmp(p->table->name, want), "load position %d: got %s, want %s", i + 1,
              p ? p->table->name : "nothing", want);
    }
    eng_destroy(&E);
}

/* Every backend on A (bound in c) against the reference. */
static void solve_all(silc_context *c, tl_capture *cap, const char *what, int spd, int64_t n)
{
    char stmt[512];
    double *xref, cond, bound;
    int s;
    CHECK(silc_exec(c, "b = A * (1 + rand(cols(A), 1)); Ad = dense(A);"
                       "xr = solve(A, b, \"backend = reference\")") == 0,
          "%s: reference: %s", what, silc_context_errmsg(c));
    cond = tl_field(tl_info(c, cap, "xr"), "condition estimate");
    xref = tl_get_dense(c, "xr", NULL, NULL);
    CHECK(xref && cond > 0, "%s: no reference solution or condition estimate", what);
    if (!xref) return;
    bound = 10 * (double)n * DBL_EPSILON * cond;
    for (s = 0; s < NS; s++) {
        double be, d, *x;
        if (!have[plugin_index(solvers[s].plugin)] || (solvers[s].spd_only && !spd)) continue;
        snprintf(stmt, sizeof stmt, "x = solve(%s, b, \"%s\")", solvers[s].dense ? "Ad" : "A",
                 solvers[s].options);
        if (silc_exec(c, stmt)) {
            CHECK(0, "%s: %s: %s", what, stmt, silc_context_errmsg(c));
            continue;
        }
        be = tl_field(tl_info(c, cap, "x"), "backward error");
        x = tl_get_dense(c, "x", NULL, NULL);
        d = x ? tl_rel_diff(x, xref, n) : NAN;
        CHECK(be <= 1e-12, "%s: %s: backward error %.3g", what, solvers[s].options, be);
        CHECK(d <= bound, "%s: %s: differs from the reference by %.3g > %.3g", what,
              solvers[s].options, d, bound);
        printf("  %-10s %-22s backward error %.1e, difference %.1e\n", what, solvers[s].label,
               be, d);
        free(x);
    }
    free(xref);
}

/* The child's whole job; returns its exit status. */
static int child(const int *order, int n)
{
    silc_context *c = NULL;
    tl_capture cap = {0};
    silc_envelope_t L;
    char err[512];
    int i;
    printf("order:");
    for (i = 0; i < n; i++) printf(" %s", plugins[order[i]]);
    printf("\n");
    preload(order, n);
    if (silc_open(&c, NULL)) {
        CHECK(0, "silc_open: %s", c ? silc_context_errmsg(c) : silc_errmsg());
        return check_done();
    }
    tl_capture_attach(c, &cap);
    CHECK(tl_laplacian2d(&L, 30) == 0 && silc_put(c, "A", &L) == 0, "put the Laplacian");
    silc_envelope_free(&L);
    solve_all(c, &cap, "laplace2d", 1, 900);
    CHECK(tl_put_shared(c, "A", "sherman1.mtx", NULL, NULL, err, sizeof err) == 0, "%s", err);
    solve_all(c, &cap, "sherman1", 0, 1000);
    CHECK(tl_put_shared(c, "A", "west0479.mtx", NULL, NULL, err, sizeof err) == 0, "%s", err);
    solve_all(c, &cap, "west0479", 0, 479);
    silc_close(&c);
    tl_capture_free(&cap);
    return check_done();
}

int main(void)
{
    int order[2][NP], n = 0, k, i;
    char path[1024];
    for (i = 0; i < NP; i++) {
        plugin_file(path, sizeof path, plugins[i]);
        have[i] = access(path, R_OK) == 0;
        if (!have[i]) printf("plugin %s not built (%s): left out\n", plugins[i], path);
        else order[0][n++] = i;
    }
    for (i = 0; i < n; i++) order[1][i] = order[0][n - 1 - i];
    CHECK(n >= 2, "fewer than two plugins built: nothing to order");
    fflush(stdout);
    for (k = 0; k < 2 && n >= 2; k++) {
        int status = 0;
        pid_t pid = fork();
        CHECK(pid >= 0, "fork failed");
        if (pid == 0) exit(child(order[k], n)); /* exit: plugin shutdown runs too */
        if (pid > 0) {
            waitpid(pid, &status, 0);
            CHECK(WIFEXITED(status) && WEXITSTATUS(status) == 0,
                  "order %d: child %s %d", k + 1, WIFEXITED(status) ? "exited with" : "killed by signal",
                  WIFEXITED(status) ? WEXITSTATUS(status) : WTERMSIG(status));
        }
    }
    return check_done();
}
