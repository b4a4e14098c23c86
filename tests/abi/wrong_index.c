/* wrong_index.c -- a plugin claiming 4-byte CSR indices: the loader must refuse it. */
#define FIX_NAME "wrong_index"
#define FIX_INDEX_BYTES 4
#include "fixture.h"
