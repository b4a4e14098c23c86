/*
 * api.c -- the public calls of silc.h: contexts, put/get/exec, and the
 * upper-case calls of the seeds on one default context.
 *
 * A context wraps an embedded engine today; the struct is the seam where a
 * remote transport will be added behind the same calls.  Each failure leaves
 * its message on the context (ctx->err); failures that have no context (a call
 * before SILC_INIT, a NULL context, an envelope constructor) leave it in the
 * per-thread buffer of envelope.c.  silc_errmsg() shows whichever is latest.
 */
#include "silc.h"

#include <ctype.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "engine.h"
#include "envelope.h"

struct silc_context {
    silc_engine *E;
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

int silc_open(silc_context **out, const char *config_path)
{
    silc_context *ctx;
    char err[4096];
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

void silc_close(silc_context **pctx)
{
    if (!pctx || !*pctx) return;
    eng_destroy(&(*pctx)->E);
    free(*pctx);
    *pctx = NULL;
}

/* Names follow the language's identifiers, so every put value can be used. */
static int valid_name(const char *s)
{
    if (!(isalpha((unsigned char)*s) || *s == '_')) return 0;
    for (s++; *s; s++)
        if (!(isalnum((unsigned char)*s) || *s == '_')) return 0;
    return 1;
}

int silc_put(silc_context *ctx, const char *name, const silc_envelope_t *e)
{
    silc_value *v;
    char err[1024];
    if (!ctx) return env_error("silc_put: NULL context");
    if (!name) return ctx_error(ctx, "silc_put: NULL name");
    if (!e) return ctx_error(ctx, "silc_put: NULL envelope for '%s'", name);
    if (!valid_name(name))
        return ctx_error(ctx, "invalid name '%s': names start with a letter or '_' and contain "
                              "only letters, digits and '_'", name);
    if (env_to_value(e, &v, err, sizeof err)) return ctx_error(ctx, "'%s': %s", name, err);
    if (store_set(&ctx->E->store, name, v)) {
        val_release(v);
        return ctx_error(ctx, "out of memory storing '%s'", name);
    }
    val_release(v);
    /* The name now holds data from the program, not a computed result. */
    eng_info_remove(ctx->E, name);
    return 0;
}

/* "undefined name 'u'" with the closest defined name, if one is close. */
static int undefined_name(silc_context *ctx, const char *name)
{
    const char **names = NULL;
    size_t n = store_names(&ctx->E->store, &names);
    const char *near = util_closest(name, names, n);
    int rc = near ? ctx_error(ctx, "undefined name '%s' (did you mean '%s'?)", name, near)
                  : ctx_error(ctx, "undefined name '%s'", name);
    free(names);
    return rc;
}

int silc_get(silc_context *ctx, silc_envelope_t *e, const char *name)
{
    const silc_value *v;
    if (e) memset(e, 0, sizeof *e);
    if (!ctx) return env_error("silc_get: NULL context");
    if (!e) return ctx_error(ctx, "silc_get: NULL envelope");
    if (!name) return ctx_error(ctx, "silc_get: NULL name");
    v = store_get(&ctx->E->store, name);
    if (!v) return undefined_name(ctx, name);
    if (env_from_value(v, e))
        return ctx_error(ctx, "out of memory copying '%s' (%lldx%lld %s)", name, (long long)v->m,
                         (long long)v->n, val_format_name(v->format));
    return 0;
}

int silc_exec(silc_context *ctx, const char *statements)
{
    silc_engine *E;
    if (!ctx) return env_error("silc_exec: NULL context");
    E = ctx->E;
    E->warnings.len = 0;
    if (E->warnings.s) E->warnings.s[0] = '\0';
    if (!statements) return ctx_error(ctx, "silc_exec: NULL statements");
    if (lang_exec(E, statements)) return ctx_error(ctx, "%s", E->err[0] ? E->err : "statement failed");
    return 0;
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
    return ctx ? sb_str(&ctx->E->warnings) : "";
}

void silc_set_output(silc_context *ctx, silc_output_fn fn, void *user)
{
    if (!ctx) return;
    ctx->E->output = fn;
    ctx->E->output_user = fn ? user : NULL;
}

/* ---- the default context --------------------------------------------------- */

static const char not_initialised[] = "SILC_INIT has not been called";

int SILC_INIT(void)
{
    if (default_ctx) return ctx_error(default_ctx, "SILC_INIT: already initialised");
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
