/*
 * api.c -- the public calls of silc.h: contexts, put/get/exec, and the
 * upper-case calls of the seeds on one default context.
 *
 * A context is embedded (an engine in this process) or remote (a connection
 * to silcd, remote.c); every call checks its arguments here, once for both,
 * and then goes to one or the other.  The embedded operations themselves are
 * the api_* functions of client.h, which silcd runs for its sessions, so both
 * modes produce the same results and the same messages.  Each failure leaves
 * its message on the context (ctx->err); failures that have no context (a
 * call before SILC_INIT, a NULL context, an envelope constructor) leave it in
 * the per-thread buffer of envelope.c.  silc_errmsg() shows whichever is
 * latest.
 */
#define _POSIX_C_SOURCE 200809L
#include "silc.h"

#include <ctype.h>
#include <errno.h>
#include <fcntl.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "client.h"
#include "dist.h"
#include "silc_comm.h"
#include "engine.h"
#include "lang.h"
#include "store.h"

struct silc_context {
    silc_engine *E;          /* embedded, or NULL */
    rem_conn *R;             /* remote, or NULL */
    silc_output_fn output;   /* remote: where TEXT replies go (NULL = stdout) */
    void *output_user;
    strbuf warnings;         /* remote: WARN replies of the last exec */
    char err[4096];
};

static silc_context *default_ctx;

static int ctx_error(silc_context *ctx, const char *fmt, ...)
#if defined(__GNUC__)
    __attribute__((format(printf, 2, 3)))
#endif
    ;

static int ctx_error(silc_context *ctx, const char *fmt, ...)
{
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(ctx->err, sizeof ctx->err, fmt, ap);
    va_end(ap);
    if (ctx == default_ctx) env_error_forget();
    return -1;
}

/* ---- embedded operations (client.h) ------------------------------------- */

int api_check_name(const char *name, char *err, size_t errlen)
{
    if (util_is_name(name)) return 0;
    snprintf(err, errlen, "invalid name '%s': names start with a letter or '_' and contain "
                          "only letters, digits and '_'", name);
    return -1;
}

int api_bind(silc_engine *E, const char *name, silc_value *v, char *err, size_t errlen)
{
    /* A PUT of exactly what the name holds keeps the value it holds, and so
     * its identity and what hangs on it: a program that PUTs the same
     * matrix every step (the seeds' limited mode) is not refactored every
     * step.  The comparison is one pass over arrays just copied. */
    const silc_value *old = store_get(&E->store, name);
    if (old && val_same_contents(old, v)) {
        eng_info_remove(E, name);
        return 0;
    }
    if (store_set(&E->store, name, v)) {
        snprintf(err, errlen, "out of memory storing '%s'", name);
        return -1;
    }
    /* The name now holds data from the program, not a computed result. */
    eng_info_remove(E, name);
    return 0;
}

const silc_value *api_lookup(silc_engine *E, const char *name, char *err, size_t errlen)
{
    const char **names = NULL;
    const silc_value *v = store_get(&E->store, name);
    size_t n;
    const char *near;
    if (v) return v;
    n = store_names(&E->store, &names);
    near = util_closest(name, names, n);
    if (near) snprintf(err, errlen, "undefined name '%s' (did you mean '%s'?)", name, near);
    else snprintf(err, errlen, "undefined name '%s'", name);
    free(names);
    return NULL;
}

int api_exec(silc_engine *E, const char *statements, char *err, size_t errlen)
{
    E->warnings.len = 0;
    E->warnings.failed = 0;
    if (E->warnings.s) E->warnings.s[0] = '\0';
    eng_interrupt_clear(E); /* an interrupt stops the exec it meets, not the next one */
    if (lang_exec(E, statements) == 0) return 0;
    snprintf(err, errlen, "%s", E->err[0] ? E->err : "statement failed");
    return -1;
}

/* ---- contexts ------------------------------------------------------------ */

/* The token for a remote server: SILC_TOKEN, else the first line of
 * SILC_TOKEN_FILE, else none.  Returns a malloc'd string or NULL.  The file
 * must be a regular one (a FIFO with no writer hung the client; /dev/zero
 * read as an empty token), read without blocking and at most 8 KiB. */
static char *remote_token(char *err, size_t errlen, int *failed)
{
    const char *t = getenv("SILC_TOKEN"), *path = getenv("SILC_TOKEN_FILE");
    char buf[8192];
    size_t n = 0;
    ssize_t got;
    int fd;
    *failed = 0;
    if (t && *t) return util_strdup(t);
    if (!path || !*path) return NULL;
    if ((fd = util_open_read_at(AT_FDCWD, path, 1)) < 0) {
        if (errno == EINVAL) snprintf(err, errlen, "SILC_TOKEN_FILE '%s' is not a regular file", path);
        else snprintf(err, errlen, "cannot read SILC_TOKEN_FILE '%s': %s", path, strerror(errno));
        *failed = 1;
        return NULL;
    }
    while (n < sizeof buf - 1 && (got = read(fd, buf + n, sizeof buf - 1 - n)) > 0) n += (size_t)got;
    close(fd);
    buf[n] = '\0';
    buf[strcspn(buf, "\r\n")] = '\0';
    return util_strdup(buf);
}

int silc_open_remote(silc_context **out, const char *url)
{
    silc_context *ctx;
    char *token;
    int failed;
    if (!out) return env_error("silc_open_remote: NULL context pointer");
    *out = NULL;
    pool_install_default();
    if (!url || !*url) return env_error("silc_open_remote: no server address");
    if (!(ctx = calloc(1, sizeof *ctx))) return env_error("silc_open_remote: out of memory");
    sb_init(&ctx->warnings);
    token = remote_token(ctx->err, sizeof ctx->err, &failed);
    if (failed || rem_open(&ctx->R, url, token, ctx->err, sizeof ctx->err)) {
        free(token);
        env_error("%s", ctx->err);
        free(ctx);
        return -1;
    }
    free(token);
    *out = ctx;
    return 0;
}

int silc_open(silc_context **out, const char *config_path)
{
    silc_context *ctx;
    const char *server = getenv("SILC_SERVER");
    char err[4096];
    pool_install_default();
    /* Remote mode: the server's configuration applies, not config_path. */
    if (server && *server) return silc_open_remote(out, server);
    if (!out) return env_error("silc_open: NULL context pointer");
    *out = NULL;
    ctx = calloc(1, sizeof *ctx);
    if (!ctx) return env_error("silc_open: out of memory");
    if (eng_create(&ctx->E, config_path, err, sizeof err)) {
        free(ctx);
        return env_error("%s", err);
    }
    *out = ctx;
    return 0;
}

/* Ranks other than 0 print nothing by default: one copy of `who`, `info`
 * and `explain` per job, as an MPI program prints on rank 0. */
static void quiet(void *user, const char *text)
{
    (void)user;
    (void)text;
}

int silc_open_comm(silc_context **out, const char *config_path, silc_comm_ops *ops)
{
    silc_context *ctx;
    char err[4096];
    int rc, failed;
    if (!out) {
        if (ops && ops->destroy) ops->destroy(ops->impl);
        return env_error("silc_open_comm: NULL context pointer");
    }
    *out = NULL;
    if (!ops) return env_error("silc_open_comm: no communicator");
    pool_install_default();
    ctx = calloc(1, sizeof *ctx);
    rc = ctx ? eng_create_comm(&ctx->E, config_path, ops, err, sizeof err) : -1;
    if (!ctx) {
        snprintf(err, sizeof err, "silc_open_comm: out of memory");
        if (ops->destroy) ops->destroy(ops->impl);
    }
    /* Every rank opens or none does: a rank left without an engine would
     * leave the others waiting in their first collective.  The engines
     * that opened agree through their communicator; a rank whose engine
     * failed cannot reach it any more, so it ends the job instead. */
    if (rc) {
        free(ctx);
        return env_error("%s", err);
    }
    failed = dist_agree(ctx->E, 0);
    (void)failed;
    if (ctx->E->dist->rank != 0) ctx->E->output = quiet;
    *out = ctx;
    return 0;
}

static silc_spmd_opener spmd_opener;

void silc_set_spmd_opener(silc_spmd_opener open)
{
    spmd_opener = open;
}

int silc_context_rank(const silc_context *ctx, int *rank, int *size)
{
    if (!ctx) return env_error("silc_context_rank: NULL context");
    if (rank) *rank = ctx->E ? dist_rank(ctx->E) : 0;
    if (size) *size = ctx->E ? dist_size(ctx->E) : 1;
    return 0;
}

/* SPMD contexts: every call is collective.  Checks that all ranks make the
 * same call (what, text), then agrees on this rank's local verdict rc (with
 * its message in ctx->err), so that all ranks go on or all fail. */
static int spmd_enter(silc_context *ctx, const char *what, const char *text, int rc)
{
    silc_engine *E = ctx->E;
    if (!E || !E->dist) return rc;
    if (rc) snprintf(E->err, sizeof E->err, "%s", ctx->err);
    if (dist_check_call(E, what, rc ? "" : text)) {
        /* The mismatch outranks a local error: it is what went wrong first. */
        snprintf(ctx->err, sizeof ctx->err, "%s", E->err);
        return -1;
    }
    if (dist_agree(E, rc)) {
        snprintf(ctx->err, sizeof ctx->err, "%s", E->err);
        return -1;
    }
    return 0;
}

void silc_close(silc_context **pctx)
{
    if (!pctx || !*pctx) return;
    eng_destroy(&(*pctx)->E);
    rem_close(&(*pctx)->R);
    sb_free(&(*pctx)->warnings);
    free(*pctx);
    *pctx = NULL;
}

/* The result of an operation that wrote its message to ctx->err. */
static int ctx_result(silc_context *ctx, int rc)
{
    if (rc && ctx == default_ctx) env_error_forget();
    return rc ? -1 : 0;
}

int silc_put(silc_context *ctx, const char *name, const silc_envelope_t *e)
{
    silc_value *v;
    char err[1024];
    int rc;
    if (!ctx) return env_error("silc_put: NULL context");
    if (!name) return ctx_error(ctx, "silc_put: NULL name");
    if (!e) return ctx_error(ctx, "silc_put: NULL envelope for '%s'", name);
    if (api_check_name(name, ctx->err, sizeof ctx->err)) return ctx_result(ctx, -1);
    if (env_not_constructed(e, err, sizeof err))
        return ctx_error(ctx, "envelope '%s' was not constructed: %s", name, err);
    if (ctx->R) {
        /* The same checks as embedded, before anything is sent. */
        if (env_check(e, err, sizeof err)) return ctx_error(ctx, "'%s': %s", name, err);
        return ctx_result(ctx, rem_put(ctx->R, name, e, ctx->err, sizeof ctx->err));
    }
    if (!ctx->E->dist && env_same_as_value(e, store_get(&ctx->E->store, name))) {
        /* What the name holds already: keep it, as api_bind would after a
         * copy and a comparison; this is the comparison alone. */
        eng_info_remove(ctx->E, name);
        return ctx_result(ctx, 0);
    }
    rc = env_to_value(e, &v, err, sizeof err);
    if (rc) ctx_error(ctx, "'%s': %s", name, err);
    if (spmd_enter(ctx, "PUT", name, rc)) {
        if (!rc) val_release(v);
        return ctx_result(ctx, -1);
    }
    rc = api_bind(ctx->E, name, v, ctx->err, sizeof ctx->err);
    val_release(v);
    return ctx_result(ctx, rc);
}

int silc_put_rows(silc_context *ctx, const char *name, int64_t first_row, const silc_envelope_t *e)
{
    silc_value *v = NULL;
    char err[1024];
    int rc = 0;
    if (!ctx) return env_error("silc_put_rows: NULL context");
    if (!name) rc = ctx_error(ctx, "silc_put_rows: NULL name");
    else if (!e) rc = ctx_error(ctx, "silc_put_rows: NULL envelope for '%s'", name);
    else if (api_check_name(name, ctx->err, sizeof ctx->err)) rc = -1;
    else if (env_not_constructed(e, err, sizeof err))
        rc = ctx_error(ctx, "envelope '%s' was not constructed: %s", name, err);
    else if (first_row < 0) rc = ctx_error(ctx, "silc_put_rows '%s': first row %lld is negative", name, (long long)first_row);
    else if (env_to_value(e, &v, err, sizeof err)) rc = ctx_error(ctx, "'%s': %s", name, err);
    if (!ctx->E || !ctx->E->dist) {
        /* One process: the block is the whole value. */
        if (!rc && (first_row != 0))
            rc = ctx_error(ctx, "silc_put_rows '%s': rows start at %lld, but on one process the block "
                                "is the whole value (first row 0)", name, (long long)first_row);
        if (!rc && ctx->R) {
            val_release(v);
            return silc_put(ctx, name, e);
        }
        if (!rc) rc = api_bind(ctx->E, name, v, ctx->err, sizeof ctx->err);
        val_release(v);
        return ctx_result(ctx, rc);
    }
    if (spmd_enter(ctx, "PUT_ROWS", name ? name : "", rc)) {
        val_release(v);
        return ctx_result(ctx, -1);
    }
    if (dist_put_rows(ctx->E, name, first_row, v)) {
        snprintf(ctx->err, sizeof ctx->err, "%s", ctx->E->err);
        return ctx_result(ctx, -1);
    }
    return 0;
}

/* silcd answers a GET of a complex value with the refusal that names
 * silc_get_complex, the call behind a GET; silc_get_rows sends the same
 * GET, so its caller is pointed to its own call (complex_getter), as the
 * embedded refusal does.  Any other message is left as it came. */
static void name_complex_getter(silc_context *ctx, const char *name, const char *complex_getter)
{
    char server_text[sizeof ctx->err];
    if (!strcmp(complex_getter, "silc_get_complex")) return;
    env_complex_refusal(name, "silc_get_complex", server_text, sizeof server_text);
    if (!strcmp(ctx->err, server_text)) env_complex_refusal(name, complex_getter, ctx->err, sizeof ctx->err);
}

/* silc_get and silc_get_complex (and silc_get_rows on a remote context): a
 * caller that did not ask for complex values gets none (silc.h), and the
 * refusal names complex_getter, the call that would fetch it. */
static int get_value(silc_context *ctx, silc_envelope_t *e, const char *name, int accept_complex,
                     const char *complex_getter)
{
    const silc_value *v;
    const char *fn = accept_complex ? "silc_get_complex" : "silc_get";
    if (e) memset(e, 0, sizeof *e);
    if (!ctx) return env_error("%s: NULL context", fn);
    if (!e) return ctx_error(ctx, "%s: NULL envelope", fn);
    if (!name) return ctx_error(ctx, "%s: NULL name", fn);
    if (ctx->R) {
        if (!rem_get(ctx->R, e, name, accept_complex, ctx->err, sizeof ctx->err)) return 0;
        if (!accept_complex) name_complex_getter(ctx, name, complex_getter);
        return ctx_result(ctx, -1);
    }
    v = api_lookup(ctx->E, name, ctx->err, sizeof ctx->err);
    if (v && !accept_complex && env_refuse_complex(name, v, complex_getter, ctx->err, sizeof ctx->err)) v = NULL;
    if (spmd_enter(ctx, "GET", name, v ? 0 : -1)) return ctx_result(ctx, -1);
    if (dist_is(v) && !(v = dist_whole(ctx->E, v, 1))) { /* every rank gets the whole value */
        snprintf(ctx->err, sizeof ctx->err, "%s", ctx->E->err);
        return ctx_result(ctx, -1);
    }
    if (env_from_value(v, e))
        return ctx_error(ctx, "out of memory copying '%s' (%lldx%lld %s)", name, (long long)v->m,
                         (long long)v->n, val_format_name(v->format));
    return 0;
}

int silc_get(silc_context *ctx, silc_envelope_t *e, const char *name)
{
    return get_value(ctx, e, name, 0, "silc_get_complex");
}

int silc_get_complex(silc_context *ctx, silc_envelope_t *e, const char *name)
{
    return get_value(ctx, e, name, 1, "silc_get_complex");
}

/* silc_get_rows and silc_get_rows_complex: as get_value, a caller that did
 * not ask for complex values gets none; on a remote context (one process)
 * the block is the whole value. */
static int get_rows(silc_context *ctx, silc_envelope_t *e, int64_t *first_row, const char *name,
                    int accept_complex)
{
    const silc_value *v = NULL;
    silc_value *blk = NULL;
    const char *fn = accept_complex ? "silc_get_rows_complex" : "silc_get_rows";
    int64_t first = 0;
    int rc = 0;
    if (e) memset(e, 0, sizeof *e);
    if (first_row) *first_row = 0;
    if (!ctx) return env_error("%s: NULL context", fn);
    if (!e) rc = ctx_error(ctx, "%s: NULL envelope", fn);
    else if (!name) rc = ctx_error(ctx, "%s: NULL name", fn);
    if (ctx->R)
        return rc ? ctx_result(ctx, rc) : get_value(ctx, e, name, accept_complex, "silc_get_rows_complex");
    if (!rc && !(v = api_lookup(ctx->E, name, ctx->err, sizeof ctx->err))) rc = -1;
    if (!rc && !accept_complex && env_refuse_complex(name, v, "silc_get_rows_complex", ctx->err, sizeof ctx->err))
        rc = -1;
    if (spmd_enter(ctx, "GET_ROWS", name ? name : "", rc)) return ctx_result(ctx, -1);
    if (dist_rows_of(ctx->E, v, &blk, &first)) {
        snprintf(ctx->err, sizeof ctx->err, "%s", ctx->E->err);
        return ctx_result(ctx, -1);
    }
    rc = env_from_value(blk, e);
    val_release(blk);
    if (ctx->E->dist && dist_agree(ctx->E, rc ? (snprintf(ctx->E->err, sizeof ctx->E->err, "out of memory copying '%s'", name), -1) : 0)) {
        snprintf(ctx->err, sizeof ctx->err, "%s", ctx->E->err);
        silc_envelope_free(e);
        return ctx_result(ctx, -1);
    }
    if (rc) return ctx_error(ctx, "out of memory copying '%s'", name);
    if (first_row) *first_row = first;
    return 0;
}

int silc_get_rows(silc_context *ctx, silc_envelope_t *e, int64_t *first_row, const char *name)
{
    return get_rows(ctx, e, first_row, name, 0);
}

int silc_get_rows_complex(silc_context *ctx, silc_envelope_t *e, int64_t *first_row, const char *name)
{
    return get_rows(ctx, e, first_row, name, 1);
}

int silc_exec(silc_context *ctx, const char *statements)
{
    if (!ctx) return env_error("silc_exec: NULL context");
    if (ctx->R) {
        ctx->warnings.len = 0;
        if (ctx->warnings.s) ctx->warnings.s[0] = '\0';
    } else {
        ctx->E->warnings.len = 0;
        if (ctx->E->warnings.s) ctx->E->warnings.s[0] = '\0';
    }
    if (!statements) return ctx_error(ctx, "silc_exec: NULL statements");
    if (ctx->R)
        return ctx_result(ctx, rem_exec(ctx->R, statements, ctx->output, ctx->output_user,
                                        &ctx->warnings, ctx->err, sizeof ctx->err));
    if (spmd_enter(ctx, "EXEC", statements, 0)) return ctx_result(ctx, -1);
    return ctx_result(ctx, api_exec(ctx->E, statements, ctx->err, sizeof ctx->err));
}

/* Touches only the engine's atomic flag or writes one frame (rem_cancel),
 * so it may run in a signal handler or another thread. */
int silc_cancel(silc_context *ctx)
{
    if (!ctx) return -1;
    if (ctx->E) {
        eng_interrupt(ctx->E);
        return 0;
    }
    return rem_cancel(ctx->R);
}

/* save / load as a statement, so that embedded and remote contexts do the
 * same (the engine's h5io.c). */
static int save_or_load(silc_context *ctx, const char *word, const char *path, const char *names)
{
    char *stmt;
    size_t len;
    int rc;
    if (!ctx) return env_error("silc_%s: NULL context", word);
    if (!path || !*path || strpbrk(path, "\"\n"))
        return ctx_error(ctx, "silc_%s: the file name must be non-empty, without '\"' or a newline", word);
    if (names && strpbrk(names, "\";\n"))
        return ctx_error(ctx, "silc_%s: names must be names separated by spaces", word);
    len = strlen(word) + strlen(path) + (names ? strlen(names) : 0) + 8;
    if (!(stmt = malloc(len))) return ctx_error(ctx, "silc_%s: out of memory", word);
    snprintf(stmt, len, "%s \"%s\" %s", word, path, names ? names : "");
    rc = silc_exec(ctx, stmt);
    free(stmt);
    return rc;
}

int silc_save(silc_context *ctx, const char *path, const char *names)
{
    return save_or_load(ctx, "save", path, names);
}

int silc_load(silc_context *ctx, const char *path, const char *names)
{
    return save_or_load(ctx, "load", path, names);
}

const char *silc_context_errmsg(const silc_context *ctx)
{
    if (!ctx) {
        const char *m = env_error_last();
        return m ? m : "";
    }
    return ctx->err;
}

const char *silc_context_warnings(const silc_context *ctx)
{
    if (!ctx) return "";
    return sb_str(ctx->R ? &ctx->warnings : &ctx->E->warnings);
}

void silc_set_output(silc_context *ctx, silc_output_fn fn, void *user)
{
    if (!ctx) return;
    if (ctx->R) {
        ctx->output = fn;
        ctx->output_user = fn ? user : NULL;
        return;
    }
    ctx->E->output = fn;
    ctx->E->output_user = fn ? user : NULL;
}

/* ---- the default context --------------------------------------------------- */

static const char not_initialised[] = "SILC_INIT has not been called";

int SILC_INIT(void)
{
    const char *mode = getenv("SILC_MODE");
    if (default_ctx) return ctx_error(default_ctx, "SILC_INIT: already initialised");
    if (mode && !strcmp(mode, "spmd")) {
        if (!spmd_opener)
            return env_error("SILC_MODE=spmd needs the program linked with libsilc_mpi "
                             "(-lsilc_mpi): this one is not");
        return spmd_opener(&default_ctx, NULL);
    }
    if (mode && *mode && strcmp(mode, "embedded") && strcmp(mode, "remote"))
        return env_error("SILC_MODE='%s' is not a mode: embedded (default), remote (with SILC_SERVER) "
                         "or spmd (an MPI program)", mode);
    return silc_open(&default_ctx, NULL);
}

int SILC_FINALIZE(void)
{
    if (!default_ctx) return env_error("%s", not_initialised);
    silc_close(&default_ctx);
    return 0;
}

int SILC_PUT(const char *name, const silc_envelope_t *e)
{
    if (!default_ctx) return env_error("%s", not_initialised);
    return silc_put(default_ctx, name, e);
}

int SILC_GET(silc_envelope_t *e, const char *name)
{
    if (!default_ctx) {
        if (e) memset(e, 0, sizeof *e);
        return env_error("%s", not_initialised);
    }
    return silc_get(default_ctx, e, name);
}

int SILC_EXEC(const char *statements)
{
    if (!default_ctx) return env_error("%s", not_initialised);
    return silc_exec(default_ctx, statements);
}

const char *silc_errmsg(void)
{
    const char *m = env_error_last();
    if (m) return m;
    return default_ctx ? default_ctx->err : "";
}

const char *silc_warnings(void)
{
    return silc_context_warnings(default_ctx);
}

silc_context *silc_default_context(void)
{
    return default_ctx;
}
