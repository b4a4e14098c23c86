/*
 * store.h -- the engine's data model (core/store/), the lowest layer that
 * knows a matrix: values and the store (value.c), and envelopes, their
 * public form (envelope.c).  Nothing here knows an engine.
 *
 * ---- values and the store (value.c)
 *
 * A value is an immutable m x n real or complex matrix (its field: a complex
 * value stores each entry as two doubles, real then imaginary, the layout of
 * C's double complex; silc_plugin.h) in one storage format (dense
 * column-major, sorted 0-based CSR, LAPACK band), reference counted, with a
 * process-unique id, lazily computed structural properties, and attachments
 * (derived data with a destructor: factorizations, converted copies) that die
 * with it.  Immutability is what makes attachments safe: `A` keeps its id and
 * its factorization until the name is rebound.  Values are built mutable by the
 * constructors below, filled, and then frozen by being handed to the store or
 * returned from an operation; nothing writes to a value after that, with one
 * exception that no one can observe: `x += ...` updates x's dense value in
 * place when the store's binding is its only reference and it has no
 * attachments (copy-on-write, eval.c), and then gives it a new id.
 *
 * The store maps names to values for one context.  Binding retains, rebinding
 * or clearing releases.
 */
#ifndef SILC_STORE_H
#define SILC_STORE_H

#include <stddef.h>
#include <stdint.h>

#include "silc_plugin.h"
#include "silc.h"

typedef struct val_attachment {
    char *key;
    void *data;
    void (*destroy)(void *);
    int64_t bytes;              /* the memory it holds, as charged (val_attach_charge); 0 = not known */
    int charged;                /* made by a plugin call the dispatcher measured: a plugin's state
                                   (a factorization), which val_attach_release may let go */
    uint64_t used;              /* when last set or looked up (a process-wide clock): least
                                   recently used goes first */
    struct val_attachment *next;
} val_attachment;

/* A row partition: rank r holds rows [starts[r], starts[r+1]).  Shared,
 * reference counted, by the values distributed the same way, so "same
 * layout" is one comparison (dist.h). */
typedef struct dist_part {
    int64_t refcount;
    int size;
    int64_t starts[];           /* size + 1 */
} dist_part;

/* Where a distributed value's whole copy is: the same on every rank. */
enum { DIST_WHOLE_NONE = 0, DIST_WHOLE_ROOT = 1, DIST_WHOLE_ALL = 2 };

/* What makes a value distributed (dist.c builds and reads it; value.c only
 * frees it).  The value itself then has no arrays: its m, n and format are
 * the whole value's, block holds this rank's rows (an ordinary value,
 * global column indices), and whole the gathered copy once one was needed,
 * on rank 0 (DIST_WHOLE_ROOT) or on every rank (DIST_WHOLE_ALL). */
typedef struct val_dist {
    struct dist_ctx *ctx;       /* the engine's communicator and counters */
    dist_part *part;
    struct silc_value *block;
    struct silc_value *whole;
    int where;
} val_dist;

struct silc_value {
    int64_t refcount;
    uint64_t id;
    int64_t m, n;
    int format;              /* enum silc_format */
    int field;               /* enum silc_field: complex values hold 2 doubles per entry in val */
    double *val;
    silc_index *rowptr, *colind;
    int64_t nnz;             /* csr: entries in use; dense m*n; band ld*n (entries, not doubles) */
    int64_t cap;             /* csr: capacity of colind/val, in entries */
    int64_t kl, ku, ld;
    int props_have;          /* SILC_PROPS_* bits: the parts of props that are valid */
    silc_props props;
    int scan_ready;          /* SCAN_FINITE: scan_nonfinite is known; SCAN_MAXABS: both */
    int scan_nonfinite;
    double scan_maxabs;
    val_attachment *attach;
    val_dist *dist;          /* NULL: the value is whole here (val_dist, below) */
    int64_t bindings;        /* names of a store bound to it (store_set, store_remove): a
                                cache holding a value no name holds pays for its arrays */
    uint64_t counted;        /* the last walk of lang/memo.c's accounting that counted its
                                attachments (so a value held twice is counted once) */
};

/* Doubles per entry of v's val: 1 real, 2 complex. */
static inline int val_width(const silc_value *v)
{
    return v->field == SILC_FIELD_COMPLEX ? 2 : 1;
}

/* Constructors: zero-filled; NULL on allocation failure or negative sizes.
 * The _complex ones make complex values, held to the same limits with 2
 * doubles an entry. */
silc_value *val_dense_new(int64_t m, int64_t n);
silc_value *val_csr_new(int64_t m, int64_t n, int64_t nnz_capacity);
silc_value *val_band_new(int64_t m, int64_t n, int64_t kl, int64_t ku);
silc_value *val_dense_new_complex(int64_t m, int64_t n);
silc_value *val_csr_new_complex(int64_t m, int64_t n, int64_t nnz_capacity);
silc_value *val_band_new_complex(int64_t m, int64_t n, int64_t kl, int64_t ku);
silc_value *val_scalar_new(double x);
silc_value *val_scalar_new_complex(double re, double im);
/* Complex values from real ones, and back.  val_promote: a complex copy of
 * v (imaginary parts 0) in v's format; a complex v is retained, not copied.
 * val_part: the real (imag = 0) or imaginary (imag = 1) part of v as a real
 * value in v's format (of a real v, a copy or zeros): the demotion, only
 * on request (real(x), imag(x)).  NULL when out of memory or over a limit
 * (val_refusal says which). */
silc_value *val_promote(const silc_value *v);
silc_value *val_part(const silc_value *v, int imag);
/* re + i*im as a complex value, re and im real values of one format and
 * shape (CSR: the union of their patterns); NULL otherwise or when out of
 * memory.  Joins the parts val_part splits. */
silc_value *val_complex_of_parts(const silc_value *re, const silc_value *im);
/* 1 when every imaginary part of v is 0 (and for every real v). */
int val_imag_is_zero(const silc_value *v);
int val_csr_set_nnz(silc_value *v, int64_t nnz);
/* Fills a CSR value made for rowptr[m] entries from rowptr/colind/values
 * (which may be its own arrays: data received in place), checking that each
 * row's columns lie in [0, n) and strictly increase, and computing the
 * shape part of the properties in the same pass, while each row is in
 * cache.  rowptr must be valid (0 first, never decreasing).  -1 at the first
 * row that fails: the value is then partly filled, to be dropped, and
 * env_check says what was wrong. */
int val_csr_fill_checked(silc_value *v, const silc_index *rowptr, const silc_index *colind,
                         const double *values);
/* As the constructors, elements left unset: for a caller that writes them all. */
silc_value *val_new_unset(int format, int64_t m, int64_t n, int64_t nnz, int64_t kl, int64_t ku);
silc_value *val_new_unset_field(int format, int field, int64_t m, int64_t n, int64_t nnz, int64_t kl,
                                int64_t ku);
/* Recycling of value arrays, process-wide (silcd installs a pool): take(bytes)
 * returns an array of at least bytes with any contents, or NULL; give(p) gets
 * every freed array and returns 1 when it kept it (then no longer to free).
 * Install before any thread uses values; NULL hooks mean plain malloc/free. */
void val_set_array_pool(void *(*take)(size_t bytes), int (*give)(void *p));
/* An array of count elements of size bytes, zero-filled when zero is set,
 * from the pool when it has one; never asks for zero bytes, so NULL always
 * means failure.  Value and envelope arrays are made and freed with these. */
void *val_array_alloc(int64_t count, size_t size, int zero);
/* The largest value (its arrays' bytes) the constructors make in this
 * process; source names the setting in refusals ("silcd --max-value-bytes").
 * Unset: the machine's physical memory.  Set once, before values are made. */
void val_set_max_bytes(uint64_t bytes, const char *source);
uint64_t val_max_bytes(void);
/* Why this thread's last constructor returned NULL if a size limit refused
 * it ("a 10000000000x10000000000 csr value needs ... exceeds the limit ...
 * by ..."), or "" if it was malloc: callers report it instead of "out of
 * memory" (eng_oom). */
const char *val_refusal(void);
/* 0 if bytes fit the limit; else -1 and val_refusal() says "<what> needs N
 * bytes (..), over the limit of .. by ..: the most one value may hold (..)".
 * For sizes claimed before any value exists (a Matrix Market size line). */
int val_claim(double bytes, const char *what);
void val_array_free(void *p);
/* A budget for the values alive at once in this process (silcd's
 * --max-session-bytes at a request's peak): while limit > 0, a constructor
 * whose arrays would bring val_live_bytes() - exempt over limit returns NULL
 * and val_refusal() says so, naming source.  limit 0 lifts it. */
void val_budget_set(int64_t exempt, uint64_t limit, const char *source);
/* 1 if a constructor was refused by the budget since it was last set. */
int val_budget_refused(void);
/* The budget's check for bytes claimed before any value is made (a file's
 * shapes, summed over everything a `load` would bind): 0 if they fit what
 * the budget has left (or no budget is set); else -1, val_refusal() says
 * "<what> would bring the values held at once ... (<source>)" as a refused
 * constructor's, and val_budget_refused() becomes 1. */
int val_budget_claim(double bytes, const char *what);
/* What the budget has left, in bytes (negative when over; INT64_MAX when
 * no budget is set). */
int64_t val_budget_room(void);
/* Bytes of the arrays of every value alive in this process. */
int64_t val_live_bytes(void);
/* The bytes a value of this claim costs, the one formula every limit uses:
 * its arrays, and for band storage also one double per row and column
 * (the row sums of its norms, a product's result), which band storage
 * itself does not grow with.  A double: claims may exceed 64 bits. */
double val_shape_bytes(int format, int64_t m, int64_t n, int64_t nnz, int64_t kl, int64_t ku);
/* The same for a value of this field (a complex one: 2 doubles an entry). */
double val_shape_bytes_field(int format, int field, int64_t m, int64_t n, int64_t nnz, int64_t kl,
                             int64_t ku);

silc_value *val_retain(silc_value *v);    /* returns v; NULL-safe */
void val_release(silc_value *v);          /* frees at zero, attachments first; NULL-safe */

void val_view(const silc_value *v, silc_view *out);
const silc_props *val_props(const silc_value *v); /* computes and caches on first call */
/* Only some parts of the properties (SILC_PROPS_*, silc_plugin.h), each
 * computed and cached when first asked for (value.c says why). */
const silc_props *val_props_part(const silc_value *v, int parts);
/* The infinity norm, largest modulus and Frobenius norm of v into *p,
 * without its column sums (p->norm1 = NaN) and without caching them: a
 * distributed value's block, whose column sums span the ranks (dist.c
 * reduces its own, and a symmetric value needs none).  Returns 0, or -1
 * when memory ran short (then norminf is the upper bound sum|a_ij|). */
int val_row_norms(const silc_value *v, silc_props *p);
/* The shape part of a whole real dense v's properties (as val_props_part
 * computes it, with the scan cache) and a copy of its m*n entries into
 * copy, in one read of v: a solve's backend factors such a copy in place
 * (the dispatcher's factor copy, dispatch.c), and A is 8 MB at n = 1000.
 * copy NULL: the shape alone (val_props_part's pass for it).  -1 (nothing
 * done) when v is not such a value or its shape is known. */
int val_shape_into(silc_value *v, double *copy);
/* Any NaN or Inf among the stored entries, and the largest |entry| (NaN if
 * any is NaN), from one cached scan: what a solve needs of its right-hand
 * side, without computing the properties. */
int val_has_nonfinite(const silc_value *v);
double val_max_abs(const silc_value *v);
/* After changing a value's entries in place (only before it is shared):
 * forget what the caches said. */
void val_forget_caches(silc_value *v);
/* After updating an unshared value in place (copy-on-write, eval.c): forget
 * the caches and take a new id, so that nothing keyed by the old id can
 * mistake the new contents for the old. */
void val_mutated(silc_value *v);
int val_is_scalar(const silc_value *v);   /* 1x1 */
double val_scalar(const silc_value *v);   /* the (1,1) entry of a 1x1 value */
double val_get(const silc_value *v, int64_t i, int64_t j); /* 0-based, any format; real part */
/* The (i, j) entry as a complex number (imaginary part 0 for a real value). */
double _Complex val_get_complex(const silc_value *v, int64_t i, int64_t j);
/* 1 when a and b hold the same format, shape, pattern and value bits (whole
 * values only). */
int val_same_contents(const silc_value *a, const silc_value *b);
/* The same for two views of values of one field, width doubles an entry
 * (val_same_contents and env_same_as_value). */
int view_same_contents(const silc_view *x, const silc_view *y, int width);
size_t val_bytes(const silc_value *v);    /* memory held by the arrays */
const char *val_format_name(int format);  /* "dense", "csr", "band" */

/* Distributed values (dist.c).  val_dist_new makes an array-less value of
 * the whole shape that takes over block and retains part.  The hooks let
 * the properties and scans of such a value be computed collectively by
 * dist.c (which installs them) when someone asks: value.c sits below the
 * communicator. */
silc_value *val_dist_new(int64_t m, int64_t n, int format, struct dist_ctx *ctx, dist_part *part,
                         silc_value *block);
dist_part *dist_part_ref(dist_part *p);
void dist_part_unref(dist_part *p);
typedef struct val_dist_hooks {
    void (*props)(silc_value *v, int parts);     /* fill v->props for parts, set props_have */
    void (*scan)(silc_value *v);                 /* fill scan_nonfinite, scan_maxabs, SCAN_MAXABS */
} val_dist_hooks;
void val_set_dist_hooks(const val_dist_hooks *h);

void *val_attach_get(const silc_value *v, const char *key);
int val_attach_set(const silc_value *v, const char *key, void *data, void (*destroy)(void *));
/* The memory an attachment holds, as measured by whoever made it (the
 * dispatcher, around the plugin call that attached it: disp_run): 0, or -1
 * if v has no attachment key.  A replaced attachment keeps its charge. */
int val_attach_charge(const silc_value *v, const char *key, int64_t bytes);
/* Lets go of v's charged attachments (a plugin's factorization: the next
 * solve makes it again); returns the bytes they were charged. */
int64_t val_attach_release(const silc_value *v);
/* When v's charged attachments were last used (val_attach_get/_set); 0 if
 * it has none. */
uint64_t val_attach_last_use(const silc_value *v);
/* The charges of every attachment alive in the process. */
int64_t val_attach_live_bytes(void);
/* The charges of all of v's attachments: what a cache keeping v holds
 * beyond its arrays (the memo's session charge, memo.c). */
int64_t val_attach_bytes(const silc_value *v);

/* ---- the store ------------------------------------------------------------- */
typedef struct store_entry {
    silc_value *value;
    struct store_entry *next;
    size_t hash;            /* of name (value.c): compared before the name */
    char name[];            /* in the entry: a lookup reads one allocation, not two */
} store_entry;

typedef struct silc_store {
    store_entry **buckets;
    size_t nbuckets, count;
} silc_store;

int store_init(silc_store *s);
void store_free(silc_store *s);
silc_value *store_get(const silc_store *s, const char *name);     /* borrowed, NULL if absent */
int store_set(silc_store *s, const char *name, silc_value *v);    /* retains v; releases the old */
int store_remove(silc_store *s, const char *name);                /* 0 removed, 1 absent */
void store_clear(silc_store *s);
/* Names in sorted order; *names is malloc'd array of borrowed strings. */
size_t store_names(const silc_store *s, const char ***names);

/*
 * ---- envelopes (envelope.c): the bridge between public envelopes (silc.h)
 * and engine values (above), and the message buffer of calls that have no context.
 *
 * Envelope constructors and silc_mm_read/write run without a context, so
 * their failure messages go to a per-thread buffer.  silc_errmsg() shows that
 * message until a later failure on the default context supersedes it (the API
 * calls env_error_forget() when it records one).
 */

/* ---- the checked constructor (envelope.c) ---------------------------------
 * A value as someone outside claims it: format and shape, then arrays.
 * Every value handed to SILC from outside is built or checked through
 * these: silc_put / SILC_PUT (embedded, and by the remote client before it
 * sends), silcd's PUT (descriptor first, arrays after they arrive), HDF5
 * `load`, Matrix Market files, and plugin results (host.c).  The claim is
 * checked first (sizes non-negative, m*n, nnz and (kl+ku+1)*n without
 * overflow, val_shape_bytes within val_max_bytes()), so nothing is
 * allocated or read for a value that cannot be; then the arrays: CSR
 * rowptr 0 first, never decreasing, rowptr[m] == nnz, columns in [0, n)
 * and strictly increasing in each row.  Messages print sizes and indices,
 * never an address. */
typedef struct val_parts {
    int format;                 /* SILC_FMT_* */
    int field;                  /* SILC_FIELD_*: complex values hold 2 doubles an entry */
    int64_t m, n;
    int64_t nnz;                /* csr: entries colind and values hold; else unused */
    int64_t kl, ku;             /* band only */
    const silc_index *rowptr;   /* csr: m+1 */
    const silc_index *colind;   /* csr: nnz */
    const double *values;       /* dense m*n, csr nnz, band (kl+ku+1)*n entries */
} val_parts;
/* The bytes the claim costs (val_shape_bytes). */
double val_parts_bytes(const val_parts *p);
/* The claim alone (no array is read): 0, or -1 with the reason in err. */
int val_parts_claim(const val_parts *p, char *err, size_t errlen);
/* The claim and the arrays. */
int val_parts_check(const val_parts *p, char *err, size_t errlen);
/* Checks and copies into a new value (refcount 1). */
int val_from_parts(const val_parts *p, silc_value **out, char *err, size_t errlen);
/* Checks p and fills v, a CSR value made for p's claim, from it (p's arrays
 * may be v's own: data read in place), shape computed on the way. */
int val_parts_fill(silc_value *v, const val_parts *p, char *err, size_t errlen);
/* A finished value's arrays against its own claim (plugin results). */
int val_check_value(const silc_value *v, char *err, size_t errlen);

/* 1 when e was left by a failed constructor (or silc_mm_read), with that
 * constructor's message in err; 0 otherwise.  A PUT of such an envelope is
 * refused ("envelope 'A' was not constructed: ..."). */
int env_not_constructed(const silc_envelope_t *e, char *err, size_t errlen);
/* Marks e as not constructed with this thread's last env_error; -1. */
int env_mark_not_constructed(silc_envelope_t *e);

/* Validates an envelope without copying it (the checks env_to_value makes):
 * used by the remote client before sending and by silcd on what it received,
 * so both report exactly the embedded messages. */
int env_check(const silc_envelope_t *e, char *err, size_t errlen);
/* Copies an envelope into a new value (refcount 1), validating it first:
 * shapes, array presence, CSR rowptr/colind consistency and sorted,
 * duplicate-free rows.  On failure writes the reason to err. */
int env_to_value(const silc_envelope_t *e, silc_value **out, char *err, size_t errlen);
/* The CSR part of env_to_value for a value made for e's rowptr[m] entries:
 * checks and fills it from e's arrays (which may be the value's own), with
 * the value's shape computed on the way (val_csr_fill_checked).  0, or -1
 * with the reason in err. */
int env_csr_fill(silc_value *v, const silc_envelope_t *e, char *err, size_t errlen);
/* 1 when e holds exactly v's format, shape, pattern and value bits: then a
 * PUT of e to the name holding v need copy nothing (silc_put).  Reads no
 * array of e beyond what v's shape says a valid e has; 0 for anything that
 * is not such an e. */
int env_same_as_value(const silc_envelope_t *e, const silc_value *v);
/* Copies a value into a freshly built envelope of the same format. */
int env_from_value(const silc_value *v, silc_envelope_t *e);
/* The store's format and field of an envelope format code (silc.h: the
 * SILC_COMPLEX bit), and back. */
int env_format_base(int envelope_format);
int env_format_field(int envelope_format);
int env_format_code(int format, int field);
/* -1 with "'z' is complex: ..." in err when v is complex: what a GET from a
 * caller that did not ask for complex values answers (silc_get, silcd's
 * GET, silc_get_rows); getter names the call that would fetch it
 * (silc_get_complex, silc_get_rows_complex).  0 for a real v. */
int env_refuse_complex(const char *name, const silc_value *v, const char *getter, char *err, size_t errlen);
/* That refusal's text, whatever v: a remote client compares silcd's answer
 * to a GET with it to name its own getter instead of silc_get_complex. */
int env_complex_refusal(const char *name, const char *getter, char *err, size_t errlen);

/* Records a context-free failure message; returns -1. */
int env_error(const char *fmt, ...)
#if defined(__GNUC__)
    __attribute__((format(printf, 1, 2)))
#endif
    ;
/* The context-free message of this thread if it is the latest failure, else NULL. */
const char *env_error_last(void);
void env_error_forget(void);

#endif
