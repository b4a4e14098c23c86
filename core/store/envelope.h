/*
 * envelope.h -- the bridge between public envelopes (silc.h) and engine
 * values (value.h), and the message buffer of calls that have no context.
 *
 * Envelope constructors and silc_mm_read/write run without a context, so
 * their failure messages go to a per-thread buffer.  silc_errmsg() shows that
 * message until a later failure on the default context supersedes it (the API
 * calls env_error_forget() when it records one).
 */
#ifndef SILC_ENVELOPE_H
#define SILC_ENVELOPE_H

#include "silc.h"
#include "value.h"

/* Validates an envelope without copying it (the checks env_to_value makes):
 * used by the remote client before sending and by silcd on what it received,
 * so both report exactly the embedded messages. */
int env_check(const silc_envelope_t *e, char *err, size_t errlen);
/* Copies an envelope into a new value (refcount 1), validating it first:
 * shapes, array presence, CSR rowptr/colind consistency and sorted,
 * duplicate-free rows.  On failure writes the reason to err. */
int env_to_value(const silc_envelope_t *e, silc_value **out, char *err, size_t errlen);
/* The CSR part of env_to_value for a value made for e's rowptr[m] entries:
 * checks and fills it from e's arrays (which may be the value's own), with
 * the value's shape computed on the way (val_csr_fill_checked).  0, or -1
 * with the reason in err. */
int env_csr_fill(silc_value *v, const silc_envelope_t *e, char *err, size_t errlen);
/* 1 when e holds exactly v's format, shape, pattern and value bits: then a
 * PUT of e to the name holding v need copy nothing (silc_put).  Reads no
 * array of e beyond what v's shape says a valid e has; 0 for anything that
 * is not such an e. */
int env_same_as_value(const silc_envelope_t *e, const silc_value *v);
/* Copies a value into a freshly built envelope of the same format. */
int env_from_value(const silc_value *v, silc_envelope_t *e);

/* Records a context-free failure message; returns -1. */
int env_error(const char *fmt, ...)
#if defined(__GNUC__)
    __attribute__((format(printf, 1, 2)))
#endif
    ;
/* The context-free message of this thread if it is the latest failure, else NULL. */
const char *env_error_last(void);
void env_error_forget(void);

#endif
