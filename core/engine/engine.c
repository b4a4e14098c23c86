/*
 * engine.c -- the embedded engine behind a context: its creation (store,
 * options, plugins, configuration file, in that order so that the file can
 * name options of any loaded plugin) and destruction.  It is the one place
 * that knows every layer (docs/architecture.md), so it sits above them all;
 * the state they share is context/.
 */
#define _POSIX_C_SOURCE 200809L
#include "engine.h"
#include "dispatch.h"
#include "lang.h"
#include "dist.h"
#include "tune.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include <limits.h>

/* Seed of rand(): fixed so that scripts are reproducible run to run. */
#define ENG_RAND_SEED 0x9E3779B97F4A7C15ull

/* The configuration file to read, or NULL for built-in defaults. */
static const char *config_file(const char *config_path)
{
    const char *env;
    if (config_path) return config_path;
    env = getenv("SILC_CONFIG");
    if (env && *env) return env;
    if (access("./silc.conf", F_OK) == 0) return "./silc.conf";
    return NULL;
}

/* Thread budget from core.threads; anything but a positive integer means 1
 * (the tuner raises it later). */
static int config_threads(const silc_engine *E)
{
    const char *t = cfg_get(E, "core.threads");
    char *end;
    long n;
    if (!t) return 1;
    n = strtol(t, &end, 10);
    if (end == t || *end != '\0' || n < 1 || n > 4096) return 1;
    return (int)n;
}

static int eng_setup(silc_engine *E, const char *config_path)
{
    const char *path;
    if (store_init(&E->store)) return eng_error(E, "out of memory creating the store");
    if (cfg_create(E)) return -1;
    if (ld_create(E)) return -1;
    /* An installed engine loads the plugins of its own install, wherever
     * `cmake --install --prefix` put it; a build tree's engine those of the
     * build tree, then of the configured install directory.  These may
     * legitimately be absent; a directory the user named must work. */
    {
        char fixed[2 * PATH_MAX + 2];
        ld_fixed_plugin_dirs(fixed, sizeof fixed);
        ld_load_path(E, fixed);
    }
    E->err[0] = '\0';
    path = getenv("SILC_PLUGIN_PATH");
    if (path && *path && ld_load_path(E, path)) return -1;
    path = config_file(config_path);
    if (path && cfg_load_file(E, path)) return -1;
    path = cfg_get(E, "core.plugin_path");
    if (path && *path && ld_load_path(E, path)) return -1;
    /* A backend the configuration names must be loaded by now, unless it is
     * marked optional ("lis-style?"): an error at start, not a substitute. */
    if (disp_check_configured(E)) return -1;
    E->threads = config_threads(E);
    ld_set_threads(E, E->threads);
    return 0;
}

int eng_create(silc_engine **out, const char *config_path, char *err, size_t errlen)
{
    return eng_create_comm(out, config_path, NULL, err, errlen);
}

int eng_create_comm(silc_engine **out, const char *config_path, silc_comm_ops *comm, char *err,
                    size_t errlen)
{
    silc_engine *E;
    if (!out) return -1;
    *out = NULL;
    E = calloc(1, sizeof *E);
    if (!E) {
        if (err && errlen) snprintf(err, errlen, "out of memory creating the engine");
        return -1;
    }
    sb_init(&E->warnings);
    E->threads = 1;
    E->rand_state = ENG_RAND_SEED;
    /* The communicator first: the loader picks MPI builds of plugins for it. */
    if ((comm && dist_attach(E, comm, disp_run)) || eng_setup(E, config_path)) {
        if (comm && !E->dist && comm->destroy) comm->destroy(comm->impl);
        if (err && errlen)
            snprintf(err, errlen, "%s", E->err[0] ? E->err : "engine initialisation failed");
        eng_destroy(&E);
        return -1;
    }
    *out = E;
    return 0;
}

void eng_destroy(silc_engine **pE)
{
    silc_engine *E;
    if (!pE || !*pE) return;
    E = *pE;
    /* Values first: their attachments may belong to plugins still loaded.
     * The tuner holds some too. */
    tuner_free(E);
    memo_free(E);
    store_free(&E->store);
    if (E->lang_cache_free && E->lang_cache) E->lang_cache_free(E->lang_cache);
    eng_info_free_all(E);
    cfg_destroy(E);
    ld_destroy(E);
    dist_detach(E);
    sb_free(&E->warnings);
    free(E);
    *pE = NULL;
}

void eng_open_plugins(silc_engine *E)
{
    ld_open_all(E);
    h5_module_open(); /* the HDF5 module too, when installed (silcd's sessions inherit it) */
}
