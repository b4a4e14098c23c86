/*
 * dispatch.c -- from an operation to the backend that runs it.
 *
 * Every call gets a chain of operation classes, most specific first (a solve
 * with a symmetric, positive-diagonal sparse matrix is "solve.sparse.spd",
 * then "solve.sparse").  The class chain picks an ordered list of backends:
 * a per-call "backend = X", else the first class of the chain that the
 * configuration names (so a config that only sets solve.sparse governs SPD
 * systems too), else the built-in default, which follows the structure rules
 * users know from MATLAB's `\`.  The list is walked: a backend that is not
 * installed, does not provide the operation, or declines the operands is
 * skipped; a Cholesky that finds the matrix not positive definite sends the
 * same list round again under the general class (LU); any other failure stops
 * with the backend's message.  The reference plugin ends every list, so an
 * operation always has somewhere to go.
 *
 * Every solve gets the same accuracy report whoever ran it: the backward error
 * comes from accuracy.c, so backends are judged by one yardstick.
 *
 * Complex operands (ABI 1.8) go only to a backend whose plugin lists the
 * op in complex_ops; any other is passed over ("does not take complex
 * values") and the list moves on.  A call never mixes fields: real
 * operands of a call with a complex one are promoted first (one copy each,
 * released after), except a real A solved against a complex b, which is
 * two real solves sharing A's factorization (disp_run).
 */
#define _POSIX_C_SOURCE 200809L
#include "dispatch.h"
#include "accuracy.h"
#include "dist.h"

#include <float.h>
#include <math.h>
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#if defined(__SANITIZE_ADDRESS__)
#define SILC_HEAP_FROM_SANITIZER 1
#elif defined(__has_feature)
#if __has_feature(address_sanitizer)
#define SILC_HEAP_FROM_SANITIZER 1
#endif
#endif
#ifdef SILC_HEAP_FROM_SANITIZER
/* The sanitizer runtime's (sanitizer/allocator_interface.h, which gcc does
 * not ship). */
size_t __sanitizer_get_current_allocated_bytes(void);
#elif defined(__GLIBC__) && (__GLIBC__ > 2 || (__GLIBC__ == 2 && __GLIBC_MINOR__ >= 33))
#define SILC_HEAP_FROM_MALLINFO2 1
#include <malloc.h>
#endif

const char *const disp_class_names[] = {
    "solve.diag", "solve.triangular", "solve.band", "solve.dense", "solve.dense.spd",
    "solve.sparse", "solve.sparse.spd", "solve.sparse.mmatrix.spd", "solve.rect", "matmul.sparse_sparse",
    "matmul.sparse_dense", "matmul.dense", "add", "elementwise", "transpose", "reduce",
    "convert", "diag", NULL};

static const char *const op_names[SILC_OP_COUNT] = {
    "add", "scale", "matmul", "elementwise", "map", "transpose", "solve", "reduce", "convert",
    "diag"};

/* Built-in backend lists; a class not listed uses the reference alone.
 * The sparse lists follow bench/backends on this machine (docs/backends.md,
 * one thread): CHOLMOD was fastest on the largest SPD problem (the 2-D
 * Laplacian, 250000 unknowns: 1.3 s against UMFPACK 1.9, MUMPS 2.4, KLU 3.0),
 * UMFPACK fastest of the LU libraries on grid-like systems and on bayer10;
 * KLU wins memplus (circuit) but fills badly on grids and missed the 1e-12
 * backward error on bayer10, so it is not a default.  MUMPS follows UMFPACK
 * for solve.sparse. */
static const struct {
    const char *cls;
    const char *list;
} default_lists[] = {
    {"solve.diag", "reference"},
    {"solve.triangular", "lapack, reference"},
    {"solve.band", "lapack, reference"},
    {"solve.dense", "lapack, reference"},
    {"solve.dense.spd", "lapack, reference"},
    {"solve.sparse", "suitesparse.umfpack, mumps, reference"},
    {"solve.sparse.spd", "suitesparse.cholmod, suitesparse.umfpack, reference"},
    {"solve.sparse.mmatrix.spd", "lis-style, suitesparse.cholmod, suitesparse.umfpack, reference"},
    {"solve.rect", "suitesparse.spqr, lapack, reference"},
};

const char *disp_default_list(const char *cls)
{
    size_t i;
    for (i = 0; i < sizeof default_lists / sizeof default_lists[0]; i++)
        if (!strcmp(default_lists[i].cls, cls)) return default_lists[i].list;
    return "reference";
}

/* For a solve whose operands are distributed (dist.h), the built-in lists
 * start with the backends that solve on the row blocks where they lie --
 * MUMPS (AMF ordering, the fastest of PETSc's direct packages here:
 * docs/distributed.md), then PETSc -- before the sequential ones, which
 * would gather the matrix to every rank. */
static const struct {
    const char *cls;
    const char *list;
} distributed_lists[] = {
    {"solve.sparse", "mumps, petsc, suitesparse.umfpack, reference"},
    {"solve.sparse.spd", "mumps, petsc, suitesparse.cholmod, suitesparse.umfpack, reference"},
};

#define DISP_MAX_LIST 33 /* the config's 32 plus the appended reference */

/* The backends to try for one call, and where the list came from. */
typedef struct blist {
    char buf[1024];
    const char *names[DISP_MAX_LIST];
    int n;
    char key[160];          /* the dispatch key the names come from; "" for a built-in list */
    char absent[256];       /* optional or built-in names left out: not installed here */
    int forced;             /* per-call backend = X: no fallback */
    int nlisted;            /* names the configuration or default listed (then "reference") */
    /* Where the names came from, for explain (list_source formats it
     * there: every operation resolves a list, few are explained). */
    const char *forced_text;    /* the per-call backend = ... text */
    const char *default_class;  /* the class whose built-in list applies */
    int default_distributed;
} blist;

/* ---- classes --------------------------------------------------------------- */

/* solve.sparse.mmatrix.spd is the first solve with a large symmetric
 * M-matrix (a Stieltjes matrix: positive diagonal, off-diagonal entries
 * <= 0, like every diffusion stencil).  Its default sends it to lis-style's
 * CG + SA-AMG, stopped at a backward error of 1e-12, before CHOLMOD: on the
 * 2-D Laplacian that is 5-8x cheaper than a Cholesky factorization from
 * 10 000 unknowns up (docs/backends.md), and algebraic multigrid is built
 * for exactly these matrices.  A second solve with the same A is
 * solve.sparse.spd, where a factorization reused for every later solve is
 * what pays.  So is a first solve the evaluator expects to be repeated
 * (E->solve_again: inside a loop that does not assign A, or the first step
 * of a run `tune on N` announced): started with the factorization, a time
 * loop pays for no AMG solve it would throw away. */
#define MMATRIX_MIN_N 10000
#define SOLVED_KEY "dispatch.solved" /* attached to A by its first sparse solve */

/* A is CSR with at least MMATRIX_MIN_N rows and no positive off-diagonal
 * entry (the caller knows it symmetric with a positive diagonal). */
static int large_mmatrix(const silc_value *A)
{
    silc_view v;
    int64_t i, k;
    if (A->format != SILC_FMT_CSR || A->n < MMATRIX_MIN_N) return 0;
    val_view(A, &v);
    for (i = 0; i < v.m; i++)
        for (k = v.rowptr[i]; k < v.rowptr[i + 1]; k++)
            if (v.colind[k] != i && !(v.val[k] <= 0)) return 0;
    return 1;
}

/* The class is there for its built-in list: a configuration that names
 * solve.sparse.spd or solve.sparse (and not this class) governs the solve
 * under the class it named, and a per-call `backend = X` runs under the
 * class X knows. */
static int mmatrix_class_applies(const silc_engine *E)
{
    return !cfg_get(E, "backend") &&
           (cfg_get(E, "dispatch.solve.sparse.mmatrix.spd") ||
            !(cfg_get(E, "dispatch.solve.sparse.spd") || cfg_get(E, "dispatch.solve.sparse")));
}

/* After a sparse solve with A succeeded: A's next solve is a repeat. */
static void note_solved(const silc_call *call)
{
    static char solved; /* a marker: the attachment's presence is the fact */
    const silc_value *A = call->in[0];
    if (call->op == SILC_OP_SOLVE && A->format == SILC_FMT_CSR && !val_attach_get(A, SOLVED_KEY))
        val_attach_set(A, SOLVED_KEY, &solved, NULL); /* out of memory: the next solve is a "first" again */
}

/* 1 for a class whose backends try Cholesky first (silc_plugin.h). */
static int spd_class(const char *cls)
{
    size_t n = strlen(cls);
    return n >= 4 && !strcmp(cls + n - 4, ".spd");
}

/* 1 when the configuration (or the call's options) names a backend list
 * for a sparse solve class and none for solve.band: then a banded CSR
 * matrix is the user's sparse system, not LAPACK's band one (a config that
 * says `solve.sparse = lis-style` means every sparse solve). */
static int sparse_governs_band(const silc_engine *E)
{
    return E && !cfg_get(E, "dispatch.solve.band") &&
           (cfg_get(E, "dispatch.solve.sparse") || cfg_get(E, "dispatch.solve.sparse.spd"));
}

/* The properties a solve's classification asks of A.  A dense A's norms
 * come in the shape's own pass for little more, and a first solve's report
 * needs them (||A||_inf for the backward error, ||A||_1 for the estimate),
 * so they are asked together; a solve that reports neither
 * (accuracy.condest = off, solve.backward_error = on_request) takes the
 * shape alone, a pass with no ordered sums (val_props_part), and the norms
 * come later if `info` wants them; when that pass can also copy A for the
 * backend, run_call has it do so first (prepare_dense_copy). */
static int solve_parts(const silc_engine *E, const silc_value *A)
{
    const char *c, *b;
    if (!E || A->format != SILC_FMT_DENSE) return SILC_PROPS_SHAPE;
    c = cfg_get(E, "accuracy.condest");
    b = cfg_get(E, "solve.backward_error");
    if (c && !strcmp(c, "off") && b && !strcmp(b, "on_request")) return SILC_PROPS_SHAPE;
    return SILC_PROPS_SHAPE | SILC_PROPS_NORMS;
}

/* A bare dense solve (solve_parts: the shape alone) of a square real A
 * whose shape is not known yet and whose corners A(n,1) and A(1,n) are
 * nonzero -- so kl = ku = n - 1: not diagonal, not triangular, not banded,
 * and its class (general or SPD) factors a copy of all of A -- gets its
 * shape pass and that copy in one read of A (val_shape_into), the copy
 * kept in *copy for the backend (host->take_dense_copy).  At n = 1000 A is
 * 8 MB, 8x the L2: the shape pass and the backend's own memcpy each read
 * it from memory.  Nothing is made when the array cannot be had: the
 * classification then makes its pass as before. */
static void prepare_dense_copy(const silc_engine *E, const silc_call *call, disp_dense_copy *copy)
{
    silc_value *A = (silc_value *)call->in[0]; /* the shape is a cache, not the contents */
    copy->of = NULL;
    copy->array = NULL;
    if (call->op != SILC_OP_SOLVE || !A || E->dist || A->dist || A->format != SILC_FMT_DENSE ||
        A->field != SILC_FIELD_REAL || A->m != A->n || A->n < 2 || (A->props_have & SILC_PROPS_SHAPE) ||
        solve_parts(E, A) != SILC_PROPS_SHAPE || A->val[A->n - 1] == 0 || A->val[(A->n - 1) * A->m] == 0)
        return;
    copy->array = val_array_alloc(A->m * A->n, sizeof(double), 0);
    if (copy->array && val_shape_into(A, copy->array) == 0) {
        copy->of = A;
    } else {
        val_array_free(copy->array);
        copy->array = NULL;
    }
}

/* The class chain of call, with a readable reason in why (may be NULL). */
static int classify(const silc_engine *E, const silc_call *call, const char *out[4], char *why, size_t whylen)
{
    const silc_value *A, *B;
    const silc_props *p;
    const char *reason;
    char band_reason[160], spd_reason[320];
    int sparse, banded = 0, n = 0;
    if (why && whylen) why[0] = '\0';
    if (!call || call->op < 0 || call->op >= SILC_OP_COUNT || call->nin < 1 || !call->in[0])
        return 0;
    A = call->in[0];
    B = call->nin > 1 ? call->in[1] : NULL;
    switch (call->op) {
    case SILC_OP_SOLVE:
        p = val_props_part(A, solve_parts(E, A)); /* symmetry only if the shape leaves it open */
        if (!p) return 0;
        sparse = A->format == SILC_FMT_CSR;
        if (A->m != A->n) {
            out[n++] = "solve.rect";
            reason = "not square (least squares)";
        } else if (p->diagonal) {
            out[n++] = "solve.diag";
            reason = "diagonal";
        } else if (p->lower || p->upper) {
            out[n++] = "solve.triangular";
            reason = p->lower ? "lower triangular" : "upper triangular";
        } else if ((banded = A->format == SILC_FMT_BAND ||
                             ((double)p->nnz >= 0.5 * (double)(p->kl + p->ku + 1) * (double)A->n &&
                              2 * (p->kl + p->ku + 1) < A->n)) &&
                   !(sparse && sparse_governs_band(E))) {
            out[n++] = "solve.band";
            snprintf(band_reason, sizeof band_reason, "banded (kl=%lld, ku=%lld)",
                     (long long)p->kl, (long long)p->ku);
            reason = band_reason;
        } else if (p->pos_diag && val_props_part(A, SILC_PROPS_SYMMETRY)->hermitian) {
            /* Hermitian (for a real A: symmetric) with a real positive
             * diagonal: Cholesky's class.  A complex symmetric A (A = A.')
             * is not, and goes to the general class below (LU).  (Not on an
             * MPI engine: its lists start with the distributed solvers.)  A
             * repeat, or a first solve expected to be repeated, is scanned
             * only to explain itself. */
            int repeat = sparse && val_attach_get(A, SOLVED_KEY) != NULL;
            const char *again = sparse && E && !repeat ? E->solve_again : NULL;
            int mm = sparse && E && !E->dist && (!(repeat || again) || why) && mmatrix_class_applies(E) &&
                     A->field == SILC_FIELD_REAL && large_mmatrix(A);
            if (mm && !repeat && !again) out[n++] = "solve.sparse.mmatrix.spd";
            out[n++] = sparse ? "solve.sparse.spd" : "solve.dense.spd";
            out[n++] = sparse ? "solve.sparse" : "solve.dense";
            snprintf(spd_reason, sizeof spd_reason, "%s%s%s%s",
                     banded ? "banded, but a sparse class is configured and solve.band is not; " : "",
                     !mm ? (A->field == SILC_FIELD_COMPLEX ? "Hermitian with real positive diagonal"
                                                          : "symmetric with positive diagonal")
                     : repeat ? "symmetric M-matrix solved before (a factorization kept for the later solves "
                                "pays from here)"
                     : again  ? "symmetric M-matrix, first solve with it, "
                              : "symmetric M-matrix (positive diagonal, off-diagonal entries <= 0), first "
                                "solve with it",
                     mm && again ? again : "",
                     mm && again ? " (a factorization kept for the later solves pays from the first)" : "");
            reason = spd_reason;
        } else if (banded) {
            out[n++] = "solve.sparse";
            reason = "banded, but a sparse class is configured and solve.band is not";
        } else {
            out[n++] = sparse ? "solve.sparse" : "solve.dense";
            const silc_props *ps = why ? val_props_part(A, SILC_PROPS_SYMMETRY) : NULL;
            reason = !ps ? "general"
                     : A->field == SILC_FIELD_COMPLEX && ps->hermitian ? "Hermitian, some diagonal entry not real and > 0"
                     : A->field == SILC_FIELD_COMPLEX && ps->symmetric ? "complex symmetric (A = A.'), not Hermitian"
                     : ps->symmetric ? "symmetric, some diagonal entry <= 0"
                                     : "general";
        }
        if (why && whylen) {
            int k = snprintf(why, whylen, "A is %lldx%lld %s%s, %s -> %s", (long long)A->m,
                             (long long)A->n, A->field == SILC_FIELD_COMPLEX ? "complex " : "",
                             val_format_name(A->format), reason, out[0]);
            for (int c = 1; c < n && k > 0 && (size_t)k < whylen; c++) {
                int more = snprintf(why + k, whylen - (size_t)k, ", then %s", out[c]);
                k = more > 0 ? k + more : -1;
            }
        }
        return n;
    case SILC_OP_MATMUL:
        if (!B) return 0;
        if (A->format == SILC_FMT_CSR && B->format == SILC_FMT_CSR) out[n++] = "matmul.sparse_sparse";
        else if (A->format == SILC_FMT_CSR || B->format == SILC_FMT_CSR) out[n++] = "matmul.sparse_dense";
        else out[n++] = "matmul.dense";
        break;
    case SILC_OP_ADD:
    case SILC_OP_SCALE: out[n++] = "add"; break;
    case SILC_OP_EWISE:
    case SILC_OP_MAP: out[n++] = "elementwise"; break;
    case SILC_OP_TRANSPOSE: out[n++] = "transpose"; break;
    case SILC_OP_REDUCE: out[n++] = "reduce"; break;
    case SILC_OP_CONVERT: out[n++] = "convert"; break;
    case SILC_OP_DIAG: out[n++] = "diag"; break;
    default: return 0;
    }
    if (why && whylen) snprintf(why, whylen, "%s -> %s", op_names[call->op], out[0]);
    return n;
}

int disp_classes(silc_engine *E, const silc_call *call, const char *out[4])
{
    return classify(E, call, out, NULL, 0);
}

/* ---- backend lists --------------------------------------------------------- */

/* Splits a comma list into L->names.  A name written "name?" is optional:
 * the '?' is dropped, and so is the name when no loaded plugin provides it
 * (as every name of a built-in list, given by all_optional): the list is
 * then the backends that exist, and L->absent says which were left out. */
static void split_list(const silc_engine *E, blist *L, const char *text, int all_optional)
{
    char *p;
    size_t len = strnlen(text, sizeof L->buf - 1); /* cut as snprintf would, without printf's cost */
    memcpy(L->buf, text, len);
    L->buf[len] = '\0';
    L->n = 0;
    for (p = L->buf; p && L->n < DISP_MAX_LIST - 1;) {
        char *comma = strchr(p, ','), *end;
        int optional = all_optional;
        if (comma) *comma = '\0';
        while (*p == ' ' || *p == '\t') p++;
        end = p + strlen(p);
        while (end > p && (end[-1] == ' ' || end[-1] == '\t')) *--end = '\0';
        if (end - p > 1 && end[-1] == '?') *--end = '\0', optional = 1;
        if (*p && optional && !ld_find(E, p)) {
            size_t l = strlen(L->absent);
            snprintf(L->absent + l, sizeof L->absent - l, "%s%s", l ? ", " : "", p);
        } else if (*p) {
            L->names[L->n++] = p;
        }
        p = comma ? comma + 1 : NULL;
    }
}

/* E->err for a configured backend that is not loaded (key: the dispatch
 * key that names it). */
static int missing_backend(silc_engine *E, const char *key, const char *name)
{
    strbuf why;
    int rc;
    sb_init(&why);
    ld_explain_missing(E, name, &why);
    rc = eng_error(E, "%s names backend '%s', which is not installed: %s (write '%s?' to make it optional)", key,
                   name, why.failed ? "out of memory" : sb_str(&why), name);
    sb_free(&why);
    return rc;
}

int disp_check_configured(silc_engine *E)
{
    size_t c;
    for (c = 0; disp_class_names[c]; c++) {
        char key[160];
        const char *text;
        blist L;
        int i;
        snprintf(key, sizeof key, "dispatch.%s", disp_class_names[c]);
        if (!(text = cfg_get(E, key))) continue;
        memset(&L, 0, sizeof L);
        split_list(E, &L, text, 0);
        for (i = 0; i < L.n; i++)
            if (!ld_find(E, L.names[i])) return missing_backend(E, key, L.names[i]);
    }
    return 0;
}

/* Where resolve_list found L's names, as explain says it. */
static void list_source(const blist *L, strbuf *b)
{
    if (L->forced) sb_printf(b, "per-call option backend = %s", L->forced_text);
    else if (L->key[0]) sb_printf(b, "config key %s", L->key);
    else sb_printf(b, "built-in default for %s%s", L->default_class,
                   L->default_distributed ? ", distributed operands" : "");
}

static void resolve_list_afresh(const silc_engine *E, int distributed, const char *const *chain, int nchain,
                                blist *L)
{
    const char *forced = cfg_get(E, "backend"), *text = NULL;
    char key[sizeof L->key] = "dispatch.";
    size_t i;
    int c;
    /* Every field but the arrays, which are written before they are read
     * (a whole memset is 1.7 KB a call) */
    L->n = L->nlisted = L->forced = L->default_distributed = 0;
    L->key[0] = L->absent[0] = '\0';
    L->forced_text = L->default_class = NULL;
    if (forced) {
        split_list(E, L, forced, 0);
        L->nlisted = L->n;
        L->forced = 1;
        L->forced_text = forced;
        return;
    }
    for (c = 0; c < nchain && !text; c++) {
        /* "dispatch." + the class, as snprintf would cut it, by copies */
        size_t at = sizeof "dispatch." - 1, len = strnlen(chain[c], sizeof key - 1 - at);
        memcpy(key + at, chain[c], len);
        key[at + len] = '\0';
        text = cfg_get(E, key);
    }
    if (text) memcpy(L->key, key, sizeof L->key);
    if (!text) {
        text = "reference";
        for (i = 0; i < sizeof default_lists / sizeof default_lists[0]; i++)
            if (strcmp(default_lists[i].cls, chain[0]) == 0) text = default_lists[i].list;
        for (i = 0; distributed && i < sizeof distributed_lists / sizeof distributed_lists[0]; i++)
            if (strcmp(distributed_lists[i].cls, chain[0]) == 0) text = distributed_lists[i].list;
        L->default_class = chain[0];
        L->default_distributed = distributed;
    }
    split_list(E, L, text, !L->key[0]);
    L->nlisted = L->n;
    for (c = 0; c < L->n; c++)
        if (strcmp(L->names[c], "reference") == 0) return;
    L->names[L->n++] = "reference";
}

/* ---- the resolved lists of the last class chains -----------------------------
 * Resolving a list reads two or three settings, copies and splits a text
 * and looks each name up: a tenth of a small SpMV statement's fixed cost
 * (docs/overhead.md, issue 30).  What comes out depends only on the class
 * chain, on whether the operands are distributed, on the settings and on
 * which backends are installed; so the last LIST_CACHE lists are kept, each
 * with the settings' generation it was made under (cfg_generation), and one
 * made under another generation is made again.  The installed backends
 * change only when core.plugin_path is set (a setting: a new generation)
 * or at engine start; a plugin opened at first use (loader.c) was already
 * known by name, and one that failed to open stays closed.  The chain is
 * compared by its pointers (classify's string constants): another pointer
 * to the same text only misses.  A list is copied out, never lent: a call
 * inside the walk (refinement, per-call options) may remake the entry. */
#define LIST_CACHE 8

typedef struct cached_list {
    const char *chain[4];
    int nchain, distributed;
    uint64_t generation, used;
    size_t buflen;         /* bytes of L.buf in use */
    blist L;
} cached_list;

typedef struct list_cache {
    cached_list e[LIST_CACHE];
    int n;
    uint64_t clock;
} list_cache;

/* Whether name points into L's buffer (else at a constant: "reference");
 * compared as integers, since C orders only pointers into one object. */
static int in_buf(const blist *L, const char *name)
{
    uintptr_t p = (uintptr_t)name, b = (uintptr_t)L->buf;
    return p >= b && p < b + sizeof L->buf;
}

/* *to = *from, with the names that point into from's buffer pointing into
 * to's, copying only the bytes in use. */
static void blist_copy(blist *to, const blist *from, size_t buflen)
{
    int i;
    memcpy(to->buf, from->buf, buflen);
    for (i = 0; i < from->n; i++)
        to->names[i] = in_buf(from, from->names[i]) ? to->buf + ((uintptr_t)from->names[i] - (uintptr_t)from->buf)
                                                    : from->names[i];
    to->n = from->n;
    memcpy(to->key, from->key, strlen(from->key) + 1);
    memcpy(to->absent, from->absent, strlen(from->absent) + 1);
    to->forced = from->forced;
    to->nlisted = from->nlisted;
    to->forced_text = from->forced_text;
    to->default_class = from->default_class;
    to->default_distributed = from->default_distributed;
}

/* The bytes of L->buf that split_list wrote (the text with its commas cut). */
static size_t buf_in_use(const blist *L)
{
    size_t end = 0;
    for (int i = 0; i < L->n; i++)
        if (in_buf(L, L->names[i])) {
            size_t e = (size_t)((uintptr_t)L->names[i] - (uintptr_t)L->buf) + strlen(L->names[i]) + 1;
            if (e > end) end = e;
        }
    return end;
}

static void resolve_list(const silc_engine *E, const silc_call *call, const char *const *chain, int nchain,
                         blist *L)
{
    int distributed = E->dist && dist_call_has(call), i, c;
    uint64_t generation = cfg_generation(E);
    list_cache *C = nchain >= 1 && nchain <= 4 ? cfg_derived(E, sizeof *C) : NULL;
    cached_list *e = NULL;
    if (!C) { /* out of memory: every call resolves its list */
        resolve_list_afresh(E, distributed, chain, nchain, L);
        return;
    }
    for (i = 0; i < C->n && !e; i++) {
        cached_list *x = &C->e[i];
        if (x->nchain != nchain || x->distributed != distributed) continue;
        for (c = 0; c < nchain && x->chain[c] == chain[c]; c++) continue;
        if (c == nchain) e = x;
    }
    if (e && e->generation == generation) {
        e->used = ++C->clock;
        blist_copy(L, &e->L, e->buflen);
        return;
    }
    resolve_list_afresh(E, distributed, chain, nchain, L);
    if (!e) { /* a new chain: a free entry, or the least recently used one */
        int old = 0;
        if (C->n < LIST_CACHE) old = C->n++;
        else
            for (i = 1; i < C->n; i++)
                if (C->e[i].used < C->e[old].used) old = i;
        e = &C->e[old];
        for (c = 0; c < nchain; c++) e->chain[c] = chain[c];
        e->nchain = nchain;
        e->distributed = distributed;
    }
    e->generation = generation;
    e->used = ++C->clock;
    e->buflen = buf_in_use(L);
    blist_copy(&e->L, L, e->buflen);
}

static int provides(const ld_backend *b, int op)
{
    return op < b->backend->n_ops && b->backend->ops[op].run != NULL;
}

/* 1 when call has a complex operand (or a complex alpha or beta). */
static int call_complex(const silc_call *call)
{
    for (int i = 0; i < call->nin; i++)
        if (call->in[i] && call->in[i]->field == SILC_FIELD_COMPLEX) return 1;
    return call->alpha_imag != 0 || call->beta_imag != 0;
}

/* The complex operands of call, as a user reads them ("operand 1 (3x3
 * complex csr)"), for the error of a chain no backend would take. */
static void describe_complex_operands(const silc_call *call, strbuf *b)
{
    const char *sep = "";
    for (int i = 0; i < call->nin; i++) {
        const silc_value *v = call->in[i];
        if (!v || v->field != SILC_FIELD_COMPLEX) continue;
        sb_printf(b, "%soperand %d (%lldx%lld complex %s)", sep, i + 1, (long long)v->m, (long long)v->n,
                  val_format_name(v->format));
        sep = ", ";
    }
    if (!*sep) sb_printf(b, "a complex scalar factor");
}

static const char *status_text(int status)
{
    switch (status) {
    case SILC_EARG: return "invalid operands";
    case SILC_ENOMEM: return "out of memory";
    case SILC_ESINGULAR: return "singular matrix";
    case SILC_ENOTSPD: return "not positive definite";
    case SILC_ENOTCONV: return "did not converge";
    case SILC_EBREAKDOWN: return "iterative method broke down";
    case SILC_EDECLINE: return "declined";
    case SILC_ELIB: return "library failure";
    case SILC_EUNSUP: return "not supported";
    case SILC_EINTERNAL: return "internal error";
    default: return "failed";
    }
}

/* ---- the accuracy report --------------------------------------------------- */

/* The warnings a condition number cond deserves: "singular to working
 * precision" from 1/eps, "fewer than 4 correct digits" above 1e-4/eps.  cond
 * is the estimate once it is made (at solve time, or when the report is
 * read: disp_condest_resolve), or, with lower_bound, a rigorous lower bound
 * of cond_1 that settles the warning before the estimate is made
 * (condest_settle), and the text says so. */
static void warn_condition_of(silc_engine *E, double cond, int lower_bound)
{
    char what[160];
    double eps_cond = cond * DBL_EPSILON;
    if (lower_bound)
        snprintf(what, sizeof what, "cond_1 >= %.2g so far, a rigorous lower bound; the condition estimate is made "
                 "when the report is read", cond);
    else
        snprintf(what, sizeof what, "condition estimate %.2g", cond);
    if (cond > 0 && eps_cond >= 1)
        eng_warn(E, "'\\': matrix is singular to working precision (%s)", what);
    else if (cond > 0 && eps_cond > 1e-4)
        eng_warn(E, "'\\': result may have fewer than 4 correct digits (%s)", what);
}

static void warn_condition(silc_engine *E, const silc_report *r)
{
    warn_condition_of(E, r->cond_est, 0);
}

/* Completes the report of a solve that succeeded and warns about a result that
 * deserves distrust.  -1 when the backward error could not be computed (out
 * of memory): a result returned without it could hide an unsolved system. */
static int finish_solve(silc_engine *E, silc_call *call, int cholesky_failed, int may_defer)
{
    silc_report *r = call->report;
    if (cholesky_failed) {
        char note[sizeof r->note];
        /* Name the method that did solve: after Cholesky, a symmetric
         * matrix goes to LDL' (dsytrf), not necessarily to LU. */
        snprintf(note, sizeof note, "Cholesky failed (not positive definite); used %.64s%s%.120s",
                 r->method[0] ? r->method : "the next method in the chain",
                 r->note[0] ? "; " : "", r->note);
        memcpy(r->note, note, sizeof note);
    }
    warn_condition(E, r);
    acc_report(E, call, may_defer, cfg_get(E, "solve.backward_error"));
    if (r->backward_error < 0 && r->backward_error != ACC_DEFERRED)
        return eng_error(E, "out of memory computing the backward error of '\\'");
    if (val_has_nonfinite(call->out))
        eng_warn(E, "'\\': the result contains NaN or Inf (backend %s)", r->backend);
    return 0;
}

/* ---- refinement (refine.c) -------------------------------------------------- */

/* A report as a backend gets it: zeroed, estimates unknown, and told
 * whether the session wants a condition estimate (accuracy.condest), and
 * whether one that costs solves of its own may be left for later (later:
 * the caller may defer it, and accuracy.condest is auto or on_request). */
static void report_reset(silc_engine *E, silc_report *r, int later)
{
    const char *c = cfg_get(E, "accuracy.condest");
    memset(r, 0, sizeof *r);
    r->cond_est = r->rcond = -1;
    r->forward_bound = -1;
    r->condest_off = c && !strcmp(c, "off");
    /* 2: on_request, whose estimate is never made at once, wants no bound */
    r->condest_later = !later                                             ? 0
                       : !c || !strcmp(c, "auto") || !strcmp(c, "on") ? 1
                       : !strcmp(c, "on_request")                     ? 2
                                                                      : 0;
}

/* refine_how's correction solve: D = A \ R by backend be (an ld_backend)
 * with the call's class and options; NULL (and why in err) when it fails. */
static silc_value *correction(const void *be, silc_engine *E, const silc_call *call, const silc_value *R,
                              char *err, size_t errlen)
{
    const ld_backend *b = be;
    silc_call c = *call;
    silc_report rep;
    host_call_ctx ctx;
    int rc;
    report_reset(E, &rep, 1); /* a correction makes no estimate: the solve's report has it */
    memset(&ctx, 0, sizeof ctx);
    ctx.E = E;
    ctx.backend = b;
    c.in[1] = R;
    c.out = NULL;
    c.report = &rep;
    c.host_private = &ctx;
    rc = b->backend->ops[SILC_OP_SOLVE].run(&c);
    if (rc == SILC_OK && c.out && c.out->m == call->out->m && c.out->n == call->out->n)
        return c.out;
    val_release(c.out);
    snprintf(err, errlen, "%s", ctx.err[0] ? ctx.err : "the correction solve failed");
    return NULL;
}

/* Iterative refinement of call->out by backend b, at least at_least steps
 * (refine_solve), with the settings of this call. */
static void refine(silc_engine *E, silc_call *call, const ld_backend *b, int64_t at_least)
{
    refine_how how;
    const char *acc;
    how.steps = cfg_get(E, "solve.refine");
    how.residual = cfg_get(E, "solve.refine_residual");
    acc = cfg_get(E, "tune.accuracy"); /* config.c checked it is a number in (0, 1) */
    how.target = acc ? strtod(acc, NULL) : 0;
    how.backend = b->full_name;
    how.correct = correction;
    how.ctx = b;
    refine_solve(E, call, &how, at_least);
}

/* ---- the condition estimate, now or when the report is read -----------------
 * Hager-Higham needs about four column solves after the factorization; where
 * a solve costs 10-30 % of the factorization (KLU and CHOLMOD on very sparse
 * matrices, MUMPS's fixed cost per solve phase) the estimate cannot cost
 * under 15 % of it at solve time.  So under accuracy.condest = auto (the
 * default; `on` says the same) a solve asks its backend to leave out an
 * estimate that costs solves of its own (report->condest_later, ABI 1.8).
 * A backend that did says so, with the estimate's cost in solves like the one
 * it just made, and condest_settle makes it at once -- a condest_only call to
 * the same backend, whose factorization is attached to A -- when that costs
 * at most DISP_CONDEST_BUDGET of the factorization the call made, or when
 * the condition warnings could fire (condest_urgent), so that they come at
 * solve time.  Otherwise the estimate is owed and made when the report is
 * read (disp_condest_resolve, from `info`).  A solve that reused a
 * factorization made none to weigh the cost against: its estimate is owed.
 * accuracy.condest = now keeps every estimate at solve time (the backend
 * then folds its first block into the user's solve, as before);
 * on_request owes every estimate that costs solves, whatever it could
 * warn (its warnings then come when the report is read), for a program of
 * many solves that reads few reports. */
#define DISP_CONDEST_BUDGET 0.15
/* When an owed estimate is urgent.  The warnings (warn_condition) depend on
 * the estimate alone: cond_est eps > 1e-4, i.e. cond_est > DISP_CONDEST_WARN_AT
 * = 4.5e11.  What the solve knows for free:
 *   L, a rigorous lower bound of cond_1, and of the estimate too (the
 *     estimator starts from the same vectors and keeps its best): the
 *     estimator's start block solved with the user's columns (MUMPS, the
 *     reference: condest_lower), else the solve's own ||A||_1 ||x||_1 /
 *     ||b||_1 (acc_cond_lower_bound);
 *   the library's pivot ratio (UMFPACK, KLU, CHOLMOD), no bound at all.
 * The estimate is at most DISP_CONDEST_LOWER_SLACK x the start block's L
 * on every shared matrix (docs/accuracy.md, measured with MUMPS and the
 * reference: 7900 on bayer10, where L alone is over the threshold; 620 on
 * west0479, the largest where it is not), so it is skipped only when L x
 * the slack cannot reach the threshold: below L = 5.6e7 the warning
 * cannot fire on any matrix like the shared ones.  The solve's own bound
 * is far weaker (1e3 to 1e12 below the estimate with b = A * ones): it
 * serves only where a backend gives neither of the others (MUMPS's solve
 * that runs its error analysis), and rarely proves anything.
 * UMFPACK's and KLU's pivot ratio is no bound (3.8 against 840 on the 1-D
 * Laplacian, 2 against 1.5e11 on fs_183_6), but every shared matrix that
 * warns has one of 1.2e7 or more: 1e6 keeps a margin of 12 (a heuristic,
 * documented as such; `now` is the setting that never relies on it).
 * Real UMFPACK and KLU answer a ratio above it with the start block's L
 * (ss.h, SILC_CONDEST_PIVOT_HINT), which then decides by the rule for L.
 * CHOLMOD's, (max L_ii / min L_ii)^2 of A = L L', is a rigorous lower
 * bound of cond_2(A) <= cond_1(A) and comes as condest_lower (cholmod.c);
 * the estimate is at most 740 times it on the shared spd matrices. */
#define DISP_CONDEST_WARN_AT (1e-4 / DBL_EPSILON)
#define DISP_CONDEST_LOWER_SLACK 8000.0
#define DISP_CONDEST_PIVOT_HINT SILC_CONDEST_PIVOT_HINT /* shared with the plugins that answer it */

/* The estimate's cost as a share of the factorization the solve made
 * (INFINITY when it made none). */
static double condest_share(const silc_report *r)
{
    if (r->reused_factor || !(r->factor_seconds > 0)) return INFINITY;
    return r->condest_solves * r->solve_seconds / r->factor_seconds;
}

void disp_condest_why(const silc_report *r, char *buf, size_t len)
{
    double share = condest_share(r);
    if (isfinite(share))
        snprintf(buf, len, "it costs %.3g solves = %.0f %% of the factorization", r->condest_solves,
                 100 * share);
    else
        snprintf(buf, len, "it costs %.3g solves and the solve reused a factorization", r->condest_solves);
}

/* Backend b's estimate alone (condest_only) for the call like's A, class and
 * options (those in force), into r: cond_est, and the plugin's note of how
 * it was made added to r's.  The call's status; r unchanged unless SILC_OK
 * and an estimate came. */
static int estimate_only(silc_engine *E, const ld_backend *b, const silc_call *like, silc_report *r)
{
    silc_call c = *like;
    silc_report rep;
    host_call_ctx ctx;
    int rc;
    report_reset(E, &rep, 0);
    rep.condest_off = 0; /* owed under the setting of the solve, whatever it is now */
    rep.condest_only = 1;
    memset(&ctx, 0, sizeof ctx);
    ctx.E = E;
    ctx.backend = b;
    c.nin = 2; /* no initial guess */
    c.out = NULL;
    c.report = &rep;
    c.host_private = &ctx;
    rc = b->backend->ops[SILC_OP_SOLVE].run(&c);
    val_release(c.out);
    if (rc != SILC_OK || !(rep.cond_est >= 0 || isnan(rep.cond_est))) return rc == SILC_OK ? SILC_EDECLINE : rc;
    r->cond_est = rep.cond_est;
    if (rep.note[0] && !strstr(r->note, rep.note)) {
        size_t len = strlen(r->note);
        snprintf(r->note + len, sizeof r->note - len, "%s%s", len ? "; " : "", rep.note);
    }
    return SILC_OK;
}

/* 1 when the warnings could fire on the estimate the solve left owed (the
 * rule above DISP_CONDEST_WARN_AT). */
static int condest_urgent(const silc_call *call)
{
    const silc_report *r = call->report;
    double lower = r->condest_lower;
    /* a backend that gives a rigorous bound is judged by it, not by the
     * pivot heuristic (CHOLMOD's ratio is one: see the rule above) */
    if (lower > 0) return !(lower * DISP_CONDEST_LOWER_SLACK < DISP_CONDEST_WARN_AT);
    if (r->pivot_ratio > DISP_CONDEST_PIVOT_HINT) return 1;
    /* The solve's own lower bound costs a pass over A (for ||A||_1) and
     * the operands, a few per cent of a KLU factorization: only where the
     * backend gives no hint of its own. */
    if (r->pivot_ratio == 0 && lower == 0) lower = acc_cond_lower_bound(call->in[0], call->in[1], call->out);
    return !(lower * DISP_CONDEST_LOWER_SLACK < DISP_CONDEST_WARN_AT); /* NaN: urgent */
}

/* 1 when the backend's rigorous lower bound L (condest_lower) settles which
 * condition warning the estimate would give, so that an urgent estimate may
 * still be owed with its warning given at solve time (condest_settle).  The
 * estimate starts from L's vectors and never decreases, so it is >= L (a
 * CHOLMOD diagonal bound is of cond_1 only: hence the warning's text speaks
 * of cond_1).  L >= 1/eps settles "singular to working precision"; L >=
 * DISP_CONDEST_WARN_AT settles "fewer than 4 correct digits", and the
 * singular warning is ruled out by the rule that makes the estimate urgent
 * (it is at most DISP_CONDEST_LOWER_SLACK x L on every shared matrix) when
 * L x the slack < 1/eps, i.e. L < 5.6e11: bayer10 (L 4.83e11, estimate
 * 3.82e15).  Between the two (watt_2, L 8.5e11) the estimate is made at
 * once, as an L below the threshold makes it: "singular" could fire. */
static int condest_settled(const silc_report *r)
{
    double eps_lower = r->condest_lower * DBL_EPSILON; /* warn_condition_of's tests */
    if (eps_lower >= 1) return 1;
    return eps_lower > 1e-4 && eps_lower * DISP_CONDEST_LOWER_SLACK < 1;
}

/* A solve whose backend left its estimate out (condest_deferred = 1): made
 * now when it is cheap or the matrix may be ill-conditioned, else owed.
 * -1 when that estimate ran out of memory: the solve fails, as it did when
 * the backend made it (no estimate would mean no warning). */
static int condest_settle(silc_engine *E, silc_call *call, const ld_backend *b)
{
    silc_report *r = call->report;
    const char *mode = cfg_get(E, "accuracy.condest");
    if (r->condest_deferred != 1) {
        r->condest_deferred = 0; /* a plugin that knows no deferral may have left anything */
        return 0;
    }
    if (mode && !strcmp(mode, "on_request")) return 0; /* owed, whatever it costs */
    if (condest_share(r) > DISP_CONDEST_BUDGET) {
        if (!condest_urgent(call)) return 0; /* owed */
        if (condest_settled(r)) { /* owed, its warning given now */
            warn_condition_of(E, r->condest_lower, 1);
            return 0;
        }
    }
    r->condest_deferred = 0;
    return estimate_only(E, b, call, r) == SILC_ENOMEM ? -1 : 0; /* else none: "the backend gives none" */
}

int disp_condest_resolve(silc_engine *E, eng_pending *p, silc_report *r)
{
    const ld_backend *b;
    silc_call c;
    int rc = 0;
    if (r->condest_deferred != 1) return 0;
    r->condest_deferred = DISP_CONDEST_LOST;
    if (!p->A || !p->B || !(b = ld_find(E, r->backend)) || !provides(b, SILC_OP_SOLVE)) return 0;
    memset(&c, 0, sizeof c);
    c.op = SILC_OP_SOLVE;
    c.sub = p->sub;
    c.nin = 2;
    c.in[0] = p->A;
    c.in[1] = p->B;
    c.options = p->options;
    c.op_class = p->op_class;
    if (p->options && cfg_set_call_options(E, p->options)) return 0;
    switch (estimate_only(E, b, &c, r)) {
    case SILC_OK:
        r->condest_deferred = DISP_CONDEST_READ;
        warn_condition(E, r);
        break;
    case SILC_EDECLINE: break; /* no factorization attached any more: DISP_CONDEST_LOST */
    case SILC_ENOMEM: /* still owed: `info` fails, and may be asked again */
        r->condest_deferred = 1;
        rc = eng_error(E, "out of memory for the condition estimate");
        break;
    default: r->condest_deferred = 0; /* it failed: "the backend gives none" */
    }
    if (p->options) cfg_clear_call_options(E);
    return rc;
}

/* ---- running --------------------------------------------------------------- */

/* ---- what a solve leaves attached --------------------------------------------
 * A plugin's factorization hangs off its matrix (an attachment) and lives
 * as long as the value; the plugin ABI does not say how large it is, and
 * UMFPACK, MUMPS or PETSc allocate it with their own malloc.  So it is
 * measured: the heap in use (glibc's mallinfo2: the main arena, where the
 * engine's thread allocates, and every mmapped block; under AddressSanitizer
 * its allocator's count; and the large allocator's huge-page blocks) grows across the call by what the call kept,
 * less the value arrays it made (its result, counted by the store); that
 * growth is charged to the attachments the call added (val_attach_charge),
 * shared if it added several (a collective solve's: summed over the
 * ranks).  What else the call kept for itself (a
 * plugin's pattern cache) is charged with them: an overestimate, on the
 * safe side.  silcd counts these charges against a session's limit, on
 * whatever value the session holds, and releases the least recently used
 * first when it is reached (lang/memo.c: memo_held, memo_release).
 * Elsewhere (no mallinfo2, or no budget to count against) nothing is
 * charged. */
static int64_t heap_in_use(void)
{
    /* plus the large allocator's mappings (a SuiteSparse factorization on
     * huge pages, util/largealloc.c), which neither count sees */
#if defined(SILC_HEAP_FROM_SANITIZER)
    return (int64_t)(__sanitizer_get_current_allocated_bytes() + util_large_in_use());
#elif defined(SILC_HEAP_FROM_MALLINFO2)
    struct mallinfo2 mi = mallinfo2();
    return (int64_t)(mi.uordblks + mi.hblkhd + util_large_in_use());
#else
    return -1;
#endif
}

typedef struct attach_watch {
    int on;
    int64_t heap, live;
    const val_attachment *before[3];   /* each operand's attachment list before the call */
} attach_watch;

static void watch_begin(attach_watch *w, const silc_call *call)
{
    int i;
    w->on = 0;
    /* Only a session with a memory budget (silcd) reads the charges: with
     * none (embedded) the two heap readings a solve would cost are skipped. */
    if (call->op != SILC_OP_SOLVE || val_budget_room() == INT64_MAX || (w->heap = heap_in_use()) < 0) return;
    for (i = 0; i < 3; i++) w->before[i] = i < call->nin && call->in[i] ? call->in[i]->attach : NULL;
    w->live = val_live_bytes();
    w->on = 1;
}

/* New attachments are put first in a value's list: those before the old
 * head are the call's.  One that owns nothing (no destructor: a marker) is
 * not charged. */
static int new_attachments(const silc_value *v, const val_attachment *before, int charge_them, int64_t bytes)
{
    const val_attachment *a;
    int count = 0;
    for (a = v ? v->attach : NULL; a && a != before; a = a->next)
        if (a->destroy) {
            if (charge_them) val_attach_charge(v, a->key, bytes);
            count++;
        }
    return count;
}

/* ranks: the engine of a collective call, whose factorization lies in
 * parts on every rank: each rank's charge is the sum of the parts (every
 * rank reaches this reduction, whether or not its part attached), so that
 * the one rank that measures a session (silcd --mpi's rank 0) counts all of
 * it. */
static void watch_end(attach_watch *w, const silc_call *call, silc_engine *ranks)
{
    int64_t kept;
    int i, count = 0;
    if (!w->on) return;
    kept = heap_in_use() - w->heap - (val_live_bytes() - w->live);
    if (ranks) kept = (int64_t)dist_sum(ranks, kept > 0 ? (double)kept : 0);
    for (i = 0; i < 3 && i < call->nin; i++)
        if (!(i > 0 && call->in[i] == call->in[0])) count += new_attachments(call->in[i], w->before[i], 0, 0);
    if (!count) return;
    for (i = 0; i < 3 && i < call->nin; i++)
        if (!(i > 0 && call->in[i] == call->in[0]))
            new_attachments(call->in[i], w->before[i], 1, kept > 0 ? kept / count : 0);
}

/* One attempt of backend b; the report is reset for every attempt so nothing
 * of a failed backend leaks into the one that succeeds.  condest_later: the
 * condition estimate may be left for later (report_reset). */
static int run_one(silc_engine *E, silc_call *call, const ld_backend *b, int condest_later)
{
    double t0;
    attach_watch watch;
    int rc;
    call->out = NULL;
    if (call->op == SILC_OP_SOLVE) report_reset(E, call->report, condest_later);
    watch_begin(&watch, call);
    t0 = call->op == SILC_OP_SOLVE ? util_now() : 0; /* only a solve's report reads it */
    rc = b->backend->ops[call->op].run(call);
    watch_end(&watch, call, ((const host_call_ctx *)call->host_private)->collective ? E : NULL);
    if (rc == SILC_OK) rc = host_check_result(call);
    if (rc == SILC_OK && call->op == SILC_OP_SOLVE) {
        call->report->seconds = util_now() - t0;
        snprintf(call->report->backend, sizeof call->report->backend, "%s", b->full_name);
        /* accuracy.condest = off: a plugin older than ABI 1.7 estimated
         * anyway; the report says "not estimated" all the same. */
        if (call->report->condest_off) call->report->cond_est = -1;
    }
    if (rc != SILC_OK) {
        val_release(call->out);
        call->out = NULL;
    }
    return rc;
}

/* The listed backends after index i that might still take the call: a
 * failure hands the call on only to those (the reference plugin that
 * resolve_list appends to every list is a last resort for operations no
 * listed backend provides, not a fallback for one that failed; a per-call
 * `backend = X` of one name has nothing to fall back to). */
static int fallback_left(const blist *L, int i)
{
    return i + 1 < L->nlisted;
}

/* A backend's failure, or a result that failed verification, recorded as
 * one line of the chain's account; E->err holds the message. */
static void note_attempt(silc_engine *E, strbuf *attempts, double seconds)
{
    sb_printf(attempts, "%s%s (%.3g s)", attempts->len ? "\n  " : "", E->err, seconds);
}

/* The backends that failed on a matrix, remembered with it (an attachment
 * of A: it goes when A goes): a time loop that solves with the same A
 * every step does not pay for the same failure every step.  A solve's
 * failure can depend on its right-hand side (an iterative method's), but a
 * backend that failed on A once is a poor first choice for it. */
#define FAILED_KEY "dispatch.failed"

/* Entries are "name\n", or "name?\n" for a result that failed
 * verification, which counts only while solve.verify is on. */
static int failed_before(silc_engine *E, const silc_value *A, const char *name)
{
    const char *list = val_attach_get(A, FAILED_KEY), *v;
    size_t len = strlen(name);
    int verifying;
    if (!list) return 0; /* the usual case: nothing failed on A */
    v = cfg_get(E, "solve.verify");
    verifying = !(v && !strcmp(v, "off"));
    for (; list && *list; list += strcspn(list, "\n") + (list[strcspn(list, "\n")] != 0))
        if (!strncmp(list, name, len) &&
            (list[len] == '\n' || !list[len] || (verifying && list[len] == '?')))
            return 1;
    return 0;
}

static void remember_failure(const silc_value *A, const char *name, int verification)
{
    const char *old = val_attach_get(A, FAILED_KEY);
    size_t ol = old ? strlen(old) : 0, size = ol + strlen(name) + 3;
    char *list = malloc(size);
    if (!list) return; /* only a memory of the failure is lost */
    snprintf(list, size, "%s%s%s\n", old ? old : "", name, verification ? "?" : "");
    if (val_attach_set(A, FAILED_KEY, list, free)) free(list);
}

/* What lets a back-substitution defer its backward error (accuracy.h):
 * the factorization's first solve, checked at once, vouches for the later
 * ones -- but only for the verification bound it was checked against.
 * Each backend's largest measured backward error on A before refinement
 * is kept with A (an attachment: it goes when A goes), and a solve defers
 * only when that number passes the solve.verify bound in force now.  So a
 * bound set after the first solve (KLU on bayer10 at 8e-13 under
 * solve.verify = 1e-13) checks, and refines, the next solve at once, as
 * it would have the first one had it been set before; and a factorization
 * whose raw solves needed refinement gets it on every solve. */
#define VOUCHED_KEY "dispatch.vouched:"

static double *vouched_slot(const silc_value *A, const ld_backend *b, char *key, size_t keylen)
{
    snprintf(key, keylen, VOUCHED_KEY "%s", b->full_name);
    return val_attach_get(A, key);
}

/* 1 when b's earlier results on A passed limit before refinement. */
static int vouched(const silc_value *A, const ld_backend *b, double limit)
{
    char key[128];
    const double *worst = vouched_slot(A, b, key, sizeof key);
    return worst && *worst <= limit;
}

/* Remembers a result of b on A whose backward error was measured. */
static void vouch(const silc_value *A, const ld_backend *b, const silc_report *r)
{
    char key[128];
    double raw = r->backward_error_unrefined >= 0 ? r->backward_error_unrefined : r->backward_error;
    double *worst = vouched_slot(A, b, key, sizeof key);
    if (!(raw >= 0)) raw = INFINITY; /* NaN: never vouches */
    if (worst) {
        if (raw > *worst) *worst = raw;
        return;
    }
    if (!(worst = malloc(sizeof *worst))) return; /* then the next solve is checked at once */
    *worst = raw;
    if (val_attach_set(A, key, worst, free)) free(worst);
}

/* Drops the warnings added since mark: they were a discarded result's. */
static void drop_warnings(silc_engine *E, size_t mark)
{
    E->warnings.len = mark;
    if (E->warnings.s) E->warnings.s[mark] = 0;
}

/* The error of a chain whose every listed backend failed: each attempt's
 * reason on a line of its own, the last one included. */
static void chain_error(silc_engine *E, strbuf *attempts)
{
    char last[sizeof E->err];
    if (!attempts->len) return;
    snprintf(last, sizeof last, "%s", E->err);
    eng_error(E, "every backend of the list failed:\n  %s\n  %s", sb_str(attempts), last);
}

/* Backend b, entry i of L, failed (E->err says why; verification: its
 * result failed verification): 1 when the next listed backend takes over --
 * the attempt is recorded, and remembered with A -- else 0, E->err then
 * being the chain's error. */
static int hand_over(silc_engine *E, const silc_call *call, const blist *L, int i, const ld_backend *b,
                     strbuf *attempts, double seconds, int verification)
{
    /* An interrupt (or silcd's stop) ends the chain: no next backend, and
     * no failure remembered against the matrix, since the attempt may have
     * failed only because it was told to stop.  Not on a communicator,
     * where the ranks agree on stops after the statement (eval.c). */
    if (!E->dist && eng_cancel_check(E)) return 0;
    if (!fallback_left(L, i)) {
        chain_error(E, attempts);
        return 0;
    }
    note_attempt(E, attempts, seconds);
    if (!E->dist) remember_failure(call->in[0], b->full_name, verification);
    return 1;
}

static int walk(silc_engine *E, silc_call *call, const char *const *chain, int nchain,
                const blist *L, int may_defer, disp_dense_copy *copy)
{
    strbuf skipped, attempts;
    dist_swap swap;
    int ci, i, rc, cholesky_failed = 0, complex = call_complex(call);
    sb_init(&skipped);
    sb_init(&attempts);
    for (ci = 0; ci < nchain; ci++) {
        int next_class = 0;
        for (i = 0; i < L->n && !next_class; i++) {
            const ld_backend *b = ld_find(E, L->names[i]);
            const char *why = NULL;
            host_call_ctx ctx;
            size_t warned = E->warnings.len;
            double t0;
            if (ci > 0 && i == 0) sb_printf(&skipped, "[%s] ", chain[ci]);
            if (!b && L->key[0]) {
                /* A dispatch key set in the session after the start check
                 * (disp_check_configured): the same error, not a substitute. */
                missing_backend(E, L->key, L->names[i]);
                call->host_private = NULL;
                sb_free(&skipped);
                sb_free(&attempts);
                return SILC_EUNSUP;
            }
            if (!b) {
                sb_printf(&skipped, "%s not installed; ", L->names[i]);
                continue;
            }
            if (!provides(b, call->op)) {
                sb_printf(&skipped, "%s does not provide %s; ", b->full_name, op_names[call->op]);
                continue;
            }
            if (complex && !ld_backend_takes_complex(b, call->op)) {
                sb_printf(&skipped, "%s does not take complex values; ", b->full_name);
                continue;
            }
            if (call->op == SILC_OP_SOLVE && fallback_left(L, i) && failed_before(E, call->in[0], b->full_name)) {
                sb_printf(&attempts, "%s%s: skipped: it failed on this matrix before", attempts.len ? "\n  " : "",
                          b->full_name);
                continue;
            }
            memset(&ctx, 0, offsetof(host_call_ctx, err)); /* err is a string (dispatch.h) */
            ctx.err[0] = '\0';
            ctx.E = E;
            ctx.backend = b;
            ctx.copy = copy;
            call->host_private = &ctx;
            call->op_class = chain[ci];
            /* Distributed operands (dist.h): a collective backend runs on the
             * row blocks on every rank; any other gets whole copies. */
            if (dist_walk_begin(E, call, ld_backend_collective(b, call->op), &swap) < 0) {
                call->host_private = NULL;
                sb_free(&skipped);
                sb_free(&attempts);
                return SILC_ENOMEM;
            }
            ctx.collective = swap.mode == DIST_COLLECTIVE;
            if (b->backend->ops[call->op].accepts && !b->backend->ops[call->op].accepts(call, &why)) {
                sb_printf(&skipped, "%s declines: %s; ", b->full_name, why ? why : "no reason given");
                dist_walk_end(call, &swap);
                continue;
            }
            /* Only an attempt that can hand over to another backend reports
             * its time (hand_over); a clock read is 70-80 ns in a VM. */
            t0 = fallback_left(L, i) ? util_now() : 0;
            {
                /* An initial guess (in[2]) goes only to plugins that know of it (ABI 1.6). */
                int hide_guess = call->nin == 3 && b->plugin && b->plugin->table &&
                                 b->plugin->table->abi_minor < 6;
                if (hide_guess) call->nin = 2;
                rc = run_one(E, call, b, may_defer && !ctx.collective && !E->dist);
                if (hide_guess) call->nin = 3;
            }
            if (rc == SILC_OK && !call->out) {
                rc = SILC_EINTERNAL;
                snprintf(ctx.err, sizeof ctx.err, "reported success but returned no result");
            }
            if (ctx.collective) { /* every rank learns how every rank did */
                if (rc != SILC_OK) eng_error(E, "%s: %s", b->full_name, ctx.err[0] ? ctx.err : status_text(rc));
                else E->err[0] = 0;
                rc = dist_agree(E, rc);
                if (rc != SILC_OK) {
                    val_release(call->out);
                    call->out = NULL;
                    snprintf(ctx.err, sizeof ctx.err, "%.1000s", E->err);
                }
            }
            if (rc == SILC_OK && call->op == SILC_OP_SOLVE && condest_settle(E, call, b)) {
                val_release(call->out);
                call->out = NULL;
                rc = SILC_ENOMEM;
                snprintf(ctx.err, sizeof ctx.err, "out of memory for the condition estimate");
            }
            if (rc == SILC_OK) {
                double limit;
                /* Hook (refine.c): iterative refinement as solve.refine asks,
                 * by the backend that just solved, before the report (not
                 * of a distributed solve: refine.c reads whole arrays). */
                if (call->op == SILC_OP_SOLVE && !ctx.collective) refine(E, call, b, 0);
                if (call->op == SILC_OP_SOLVE && ctx.collective) {
                    int rk = dist_size(E);
                    call->report->backward_error_unrefined = -1; /* no refinement ran */
                    size_t l = strlen(call->report->note);
                    if (!strstr(call->report->note, "ranks"))
                        snprintf(call->report->note + l, sizeof call->report->note - l, "%son %d ranks",
                                 l ? "; " : "", rk);
                }
                {
                    /* Deferral needs a measured first solve that passes
                     * today's bound (vouched, above), unless the user gave
                     * that check up (solve.backward_error = on_request);
                     * distributed solves keep the old rule (their ranks
                     * must agree). */
                    int local = call->op == SILC_OP_SOLVE && !ctx.collective && !E->dist;
                    /* read only where it counts: a setting lookup is ~50
                     * instructions, 1 % of a small product's fixed cost */
                    const char *when = local ? cfg_get(E, "solve.backward_error") : NULL;
                    int defer = may_defer &&
                                (!local || (when && !strcmp(when, "on_request")) ||
                                 vouched(call->in[0], b,
                                         acc_verify_limit(cfg_get(E, "solve.verify"), call->report)));
                    rc = call->op == SILC_OP_SOLVE && finish_solve(E, call, cholesky_failed, defer);
                    if (!rc && local && call->report->backward_error != ACC_DEFERRED)
                        vouch(call->in[0], b, call->report);
                }
                dist_walk_end(call, &swap);
                call->host_private = NULL;
                if (rc) {
                    val_release(call->out);
                    call->out = NULL;
                    sb_free(&skipped);
                    sb_free(&attempts);
                    return SILC_ENOMEM;
                }
                /* Verification: a result whose backward error says it does
                 * not solve the system is a failure like any other (a
                 * deferred one was verified with its factorization). */
                limit = call->op == SILC_OP_SOLVE ? acc_verify_limit(cfg_get(E, "solve.verify"), call->report) : INFINITY;
                if (call->op == SILC_OP_SOLVE && call->report->backward_error != ACC_DEFERRED &&
                    !(call->report->backward_error <= limit) && call->report->iterations == 0 &&
                    call->report->refine_steps == 0 && !ctx.collective && !E->dist &&
                    isfinite(call->report->backward_error)) {
                    /* A direct result that missed: refinement first, by the
                     * same factorization (one triangular solve a step),
                     * before the next backend factors afresh. */
                    drop_warnings(E, warned);
                    call->host_private = &ctx;
                    refine(E, call, b, REFINE_RESCUE_STEPS);
                    call->host_private = NULL;
                    if (call->report->refine_steps > 0 && finish_solve(E, call, 0, 0)) {
                        val_release(call->out);
                        call->out = NULL;
                        sb_free(&skipped);
                        sb_free(&attempts);
                        return SILC_ENOMEM;
                    }
                }
                if (call->op == SILC_OP_SOLVE && call->report->backward_error != ACC_DEFERRED &&
                    !(call->report->backward_error <= limit)) {
                    eng_error(E, "%s: verification failed: backward error %.2g above %.2g (solve.verify)%s%s",
                              b->full_name, call->report->backward_error, limit,
                              call->report->iterations > 0 ? "; " : "",
                              call->report->iterations > 0 ? call->report->method : "");
                    val_release(call->out);
                    call->out = NULL;
                    drop_warnings(E, warned);
                    if (hand_over(E, call, L, i, b, &attempts, util_now() - t0, 1)) continue;
                    sb_free(&skipped);
                    sb_free(&attempts);
                    return SILC_ENOTCONV;
                }
                if (call->op == SILC_OP_SOLVE)
                    snprintf(call->report->attempts, sizeof call->report->attempts, "%s", sb_str(&attempts));
                sb_free(&skipped);
                sb_free(&attempts);
                return 0;
            }
            dist_walk_end(call, &swap);
            if (rc == SILC_ENOTSPD && ci + 1 < nchain) {
                /* The list again under the first class that is not SPD's
                 * (the loop's ci++ moves to it). */
                cholesky_failed = 1;
                next_class = 1;
                while (ci + 2 < nchain && spd_class(chain[ci + 1])) ci++;
            } else if (rc == SILC_EDECLINE) {
                sb_printf(&skipped, "%s declines: %s; ", b->full_name,
                          ctx.err[0] ? ctx.err : "no reason given");
            } else {
                /* The message is prefixed with the backend, unless the
                 * plugin already named itself ("lis-style BiCG: ..."). */
                size_t bl = strlen(b->full_name);
                if (rc == SILC_ENOMEM && *val_refusal())
                    /* A value constructor that refused a size said how
                     * large: that beats the plugin's "out of memory". */
                    eng_error(E, "%s: %s", b->full_name, val_refusal());
                else if ((strncmp(ctx.err, b->full_name, bl) == 0 && (ctx.err[bl] == ':' || ctx.err[bl] == ' ')) ||
                         (ctx.collective && strncmp(ctx.err, "rank ", 5) == 0))
                    eng_error(E, "%s", ctx.err);
                else
                    eng_error(E, "%s: %s", b->full_name, ctx.err[0] ? ctx.err : status_text(rc));
                call->host_private = NULL;
                drop_warnings(E, warned);
                /* The next listed backend takes over (out of memory is
                 * not the backend's fault: it stops the chain). */
                if (rc == SILC_ENOMEM) chain_error(E, &attempts);
                else if (hand_over(E, call, L, i, b, &attempts, util_now() - t0, 0)) continue;
                sb_free(&skipped);
                sb_free(&attempts);
                return rc;
            }
        }
        if (!next_class) break;
    }
    call->host_private = NULL;
    /* Drop the trailing "; " of the last reason. */
    if (skipped.len >= 2) skipped.s[skipped.len -= 2] = '\0';
    if (complex) {
        strbuf what;
        sb_init(&what);
        describe_complex_operands(call, &what);
        eng_error(E, "no backend can run %s (%s) on complex values -- %s: %s", op_names[call->op], chain[0],
                  sb_str(&what), sb_str(&skipped));
        sb_free(&what);
    } else {
        eng_error(E, "no backend can run %s (%s): %s", op_names[call->op], chain[0], sb_str(&skipped));
    }
    chain_error(E, &attempts);
    sb_free(&skipped);
    sb_free(&attempts);
    return SILC_EUNSUP;
}

/* 1 when classify asked whether a solve's A is symmetric and could not tell
 * (out of memory), so chose a general class: going on with a general method
 * instead of Cholesky would give other bits, or another explanation, than
 * with memory to spare.  (With a `why`, classify asks twice, and the second
 * time may have found A symmetric after all.) */
static int symmetry_unknown(const silc_call *call, const char *const chain[4])
{
    const silc_value *A = call->in[0];
    return call->op == SILC_OP_SOLVE && A->props.pos_diag &&
           (!(A->props_have & SILC_PROPS_SYMMETRY) || A->props.hermitian) &&
           !strcmp(chain[0], A->format == SILC_FMT_CSR ? "solve.sparse" : "solve.dense");
}

static int run_call(silc_engine *E, silc_call *call)
{
    const char *chain[4];
    silc_report local;
    disp_dense_copy copy;
    blist L;
    int n, rc, own_options;
    if (!E || !call) return SILC_EARG;
    call->out = NULL;
    own_options = call->options != NULL;
    if (own_options && cfg_set_call_options(E, call->options)) return SILC_EARG;
    prepare_dense_copy(E, call, &copy);
    n = classify(E, call, chain, NULL, 0);
    if (n == 0) {
        eng_error(E, "invalid call: operation %d with %d operand(s)", call->op, call->nin);
        rc = SILC_EARG;
    } else if (call->op == SILC_OP_SOLVE && (call->nin < 2 || !call->in[1])) {
        eng_error(E, "solve needs a right-hand side");
        rc = SILC_EARG;
    } else if (symmetry_unknown(call, chain)) {
        eng_error(E, "out of memory classifying the matrix of '\\'");
        rc = SILC_ENOMEM;
    } else if (call->op == SILC_OP_SOLVE &&
               (refine_check_finite(E, call->in[0], 1, "the matrix") ||
                refine_check_finite(E, call->in[1], 0, "the right-hand side"))) {
        /* Hook (refine.c): NaN/Inf operands are an error before any backend runs. */
        rc = SILC_EARG;
    } else {
        silc_report *saved = call->report;
        scale_state S;
        /* Read below whether or not scaling ran: unset, a distributed
         * solve's ranks would disagree on deferring its backward error. */
        memset(&S, 0, sizeof S);
        /* A distributed system is not rescaled (scale.c copies whole arrays). */
        int scaling = call->op == SILC_OP_SOLVE && !dist_call_has(call);
        if (scaling && !call->report) call->report = &local;
        /* Hook (scale.c): systems near 1e+-300 are solved scaled by 2^k. */
        if (scaling && scale_solve_begin(E, call, &S)) {
            rc = SILC_ENOMEM;
        } else {
            resolve_list(E, call, chain, n, &L);
            /* A scaled solve's deferred residual would be formed unscaled,
             * where it may overflow: no deferral then. */
            rc = walk(E, call, chain, n, &L, E->accuracy_defer && !S.ea && !S.eb, &copy);
            if (rc == SILC_OK && !E->dist) note_solved(call);
            if (scaling && scale_solve_end(call, &S))
                eng_warn(E, "'\\': the solution has entries beyond the largest double (returned as Inf); "
                            "the backward error was measured before the final scaling by 2^%d",
                         S.ea - S.eb);
        }
        call->report = saved;
    }
    val_array_free(copy.array); /* no backend took it */
    if (own_options) cfg_clear_call_options(E);
    return rc;
}

/* A real A against a complex b: x = A \ real(b) + i (A \ imag(b)), two
 * real solves of which the second finds A's factorization attached to A
 * by the first (promoting A would factor a complex copy of it, in 4x the
 * arithmetic).  The report is the first solve's with the worse backward
 * error of the two. */
static int run_split_solve(silc_engine *E, silc_call *call)
{
    const silc_value *b = call->in[1];
    silc_value *part[2] = {NULL, NULL}, *x[2] = {NULL, NULL};
    silc_report *rep = call->report, first;
    int nin = call->nin, rc = 0, k;
    memset(&first, 0, sizeof first);
    if (nin == 3 && call->in[2] && call->in[2]->field == SILC_FIELD_COMPLEX) call->nin = 2; /* no real guess */
    for (k = 0; k < 2 && !rc; k++) {
        if (!(part[k] = val_part(b, k))) {
            rc = SILC_ENOMEM;
            eng_error(E, "%s", *val_refusal() ? val_refusal() : "out of memory splitting a complex right-hand side");
            break;
        }
        call->in[1] = part[k];
        rc = run_call(E, call);
        x[k] = call->out;
        call->out = NULL;
        if (!rc && rep && k == 0) first = *rep;
    }
    call->in[1] = b;
    call->nin = nin;
    if (!rc && !(call->out = val_complex_of_parts(x[0], x[1]))) {
        rc = SILC_ENOMEM;
        eng_error(E, "%s", *val_refusal() ? val_refusal() : "out of memory joining a complex solution");
    }
    if (!rc && rep) {
        double second = rep->backward_error;
        *rep = first;
        if (first.backward_error >= 0 && (second > first.backward_error || second == ACC_DEFERRED))
            rep->backward_error = second;
    }
    for (k = 0; k < 2; k++) {
        val_release(part[k]);
        val_release(x[k]);
    }
    return rc;
}

/* A call mixing real and complex operands (or a complex alpha with a real
 * operand): each real operand promoted once for the call, released after;
 * the result is the call's. */
static int run_promoted(silc_engine *E, silc_call *call)
{
    const silc_value *saved[4] = {NULL, NULL, NULL, NULL};
    silc_value *copies[4] = {NULL, NULL, NULL, NULL};
    int i, rc = 0, n = call->nin < 4 ? call->nin : 4;
    for (i = 0; i < n && !rc; i++) {
        saved[i] = call->in[i];
        if (!call->in[i] || call->in[i]->field == SILC_FIELD_COMPLEX) continue;
        if (i > 0 && call->in[i] == saved[0]) { /* the same operand twice: one copy */
            copies[i] = val_retain(copies[0]);
        } else if (!(copies[i] = dist_is(call->in[i]) ? dist_promote(E, call->in[i]) : val_promote(call->in[i]))) {
            rc = SILC_ENOMEM;
            eng_error(E, "%s", *val_refusal() ? val_refusal() : "out of memory promoting a real operand to complex");
            break;
        }
        call->in[i] = copies[i];
    }
    if (!rc) rc = run_call(E, call);
    for (i = 0; i < n; i++) {
        if (saved[i]) call->in[i] = saved[i];
        val_release(copies[i]);
    }
    return rc;
}

int disp_run(silc_engine *E, silc_call *call)
{
    int i, any_real = 0;
    if (!E || !call) return SILC_EARG;
    if (!call_complex(call)) return run_call(E, call);
    /* Distributed operands: a real one is promoted block by block
     * (dist_promote), never split into parts, which would gather it. */
    if (call->op == SILC_OP_SOLVE && call->nin >= 2 && call->in[0] && call->in[1] && !dist_call_has(call) &&
        call->in[0]->field == SILC_FIELD_REAL && call->in[1]->field == SILC_FIELD_COMPLEX)
        return run_split_solve(E, call);
    for (i = 0; i < call->nin; i++) any_real |= call->in[i] && call->in[i]->field == SILC_FIELD_REAL;
    return any_real ? run_promoted(E, call) : run_call(E, call);
}

/* ---- explain --------------------------------------------------------------- */

int disp_explain(silc_engine *E, const silc_call *call, strbuf *b)
{
    const char *chain[4];
    char why[384];
    silc_call c;
    dist_swap swap;
    blist L;
    int n, i, chosen = 0;
    if (!E || !call || !b) return -1;
    if (call->options && cfg_set_call_options(E, call->options)) return -1;
    n = classify(E, call, chain, why, sizeof why);
    if (n == 0) {
        if (call->options) cfg_clear_call_options(E);
        return eng_error(E, "invalid call: operation %d with %d operand(s)", call->op, call->nin);
    }
    if (symmetry_unknown(call, chain)) {
        if (call->options) cfg_clear_call_options(E);
        return eng_error(E, "out of memory classifying the matrix of '\\'");
    }
    resolve_list(E, call, chain, n, &L);
    sb_printf(b, "%s\n", why);
    sb_puts(b, "backends (");
    list_source(&L, b);
    sb_puts(b, "):");
    for (i = 0; i < L.n; i++) sb_printf(b, "%s %s", i ? "," : "", L.names[i]);
    if (L.absent[0]) sb_printf(b, " (not installed, left out: %s)", L.absent);
    sb_puts(b, "\n");
    c = *call;
    c.op_class = chain[0];
    c.out = NULL;
    for (i = 0; i < L.n && !chosen; i++) {
        const ld_backend *be = ld_find(E, L.names[i]);
        const char *reason = NULL;
        host_call_ctx ctx;
        if (!be) {
            sb_printf(b, "  %s: not installed (%s: a solve fails)\n", L.names[i],
                      L.forced ? "the per-call backend" : "configured, not optional");
            continue;
        }
        if (!provides(be, call->op)) {
            sb_printf(b, "  %s: does not provide %s\n", be->full_name, op_names[call->op]);
            continue;
        }
        if (call_complex(call) && !ld_backend_takes_complex(be, call->op)) {
            sb_printf(b, "  %s: does not take complex values\n", be->full_name);
            continue;
        }
        memset(&ctx, 0, sizeof ctx);
        ctx.E = E;
        ctx.backend = be;
        c.host_private = &ctx;
        /* As walk: a backend judges the operands it would get (gathered
         * copies, kept with the values, when it is not collective). */
        if (dist_walk_begin(E, &c, ld_backend_collective(be, c.op), &swap) < 0) {
            if (call->options) cfg_clear_call_options(E);
            return -1;
        }
        ctx.collective = swap.mode == DIST_COLLECTIVE;
        if (be->backend->ops[call->op].accepts && !be->backend->ops[call->op].accepts(&c, &reason)) {
            dist_walk_end(&c, &swap);
            sb_printf(b, "  %s: declines: %s\n", be->full_name, reason ? reason : "no reason given");
            continue;
        }
        dist_walk_end(&c, &swap);
        sb_printf(b, "  %s -> would run%s\n", be->full_name,
                  !E->dist || !dist_call_has(call) ? ""
                  : ld_backend_collective(be, call->op) && call->op == SILC_OP_SOLVE
                      ? " (collective, on the row blocks of every rank)"
                      : " (sequential, on operands gathered to every rank)");
        chosen = 1;
    }
    if (!chosen) sb_printf(b, "  no backend can run this\n");
    else if (n > 1)
        sb_printf(b, "  (if Cholesky finds A not positive definite, the list is tried again "
                     "under %s)\n", chain[n - 1]);
    if (chosen && fallback_left(&L, i - 1) && call->op == SILC_OP_SOLVE) {
        const char *v = cfg_get(E, "solve.verify");
        if (v && !strcmp(v, "off"))
            sb_puts(b, "  (if it fails, the next listed backend takes over; solve.verify = off)\n");
        else
            sb_printf(b, "  (if it fails, or its result's backward error is above %s (solve.verify), the next "
                         "listed backend takes over)\n",
                      v && strcmp(v, "auto") ? v : "1e-6, or 10x an iterative method's tolerance");
    }
    if (call->options) cfg_clear_call_options(E);
    return 0;
}
