/*
 * dispatch.h -- from an operation to the backend that runs it: the options
 * database, the plugins, the host API handed to them and the dispatcher.
 *
 *   config.c    options database: config file (inih), `set`, per-call options;
 *               key validation with "did you mean"; server vs session
 *               settings and a silcd session's files (cfg_serve)
 *   loader.c    plugins: built-in reference, dlopen(RTLD_NOW|RTLD_LOCAL) of the
 *               rest, ABI checks, backend look-up by full name
 *   host.c      the silc_host_api table handed to plugins
 *   dispatch.c  operation class -> ordered backend list -> first that accepts;
 *               fallbacks; accuracy report of every solve; `explain` text
 *
 * Below it are the accuracy machinery (accuracy.h) and the distributed layer
 * (dist.h), which it calls; the plugins call back up only through the host
 * API table.
 */
#ifndef SILC_DISPATCH_H
#define SILC_DISPATCH_H

#include "context.h"

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
/* A number that changes with every change of any setting, in any scope (a
 * `set`, a file, per-call options set or cleared): what a cache of things
 * derived from settings compares to stay fresh. */
uint64_t cfg_generation(const silc_engine *E);
/* The dispatcher's cache (dispatch.c: resolved backend lists), kept with
 * the options database and freed with it: bytes zeroed on the first call,
 * the same block after; NULL when out of memory (then nothing is cached). */
void *cfg_derived(const silc_engine *E, size_t bytes);
/* Appends every key SILC knows here (the settings table, each dispatch
 * class, each loaded plugin's options) with the value in force and where it
 * came from -- default, FILE:LINE, session, call -- to b (`set`). */
void cfg_list(const silc_engine *E, strbuf *b);
/* One key's line of that listing (`set KEY`), and with describe set what it
 * does and its default first (`help KEY`).  An unknown key: -1 with E->err
 * naming the nearest real key. */
int cfg_show_key(silc_engine *E, const char *key, strbuf *b, int describe);
/* A loaded plugin's backends and options with their types, defaults and
 * help, from its own option table (`help mumps`); -1 if no such plugin. */
int cfg_describe_plugin(const silc_engine *E, const char *name, strbuf *b);
/* The names of every plugin the engine can load, on one line after a
 * heading that points to `help PLUGIN` (the end of a bare `help`). */
void cfg_list_plugins(const silc_engine *E, strbuf *b);
/* The built-in backend list of a dispatch class ("reference" for most). */
const char *disp_default_list(const char *cls);
/* Appends the table of server and session settings (for `help set`). */
void cfg_describe_keys(strbuf *b);

/* Makes E a silcd session's engine (docs/security.md): from now on `set` and
 * per-call options may not change a server setting, free-form plugin option
 * strings are sanitized, and the files statements name resolve beneath
 * data_dir/session-<session_id> (created 0700), or data_dir itself when
 * shared; data_dir NULL refuses every file statement.  Call it after the
 * config file was read. */
int cfg_serve(silc_engine *E, const char *data_dir, int shared, unsigned long session_id);
/* 0 embedded, 1 a silcd session that keeps no files, 2 one that does. */
int cfg_serving(const silc_engine *E);

/* A file a statement reads or writes: its folder, its name there, and the
 * open file (read) or the temporary being written (write). */
typedef struct cfg_file {
    int dirfd, fd;
    char leaf[256];
    char tmp[300];   /* the temporary's name while one exists, else "" */
} cfg_file;
/* path opened for reading (a regular file, not a symbolic link): beneath
 * the session's folder in silcd, as the operating system resolves it when
 * embedded.  what ("load") starts every message.  -1 + E->err on refusal. */
int cfg_file_read(silc_engine *E, const char *what, const char *path, cfg_file *f);
/* A new temporary beside path (resolved as for cfg_file_read), created
 * O_EXCL | O_NOFOLLOW; f->fd is open for writing.  cfg_file_commit renames
 * it over path (a symbolic link there is replaced, not written through);
 * cfg_file_close alone discards it and leaves path as it was. */
int cfg_file_write(silc_engine *E, const char *what, const char *path, cfg_file *f);
/* As cfg_file_write, for a path the operator named (the wisdom file):
 * resolved as the operating system does, in silcd too. */
int cfg_file_write_operator(silc_engine *E, const char *what, const char *path, cfg_file *f);
int cfg_file_commit(silc_engine *E, const char *what, const char *path, cfg_file *f);
void cfg_file_close(cfg_file *f);

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
/* Finds every libsilc_plugin_*.so in the directories of a ':'-separated
 * list, to be opened when first needed (an engine on a communicator opens
 * them at once); refusals are logged as warnings, not errors. */
int ld_load_path(silc_engine *E, const char *dirs);
/* Opens every plugin found and not opened yet (lookups that list every
 * backend or plugin do it themselves). */
void ld_open_all(const silc_engine *E);
/* The plugin directory of the install this engine runs from (beside
 * libsilc.so, or beside the bindir of a program that links the engine), if
 * there is one: 0 and the path in out, else -1 (a build tree). */
int ld_installed_plugin_dir(char *out, size_t len);
/* The plugin directories no session can change, ':'-separated: the
 * installed one, or else the build tree's and the configured install
 * directory.  The engine loads plugins from them first; the HDF5 module
 * (lang/h5io.c) is opened from them only. */
void ld_fixed_plugin_dirs(char *out, size_t len);
const ld_backend *ld_find(const silc_engine *E, const char *full_name);
size_t ld_backend_names(const silc_engine *E, const char ***names); /* malloc'd array */
const ld_plugin *ld_find_plugin(const silc_engine *E, const char *plugin_name);
size_t ld_plugin_count(const silc_engine *E);
const ld_plugin *ld_plugin_at(const silc_engine *E, size_t i);
void ld_set_threads(silc_engine *E, int nthreads); /* every plugin's set_threads */
/* 1 when b's plugin lists op among b's collective_ops (ABI 1.5): b runs it
 * on the row blocks of every rank of an SPMD engine (dist.h). */
int ld_backend_collective(const ld_backend *b, int op);
/* 1 when b's plugin (ABI 1.8 or later) lists op among b's complex_ops: only
 * then does b get complex operands (silc_plugin.h). */
int ld_backend_takes_complex(const ld_backend *b, int op);
/* Names every backend may be configured with, loaded or not (for suggestions
 * and for telling "not installed" from "unknown"). */
extern const char *const ld_known_backends[];
/* Why this engine has no backend `name`: appends to b the directories it
 * searched for plugins and, when a file of name's plugin was found but
 * refused, the refusal. */
void ld_explain_missing(const silc_engine *E, const char *name, strbuf *b);

/* ---- dispatch.c: configured backends that must exist ------------------------ */
/* 0 when every backend the configuration's dispatch lists name is loaded,
 * or marked optional ("name?"); else -1 with E->err naming the key, the
 * backend, its plugin and where plugins were searched (engine.c calls it
 * once the configuration is read: an error at start, never a silent
 * substitute). */
int disp_check_configured(silc_engine *E);

/* ---- host.c ---------------------------------------------------------------- */
const silc_host_api *host_api(void);
/* SILC_OK, or SILC_EINTERNAL with the reason in the call's error when the
 * result the plugin returned breaks its own claim (val_check_value). */
int host_check_result(silc_call *call);
/* The thread budget host->threads() reports; set by ld_set_threads. */
void host_set_threads(int nthreads);
/* A copy of a solve's dense A that dispatch.c made in its shape pass
 * (val_shape_into), until a backend takes it (host->take_dense_copy) or
 * the call ends and dispatch.c frees it. */
typedef struct disp_dense_copy {
    const silc_value *of;
    double *array;                  /* val_array_alloc'd, as host->alloc's arrays */
} disp_dense_copy;
/* Per-call bookkeeping behind call->host_private. */
typedef struct host_call_ctx {
    silc_engine *E;
    const ld_backend *backend;      /* backend running the call (options prefix) */
    int status;
    int collective;                 /* runs on the row blocks of every rank (dist.h) */
    disp_dense_copy *copy;          /* NULL, or the solve's copy of A not taken yet */
    /* Last: a string, so a call's context zeroes what comes before it and
     * empties it (dispatch.c's walk; zeroing its 1 KB too wrote 17 cache
     * lines a call: docs/overhead.md, SpMV). */
    char err[1024];
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
/* report->condest_deferred as the host leaves it: 0 made at solve time (or
 * none), 1 owed (accuracy.condest = auto and costly: dispatch.c), and: */
#define DISP_CONDEST_READ 2   /* made when the report was read */
#define DISP_CONDEST_LOST 3   /* owed, but the factorization was gone when it was read */
/* Makes the estimate r owes (condest_deferred = 1) with the operands, class
 * and options p holds: backend r->backend's factorization still attached to
 * A, asked for the estimate alone; warns as a solve would.  It does not
 * factor again: with the factorization released (A's attachment evicted by
 * the memo's limit) r says DISP_CONDEST_LOST.  p is kept (the forward-error
 * bound needs its residual: acc_pending_resolve).  -1 (E->err) when out of
 * memory: still owed. */
int disp_condest_resolve(silc_engine *E, eng_pending *p, silc_report *r);
/* Why r's estimate was owed: "it costs N solves = X % of the factorization". */
void disp_condest_why(const silc_report *r, char *buf, size_t len);
/* Class chain of a call, most specific first, e.g. {"solve.sparse.spd",
 * "solve.sparse"}; returns the count (<= 4). */
int disp_classes(silc_engine *E, const silc_call *call, const char *out[4]);
/* Every class name that may appear in [dispatch] (for key validation). */
extern const char *const disp_class_names[];

#endif
