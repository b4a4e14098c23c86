/* wrong_major.c -- a plugin built for ABI major 2: the loader must refuse it. */
#define FIX_NAME "wrong_major"
#define FIX_MAJOR 2
#include "fixture.h"
