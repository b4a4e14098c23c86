/*
 * silc_h5.h -- the interface between libsilc and libsilc_h5.so, the module
 * that holds every HDF5 call of `save` and `load`.
 *
 * libsilc does not link HDF5: Debian's libhdf5 pulls in 35 libraries (curl,
 * OpenSSL, Kerberos, LDAP) and tripled the start-up of a text that solves
 * nothing (docs/overhead.md).  core/lang/h5io.c opens this module with
 * dlopen(RTLD_NOW | RTLD_LOCAL) the first time a save or load runs, from
 * the fixed plugin directory of the install or build tree only (never from
 * a path a session can set), and checks the table below (version and size)
 * before using it.
 *
 * The split: the module knows HDF5 and the file layouts (docs/hdf5.md) and
 * the checks that are HDF5's (links, external or virtual storage, type
 * classes, compound members); the core keeps everything else -- which file
 * a name means and how it is opened (openat, O_NOFOLLOW, --data-dir: the
 * module only gets the open file as /proc/self/fd/N), values, their claims
 * against the value limit and the session budget, binding.  The module
 * reads into arrays the core allocated from a claim it checked.
 *
 * Every function returns 0 (or a handle) on success; on failure -1 (NULL)
 * with the complete message ("load: 'A' in 'f.h5' ...") in err.
 */
#ifndef SILC_H5_H
#define SILC_H5_H

#include <stddef.h>
#include <stdint.h>

#define SILC_H5_MODULE_FILE "libsilc_h5.so"
#define SILC_H5_ENTRY_SYMBOL "silc_h5_module"
/* Stepped on any change to the table or to silc_h5_value; the core accepts
 * only its own version. */
#define SILC_H5_VERSION 1

enum silc_h5_format { SILC_H5_DENSE = 0, SILC_H5_CSR = 1, SILC_H5_BAND = 2 };

/* One value: what save writes from, what load's describe claims and read
 * fills.  Arrays are SILC's own storage: dense column-major m x n; band
 * LAPACK's (kl+ku+1) x n column-major; CSR 0-based rowptr (m+1), colind and
 * val (nnz).  A complex value holds 2 doubles an entry (re, im), which is
 * the memory layout of the compound {r, i} h5py writes. */
typedef struct silc_h5_value {
    int format;                 /* enum silc_h5_format */
    int is_complex;
    int64_t m, n, nnz, kl, ku;
    double *val;
    int64_t *rowptr, *colind;
    int column_major;           /* describe -> read: how a dense dataset lies (module's own) */
} silc_h5_value;

typedef struct silc_h5_file silc_h5_file;

typedef struct silc_h5_api {
    size_t struct_size;         /* sizeof(silc_h5_api) of the module's build */
    int version;                /* SILC_H5_VERSION */
    /* save: create_file makes a new file at fd_path (the core's temporary,
     * opened); write_value writes one value under name; close_file closes
     * a file of either kind (-1 when closing a saved file failed: it is
     * bad).  path is the user's name of the file, for messages. */
    silc_h5_file *(*create_file)(const char *fd_path, const char *path, char *err, size_t errlen);
    int (*write_value)(silc_h5_file *f, const char *name, const silc_h5_value *v, char *err, size_t errlen);
    int (*close_file)(silc_h5_file *f, char *err, size_t errlen);
    /* load: open_file opens a file read-only ("load: 'x' is not an HDF5
     * file"); each_name calls each(ctx, name) for the names of the root
     * group in name order, failing at the first non-zero return; describe
     * fills v's format, field and shape (no array) and sets *foreign when
     * the object is none of SILC's layouts (a load of the whole file skips
     * those); read_value fills the arrays of v -- the claim describe gave,
     * unchanged, with arrays the caller made for it -- and fails when the
     * object no longer matches that claim. */
    silc_h5_file *(*open_file)(const char *fd_path, const char *path, char *err, size_t errlen);
    int (*each_name)(silc_h5_file *f, int (*each)(void *ctx, const char *name), void *ctx, char *err, size_t errlen);
    int (*describe)(silc_h5_file *f, const char *name, silc_h5_value *v, int *foreign, char *err, size_t errlen);
    int (*read_value)(silc_h5_file *f, const char *name, silc_h5_value *v, char *err, size_t errlen);
} silc_h5_api;

/* The module's one exported symbol. */
typedef const silc_h5_api *(*silc_h5_entry_fn)(void);

#endif
