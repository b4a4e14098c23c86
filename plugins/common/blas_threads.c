/*
 * blas_threads.c -- look up openblas_set_num_threads for a plugin whose
 * library is threaded only through BLAS (MUMPS, PETSc, SuiteSparse).
 *
 * Compiled into each plugin that needs it (silc_add_plugin SOURCES): plugins
 * must not link each other or libsilc, so there is no shared copy.  The
 * module is loaded RTLD_LOCAL, which hides its BLAS from a global look-up;
 * dlsym on the module's own handle searches the module and its dependencies.
 * RTLD_NOLOAD never loads anything new, and dlclose drops only the reference
 * it added.  Failing that, the global scope and the usual BLAS SONAMEs.
 */
#define _GNU_SOURCE /* dladdr, RTLD_DEFAULT, RTLD_NOLOAD */
#include "blas_threads.h"
#include "silc_plugin.h"

#include <dlfcn.h>
#include <string.h>

static void *lookup_in(const char *file)
{
    void *sym, *h = dlopen(file, RTLD_LAZY | RTLD_LOCAL | RTLD_NOLOAD);
    if (!h) return NULL;
    sym = dlsym(h, "openblas_set_num_threads");
    dlclose(h);
    return sym;
}

blas_threads_fn blas_threads_find(const void *anchor)
{
    static const char *const sonames[] = {"libblas.so.3", "libopenblas.so.0", NULL};
    blas_threads_fn fn = NULL;
    Dl_info info;
    void *sym = NULL;
    int i;
    if (dladdr(anchor, &info) && info.dli_fname) sym = lookup_in(info.dli_fname);
    if (!sym) sym = dlsym(RTLD_DEFAULT, "openblas_set_num_threads");
    for (i = 0; !sym && sonames[i]; i++) sym = lookup_in(sonames[i]);
    /* ISO C has no object-to-function pointer cast; POSIX guarantees the
     * representation, so copy the bits. */
    if (sym) memcpy(&fn, &sym, sizeof fn);
    return fn;
}

/* Each plugin compiles its own copy of this file, so this is per plugin. */
static blas_threads_fn attached;

static void set_attached(int n)
{
    if (attached && n > 0) attached(n);
}

int blas_threads_attach(struct silc_plugin *pl)
{
    attached = blas_threads_find(pl);
    if (attached) pl->set_threads = set_attached;
    return attached != NULL;
}
