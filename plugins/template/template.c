/*
 * template.c -- a minimal SILC plugin to copy when writing a new backend.
 *
 * It provides one backend, "template", with one operation: SILC_OP_SCALE
 * (out = alpha * A) for dense values.  Everything a real plugin needs is here
 * in miniature: the exported init function with its ABI fields, an ops table
 * indexed by SILC_OP_*, an accepts-predicate that says why it declines, a
 * typed option read through the host, errors reported with host->error, and
 * a result built with host->dense_new and returned in call->out.
 *
 * Build it with silc_add_plugin(template SOURCES template.c) (hidden
 * visibility, -Wl,--no-undefined); select it with
 *   [dispatch]
 *   add = template
 * or for one call with the per-call option "backend = template".
 */
#include "silc_plugin.h"


/* The host table handed to init; valid until shutdown. */
static const silc_host_api *host;

static int scale_accepts(const silc_call *call, const char **why)
{
    silc_view a;
    host->view(call->in[0], &a);
    if (a.format != SILC_FMT_DENSE) {
        *why = "template handles dense values only";
        return 0;
    }
    return 1;
}

static int scale_run(silc_call *call)
{
    silc_view a, o;
    silc_value *out;
    int64_t i, verbose;
    int rc;
    /* Options are looked up per call: per-call options, then `set`, then the file. */
    rc = host->option_int(call, "verbose", 0, &verbose);
    if (rc) return rc;
    host->view(call->in[0], &a);
    if (a.format != SILC_FMT_DENSE) return SILC_EDECLINE;
    out = host->dense_new(a.m, a.n);
    if (!out) return host->error(call, SILC_ENOMEM, "template: cannot allocate %lldx%lld result",
                                 (long long)a.m, (long long)a.n);
    host->view(out, &o);
    for (i = 0; i < a.m * a.n; i++) o.val[i] = call->alpha * a.val[i];
    if (verbose) host->log(2, "template: scaled a %lldx%lld matrix", (long long)a.m, (long long)a.n);
    call->out = out;
    return SILC_OK;
}

static const silc_op_entry template_ops[SILC_OP_COUNT] = {
    [SILC_OP_SCALE] = {scale_run, scale_accepts},
};

static const silc_backend template_backends[] = {
    {NULL, "example backend: dense scaling", SILC_OP_COUNT, template_ops},
};

static const silc_option_spec template_options[] = {
    {"verbose", SILC_OPT_BOOL, "false", "log every call at info level"},
};

static const silc_plugin template_plugin = {
    SILC_ABI_MAJOR, SILC_ABI_MINOR, sizeof(silc_plugin), (int)sizeof(silc_index),
    "template", "0.1",
    1, template_backends,
    1, template_options,
    NULL, /* set_threads: single-threaded */
    NULL, /* shutdown: nothing to release */
    NULL, /* collective_ops: runs on one process only (ABI 1.5) */
    NULL, /* complex_ops: real values only (ABI 1.8) */
};

SILC_PLUGIN_EXPORT int silc_plugin_init(const silc_host_api *h, const silc_plugin **out,
                                        const char **errmsg)
{
    /* Refuse a host older than the fields this plugin uses. */
    if (silc_host_check(h, SILC_HOST_NEEDS(attach_set), errmsg) || !out) return 1;
    host = h;
    *out = &template_plugin;
    return 0;
}
