/*
 * test_abi.c -- the loader refuses every kind of broken plugin with a message
 * that says exactly what is wrong, and runs a good one.
 *
 * The purpose-made modules (wrong_major.c, wrong_index.c, no_symbol.c,
 * init_fails.c, no_ops.c, good.c) are built next to this test; their
 * directory comes in as ABI_PLUGIN_DIR and the template plugin's file as
 * TEMPLATE_PLUGIN.  The test drives the internal engine (engine.h, dispatch.h) directly,
 * after checking that the public context opens and closes.
 */
#include "check.h"
#include "dispatch.h"
#include "engine.h"

#include <stdio.h>
#include <string.h>

#ifndef ABI_PLUGIN_DIR
#error "ABI_PLUGIN_DIR must name the directory of the test plugins"
#endif
#ifndef TEMPLATE_PLUGIN
#error "TEMPLATE_PLUGIN must name the template plugin's file"
#endif

static void module(char *out, size_t len, const char *name)
{
    snprintf(out, len, "%s/abi_%s.so", ABI_PLUGIN_DIR, name);
}

/* Loading the module must fail with exactly the message want. */
static void refused(silc_engine *E, const char *name, const char *want)
{
    char path[1024];
    module(path, sizeof path, name);
    CHECK(ld_load_file(E, path) != 0, "%s: loaded but should be refused", name);
    CHECK(strcmp(E->err, want) == 0, "%s: message\n  got  '%s'\n  want '%s'", name, E->err, want);
    CHECK(ld_find_plugin(E, name) == NULL, "%s: refused plugin is registered", name);
}

static silc_value *dense(int64_t m, int64_t n, const double *colmajor)
{
    silc_value *v = val_dense_new(m, n);
    if (v) memcpy(v->val, colmajor, (size_t)(m * n) * sizeof(double));
    return v;
}

/* SCALE through the dispatcher with a forced backend; out must be want. */
static void scale_via(silc_engine *E, const char *backend, const silc_value *A, double alpha,
                      const double *want)
{
    char opts[128];
    silc_call c;
    silc_view w;
    int64_t i;
    memset(&c, 0, sizeof c);
    snprintf(opts, sizeof opts, "backend = %s", backend);
    c.op = SILC_OP_SCALE;
    c.nin = 1;
    c.in[0] = A;
    c.alpha = alpha;
    c.options = opts;
    CHECK(disp_run(E, &c) == 0, "scale via %s failed: %s", backend, E->err);
    if (!c.out) return;
    val_view(c.out, &w);
    for (i = 0; i < w.m * w.n; i++) CHECK_NEAR(w.val[i], want[i], 0);
    val_release(c.out);
    CHECK(cfg_get(E, "backend") == NULL, "per-call option outlived the call");
}

int main(void)
{
    silc_context *ctx = NULL;
    silc_engine *E = NULL;
    char err[1024], path[1024], want[2048];
    static const double a[4] = {1, 3, 2, 4};
    static const double good_want[4] = {3, 7, 5, 9}, template_want[4] = {2, 6, 4, 8};
    silc_value *A, *S;
    silc_call c;
    strbuf b;

    CHECK(silc_open(&ctx, "/dev/null") == 0, "silc_open failed");
    silc_close(&ctx);
    CHECK(ctx == NULL, "silc_close did not clear the handle");

    CHECK(eng_create(&E, "/dev/null", err, sizeof err) == 0, "eng_create: %s", err);
    if (!E) return check_done();
    CHECK(ld_find(E, "reference") != NULL, "built-in reference plugin missing");

    module(path, sizeof path, "wrong_major");
    snprintf(want, sizeof want, "plugin 'wrong_major' (%s) was built for ABI major 2, this host has %d",
             path, SILC_ABI_MAJOR);
    refused(E, "wrong_major", want);

    module(path, sizeof path, "wrong_index");
    snprintf(want, sizeof want, "plugin 'wrong_index' (%s) uses 4-byte indices, host uses 8", path);
    refused(E, "wrong_index", want);

    module(path, sizeof path, "init_fails");
    snprintf(want, sizeof want, "cannot load plugin %s: silc_plugin_init failed: libfoo not found",
             path);
    refused(E, "init_fails", want);

    module(path, sizeof path, "no_ops");
    snprintf(want, sizeof want, "plugin 'no_ops' (%s) provides no operations", path);
    refused(E, "no_ops", want);

    /* The dlerror() text after the reason varies by C library; the start not. */
    module(path, sizeof path, "no_symbol");
    CHECK(ld_load_file(E, path) != 0, "no_symbol loaded");
    snprintf(want, sizeof want, "cannot load plugin %s: no silc_plugin_init symbol (", path);
    CHECK(strncmp(E->err, want, strlen(want)) == 0, "no_symbol: got '%s'", E->err);
    CHECK(strstr(E->err, "silc_plugin_init") != NULL, "no_symbol: dlerror text missing");

    CHECK(ld_load_file(E, ABI_PLUGIN_DIR "/abi_missing.so") != 0, "a missing file loaded");
    CHECK(strncmp(E->err, "cannot load plugin " ABI_PLUGIN_DIR "/abi_missing.so: ",
                  strlen("cannot load plugin " ABI_PLUGIN_DIR "/abi_missing.so: ")) == 0,
          "missing file: got '%s'", E->err);
    CHECK(ld_load_path(E, ABI_PLUGIN_DIR "/no_such_dir") != 0, "a missing directory was accepted");

    /* A good plugin loads; the same file again is no conflict; another file
     * with the same plugin name is refused. */
    module(path, sizeof path, "good");
    CHECK(ld_load_file(E, path) == 0, "good plugin refused: %s", E->err);
    CHECK(ld_find(E, "good") != NULL, "backend 'good' not registered");
    CHECK(ld_load_file(E, path) == 0, "same file twice refused: %s", E->err);
    module(want, sizeof want, "good_copy");
    CHECK(ld_load_file(E, want) != 0, "second plugin named 'good' accepted");
    CHECK(strstr(E->err, "a plugin of that name is already loaded from") != NULL,
          "duplicate: got '%s'", E->err);

    CHECK(ld_load_file(E, TEMPLATE_PLUGIN) == 0, "template plugin refused: %s", E->err);
    CHECK(ld_find(E, "template") != NULL, "backend 'template' not registered");

    A = dense(2, 2, a);
    CHECK(A != NULL, "value allocation");
    if (A) {
        scale_via(E, "good", A, 2, good_want);
        scale_via(E, "template", A, 2, template_want);

        memset(&c, 0, sizeof c);
        c.op = SILC_OP_SCALE;
        c.nin = 1;
        c.in[0] = A;
        c.alpha = 2;
        c.options = "backend = template";
        sb_init(&b);
        CHECK(disp_explain(E, &c, &b) == 0, "explain failed: %s", E->err);
        CHECK(strstr(sb_str(&b), "template -> would run") != NULL, "explain: %s", sb_str(&b));
        CHECK(strstr(sb_str(&b), "per-call option backend = template") != NULL, "explain: %s",
              sb_str(&b));
        sb_free(&b);

        /* The template takes dense values only: a CSR operand is declined. */
        S = val_csr_new(2, 2, 0);
        if (S) {
            c.in[0] = S;
            CHECK(disp_run(E, &c) != 0 && c.out == NULL, "template ran on a CSR value");
            CHECK(strcmp(E->err, "no backend can run scale (add): template declines: template "
                                 "handles dense values only") == 0,
                  "decline: got '%s'", E->err);
            val_release(S);
        }

        /* An unknown forced backend is an error with a suggestion. */
        c.in[0] = A;
        c.options = "backend = templat";
        CHECK(disp_run(E, &c) != 0, "unknown backend accepted");
        CHECK(strcmp(E->err, "unknown backend 'templat' in option 'backend'; did you mean 'template'?") == 0,
              "unknown backend: got '%s'", E->err);
        val_release(A);
    }
    eng_destroy(&E);
    CHECK(E == NULL, "eng_destroy did not clear the handle");
    return check_done();
}
