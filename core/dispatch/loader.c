/*
 * loader.c -- the plugins of one engine: the built-in reference plugin, and
 * shared objects found in configured directories.
 *
 * A plugin file is opened with dlopen(RTLD_NOW | RTLD_LOCAL) and nothing else:
 * RTLD_GLOBAL would put every library a plugin pulls in (Debian's sequential
 * MUMPS, PETSc's own MUMPS) into one global namespace where same-named symbols
 * cross-bind and crash.  RTLD_NOW makes a missing dependency a load-time error
 * with dlerror()'s text instead of a crash at first use.  Every table is
 * checked before the plugin is accepted (ABI major, index width, table size,
 * at least one operation) and a refused plugin is closed again, so nothing of
 * it stays in the process.
 *
 * Plugins are opened when first needed, not when their directory is read:
 * a directory listing only records the files (ld_pending), and the first
 * lookup of one of a file's backends (ld_find: a dispatch, a configured
 * backend list checked at start, a plugin's option set) opens that file,
 * found by its name (libsilc_plugin_NAME.so holds plugin NAME).  Opening
 * every plugin at start cost `silc -e 'x = 1'` 70-80 ms, mostly PETSc's and
 * MPI's libraries, whether the text needed them or not.  Whatever lists
 * all backends or plugins (help, the tuner, suggestions) opens every file
 * first, so it sees exactly what an eager load saw.  A file that cannot be
 * opened is warned about when it is first needed, once per process.
 *
 * An accepted plugin belongs to the process, not to the engine that loaded it:
 * it is opened and initialised once, shared by every context, and shut down at
 * exit, never dlclose'd.  Libraries behind plugins (MPI, PETSc, the Fortran
 * runtime under MUMPS, OpenMP) keep process-wide state and are not safe to
 * unload or to shut down while another context still uses them.
 */
#define _GNU_SOURCE /* realpath, dladdr */
#include "dispatch.h"

#include <dirent.h>
#include <sys/stat.h>
#include <dlfcn.h>
#include <errno.h>
#include <limits.h>
#include <pthread.h>
#include <stddef.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#if defined(__SANITIZE_ADDRESS__)
#include <sanitizer/lsan_interface.h>
#endif

/* The reference plugin is compiled into libsilc (plugin-reference/). */
extern int silc_reference_plugin_init(const silc_host_api *host, const silc_plugin **out,
                                      const char **errmsg);

const char *const ld_known_backends[] = {
    "reference", "lapack", "suitesparse.umfpack", "suitesparse.cholmod", "suitesparse.klu",
    "suitesparse.spqr", "mumps", "petsc", "lis-style", "template", NULL};

/* Every plugin the process has accepted, in load order. */
static struct {
    ld_plugin **items;
    size_t n;
    int exit_hook;
} g_loaded;
static pthread_mutex_t g_lock = PTHREAD_MUTEX_INITIALIZER;

/* A plugin file found in a directory and not opened yet. */
typedef struct ld_pending {
    char *path;
    char *name;                 /* NAME of libsilc_plugin_NAME.so */
} ld_pending;

struct ld_set {
    ld_plugin **plugins;        /* borrowed from g_loaded: backends point into them */
    size_t nplugins;
    ld_pending *pending;        /* in the order an eager load would have opened them */
    size_t npending, cappending;
    ld_backend **backends;
    size_t nbackends;
    strbuf searched;            /* the plugin directories tried, "a, b" (for errors) */
    strbuf refused;             /* "file: why\n" for each plugin file refused */
};

/* Plugin files already warned about in this process: a refused plugin is
 * reported once, not once per directory listing or engine that meets it. */
static strbuf g_warned;

static const ld_plugin *find_loaded_plugin(const silc_engine *E, const char *plugin_name);

#define LD_FILE_PREFIX "libsilc_plugin_"
#define LD_FILE_SUFFIX ".so"
#define LD_REFERENCE_FILE "libsilc_plugin_reference.so"

/* A table smaller than ABI 1.0's cannot be read safely; one absurdly large is
 * not a table at all. */
#define LD_MAX_STRUCT_SIZE ((size_t)1 << 16)

static char *full_name(const silc_plugin *pl, const silc_backend *b)
{
    size_t len = strlen(pl->name) + (b->name ? strlen(b->name) + 1 : 0) + 1;
    char *s = malloc(len);
    if (!s) return NULL;
    if (b->name) snprintf(s, len, "%s.%s", pl->name, b->name);
    else snprintf(s, len, "%s", pl->name);
    return s;
}

static int backend_has_ops(const silc_backend *b)
{
    int i;
    if (!b->ops || b->n_ops <= 0) return 0;
    for (i = 0; i < b->n_ops && i < SILC_OP_COUNT; i++)
        if (b->ops[i].run) return 1;
    return 0;
}

/* Checks a plugin's table; path is only for messages. */
static int check_table(silc_engine *E, const silc_plugin *pl, const char *path)
{
    const char *name;
    int i, any = 0;
    if (!pl) return eng_error(E, "plugin %s: silc_plugin_init returned no table", path);
    name = pl->name ? pl->name : "?";
    if (pl->abi_major != SILC_ABI_MAJOR)
        return eng_error(E, "plugin '%s' (%s) was built for ABI major %d, this host has %d", name,
                         path, pl->abi_major, SILC_ABI_MAJOR);
    if (pl->index_bytes != (int)sizeof(silc_index))
        return eng_error(E, "plugin '%s' (%s) uses %d-byte indices, host uses %d", name, path,
                         pl->index_bytes, (int)sizeof(silc_index));
    /* A 1.0 table ends at shutdown; later fields are read only when present. */
    if (pl->struct_size < offsetof(silc_plugin, collective_ops) || pl->struct_size > LD_MAX_STRUCT_SIZE)
        return eng_error(E, "plugin '%s' (%s) has a table of %zu bytes, ABI %d.0 needs at least %zu",
                         name, path, pl->struct_size, SILC_ABI_MAJOR, sizeof(silc_plugin));
    if (!pl->name || !pl->name[0] || strchr(pl->name, '.'))
        return eng_error(E, "plugin at %s has no valid name (non-empty, without '.')", path);
    if (pl->n_options < 0 || (pl->n_options > 0 && !pl->options))
        return eng_error(E, "plugin '%s' (%s) has an invalid option list", name, path);
    for (i = 0; i < pl->n_options; i++)
        if (!pl->options[i].key)
            return eng_error(E, "plugin '%s' (%s) lists an option without a name", name, path);
    if (pl->n_backends < 0 || (pl->n_backends > 0 && !pl->backends))
        return eng_error(E, "plugin '%s' (%s) has an invalid backend list", name, path);
    for (i = 0; i < pl->n_backends; i++)
        if (backend_has_ops(&pl->backends[i])) any = 1;
    if (!any) return eng_error(E, "plugin '%s' (%s) provides no operations", name, path);
    return 0;
}

/* Shuts every plugin down at exit, last loaded first, like destructors. */
static void shutdown_all(void)
{
    size_t i;
    pthread_mutex_lock(&g_lock);
    for (i = g_loaded.n; i-- > 0;) {
        ld_plugin *p = g_loaded.items[i];
        if (p->table->shutdown) p->table->shutdown();
        free(p->path);
        free(p);
    }
    free(g_loaded.items);
    g_loaded.items = NULL;
    g_loaded.n = 0;
    pthread_mutex_unlock(&g_lock);
}

#if defined(__SANITIZE_ADDRESS__)
/* AddressSanitizer builds check for leaks here, at the plugins' shutdown,
 * instead of at the very end of the process.  The libraries the plugins pull
 * in register exit handlers of their own when they are loaded (libstdc++'s
 * stream flush, GnuTLS under OpenMPI), and once those have touched their
 * thread-local storage, gcc 12's LeakSanitizer can misread the dynamic TLS
 * vector and crash in its tracer ("Tracer caught signal 11"), depending only
 * on how many TLS modules are loaded.  Registered after every new plugin, so
 * the last registration (which runs first) follows the last dlopen: the
 * check sees the process before any library's exit handler runs. */
static void shutdown_then_check_leaks(void)
{
    static int done;
    if (done) return;
    done = 1;
    shutdown_all();
    __lsan_do_leak_check();
}
#endif

/* The process-wide entry of an accepted plugin (caller holds g_lock). */
static ld_plugin *register_plugin(const silc_plugin *pl, void *handle, const char *path)
{
    ld_plugin *p, **np = realloc(g_loaded.items, (g_loaded.n + 1) * sizeof *np);
    if (!np) return NULL;
    g_loaded.items = np;
    p = calloc(1, sizeof *p);
    if (!p || !(p->path = util_strdup(path))) {
        free(p);
        return NULL;
    }
    p->table = pl;
    p->handle = handle;
    g_loaded.items[g_loaded.n++] = p;
    if (!g_loaded.exit_hook) g_loaded.exit_hook = atexit(shutdown_all) == 0;
    return p;
}

/* The accepted plugin loaded from this file or, for path NULL, the built-in
 * one (caller holds g_lock). */
static ld_plugin *registered(const char *path)
{
    size_t i;
    for (i = 0; i < g_loaded.n; i++) {
        ld_plugin *p = g_loaded.items[i];
        char other[PATH_MAX];
        if (!path ? !p->handle : p->handle && realpath(p->path, other) && strcmp(path, other) == 0)
            return p;
    }
    return NULL;
}

/* Makes an accepted plugin and its backends usable by this engine. */
static int add_plugin(silc_engine *E, ld_plugin *p)
{
    ld_set *S = E->plugins;
    const silc_plugin *pl = p->table;
    ld_plugin **np;
    ld_backend **nb;
    int i, added = 0;
    np = realloc(S->plugins, (S->nplugins + 1) * sizeof *np);
    if (!np) return eng_error(E, "out of memory loading plugin %s", p->path);
    S->plugins = np;
    nb = realloc(S->backends, (S->nbackends + (size_t)pl->n_backends) * sizeof *nb);
    if (!nb && pl->n_backends > 0) return eng_error(E, "out of memory loading plugin %s", p->path);
    if (nb) S->backends = nb;
    for (i = 0; i < pl->n_backends; i++) {
        ld_backend *b;
        if (!backend_has_ops(&pl->backends[i])) continue;
        b = calloc(1, sizeof *b);
        if (!b || !(b->full_name = full_name(pl, &pl->backends[i]))) {
            free(b);
            while (added-- > 0) {
                ld_backend *last = S->backends[--S->nbackends];
                free(last->full_name);
                free(last);
            }
            return eng_error(E, "out of memory loading plugin %s", p->path);
        }
        b->backend = &pl->backends[i];
        b->plugin = p;
        S->backends[S->nbackends++] = b;
        added++;
    }
    S->plugins[S->nplugins++] = p;
    if (pl->set_threads && E->threads > 0) pl->set_threads(E->threads);
    return 0;
}

int ld_create(silc_engine *E)
{
    const silc_plugin *pl = NULL;
    const char *msg = NULL;
    ld_plugin *p;
    E->plugins = calloc(1, sizeof *E->plugins);
    if (!E->plugins) return eng_error(E, "out of memory creating the plugin set");
    pthread_mutex_lock(&g_lock);
    p = registered(NULL);
    if (!p) {
        if (silc_reference_plugin_init(host_api(), &pl, &msg)) {
            pthread_mutex_unlock(&g_lock);
            return eng_error(E, "built-in reference plugin failed to start: %s",
                             msg ? msg : "no reason given");
        }
        if (check_table(E, pl, "built-in") || !(p = register_plugin(pl, NULL, "built-in"))) {
            pthread_mutex_unlock(&g_lock);
            return E->err[0] ? -1 : eng_error(E, "out of memory registering the reference plugin");
        }
    }
    pthread_mutex_unlock(&g_lock);
    return add_plugin(E, p);
}

/* Frees this engine's view of the plugins; the plugins stay loaded (see top). */
void ld_destroy(silc_engine *E)
{
    ld_set *S;
    size_t i;
    if (!E || !E->plugins) return;
    S = E->plugins;
    for (i = 0; i < S->nbackends; i++) {
        free(S->backends[i]->full_name);
        free(S->backends[i]);
    }
    free(S->plugins);
    free(S->backends);
    for (i = 0; i < S->npending; i++) {
        free(S->pending[i].path);
        free(S->pending[i].name);
    }
    free(S->pending);
    sb_free(&S->searched);
    sb_free(&S->refused);
    free(S);
    E->plugins = NULL;
}

/* Records a refused plugin file with the engine, and warns about it on
 * stderr the first time this process meets it. */
static void note_refused(silc_engine *E, const char *path)
{
    int first;
    sb_printf(&E->plugins->refused, "%s\n", E->err);
    pthread_mutex_lock(&g_lock);
    first = !g_warned.s || !strstr(g_warned.s, path);
    if (first) sb_printf(&g_warned, "%s\n", path);
    pthread_mutex_unlock(&g_lock);
    if (first) fprintf(stderr, "silc: warning: %s\n", E->err);
}

void ld_explain_missing(const silc_engine *E, const char *name, strbuf *b)
{
    char plugin[64];
    const char *dot = strchr(name, '.'), *line;
    size_t len = dot ? (size_t)(dot - name) : strlen(name);
    if (len >= sizeof plugin) len = sizeof plugin - 1;
    memcpy(plugin, name, len);
    plugin[len] = '\0';
    sb_printf(b, "plugin '%s' (" LD_FILE_PREFIX "%s" LD_FILE_SUFFIX ") is not loaded; searched: %s", plugin,
              plugin, E && E->plugins && E->plugins->searched.len ? sb_str(&E->plugins->searched) : "(no directory)");
    /* a file of that plugin found but refused: say why */
    for (line = E && E->plugins ? E->plugins->refused.s : NULL; line && *line;) {
        size_t ll = strcspn(line, "\n");
        char file[sizeof LD_FILE_PREFIX + 64 + sizeof LD_FILE_SUFFIX];
        snprintf(file, sizeof file, LD_FILE_PREFIX "%s" LD_FILE_SUFFIX, plugin);
        if (memmem(line, ll, file, strlen(file))) sb_printf(b, "; %.*s", (int)ll, line);
        line += ll + (line[ll] != 0);
    }
}

/* Opens, initialises and checks a plugin file not loaded before (caller holds
 * g_lock); real is its canonical path. */
static ld_plugin *open_plugin(silc_engine *E, const char *path, const char *real)
{
    void *handle, *sym;
    silc_plugin_init_fn init;
    const silc_plugin *pl = NULL;
    const char *msg = NULL;
    ld_plugin *p;
    dlerror();
    handle = dlopen(path, RTLD_NOW | RTLD_LOCAL);
    if (!handle) {
        const char *why = dlerror();
        eng_error(E, "cannot load plugin %s: %s", path, why ? why : "dlopen failed");
        return NULL;
    }
    dlerror();
    sym = dlsym(handle, SILC_PLUGIN_INIT_SYMBOL);
    if (!sym) {
        const char *why = dlerror();
        eng_error(E, "cannot load plugin %s: no %s symbol (%s)", path, SILC_PLUGIN_INIT_SYMBOL,
                  why ? why : "not exported");
        dlclose(handle);
        return NULL;
    }
    /* POSIX guarantees a dlsym'd function pointer round-trips through void *;
     * memcpy keeps -Wpedantic quiet about the object-to-function conversion. */
    memcpy(&init, &sym, sizeof init);
    if (init(host_api(), &pl, &msg)) {
        eng_error(E, "cannot load plugin %s: %s failed: %s", path, SILC_PLUGIN_INIT_SYMBOL,
                  msg ? msg : "no reason given");
        dlclose(handle);
        return NULL;
    }
    if (check_table(E, pl, path)) {
        if (pl && pl->abi_major == SILC_ABI_MAJOR && pl->shutdown) pl->shutdown();
        dlclose(handle);
        return NULL;
    }
#if defined(__SANITIZE_ADDRESS__)
    atexit(shutdown_then_check_leaks);
#endif
    if (!(p = register_plugin(pl, handle, real))) {
        eng_error(E, "out of memory loading plugin %s", path);
        if (pl->shutdown) pl->shutdown();
        dlclose(handle);
    }
    return p;
}

int ld_load_file(silc_engine *E, const char *path)
{
    ld_plugin *p;
    const ld_plugin *other;
    char real[PATH_MAX];
    size_t i;
    if (!E || !E->plugins || !path) return -1;
    if (!realpath(path, real))
        return eng_error(E, "cannot load plugin %s: %s", path, strerror(errno));
    /* The same file reached twice (a directory listed twice, a config naming
     * the build directory again) is not a conflict. */
    for (i = 0; i < E->plugins->nplugins; i++) {
        char other_real[PATH_MAX];
        const ld_plugin *q = E->plugins->plugins[i];
        if (q->handle && realpath(q->path, other_real) && strcmp(real, other_real) == 0) return 0;
    }
    pthread_mutex_lock(&g_lock);
    p = registered(real);
    if (!p) p = open_plugin(E, path, real);
    pthread_mutex_unlock(&g_lock);
    if (!p) return -1;
    other = find_loaded_plugin(E, p->table->name);
    if (other)
        return eng_error(E,
                         "plugin '%s' (%s) not loaded: a plugin of that name is already loaded from %s",
                         p->table->name, path, other->path);
    return add_plugin(E, p);
}

static int plugin_file_name(const char *name)
{
    size_t n = strlen(name), np = strlen(LD_FILE_PREFIX), ns = strlen(LD_FILE_SUFFIX);
    if (n <= np + ns) return 0;
    if (strncmp(name, LD_FILE_PREFIX, np) != 0) return 0;
    if (strcmp(name + n - ns, LD_FILE_SUFFIX) != 0) return 0;
    /* The reference is built in: its module copy would only duplicate the name. */
    return strcmp(name, LD_REFERENCE_FILE) != 0;
}

static int cmp_str(const void *a, const void *b)
{
    return strcmp(*(char *const *)a, *(char *const *)b);
}

/* Records a plugin file to open when first needed; -1 when out of memory. */
static int add_pending(ld_set *S, const char *path, const char *file)
{
    size_t np = strlen(LD_FILE_PREFIX), len = strlen(file) - np - strlen(LD_FILE_SUFFIX);
    ld_pending q;
    if (S->npending == S->cappending) {
        size_t cap = S->cappending ? 2 * S->cappending : 8;
        ld_pending *grown = realloc(S->pending, cap * sizeof *grown);
        if (!grown) return -1;
        S->pending = grown;
        S->cappending = cap;
    }
    q.path = util_strdup(path);
    q.name = malloc(len + 1);
    if (!q.path || !q.name) {
        free(q.path);
        free(q.name);
        return -1;
    }
    memcpy(q.name, file + np, len);
    q.name[len] = '\0';
    S->pending[S->npending++] = q;
    return 0;
}

/* Loads the plugins of one directory in name order (so which of two
 * same-named plugins wins does not depend on readdir order). */
/* 1 if dir/sub/name exists. */
static int exists_in(const char *dir, const char *sub, const char *name)
{
    char path[PATH_MAX];
    struct stat st;
    int len = snprintf(path, sizeof path, "%s/%s/%s", dir, sub, name);
    return len > 0 && (size_t)len < sizeof path && stat(path, &st) == 0;
}

static int load_dir(silc_engine *E, const char *dir)
{
    DIR *d = opendir(dir);
    struct dirent *ent;
    char **names = NULL;
    size_t n = 0, cap = 0, i;
    if (!E->plugins->searched.s || !strstr(E->plugins->searched.s, dir))
        sb_printf(&E->plugins->searched, "%s%s", E->plugins->searched.len ? ", " : "", dir);
    if (!d) return eng_error(E, "cannot read plugin directory %s: %s", dir, strerror(errno));
    /* An engine on a communicator (dist.h) takes the MPI builds of plugins
     * from dir/mpi first, and then not the sequential build of the same
     * file: Debian's sequential MUMPS and the MPI one must never share a
     * process (docs/distributed.md). */
    if (E->dist && exists_in(dir, "mpi", ".")) {
        char sub[PATH_MAX];
        if ((size_t)snprintf(sub, sizeof sub, "%s/mpi", dir) < sizeof sub) load_dir(E, sub);
    }
    while ((ent = readdir(d)) != NULL) {
        if (!plugin_file_name(ent->d_name)) continue;
        if (E->dist && exists_in(dir, "mpi", ent->d_name)) continue;
        if (n == cap) {
            char **nn = realloc(names, (cap = cap ? 2 * cap : 16) * sizeof *nn);
            if (!nn) break;
            names = nn;
        }
        if (!(names[n] = util_strdup(ent->d_name))) break;
        n++;
    }
    closedir(d);
    if (n) qsort(names, n, sizeof *names, cmp_str);
    for (i = 0; i < n; i++) {
        strbuf path;
        sb_init(&path);
        sb_printf(&path, "%s/%s", dir, names[i]);
        /* An engine on a communicator opens everything now: every rank
         * must open the same plugins (PETSc's start is collective), and a
         * lookup made by one rank alone (a message's suggestions) must not
         * open one there.  Out of memory: open it now rather than lose it. */
        if (E->dist || add_pending(E->plugins, sb_str(&path), names[i])) {
            if (ld_load_file(E, sb_str(&path))) note_refused(E, sb_str(&path));
        }
        sb_free(&path);
        free(names[i]);
    }
    free(names);
    E->err[0] = '\0';
    return 0;
}

/* Opens the pending files named name (NULL: all of them), in order; a file
 * refused is noted and warned about as an eager load did.  E's error text is
 * kept: a lookup is not an error of the statement that made it.  The set
 * is a cache of what the directories hold, so a const engine's lookup may
 * fill it. */
static void open_pending(const silc_engine *cE, const char *name)
{
    silc_engine *E = (silc_engine *)cE;
    ld_set *S = E->plugins;
    char saved[sizeof E->err];
    size_t i = 0;
    memcpy(saved, E->err, sizeof saved);
    while (i < S->npending) {
        ld_pending q = S->pending[i];
        if (name && strcmp(q.name, name) != 0) {
            i++;
            continue;
        }
        /* taken off the list first: opening may look plugins up again */
        memmove(S->pending + i, S->pending + i + 1, (S->npending - i - 1) * sizeof *S->pending);
        S->npending--;
        if (ld_load_file(E, q.path)) note_refused(E, q.path);
        free(q.path);
        free(q.name);
    }
    memcpy(E->err, saved, sizeof saved);
}

#ifndef SILC_PLUGIN_LIBDIR_REL
#define SILC_PLUGIN_LIBDIR_REL "silc/plugins"
#endif
#ifndef SILC_INSTALL_LIBDIR
#define SILC_INSTALL_LIBDIR "lib"
#endif

/* An object of the engine's own image, for dladdr to find the file. */
static const char engine_marker = 0;

int ld_installed_plugin_dir(char *out, size_t len)
{
    /* Where this engine's code lives -- libsilc.so in an install's libdir,
     * or a program linking the engine statically in its bindir -- tells
     * where the install put the plugins, whatever prefix it was given. */
    static const char *const beside[] = {"/" SILC_PLUGIN_LIBDIR_REL, "/../" SILC_INSTALL_LIBDIR "/" SILC_PLUGIN_LIBDIR_REL};
    Dl_info info;
    char dir[PATH_MAX];
    struct stat st;
    size_t i;
    char *slash;
    if (!dladdr(&engine_marker, &info) || !info.dli_fname ||
        !realpath(info.dli_fname, dir))
        return -1;
    slash = strrchr(dir, '/');
    if (!slash) return -1;
    *slash = '\0';
    for (i = 0; i < sizeof beside / sizeof beside[0]; i++) {
        if ((size_t)snprintf(out, len, "%s%s", dir, beside[i]) >= len) continue;
        if (stat(out, &st) == 0 && S_ISDIR(st.st_mode)) return 0;
    }
    return -1;
}

#ifndef SILC_PLUGIN_BUILD_DIR
#define SILC_PLUGIN_BUILD_DIR "./plugins"
#endif
#ifndef SILC_PLUGIN_INSTALL_DIR
#define SILC_PLUGIN_INSTALL_DIR "/usr/local/lib/silc"
#endif

void ld_fixed_plugin_dirs(char *out, size_t len)
{
    /* An installed engine's own install, wherever `cmake --install --prefix`
     * put it; a build tree's engine the build tree's, then the configured
     * install directory. */
    if (ld_installed_plugin_dir(out, len) != 0)
        snprintf(out, len, "%s", SILC_PLUGIN_BUILD_DIR ":" SILC_PLUGIN_INSTALL_DIR);
}

int ld_load_path(silc_engine *E, const char *dirs)
{
    const char *p = dirs;
    int rc = 0;
    char bad[sizeof E->err];
    if (!E || !dirs) return -1;
    while (*p) {
        size_t len = strcspn(p, ":");
        if (len > 0) {
            char dir[PATH_MAX];
            if (len >= sizeof dir) len = sizeof dir - 1;
            memcpy(dir, p, len);
            dir[len] = '\0';
            if (load_dir(E, dir) && !rc) {
                rc = -1;
                memcpy(bad, E->err, sizeof bad);
            }
        }
        p += len;
        if (*p) p++;
    }
    /* Every directory is tried; the first that could not be read is reported. */
    if (rc) memcpy(E->err, bad, sizeof bad);
    return rc;
}

/* b's entry in one of its plugin's per-backend op masks (the field at
 * field_offset: collective_ops, complex_ops), read only from a table of
 * ABI minor since_minor or later that is long enough to hold the field: an
 * older plugin's struct ends before it (and such a plugin is never handed
 * distributed or complex data).  0 also when the plugin leaves it NULL. */
static uint32_t backend_op_mask(const ld_backend *b, int since_minor, size_t field_offset)
{
    const silc_plugin *pl = b->plugin->table;
    const uint32_t *mask;
    int i;
    if (pl->abi_minor < since_minor || pl->struct_size < field_offset + sizeof mask) return 0;
    memcpy(&mask, (const char *)pl + field_offset, sizeof mask);
    for (i = 0; mask && i < pl->n_backends; i++)
        if (&pl->backends[i] == b->backend) return mask[i];
    return 0;
}

int ld_backend_collective(const ld_backend *b, int op)
{
    return (backend_op_mask(b, 5, offsetof(silc_plugin, collective_ops)) & SILC_COLLECTIVE(op)) != 0;
}

int ld_backend_takes_complex(const ld_backend *b, int op)
{
    return (backend_op_mask(b, 8, offsetof(silc_plugin, complex_ops)) & SILC_COMPLEX_OPS(op)) != 0;
}

static const ld_backend *find_loaded(const silc_engine *E, const char *full_name)
{
    size_t i;
    for (i = 0; i < E->plugins->nbackends; i++)
        if (strcmp(E->plugins->backends[i]->full_name, full_name) == 0)
            return E->plugins->backends[i];
    return NULL;
}

const ld_backend *ld_find(const silc_engine *E, const char *full_name)
{
    const ld_backend *b;
    char plugin[64];
    size_t len;
    if (!E || !E->plugins || !full_name) return NULL;
    if ((b = find_loaded(E, full_name)) || !E->plugins->npending) return b;
    /* the file of the backend's plugin first; if a plugin's name differs
     * from its file's, only opening them all can tell */
    len = strcspn(full_name, ".");
    if (len < sizeof plugin) {
        memcpy(plugin, full_name, len);
        plugin[len] = '\0';
        open_pending(E, plugin);
        if ((b = find_loaded(E, full_name)) || !E->plugins->npending) return b;
    }
    open_pending(E, NULL);
    return find_loaded(E, full_name);
}

size_t ld_backend_names(const silc_engine *E, const char ***names)
{
    size_t i, n;
    *names = NULL;
    ld_open_all(E);
    if (!E || !E->plugins || E->plugins->nbackends == 0) return 0;
    n = E->plugins->nbackends;
    *names = malloc(n * sizeof **names);
    if (!*names) return 0;
    for (i = 0; i < n; i++) (*names)[i] = E->plugins->backends[i]->full_name;
    return n;
}

static const ld_plugin *find_loaded_plugin(const silc_engine *E, const char *plugin_name)
{
    size_t i;
    for (i = 0; i < E->plugins->nplugins; i++)
        if (strcmp(E->plugins->plugins[i]->table->name, plugin_name) == 0)
            return E->plugins->plugins[i];
    return NULL;
}

const ld_plugin *ld_find_plugin(const silc_engine *E, const char *plugin_name)
{
    const ld_plugin *p;
    if (!E || !E->plugins || !plugin_name) return NULL;
    if ((p = find_loaded_plugin(E, plugin_name)) || !E->plugins->npending) return p;
    open_pending(E, plugin_name);
    if ((p = find_loaded_plugin(E, plugin_name)) || !E->plugins->npending) return p;
    open_pending(E, NULL);
    return find_loaded_plugin(E, plugin_name);
}

void ld_open_all(const silc_engine *E)
{
    if (E && E->plugins && E->plugins->npending) open_pending(E, NULL);
}

size_t ld_plugin_count(const silc_engine *E)
{
    ld_open_all(E);
    return E && E->plugins ? E->plugins->nplugins : 0;
}

const ld_plugin *ld_plugin_at(const silc_engine *E, size_t i)
{
    return i < ld_plugin_count(E) ? E->plugins->plugins[i] : NULL;
}

void ld_set_threads(silc_engine *E, int nthreads)
{
    size_t i;
    if (!E || nthreads < 1) return;
    E->threads = nthreads;
    host_set_threads(nthreads);
    /* the opened plugins; one opened later gets E->threads (add_plugin) */
    for (i = 0; E->plugins && i < E->plugins->nplugins; i++)
        if (E->plugins->plugins[i]->table->set_threads)
            E->plugins->plugins[i]->table->set_threads(nthreads);
}
