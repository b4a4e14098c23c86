/*
 * fixture.h -- shared body of the purpose-made plugins of the ABI tests.
 *
 * Each test plugin (wrong_major.c, wrong_index.c, ...) defines the fields it
 * gets wrong and includes this file, which supplies a working SCALE operation
 * and the plugin table built from those fields, so every plugin differs from
 * a good one in exactly the defect it is named after.
 */
#include "silc_plugin.h"

#ifndef FIX_NAME
#define FIX_NAME "good"
#endif
#ifndef FIX_MAJOR
#define FIX_MAJOR SILC_ABI_MAJOR
#endif
#ifndef FIX_MINOR
#define FIX_MINOR SILC_ABI_MINOR
#endif
#ifndef FIX_STRUCT_SIZE
#define FIX_STRUCT_SIZE sizeof(silc_plugin)
#endif
#ifndef FIX_COMPLEX_OPS
#define FIX_COMPLEX_OPS 0
#endif
#ifndef FIX_INDEX_BYTES
#define FIX_INDEX_BYTES ((int)sizeof(silc_index))
#endif

static const silc_host_api *fix_host;

#ifndef FIX_NO_OPS
#ifdef FIX_TAKES_COMPLEX
/* A complex A (ABI 1.8): out = (alpha + i alpha_imag) A + 2, its own
 * signature. */
static int fix_scale_complex(silc_call *call, const silc_view *a)
{
    silc_value *out = fix_host->dense_new_complex(a->m, a->n);
    silc_view o;
    int64_t i;
    if (!out) return fix_host->error(call, SILC_ENOMEM, "out of memory");
    fix_host->view(out, &o);
    for (i = 0; i < a->m * a->n; i++) {
        double re = a->val[2 * i], im = a->val[2 * i + 1];
        o.val[2 * i] = call->alpha * re - call->alpha_imag * im + 2;
        o.val[2 * i + 1] = call->alpha * im + call->alpha_imag * re;
    }
    call->out = out;
    return SILC_OK;
}
#endif

/* out = alpha * A + 1, so a test can tell this plugin ran and not another. */
static int fix_scale(silc_call *call)
{
    silc_view a, o;
    silc_value *out;
    int64_t i;
    fix_host->view(call->in[0], &a);
    /* The host must never hand complex data to a fixture that does not
     * list SCALE in complex_ops (test_complex_core): say so loudly. */
    if (fix_host->abi_minor >= 8 && fix_host->field(call->in[0]) == SILC_FIELD_COMPLEX) {
#ifdef FIX_TAKES_COMPLEX
        if (a.format == SILC_FMT_DENSE) return fix_scale_complex(call, &a);
#else
        return fix_host->error(call, SILC_EINTERNAL, "%s was handed complex data", FIX_NAME);
#endif
    }
    if (a.format != SILC_FMT_DENSE) return fix_host->error(call, SILC_EDECLINE, "dense only");
    out = fix_host->dense_new(a.m, a.n);
    if (!out) return fix_host->error(call, SILC_ENOMEM, "out of memory");
    fix_host->view(out, &o);
    for (i = 0; i < a.m * a.n; i++) o.val[i] = call->alpha * a.val[i] + 1;
    call->out = out;
    return SILC_OK;
}
#endif

#ifdef FIX_NO_OPS
static const silc_op_entry fix_ops[SILC_OP_COUNT] = {{0, 0}};
#else
static const silc_op_entry fix_ops[SILC_OP_COUNT] = {[SILC_OP_SCALE] = {fix_scale, 0}};
#endif

static const silc_backend fix_backends[] = {
    {0, "ABI test fixture", SILC_OP_COUNT, fix_ops},
};

static const silc_plugin fix_plugin = {
    FIX_MAJOR, FIX_MINOR, FIX_STRUCT_SIZE, FIX_INDEX_BYTES,
    FIX_NAME, "1.0", 1, fix_backends, 0, 0, 0, 0, 0, FIX_COMPLEX_OPS,
};

#ifndef FIX_NO_SYMBOL
SILC_PLUGIN_EXPORT int silc_plugin_init(const silc_host_api *h, const silc_plugin **out,
                                        const char **errmsg)
{
#ifdef FIX_INIT_FAILS
    (void)h;
    (void)out;
    (void)fix_plugin;
    *errmsg = FIX_INIT_FAILS;
    return 1;
#else
    (void)errmsg;
    fix_host = h;
    *out = &fix_plugin;
    return 0;
#endif
}
#endif
