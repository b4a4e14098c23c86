/* no_ops.c -- a plugin whose only backend provides no operation at all. */
#define FIX_NAME "no_ops"
#define FIX_NO_OPS
#include "fixture.h"
