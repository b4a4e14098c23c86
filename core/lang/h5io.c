/*
 * h5io.c -- `save "file.h5" [names]` and `load "file.h5" [names]`: a
 * session's values in HDF5, in the layouts other tools read without SILC
 * (h5py, scipy, anndata):
 *
 *   dense m x n   a 2-D float64 dataset of shape (m, n), row i = row i
 *   CSR           a group with datasets data (float64), indices and indptr
 *                 (int64, 0-based) and an attribute shape = (m, n); also
 *                 encoding-type = "csr_matrix", as anndata writes it
 *   band          a 2-D float64 dataset of shape (kl+ku+1, n), LAPACK's band
 *                 storage, with attributes silc-format = "band", kl, ku and
 *                 shape = (m, n)
 *
 * save writes a new file beside the old one and renames it over, so a
 * failed save leaves the old file (the new one is created under a fresh name
 * with O_EXCL | O_NOFOLLOW, so a link planted beside it redirects nothing, and
 * a link at the name itself is replaced, not written through); load reads every value first and binds
 * them only when all were read, so a failed load changes nothing.  An
 * object that is none of the layouts is an error naming it.  Built only
 * with HDF5 (SILC_HAVE_HDF5); without it both statements say so.
 *
 * Which file a name means is the options database's (cfg_file_read,
 * cfg_file_write: beneath silcd's --data-dir in a server session); HDF5 is
 * handed the file already opened, as /proc/self/fd/N.
 */
#define _POSIX_C_SOURCE 200809L
#include "context.h"
#include "dispatch.h"
#include "store.h"
#include "lang.h"
#include "util.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#ifndef SILC_HAVE_HDF5

int h5_save(silc_engine *E, const char *path, const char *const *names, size_t n)
{
    (void)path, (void)names, (void)n;
    return eng_error(E, "save: this SILC was built without HDF5 (apt-get install libhdf5-dev and rebuild)");
}

int h5_load(silc_engine *E, const char *path, const char *const *names, size_t n)
{
    (void)path, (void)names, (void)n;
    return eng_error(E, "load: this SILC was built without HDF5 (apt-get install libhdf5-dev and rebuild)");
}

#else
#include <hdf5.h>

/* ---- small helpers ------------------------------------------------------------ */

static int put_attr_i64(hid_t obj, const char *name, const int64_t *v, hsize_t count)
{
    hid_t sp = H5Screate_simple(1, &count, NULL), a = -1;
    int rc = -1;
    if (sp >= 0) a = H5Acreate2(obj, name, H5T_STD_I64LE, sp, H5P_DEFAULT, H5P_DEFAULT);
    if (a >= 0 && H5Awrite(a, H5T_NATIVE_INT64, v) >= 0) rc = 0;
    if (a >= 0) H5Aclose(a);
    if (sp >= 0) H5Sclose(sp);
    return rc;
}

/* A variable-length UTF-8 string, as h5py and anndata write theirs (h5py
 * reads it back as str, not bytes). */
static int put_attr_str(hid_t obj, const char *name, const char *text)
{
    hid_t t = H5Tcopy(H5T_C_S1), sp = H5Screate(H5S_SCALAR), a = -1;
    int rc = -1;
    if (t >= 0 && H5Tset_size(t, H5T_VARIABLE) >= 0 && H5Tset_cset(t, H5T_CSET_UTF8) >= 0 && sp >= 0)
        a = H5Acreate2(obj, name, t, sp, H5P_DEFAULT, H5P_DEFAULT);
    if (a >= 0 && H5Awrite(a, t, &text) >= 0) rc = 0;
    if (a >= 0) H5Aclose(a);
    if (sp >= 0) H5Sclose(sp);
    if (t >= 0) H5Tclose(t);
    return rc;
}

/* The string attribute name of obj into out ("" when absent or not a string). */
static void get_attr_str(hid_t obj, const char *name, char *out, size_t len)
{
    hid_t a, t, mt;
    out[0] = 0;
    if (H5Aexists(obj, name) <= 0 || (a = H5Aopen(obj, name, H5P_DEFAULT)) < 0) return;
    t = H5Aget_type(a);
    if (t >= 0 && H5Tget_class(t) == H5T_STRING && H5Tis_variable_str(t) > 0) {
        char *v = NULL;
        mt = H5Tcopy(t);
        if (H5Aread(a, mt, &v) >= 0 && v) snprintf(out, len, "%s", v);
        if (v) H5free_memory(v);
        H5Tclose(mt);
    } else if (t >= 0 && H5Tget_class(t) == H5T_STRING && H5Tget_size(t) < len) {
        mt = H5Tcopy(t);
        H5Tset_size(mt, len - 1);
        H5Tset_strpad(mt, H5T_STR_NULLTERM);
        memset(out, 0, len);
        if (H5Aread(a, mt, out) < 0) out[0] = 0;
        H5Tclose(mt);
    }
    if (t >= 0) H5Tclose(t);
    H5Aclose(a);
}

/* An integer attribute of up to count entries into v; the number read, or -1. */
static int get_attr_i64(hid_t obj, const char *name, int64_t *v, hssize_t count)
{
    hid_t a, sp;
    hssize_t n;
    int rc = -1;
    if (H5Aexists(obj, name) <= 0 || (a = H5Aopen(obj, name, H5P_DEFAULT)) < 0) return -1;
    sp = H5Aget_space(a);
    n = sp >= 0 ? H5Sget_simple_extent_npoints(sp) : -1;
    if (n >= 1 && n <= count && H5Aread(a, H5T_NATIVE_INT64, v) >= 0) rc = (int)n;
    if (sp >= 0) H5Sclose(sp);
    H5Aclose(a);
    return rc;
}

static hid_t write_dataset(hid_t loc, const char *name, hid_t file_type, hid_t mem_type, int rank,
                           const hsize_t *dims, const void *data)
{
    hid_t sp = H5Screate_simple(rank, dims, NULL), d = -1;
    if (sp >= 0) d = H5Dcreate2(loc, name, file_type, sp, H5P_DEFAULT, H5P_DEFAULT, H5P_DEFAULT);
    if (d >= 0 && H5Dwrite(d, mem_type, H5S_ALL, H5S_ALL, H5P_DEFAULT, data) < 0) {
        H5Dclose(d);
        d = -1;
    }
    if (sp >= 0) H5Sclose(sp);
    return d;
}

/* ---- save ---------------------------------------------------------------------- */

/* m x n column-major (ld rows) as a row-major (m, n) array, malloc'd. */
static double *row_major(const double *a, int64_t m, int64_t n, int64_t ld)
{
    double *t = malloc((size_t)(m * n > 0 ? m * n : 1) * sizeof *t);
    int64_t i, j;
    if (t)
        for (i = 0; i < m; i++)
            for (j = 0; j < n; j++) t[i * n + j] = a[i + j * ld];
    return t;
}

static int save_one(silc_engine *E, hid_t file, const char *name, const silc_value *v)
{
    int64_t shape[2] = {v->m, v->n};
    hid_t obj = -1;
    int rc = -1;
    if (v->format == SILC_FMT_CSR) {
        hsize_t nz = (hsize_t)v->nnz, np = (hsize_t)v->m + 1;
        hid_t d;
        obj = H5Gcreate2(file, name, H5P_DEFAULT, H5P_DEFAULT, H5P_DEFAULT);
        if (obj < 0) return eng_error(E, "save: H5Gcreate2 failed for '%s'", name);
        rc = 0;
        if ((d = write_dataset(obj, "data", H5T_IEEE_F64LE, H5T_NATIVE_DOUBLE, 1, &nz, v->val)) < 0) rc = -1;
        else H5Dclose(d);
        if (!rc && (d = write_dataset(obj, "indices", H5T_STD_I64LE, H5T_NATIVE_INT64, 1, &nz, v->colind)) < 0)
            rc = -1;
        else if (!rc) H5Dclose(d);
        if (!rc && (d = write_dataset(obj, "indptr", H5T_STD_I64LE, H5T_NATIVE_INT64, 1, &np, v->rowptr)) < 0)
            rc = -1;
        else if (!rc) H5Dclose(d);
        if (!rc && (put_attr_i64(obj, "shape", shape, 2) || put_attr_str(obj, "encoding-type", "csr_matrix") ||
                    put_attr_str(obj, "encoding-version", "0.1.0")))
            rc = -1;
    } else {
        int band = v->format == SILC_FMT_BAND;
        int64_t rows = band ? v->ld : v->m;
        hsize_t dims[2] = {(hsize_t)rows, (hsize_t)v->n};
        double *t = row_major(v->val, rows, v->n, rows);
        if (!t) return eng_error(E, "save: out of memory writing '%s'", name);
        obj = write_dataset(file, name, H5T_IEEE_F64LE, H5T_NATIVE_DOUBLE, 2, dims, t);
        free(t);
        if (obj < 0) return eng_error(E, "save: H5Dcreate2/H5Dwrite failed for '%s'", name);
        rc = 0;
        if (band && (put_attr_str(obj, "silc-format", "band") || put_attr_i64(obj, "kl", &v->kl, 1) ||
                     put_attr_i64(obj, "ku", &v->ku, 1) || put_attr_i64(obj, "shape", shape, 2)))
            rc = -1;
    }
    if (v->format == SILC_FMT_CSR) H5Gclose(obj);
    else H5Dclose(obj);
    return rc ? eng_error(E, "save: writing '%s' failed (HDF5)", name) : 0;
}

int h5_save(silc_engine *E, const char *path, const char *const *names, size_t n)
{
    const char **all = NULL;
    char fdpath[64];
    cfg_file out;
    hid_t file;
    size_t i, count = n;
    int rc = 0;
    H5Eset_auto2(H5E_DEFAULT, NULL, NULL); /* errors are ours to report */
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
    file = H5Fcreate(fdpath, H5F_ACC_TRUNC, H5P_DEFAULT, H5P_DEFAULT);
    if (file < 0) {
        cfg_file_close(&out);
        free(all);
        return eng_error(E, "save: cannot create '%s' (H5Fcreate)", path);
    }
    for (i = 0; i < count && !rc; i++) rc = save_one(E, file, names[i], store_get(&E->store, names[i]));
    if (H5Fclose(file) < 0 && !rc) rc = eng_error(E, "save: closing '%s' failed (H5Fclose)", path);
    if (!rc) rc = cfg_file_commit(E, "save", path, &out);
    else cfg_file_close(&out);
    free(all);
    return rc;
}

/* ---- load ---------------------------------------------------------------------- */

/* The value of the object name of file, or NULL with E->err naming it. */
static silc_value *load_one(silc_engine *E, hid_t file, const char *path, const char *name)
{
    H5O_info_t info;
    silc_value *v = NULL;
    int64_t shape[2];
    if (H5Lexists(file, name, H5P_DEFAULT) <= 0) {
        eng_error(E, "load: '%s' is not in '%s'", name, path);
        return NULL;
    }
    if (H5Oget_info_by_name2(file, name, &info, H5O_INFO_BASIC, H5P_DEFAULT) < 0) {
        eng_error(E, "load: cannot read '%s' in '%s'", name, path);
        return NULL;
    }
    if (info.type == H5O_TYPE_GROUP) {
        /* CSR: data, indices, indptr and shape, as scipy / anndata write it */
        hid_t g = H5Gopen2(file, name, H5P_DEFAULT), d[3] = {-1, -1, -1};
        static const char *const parts[3] = {"data", "indices", "indptr"};
        hssize_t len[3];
        silc_envelope_t e;
        double *data = NULL;
        int64_t *indices = NULL, *indptr = NULL;
        char err[512];
        int k, ok = g >= 0 && get_attr_i64(g, "shape", shape, 2) == 2 && shape[0] >= 0 && shape[1] >= 0;
        for (k = 0; ok && k < 3; k++) {
            hid_t sp;
            ok = H5Lexists(g, parts[k], H5P_DEFAULT) > 0 && (d[k] = H5Dopen2(g, parts[k], H5P_DEFAULT)) >= 0;
            sp = ok ? H5Dget_space(d[k]) : -1;
            ok = ok && sp >= 0 && H5Sget_simple_extent_ndims(sp) == 1;
            len[k] = ok ? H5Sget_simple_extent_npoints(sp) : -1;
            if (sp >= 0) H5Sclose(sp);
        }
        if (!ok || len[0] != len[1] || len[2] != shape[0] + 1) {
            eng_error(E, "load: '%s' in '%s' is not a SILC value: a group needs datasets data, indices, indptr "
                         "(%s) and a shape attribute", name, path, ok ? "of matching lengths" : "1-D");
        } else if (!(data = malloc((size_t)(len[0] ? len[0] : 1) * sizeof *data)) ||
                   !(indices = malloc((size_t)(len[1] ? len[1] : 1) * sizeof *indices)) ||
                   !(indptr = malloc((size_t)len[2] * sizeof *indptr))) {
            eng_error(E, "load: out of memory reading '%s'", name);
        } else if (H5Dread(d[0], H5T_NATIVE_DOUBLE, H5S_ALL, H5S_ALL, H5P_DEFAULT, data) < 0 ||
                   H5Dread(d[1], H5T_NATIVE_INT64, H5S_ALL, H5S_ALL, H5P_DEFAULT, indices) < 0 ||
                   H5Dread(d[2], H5T_NATIVE_INT64, H5S_ALL, H5S_ALL, H5P_DEFAULT, indptr) < 0) {
            eng_error(E, "load: reading '%s' in '%s' failed (H5Dread)", name, path);
        } else {
            /* The envelope's checks, as a PUT's: rowptr, column range, order. */
            memset(&e, 0, sizeof e);
            e.m = shape[0], e.n = shape[1], e.format = SILC_CSR, e.nnz = len[0];
            e.values = data, e.rowptr = indptr, e.colind = indices;
            if (env_to_value(&e, &v, err, sizeof err))
                eng_error(E, "load: '%s' in '%s': %s", name, path, err);
        }
        for (k = 0; k < 3; k++)
            if (d[k] >= 0) H5Dclose(d[k]);
        if (g >= 0) H5Gclose(g);
        free(data), free(indices), free(indptr);
        return v;
    }
    if (info.type == H5O_TYPE_DATASET) {
        hid_t d = H5Dopen2(file, name, H5P_DEFAULT), sp = d >= 0 ? H5Dget_space(d) : -1, t = -1;
        hsize_t dims[2] = {0, 1};
        int rank = sp >= 0 ? H5Sget_simple_extent_ndims(sp) : -1, numeric;
        char fmt[16];
        double *buf = NULL;
        if (rank >= 1 && rank <= 2) H5Sget_simple_extent_dims(sp, dims, NULL);
        t = d >= 0 ? H5Dget_type(d) : -1;
        numeric = t >= 0 && (H5Tget_class(t) == H5T_FLOAT || H5Tget_class(t) == H5T_INTEGER);
        get_attr_str(d, "silc-format", fmt, sizeof fmt);
        if (rank < 1 || rank > 2 || !numeric) {
            eng_error(E, "load: '%s' in '%s' is not a SILC value: a dataset must be a 1-D or 2-D array of numbers",
                      name, path);
        } else if (!strcmp(fmt, "band")) {
            int64_t kl, ku;
            if (get_attr_i64(d, "kl", &kl, 1) != 1 || get_attr_i64(d, "ku", &ku, 1) != 1 ||
                get_attr_i64(d, "shape", shape, 2) != 2 || kl < 0 || ku < 0 || rank != 2 ||
                dims[0] != (hsize_t)(kl + ku + 1) || dims[1] != (hsize_t)shape[1] || shape[0] < 0)
                eng_error(E, "load: '%s' in '%s' is not a SILC band value: it needs kl, ku and shape attributes "
                             "and kl+ku+1 rows of n columns", name, path);
            else if (!(v = val_band_new(shape[0], shape[1], kl, ku)))
                eng_error(E, "load: out of memory for '%s'", name);
        } else if (!(v = val_dense_new((int64_t)dims[0], (int64_t)dims[1]))) {
            eng_error(E, "load: out of memory for '%s'", name);
        }
        if (v && !(buf = malloc((size_t)(dims[0] * dims[1] > 0 ? dims[0] * dims[1] : 1) * sizeof *buf))) {
            val_release(v);
            v = NULL;
            eng_error(E, "load: out of memory reading '%s'", name);
        }
        if (v && dims[0] * dims[1] > 0 && H5Dread(d, H5T_NATIVE_DOUBLE, H5S_ALL, H5S_ALL, H5P_DEFAULT, buf) < 0) {
            val_release(v);
            v = NULL;
            eng_error(E, "load: reading '%s' in '%s' failed (H5Dread)", name, path);
        }
        if (v) { /* row-major (rows, n) into column-major */
            int64_t i, j, r = (int64_t)dims[0], c = (int64_t)dims[1];
            for (i = 0; i < r; i++)
                for (j = 0; j < c; j++) v->val[i + j * r] = buf[i * c + j];
        }
        free(buf);
        if (t >= 0) H5Tclose(t);
        if (sp >= 0) H5Sclose(sp);
        if (d >= 0) H5Dclose(d);
        return v;
    }
    eng_error(E, "load: '%s' in '%s' is not a SILC value (neither a dataset nor a group)", name, path);
    return NULL;
}

/* The names of file's root, for a load of everything. */
typedef struct root_names {
    char **names;
    size_t n, cap;
    int failed;
} root_names;

static herr_t add_name(hid_t g, const char *name, const H5L_info_t *info, void *user)
{
    root_names *r = user;
    (void)g, (void)info;
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

int h5_load(silc_engine *E, const char *path, const char *const *names, size_t n)
{
    root_names all = {NULL, 0, 0, 0};
    silc_value **got = NULL, **olds = NULL;
    char fdpath[64];
    cfg_file in;
    hid_t file;
    size_t i, k, count = n;
    int rc = 0;
    H5Eset_auto2(H5E_DEFAULT, NULL, NULL);
    if (cfg_file_read(E, "load", path, &in)) return -1;
    util_fd_path(in.fd, fdpath, sizeof fdpath);
    if (H5Fis_hdf5(fdpath) <= 0) {
        cfg_file_close(&in);
        return eng_error(E, "load: '%s' is not an HDF5 file", path);
    }
    file = H5Fopen(fdpath, H5F_ACC_RDONLY, H5P_DEFAULT);
    cfg_file_close(&in); /* HDF5 holds its own descriptor of the same file */
    if (file < 0) return eng_error(E, "load: cannot open '%s' (H5Fopen)", path);
    if (!n) {
        if (H5Literate(file, H5_INDEX_NAME, H5_ITER_INC, NULL, add_name, &all) < 0 || all.failed)
            rc = eng_error(E, "load: cannot list '%s'", path);
        names = (const char *const *)all.names;
        count = all.n;
    }
    for (i = 0; !rc && i < count; i++)
        if (!util_is_name(names[i]))
            rc = eng_error(E, "load: '%s' in '%s' is not a name SILC can bind (a letter or '_', then letters, "
                              "digits and '_')", names[i], path);
    if (!rc && (!(got = calloc(count ? count : 1, sizeof *got)) || !(olds = calloc(count ? count : 1, sizeof *olds))))
        rc = eng_error(E, "load: out of memory");
    for (i = 0; !rc && i < count; i++)
        if (!(got[i] = load_one(E, file, path, names[i]))) rc = -1;
    H5Fclose(file);
    /* Every value read: now they are bound.  Only a new name can fail to
     * bind (out of memory); then the names bound so far get back what they
     * held (rebinding never allocates) or go. */
    for (i = 0; !rc && i < count; i++) {
        silc_value *old = store_get(&E->store, names[i]);
        if (old) val_retain(old);
        if (store_set(&E->store, names[i], got[i])) {
            val_release(old);
            while (i-- > 0) {
                silc_value *prev = olds[i];
                if (prev) store_set(&E->store, names[i], prev);
                else store_remove(&E->store, names[i]);
            }
            rc = eng_error(E, "load: out of memory binding the values of '%s'", path);
            break;
        }
        olds[i] = old;
    }
    for (i = 0; !rc && i < count; i++) eng_info_remove(E, names[i]);
    for (k = 0; olds && k < count; k++) val_release(olds[k]);
    free(olds);
    for (k = 0; got && k < count; k++) val_release(got[k]);
    free(got);
    for (k = 0; k < all.n; k++) free(all.names[k]);
    free(all.names);
    return rc;
}
#endif
