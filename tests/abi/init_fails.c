/* init_fails.c -- a plugin whose init fails (its library is missing): the
 * loader must refuse it and show the plugin's own message. */
#define FIX_NAME "init_fails"
#define FIX_INIT_FAILS "libfoo not found"
#include "fixture.h"
