/*
 * engine.h -- the embedded engine behind a context: store, options database,
 * loaded plugins, parse cache, per-name accuracy records, error and output.
 *
 * Modules and who owns what:
 *   engine.c    create/destroy, errors, output, info records
 *   config.c    options database: config file (inih), `set`, per-call options;
 *               key validation with "did you mean"
 *   loader.c    plugins: built-in reference, dlopen(RTLD_NOW|RTLD_LOCAL) of the
 *               rest, ABI checks, backend look-up by full name
 *   host.c      the silc_host_api table handed to plugins
 *   dispatch.c  operation class -> ordered backend list -> first that accepts;
 *               fallbacks; accuracy report of every solve; `explain` text
 *   lang: lexer.c, parser.c, eval.c -- lexer, parser, AST cache, evaluator (lang.h)
 * The evaluator never calls a plugin directly: it fills a silc_call and hands it
 * to disp_run().
 */
#ifndef SILC_ENGINE_H
#define SILC_ENGINE_H

#include "silc.h"
#include "silc_plugin.h"
#include "util.h"
#include "value.h"

typedef struct silc_engine silc_engine;
typedef struct cfg_db cfg_db;
typedef struct ld_set ld_set;
typedef struct eng_memo eng_memo;

/* The operands and result of a solve whose backward error is deferred
 * (accuracy.h); all NULL when none is. */
typedef struct acc_pending {
    silc_value *A, *B, *X;
} acc_pending;

/* How a value bound to a name was last computed (`info x`). */
typedef struct eng_info {
    char *statement;        /* text of the statement that bound it */
    int has_solve;          /* the statement ran a solve: report is meaningful */
    silc_report report;     /* of the last solve in the statement */
    double seconds;         /* wall time of the whole statement */
    char backends[128];     /* backends that ran, comma separated, deduplicated */
    int ranks;              /* of an SPMD engine (dist.h), else 0 */
    uint64_t moved_matrix, moved_vector; /* bytes moved between ranks by the statement */
    acc_pending pending;    /* report.backward_error == ACC_DEFERRED: owned refs */
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
    void *lang_cache;                   /* owned by lang.c */
    void (*lang_cache_free)(void *);
    eng_info_entry *infos;
    silc_output_fn output;              /* NULL = stdout */
    void *output_user;
    int threads;                        /* thread budget granted to plugins */
    int accuracy_defer;                 /* solves may defer their backward error
                                           (accuracy.h); set by the evaluator */
    uint64_t rand_state;                /* rand() seed state */
    uint64_t loop_budget;               /* most `while` iterations one exec may run, 0 =
                                           unlimited (the default): an internal guard that
                                           the fuzzers set so `while 1 {}` ends; no option */
    void *tuner;                        /* tuner.c's state, NULL until needed; freed by tuner_free */
    struct dist_ctx *dist;              /* the communicator of an SPMD engine (dist.h), NULL = one process */
    struct eng_memo *memo;              /* repeated operations' results (memo.h), NULL until needed */
    char err[4096];
    strbuf warnings;                    /* warnings of the current/last exec */
};

/* ---- engine.c -------------------------------------------------------------- */
/* config_path NULL: SILC_CONFIG, else ./silc.conf if present, else defaults. */
int eng_create(silc_engine **out, const char *config_path, char *err, size_t errlen);
/* As eng_create, on every rank of comm (taken over, also on failure): an
 * SPMD engine (dist.h).  Collective. */
struct silc_comm_ops;
int eng_create_comm(silc_engine **out, const char *config_path, struct silc_comm_ops *comm, char *err,
                    size_t errlen);
void eng_destroy(silc_engine **E);
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
/* Copies info; takes over its pending references (also on failure). */
int eng_info_set(silc_engine *E, const char *name, eng_info *info);
/* As eng_info_set, but takes over info->statement (malloc'd) too; allocates
 * nothing when name already has a record (see eng_info_reserve). */
int eng_info_take(silc_engine *E, const char *name, eng_info *info);
/* Makes sure name has a record, so that the next eng_info_take of name
 * cannot fail: for a change that cannot be undone (an update in place). */
int eng_info_reserve(silc_engine *E, const char *name);
eng_info *eng_info_get(const silc_engine *E, const char *name);
void eng_info_remove(silc_engine *E, const char *name);

/* ---- config.c -------------------------------------------------------------- */
enum cfg_scope { CFG_SCOPE_FILE = 0, CFG_SCOPE_SESSION = 1, CFG_SCOPE_CALL = 2 };
/* Keys: dispatch.<class> (comma list of backend names), <plugin>.<option>
 * (options the plugin lists), tune.threads, tune.accuracy, core.plugin_path,
 * core.threads.  Unknown keys, unknown backends and ill-typed values are
 * errors naming the closest valid key/backend. */
int cfg_create(silc_engine *E);
void cfg_destroy(silc_engine *E);
int cfg_load_file(silc_engine *E, const char *path);
int cfg_set(silc_engine *E, int scope, const char *key, const char *value);
/* Parses "key = value; key = value" (newlines or ';' separate) into the call
 * scope, replacing what was there.  "backend = NAME" is shorthand for forcing a
 * backend for this call. */
int cfg_set_call_options(silc_engine *E, const char *text);
void cfg_clear_call_options(silc_engine *E);
/* Value of key, the narrowest scope first; NULL if unset anywhere. */
const char *cfg_get(const silc_engine *E, const char *key);
/* Appends every set key with its value and scope to b (for `set` with no args). */
void cfg_list(const silc_engine *E, strbuf *b);

/* ---- loader.c -------------------------------------------------------------- */
typedef struct ld_backend {
    char *full_name;                /* "suitesparse.umfpack" */
    const silc_backend *backend;
    const struct ld_plugin *plugin;
} ld_backend;

typedef struct ld_plugin {
    const silc_plugin *table;
    void *handle;                   /* dlopen handle, NULL for built-in */
    char *path;
} ld_plugin;

int ld_create(silc_engine *E);                 /* registers the built-in reference plugin */
void ld_destroy(silc_engine *E);
/* Loads one plugin file.  On refusal returns non-zero with E->err naming the
 * file and the reason (wrong ABI major "plugin 2, host 1", index width, missing
 * symbol, init failure with the plugin's message, no ops at all). */
int ld_load_file(silc_engine *E, const char *path);
/* Loads every libsilc_plugin_*.so in the directories of a ':'-separated list;
 * refusals are logged as warnings, not errors. */
int ld_load_path(silc_engine *E, const char *dirs);
/* The plugin directory of the install this engine runs from (beside
 * libsilc.so, or beside the bindir of a program that links the engine), if
 * there is one: 0 and the path in out, else -1 (a build tree). */
int ld_installed_plugin_dir(char *out, size_t len);
const ld_backend *ld_find(const silc_engine *E, const char *full_name);
size_t ld_backend_names(const silc_engine *E, const char ***names); /* malloc'd array */
const ld_plugin *ld_find_plugin(const silc_engine *E, const char *plugin_name);
size_t ld_plugin_count(const silc_engine *E);
const ld_plugin *ld_plugin_at(const silc_engine *E, size_t i);
void ld_set_threads(silc_engine *E, int nthreads); /* every plugin's set_threads */
/* Names every backend may be configured with, loaded or not (for suggestions
 * and for telling "not installed" from "unknown"). */
extern const char *const ld_known_backends[];

/* ---- host.c ---------------------------------------------------------------- */
const silc_host_api *host_api(void);
/* The thread budget host->threads() reports; set by ld_set_threads. */
void host_set_threads(int nthreads);
/* Per-call bookkeeping behind call->host_private. */
typedef struct host_call_ctx {
    silc_engine *E;
    const ld_backend *backend;      /* backend running the call (options prefix) */
    char err[1024];
    int status;
    int collective;                 /* runs on the row blocks of every rank (dist.h) */
} host_call_ctx;

/* ---- dispatch.c ------------------------------------------------------------ */
/* Runs call: picks the backend by class and configuration, falls back on
 * SILC_EDECLINE / SILC_ENOTSPD, and for SOLVE fills call->report (backend, wall
 * time, backward error computed by the core).  On failure E->err holds
 * "<backend>: <message>" and call->out is NULL.  call->report may be NULL for
 * non-solve ops.  Returns 0 or the failing silc_status. */
int disp_run(silc_engine *E, silc_call *call);
/* Appends to b what disp_run would do for call and why, without running it. */
int disp_explain(silc_engine *E, const silc_call *call, strbuf *b);
/* Class chain of a call, most specific first, e.g. {"solve.sparse.spd",
 * "solve.sparse"}; returns the count (<= 4). */
int disp_classes(silc_engine *E, const silc_call *call, const char *out[4]);
/* Every class name that may appear in [dispatch] (for key validation). */
extern const char *const disp_class_names[];

/* ---- lang (lexer.c, parser.c, eval.c) -------------------------------------- */
/* Executes a statement list.  Statements run in order; the first failing one
 * stops the run, leaves the store as the earlier statements left it, and sets
 * E->err to "statement N: <message>" (N only when the text has several). */
int lang_exec(silc_engine *E, const char *text);

#endif
