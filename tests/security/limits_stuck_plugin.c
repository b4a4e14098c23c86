/*
 * limits_stuck_plugin.c -- a plugin named "stuck" whose SCALE never
 * returns by itself, as a library caught in a long or endless computation:
 * the limit cases (tests/security/limits.py) stop it.  alpha = 17 spins
 * without ever asking the host (only silcd's timer or kill can end it);
 * alpha = 19 spins asking host->cancelled() (ABI 1.7) and returns when
 * told to stop; any other alpha computes alpha * A.
 */
#include <stddef.h>

#include "silc_plugin.h"

static const silc_host_api *host;

static int stuck_scale(silc_call *call)
{
    silc_view a, o;
    silc_value *out;
    volatile double sink = 0;
    int64_t i;
    if (call->alpha == 17)
        for (;;) sink += 1;
    if (call->alpha == 19) {
        while (!host->cancelled(call)) sink += 1;
        return host->error(call, SILC_ELIB, "stuck: stopped on request");
    }
    host->view(call->in[0], &a);
    if (a.format != SILC_FMT_DENSE) return host->error(call, SILC_EDECLINE, "dense only");
    if (!(out = host->dense_new(a.m, a.n))) return host->error(call, SILC_ENOMEM, "out of memory");
    host->view(out, &o);
    for (i = 0; i < a.m * a.n; i++) o.val[i] = call->alpha * a.val[i];
    call->out = out;
    return SILC_OK;
}

static const silc_op_entry stuck_ops[SILC_OP_COUNT] = {[SILC_OP_SCALE] = {stuck_scale, 0}};

static const silc_backend stuck_backends[] = {
    {0, "never returns on alpha 17; on 19, until the host says stop", SILC_OP_COUNT, stuck_ops},
};

static const silc_plugin stuck_plugin = {
    SILC_ABI_MAJOR, SILC_ABI_MINOR, sizeof(silc_plugin), (int)sizeof(silc_index),
    "stuck", "1.0", 1, stuck_backends, 0, 0, 0, 0, 0,
};

SILC_PLUGIN_EXPORT int silc_plugin_init(const silc_host_api *h, const silc_plugin **out,
                                        const char **errmsg)
{
    if (silc_host_check(h, SILC_HOST_NEEDS(cancelled), errmsg)) return 1;
    host = h;
    *out = &stuck_plugin;
    return 0;
}
