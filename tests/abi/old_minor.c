/* old_minor.c -- a plugin built against ABI 1.7: its table ends before
 * complex_ops, so the host must never hand it a complex value (its SCALE
 * fails loudly if it is; test_complex_core). */
#include <stddef.h>
#define FIX_NAME "old_minor"
#define FIX_MINOR 7
#define FIX_STRUCT_SIZE offsetof(silc_plugin, complex_ops)
#include "fixture.h"
