/* no_symbol.c -- a shared object without silc_plugin_init: not a plugin. */
#define FIX_NAME "no_symbol"
#define FIX_NO_SYMBOL
#include "fixture.h"

/* Something exported, so the module is a valid shared object. */
SILC_PLUGIN_EXPORT int silc_not_a_plugin(void)
{
    return fix_plugin.abi_major + (fix_host != 0);
}
