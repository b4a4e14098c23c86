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

#endif
