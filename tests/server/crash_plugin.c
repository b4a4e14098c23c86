/*
 * crash_plugin.c -- a plugin named "crash" whose SCALE misbehaves on
 * purpose, so the server tests can show that a session killed by a plugin
 * bug or a library abort loses only itself (tests/test_server.c) and that
 * a call caught in an endless computation is stopped by the limits
 * (tests/security/limits.py).  alpha = 13 calls abort(), as a third-party
 * library's failed assertion does; alpha = 11 writes through a null
 * pointer; alpha = 17 spins without ever asking the host (only silcd's
 * timer or kill can end it); alpha = 19 spins asking host->cancelled()
 * (ABI 1.7) and returns when told to stop; any other alpha computes
 * alpha * A.
 */
#include <signal.h>
#include <stdlib.h>

#include "silc_plugin.h"

static const silc_host_api *host;

static int crash_scale(silc_call *call)
{
    silc_view a, o;
    silc_value *out;
    volatile double sink = 0;
    int64_t i;
    if (call->alpha == 13) abort();
    if (call->alpha == 11) raise(SIGSEGV);
    if (call->alpha == 17)
        for (;;) sink += 1;
    if (call->alpha == 19) {
        while (!host->cancelled(call)) sink += 1;
        return host->error(call, SILC_ELIB, "crash: stopped on request");
    }
    host->view(call->in[0], &a);
    if (a.format != SILC_FMT_DENSE) return host->error(call, SILC_EDECLINE, "dense only");
    if (!(out = host->dense_new(a.m, a.n))) return host->error(call, SILC_ENOMEM, "out of memory");
    host->view(out, &o);
    for (i = 0; i < a.m * a.n; i++) o.val[i] = call->alpha * a.val[i];
    call->out = out;
    return SILC_OK;
}

static const silc_op_entry crash_ops[SILC_OP_COUNT] = {[SILC_OP_SCALE] = {crash_scale, 0}};

static const silc_backend crash_backends[] = {
    {0, "dies on alpha 13 (abort) and 11 (SIGSEGV); never returns on 17; on 19, until the host says stop", SILC_OP_COUNT, crash_ops},
};

static const silc_plugin crash_plugin = {
    SILC_ABI_MAJOR, SILC_ABI_MINOR, sizeof(silc_plugin), (int)sizeof(silc_index),
    "crash", "1.0", 1, crash_backends, 0, 0, 0, 0, 0, 0,
};

SILC_PLUGIN_EXPORT int silc_plugin_init(const silc_host_api *h, const silc_plugin **out,
                                        const char **errmsg)
{
    if (silc_host_check(h, SILC_HOST_NEEDS(cancelled), errmsg)) return 1;
    host = h;
    *out = &crash_plugin;
    return 0;
}
