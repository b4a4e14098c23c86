/*
 * lang.h -- the command language (core/lang/): tokens (lexer.c), the
 * syntax tree (parser.c), the evaluator's state shared with the built-in
 * functions (builtins.c), subscripts (index.c) and matrix literals
 * (concat.c), `help` (help.c), save/load (h5io.c), the memo of repeated
 * operations (memo.c) and how values are shown (display.c), all driven by
 * lang_exec() in eval.c.  The language
 * calls down into the tuner, the dispatcher, the accuracy machinery and the
 * distributed layer; only the engine and the client call it.
 *
 * A text is lexed and parsed whole before anything runs, so a syntax error
 * anywhere refuses the text.  The parsed program keeps its own copy of the
 * text; every node records its source span so error messages and `info` can
 * quote the code the user wrote.
 */
#ifndef SILC_LANG_H
#define SILC_LANG_H

#include "dispatch.h"

/* ---- running a text (eval.c) ------------------------------------------------- */
/* Executes a statement list.  Statements run in order; the first failing one
 * stops the run, leaves the store as the earlier statements left it, and sets
 * E->err to "statement N: <message>" (N only when the text has several). */
int lang_exec(silc_engine *E, const char *text);

/* ---- tokens ----------------------------------------------------------------- */
enum lx_kind {
    TK_EOF = 0, TK_NEWLINE, TK_NUMBER, TK_NAME, TK_STRING, TK_RAW,
    TK_PLUS, TK_MINUS, TK_STAR, TK_SLASH, TK_BACKSLASH, TK_EMUL, TK_EDIV,
    TK_CARET, TK_EPOW, TK_QUOTE,
    TK_DOTQUOTE,           /* .' plain transpose (' is the conjugate transpose) */
    TK_LPAREN, TK_RPAREN, TK_LBRACKET, TK_RBRACKET, TK_LBRACE, TK_RBRACE,
    TK_COMMA, TK_SEMI, TK_COLON,
    TK_ASSIGN, TK_PLUSEQ, TK_MINUSEQ, TK_STAREQ, TK_SLASHEQ,
    TK_EQ, TK_NE, TK_LT, TK_LE, TK_GT, TK_GE, TK_AND, TK_OR, TK_NOT
};

typedef struct lx_token {
    int kind;              /* enum lx_kind */
    int line, col;         /* 1-based */
    size_t start, len;     /* span in the source text */
    double num;            /* TK_NUMBER */
    int imag;              /* TK_NUMBER written with an i or j suffix (2.5i): imaginary */
    int space_before;      /* white space precedes it: in a matrix literal `[1 -2]` is two
                              elements and `[1 - 2]` one, as in Octave (parser.c) */
} lx_token;

typedef struct lx_tokens {
    lx_token *t;
    size_t n, cap;
} lx_tokens;

/* Tokenizes text; the `set` keyword's argument becomes one TK_RAW token.
 * Inside a matrix literal a line break separates rows, so it becomes a
 * TK_SEMI (none after `[`, `,` or `;`); inside ( ) and subscripts it is
 * dropped, so an expression may span lines.
 * Returns 0, or -1 with "L:C: message" in err. */
int lx_tokenize(const char *text, lx_tokens *out, char *err, size_t errlen);
void lx_free(lx_tokens *toks);
/* Printable form of a token for messages: "'*'", "end of input", "newline". */
void lx_describe(const char *text, const lx_token *tk, char *out, size_t outlen);

/* ---- syntax tree -------------------------------------------------------------- */
enum ast_kind {
    /* expressions */
    AST_NUM, AST_NAME, AST_STRING, AST_END, AST_COLON_ALL, AST_RANGE,
    AST_BINARY, AST_UNARY, AST_TRANSPOSE, AST_INDEX, AST_CALL,
    AST_MATRIX,            /* [a, b; c, d]: kids are AST_ROW nodes (none for []) */
    AST_ROW,               /* one row of a matrix literal: kids are its blocks */
    /* statements (after every expression kind: parser.c tests kind < ST_EXPR) */
    ST_EXPR, ST_ASSIGN, ST_OPASSIGN, ST_INDEX_ASSIGN, ST_CLEAR, ST_WHO, ST_SET,
    ST_INFO, ST_EXPLAIN, ST_IF, ST_WHILE, ST_BREAK, ST_CONTINUE,
    ST_FOR,                /* for name = cond: kids[0] the body block; each column of the
                              value of cond in turn (a range is never built whole) */
    ST_BLOCK,              /* { statements } of IF / WHILE: kids are the statements */
    ST_TUNE,               /* tune WORD: name the word; kids AST_NUM arguments (fit: p, t
                              pairs); els unused; an AST_STRING kid names a file */
    ST_HELP,               /* help [NAME]: name is NULL or the word asked about */
    ST_PROFILE,            /* profile [clear]: name is NULL or "clear" */
    ST_SAVE, ST_LOAD       /* save/load "file" [names]: name is the file, kids AST_NAME */
};

/* The names a loop's body may bind (ST_FOR, ST_WHILE; parser.c): its
 * assignments, its loop variable, clear and load, nested loops' included;
 * what tells the evaluator that a matrix stays the same from one iteration
 * to the next (eval.c: solve_again).  any: the body may bind any name (a
 * clear or load without names), or it binds more than AST_LOOP_BINDS_MAX
 * (then the list is not kept). */
#define AST_LOOP_BINDS_MAX 32
typedef struct ast_binds {
    int any;
    size_t n;
    const char *names[AST_LOOP_BINDS_MAX];  /* the binding statements' names (not owned) */
} ast_binds;

typedef struct ast_node ast_node;
struct ast_node {
    int kind;              /* enum ast_kind */
    int op;                /* operator token kind (BINARY, UNARY, OPASSIGN) */
    int line, col;
    int height;            /* 1 + the tallest kid's: bounds every walk of the tree */
    int quiet;             /* a statement followed by ';': its value is not shown */
    size_t start, end;     /* source span [start, end) */
    double num;            /* AST_NUM */
    int imag;              /* AST_NUM: the number is num times the imaginary unit */
    char *name;            /* NAME, CALL, STRING (unquoted text), assignment target, SET raw text */
    /* kids: BINARY/UNARY/TRANSPOSE operands; INDEX base then subscripts; CALL
     * arguments; RANGE from, to or from, step, to; EXPR/ASSIGN/OPASSIGN the expression;
     * INDEX_ASSIGN the value then the subscripts; CLEAR names; EXPLAIN the
     * statement; IF/WHILE the body block; BLOCK the statements */
    ast_node **kids;
    size_t nkids;
    ast_node *cond;        /* IF, WHILE */
    ast_node *els;         /* IF: else branch (a block or another IF), may be NULL */
    ast_binds *binds;      /* FOR, WHILE: what the body binds (owned); else NULL */
};

/* A parsed text: the owned copy of the source and its top-level statements. */
typedef struct lang_program {
    char *text;
    ast_node **stmts;
    size_t nstmts;
} lang_program;

/* Parses text into *out.  Returns 0, or -1 with "L:C: message" in err. */
int ps_parse(const char *text, lang_program **out, char *err, size_t errlen);
void ps_free(lang_program *p);
/* 1 when the body of loop (ST_FOR, ST_WHILE) may bind name. */
int ps_loop_binds(const ast_node *loop, const char *name);

/* ---- evaluation state --------------------------------------------------------- */
typedef struct lang_ev {
    silc_engine *E;
    const char *src;       /* text of the program being run */
    int explain;           /* explain mode: describe operations, run no solve */
    strbuf *explain_out;
    int explain_step;
    int64_t end_value;     /* what `end` means in the subscript being evaluated */
    int in_subscript;
    int has_solve;         /* the current statement ran a solve */
    uint64_t moved0[2];    /* dist.h's byte counters (matrices, vectors) when the statement began */
    eng_pending pending;   /* its operands when its backward error is deferred */
    char backends[128];    /* solve backends of the current statement */
    char *bind_text;       /* the statement's text, made before an update in place */
    uint64_t loops;        /* `while` iterations of this exec (E->loop_budget) */
    int loop_depth;        /* `while` loops open (the outermost one's iterations are the tuner's steps) */
    const struct ev_loop *loop; /* the innermost loop running (eval.c), NULL outside loops */
    const ast_node *solve_matrix; /* the operand text of the matrix of the solve about to run
                                     (A of `A \ b`, `solve(A, b)`), or NULL */
    const silc_value *warm; /* initial guess for the statement's solve (solve.initial_guess), or NULL */
    const ast_node *warm_for; /* the assignment whose guess is looked up at its first solve, or NULL */
    silc_value *warm_held; /* the reference to the guess that exec_assign releases */
    int profile;           /* core.profile = on when the exec began: time statements and calls */
    double t_first;        /* the exec's start on the clock, for its first statement; then 0 */
    /* Last, and not zeroed by lang_exec: 1.2 KB that a statement without a
     * solve never reads (has_solve says when it holds one), whose zeroing
     * was 19 cache lines written per EXEC (docs/overhead.md, SpMV). */
    silc_report report;    /* the statement's last solve report, when has_solve */
} lang_ev;

/* Operand description for messages: "'A'" when the node is short source text,
 * else "the left operand" / "the right operand" (side 0 / 1). */
void ev_operand_name(const lang_ev *V, const ast_node *n, int side, char *out, size_t outlen);
/* Runs one operation through the dispatcher (or, in explain mode, describes
 * it and runs it only when it is not a solve).  what names the operation for
 * explain ("A \ b").  Returns 0 with *out set (owned), or -1 with E->err set. */
int ev_run(lang_ev *V, silc_call *call, const char *what, silc_value **out);
/* ev_run of the common one- and two-operand call (b may be NULL). */
int ev_run_op(lang_ev *V, int op, int sub, const silc_value *a, const silc_value *b,
              double alpha, double beta, const char *what, silc_value **out);
/* "3x4" */
void ev_shape(const silc_value *v, char *out, size_t outlen);
/* diagvec(L' * R) as the column sums of L .* R (eval.c says when): whether
 * the call has that form, and its value. */
int ev_is_diagvec_of_product(const ast_node *call);
int ev_diagvec_of_product(lang_ev *V, const ast_node *call, silc_value **out);

/* ---- built-in functions (builtins.c) ------------------------------------------ */
/* Names of every built-in function and constant (for suggestions), NULL-ended. */
extern const char *const bi_names[];
int bi_is_function(const char *name);
/* Constant by name (pi, inf, nan, eps): 1 and *x, or 0. */
int bi_constant(const char *name, double *x);
/* Calls function node->name with the call node's arguments.  Returns 0 and
 * *out, or -1 with E->err set. */
int bi_call(lang_ev *V, const ast_node *call, silc_value **out);
/* Shared with index.c: CSR copy of any value (core-side, no dispatch). */
silc_value *bi_to_csr(const silc_value *a);

/* ---- matrix literals (concat.c) ---------------------------------------------- */
/* [a, b; c, d]: blocks side by side must have equal rows, rows stacked equal
 * columns; 0x0 blocks are skipped, as in MATLAB.  The result is CSR when any
 * block is CSR, else dense.  Returns 0 with *out, or -1 with E->err set. */
int cc_matrix(lang_ev *V, const ast_node *n, silc_value **out);

/* ---- subscripts (index.c) ----------------------------------------------------- */
/* base[subs] and target[subs] = rhs.  what names the matrix for messages
 * ("'v'").  Return 0 with *out set (owned), or -1 with E->err set. */
int ix_extract(lang_ev *V, ast_node *const *subs, size_t nsubs, const char *what,
               const silc_value *base, silc_value **out);
int ix_assign(lang_ev *V, ast_node *const *subs, size_t nsubs, const char *what,
              const silc_value *target, const silc_value *rhs, silc_value **out);

/* eval.c entry used by index.c and builtins.c */
int ev_expr(lang_ev *V, const ast_node *n, silc_value **out);
/* As ev_expr, but the value may be distributed by rows (dist.h): for the
 * consumers that hand it to ev_run or bind it, never read its arrays.
 * ev_expr gathers such a value to every rank first. */
int ev_expr_dist(lang_ev *V, const ast_node *n, silc_value **out);

/* display.c: v as Octave shows it, `name = ...` (name NULL: as disp(v)
 * shows it, without the name), into b; core.format says short or long. */
void dp_show(silc_engine *E, strbuf *b, const char *name, const silc_value *v);

/* help.c: `help` (every statement and built-in word) or `help NAME` (its
 * usage and what it does) into out; -1 with err for an unknown name.  The
 * README's statement (statements = 1) and built-in tables, as markdown. */
int lang_help(strbuf *out, const char *name, char *err, size_t errlen);
void lang_help_markdown(strbuf *out, int statements);

/*
 * ---- save and load (h5io.c): a session's values in HDF5 (h5io.c says the
 * layouts, and why a failed save or load changes nothing).
 */

/* names[0..n) (n = 0: every name) to path, replacing the file.  0, or -1
 * with E->err. */
int h5_save(silc_engine *E, const char *path, const char *const *names, size_t n);
/* names[0..n) (n = 0: every object at the file's root) from path, bound
 * all or none.  0, or -1 with E->err naming the object. */
int h5_load(silc_engine *E, const char *path, const char *const *names, size_t n);
/* Opens the HDF5 module (libsilc_h5.so) now rather than at the first save
 * or load, when it is installed (silcd's parent, before it forks sessions);
 * says nothing when it is not: the statements do. */
void h5_module_open(void);

/*
 * ---- the memo (memo.c): repeated operations on unchanged operands return
 * the value they gave before (memo.c says when and why).
 */

/* The value call gave the last time it ran on these operands (retained), or NULL. */
silc_value *memo_lookup(silc_engine *E, const silc_call *call);
/* After call ran and gave result: remember it (warned: the call warned, so
 * it is never handed out).  Failing to remember loses nothing. */
void memo_note(silc_engine *E, const silc_call *call, silc_value *result, int warned);
/* What a session holds (silcd's --max-session-bytes): the arrays of its
 * bound values, per name; those of the memo's results no name holds; and
 * the plugin state (factorizations) that solves attached to any of these
 * or to the operands an `info` record keeps, each value's once, as the
 * dispatcher measured it (on an SPMD engine, this rank's part). */
typedef struct memo_holdings {
    uint64_t bound, memo_arrays, attached;
} memo_holdings;
/* The sum of the three; h (if not NULL) gets each. */
uint64_t memo_held(const silc_engine *E, memo_holdings *h);
/* Lets go until memo_held(E) <= room, or nothing is left to let go: the
 * memo's results first, then attached state (no name's before a bound
 * value's), least recently used first.  Bound values stay; when they alone
 * are over room nothing is let go (the caller refuses).  Not on an SPMD
 * engine, whose ranks must let go together: */
void memo_release(silc_engine *E, double room);
/* There (silcd --mpi), rank 0 makes memo_release's choice without letting
 * anything go: what would go is appended to plan, one holder a line ("0
 * NAME": the value bound to NAME; "1 NAME" .. "3 NAME": operand A, B, X of
 * NAME's info record), in order, and the bytes held after it are returned.
 * Every rank then lets go of the plan's holders, in its order, with
 * memo_release_named at a point all reach: 0, or -1 with err when this
 * engine lacks a holder the plan names (the ranks disagree). */
uint64_t memo_release_plan(const silc_engine *E, double room, strbuf *plan);
int memo_release_named(silc_engine *E, const char *plan, char *err, size_t errlen);
/* Under a value budget (val_budget_set: inside a silcd request), lets go as
 * memo_release does until the attached state and need more bytes fit what
 * the budget has left (it counts the values themselves).  Nothing without
 * a budget.  memo_lookup does it before every call, sparing the call's
 * operands. */
void memo_make_room(silc_engine *E, double need);
/* At the engine's end. */
void memo_free(silc_engine *E);

#endif
