/*
 * context.h -- the state of one engine that every layer reads and writes:
 * struct silc_engine (its store, and the opaque state of the layers above,
 * each owned by its folder), the error message, warnings and output of the
 * running exec, and the per-name records that `info` shows.
 *
 * This is the lowest layer that knows an engine (docs/architecture.md): the
 * dispatcher, the accuracy machinery, the distributed layer and the language
 * all report through eng_error / eng_warn, so these cannot live with the
 * engine's creation (engine/), which calls all of them.
 */
#ifndef SILC_CONTEXT_H
#define SILC_CONTEXT_H

#include <stdatomic.h>

#include "silc.h"
#include "silc_plugin.h"
#include "util.h"
#include "store.h"

typedef struct silc_engine silc_engine;
typedef struct cfg_db cfg_db;
typedef struct ld_set ld_set;
typedef struct eng_memo eng_memo;

/* The operands and result of a solve whose backward error or condition
 * estimate is deferred (accuracy.h: acc_pending_resolve computes the one,
 * dispatch.h: disp_condest_resolve the other, with the factorization still
 * attached to A, asked of the same backend under the same class and
 * options); all NULL when none is. */
typedef struct eng_pending {
    silc_value *A, *B, *X;
    const char *op_class;   /* the class the backend solved under (a static string) */
    int sub;
    char *options;          /* the call's option text (owned), NULL when none */
} eng_pending;

/* How a value bound to a name was last computed (`info x`). */
typedef struct eng_info {
    char *statement;        /* text of the statement that bound it */
    int has_solve;          /* the statement ran a solve: report is meaningful */
    silc_report report;     /* of the last solve in the statement */
    double seconds;         /* wall time of the whole statement */
    char backends[128];     /* backends that ran, comma separated, deduplicated */
    int ranks;              /* of an SPMD engine (dist.h), else 0 */
    uint64_t moved_matrix, moved_vector; /* bytes moved between ranks by the statement */
    eng_pending pending;    /* report.backward_error == ACC_DEFERRED: owned refs */
} eng_info;

typedef struct eng_info_entry {
    char *name;
    eng_info info;
    struct eng_info_entry *next;
} eng_info_entry;

struct silc_engine {
    silc_store store;
    cfg_db *cfg;
    ld_set *plugins;
    void *lang_cache;                   /* the parse cache, owned by lang/ (eval.c) */
    void (*lang_cache_free)(void *);
    eng_info_entry *infos;
    silc_output_fn output;              /* NULL = stdout */
    void *output_user;
    int threads;                        /* thread budget granted to plugins */
    int accuracy_defer;                 /* solves may defer their backward error
                                           (accuracy.h); set by the evaluator */
    const char *solve_again;            /* set by the evaluator around one solve whose A it
                                           expects to be solved with again (a loop that does
                                           not assign A, `tune on N`): why, for explain; NULL
                                           = a one-shot solve as far as it knows (dispatch.c:
                                           a factorization then pays from the first solve) */
    uint64_t rand_state;                /* rand() seed state */
    uint64_t loop_budget;               /* most `while` iterations one exec may run, 0 =
                                           unlimited (the default): an internal guard that
                                           the fuzzers set so `while 1 {}` ends; no option */
    void *tuner;                        /* tuner.c's state, NULL until needed; freed by tuner_free */
    struct dist_ctx *dist;              /* the communicator of an SPMD engine (dist.h), NULL = one process */
    struct eng_memo *memo;              /* repeated operations' results (lang.h: memo_lookup), NULL until needed */
    /* Asked between statements and at each iteration of an empty `while`
     * (eng_cancel_check): nonzero, with why filled, stops the running exec.
     * NULL = never (embedded).  silcd sets it to enforce its request time
     * limit and to stop a request whose client has gone. */
    int (*cancel)(void *user, char *why, size_t whylen);
    void *cancel_user;
    /* Set by eng_interrupt (silc_cancel: a signal handler or another
     * thread), cleared when an exec starts; asked wherever the hook is.
     * Lock-free, so setting it is async-signal-safe. */
    atomic_int interrupt;
    size_t max_statement_bytes;         /* longest statement text an exec parses, 0 = no cap */
    char err[4096];
    strbuf warnings;                    /* warnings of the current/last exec */
};

int eng_error(silc_engine *E, const char *fmt, ...)   /* sets E->err, returns -1 */
#if defined(__GNUC__)
    __attribute__((format(printf, 2, 3)))
#endif
    ;
/* A constructor returned NULL: reports the size refusal it left
 * (val_refusal) or "out of memory", and returns -1. */
int eng_oom(silc_engine *E);
void eng_print(silc_engine *E, const char *text);     /* to the output callback or stdout */
/* Records a warning of the running exec ("matrix is singular to working
 * precision ..."); the API clears them at each exec start and the CLI prints them
 * to stderr as "warning: ...". */
void eng_warn(silc_engine *E, const char *fmt, ...)
#if defined(__GNUC__)
    __attribute__((format(printf, 2, 3)))
#endif
    ;
/* 0 to go on; -1 with E->err set when the running exec must stop: it was
 * interrupted (eng_interrupt: "interrupted"), or the engine's cancel hook
 * asks (a request past its time limit, a client gone, a CANCEL frame). */
int eng_cancel_check(silc_engine *E);
/* The same question without touching E->err: 1 (why filled) or 0.  For a
 * plugin polling host->cancelled() and the dispatcher between backends. */
int eng_cancel_pending(silc_engine *E, char *why, size_t whylen);
/* Asks the running exec to stop at its next check; async-signal-safe and
 * callable from any thread.  eng_interrupt_clear (an exec's start) forgets
 * an earlier request. */
void eng_interrupt(silc_engine *E);
void eng_interrupt_clear(silc_engine *E);
/* The message of an interrupted statement. */
#define ENG_INTERRUPTED "interrupted"

/* The bindings, their `info` records and the rand() state, to put back when
 * a statement or request is undone: a request stopped by silcd's limits
 * (server/session.c) or a top-level loop or `if` that fails or is
 * interrupted (eval.c).  Cheap, since values are immutable: the names and
 * references to the values.  An update in place (eval.c) then copies the
 * value once, since the snapshot holds it too. */
typedef struct eng_binding {
    char *name;
    silc_value *value;          /* retained */
} eng_binding;
typedef struct eng_snapshot {
    size_t n;
    eng_binding *bindings;      /* sorted by name */
    eng_info_entry *infos;
    uint64_t rand_state;
} eng_snapshot;
/* 0, or -1 when out of memory (s is then empty). */
int eng_snapshot_take(const silc_engine *E, eng_snapshot *s);
/* Puts everything back as it was and consumes s.  Allocates only to bind
 * again a name that was cleared since: -1 if that ran out of memory. */
int eng_snapshot_restore(silc_engine *E, eng_snapshot *s);
void eng_snapshot_free(eng_snapshot *s);
/* Copies info; takes over its pending references (also on failure). */
int eng_info_set(silc_engine *E, const char *name, eng_info *info);
/* As eng_info_set, but takes over info->statement (malloc'd) too; allocates
 * nothing when name already has a record (see eng_info_make). */
int eng_info_take(silc_engine *E, const char *name, eng_info *info);
/* name's record, made (empty) when it has none; NULL, with the engine's
 * error set, when out of memory.  A binding fills it in place (eval.c's
 * bind); a change that cannot be undone (an update in place) makes it
 * beforehand, so that the binding after it allocates nothing. */
eng_info *eng_info_make(silc_engine *E, const char *name);
eng_info *eng_info_get(const silc_engine *E, const char *name);
void eng_info_remove(silc_engine *E, const char *name);
/* Every record, at the engine's end. */
void eng_info_free_all(silc_engine *E);

/* Holds call's operands and result (retained), class and options as the
 * deferred backward error or condition estimate of the statement's solve;
 * releases what p held before.  -1 when out of memory (p then empty). */
int eng_pending_hold(eng_pending *p, const silc_call *call);
/* Releases what p holds and empties it. */
void eng_pending_release(eng_pending *p);

#endif
