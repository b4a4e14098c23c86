/*
 * test_reliability.c -- the catalogue of bad inputs and numeric failures
 * (docs/reliability.md, "Catalogue"), as one table that this program runs.
 *
 * Each row is something a user or a client can get wrong -- a statement, a
 * Matrix Market file, a config file, a call of the C API in the wrong order
 * or with the wrong arguments -- or a numeric failure of one backend.  Every
 * row is checked for its exact message, for the context still working
 * afterwards, and, for statements, for the store being exactly as before
 * (every name, shape and bit compared).  `test_reliability --markdown`
 * prints the table that docs/reliability.md holds, so the document shows
 * what this program checks and nothing else.
 *
 * Rows that need a plugin this build lacks are skipped with a line saying so;
 * CI installs every plugin.  Rows held by other tests (the server, the wire
 * protocol, out of memory) are listed in docs/reliability.md beside them.
 */
#include "check.h"

#include <silc.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

enum row_kind {
    R_EXEC,       /* statements on the fixture: the error message, store unchanged */
    R_WARN,       /* statements that succeed with a warning containing want */
    R_MM,         /* a Matrix Market file: silc_mm_read's message after the path */
    R_CONFIG,     /* a config file: silc_open's message after the path */
    R_API         /* a C API misuse, numbered in api_misuse() */
};

typedef struct row {
    const char *area;
    int kind;
    const char *needs;     /* backend that must be loaded, or NULL */
    const char *input;     /* statement, file text, or (R_API) what is done */
    const char *want;      /* the exact message (R_WARN: a part of the warnings) */
} row;

/* The fixture every R_EXEC row starts from (docs: "the fixture"). */
static const char *const fixture_text =
    "v = [1; 2; 3]; M = [1, 2; 3, 4]; S = sparse([1, 2], [1, 2], [1, 1], 2, 2); "
    "Z = [1, 2; 2, 4]; Zs = sparse(Z); b = [1; 1]; Ind = sparse([1, 2; 2, 1]); "
    "L = sparse([2, -1, 0, 0; -1, 2, -1, 0; 0, -1, 2, -1; 0, 0, -1, 2]); e1 = [1; 0; 0; 0]";
static const char *const fixture_names[] = {"v", "M", "S", "Z", "Zs", "b", "Ind", "L", "e1"};

#define LANG(input, want) {"language", R_EXEC, NULL, input, want}
#define NUM(needs, input, want) {"numeric", R_EXEC, needs, input, want}
#define MMF(input, want) {"Matrix Market", R_MM, NULL, input, want}
#define CONF(input, want) {"config", R_CONFIG, NULL, input, want}
#define API(input, want) {"API", R_API, NULL, input, want}

static const row rows[] = {
    /* ---- syntax: the text is refused whole, nothing runs -------------------- */
    LANG("x = (1 + 2", "1:11: expected ')' (to close '(' at 1:5) near end of input"),
    LANG("x = 1 +", "1:8: unexpected end of input"),
    LANG("x = )", "1:5: unexpected ')'"),
    LANG("x = 1 2", "1:7: unexpected '2'"),
    LANG("x = 1.2.3", "1:8: unexpected '.3'"),
    LANG("x = 0x12", "1:5: malformed number near '0x'"),
    LANG("x = $", "1:5: unexpected character '$'"),
    LANG("x = \"abc", "1:5: unfinished string"),
    LANG("x = \"abc\"", "1:5: unexpected '\"abc\"'"),
    LANG("x = 1 :: 3", "1:8: unexpected ':'"),
    LANG("x = 1 < 2 < 3", "1:11: comparisons do not chain: use '&&' near '<'"),
    LANG("x = 1; continue", "1:8: 'continue' outside a loop"),
    LANG("explain", "1:8: explain needs a statement, as in 'explain x = A \\ b'"),
    LANG("tune bogus", "1:6: unknown tune command 'bogus' (on, off, status, step, forget, report, fit)"),
    LANG("v + 1 = 2", "1:7: cannot assign to this expression near '='"),
    LANG("x = 1; y = (", "1:13: unexpected end of input"),
    /* ---- nesting limits (the issue 14 crash) ------------------------------ */
    LANG("x = ((((((((((((((((((((((((((((((((((((((((((((((((((((((((((((((((((((((((((((((((((((((("
         "((((((((((((((((((((((((((((((((((((((((((((((((((((((((((((((((((((((((((((((((((((((((((((("
         "((((((((((((((((((((((((((((((((((((((((((((((((((((((((((((((((((((((((((((((((((1",
         "1:261: expression nested deeper than 256 levels"),
    /* ---- run time: the failing statement changes nothing ------------------ */
    LANG("x = vv", "undefined name 'vv' (did you mean 'v'?)"),
    LANG("info nosuch", "undefined name 'nosuch'"),
    LANG("x = v + M", "'+' needs operands of the same shape or a scalar: 'v' is 3x1, 'M' is 2x2"),
    LANG("x = M * v", "'*' inner dimensions differ: 'M' is 2x2, 'v' is 3x1"),
    LANG("x = M \\ v", "'\\' needs as many rows in the right-hand side: 'M' is 2x2, 'v' is 3x1"),
    LANG("x = M / v", "'/' needs operands with the same number of columns: 'M' is 2x2, 'v' is 3x1"),
    LANG("x = v ^ 2", "'v' is 3x1 but '^' needs a square matrix"),
    LANG("x = M ^ 0.5",
         "'^' of a matrix needs a nonnegative integer exponent, got 0.5 (use '^@' for element-wise powers)"),
    LANG("x = M ^ -1",
         "'^' of a matrix needs a nonnegative integer exponent, got -1 (use '^@' for element-wise powers)"),
    LANG("x = [1, 2; 3]", "'[...]': stacked rows need equal widths: row 1 is 2 wide, row 2 is 1 wide"),
    LANG("x = [v, M]", "'[...]' row 1: blocks side by side need equal row counts: 'v' is 3x1, 'M' is 2x2"),
    LANG("x = v[4]", "v(4): out of bound 3 (dimensions are 3x1)"),
    LANG("x = v[0]", "v(0): subscripts must be integers from 1 up ('v' is 3x1)"),
    LANG("x = v[1.5]", "v(1.5): subscripts must be integers from 1 up ('v' is 3x1)"),
    LANG("x = v[end + 1]", "v(4): out of bound 3 (dimensions are 3x1)"),
    LANG("x = v(end + 1)", "v(4): out of bound 3 (dimensions are 3x1)"),
    LANG("x = M[3, 1]", "M(3,_): out of bound 2 (dimensions are 2x2)"),
    LANG("M(5) = 1", "M(5): out of bound 4 (dimensions are 2x2): a matrix grows by assignment only with two "
                     "subscripts, A(i, j) = x (Octave: invalid resizing operation or ambiguous assignment to an "
                     "out-of-bounds array element)"),
    LANG("v(1e300) = 1", "v(1e+300): out of bound 3 (dimensions are 3x1)"),
    LANG("v[1:2] = [1; 2; 3]", "cannot assign a 3x1 value to 2 elements of 'v'"),
    LANG("v += [1; 2]", "'+' needs operands of the same shape or a scalar: 'v' is 3x1, '[1; 2]' is 2x1"),
    LANG("M *= v", "'*' inner dimensions differ: 'M' is 2x2, 'v' is 3x1"),
    LANG("x = 1; v = v + [1; 2]",
         "statement 2: '+' needs operands of the same shape or a scalar: 'v' is 3x1, '[1; 2]' is 2x1"),
    LANG("if (v) { x = 1 }", "condition must be a scalar, got 3x1"),
    LANG("if (nan) { x = 1 }", "condition is NaN"),
    LANG("while (0 / 0) { x = 1 }", "condition is NaN"),
    LANG("x = nosuch(1)", "unknown function 'nosuch'"),
    LANG("x = abs(1, 2)", "abs takes 1 argument, got 2"),
    LANG("x = zeros(-1)", "zeros: argument 1 must be an integer >= 0, got -1"),
    /* sizes are checked before anything is allocated ('#': this machine's memory) */
    LANG("x = sparse(1, 1, 1, 1e10, 1e10)", "a 10000000000x10000000000 csr value needs 80000000024 "
         "bytes (74.5 GiB), over the limit of # bytes (# GiB) by # GiB: the most one value may hold "
         "(the machine's memory)"),
    LANG("x = zeros(1e10)", "a 10000000000x10000000000 dense value needs 800000000000000000000 bytes "
         "(693.9 EiB), over the limit of # bytes (# GiB) by # EiB: the most one value may hold "
         "(the machine's memory)"),
    LANG("x = rand(1e6, 1e6)", "a 1000000x1000000 dense value needs 8000000000000 bytes (7.3 TiB), "
         "over the limit of # bytes (# GiB) by # TiB: the most one value may hold (the machine's "
         "memory)"),
    LANG("x = dense(eye(1e7))", "reference: a 10000000x10000000 dense value needs 800000000000000 bytes "
         "(727.6 TiB), over the limit of # bytes (# GiB) by # TiB: the most one value may hold "
         "(the machine's memory)"),
    /* a band value's storage, (kl + ku + 1) x n, is claimed before it is
     * allocated, by band() as by every band constructor (issue 32) */
    LANG("x = band(M, 1e12, 1)", "reference: a 2x2 band value needs 16000000000064 bytes (14.6 TiB), "
         "over the limit of # bytes (# GiB) by # TiB: the most one value may hold (the machine's "
         "memory)"),
    /* a work array is held to the same limit (fuzz_lang: calloc'd 4.4 TiB before) */
    LANG("x = max(eye(2, 61e10))", "reference: a plugin's work array needs 4880000000008 bytes "
         "(4.4 TiB), over the limit of # bytes (# GiB) by # TiB: the most one value may hold "
         "(the machine's memory)"),
    /* and so are subscripts' index lists (fuzz_lang: malloc'd 4.4 TiB before) */
    LANG("x = (eye(2, 61e10))[1, :]", "the subscript's index list needs 4880000000000 bytes "
         "(4.4 TiB), over the limit of # bytes (# GiB) by # TiB: the most one value may hold "
         "(the machine's memory)"),
    LANG("x = rand(-3)", "rand: argument 1 must be an integer >= 0, got -3"),
    LANG("x = norm(v, 3)", "norm: p must be 1, 2, inf or \"fro\""),
    LANG("x = band(M, -1, 0)", "band: argument 2 must be an integer >= 0, got -1"),
    LANG("x = band(M, 0, 0)", "band(M, 0, 0): entry (1,2) lies outside the band"),
    LANG("x = diag(M)", "diag needs a vector, got 2x2 (diagvec(A) gives the diagonal of a matrix)"),
    LANG("x = dot(v, M)", "dot needs operands of the same shape: 'v' is 3x1, 'M' is 2x2"),
    LANG("x = sparse([1, 2], [1], [1, 1], 2, 2)", "sparse: i has 2 entries but j has 1"),
    LANG("x = sparse(0, 1, 1, 2, 2)", "sparse: row index 0 (entry 1) is out of range 1..2"),
    LANG("x = M \\ [nan; 1]", "'[nan; 1]' has NaN at (1, 1): a solve needs finite entries"),
    LANG("x = M \\ [inf; 1]", "'[inf; 1]' has Inf at (1, 1): a solve needs finite entries"),
    LANG("set nokey = 1", "key 'nokey' has no section (write section.key, e.g. tune.threads)"),
    LANG("set tune.threads = many",
         "tune.threads expects 'auto' or a thread count from 1 to 4096, got 'many'"),
    LANG("x = solve(M, b, \"nokey = 1\")", "key 'nokey' has no section (write section.key, e.g. tune.threads)"),
    /* ---- numeric failures, per backend ------------------------------------ */
    NUM("reference", "x = solve(Z, b, \"backend = reference\")",
        "reference: dense LU: matrix is singular (zero pivot in column 2)"),
    NUM("reference", "x = [1, 0; 0, 0] \\ b", "reference: singular diagonal matrix: zero diagonal entry at row 2"),
    NUM("lapack", "x = solve(Z, b, \"backend = lapack\")",
        "lapack: dsytrf: singular matrix (D(2,2) is exactly zero, status 2)"),
    NUM("suitesparse.umfpack", "x = solve(Zs, b, \"backend = suitesparse.umfpack\")",
        "suitesparse.umfpack: umfpack_dl_numeric: singular matrix (status 1)"),
    NUM("suitesparse.klu", "x = solve(Zs, b, \"backend = suitesparse.klu\")",
        "suitesparse.klu: klu_l_factor: singular matrix (status 1)"),
    NUM("suitesparse.spqr", "x = solve(Zs, b, \"backend = suitesparse.spqr\")",
        "suitesparse.spqr: SuiteSparseQR_C_factorize: singular matrix (rank 1 < 2)"),
    NUM("suitesparse.cholmod", "x = solve(Ind, b, \"backend = suitesparse.cholmod\")",
        "no backend can run solve (solve.sparse.spd): [solve.sparse] suitesparse.cholmod declines: "
        "Cholesky only: runs under the solve.*.spd classes"),
    NUM("mumps", "x = solve(Zs, b, \"backend = mumps\")",
        "mumps: dmumps_c (JOB=4): numerically singular matrix (INFOG(1)=-10, INFOG(2)=1)"),
    NUM("mumps", "x = solve(Zs, b, \"backend = mumps; mumps.icntl_99 = 1\")",
        "plugin 'mumps' has no option 'icntl_99'; did you mean 'icntl_9'?"),
    NUM("petsc", "x = solve(L, e1, \"backend = petsc; petsc.options = -ksp_type cg -pc_type none -ksp_max_it 2\")",
        "petsc: KSPSolve: diverged (KSP_DIVERGED_ITS) after 2 iterations, relative residual 0.333 "
        "(KSP cg + PC none)"),
    NUM("petsc", "x = solve(Zs, b, \"backend = petsc\")",
        "petsc: KSPSolve: diverged (KSP_DIVERGED_BREAKDOWN) after 30 iterations, relative residual # "
        "(KSP gmres + PC icc (petsc))"),
    NUM("lis-style", "x = solve(L, e1, \"backend = lis-style; lis-style.options = -i cg -maxiter 2\")",
        "lis-style CG: not converged after 2 iterations (relative residual 3.3e-01)"),
    NUM("lis-style", "x = solve(Zs, b, \"backend = lis-style\")",
        "lis-style CG: breakdown at iteration 9 (p'Ap <= 0: A or the preconditioner is not positive "
        "definite); relative residual 5.7e+16"),
    NUM("lis-style", "x = solve(Zs, b, \"backend = lis-style; lis-style.options = -i cg -tol abc\")",
        "lis-style options: -tol expects a positive number, got 'abc' (in '-i cg -tol abc')"),
    NUM(NULL, "x = solve(M, b, \"backend = nosuch\")",
        "unknown backend 'nosuch' in option 'backend' (known: reference, lapack, suitesparse.umfpack, "
        "suitesparse.cholmod, suitesparse.klu, suitesparse.spqr, mumps, petsc, lis-style)"),
    {"numeric", R_WARN, NULL, "x = [1, 1; 1, 1 + 1e-15] \\ b", "result may have fewer than 4 correct digits (condition estimate"},
    /* ---- Matrix Market files ------------------------------------------------ */
    MMF("", ":1: empty file (expected a %%MatrixMarket banner)"),
    MMF("hello\n", ":1: not a Matrix Market file (expected '%%MatrixMarket matrix <coordinate|array> "
                   "<field> <symmetry>')"),
    MMF("%%MatrixMarket vector coordinate real general\n", ":1: object 'vector' is not supported (only 'matrix')"),
    MMF("%%MatrixMarket matrix coordinate complex general\n1 1 1\n1 1 1\n",
        ":3:6: expected a value, found the end of the line"),
    MMF("%%MatrixMarket matrix coordinate complex hermitian\n2 2 1\n1 1 1 0.5\n",
        ":3:1: diagonal entry (1, 1) of a hermitian file has imaginary part 0.5 (it must be real)"),
    MMF("%%MatrixMarket matrix array pattern general\n", ":1: an array file cannot have field 'pattern'"),
    MMF("%%MatrixMarket matrix coordinate real general\n", ":1: file ends before the size line"),
    MMF("%%MatrixMarket matrix coordinate real general\n2 two 1\n",
        ":2:3: column count 'two' is not an integer"),
    MMF("%%MatrixMarket matrix coordinate real general\n2 2 3\n1 1 1\n2 2 2\n", ":4: file ends after 2 of 3 entries"),
    MMF("%%MatrixMarket matrix coordinate real general\n2 2 1\n1 1 1\n2 2 2\n",
        ":4: more entries than the 1 the size line announces"),
    MMF("%%MatrixMarket matrix coordinate real general\n2 2 1\n1 3 1\n", ":3:1: entry (1, 3) is outside the 2x2 matrix"),
    MMF("%%MatrixMarket matrix coordinate real general\n2 2 1\n1 x 1\n", ":3:3: column index 'x' is not an integer"),
    MMF("%%MatrixMarket matrix coordinate real symmetric\n2 3 1\n1 1 1\n",
        ":2: a symmetric, skew-symmetric or hermitian matrix must be square, not 2x3"),
    MMF("%%MatrixMarket matrix coordinate real skew-symmetric\n2 2 1\n1 1 1\n",
        ":3:1: diagonal entry (1, 1) in a skew-symmetric file"),
    MMF("%%MatrixMarket matrix array real general\n2 1\n1\n", ":3: file ends before entry (2, 1)"),
    /* numbers and symmetry by the format's rules (tests/security/values_mm.c has the full table) */
    MMF("%%MatrixMarket matrix coordinate integer general\n1 1 1\n1 1 1.5\n",
        ":3:5: integer value '1.5' is not an integer"),
    MMF("%%MatrixMarket matrix coordinate integer general\n1 1 1\n1 1 0x10\n",
        ":3:5: integer value '0x10' is not an integer"),
    MMF("%%MatrixMarket matrix coordinate integer general\n1 1 1\n1 1 9007199254740993\n",
        ":3:5: integer value '9007199254740993' has no exact double (SILC stores doubles: integers beyond "
        "2^53 = 9007199254740992 only where exact)"),
    MMF("%%MatrixMarket matrix coordinate real general\n1 1 1\n1 1 1e400\n",
        ":3:5: value '1e400' overflows the doubles (set SILC_MM_ALLOW_NONFINITE=1 to accept it as inf)"),
    MMF("%%MatrixMarket matrix coordinate real general\n1 1 1\n1 1 nan\n",
        ":3:5: value 'nan' is not finite (set SILC_MM_ALLOW_NONFINITE=1 to accept it)"),
    MMF("%%MatrixMarket matrix coordinate real hermitian\n2 2 1\n2 1 3\n",
        ":1: symmetry 'hermitian' needs a complex field, and this file's is 'real' (say symmetric for a real "
        "symmetric matrix)"),
    MMF("%%MatrixMarket matrix coordinate real symmetric\n2 2 2\n1 1 4\n1 2 3\n",
        ":4:1: entry (1, 2) is above the diagonal: a symmetric file stores the lower triangle only"),
    /* sizes claimed by the size line are checked before anything is allocated */
    MMF("%%MatrixMarket matrix array real general\n100000 100000\n1\n",
        ":2: the 100000x100000 array the size line announces needs 80000000000 bytes (74.5 GiB), "
        "over the limit of # bytes (# GiB) by # GiB: the most one value may hold (the machine's memory)"),
    MMF("%%MatrixMarket matrix coordinate real general\n10 10 1000000000000\n1 1 1\n",
        ":2: the 10x10 matrix of 1000000000000 entries the size line announces needs 64000000000352 "
        "bytes (58.2 TiB), over the limit of # bytes (# GiB) by # TiB: the most one value may hold "
        "(the machine's memory)"),
    /* ---- config files -------------------------------------------------------- */
    CONF("[tune]\nthread = 4\n", ":2: unknown key 'tune.thread'; did you mean 'tune.threads'?"),
    CONF("[mump]\nicntl_7 = 2\n", ":2: unknown section [mump]; did you mean [mumps]?"),
    CONF("[dispatch]\nsolve.sparse = umfpack\n",
         ":2: unknown backend 'umfpack' in dispatch.solve.sparse; did you mean 'suitesparse.umfpack'?"),
    CONF("[dispatch]\nsolve.sparce = reference\n",
         ":2: unknown dispatch class 'solve.sparce'; did you mean 'solve.sparse'?"),
    CONF("[tune]\nthreads = many\n",
         ":2: tune.threads expects 'auto' or a thread count from 1 to 4096, got 'many'"),
    CONF("[tune]\n\nthreads 4\n", ":3: syntax error (expected '[section]' or 'key = value')"),
    CONF("[lis-style]\noptions = -i cg -p ilu -tol 1e-12 -maxiter 1000 -print 0 -restart 40 -omega 1.9 "
         "-ell 2 -m 3 -initx_zeros true -scale none -ilu_fill 0 -saamg_theta 0.05 -saamg_unsym false "
         "-precision double -conv_cond 0\n",
         ":2: line longer than 199 characters (the INI reader's limit)"),
    /* ---- the C API ------------------------------------------------------------ */
    API("SILC_GET before SILC_INIT", "SILC_INIT has not been called"),
    API("SILC_EXEC before SILC_INIT", "SILC_INIT has not been called"),
    API("silc_put with a NULL context", "silc_put: NULL context"),
    API("silc_put with a NULL name", "silc_put: NULL name"),
    API("silc_put of the name \"1x\"", "invalid name '1x': names start with a letter or '_' and contain only letters, digits and '_'"),
    API("silc_put with a NULL envelope", "silc_put: NULL envelope for 'x'"),
    API("silc_put of a CSR envelope whose rowptr decreases", "'x': rowptr decreases at row 1 (rowptr[1] = 2 > rowptr[2] = 1)"),
    API("silc_put of a CSR envelope with a column out of range", "'x': column index 5 out of range [0, 2) in row 0"),
    API("silc_get of an unknown name", "undefined name 'nosuch'"),
    API("silc_exec with NULL text", "silc_exec: NULL statements"),
    API("silc_open with a missing config file", "cannot read config file /nonexistent/silc.conf: No such file or directory"),
    API("silc_open_remote to a URL of an unknown scheme", "'http://x': server address must be tcp://host:port or unix:/path"),
    API("silc_envelope_dense with negative rows", "silc_envelope_dense: invalid size -1x1"),
    API("silc_envelope_dense of 1e6 x 1e6 zeros", "silc_envelope_dense: 1000000x1000000: the envelope "
        "needs 8000000000000 bytes (7.3 TiB), over the limit of # bytes (# GiB) by # TiB: the most one "
        "value may hold (the machine's memory)"),
};

/* ---- running a row ------------------------------------------------------------ */

static char captured[1 << 14];

static void capture(void *user, const char *text)
{
    (void)user;
    strncat(captured, text, sizeof captured - strlen(captured) - 1);
}

static int write_text(const char *path, const char *text)
{
    FILE *f = fopen(path, "w");
    if (!f) return -1;
    fputs(text, f);
    return fclose(f);
}

/* The message with "<path>" removed from its front, or NULL. */
static const char *after_path(const char *msg, const char *path)
{
    size_t n = strlen(path);
    return strncmp(msg, path, n) ? NULL : msg + n;
}

/* Everything a statement could change: `who` and every fixture value. */
typedef struct snapshot {
    char who[4096];
    silc_envelope_t vals[sizeof fixture_names / sizeof fixture_names[0]];
} snapshot;

static void snapshot_take(silc_context *c, snapshot *s)
{
    size_t i;
    memset(s, 0, sizeof *s);
    captured[0] = 0;
    silc_exec(c, "who");
    snprintf(s->who, sizeof s->who, "%s", captured);
    for (i = 0; i < sizeof fixture_names / sizeof fixture_names[0]; i++)
        silc_get(c, &s->vals[i], fixture_names[i]);
}

static size_t env_bytes(const silc_envelope_t *e, size_t *nidx)
{
    *nidx = e->format == SILC_CSR ? (size_t)e->m + 1 : 0;
    return (size_t)(e->format == SILC_CSR ? e->nnz : e->m * e->n);
}

static int same_envelope(const silc_envelope_t *a, const silc_envelope_t *b)
{
    size_t nidx, nv = env_bytes(a, &nidx);
    if (a->format != b->format || a->m != b->m || a->n != b->n || a->nnz != b->nnz) return 0;
    if (nv && memcmp(a->values, b->values, nv * sizeof(double))) return 0;
    if (nidx && (memcmp(a->rowptr, b->rowptr, nidx * sizeof(int64_t)) ||
                 memcmp(a->colind, b->colind, nv * sizeof(int64_t))))
        return 0;
    return 1;
}

static void snapshot_check(silc_context *c, snapshot *before, const char *input)
{
    snapshot after;
    size_t i;
    snapshot_take(c, &after);
    CHECK(!strcmp(before->who, after.who), "[%s] the store's names changed:\n%s\nthen\n%s", input,
          before->who, after.who);
    for (i = 0; i < sizeof fixture_names / sizeof fixture_names[0]; i++) {
        CHECK(same_envelope(&before->vals[i], &after.vals[i]), "[%s] '%s' changed", input, fixture_names[i]);
        silc_envelope_free(&before->vals[i]);
        silc_envelope_free(&after.vals[i]);
    }
}

/* 1 if backend is loaded in c (forcing it on a 1x1 solve must not say it is unknown). */
static int has_backend(silc_context *c, const char *backend)
{
    char text[128];
    snprintf(text, sizeof text, "tmp_probe = solve(1, 1, \"backend = %s\")", backend);
    if (silc_exec(c, text) == 0) {
        silc_exec(c, "clear tmp_probe");
        return 1;
    }
    return strstr(silc_context_errmsg(c), "unknown backend") == NULL &&
           strstr(silc_context_errmsg(c), "not loaded") == NULL;
}

/* want == got, where a '#' in want stands for one number: a residual after a
 * breakdown on a singular matrix is rounding noise that differs between
 * BLAS builds (11.7 on one machine, 4.12 on another), while the rest of the
 * message is what the row holds. */
static int message_matches(const char *want, const char *got)
{
    for (; *want; want++, got++) {
        if (*want == '#') {
            const char *start = got;
            while (*got && strchr("0123456789.e+-", *got)) got++;
            if (got == start) return 0;
            got--;
        } else if (*want != *got) {
            return 0;
        }
    }
    return *got == '\0';
}

static int run_exec(const row *r)
{
    silc_context *c = NULL;
    snapshot before;
    int rc;
    if (silc_open(&c, NULL) || silc_exec(c, fixture_text)) {
        CHECK(0, "fixture: %s", c ? silc_context_errmsg(c) : silc_errmsg());
        silc_close(&c);
        return 0;
    }
    silc_set_output(c, capture, NULL);
    if (r->needs && !has_backend(c, r->needs)) {
        printf("skipped (no %s in this build): %s\n", r->needs, r->input);
        silc_close(&c);
        return -1;
    }
    snapshot_take(c, &before);
    rc = silc_exec(c, r->input);
    if (r->kind == R_WARN) {
        CHECK(rc == 0 && strstr(silc_context_warnings(c), r->want), "[%s] want a warning '%s', got '%s' %s",
              r->input, r->want, silc_context_warnings(c), rc ? silc_context_errmsg(c) : "");
        for (size_t i = 0; i < sizeof fixture_names / sizeof fixture_names[0]; i++)
            silc_envelope_free(&before.vals[i]);
    } else {
        const char *msg = silc_context_errmsg(c);
        /* one statement: no "statement N: " prefix; its own prefix is part of want */
        CHECK(rc != 0 && message_matches(r->want, msg), "[%s]\n   got  \"%s\"\n   want \"%s\"", r->input,
              rc ? msg : "(success)", r->want);
        if (!strncmp(r->input, "x = 1; ", 7)) silc_exec(c, "clear x");   /* statement 1 stays done */
        snapshot_check(c, &before, r->input);
    }
    CHECK(silc_exec(c, "y = v' * v") == 0, "[%s] context unusable afterwards: %s", r->input,
          silc_context_errmsg(c));
    silc_close(&c);
    return 0;
}

static void run_mm(const row *r)
{
    const char *path = "/tmp/silc_test_reliability.mtx";
    char err[1024];
    silc_envelope_t e;
    const char *tail;
    if (write_text(path, r->input)) {
        CHECK(0, "cannot write %s", path);
        return;
    }
    CHECK(silc_mm_read(&e, path, err, sizeof err) != 0, "[%s] accepted", r->input);
    tail = after_path(err, path);
    CHECK(tail && message_matches(r->want, tail), "[%s]\n   got  \"%s\"\n   want \"<path>%s\"", r->input,
          err, r->want);
    CHECK(e.values == NULL && e.rowptr == NULL, "[%s] a refused file left arrays", r->input);
    remove(path);
}

static void run_config(const row *r)
{
    const char *path = "/tmp/silc_test_reliability.conf";
    silc_context *c = NULL;
    const char *tail;
    if (write_text(path, r->input)) {
        CHECK(0, "cannot write %s", path);
        return;
    }
    CHECK(silc_open(&c, path) != 0, "[%s] accepted", r->input);
    tail = after_path(c ? silc_context_errmsg(c) : silc_errmsg(), path);
    CHECK(tail && !strcmp(tail, r->want), "[%s]\n   got  \"%s\"\n   want \"<path>%s\"", r->input,
          c ? silc_context_errmsg(c) : silc_errmsg(), r->want);
    silc_close(&c);
    remove(path);
}

/* The API rows, in table order: each makes one mistake and returns the
 * message it got. */
static const char *api_misuse(int k, char *buf, size_t len)
{
    static const int64_t bad_rowptr[] = {0, 2, 1}, rowptr[] = {0, 1, 2}, colind[] = {0, 1}, bad_col[] = {5, 1};
    static const double vals[] = {1, 2};
    silc_context *c = NULL;
    silc_envelope_t e;
    int rc = 0;
    buf[0] = 0;
    if (k >= 2 && k <= 9 && silc_open(&c, NULL)) return "silc_open failed";
    memset(&e, 0, sizeof e);
    switch (k) {
    case 0: rc = SILC_GET(&e, "x"); snprintf(buf, len, "%s", silc_errmsg()); break;
    case 1: rc = SILC_EXEC("x = 1"); snprintf(buf, len, "%s", silc_errmsg()); break;
    case 2:
        silc_envelope_scalar(&e, 1);
        rc = silc_put(NULL, "x", &e);
        snprintf(buf, len, "%s", silc_errmsg());
        break;
    case 3:
        silc_envelope_scalar(&e, 1);
        rc = silc_put(c, NULL, &e);
        break;
    case 4:
        silc_envelope_scalar(&e, 1);
        rc = silc_put(c, "1x", &e);
        break;
    case 5: rc = silc_put(c, "x", NULL); break;
    case 6:
        e.format = SILC_CSR, e.m = 2, e.n = 2, e.nnz = 2;
        e.rowptr = (int64_t *)bad_rowptr, e.colind = (int64_t *)colind, e.values = (double *)vals;
        rc = silc_put(c, "x", &e);
        memset(&e, 0, sizeof e);   /* the arrays are static: nothing to free */
        break;
    case 7:
        e.format = SILC_CSR, e.m = 2, e.n = 2, e.nnz = 2;
        e.rowptr = (int64_t *)rowptr, e.colind = (int64_t *)bad_col, e.values = (double *)vals;
        rc = silc_put(c, "x", &e);
        memset(&e, 0, sizeof e);
        break;
    case 8: rc = silc_get(c, &e, "nosuch"); break;
    case 9: rc = silc_exec(c, NULL); break;
    case 10: {
        silc_context *d = NULL;
        rc = silc_open(&d, "/nonexistent/silc.conf");
        snprintf(buf, len, "%s", d ? silc_context_errmsg(d) : silc_errmsg());
        silc_close(&d);
        break;
    }
    case 11: {
        silc_context *d = NULL;
        rc = silc_open_remote(&d, "http://x");
        snprintf(buf, len, "%s", silc_errmsg());
        silc_close(&d);
        break;
    }
    case 12: rc = silc_envelope_dense(&e, -1, 1, NULL); snprintf(buf, len, "%s", silc_errmsg()); break;
    case 13:
        rc = silc_envelope_dense(&e, 1000000, 1000000, NULL);
        snprintf(buf, len, "%s", silc_errmsg());
        break;
    default: return "no such API row";
    }
    if (!buf[0] && c) snprintf(buf, len, "%s", silc_context_errmsg(c));
    if (rc == 0) snprintf(buf, len, "(accepted)");
    if (c) {
        /* a refused put leaves no name behind, and the context goes on */
        silc_envelope_t x;
        if (k >= 3 && k <= 7) {
            CHECK(silc_get(c, &x, "x") != 0, "API row %d bound x", k);
            silc_envelope_free(&x);
        }
        CHECK(silc_exec(c, "y = 1") == 0, "API row %d: context unusable: %s", k, silc_context_errmsg(c));
    }
    silc_envelope_free(&e);
    silc_close(&c);
    return buf;
}

/* Prints s inside a Markdown table cell's code span: newlines as \n, pipes
 * escaped, cut after max characters. */
static void cell(const char *s, size_t max)
{
    const char *p;
    putchar('`');
    for (p = s; *p; p++) {
        if ((size_t)(p - s) >= max) {
            fputs("...", stdout);
            break;
        }
        if (*p == '\n') fputs("\\n", stdout);
        else if (*p == '|') fputs("\\|", stdout);
        else putchar(*p);
    }
    putchar('`');
}

static void print_markdown(void)
{
    size_t i;
    printf("| # | area | input | message (exact; a warning's part for \"warning\") |\n| --- | --- | --- | --- |\n");
    for (i = 0; i < sizeof rows / sizeof rows[0]; i++) {
        const row *r = &rows[i];
        printf("| %zu | %s%s%s%s | ", i + 1, r->area, r->needs ? " (" : "", r->needs ? r->needs : "",
               r->needs ? ")" : "");
        cell(r->input, 120);
        printf(" | %s", r->kind == R_WARN ? "warning: " : "");
        cell(r->want, 400);
        printf(" |\n");
    }
}

int main(int argc, char **argv)
{
    size_t i;
    int api = 0, skipped = 0;
    if (argc > 1 && !strcmp(argv[1], "--markdown")) {
        print_markdown();
        return 0;
    }
    for (i = 0; i < sizeof rows / sizeof rows[0]; i++) {
        const row *r = &rows[i];
        char buf[1024];
        switch (r->kind) {
        case R_EXEC:
        case R_WARN:
            if (run_exec(r)) skipped++;
            break;
        case R_MM: run_mm(r); break;
        case R_CONFIG: run_config(r); break;
        case R_API: {
            const char *got = api_misuse(api++, buf, sizeof buf);
            CHECK(message_matches(r->want, got), "[%s]\n   got  \"%s\"\n   want \"%s\"", r->input, got,
                  r->want);
            break;
        }
        }
    }
    printf("%zu catalogue rows, %d skipped for missing plugins\n", sizeof rows / sizeof rows[0], skipped);
    return check_done();
}
