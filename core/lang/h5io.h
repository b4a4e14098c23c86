/*
 * h5io.h -- save and load a session's values in HDF5 (h5io.c: the layouts,
 * and why a failed save or load changes nothing).
 */
#ifndef SILC_H5IO_H
#define SILC_H5IO_H

#include "context.h"

/* names[0..n) (n = 0: every name) to path, replacing the file.  0, or -1
 * with E->err. */
int h5_save(silc_engine *E, const char *path, const char *const *names, size_t n);
/* names[0..n) (n = 0: every object at the file's root) from path, bound
 * all or none.  0, or -1 with E->err naming the object. */
int h5_load(silc_engine *E, const char *path, const char *const *names, size_t n);

#endif
