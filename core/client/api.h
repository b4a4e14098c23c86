/*
 * api.h -- the embedded operations behind silc_put, silc_get and silc_exec,
 * shared by api.c (embedded contexts) and silcd (one engine per session), so
 * that a remote caller gets exactly the messages an embedded one gets.
 * Each returns 0 or -1 with the message in err.
 */
#ifndef SILC_API_H
#define SILC_API_H

#include <stddef.h>

#include "engine.h"

/* Names follow the language's identifiers, so every put value can be used. */
int api_check_name(const char *name, char *err, size_t errlen);
/* Binds v (retained) to name as data from the program. */
int api_bind(silc_engine *E, const char *name, silc_value *v, char *err, size_t errlen);
/* The value bound to name (borrowed), or NULL with "undefined name 'u' (did
 * you mean 'v'?)" in err. */
const silc_value *api_lookup(silc_engine *E, const char *name, char *err, size_t errlen);
/* Runs statements, warnings collected in E->warnings (cleared first). */
int api_exec(silc_engine *E, const char *statements, char *err, size_t errlen);

#endif
