/*
 * silc.h -- the public C API of SILC.
 *
 * A program deposits matrices under names, asks for computation as text, and
 * fetches results by name:
 *
 *     silc_envelope_t A, b, u;
 *     SILC_INIT();
 *     silc_envelope_csr(&A, n, n, rowptr, colind, values);
 *     silc_envelope_dense(&b, n, 1, rhs);
 *     SILC_PUT("A", &A); SILC_PUT("b", &b);
 *     if (SILC_EXEC("u = A \\ b")) fprintf(stderr, "%s\n", silc_errmsg());
 *     SILC_GET(&u, "u");
 *     silc_envelope_to_dense(&u, x);
 *     silc_envelope_free(&A); silc_envelope_free(&b); silc_envelope_free(&u);
 *     SILC_FINALIZE();
 *
 * The upper-case calls use one default context; the silc_* calls take an
 * explicit context (several may be open at once; a context is not thread-safe,
 * use one per thread).  The API does not depend on where computation runs:
 * embedded in this process, or a silcd server (SILC_SERVER=tcp://host:port or
 * unix:/path, or silc_open_remote), behind the same calls.
 *
 * Every function returning int returns 0 on success and non-zero on failure; the
 * message is then available from silc_errmsg() / silc_context_errmsg().
 *
 * Ownership: an envelope owns its arrays.  Constructors copy the caller's
 * arrays; SILC_GET fills an envelope with freshly allocated arrays; release them
 * all with silc_envelope_free().  Strings returned as const char * belong to
 * the context and stay valid until the next call on that context.
 */
#ifndef SILC_H
#define SILC_H

#include <stddef.h>
#include <stdint.h>
#include <stdio.h>

#ifdef __cplusplus
extern "C" {
#endif

#define SILC_VERSION "1.0.0" /* CMakeLists.txt checks it is the project version */

/* Limits of one EXEC text, so that no text can exhaust the stack of the
 * recursive parser and evaluator (they hold in a server as embedded):
 * brackets, unary operators, powers, `if`/`while` blocks and `else if`
 * chains nest at most SILC_MAX_NESTING levels ("1:4000: expression nested
 * deeper than 256 levels"), and an expression tree is at most
 * SILC_MAX_EXPR_HEIGHT operations tall, which a chain such as a sum of that
 * many terms reaches ("expression too long: ... operations in a chain").
 * Deeper texts are refused whole, before anything runs. */
#define SILC_MAX_NESTING 256
#define SILC_MAX_EXPR_HEIGHT 1024

/* What libsilc exports: the functions below and nothing else (the engine
 * is compiled with hidden visibility), so no name of its internals can clash
 * with one of the program's. */
#if defined(_WIN32)
#define SILC_API
#elif defined(__GNUC__)
#define SILC_API __attribute__((visibility("default")))
#else
#define SILC_API
#endif

/* Storage formats of an envelope (the same codes as the plugin ABI). */
typedef enum {
    SILC_DENSE = 0, /* column-major m*n */
    SILC_CSR = 1,   /* 0-based compressed sparse rows */
    SILC_BAND = 2,  /* LAPACK band storage, ld = kl+ku+1, A(i,j) = values[(ku+i-j) + j*ld] */
    /* Complex values: the format of a complex envelope has the SILC_COMPLEX
     * bit set, and its values hold two doubles an entry, the real part then
     * the imaginary part (interleaved: the layout of C's double _Complex,
     * Fortran's complex(8), NumPy's complex128), so a double _Complex array
     * may be passed cast to (const double *).  Counts (nnz) count entries. */
    SILC_COMPLEX = 16,
    SILC_DENSE_COMPLEX = 16,
    SILC_CSR_COMPLEX = 17,
    SILC_BAND_COMPLEX = 18
} silc_format_t;

/* A matrix in transit between the program and SILC.  Fields are readable; build
 * envelopes with the constructors below.  rowptr/colind are int64 whatever width
 * the caller gave.  A hand-filled envelope must tell the truth about its arrays:
 * a CSR one holds m+1 row pointers and nnz entries in colind and values
 * (silc_put refuses rowptr[m] != nnz, but cannot see an array shorter than m
 * says).  A constructor that fails leaves the envelope marked as not
 * constructed (no arrays; free it or not): silc_put refuses it with
 * "envelope 'A' was not constructed: <the constructor's message>". */
typedef struct silc_envelope_t {
    int64_t m, n;
    silc_format_t format;
    double *values;     /* dense: m*n; csr: nnz; band: (kl+ku+1)*n entries (complex: 2 doubles each) */
    int64_t *rowptr;    /* csr: m+1 entries, else NULL */
    int64_t *colind;    /* csr: nnz entries, else NULL */
    int64_t nnz;        /* csr: stored entries; dense: m*n; band: (kl+ku+1)*n */
    int64_t kl, ku;     /* band only */
} silc_envelope_t;

/* ---- envelopes ------------------------------------------------------------- */
/* Dense, column-major; a vector is n x 1, a scalar 1 x 1.  colmajor may be NULL
 * for zeros.  Copies. */
SILC_API int silc_envelope_dense(silc_envelope_t *e, int64_t m, int64_t n, const double *colmajor);
SILC_API int silc_envelope_scalar(silc_envelope_t *e, double x);
SILC_API int silc_envelope_vector(silc_envelope_t *e, int64_t n, const double *x);
/* CSR, 0-based, copies.  Rows need not be sorted: columns are sorted on copy and
 * duplicates are an error (use sparse(i,j,v,m,n) in the language to sum them). */
SILC_API int silc_envelope_csr(silc_envelope_t *e, int64_t m, int64_t n, const int64_t *rowptr,
                               const int64_t *colind, const double *values);
SILC_API int silc_envelope_csr32(silc_envelope_t *e, int64_t m, int64_t n, const int32_t *rowptr,
                                 const int32_t *colind, const double *values);
/* Complex envelopes (dense column-major and CSR as above), values holding
 * 2 doubles an entry, interleaved re, im (pass a double _Complex array
 * cast to const double *).  A complex envelope is PUT as any other; a
 * complex value is fetched only by silc_get_complex (below). */
SILC_API int silc_envelope_dense_complex(silc_envelope_t *e, int64_t m, int64_t n, const double *colmajor);
SILC_API int silc_envelope_csr_complex(silc_envelope_t *e, int64_t m, int64_t n, const int64_t *rowptr,
                                       const int64_t *colind, const double *values);
/* 1 when e holds a complex value (format & SILC_COMPLEX). */
SILC_API int silc_envelope_is_complex(const silc_envelope_t *e);
/* Band, LAPACK layout with ld = kl+ku+1.  Copies. */
SILC_API int silc_envelope_band(silc_envelope_t *e, int64_t m, int64_t n, int64_t kl, int64_t ku,
                                const double *band);
SILC_API int64_t silc_envelope_rows(const silc_envelope_t *e);
SILC_API int64_t silc_envelope_cols(const silc_envelope_t *e);
/* Writes all m*n entries column-major into colmajor_out (caller's array;
 * 2*m*n doubles, interleaved, for a complex envelope). */
SILC_API int silc_envelope_to_dense(const silc_envelope_t *e, double *colmajor_out);
/* Frees the arrays and zeroes the envelope; NULL and zeroed envelopes are fine. */
SILC_API void silc_envelope_free(silc_envelope_t *e);

/* Matrix Market: read coordinate (real, integer, pattern, complex; general,
 * symmetric, skew-symmetric, and for complex files hermitian, whose stored
 * lower triangle is mirrored conjugated and whose diagonal must be real) into
 * CSR, or array into dense; a complex file gives a complex envelope.  Read by the format's rules, with "path:line:column: ..." messages:
 * integer fields take integers within int64, reals are decimal (no hex), inf,
 * nan and reals that overflow are refused unless the environment sets
 * SILC_MM_ALLOW_NONFINITE=1, "hermitian" needs a complex field, and a symmetric
 * or skew-symmetric file stores only the lower triangle (an entry above it is
 * refused).  A failed read leaves e not constructed, as a failed constructor.
 * Write: dense as array, CSR/band as coordinate general, %.17g. */
SILC_API int silc_mm_read(silc_envelope_t *e, const char *path, char *err, size_t errlen);
/* (Write: a complex envelope as `complex general`, "re im" on each line; a
 * complex band envelope as coordinate complex, its nonzero entries.) */
SILC_API int silc_mm_write(const silc_envelope_t *e, FILE *out);

/* ---- contexts -------------------------------------------------------------- */
typedef struct silc_context silc_context;

/* Opens an embedded context.  config_path may be NULL: then SILC_CONFIG, else
 * ./silc.conf if it exists, else built-in defaults.  On failure returns non-zero
 * and, if *out was set, silc_context_errmsg(*out) says why (else the message is
 * in silc_errmsg()). */
SILC_API int silc_open(silc_context **out, const char *config_path);
/* Opens a remote context on a silcd server: url is tcp://host:port or
 * unix:/path/to/socket.  The token, when the server wants one, comes from
 * SILC_TOKEN, else the first line of the file named by SILC_TOKEN_FILE.
 * silc_open and SILC_INIT do the same with SILC_SERVER when it is set (the
 * server's configuration then applies, config_path is not used).  Every other
 * call behaves as on an embedded context: same results, same messages; a lost
 * connection is reported by the call that meets it.  Replies are checked as
 * silcd checks requests: a value over SILC_MAX_REPLY_BYTES (default 2G) is
 * refused (the session goes on), a malformed reply or a server silent for
 * SILC_IO_TIMEOUT seconds (default 300; inside a reply, or before the reply
 * to anything but silc_exec, whose wait SILC_EXEC_TIMEOUT bounds, none by
 * default) fails the call naming the server and closes the connection
 * (docs/remote.md).  On failure the message is in silc_errmsg(). */
SILC_API int silc_open_remote(silc_context **out, const char *url);
SILC_API void silc_close(silc_context **ctx);
/* Binds a copy of e to name (the envelope stays the caller's).  The copy is
 * checked as it is made, by the checker every value from outside passes (a
 * remote context checks before sending, so the messages are the same): the
 * claimed size first, against overflow and the value limit (silcd
 * --max-value-bytes and the session's --max-session-bytes remotely; a band
 * value is charged for its rows too), then a CSR envelope's rowptr must start
 * at 0, never decrease and end at nnz, and each row's columns lie in [0, n)
 * and strictly increase (the constructors guarantee this; a hand-filled
 * envelope gets a message naming the row).  An envelope whose constructor
 * failed is refused: "envelope 'A' was not constructed: ...".  The same pass records what `\` asks of a matrix first
 * (triangles, band widths, positive diagonal, NaN/Inf): on bcsstk16 the put
 * takes 0.85 ms and the solve that follows needs no pass of its own for it.
 * On failure name keeps its old value. */
SILC_API int silc_put(silc_context *ctx, const char *name, const silc_envelope_t *e);
/* silc_get fetches real values only: a complex value is refused ("'z' is
 * complex: fetch it with silc_get_complex"), so that a program written
 * before complex values never reads half of one.  silc_get_complex fetches
 * either field; silc_envelope_is_complex(e) tells which came. */
SILC_API int silc_get(silc_context *ctx, silc_envelope_t *e, const char *name);
SILC_API int silc_get_complex(silc_context *ctx, silc_envelope_t *e, const char *name);
SILC_API int silc_exec(silc_context *ctx, const char *statements);
/* Interrupts the silc_exec running on ctx: it fails with "interrupted"
 * ("statement 2: interrupted" in a text of several statements) at its next
 * check -- after each statement and loop iteration, before each plugin
 * call, and inside plugins that poll host->cancelled() -- and the
 * interrupted statement leaves the store as before it (a whole loop or
 * `if` is undone); earlier statements of the text stay done.  A library
 * call that never polls finishes first.  Async-signal-safe and
 * thread-safe: call it from a SIGINT handler or from another thread while
 * silc_exec runs (not concurrently with silc_close).  On a remote context
 * it sends a CANCEL frame (docs/protocol.md) if an exec is waiting for its
 * reply.  With no exec running it does nothing (the next exec starts
 * afresh).  Returns 0, or -1 for a NULL context; sets no message. */
SILC_API int silc_cancel(silc_context *ctx);
/* The statements `save "path" names` and `load "path" names` (HDF5; README
 * "Saving and loading"): names is a space-separated list, NULL or "" for
 * every name (save) or every SILC value of the file (load: other objects
 * are skipped, and a warning names them; a name given must be a SILC value).
 * Layouts, dense orientation included: docs/hdf5.md.  A failed save
 * leaves the old file, a failed load changes no name.  load reads a file as
 * untrusted input: no external link is followed, datasets with external
 * storage and virtual datasets are refused, index datasets must be integers,
 * and every shape is checked against the value limit before any read.  On a remote context
 * path is on the server's machine. */
SILC_API int silc_save(silc_context *ctx, const char *path, const char *names);
SILC_API int silc_load(silc_context *ctx, const char *path, const char *names);
SILC_API const char *silc_context_errmsg(const silc_context *ctx);
/* Warnings of the last silc_exec (one per line, "" if none): results that were
 * computed but deserve distrust, e.g. "matrix is singular to working precision
 * (1-norm condition estimate 3.2e+17)".  Valid until the next call. */
SILC_API const char *silc_context_warnings(const silc_context *ctx);
/* Where `who`, `info`, `explain`, `help`, `set`, `profile` and `disp(x)` print
 * (default: stdout).  The callback gets one complete piece of text at a
 * time; NULL restores stdout.  silc_exec / SILC_EXEC never print a value on
 * their own: a statement without ';' shows its value (as Octave does) only
 * after `set core.display = on`, which the silc command sets. */
typedef void (*silc_output_fn)(void *user, const char *text);
SILC_API void silc_set_output(silc_context *ctx, silc_output_fn fn, void *user);

/* ---- MPI programs (SPMD) --------------------------------------------------- */
/* An MPI program opens one context per rank over its communicator
 * (silc_open_mpi in silc_mpi.h, or SILC_INIT with SILC_MODE=spmd when the
 * program links libsilc_mpi).  Every call on such a context is collective:
 * all ranks make the same calls in the same order (a mismatch -- ranks
 * EXECing different texts, one rank PUTting while another GETs -- is an error
 * on every rank, naming the ranks and the calls).  silc_put binds the same
 * whole value on every rank (each passes it), silc_get returns the whole
 * value on every rank; the row-block calls below move nothing between ranks.
 * docs/distributed.md says which operations run distributed.
 *
 * silc_put_rows: this rank's rows [first_row, first_row + block->m) of the
 * value `name`; the blocks of the ranks, in rank order, must tile the rows
 * with no gap or overlap and have the same columns, format (CSR or dense;
 * CSR column indices are global) and field (real, or complex on every rank).
 * On one process (any other context) the block must be the whole value,
 * first_row 0.
 * silc_get_rows: this rank's rows of `name` and, in *first_row (may be NULL),
 * the first of them: a value computed from distributed operands keeps their
 * rows; a whole value is split evenly, as PETSc's PETSC_DECIDE splits it.
 * Real values only, as silc_get: a complex one is refused ("'x' is complex
 * ... fetch it with silc_get_rows_complex").
 * silc_get_rows_complex: the same for either field, as silc_get_complex: a
 * complex value's rows come as a complex block (2 doubles an entry,
 * interleaved; silc_envelope_is_complex(block) tells which came). */
SILC_API int silc_put_rows(silc_context *ctx, const char *name, int64_t first_row,
                           const silc_envelope_t *block);
SILC_API int silc_get_rows(silc_context *ctx, silc_envelope_t *block, int64_t *first_row,
                           const char *name);
SILC_API int silc_get_rows_complex(silc_context *ctx, silc_envelope_t *block, int64_t *first_row,
                                   const char *name);
/* This process's rank and the number of ranks of ctx (0 and 1 unless the
 * context is an SPMD one). */
SILC_API int silc_context_rank(const silc_context *ctx, int *rank, int *size);

/* ---- the default context (the seeds' calls) -------------------------------- */
SILC_API int SILC_INIT(void);
SILC_API int SILC_FINALIZE(void);
SILC_API int SILC_PUT(const char *name, const silc_envelope_t *e);
SILC_API int SILC_GET(silc_envelope_t *e, const char *name);
SILC_API int SILC_EXEC(const char *statements);
/* The message of the last failure, and the warnings of the last SILC_EXEC,
 * on the default context. */
SILC_API const char *silc_errmsg(void);
SILC_API const char *silc_warnings(void);
SILC_API silc_context *silc_default_context(void); /* NULL before SILC_INIT */

#ifdef __cplusplus
}
#endif
#endif /* SILC_H */
