/*
 * h5file.c -- libsilc_h5.so: every HDF5 call of `save` and `load`, opened by
 * libsilc on first use (silc_h5.h says why and how).  The layouts, which
 * other tools read without SILC (h5py, scipy, anndata, Octave, MATLAB;
 * docs/hdf5.md):
 *
 *   dense m x n   a 2-D dataset of HDF5 shape (n, m) holding the column-major
 *                 array, with attribute MATLAB_class = "double": MATLAB
 *                 -v7.3's layout, which Octave's load -hdf5 (it reverses
 *                 HDF5's dimensions) reads as m x n; h5py/numpy read it as
 *                 (n, m), and the attribute says to transpose.  A dataset
 *                 without the attribute (h5py's, scipy's) is read row-major:
 *                 shape (m, n), row i = row i
 *   CSR           a group with datasets data, indices and indptr (int64,
 *                 0-based) and an attribute shape = (m, n); also
 *                 encoding-type = "csr_matrix", as anndata writes it
 *   band          a 2-D dataset of shape (kl+ku+1, n), LAPACK's band
 *                 storage, with attributes silc-format = "band", kl, ku and
 *                 shape = (m, n)
 *
 * Numbers are float64; a complex value's are the compound {r: float64, i:
 * float64} h5py writes for numpy's complex128.  load reads any integer or
 * float dataset as real, and a compound of exactly two float32 or float64
 * members named r and i as complex (h5py's complex64 is promoted); a
 * compound with other members is another program's record (skipped by a
 * load of the whole file), and one named r, i whose members are not floats
 * is refused.
 *
 * A file is input: it may be crafted.  Every object is read through these
 * checks (docs/security.md, "Values handed to SILC"):
 *   - links: only hard and soft links are followed, and no open follows an
 *     external link (the access lists refuse traversal), so a name cannot
 *     make SILC open another file;
 *   - storage: a dataset with external storage (H5Pset_external: raw data
 *     in some other file) or a virtual one (mapped from other datasets or
 *     files) is refused, naming it;
 *   - claims: describe reports the shape an object announces (its
 *     dataspace, its shape, kl and ku attributes) for the core to check
 *     (val_parts_claim: overflow, the value limit; the session budget)
 *     before anything is allocated, and read describes the object again
 *     and refuses it unless it is the claim the arrays were made for;
 *   - indices: indptr and indices must be integer datasets (a float index
 *     would be truncated) and attributes integers.  The CSR arrays
 *     themselves are checked by the core, as a PUT's.
 */
#define _POSIX_C_SOURCE 200809L
#include "silc_h5.h"

#include <hdf5.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#if defined(__GNUC__)
#define H5M_EXPORT __attribute__((visibility("default")))
#define H5M_PRINTF(a, b) __attribute__((format(printf, a, b)))
#else
#define H5M_EXPORT
#define H5M_PRINTF(a, b)
#endif

/* The attribute that marks a column-major dense dataset (MATLAB -v7.3's). */
#define H5_COLUMN_MAJOR_ATTR "MATLAB_class"

/* The property lists of a load: link, group and dataset access, each
 * refusing external links. */
typedef struct h5_access {
    hid_t link, group, dataset;
} h5_access;

struct silc_h5_file {
    hid_t id;
    char *path;                 /* the user's name of the file, for messages */
    h5_access acc;              /* load only */
};

static int fail(char *err, size_t errlen, const char *fmt, ...) H5M_PRINTF(3, 4);
static int fail(char *err, size_t errlen, const char *fmt, ...)
{
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(err, errlen, fmt, ap);
    va_end(ap);
    return -1;
}

/* ---- types ----------------------------------------------------------------------- */

/* The compound {r, i} of two doubles: the memory layout of a complex
 * entry (2 doubles, re then im) and, little-endian, what h5py writes. */
static hid_t complex_type(hid_t member)
{
    hid_t t = H5Tcreate(H5T_COMPOUND, 2 * sizeof(double));
    if (t >= 0 && (H5Tinsert(t, "r", 0, member) < 0 || H5Tinsert(t, "i", sizeof(double), member) < 0)) {
        H5Tclose(t);
        t = -1;
    }
    return t;
}

/* What the numbers of dataset d are: 0 real, 1 complex ({r, i} of
 * floats), or -1 with err: *foreign set when they are no numbers SILC
 * knows (strings, records of other members), left 0 when the compound is
 * named r, i but is no complex number. */
static int element_kind(hid_t d, const char *what, const char *path, int *foreign, char *err, size_t errlen)
{
    hid_t t = H5Dget_type(d);
    H5T_class_t cls = t >= 0 ? H5Tget_class(t) : H5T_NO_CLASS;
    int rc = -1, k;
    if (cls == H5T_FLOAT || cls == H5T_INTEGER) {
        rc = 0;
    } else if (cls == H5T_COMPOUND) {
        int nm = H5Tget_nmembers(t), named = nm == 2;
        char found[160] = "";
        for (k = 0; k < nm && k < 8; k++) {
            char *mn = H5Tget_member_name(t, (unsigned)k);
            if (!mn || (strcmp(mn, "r") && strcmp(mn, "i"))) named = 0;
            snprintf(found + strlen(found), sizeof found - strlen(found), "%s%s", k ? ", " : "", mn ? mn : "?");
            if (mn) H5free_memory(mn);
        }
        if (nm > 8) snprintf(found + strlen(found), sizeof found - strlen(found), ", ...");
        if (named) { /* two members, each r or i: distinct, or both the same name */
            char *m0 = H5Tget_member_name(t, 0), *m1 = H5Tget_member_name(t, 1);
            named = m0 && m1 && strcmp(m0, m1) != 0;
            if (m0) H5free_memory(m0);
            if (m1) H5free_memory(m1);
        }
        if (!named) {
            *foreign = 1;
            fail(err, errlen, "load: %s in '%s' is not a SILC value: a compound dataset must be a complex number as "
                              "h5py writes it, members exactly r and i (it has: %s)", what, path, found);
        } else {
            rc = 1;
            for (k = 0; k < 2 && rc == 1; k++) {
                hid_t mt = H5Tget_member_type(t, (unsigned)k);
                size_t size = mt >= 0 ? H5Tget_size(mt) : 0;
                if (mt < 0 || H5Tget_class(mt) != H5T_FLOAT || (size != 4 && size != 8))
                    rc = fail(err, errlen, "load: %s in '%s' is a compound {r, i} whose members are not both float32 "
                                           "or float64 (complex64 or complex128 as h5py writes them): refused",
                              what, path);
                if (mt >= 0) H5Tclose(mt);
            }
        }
    } else {
        *foreign = 1;
        fail(err, errlen, "load: %s in '%s' is not a SILC value: a dataset must be a 1-D or 2-D array of numbers",
             what, path);
    }
    if (t >= 0) H5Tclose(t);
    return rc;
}

/* ---- attributes -------------------------------------------------------------------- */

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

/* ---- save ---------------------------------------------------------------------------- */

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

/* m x n column-major entries of width w doubles (ld rows) as a row-major
 * (m, n) array, malloc'd. */
static double *row_major(const double *a, int64_t m, int64_t n, int64_t ld, int w)
{
    double *t = malloc((size_t)(m * n > 0 ? m * n : 1) * (size_t)w * sizeof *t);
    int64_t i, j;
    if (t)
        for (i = 0; i < m; i++)
            for (j = 0; j < n; j++) memcpy(t + (i * n + j) * w, a + (i + j * ld) * w, (size_t)w * sizeof *t);
    return t;
}

static silc_h5_file *file_new(hid_t id, const char *path)
{
    silc_h5_file *f = calloc(1, sizeof *f);
    if (!f || !(f->path = malloc(strlen(path) + 1))) {
        free(f);
        return NULL;
    }
    strcpy(f->path, path);
    f->id = id;
    f->acc.link = f->acc.group = f->acc.dataset = -1;
    return f;
}

static void file_free(silc_h5_file *f)
{
    if (f->acc.link >= 0) H5Pclose(f->acc.link);
    if (f->acc.group >= 0) H5Pclose(f->acc.group);
    if (f->acc.dataset >= 0) H5Pclose(f->acc.dataset);
    free(f->path);
    free(f);
}

static silc_h5_file *h5m_create(const char *fd_path, const char *path, char *err, size_t errlen)
{
    hid_t id;
    silc_h5_file *f;
    H5Eset_auto2(H5E_DEFAULT, NULL, NULL); /* errors are ours to report */
    id = H5Fcreate(fd_path, H5F_ACC_TRUNC, H5P_DEFAULT, H5P_DEFAULT);
    if (id < 0) return fail(err, errlen, "save: cannot create '%s' (H5Fcreate)", path), NULL;
    if (!(f = file_new(id, path))) {
        H5Fclose(id);
        fail(err, errlen, "save: out of memory creating '%s'", path);
    }
    return f;
}

static int h5m_close(silc_h5_file *f, char *err, size_t errlen)
{
    int rc = 0;
    if (H5Fclose(f->id) < 0) rc = fail(err, errlen, "save: closing '%s' failed (H5Fclose)", f->path);
    file_free(f);
    return rc;
}

static int h5m_write(silc_h5_file *f, const char *name, const silc_h5_value *v, char *err, size_t errlen)
{
    int64_t shape[2] = {v->m, v->n};
    int w = v->is_complex ? 2 : 1, rc = -1;
    hid_t ftype = v->is_complex ? complex_type(H5T_IEEE_F64LE) : H5Tcopy(H5T_IEEE_F64LE);
    hid_t mtype = v->is_complex ? complex_type(H5T_NATIVE_DOUBLE) : H5Tcopy(H5T_NATIVE_DOUBLE);
    hid_t obj = -1;
    if (ftype < 0 || mtype < 0) {
        rc = fail(err, errlen, "save: out of memory writing '%s' (HDF5 types)", name);
    } else if (v->format == SILC_H5_CSR) {
        hsize_t nz = (hsize_t)v->nnz, np = (hsize_t)v->m + 1;
        hid_t d;
        obj = H5Gcreate2(f->id, name, H5P_DEFAULT, H5P_DEFAULT, H5P_DEFAULT);
        if (obj < 0) {
            rc = fail(err, errlen, "save: H5Gcreate2 failed for '%s'", name);
        } else {
            rc = 0;
            if ((d = write_dataset(obj, "data", ftype, mtype, 1, &nz, v->val)) < 0) rc = -1;
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
            H5Gclose(obj);
            if (rc) fail(err, errlen, "save: writing '%s' failed (HDF5)", name);
        }
    } else {
        int band = v->format == SILC_H5_BAND;
        int64_t rows = band ? v->kl + v->ku + 1 : v->m;
        /* band: LAPACK's storage row-major, (kl+ku+1, n); dense: the
         * column-major array as HDF5 shape (n, m) (see the top) */
        hsize_t dims[2] = {(hsize_t)(band ? rows : v->n), (hsize_t)(band ? v->n : rows)};
        double *t = band ? row_major(v->val, rows, v->n, rows, w) : NULL;
        static const double none[2] = {0, 0};
        if (band && !t) {
            rc = fail(err, errlen, "save: out of memory writing '%s'", name);
        } else {
            obj = write_dataset(f->id, name, ftype, mtype, 2, dims, band ? t : v->val ? v->val : none);
            if (obj < 0) {
                rc = fail(err, errlen, "save: H5Dcreate2/H5Dwrite failed for '%s'", name);
            } else {
                rc = 0;
                if (band && (put_attr_str(obj, "silc-format", "band") || put_attr_i64(obj, "kl", &v->kl, 1) ||
                             put_attr_i64(obj, "ku", &v->ku, 1) || put_attr_i64(obj, "shape", shape, 2)))
                    rc = -1;
                if (!band && put_attr_str(obj, H5_COLUMN_MAJOR_ATTR, "double")) rc = -1;
                H5Dclose(obj);
                if (rc) fail(err, errlen, "save: writing '%s' failed (HDF5)", name);
            }
        }
        free(t);
    }
    if (ftype >= 0) H5Tclose(ftype);
    if (mtype >= 0) H5Tclose(mtype);
    return rc;
}

/* ---- load ---------------------------------------------------------------------------- */

/* External links are never traversed while loading. */
static herr_t refuse_external_link(const char *parent_file, const char *parent_group, const char *child_file,
                                   const char *child_object, unsigned *flags, hid_t fapl, void *op_data)
{
    (void)parent_file, (void)parent_group, (void)child_file, (void)child_object, (void)flags, (void)fapl,
        (void)op_data;
    return -1;
}

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

static silc_h5_file *h5m_open(const char *fd_path, const char *path, char *err, size_t errlen)
{
    hid_t id;
    silc_h5_file *f;
    H5Eset_auto2(H5E_DEFAULT, NULL, NULL);
    if (H5Fis_hdf5(fd_path) <= 0) return fail(err, errlen, "load: '%s' is not an HDF5 file", path), NULL;
    id = H5Fopen(fd_path, H5F_ACC_RDONLY, H5P_DEFAULT);
    if (id < 0) return fail(err, errlen, "load: cannot open '%s' (H5Fopen)", path), NULL;
    if (!(f = file_new(id, path)) || access_open(&f->acc)) {
        if (f) file_free(f);
        H5Fclose(id);
        return fail(err, errlen, "load: out of memory (HDF5 property lists)"), NULL;
    }
    return f;
}

static int h5m_close_read(silc_h5_file *f)
{
    int rc = H5Fclose(f->id) < 0 ? -1 : 0;
    file_free(f);
    return rc;
}

/* The names of the root group, in name order, to a callback. */
typedef struct name_walk {
    int (*each)(void *ctx, const char *name);
    void *ctx;
    int stopped;
} name_walk;

static herr_t walk_name(hid_t g, const char *name, const H5L_info_t *info, void *user)
{
    name_walk *w = user;
    (void)g, (void)info;
    if (w->each(w->ctx, name)) return (w->stopped = 1), -1;
    return 0;
}

static int h5m_each(silc_h5_file *f, int (*each)(void *ctx, const char *name), void *ctx, char *err, size_t errlen)
{
    name_walk w = {each, ctx, 0};
    if (H5Literate(f->id, H5_INDEX_NAME, H5_ITER_INC, NULL, walk_name, &w) < 0 || w.stopped)
        return fail(err, errlen, "load: cannot list '%s'", f->path);
    return 0;
}

/* 0 when the link name in loc stays in this file (hard or soft), else -1
 * with err naming it (what: "'A'" or "'A/indices'"). */
static int link_allowed(hid_t loc, const char *name, const char *what, const char *path, char *err, size_t errlen)
{
    H5L_info_t li;
    if (H5Lget_info(loc, name, &li, H5P_DEFAULT) < 0)
        return fail(err, errlen, "load: cannot read the link %s in '%s'", what, path);
    if (li.type == H5L_TYPE_EXTERNAL)
        return fail(err, errlen, "load: %s in '%s' is an external link (to an object of another file): refused",
                    what, path);
    if (li.type != H5L_TYPE_HARD && li.type != H5L_TYPE_SOFT)
        return fail(err, errlen, "load: %s in '%s' is a user-defined link: refused", what, path);
    return 0;
}

/* 0 when dataset d keeps its data in this file in an ordinary layout, else
 * -1 with err naming it. */
static int storage_allowed(hid_t d, const char *what, const char *path, char *err, size_t errlen)
{
    hid_t dcpl = H5Dget_create_plist(d);
    int external, rc = 0;
    H5D_layout_t layout;
    if (dcpl < 0) return fail(err, errlen, "load: cannot read how %s in '%s' is stored", what, path);
    external = H5Pget_external_count(dcpl);
    layout = H5Pget_layout(dcpl);
    if (external != 0)
        rc = fail(err, errlen, "load: %s in '%s' has external storage (its raw data lives in another file): refused",
                  what, path);
    else if (layout == H5D_VIRTUAL)
        rc = fail(err, errlen, "load: %s in '%s' is a virtual dataset (mapped from other datasets or files): refused",
                  what, path);
    else if (layout < 0)
        rc = fail(err, errlen, "load: cannot read the layout of %s in '%s'", what, path);
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

/* The memory type of a value's numbers. */
static hid_t number_type(int is_complex)
{
    return is_complex ? complex_type(H5T_NATIVE_DOUBLE) : H5Tcopy(H5T_NATIVE_DOUBLE);
}

/* CSR: the group g holding data, indices, indptr and a shape attribute.
 * *foreign is set when g is not laid out as a SILC value at all (another
 * program's group), as opposed to a SILC value that is broken.  Its claim
 * goes to v; its arrays too when read is set (v's arrays made for that
 * claim). */
static int load_csr(silc_h5_file *f, hid_t g, const char *name, int *foreign, silc_h5_value *v, int read,
                    char *err, size_t errlen)
{
    static const char *const parts[3] = {"data", "indices", "indptr"};
    const char *path = f->path;
    hid_t d[3] = {-1, -1, -1};
    hssize_t len[3] = {-1, -1, -1};
    int64_t shape[2];
    char what[3][300];
    int k, rc = 0, is_complex = 0;
    if (get_attr_i64(g, "shape", shape, 2) != 2 || shape[0] < 0 || shape[1] < 0) {
        *foreign = 1;
        return fail(err, errlen, "load: '%s' in '%s' is not a SILC value: a group needs datasets data, indices, "
                                 "indptr and an integer shape attribute (m, n)", name, path);
    }
    for (k = 0; !rc && k < 3; k++) {
        hid_t sp;
        snprintf(what[k], sizeof what[k], "'%s/%s'", name, parts[k]);
        if (H5Lexists(g, parts[k], f->acc.link) <= 0) {
            *foreign = 1;
            rc = fail(err, errlen, "load: '%s' in '%s' is not a SILC value: a group needs datasets data, indices, "
                                   "indptr and a shape attribute (%s is missing)", name, path, what[k]);
            break;
        }
        if ((rc = link_allowed(g, parts[k], what[k], path, err, errlen))) break;
        if ((d[k] = H5Dopen2(g, parts[k], f->acc.dataset)) < 0) {
            rc = fail(err, errlen, "load: cannot open %s in '%s'", what[k], path);
            break;
        }
        if ((rc = storage_allowed(d[k], what[k], path, err, errlen))) break;
        sp = H5Dget_space(d[k]);
        if (sp < 0 || H5Sget_simple_extent_ndims(sp) != 1)
            rc = fail(err, errlen, "load: %s in '%s' must be a 1-D dataset", what[k], path);
        else
            len[k] = H5Sget_simple_extent_npoints(sp);
        if (sp >= 0) H5Sclose(sp);
        if (!rc && k > 0 && dataset_class(d[k]) != H5T_INTEGER)
            rc = fail(err, errlen, "load: %s in '%s' is not an integer dataset: indices must be integers "
                                   "(a float index would be truncated)", what[k], path);
        if (!rc && k == 0) { /* a broken SILC value, never another program's: *foreign stays */
            int not_numbers = 0;
            is_complex = element_kind(d[k], what[k], path, &not_numbers, err, errlen);
            if (is_complex < 0 && dataset_class(d[k]) != H5T_COMPOUND)
                rc = fail(err, errlen, "load: %s in '%s' must hold numbers", what[k], path);
            else if (is_complex < 0)
                rc = -1;
        }
    }
    if (!rc && len[1] != len[0])
        rc = fail(err, errlen, "load: '%s' in '%s': indices has %lld entries but data has %lld", name, path,
                  (long long)len[1], (long long)len[0]);
    if (!rc && len[2] != shape[0] + 1)
        rc = fail(err, errlen, "load: '%s' in '%s': indptr has %lld entries but shape (%lld, %lld) needs %lld",
                  name, path, (long long)len[2], (long long)shape[0], (long long)shape[1], (long long)shape[0] + 1);
    if (!rc && read) {
        hid_t mt = number_type(is_complex);
        if (v->format != SILC_H5_CSR || v->is_complex != is_complex || v->m != shape[0] || v->n != shape[1] ||
            v->nnz != len[0])
            rc = fail(err, errlen, "load: '%s' in '%s' changed while it was being loaded", name, path);
        else if (mt < 0 ||
                 (v->nnz > 0 && (H5Dread(d[0], mt, H5S_ALL, H5S_ALL, H5P_DEFAULT, v->val) < 0 ||
                                 H5Dread(d[1], H5T_NATIVE_INT64, H5S_ALL, H5S_ALL, H5P_DEFAULT, v->colind) < 0)) ||
                 H5Dread(d[2], H5T_NATIVE_INT64, H5S_ALL, H5S_ALL, H5P_DEFAULT, v->rowptr) < 0)
            rc = fail(err, errlen, "load: reading '%s' in '%s' failed (H5Dread)", name, path);
        if (mt >= 0) H5Tclose(mt);
    } else if (!rc) {
        memset(v, 0, sizeof *v);
        v->format = SILC_H5_CSR, v->is_complex = is_complex, v->m = shape[0], v->n = shape[1], v->nnz = len[0];
    }
    for (k = 0; k < 3; k++)
        if (d[k] >= 0) H5Dclose(d[k]);
    return rc;
}

/* Dense (a 1-D or 2-D dataset of numbers: row-major, or column-major with
 * the MATLAB_class attribute) or band (silc-format = "band"); foreign, v
 * and read as load_csr's. */
static int load_dataset(silc_h5_file *f, hid_t d, const char *name, int *foreign, silc_h5_value *v, int read,
                        char *err, size_t errlen)
{
    const char *path = f->path;
    hid_t sp = H5Dget_space(d), mt;
    hsize_t dims[2] = {0, 1};
    int rank = sp >= 0 ? H5Sget_simple_extent_ndims(sp) : -1, is_complex, w, rc = 0;
    char fmt[16], what[300];
    silc_h5_value claim;
    double *buf = NULL;
    if (sp >= 0) H5Sclose(sp);
    snprintf(what, sizeof what, "'%s'", name);
    if ((is_complex = element_kind(d, what, path, foreign, err, errlen)) < 0) return -1;
    if (rank < 1 || rank > 2)
        return *foreign = 1, fail(err, errlen, "load: '%s' in '%s' is not a SILC value: a dataset must be a 1-D or "
                                               "2-D array of numbers", name, path);
    if (storage_allowed(d, what, path, err, errlen)) return -1;
    sp = H5Dget_space(d);
    H5Sget_simple_extent_dims(sp, dims, NULL);
    H5Sclose(sp);
    if (dims[0] > INT64_MAX || dims[1] > INT64_MAX)
        return fail(err, errlen, "load: '%s' in '%s' has more rows or columns than SILC can index", name, path);
    get_attr_str(d, "silc-format", fmt, sizeof fmt);
    memset(&claim, 0, sizeof claim);
    claim.is_complex = is_complex;
    if (!strcmp(fmt, "band")) {
        int64_t kl, ku, shape[2];
        if (get_attr_i64(d, "kl", &kl, 1) != 1 || get_attr_i64(d, "ku", &ku, 1) != 1 ||
            get_attr_i64(d, "shape", shape, 2) != 2 || kl < 0 || ku < 0 || kl > INT32_MAX || ku > INT32_MAX ||
            rank != 2 || dims[0] != (hsize_t)(kl + ku + 1) || dims[1] != (hsize_t)shape[1] || shape[0] < 0)
            return fail(err, errlen, "load: '%s' in '%s' is not a SILC band value: it needs integer kl, ku and shape "
                                     "attributes and kl+ku+1 rows of n columns", name, path);
        claim.format = SILC_H5_BAND, claim.m = shape[0], claim.n = shape[1], claim.kl = kl, claim.ku = ku;
    } else {
        char order[16];
        get_attr_str(d, H5_COLUMN_MAJOR_ATTR, order, sizeof order);
        claim.column_major = rank == 2 && order[0];
        claim.format = SILC_H5_DENSE, claim.m = (int64_t)dims[claim.column_major];
        claim.n = (int64_t)dims[!claim.column_major];
    }
    if (!read) {
        *v = claim;
        return 0;
    }
    if (v->format != claim.format || v->is_complex != claim.is_complex || v->m != claim.m || v->n != claim.n ||
        v->kl != claim.kl || v->ku != claim.ku || v->column_major != claim.column_major)
        return fail(err, errlen, "load: '%s' in '%s' changed while it was being loaded", name, path);
    /* The claim was checked by the core against the value limit before v's
     * arrays were made; the row-major buffer is the same size. */
    w = is_complex ? 2 : 1;
    if (!claim.column_major &&
        !(buf = malloc((size_t)(dims[0] * dims[1] > 0 ? dims[0] * dims[1] : 1) * (size_t)w * sizeof *buf)))
        return fail(err, errlen, "load: out of memory reading '%s'", name);
    if ((mt = number_type(is_complex)) < 0) rc = fail(err, errlen, "load: out of memory reading '%s'", name);
    if (!rc && dims[0] * dims[1] > 0 &&
        H5Dread(d, mt, H5S_ALL, H5S_ALL, H5P_DEFAULT, claim.column_major ? v->val : buf) < 0)
        rc = fail(err, errlen, "load: reading '%s' in '%s' failed (H5Dread)", name, path);
    if (!rc && !claim.column_major) { /* row-major (rows, n) into column-major */
        int64_t i, j, r = (int64_t)dims[0], c = (int64_t)dims[1];
        for (i = 0; i < r; i++)
            for (j = 0; j < c; j++) memcpy(v->val + (i + j * r) * w, buf + (i * c + j) * w, (size_t)w * sizeof *buf);
    }
    if (mt >= 0) H5Tclose(mt);
    free(buf);
    return rc;
}

/* The claim of the object name (read 0) or its arrays too (read 1). */
static int load_one(silc_h5_file *f, const char *name, int *foreign, silc_h5_value *v, int read, char *err,
                    size_t errlen)
{
    H5O_info_t info;
    const char *path = f->path;
    int rc = -1;
    char what[300];
    snprintf(what, sizeof what, "'%s'", name);
    if (H5Lexists(f->id, name, f->acc.link) <= 0) {
        fail(err, errlen, "load: '%s' is not in '%s'", name, path);
    } else if (link_allowed(f->id, name, what, path, err, errlen) == 0) {
        if (H5Oget_info_by_name2(f->id, name, &info, H5O_INFO_BASIC, f->acc.link) < 0) {
            fail(err, errlen, "load: cannot read '%s' in '%s'", name, path);
        } else if (info.type == H5O_TYPE_GROUP) {
            hid_t g = H5Gopen2(f->id, name, f->acc.group);
            if (g < 0) fail(err, errlen, "load: cannot open '%s' in '%s'", name, path);
            else rc = load_csr(f, g, name, foreign, v, read, err, errlen);
            if (g >= 0) H5Gclose(g);
        } else if (info.type == H5O_TYPE_DATASET) {
            hid_t d = H5Dopen2(f->id, name, f->acc.dataset);
            if (d < 0) fail(err, errlen, "load: cannot open '%s' in '%s'", name, path);
            else rc = load_dataset(f, d, name, foreign, v, read, err, errlen);
            if (d >= 0) H5Dclose(d);
        } else {
            *foreign = 1;
            fail(err, errlen, "load: '%s' in '%s' is not a SILC value (neither a dataset nor a group)", name, path);
        }
    }
    return rc;
}

static int h5m_describe(silc_h5_file *f, const char *name, silc_h5_value *v, int *foreign, char *err, size_t errlen)
{
    return load_one(f, name, foreign, v, 0, err, errlen);
}

static int h5m_read(silc_h5_file *f, const char *name, silc_h5_value *v, char *err, size_t errlen)
{
    int foreign = 0;
    return load_one(f, name, &foreign, v, 1, err, errlen);
}

/* close_file serves both: a file opened for reading has its access lists. */
static int h5m_close_any(silc_h5_file *f, char *err, size_t errlen)
{
    return f->acc.link >= 0 ? h5m_close_read(f) : h5m_close(f, err, errlen);
}

H5M_EXPORT const silc_h5_api *silc_h5_module(void);
H5M_EXPORT const silc_h5_api *silc_h5_module(void)
{
    static const silc_h5_api api = {
        sizeof(silc_h5_api), SILC_H5_VERSION, h5m_create, h5m_write, h5m_close_any,
        h5m_open, h5m_each, h5m_describe, h5m_read,
    };
    return &api;
}
