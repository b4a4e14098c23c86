/*
 * h5io.c -- `save "file.h5" [names]` and `load "file.h5" [names]`: a
 * session's values in HDF5, in the layouts other tools read without SILC
 * (h5py, scipy, anndata, Octave; docs/hdf5.md).  This is the engine's side;
 * every HDF5 call is in libsilc_h5.so (h5module/, its interface
 * h5module/silc_h5.h), which this file opens with dlopen the first time a
 * save or load runs, so that libsilc does not link HDF5 and a text that
 * saves nothing does not pay for loading it (docs/overhead.md, start-up).
 * The module comes from the fixed plugin directory of the install or build
 * tree only (ld_fixed_plugin_dirs), never from a directory a session or
 * configuration names.  Without it both statements say it is not
 * installed.
 *
 * What stays here: which file a name means and how it is opened (the
 * options database's cfg_file_read and cfg_file_write: beneath silcd's
 * --data-dir in a server session, openat with O_NOFOLLOW; the module gets
 * the open file as /proc/self/fd/N), values and their claims, and binding.
 *
 * save writes a new file beside the old one and renames it over, so a
 * failed save leaves the old file (the new one is created under a fresh name
 * with O_EXCL | O_NOFOLLOW, so a link planted beside it redirects nothing, and
 * a link at the name itself is replaced, not written through); load reads
 * every value first and binds them only when all were read, so a failed
 * load changes nothing.  Each object's claim (format, shape: what the
 * module's describe reports) is checked by the checker every value passes
 * (val_parts_claim: overflow, the value limit), and the claims of
 * everything the load binds, summed, against what silcd's session has left
 * (val_budget_claim), before anything is allocated or read; the module then
 * reads into arrays made for that claim and refuses an object that no
 * longer matches it; CSR arrays are checked as a PUT's (val_parts_fill).
 * An object that is none of the layouts is an error naming it when it was
 * asked for by name; a load of the whole file skips it (a file may hold
 * other programs' groups and strings) and warns with the list of what it
 * skipped and why.
 */
#define _POSIX_C_SOURCE 200809L
#include "context.h"
#include "dispatch.h"
#include "store.h"
#include "lang.h"
#include "util.h"
#include "silc_h5.h"

#include <dlfcn.h>
#include <limits.h>
#include <pthread.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

/* ---- the module ----------------------------------------------------------------- */

static pthread_mutex_t g_h5_lock = PTHREAD_MUTEX_INITIALIZER;
static const silc_h5_api *g_h5; /* opened once per process, never closed (as plugins) */

/* The module's table, opened now if it was not; NULL with why in err
 * (what: "save" or "load"). */
static const silc_h5_api *h5_module(const char *what, char *err, size_t errlen)
{
    char dirs[2 * PATH_MAX + 2];
    const char *p;
    const silc_h5_api *api = NULL;
    int found = 0;
    pthread_mutex_lock(&g_h5_lock);
    if (g_h5) {
        api = g_h5;
        pthread_mutex_unlock(&g_h5_lock);
        return api;
    }
    ld_fixed_plugin_dirs(dirs, sizeof dirs);
    for (p = dirs; *p && !api && !found;) {
        size_t len = strcspn(p, ":");
        char file[PATH_MAX + sizeof SILC_H5_MODULE_FILE + 1];
        struct stat st;
        if (len > 0 && len < PATH_MAX && snprintf(file, sizeof file, "%.*s/%s", (int)len, p, SILC_H5_MODULE_FILE) > 0 &&
            stat(file, &st) == 0) {
            /* RTLD_LOCAL: HDF5 and the 35 libraries it pulls in stay out
             * of the global namespace, where plugins' libraries live */
            void *handle = dlopen(file, RTLD_NOW | RTLD_LOCAL), *sym = NULL;
            silc_h5_entry_fn entry;
            found = 1;
            if (!handle) {
                const char *why = dlerror();
                snprintf(err, errlen, "%s: HDF5 support cannot be loaded: %s", what, why ? why : file);
                break;
            }
            sym = dlsym(handle, SILC_H5_ENTRY_SYMBOL);
            if (sym) memcpy(&entry, &sym, sizeof entry); /* see loader.c: POSIX's function pointer round trip */
            api = sym ? entry() : NULL;
            if (!api || api->version != SILC_H5_VERSION || api->struct_size < sizeof(silc_h5_api)) {
                snprintf(err, errlen, "%s: %s is not this SILC's HDF5 module (interface version %d, %zu bytes; "
                                      "this SILC needs version %d, %zu bytes): reinstall SILC", what, file,
                         api ? api->version : -1, api ? api->struct_size : (size_t)0, SILC_H5_VERSION,
                         sizeof(silc_h5_api));
                api = NULL;
                dlclose(handle);
            }
        }
        p += len;
        if (*p) p++;
    }
    if (!api && !found)
        snprintf(err, errlen, "%s: HDF5 support is not installed (%s not found in %s)", what, SILC_H5_MODULE_FILE,
                 dirs);
    g_h5 = api;
    pthread_mutex_unlock(&g_h5_lock);
    return api;
}

void h5_module_open(void)
{
    char err[PATH_MAX * 3];
    (void)h5_module("load", err, sizeof err);
}

/* The module's message as the engine's error. */
static int h5_fail(silc_engine *E, const char *err)
{
    return eng_error(E, "%s", err);
}

/* ---- save ---------------------------------------------------------------------- */

/* v as the module's value (arrays borrowed). */
static void to_h5_value(const silc_value *v, silc_h5_value *out)
{
    memset(out, 0, sizeof *out);
    out->format = v->format == SILC_FMT_CSR ? SILC_H5_CSR : v->format == SILC_FMT_BAND ? SILC_H5_BAND : SILC_H5_DENSE;
    out->is_complex = v->field == SILC_FIELD_COMPLEX;
    out->m = v->m, out->n = v->n, out->nnz = v->nnz, out->kl = v->kl, out->ku = v->ku;
    out->val = v->val;
    out->rowptr = v->rowptr, out->colind = v->colind;
}

int h5_save(silc_engine *E, const char *path, const char *const *names, size_t n)
{
    const silc_h5_api *h5;
    const char **all = NULL;
    char fdpath[64];
    cfg_file out;
    silc_h5_file *file;
    size_t i, count = n;
    int rc = 0;
    if (!(h5 = h5_module("save", E->err, sizeof E->err))) return -1;
    if (!n) {
        count = store_names(&E->store, &all);
        if (!count && E->store.count) return eng_error(E, "save: out of memory listing the names");
        names = all;
    }
    for (i = 0; i < count; i++) {
        const silc_value *v = store_get(&E->store, names[i]);
        if (!v) {
            free(all);
            return eng_error(E, "save: undefined name '%s'", names[i]);
        }
        if (v->dist) {
            free(all);
            return eng_error(E, "save: '%s' is distributed over ranks; save it from one process", names[i]);
        }
    }
    if (cfg_file_write(E, "save", path, &out)) {
        free(all);
        return -1;
    }
    util_fd_path(out.fd, fdpath, sizeof fdpath);
    if (!(file = h5->create_file(fdpath, path, E->err, sizeof E->err))) {
        cfg_file_close(&out);
        free(all);
        return -1;
    }
    for (i = 0; i < count && !rc; i++) {
        silc_h5_value hv;
        to_h5_value(store_get(&E->store, names[i]), &hv);
        rc = h5->write_value(file, names[i], &hv, E->err, sizeof E->err);
    }
    {
        char err[sizeof E->err];
        if (h5->close_file(file, err, sizeof err) < 0 && !rc) rc = h5_fail(E, err);
    }
    if (!rc) rc = cfg_file_commit(E, "save", path, &out);
    else cfg_file_close(&out);
    free(all);
    return rc;
}

/* ---- load ---------------------------------------------------------------------- */

/* A checked claim, with the reason as "load: 'A' in 'f.h5': ..." */
static int claim_allowed(silc_engine *E, const val_parts *p, const char *name, const char *path)
{
    char why[512];
    if (val_parts_claim(p, why, sizeof why) == 0) return 0;
    return eng_error(E, "load: '%s' in '%s': %s", name, path, why);
}

/* The module's claim as the checker's. */
static void to_parts(const silc_h5_value *h, val_parts *p)
{
    memset(p, 0, sizeof *p);
    p->format = h->format == SILC_H5_CSR ? SILC_FMT_CSR : h->format == SILC_H5_BAND ? SILC_FMT_BAND : SILC_FMT_DENSE;
    p->field = h->is_complex ? SILC_FIELD_COMPLEX : SILC_FIELD_REAL;
    p->m = h->m, p->n = h->n, p->kl = h->kl, p->ku = h->ku;
    p->nnz = p->format == SILC_FMT_CSR ? h->nnz : 0;
}

/* The value of name, read into arrays made for its checked claim h. */
static int read_value(silc_engine *E, const silc_h5_api *h5, silc_h5_file *file, const char *path, const char *name,
                      silc_h5_value *h, silc_value **out)
{
    val_parts claim;
    silc_value *v;
    char why[512];
    to_parts(h, &claim);
    if (!(v = val_new_unset_field(claim.format, claim.field, claim.m, claim.n, claim.nnz, claim.kl, claim.ku)))
        return eng_error(E, "load: out of memory for '%s'", name);
    h->val = v->val, h->rowptr = v->rowptr, h->colind = v->colind;
    if (h5->read_value(file, name, h, E->err, sizeof E->err)) {
        val_release(v);
        return -1;
    }
    if (claim.format == SILC_FMT_CSR) { /* the arrays, in place, as a PUT's */
        claim.rowptr = v->rowptr, claim.colind = v->colind, claim.values = v->val;
        if (val_parts_fill(v, &claim, why, sizeof why)) {
            val_release(v);
            return eng_error(E, "load: '%s' in '%s': %s", name, path, why);
        }
    }
    *out = v;
    return 0;
}

/* The names of file's root, for a load of everything. */
typedef struct root_names {
    char **names;
    size_t n, cap;
    int failed;
} root_names;

static int add_name(void *user, const char *name)
{
    root_names *r = user;
    if (r->n == r->cap) {
        size_t cap = r->cap ? 2 * r->cap : 16;
        char **grown = realloc(r->names, cap * sizeof *grown);
        if (!grown) return (r->failed = 1), -1;
        r->names = grown, r->cap = cap;
    }
    if (!(r->names[r->n] = malloc(strlen(name) + 1))) return (r->failed = 1), -1;
    strcpy(r->names[r->n++], name);
    return 0;
}

/* What a load of the whole file skipped, for its warning: the first
 * SKIP_LISTED names with the reason, then a count. */
#define SKIP_LISTED 16
typedef struct skip_list {
    size_t count;
    strbuf list;
} skip_list;

static void note_skipped(skip_list *s, const char *name, const char *err)
{
    /* err is "load: 'x' in 'f.h5' is not a SILC value: why" or "... is
     * not a name SILC can bind (...)": the part from "not" on says why */
    const char *why = strstr(err, "is not ");
    why = why ? why + 3 : err;
    if (s->count < SKIP_LISTED) sb_printf(&s->list, "%s'%s' (%s)", s->count ? "; " : "", name, why);
    else if (s->count == SKIP_LISTED) sb_printf(&s->list, "; and more");
    s->count++;
}

int h5_load(silc_engine *E, const char *path, const char *const *names, size_t n)
{
    const silc_h5_api *h5;
    root_names all = {NULL, 0, 0, 0};
    skip_list skipped;
    silc_value **got = NULL, **olds = NULL;
    silc_h5_value *claims = NULL;
    unsigned char *wanted = NULL; /* loaded, not skipped */
    char fdpath[64];
    cfg_file in;
    silc_h5_file *file;
    size_t i, k, count = n;
    double claimed = 0;
    int rc = 0;
    if (!(h5 = h5_module("load", E->err, sizeof E->err))) return -1;
    if (cfg_file_read(E, "load", path, &in)) return -1;
    util_fd_path(in.fd, fdpath, sizeof fdpath);
    file = h5->open_file(fdpath, path, E->err, sizeof E->err);
    cfg_file_close(&in); /* HDF5 holds its own descriptor of the same file */
    if (!file) return -1;
    skipped.count = 0;
    sb_init(&skipped.list);
    if (!n) {
        if (h5->each_name(file, add_name, &all, E->err, sizeof E->err) || all.failed)
            rc = eng_error(E, "load: cannot list '%s'", path);
        names = (const char *const *)all.names;
        count = all.n;
    }
    if (!rc && (!(got = calloc(count ? count : 1, sizeof *got)) || !(olds = calloc(count ? count : 1, sizeof *olds)) ||
                !(claims = calloc(count ? count : 1, sizeof *claims)) || !(wanted = calloc(count ? count : 1, 1))))
        rc = eng_error(E, "load: out of memory");
    /* Every object's claim first, then their sum against what the session
     * has left (silcd's --max-session-bytes: the values a load binds are
     * held together), before anything is allocated or read.  A load of the
     * whole file skips what is not SILC's (another program's groups,
     * strings, names SILC cannot bind) and says so below; a name asked for
     * must load.  A SILC value that is broken or refused fails either way. */
    for (i = 0; !rc && i < count; i++) {
        val_parts claim;
        int foreign = 0;
        if (!util_is_name(names[i])) {
            foreign = 1;
            rc = eng_error(E, "load: '%s' in '%s' is not a name SILC can bind (a letter or '_', then letters, "
                              "digits and '_')", names[i], path);
        } else if (h5->describe(file, names[i], &claims[i], &foreign, E->err, sizeof E->err)) {
            rc = -1;
        } else {
            to_parts(&claims[i], &claim);
            if (claim_allowed(E, &claim, names[i], path)) {
                rc = -1;
            } else {
                claimed += val_parts_bytes(&claim);
                wanted[i] = 1;
            }
        }
        if (rc && foreign && !n) {
            note_skipped(&skipped, names[i], E->err);
            E->err[0] = '\0';
            rc = 0;
        }
    }
    if (!rc) {
        char what[400];
        size_t nwanted = 0;
        for (i = 0; i < count; i++) nwanted += wanted[i];
        if (nwanted == 1) {
            for (i = 0; !wanted[i]; i++) {}
            snprintf(what, sizeof what, "'%.300s' (%.0f bytes)", names[i], claimed);
        } else {
            snprintf(what, sizeof what, "its %zu values (%.0f bytes)", nwanted, claimed);
        }
        memo_make_room(E, claimed); /* the memo's kept results go first */
        if (val_budget_claim(claimed, what))
            rc = eng_error(E, "load: '%s': %s", path, val_refusal());
    }
    for (i = 0; !rc && i < count; i++)
        if (wanted[i] && read_value(E, h5, file, path, names[i], &claims[i], &got[i])) rc = -1;
    h5->close_file(file, NULL, 0);
    /* Every value read: now they are bound.  Only a new name can fail to
     * bind (out of memory); then the names bound so far get back what they
     * held (rebinding never allocates) or go. */
    for (i = 0; !rc && i < count; i++) {
        silc_value *old;
        if (!got[i]) continue; /* skipped */
        old = store_get(&E->store, names[i]);
        if (old) val_retain(old);
        if (store_set(&E->store, names[i], got[i])) {
            val_release(old);
            while (i-- > 0) {
                silc_value *prev = olds[i];
                if (!got[i]) continue;
                if (prev) store_set(&E->store, names[i], prev);
                else store_remove(&E->store, names[i]);
            }
            rc = eng_error(E, "load: out of memory binding the values of '%s'", path);
            break;
        }
        olds[i] = old;
    }
    for (i = 0; !rc && i < count; i++)
        if (got[i]) eng_info_remove(E, names[i]);
    if (!rc && skipped.count)
        eng_warn(E, "load: skipped %zu object%s of '%s' that %s: %s", skipped.count, skipped.count == 1 ? "" : "s",
                 path, skipped.count == 1 ? "is not a SILC value" : "are not SILC values", sb_str(&skipped.list));
    sb_free(&skipped.list);
    for (k = 0; olds && k < count; k++) val_release(olds[k]);
    free(olds);
    for (k = 0; got && k < count; k++) val_release(got[k]);
    free(got);
    free(claims);
    free(wanted);
    for (k = 0; k < all.n; k++) free(all.names[k]);
    free(all.names);
    return rc;
}
