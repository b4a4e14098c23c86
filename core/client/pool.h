/*
 * pool.h -- the process's pool of recently freed large arrays (pool.c says
 * why).  silcd installs it with its --array-pool cap; a program using libsilc
 * gets it at its first silc_open / silc_open_remote with the cap
 * $SILC_ARRAY_POOL (MiB; 0 turns it off), else POOL_DEFAULT_MIB.
 */
#ifndef SILC_POOL_H
#define SILC_POOL_H

#include <stddef.h>

#define POOL_DEFAULT_MIB 256

/* Makes value and envelope arrays recycle through the pool, which keeps at
 * most cap bytes; 0 leaves arrays to malloc and free.  Call before the
 * threads that use values start. */
void pool_install(size_t cap);
/* pool_install with the library's default cap, once per process. */
void pool_install_default(void);

#endif
