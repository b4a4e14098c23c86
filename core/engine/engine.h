/*
 * engine.h -- the embedded engine behind a context, assembled from the
 * layers (docs/architecture.md): creation and destruction.  The client
 * (api.c) and silcd hold an engine through these, and run statements with
 * lang_exec (lang.h).
 *
 * Who owns what:
 *   engine/    create (store, options, plugins, configuration file), destroy
 *   context/   struct silc_engine, errors, warnings, output, info records
 *   lang/      lexer, parser, AST cache, evaluator (lang.h)
 *   tune/      the tuner (tune.h)
 *   dispatch/  options, plugins, host API, dispatch (dispatch.h)
 *   accuracy/  backward error, refinement, scaling (accuracy.h)
 *   dist/      values distributed over ranks (dist.h)
 * The evaluator never calls a plugin directly: it fills a silc_call and hands it
 * to disp_run().
 */
#ifndef SILC_ENGINE_H
#define SILC_ENGINE_H

#include "context.h"

/* config_path NULL: SILC_CONFIG, else ./silc.conf if present, else defaults. */
int eng_create(silc_engine **out, const char *config_path, char *err, size_t errlen);
/* As eng_create, on every rank of comm (taken over, also on failure): an
 * SPMD engine (dist.h).  Collective. */
struct silc_comm_ops;
int eng_create_comm(silc_engine **out, const char *config_path, struct silc_comm_ops *comm, char *err,
                    size_t errlen);
void eng_destroy(silc_engine **E);
/* Opens every plugin the engine found now instead of at first use (silcd's
 * parent, so that sessions inherit them by fork). */
void eng_open_plugins(silc_engine *E);
#endif
