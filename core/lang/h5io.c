/*
 * h5io.c -- `save "file.h5" [names]` and `load "file.h5" [names]`: a
 * session's values in HDF5, in the layouts other tools read without SILC
 * (h5py, scipy, anndata):
 *
 *   dense m x n   a 2-D float64 dataset of HDF5 shape (n, m) holding the
 *                 column-major array, with attribute MATLAB_class = "double":
 *                 MATLAB -v7.3's layout, which Octave's load -hdf5 (it
 *                 reverses HDF5's dimensions) reads as m x n; h5py/numpy
 *                 read it as (n, m), and the attribute says to transpose
 *                 (docs/hdf5.md).  A dataset without the attribute (h5py's,
 *                 scipy's) is read row-major: shape (m, n), row i = row i
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
 * object that is none of the layouts is an error naming it when it was
 * asked for by name; a load of the whole file skips it (a file may hold
 * other programs' groups and strings) and warns with the list of what it
 * skipped and why.  Built only
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
    hid_t t = H5Aget_type(a);
    /* Integers only: a float shape or width would be truncated. */
    int integer = t >= 0 && H5Tget_class(t) == H5T_INTEGER;
    if (t >= 0) H5Tclose(t);
    sp = H5Aget_space(a);
    n = sp >= 0 ? H5Sget_simple_extent_npoints(sp) : -1;
    if (integer && n >= 1 && n <= count && H5Aread(a, H5T_NATIVE_INT64, v) >= 0) rc = (int)n;
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

/* The attribute that marks a column-major dense dataset (MATLAB -v7.3's). */
#define H5_COLUMN_MAJOR_ATTR "MATLAB_class"

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
        /* band: LAPACK's storage row-major, (kl+ku+1, n); dense: the
         * column-major array as HDF5 shape (n, m) (see the top) */
        hsize_t dims[2] = {(hsize_t)(band ? rows : v->n), (hsize_t)(band ? v->n : rows)};
        double *t = band ? row_major(v->val, rows, v->n, rows) : NULL;
        if (band && !t) return eng_error(E, "save: out of memory writing '%s'", name);
        obj = write_dataset(file, name, H5T_IEEE_F64LE, H5T_NATIVE_DOUBLE, 2, dims,
                            band ? t : v->val ? v->val : (const double[1]){0});
        free(t);
        if (obj < 0) return eng_error(E, "save: H5Dcreate2/H5Dwrite failed for '%s'", name);
        rc = 0;
        if (band && (put_attr_str(obj, "silc-format", "band") || put_attr_i64(obj, "kl", &v->kl, 1) ||
                     put_attr_i64(obj, "ku", &v->ku, 1) || put_attr_i64(obj, "shape", shape, 2)))
            rc = -1;
        if (!band && put_attr_str(obj, H5_COLUMN_MAJOR_ATTR, "double")) rc = -1;
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
        if (v->field == SILC_FIELD_COMPLEX) { /* refused before the file is touched */
            free(all);
            return eng_error(E, "save: '%s' is complex, and complex values are not saved to HDF5 yet (issue 31: "
                                "h5py's compound r/i layout); save real(%s) and imag(%s)", names[i], names[i],
                             names[i]);
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

/* ---- load ----------------------------------------------------------------------
 * A file is input: it may be crafted.  Every object is read through these
 * checks (docs/security.md, "Values handed to SILC"):
 *   - links: only hard and soft links are followed, and no open follows an
 *     external link (the access lists refuse traversal), so a name cannot
 *     make SILC open another file;
 *   - storage: a dataset with external storage (H5Pset_external: raw data
 *     in some other file) or a virtual one (mapped from other datasets or
 *     files) is refused, naming it;
 *   - claims: the shape an object announces (its dataspace, its shape, kl
 *     and ku attributes) is checked by the checker every value passes
 *     (val_parts_claim: overflow, the value limit) before anything is
 *     allocated or read, and the claims of everything the load binds,
 *     summed, against what silcd's session has left (val_budget_claim);
 *   - indices: indptr and indices must be integer datasets (a float index
 *     would be truncated) and attributes integers;
 *   - CSR arrays are read into the value itself and checked as a PUT's
 *     (val_parts_fill: indptr from 0, monotone, ending at len(data); columns
 *     in range and increasing). */

/* External links are never traversed while loading. */
static herr_t refuse_external_link(const char *parent_file, const char *parent_group, const char *child_file,
                                   const char *child_object, unsigned *flags, hid_t fapl, void *op_data)
{
    (void)parent_file, (void)parent_group, (void)child_file, (void)child_object, (void)flags, (void)fapl,
        (void)op_data;
    return -1;
}

/* The property lists of a load: link, group and dataset access, each
 * refusing external links. */
typedef struct h5_access {
    hid_t link, group, dataset;
} h5_access;

static int access_open(h5_access *a)
{
    a->link = H5Pcreate(H5P_LINK_ACCESS);
    a->group = H5Pcreate(H5P_GROUP_ACCESS);
    a->dataset = H5Pcreate(H5P_DATASET_ACCESS);
    if (a->link < 0 || a->group < 0 || a->dataset < 0 ||
        H5Pset_elink_cb(a->link, refuse_external_link, NULL) < 0 ||
        H5Pset_elink_cb(a->group, refuse_external_link, NULL) < 0 ||
        H5Pset_elink_cb(a->dataset, refuse_external_link, NULL) < 0)
        return -1;
    return 0;
}

static void access_close(h5_access *a)
{
    if (a->link >= 0) H5Pclose(a->link);
    if (a->group >= 0) H5Pclose(a->group);
    if (a->dataset >= 0) H5Pclose(a->dataset);
}

/* 0 when the link name in loc stays in this file (hard or soft), else -1
 * with E->err naming it (what: "'A'" or "'A/indices'"). */
static int link_allowed(silc_engine *E, hid_t loc, const char *name, const char *what, const char *path)
{
    H5L_info_t li;
    if (H5Lget_info(loc, name, &li, H5P_DEFAULT) < 0)
        return eng_error(E, "load: cannot read the link %s in '%s'", what, path);
    if (li.type == H5L_TYPE_EXTERNAL)
        return eng_error(E, "load: %s in '%s' is an external link (to an object of another file): refused",
                         what, path);
    if (li.type != H5L_TYPE_HARD && li.type != H5L_TYPE_SOFT)
        return eng_error(E, "load: %s in '%s' is a user-defined link: refused", what, path);
    return 0;
}

/* 0 when dataset d keeps its data in this file in an ordinary layout, else
 * -1 with E->err naming it. */
static int storage_allowed(silc_engine *E, hid_t d, const char *what, const char *path)
{
    hid_t dcpl = H5Dget_create_plist(d);
    int external, rc = 0;
    H5D_layout_t layout;
    if (dcpl < 0) return eng_error(E, "load: cannot read how %s in '%s' is stored", what, path);
    external = H5Pget_external_count(dcpl);
    layout = H5Pget_layout(dcpl);
    if (external != 0)
        rc = eng_error(E, "load: %s in '%s' has external storage (its raw data lives in another file): refused",
                       what, path);
    else if (layout == H5D_VIRTUAL)
        rc = eng_error(E, "load: %s in '%s' is a virtual dataset (mapped from other datasets or files): refused",
                       what, path);
    else if (layout < 0)
        rc = eng_error(E, "load: cannot read the layout of %s in '%s'", what, path);
    H5Pclose(dcpl);
    return rc;
}

/* The type class of dataset d (H5T_INTEGER, H5T_FLOAT, ...), or -1. */
static int dataset_class(hid_t d)
{
    hid_t t = H5Dget_type(d);
    int c = t >= 0 ? (int)H5Tget_class(t) : -1;
    if (t >= 0) H5Tclose(t);
    return c;
}

/* A checked claim, with the reason as "load: 'A' in 'f.h5': ..." */
static int claim_allowed(silc_engine *E, const val_parts *p, const char *name, const char *path)
{
    char why[512];
    if (val_parts_claim(p, why, sizeof why) == 0) return 0;
    return eng_error(E, "load: '%s' in '%s': %s", name, path, why);
}

/* CSR: the group g holding data, indices, indptr and a shape attribute.
 * *foreign is set when g is not laid out as a SILC value at all (another
 * program's group), as opposed to a SILC value that is broken.  Its checked
 * claim goes to *claim_out; the value to *out, unless out is NULL (the claim
 * alone: nothing allocated or read).  0, or -1 with E->err. */
static int load_csr(silc_engine *E, const h5_access *acc, hid_t g, const char *path, const char *name,
                    int *foreign, val_parts *claim_out, silc_value **out)
{
    static const char *const parts[3] = {"data", "indices", "indptr"};
    hid_t d[3] = {-1, -1, -1};
    hssize_t len[3] = {-1, -1, -1};
    int64_t shape[2];
    silc_value *v = NULL;
    val_parts claim;
    char what[3][300], why[512];
    int k, rc = 0;
    if (get_attr_i64(g, "shape", shape, 2) != 2 || shape[0] < 0 || shape[1] < 0) {
        *foreign = 1;
        return eng_error(E, "load: '%s' in '%s' is not a SILC value: a group needs datasets data, indices, "
                            "indptr and an integer shape attribute (m, n)", name, path);
    }
    for (k = 0; !rc && k < 3; k++) {
        hid_t sp;
        snprintf(what[k], sizeof what[k], "'%s/%s'", name, parts[k]);
        if (H5Lexists(g, parts[k], acc->link) <= 0) {
            *foreign = 1;
            rc = eng_error(E, "load: '%s' in '%s' is not a SILC value: a group needs datasets data, indices, "
                              "indptr and a shape attribute (%s is missing)", name, path, what[k]);
            break;
        }
        if ((rc = link_allowed(E, g, parts[k], what[k], path))) break;
        if ((d[k] = H5Dopen2(g, parts[k], acc->dataset)) < 0) {
            rc = eng_error(E, "load: cannot open %s in '%s'", what[k], path);
            break;
        }
        if ((rc = storage_allowed(E, d[k], what[k], path))) break;
        sp = H5Dget_space(d[k]);
        if (sp < 0 || H5Sget_simple_extent_ndims(sp) != 1)
            rc = eng_error(E, "load: %s in '%s' must be a 1-D dataset", what[k], path);
        else
            len[k] = H5Sget_simple_extent_npoints(sp);
        if (sp >= 0) H5Sclose(sp);
        if (!rc && k > 0 && dataset_class(d[k]) != H5T_INTEGER)
            rc = eng_error(E, "load: %s in '%s' is not an integer dataset: indices must be integers "
                              "(a float index would be truncated)", what[k], path);
        if (!rc && k == 0 && dataset_class(d[k]) != H5T_FLOAT && dataset_class(d[k]) != H5T_INTEGER)
            rc = eng_error(E, "load: %s in '%s' must hold numbers", what[k], path);
    }
    if (!rc && len[1] != len[0])
        rc = eng_error(E, "load: '%s' in '%s': indices has %lld entries but data has %lld", name, path,
                       (long long)len[1], (long long)len[0]);
    if (!rc && len[2] != shape[0] + 1)
        rc = eng_error(E, "load: '%s' in '%s': indptr has %lld entries but shape (%lld, %lld) needs %lld",
                       name, path, (long long)len[2], (long long)shape[0], (long long)shape[1],
                       (long long)shape[0] + 1);
    memset(&claim, 0, sizeof claim);
    claim.format = SILC_FMT_CSR, claim.m = shape[0], claim.n = shape[1], claim.nnz = len[0];
    /* The claim is checked before anything is allocated or read. */
    if (!rc) rc = claim_allowed(E, &claim, name, path);
    if (!rc) *claim_out = claim;
    if (!rc && out && !(v = val_new_unset(SILC_FMT_CSR, claim.m, claim.n, claim.nnz, 0, 0)))
        rc = eng_error(E, "load: out of memory for '%s'", name);
    if (!out) goto done;
    if (!rc && ((claim.nnz > 0 && (H5Dread(d[0], H5T_NATIVE_DOUBLE, H5S_ALL, H5S_ALL, H5P_DEFAULT, v->val) < 0 ||
                                   H5Dread(d[1], H5T_NATIVE_INT64, H5S_ALL, H5S_ALL, H5P_DEFAULT, v->colind) < 0)) ||
                H5Dread(d[2], H5T_NATIVE_INT64, H5S_ALL, H5S_ALL, H5P_DEFAULT, v->rowptr) < 0))
        rc = eng_error(E, "load: reading '%s' in '%s' failed (H5Dread)", name, path);
    if (!rc) { /* the arrays, in place, as a PUT's */
        claim.rowptr = v->rowptr, claim.colind = v->colind, claim.values = v->val;
        if (val_parts_fill(v, &claim, why, sizeof why)) rc = eng_error(E, "load: '%s' in '%s': %s", name, path, why);
    }
done:
    for (k = 0; k < 3; k++)
        if (d[k] >= 0) H5Dclose(d[k]);
    if (rc) val_release(v);
    else if (out) *out = v;
    return rc;
}

/* Dense (a 1-D or 2-D dataset of numbers: row-major, or column-major with
 * the MATLAB_class attribute) or band (silc-format = "band"); *foreign is
 * set when d is no array of numbers; claim and out as load_csr's. */
static int load_dataset(silc_engine *E, hid_t d, const char *path, const char *name, int *foreign,
                        val_parts *claim_out, silc_value **out)
{
    hid_t sp = H5Dget_space(d);
    hsize_t dims[2] = {0, 1};
    int rank = sp >= 0 ? H5Sget_simple_extent_ndims(sp) : -1, cls = dataset_class(d);
    char fmt[16], what[300];
    silc_value *v = NULL;
    val_parts claim;
    double *buf = NULL;
    int rc = 0, column_major = 0;
    if (sp >= 0) H5Sclose(sp);
    snprintf(what, sizeof what, "'%s'", name);
    if (rank < 1 || rank > 2 || (cls != H5T_FLOAT && cls != H5T_INTEGER))
        return *foreign = 1, eng_error(E, "load: '%s' in '%s' is not a SILC value: a dataset must be a 1-D or "
                                          "2-D array of numbers", name, path);
    if (storage_allowed(E, d, what, path)) return -1;
    sp = H5Dget_space(d);
    H5Sget_simple_extent_dims(sp, dims, NULL);
    H5Sclose(sp);
    if (dims[0] > INT64_MAX || dims[1] > INT64_MAX)
        return eng_error(E, "load: '%s' in '%s' has more rows or columns than SILC can index", name, path);
    get_attr_str(d, "silc-format", fmt, sizeof fmt);
    memset(&claim, 0, sizeof claim);
    if (!strcmp(fmt, "band")) {
        int64_t kl, ku, shape[2];
        if (get_attr_i64(d, "kl", &kl, 1) != 1 || get_attr_i64(d, "ku", &ku, 1) != 1 ||
            get_attr_i64(d, "shape", shape, 2) != 2 || kl < 0 || ku < 0 || kl > INT32_MAX || ku > INT32_MAX ||
            rank != 2 || dims[0] != (hsize_t)(kl + ku + 1) || dims[1] != (hsize_t)shape[1] || shape[0] < 0)
            return eng_error(E, "load: '%s' in '%s' is not a SILC band value: it needs integer kl, ku and shape "
                                "attributes and kl+ku+1 rows of n columns", name, path);
        claim.format = SILC_FMT_BAND, claim.m = shape[0], claim.n = shape[1], claim.kl = kl, claim.ku = ku;
    } else {
        char order[16];
        get_attr_str(d, H5_COLUMN_MAJOR_ATTR, order, sizeof order);
        column_major = rank == 2 && order[0];
        claim.format = SILC_FMT_DENSE, claim.m = (int64_t)dims[column_major], claim.n = (int64_t)dims[!column_major];
    }
    /* The claim (band: its rows too) before anything is allocated or read;
     * band storage is then stored diagonals times columns. */
    if (claim_allowed(E, &claim, name, path)) return -1;
    *claim_out = claim;
    if (!out) return 0;
    if (!(v = val_new_unset(claim.format, claim.m, claim.n, 0, claim.kl, claim.ku)) ||
        !(buf = malloc((size_t)(dims[0] * dims[1] > 0 ? dims[0] * dims[1] : 1) * sizeof *buf)))
        rc = eng_error(E, "load: out of memory reading '%s'", name);
    if (!rc && dims[0] * dims[1] > 0 && H5Dread(d, H5T_NATIVE_DOUBLE, H5S_ALL, H5S_ALL, H5P_DEFAULT, buf) < 0)
        rc = eng_error(E, "load: reading '%s' in '%s' failed (H5Dread)", name, path);
    if (!rc && column_major) { /* HDF5's (n, m) is the column-major m x n array */
        if (dims[0] * dims[1] > 0) memcpy(v->val, buf, (size_t)(dims[0] * dims[1]) * sizeof *buf);
    } else if (!rc) { /* row-major (rows, n) into column-major */
        int64_t i, j, r = (int64_t)dims[0], c = (int64_t)dims[1];
        for (i = 0; i < r; i++)
            for (j = 0; j < c; j++) v->val[i + j * r] = buf[i * c + j];
    }
    free(buf);
    if (rc) val_release(v);
    else *out = v;
    return rc;
}

/* The checked claim of the object name of file, and its value in *out
 * unless out is NULL (the claim alone, nothing read).  0, or -1 with
 * E->err naming it (*foreign set when the object is none of SILC's
 * layouts). */
static int load_one(silc_engine *E, hid_t file, const char *path, const char *name, int *foreign,
                    val_parts *claim, silc_value **out)
{
    H5O_info_t info;
    h5_access acc = {-1, -1, -1};
    int rc = -1;
    char what[300];
    snprintf(what, sizeof what, "'%s'", name);
    if (access_open(&acc)) {
        access_close(&acc);
        return eng_error(E, "load: out of memory (HDF5 property lists)");
    }
    if (H5Lexists(file, name, acc.link) <= 0) {
        eng_error(E, "load: '%s' is not in '%s'", name, path);
    } else if (link_allowed(E, file, name, what, path) == 0) {
        if (H5Oget_info_by_name2(file, name, &info, H5O_INFO_BASIC, acc.link) < 0) {
            eng_error(E, "load: cannot read '%s' in '%s'", name, path);
        } else if (info.type == H5O_TYPE_GROUP) {
            hid_t g = H5Gopen2(file, name, acc.group);
            if (g < 0) eng_error(E, "load: cannot open '%s' in '%s'", name, path);
            else rc = load_csr(E, &acc, g, path, name, foreign, claim, out);
            if (g >= 0) H5Gclose(g);
        } else if (info.type == H5O_TYPE_DATASET) {
            hid_t d = H5Dopen2(file, name, acc.dataset);
            if (d < 0) eng_error(E, "load: cannot open '%s' in '%s'", name, path);
            else rc = load_dataset(E, d, path, name, foreign, claim, out);
            if (d >= 0) H5Dclose(d);
        } else {
            *foreign = 1;
            eng_error(E, "load: '%s' in '%s' is not a SILC value (neither a dataset nor a group)", name, path);
        }
    }
    access_close(&acc);
    return rc;
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
    root_names all = {NULL, 0, 0, 0};
    skip_list skipped;
    silc_value **got = NULL, **olds = NULL;
    unsigned char *wanted = NULL; /* loaded, not skipped */
    char fdpath[64];
    cfg_file in;
    hid_t file;
    size_t i, k, count = n;
    double claimed = 0;
    int rc = 0;
    H5Eset_auto2(H5E_DEFAULT, NULL, NULL);
    skipped.count = 0;
    sb_init(&skipped.list);
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
    if (!rc && (!(got = calloc(count ? count : 1, sizeof *got)) || !(olds = calloc(count ? count : 1, sizeof *olds)) ||
                !(wanted = calloc(count ? count : 1, 1))))
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
        } else if (load_one(E, file, path, names[i], &foreign, &claim, NULL)) {
            rc = -1;
        } else {
            claimed += val_parts_bytes(&claim);
            wanted[i] = 1;
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
    for (i = 0; !rc && i < count; i++) {
        val_parts claim;
        int foreign = 0;
        if (wanted[i] && load_one(E, file, path, names[i], &foreign, &claim, &got[i])) rc = -1;
    }
    H5Fclose(file);
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
    free(wanted);
    for (k = 0; k < all.n; k++) free(all.names[k]);
    free(all.names);
    return rc;
}
#endif
