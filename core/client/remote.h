/*
 * remote.h -- the client transport of remote contexts: a connection to silcd
 * carrying the calls of silc.h as protocol frames (protocol.h).  Used only by
 * api.c, which keeps the context-level state (output callback, warnings,
 * message) and calls these for the wire.
 *
 * Each call returns 0, or -1 with the message in err: the server's own text
 * for a refused request (identical to the embedded message), or a transport
 * failure naming the server.  After a transport failure the connection is
 * dead and every later call says so.
 */
#ifndef SILC_REMOTE_H
#define SILC_REMOTE_H

#include <stddef.h>

#include "silc.h"
#include "util.h"

typedef struct rem_conn rem_conn;

/* url: tcp://host:port or unix:/path.  token may be NULL (none). */
int rem_open(rem_conn **out, const char *url, const char *token, char *err, size_t errlen);
void rem_close(rem_conn **c);               /* says BYE, then closes */
int rem_put(rem_conn *c, const char *name, const silc_envelope_t *e, char *err, size_t errlen);
int rem_get(rem_conn *c, silc_envelope_t *e, const char *name, char *err, size_t errlen);
/* EXEC: TEXT replies go to fn (stdout when NULL) as they come,
 * WARN replies are appended to warnings. */
int rem_exec(rem_conn *c, const char *statements, silc_output_fn fn, void *user,
             strbuf *warnings, char *err, size_t errlen);

#endif
