/*
 * test_config.c -- the options database and the dispatcher's choices.
 *
 * Config files with mistakes must be refused with file:line and the closest
 * valid spelling; the three scopes must shadow each other (file < set <
 * per-call); every structure rule of `\` must give its class; `explain` must
 * name where the backend list came from and which backend would run; and a
 * solve must carry the core's accuracy report.
 */
#define _POSIX_C_SOURCE 200809L
#include "check.h"
#include "dispatch.h"
#include "engine.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#ifndef TEMPLATE_PLUGIN
#error "TEMPLATE_PLUGIN must name the template plugin's file"
#endif

static char conf_path[64];

/* Writes text to a fresh config file and loads it; returns cfg_load_file's status. */
static int load_text(silc_engine *E, const char *text)
{
    FILE *f;
    int fd;
    snprintf(conf_path, sizeof conf_path, "/tmp/silc_test_config_XXXXXX");
    fd = mkstemp(conf_path);
    if (fd < 0) return -99;
    f = fdopen(fd, "w");
    if (!f) {
        close(fd);
        return -99;
    }
    fputs(text, f);
    fclose(f);
    {
        int rc = cfg_load_file(E, conf_path);
        remove(conf_path);
        return rc;
    }
}

/* The file must be refused with "<path>:<line>: <msg>". */
static void file_error(silc_engine *E, const char *text, int line, const char *msg)
{
    char want[1024];
    int rc = load_text(E, text);
    CHECK(rc != 0 && rc != -99, "accepted: %s", text);
    snprintf(want, sizeof want, "%s:%d: %s", conf_path, line, msg);
    CHECK(strcmp(E->err, want) == 0, "config error\n  got  '%s'\n  want '%s'", E->err, want);
}

static void set_error(silc_engine *E, const char *key, const char *value, const char *msg)
{
    CHECK(cfg_set(E, CFG_SCOPE_SESSION, key, value) != 0, "set %s = %s accepted", key, value);
    CHECK(strcmp(E->err, msg) == 0, "set %s\n  got  '%s'\n  want '%s'", key, E->err, msg);
}

static void value_is(const silc_engine *E, const char *key, const char *want)
{
    const char *got = cfg_get(E, key);
    if (!want) CHECK(got == NULL, "%s = '%s', want unset", key, got ? got : "");
    else CHECK(got && strcmp(got, want) == 0, "%s = '%s', want '%s'", key, got ? got : "(unset)", want);
}

/* n x n dense value from a row-major literal (easier to read in tests). */
static silc_value *dense_rows(int64_t m, int64_t n, const double *rows)
{
    silc_value *v = val_dense_new(m, n);
    int64_t i, j;
    if (!v) return NULL;
    for (i = 0; i < m; i++)
        for (j = 0; j < n; j++) v->val[i + j * m] = rows[i * n + j];
    return v;
}

/* CSR copy of a dense value. */
static silc_value *to_csr(const silc_value *d)
{
    int64_t i, j, k = 0, nnz = 0;
    silc_value *v;
    for (i = 0; i < d->m * d->n; i++) nnz += d->val[i] != 0;
    v = val_csr_new(d->m, d->n, nnz);
    if (!v) return NULL;
    for (i = 0; i < d->m; i++) {
        v->rowptr[i] = k;
        for (j = 0; j < d->n; j++)
            if (d->val[i + j * d->m] != 0) {
                v->colind[k] = j;
                v->val[k++] = d->val[i + j * d->m];
            }
    }
    v->rowptr[d->m] = k;
    val_csr_set_nnz(v, k);
    return v;
}

static void classes_are(silc_engine *E, const silc_value *A, const char *c0, const char *c1)
{
    silc_call c;
    const char *out[4] = {0};
    int n;
    memset(&c, 0, sizeof c);
    c.op = SILC_OP_SOLVE;
    c.nin = 2;
    c.in[0] = A;
    c.in[1] = A;
    n = disp_classes(E, &c, out);
    CHECK(n == (c1 ? 2 : 1), "%s: %d classes", c0, n);
    CHECK(n >= 1 && strcmp(out[0], c0) == 0, "class %s, want %s", n >= 1 ? out[0] : "-", c0);
    if (c1) CHECK(n == 2 && strcmp(out[1], c1) == 0, "second class %s, want %s", n == 2 ? out[1] : "-", c1);
}

static void explain_has(silc_engine *E, const silc_value *A, const silc_value *B, const char *opts,
                        const char *want1, const char *want2)
{
    silc_call c;
    strbuf b;
    memset(&c, 0, sizeof c);
    c.op = SILC_OP_SOLVE;
    c.nin = 2;
    c.in[0] = A;
    c.in[1] = B;
    c.options = opts;
    sb_init(&b);
    CHECK(disp_explain(E, &c, &b) == 0, "explain failed: %s", E->err);
    CHECK(strstr(sb_str(&b), want1) != NULL, "explain lacks '%s':\n%s", want1, sb_str(&b));
    if (want2) CHECK(strstr(sb_str(&b), want2) != NULL, "explain lacks '%s':\n%s", want2, sb_str(&b));
    sb_free(&b);
}

static void test_files(silc_engine *E)
{
    file_error(E, "[tune]\nthread = 4\n", 2, "unknown key 'tune.thread'; did you mean 'tune.threads'?");
    file_error(E, "# comment\n[dispatch]\nsolve.sparse = umfpak, reference\n", 3,
               "unknown backend 'umfpak' in dispatch.solve.sparse; did you mean 'suitesparse.umfpack'?");
    file_error(E, "[dispatch]\nsolve.sparse = umfpack\n", 2,
               "unknown backend 'umfpack' in dispatch.solve.sparse; did you mean 'suitesparse.umfpack'?");
    file_error(E, "[dispatch]\nsolve.sparce = reference\n", 2,
               "unknown dispatch class 'solve.sparce'; did you mean 'solve.sparse'?");
    file_error(E, "[mump]\nicntl_7 = 2\n", 2, "unknown section [mump]; did you mean [mumps]?");
    file_error(E, "[tune]\nthreads = many\n", 2,
               "tune.threads expects 'auto' or a thread count from 1 to 4096, got 'many'");
    file_error(E, "[tune]\n\nthreads 4\n", 3, "syntax error (expected '[section]' or 'key = value')");
    file_error(E, "[template]\nverbos = 1\n", 2,
               "plugin 'template' has no option 'verbos'; did you mean 'verbose'?");
    CHECK(cfg_load_file(E, "/nonexistent/silc.conf") != 0, "missing file accepted");
    /* inih reads lines into a 200-byte buffer: a longer line is refused, not
     * cut or split into a second line; 199 characters still fit */
    {
        char text[512];
        snprintf(text, sizeof text, "[lis-style]\noptions = -i cg%*s\n", 199 - 15, "");
        CHECK(load_text(E, text) == 0, "199-character line refused: %s", E->err);
        snprintf(text, sizeof text, "[lis-style]\noptions = -i cg%*s\n", 200 - 15, "");
        file_error(E, text, 2, "line longer than 199 characters (the INI reader's limit)");
        snprintf(text, sizeof text, "[tune]\nthread = 4\n[lis-style]\noptions = -i cg%*s\n", 300, "");
        file_error(E, text, 2, "unknown key 'tune.thread'; did you mean 'tune.threads'?");
        snprintf(text, sizeof text, "[tune]\nthreads 4\n[lis-style]\noptions = -i cg%*s\n", 300, "");
        file_error(E, text, 2, "syntax error (expected '[section]' or 'key = value')");
    }

    /* Known but not installed backends and plugin sections are accepted, so a
     * config file serves machines with and without them. */
    CHECK(load_text(E, "[dispatch]\nsolve.sparse.spd = suitesparse.cholmod, lis-style, reference\n"
                       "[tune]\nthreads = auto\naccuracy = 1e-10\n"
                       "[lis-style]\noptions = -i cg -p ilu\n"
                       "[template]\nverbose = false\n") == 0,
          "valid file refused: %s", E->err);
    value_is(E, "dispatch.solve.sparse.spd", "suitesparse.cholmod, lis-style, reference");
    value_is(E, "tune.accuracy", "1e-10");
    value_is(E, "template.verbose", "false");
    if (!ld_find_plugin(E, "lis-style")) value_is(E, "lis-style.options", "-i cg -p ilu");
}

static void test_scopes(silc_engine *E)
{
    CHECK(load_text(E, "[dispatch]\nsolve.dense = reference\n") == 0, "file: %s", E->err);
    value_is(E, "dispatch.solve.dense", "reference");
    CHECK(cfg_set(E, CFG_SCOPE_SESSION, "dispatch.solve.dense", " lapack ,reference ") == 0,
          "set: %s", E->err);
    value_is(E, "dispatch.solve.dense", "lapack, reference");
    CHECK(cfg_set_call_options(E, "dispatch.solve.dense = reference; backend = reference") == 0,
          "call options: %s", E->err);
    value_is(E, "dispatch.solve.dense", "reference");
    value_is(E, "backend", "reference");
    cfg_clear_call_options(E);
    value_is(E, "dispatch.solve.dense", "lapack, reference");
    value_is(E, "backend", NULL);

    set_error(E, "dispatch.solve.dense", "lapak", "unknown backend 'lapak' in dispatch.solve.dense; did you mean 'lapack'?");
    set_error(E, "tune.acuracy", "1e-8", "unknown key 'tune.acuracy'; did you mean 'tune.accuracy'?");
    set_error(E, "backend", "reference",
              "'backend' forces a backend for one call only; use dispatch.<class> to change the default");
    set_error(E, "template.verbose", "maybe", "option 'template.verbose' expects true or false, got 'maybe'");
    CHECK(cfg_set_call_options(E, "tune.threads") != 0, "option without '=' accepted");
    CHECK(strcmp(E->err, "option 'tune.threads' needs the form key = value") == 0, "got '%s'", E->err);
    CHECK(cfg_set(E, CFG_SCOPE_SESSION, "mumps.icntl_7", "2") == 0 || ld_find_plugin(E, "mumps"),
          "option of an uninstalled known plugin refused: %s", E->err);
}

static void test_classes(silc_engine *E)
{
    static const double diag[] = {2, 0, 0, 0, 3, 0, 0, 0, 4};
    static const double lower[] = {2, 0, 0, 1, 3, 0, 5, 1, 4};
    static const double spd[] = {4, 1, 1, 1, 4, 1, 1, 1, 4};
    static const double gen[] = {4, 1, 2, 0, 4, 1, 3, 1, 4};
    static const double rect[] = {1, 2, 3, 4, 5, 6};
    double tri[20 * 20] = {0};
    silc_value *D = dense_rows(3, 3, diag), *L = dense_rows(3, 3, lower), *S = dense_rows(3, 3, spd);
    silc_value *G = dense_rows(3, 3, gen), *R = dense_rows(3, 2, rect), *T, *Tc, *Sc, *Gc, *Bd, *b, *b20;
    int i;
    for (i = 0; i < 20; i++) {
        tri[i * 20 + i] = 4;
        if (i > 0) tri[i * 20 + i - 1] = -1;
        if (i < 19) tri[i * 20 + i + 1] = -2;
    }
    T = dense_rows(20, 20, tri);
    Tc = to_csr(T);
    b20 = dense_rows(20, 1, tri);
    Sc = to_csr(S);
    Gc = to_csr(G);
    Bd = val_band_new(4, 4, 1, 1);
    b = dense_rows(3, 1, rect);
    if (!D || !L || !S || !G || !R || !T || !Tc || !b20 || !Sc || !Gc || !Bd || !b) {
        CHECK(0, "value allocation");
        return;
    }
    for (i = 0; i < 12; i++) Bd->val[i] = 1 + i;
    classes_are(E, D, "solve.diag", NULL);
    classes_are(E, L, "solve.triangular", NULL);
    classes_are(E, T, "solve.band", NULL);
    classes_are(E, Bd, "solve.band", NULL);
    classes_are(E, Tc, "solve.band", NULL); /* a banded CSR matrix, nothing configured */
    classes_are(E, S, "solve.dense.spd", "solve.dense");
    classes_are(E, Sc, "solve.sparse.spd", "solve.sparse");
    classes_are(E, G, "solve.dense", NULL);
    classes_are(E, Gc, "solve.sparse", NULL);
    classes_are(E, R, "solve.rect", NULL);

    /* Defaults: the list of the most specific class. */
    explain_has(E, Sc, b, NULL, "A is 3x3 csr, symmetric with positive diagonal -> solve.sparse.spd, then solve.sparse",
                "built-in default for solve.sparse.spd");
    explain_has(E, Sc, b, NULL, "-> would run", NULL);
    /* A config naming only solve.sparse governs SPD sparse systems too. */
    CHECK(cfg_set(E, CFG_SCOPE_SESSION, "dispatch.solve.sparse", "reference") == 0, "set: %s", E->err);
    explain_has(E, Sc, b, NULL, "backends (config key dispatch.solve.sparse): reference",
                "  reference -> would run");
    explain_has(E, G, b, "backend = reference", "per-call option backend = reference",
                "  reference -> would run");
    explain_has(E, R, b, NULL, "A is 3x2 dense, not square (least squares) -> solve.rect", NULL);
    /* ... and banded CSR systems, unless solve.band is configured too; a
     * dense banded matrix stays LAPACK's band system. */
    classes_are(E, Tc, "solve.sparse", NULL);
    classes_are(E, T, "solve.band", NULL);
    explain_has(E, Tc, b20, NULL,
                "A is 20x20 csr, banded, but a sparse class is configured and solve.band is not -> solve.sparse",
                "backends (config key dispatch.solve.sparse): reference");
    CHECK(cfg_set(E, CFG_SCOPE_SESSION, "dispatch.solve.band", "reference") == 0, "set: %s", E->err);
    classes_are(E, Tc, "solve.band", NULL);
    explain_has(E, Tc, b20, NULL, "banded (kl=1, ku=1) -> solve.band", "config key dispatch.solve.band");
    value_is(E, "backend", NULL);

    val_release(D);
    val_release(L);
    val_release(S);
    val_release(G);
    val_release(R);
    val_release(T);
    val_release(Tc);
    val_release(b20);
    val_release(Sc);
    val_release(Gc);
    val_release(Bd);
    val_release(b);
}

/* A solve through the dispatcher: right answer, and the core's report. */
static void test_solve(silc_engine *E)
{
    static const double spd[] = {4, 1, 1, 1, 4, 1, 1, 1, 4};
    static const double x_true[] = {1, -2, 3};
    double rhs[3];
    silc_value *A = dense_rows(3, 3, spd), *B;
    silc_report rep;
    silc_call c;
    int i, j;
    for (i = 0; i < 3; i++) {
        rhs[i] = 0;
        for (j = 0; j < 3; j++) rhs[i] += spd[i * 3 + j] * x_true[j];
    }
    B = dense_rows(3, 1, rhs);
    if (!A || !B) {
        CHECK(0, "value allocation");
        return;
    }
    memset(&c, 0, sizeof c);
    c.op = SILC_OP_SOLVE;
    c.nin = 2;
    c.in[0] = A;
    c.in[1] = B;
    c.report = &rep;
    c.options = "backend = reference";
    CHECK(disp_run(E, &c) == 0, "solve failed: %s", E->err);
    if (c.out) {
        for (i = 0; i < 3; i++) CHECK_NEAR(val_get(c.out, i, 0), x_true[i], 1e-13);
        CHECK(strcmp(rep.backend, "reference") == 0, "report backend '%s'", rep.backend);
        CHECK(rep.backward_error >= 0 && rep.backward_error < 1e-15, "backward error %g",
              rep.backward_error);
        CHECK(rep.seconds >= 0, "seconds %g", rep.seconds);
        val_release(c.out);
    }
    val_release(A);
    val_release(B);
}

static silc_engine *fresh_engine(void)
{
    silc_engine *E = NULL;
    char err[1024];
    CHECK(eng_create(&E, "/dev/null", err, sizeof err) == 0, "eng_create: %s", err);
    if (E) CHECK(ld_load_file(E, TEMPLATE_PLUGIN) == 0, "template plugin: %s", E->err);
    return E;
}

int main(void)
{
    silc_engine *E = fresh_engine();
    if (E) {
        test_files(E);
        test_scopes(E);
        eng_destroy(&E);
    }
    /* A new engine: the files above configured dispatch lists. */
    E = fresh_engine();
    if (E) {
        test_classes(E);
        test_solve(E);
        eng_destroy(&E);
    }
    return check_done();
}
