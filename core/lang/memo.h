/*
 * memo.h -- repeated operations on unchanged operands return the value they
 * gave before (memo.c says when and why).  Internal to the engine.
 */
#ifndef SILC_MEMO_H
#define SILC_MEMO_H

#include "context.h"

/* The value call gave the last time it ran on these operands (retained), or NULL. */
silc_value *memo_lookup(silc_engine *E, const silc_call *call);
/* After call ran and gave result: remember it (warned: the call warned, so
 * it is never handed out).  Failing to remember loses nothing. */
void memo_note(silc_engine *E, const silc_call *call, silc_value *result, int warned);
/* At the engine's end. */
void memo_free(silc_engine *E);

#endif
