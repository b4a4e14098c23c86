/*
 * test_fallback.c -- a configured backend list is a verified fallback chain
 * (issue 21), on real matrices from ../shared/matrices:
 *
 *   - west0067 has a zero diagonal entry: PETSc GMRES + ILU fails in
 *     KSPSetUp, and UMFPACK, listed next, solves it (backward error
 *     <= 1e-14); `info` lists the failed attempt, and the next solve with
 *     the same A skips PETSc;
 *   - bcsstk13 is SPD: PETSc GMRES + ILU reports convergence, but its result
 *     has a backward error above 10 x its tolerance, so verification fails
 *     and CHOLMOD, listed next, solves it; under solve.verify = off the
 *     unverified result stays, as before the chain;
 *   - a singular matrix fails on every listed backend: the error has one
 *     line per attempt and x keeps its old value;
 *   - a per-call `backend = X` has nothing to fall back to: its failed
 *     verification is the error;
 *   - a direct result that misses the bound is refined first (bayer10 with
 *     KLU), unless solve.refine = 0; and solve.verify set after a first
 *     solve with the same A (whose factorization is then reused) gives the
 *     same refined result and report as set before it;
 *   - a configured backend whose plugin is not on the plugin path (the
 *     template plugin, built in build/plugins/template, outside the default
 *     path) is an error at silc_open naming the plugin file and the
 *     directories searched; written "template?" it is optional, left out of
 *     explain's list, and the next backend solves; set in the session, the
 *     solve fails instead of falling back to the reference; a plugin file
 *     that cannot be loaded is warned about once per process.
 *
 * Skips (with a message) what needs a plugin this build does not have.
 */
#define _POSIX_C_SOURCE 200809L
#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#include "check.h"
#include "testlib.h"

/* 1 when every named backend is installed in c. */
static int have(silc_context *c, const char *names)
{
    char stmt[256];
    snprintf(stmt, sizeof stmt, "x0 = solve(1, 1, \"backend = %s\")", names);
    return silc_exec(c, stmt) == 0 || !tl_contains(silc_context_errmsg(c), "not installed");
}

/* Puts the shared matrix file as A with b = A * ones; its row count or -1. */
static int64_t put_system(silc_context *c, const char *file)
{
    char err[512];
    int64_t m = -1;
    if (tl_put_shared(c, "A", file, &m, NULL, err, sizeof err)) {
        CHECK(0, "%s: %s", file, err);
        return -1;
    }
    CHECK(silc_exec(c, "b = A * ones(rows(A), 1)") == 0, "b: %s", silc_context_errmsg(c));
    return m;
}

/* x = A \ b under the session's list ran on `want` after `failed` failed. */
static void check_fell_back(silc_context *c, const char *file, const char *failed, const char *why,
                            const char *want)
{
    const char *in;
    double be;
    CHECK(silc_exec(c, "x = A \\ b") == 0, "%s: the chain did not solve it: %s", file, silc_context_errmsg(c));
    in = tl_out_info(c, "x");
    be = tl_out_number(in, "backward error: ");
    CHECK(strstr(in, want) != NULL, "%s: solved by %s:\n%s", file, want, in);
    CHECK(be >= 0 && be <= 1e-14, "%s: backward error %g", file, be);
    CHECK(strstr(in, "earlier attempts") && strstr(in, failed) && strstr(in, why),
          "%s: info lists the failed %s (%s):\n%s", file, failed, why, in);
    printf("  %s: %s failed (%s), %s solved it, backward error %.2g\n", file, failed, why, want, be);
}

static void test_library_failure(silc_context *c)
{
    if (put_system(c, "west0067.mtx") < 0) return;
    CHECK(silc_exec(c, "set dispatch.solve.sparse = petsc, suitesparse.umfpack; "
                       "set petsc.options = -ksp_type gmres -pc_type ilu") == 0,
          "set: %s", silc_context_errmsg(c));
    CHECK(strstr(tl_out_exec(c, "explain x = A \\ b"), "the next listed backend takes over"),
          "explain shows the chain:\n%s", tl_out());
    check_fell_back(c, "west0067", "petsc: KSPSetUp", "missing diagonal entry", "backend: suitesparse.umfpack");
    /* The next solve with the same A (a time loop) does not try PETSc again. */
    CHECK(silc_exec(c, "x2 = A \\ (2 * b)") == 0, "second solve: %s", silc_context_errmsg(c));
    CHECK(strstr(tl_out_info(c, "x2"), "petsc: skipped: it failed on this matrix before") &&
              strstr(tl_out(), "backend: suitesparse.umfpack"),
          "the failure is remembered with A:\n%s", tl_out());
}

static void test_failed_verification(silc_context *c)
{
    const char *in;
    int rc;
    if (put_system(c, "bcsstk13.mtx") < 0) return;
    CHECK(silc_exec(c, "set dispatch.solve.sparse.spd = petsc, suitesparse.cholmod; "
                       "set petsc.options = -ksp_type gmres -pc_type ilu") == 0,
          "set: %s", silc_context_errmsg(c));
    check_fell_back(c, "bcsstk13", "petsc: verification failed: backward error", "above 0.0001 (solve.verify)",
                    "backend: suitesparse.cholmod");
    /* solve.verify = off: PETSc's unverified result is kept, as before. */
    CHECK(silc_exec(c, "set solve.verify = off; y = A \\ b") == 0, "verify off: %s", silc_context_errmsg(c));
    in = tl_out_info(c, "y");
    CHECK(strstr(in, "backend: petsc") && !strstr(in, "earlier attempts") &&
              tl_out_number(in, "backward error: ") > 1e-4,
          "solve.verify = off keeps PETSc's result:\n%s", in);
    /* A single per-call backend has nothing to fall back to. */
    rc = silc_exec(c, "set solve.verify = auto; z = solve(A, b, \"backend = petsc\")");
    CHECK(rc != 0 &&
              tl_contains(silc_context_errmsg(c), "petsc: verification failed: backward error") &&
              !tl_contains(silc_context_errmsg(c), "every backend"),
          "a forced backend's failed verification is the error: %s", silc_context_errmsg(c));
    /* A bound of its own: 1e-20 is more than any double solve can show.  A
     * back-substitution with the factorization x's solve left is verified
     * when its backward error is computed at once (solve.backward_error =
     * always); deferred, the factorization's first solve vouches for it. */
    rc = silc_exec(c, "set solve.verify = 1e-20; set solve.backward_error = always; "
                      "w = solve(A, b, \"backend = suitesparse.cholmod\")");
    CHECK(rc != 0 && tl_contains(silc_context_errmsg(c), "suitesparse.cholmod: verification failed") &&
              tl_contains(silc_context_errmsg(c), "above 1e-20"),
          "solve.verify = 1e-20 fails CHOLMOD: %s", silc_context_errmsg(c));
    CHECK(silc_exec(c, "set solve.verify = auto; set solve.backward_error = deferred") == 0, "back to auto: %s",
          silc_context_errmsg(c));
    CHECK(silc_exec(c, "set solve.verify = often") != 0 &&
              tl_contains(silc_context_errmsg(c), "solve.verify expects 'auto', 'off' or a backward error"),
          "a bad solve.verify: %s", silc_context_errmsg(c));
}

static void test_all_fail(silc_context *c)
{
    const char *e;
    double *x;
    /* Structurally singular: row 2 and column 2 empty but for a zero. */
    CHECK(silc_exec(c, "Zs = sparse([1; 2; 3; 1; 3], [1; 2; 3; 3; 1], [4; 0; 4; 1; 1], 3, 3); "
                       "bz = [1; 1; 1]; x = [7; 7; 7]; "
                       "set dispatch.solve.sparse = suitesparse.umfpack, suitesparse.klu") == 0,
          "setup: %s", silc_context_errmsg(c));
    CHECK(silc_exec(c, "x = Zs \\ bz") != 0, "a singular matrix is refused");
    e = silc_context_errmsg(c);
    CHECK(tl_contains(e, "every backend of the list failed:\n  suitesparse.umfpack: ") &&
              tl_contains(e, "singular") && tl_contains(e, "\n  suitesparse.klu: "),
          "one line per attempt: %s", e);
    printf("  all fail: %s\n", e);
    x = tl_get_dense_checked(c, "x", 3, 1);
    CHECK(x && x[0] == 7 && x[1] == 7 && x[2] == 7, "x is unchanged after the chain failed");
    free(x);
}

/* A direct result that misses the bound gets refinement from its own
 * factorization before the next backend is tried: KLU leaves bayer10 at a
 * backward error of 8e-13, one step brings it to 1e-16.  solve.refine = 0
 * says no refinement, so the miss is final. */
static void test_refinement_first(silc_context *c)
{
    const char *in;
    int rc;
    if (put_system(c, "bayer10.mtx") < 0) return;
    rc = silc_exec(c, "set solve.verify = 1e-13; x = solve(A, b, \"backend = suitesparse.klu\")");
    in = tl_out_info(c, "x");
    CHECK(rc == 0 && strstr(in, "refinement: ") && tl_out_number(in, "backward error: ") <= 1e-14,
          "bayer10: KLU refined into the bound:\n%s", in);
    /* (x's factorization is reused: its backward error is computed at once) */
    rc = silc_exec(c, "set solve.refine = 0; set solve.backward_error = always; "
                      "y = solve(A, b, \"backend = suitesparse.klu\")");
    CHECK(rc != 0 && tl_contains(silc_context_errmsg(c), "suitesparse.klu: verification failed"),
          "bayer10: with solve.refine = 0 KLU's miss is final: %s", rc ? silc_context_errmsg(c) : "solved");
    CHECK(silc_exec(c, "set solve.verify = auto; set solve.backward_error = deferred") == 0, "reset: %s",
          silc_context_errmsg(c));
}

/* solve.verify set after a first solve of the same A means what it means
 * set before: the reused factorization's result is checked at once and
 * refined (KLU leaves bayer10 at 8.3e-13; the bound 1e-13 asks for more). */
static void test_verify_after_first_solve(void)
{
    silc_context *before = tl_open_printing(), *after = tl_open_printing();
    char in_before[4096];
    const char *in;
    double be_b, be_a, raw_b, raw_a;
    if (!before || !after) goto out;
    if (put_system(before, "bayer10.mtx") < 0 || put_system(after, "bayer10.mtx") < 0) goto out;
    CHECK(silc_exec(before, "set solve.verify = 1e-13; x = solve(A, b, \"backend = suitesparse.klu\")") == 0,
          "verify before: %s", silc_context_errmsg(before));
    snprintf(in_before, sizeof in_before, "%s", tl_out_info(before, "x"));
    CHECK(silc_exec(after, "x0 = solve(A, b, \"backend = suitesparse.klu\"); set solve.verify = 1e-13; "
                           "x = solve(A, b, \"backend = suitesparse.klu\")") == 0,
          "verify after: %s", silc_context_errmsg(after));
    in = tl_out_info(after, "x");
    be_b = tl_out_number(in_before, "backward error: ");
    be_a = tl_out_number(in, "backward error: ");
    raw_b = tl_out_number(in_before, "backward error before: ");
    raw_a = tl_out_number(in, "backward error before: ");
    CHECK(be_a <= 1e-13 && be_a == be_b && raw_a == raw_b && raw_a > 1e-13 && !strstr(in, "computed now"),
          "bayer10/KLU: solve.verify set after the first solve gives backward error %.3g (raw %.3g), set before "
          "%.3g (raw %.3g):\nbefore:\n%s\nafter:\n%s",
          be_a, raw_a, be_b, raw_b, in_before, in);
    /* The raw result needed refinement: so does every later back-substitution. */
    CHECK(silc_exec(before, "y = solve(A, 2 * b, \"backend = suitesparse.klu\")") == 0, "y: %s",
          silc_context_errmsg(before));
    in = tl_out_info(before, "y");
    CHECK(strstr(in, "reused factorization: yes") && strstr(in, "refinement: 1 step") &&
              tl_out_number(in, "backward error: ") <= 1e-13,
          "the next solve with the factorization is refined too:\n%s", in);
    printf("  bayer10/KLU, solve.verify = 1e-13 set before or after a first solve: %.3g -> %.3g both times\n",
           raw_a, be_a);
out:
    silc_close(&before);
    silc_close(&after);
}

/* Creates directory path (its parent exists); 0 when it exists after. */
static int mkdir_p(const char *path)
{
    int ok = mkdir(path, 0755) == 0 || errno == EEXIST;
    CHECK(ok, "cannot create %s: %s", path, strerror(errno));
    return ok ? 0 : -1;
}

/* Writes text to path; 0 on success. */
static int write_file(const char *path, const char *text)
{
    FILE *f = fopen(path, "w");
    int ok = f && fputs(text, f) >= 0;
    if (f && fclose(f)) ok = 0;
    CHECK(ok, "cannot write %s", path);
    return ok ? 0 : -1;
}

/* The number of times needle occurs in hay. */
static int count_of(const char *hay, const char *needle)
{
    int n = 0;
    for (const char *p = hay; (p = strstr(p, needle)) != NULL; p += strlen(needle)) n++;
    return n;
}

static void test_missing_plugin(void)
{
    const char *conf = SILC_BINARY_DIR "/tests/test_fallback_missing.conf";
    const char *dir = SILC_BINARY_DIR "/tests/test_fallback_plugins";
    const char *bogus = SILC_BINARY_DIR "/tests/test_fallback_plugins/libsilc_plugin_bogus.so";
    const char *log = SILC_BINARY_DIR "/tests/test_fallback_stderr.txt";
    char text[1024], *err = NULL;
    silc_context *c = NULL;
    const char *e;
    int rc, saved;
    FILE *f;
    long len;
    /* Named and absent: an error at start, naming the plugin and the path. */
    if (write_file(conf, "[dispatch]\nsolve.sparse = template\n")) return;
    rc = silc_open(&c, conf);
    e = c ? silc_context_errmsg(c) : silc_errmsg();
    CHECK(rc != 0 && tl_contains(e, "dispatch.solve.sparse names backend 'template', which is not installed") &&
              tl_contains(e, "libsilc_plugin_template.so") && tl_contains(e, "searched: ") &&
              tl_contains(e, SILC_BINARY_DIR "/plugins") && tl_contains(e, "'template?'"),
          "a configured plugin that is absent is an error at silc_open: rc %d, %s", rc, e);
    printf("  absent plugin: %s\n", e);
    silc_close(&c);
    /* Optional: left out, said so by explain, and the next backend solves. */
    if (write_file(conf, "[dispatch]\nsolve.sparse = template?, suitesparse.umfpack\n")) return;
    rc = silc_open(&c, conf);
    CHECK(rc == 0, "an optional absent plugin opens: %s", c ? silc_context_errmsg(c) : silc_errmsg());
    if (rc == 0) {
        silc_set_output(c, tl_out_fn, NULL);
        CHECK(silc_exec(c, "A = sparse([4, -1, 0; -2, 5, 1; 0, 1, 3]); b = [1; 2; 3]") == 0, "A: %s",
              silc_context_errmsg(c));
        e = tl_out_exec(c, "explain x = A \\ b");
        CHECK(tl_contains(e, "backends (config key dispatch.solve.sparse): suitesparse.umfpack, reference "
                             "(not installed, left out: template)") &&
                  !tl_contains(e, "template: not installed"),
              "explain shows only the backends that exist:\n%s", e);
        CHECK(silc_exec(c, "x = A \\ b") == 0 && tl_contains(tl_out_info(c, "x"), "backend: suitesparse.umfpack"),
              "optional absent: umfpack solves: %s\n%s", silc_context_errmsg(c), tl_out());
        /* Set in the session: the solve fails, no silent reference. */
        rc = silc_exec(c, "set dispatch.solve.sparse = template; y = A \\ b");
        CHECK(rc != 0 && tl_contains(silc_context_errmsg(c), "names backend 'template', which is not installed"),
              "a session list naming an absent plugin fails the solve: %s", rc ? silc_context_errmsg(c) : "solved");
    }
    silc_close(&c);
    /* On the plugin path (core.plugin_path): found, and it runs. */
    snprintf(text, sizeof text, "[core]\nplugin_path = %s/plugins/template\n[dispatch]\nsolve.sparse = template\n",
             SILC_BINARY_DIR);
    if (write_file(conf, text)) return;
    rc = silc_open(&c, conf);
    CHECK(rc == 0, "template on core.plugin_path opens: %s", c ? silc_context_errmsg(c) : silc_errmsg());
    silc_close(&c);
    /* A plugin file that cannot be loaded: warned about once per process,
     * however many contexts or directory listings meet it. */
    if (mkdir_p(dir) || write_file(bogus, "not a shared object\n")) return;
    fflush(stderr);
    saved = dup(2);
    f = freopen(log, "w", stderr);
    CHECK(f != NULL, "cannot redirect stderr to %s", log);
    setenv("SILC_PLUGIN_PATH", dir, 1);
    snprintf(text, sizeof text, "[core]\nplugin_path = %s\n", dir);
    write_file(conf, text);
    for (int i = 0; i < 3; i++) {
        rc = silc_open(&c, conf);
        CHECK(rc == 0, "open %d with a bogus plugin file: %s", i, c ? silc_context_errmsg(c) : silc_errmsg());
        /* Plugins open at first need: a misspelt backend's suggestions
         * list every backend, which opens every file (the bogus one too). */
        CHECK(c && silc_exec(c, "set dispatch.solve.sparse = nosuch_backend") != 0,
              "open %d: a misspelt backend was accepted", i);
        silc_close(&c);
    }
    unsetenv("SILC_PLUGIN_PATH");
    fflush(stderr);
    if (saved >= 0) {
        dup2(saved, 2);
        close(saved);
    }
    f = fopen(log, "r");
    if (f && fseek(f, 0, SEEK_END) == 0 && (len = ftell(f)) >= 0 && (err = calloc((size_t)len + 1, 1)) &&
        fseek(f, 0, SEEK_SET) == 0)
        CHECK(fread(err, 1, (size_t)len, f) == (size_t)len, "cannot read %s", log);
    if (f) fclose(f);
    snprintf(text, sizeof text, "silc: warning: cannot load plugin %s:", bogus);
    CHECK(err && count_of(err, text) == 1, "a plugin file that cannot be loaded is warned about once, not %d times:\n%s",
          err ? count_of(err, text) : -1, err ? err : "");
    free(err);
    remove(bogus);
    remove(conf);
}

int main(void)
{
    silc_context *c = tl_open_printing();
    if (!c) return check_done();
    if (have(c, "petsc") && have(c, "suitesparse.umfpack")) {
        test_library_failure(c);
        test_failed_verification(c);
    } else {
        printf("test_fallback: petsc or suitesparse not built: the PETSc chains skipped\n");
    }
    if (have(c, "suitesparse.umfpack") && have(c, "suitesparse.klu")) {
        test_refinement_first(c);
        test_all_fail(c);
        test_verify_after_first_solve();
        test_missing_plugin();
    }
    silc_close(&c);
    return check_done();
}
