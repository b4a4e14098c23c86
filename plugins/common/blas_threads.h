/*
 * blas_threads.h -- finding OpenBLAS's thread-count setter from inside a
 * plugin.  See blas_threads.c.
 */
#ifndef SILC_BLAS_THREADS_H
#define SILC_BLAS_THREADS_H

/* openblas_set_num_threads as the module holding anchor (any address inside
 * the calling plugin) sees it, or NULL when its BLAS is not OpenBLAS. */
typedef void (*blas_threads_fn)(int);
blas_threads_fn blas_threads_find(const void *anchor);

struct silc_plugin;
/* For a plugin threaded only through its BLAS: finds OpenBLAS from the
 * plugin's own module and, if found, points pl->set_threads at it.  Returns 1
 * when found, 0 when set_threads stays NULL (nothing to control). */
int blas_threads_attach(struct silc_plugin *pl);

#endif
