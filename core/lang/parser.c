/*
 * parser.c -- recursive-descent parser from tokens to the syntax tree.
 *
 * Operator levels, loosest first: || ; && ; comparisons (not associative) ;
 * + - ; * / \ *@ /@ ; unary - + ! ; ^ ^@ (right associative, and the right
 * operand may carry a sign: 2^-1) ; postfix ' [subscripts] f(args).  So
 * -2^2 is -(2^2) and -A*B is (-A)*B, as in MATLAB.
 *
 * No input can exhaust the C stack: every recursive descent passes enter(),
 * which refuses a text nested deeper than SILC_MAX_NESTING levels, and
 * add_kid() refuses a tree taller than SILC_MAX_EXPR_HEIGHT, which a long
 * left-associative chain (`1+1+...+1`) reaches without recursing here but
 * which the evaluator and node_free() would walk recursively.
 *
 * Keywords (clear who set info explain tune if while for else break continue
 * format help save load, and the block words end endif endwhile endfor
 * elseif) are keywords only at the start of a statement and only when not
 * followed by an assignment, so `info = 3` still binds a variable.  Blocks
 * are written with braces, `while (c) { ... }`, or as in Octave, `while c
 * ... end`; a condition is any expression.  Inside a matrix literal white
 * space separates elements as Octave does (starts_new_element).  The first syntax error
 * stops parsing; its message is Lua-style, "L:C: expected ')' (to close '('
 * at 1:5) near ';'".
 */
#include "lang.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

typedef struct ps_state {
    const char *src;
    lx_token *t;
    size_t pos, n;
    int loop_depth;
    ast_node *loop;        /* the innermost loop whose body is being parsed: it collects
                              the names its statements bind (note_binding) */
    int depth;             /* nested expressions: enter() bounds it */
    int block_depth;       /* nested statements (blocks, else if, explain): the same */
    int bracket_depth;     /* inside [ ]: `end` and `:` are subscripts */
    int in_literal;        /* directly inside a matrix literal's row (not within ( ) or a
                              subscript there): white space may separate elements */
    char *err;
    size_t errlen;
    int failed;
} ps_state;

static const lx_token *peek(const ps_state *P)
{
    return &P->t[P->pos];
}

static const lx_token *peek_at(const ps_state *P, size_t k)
{
    return &P->t[P->pos + k < P->n ? P->pos + k : P->n - 1];
}

static int is(const ps_state *P, int kind)
{
    return P->t[P->pos].kind == kind;
}

static const lx_token *next(ps_state *P)
{
    const lx_token *tk = &P->t[P->pos];
    if (P->pos + 1 < P->n) P->pos++;
    return tk;
}

/* Records the first error only: later ones are consequences of it. */
static void *fail(ps_state *P, const lx_token *at, const char *fmt, ...)
#if defined(__GNUC__)
    __attribute__((format(printf, 3, 4)))
#endif
    ;
static void *fail(ps_state *P, const lx_token *at, const char *fmt, ...)
{
    if (!P->failed) {
        va_list ap;
        int k = snprintf(P->err, P->errlen, "%d:%d: ", at->line, at->col);
        va_start(ap, fmt);
        if (k > 0 && (size_t)k < P->errlen) vsnprintf(P->err + k, P->errlen - (size_t)k, fmt, ap);
        va_end(ap);
        P->failed = 1;
    }
    return NULL;
}

/* One more level of recursion on the input, or a failure past
 * SILC_MAX_NESTING; every enter() that succeeds is matched by a leave().
 * Expressions and statements count apart, so the message names what is too
 * deep; the recursion is bounded by the sum of both limits. */
static int enter_level(ps_state *P, int *depth, const char *what)
{
    if (*depth >= SILC_MAX_NESTING) {
        fail(P, peek(P), "%s nested deeper than %d levels", what, SILC_MAX_NESTING);
        return -1;
    }
    (*depth)++;
    return 0;
}

static int enter(ps_state *P)
{
    return enter_level(P, &P->depth, "expression");
}

static void leave(ps_state *P)
{
    P->depth--;
}

static int enter_block(ps_state *P)
{
    return enter_level(P, &P->block_depth, "blocks");
}

static void leave_block(ps_state *P)
{
    P->block_depth--;
}

static void *unexpected(ps_state *P, const lx_token *at)
{
    char d[64];
    lx_describe(P->src, at, d, sizeof d);
    return fail(P, at, "unexpected %s", d);
}

static int tok_is_text(const ps_state *P, const lx_token *tk, const char *word)
{
    return tk->kind == TK_NAME && tk->len == strlen(word) &&
           !strncmp(P->src + tk->start, word, tk->len);
}

static char *tok_text(const ps_state *P, const lx_token *tk)
{
    char *s = malloc(tk->len + 1);
    if (s) {
        memcpy(s, P->src + tk->start, tk->len);
        s[tk->len] = 0;
    }
    return s;
}

static void node_free(ast_node *n)
{
    size_t i;
    if (!n) return;
    for (i = 0; i < n->nkids; i++) node_free(n->kids[i]);
    free(n->kids);
    free(n->name);
    free(n->binds);
    node_free(n->cond);
    node_free(n->els);
    free(n);
}

static ast_node *node_new(ps_state *P, int kind, const lx_token *at)
{
    ast_node *n = calloc(1, sizeof *n);
    if (!n) return fail(P, at, "out of memory while parsing");
    n->kind = kind;
    n->height = 1;
    n->line = at->line;
    n->col = at->col;
    n->start = at->start;
    n->end = at->start + at->len;
    return n;
}

/* Makes kid the last kid of n.  On failure kid is either freed or already
 * n's, so the caller frees only n.  An expression's height is checked here
 * because a chain such as `1+1+...+1` grows it without any recursion in the
 * parser; statements nest only through parse_statement(), bounded there. */
static int add_kid(ps_state *P, ast_node *n, ast_node *kid)
{
    ast_node **k;
    if (!kid) return -1;
    k = realloc(n->kids, (n->nkids + 1) * sizeof *k);
    if (!k) {
        node_free(kid);
        fail(P, peek(P), "out of memory while parsing");
        return -1;
    }
    n->kids = k;
    n->kids[n->nkids++] = kid;
    if (kid->end > n->end) n->end = kid->end;
    if (kid->start < n->start) n->start = kid->start;
    if (kid->height >= n->height) n->height = kid->height + 1;
    if (n->kind < ST_EXPR && n->height > SILC_MAX_EXPR_HEIGHT) {
        lx_token at;
        memset(&at, 0, sizeof at);
        at.line = n->line;
        at.col = n->col;
        fail(P, &at, "expression too long: more than %d operations in a chain "
                     "(split it with intermediate names)", SILC_MAX_EXPR_HEIGHT);
        return -1;
    }
    return 0;
}

/* Consumes the closing token of a bracket pair or fails Lua-style. */
static int close_with(ps_state *P, int kind, const char *what, const lx_token *opener, ast_node *n)
{
    char d[64];
    if (is(P, kind)) {
        const lx_token *tk = next(P);
        if (n) n->end = tk->start + tk->len;
        return 0;
    }
    lx_describe(P->src, peek(P), d, sizeof d);
    fail(P, peek(P), "expected '%s' (to close '%.*s' at %d:%d) near %s", what, (int)opener->len,
         P->src + opener->start, opener->line, opener->col, d);
    return -1;
}

static ast_node *parse_expr(ps_state *P);
static int parse_list_items(ps_state *P, ast_node *n, int closer, const char *closetext,
                            const lx_token *opener, int subscripts);

static ast_node *binary(ps_state *P, const lx_token *optk, ast_node *l, ast_node *r)
{
    ast_node *n;
    if (!r) {
        node_free(l);
        return NULL;
    }
    n = node_new(P, AST_BINARY, optk);
    if (!n) {
        node_free(l);
        node_free(r);
        return NULL;
    }
    n->op = optk->kind;
    if (add_kid(P, n, l)) {
        node_free(r);
        node_free(n);
        return NULL;
    }
    if (add_kid(P, n, r)) {
        node_free(n);
        return NULL;
    }
    return n;
}

/* Inside a matrix literal, does the token here start the next element
 * rather than continue this one?  As in Octave: a `+` or `-` with space
 * before it and none after is a sign (`[1 -2]` is two elements, `[1 - 2]`
 * and `[1 -  2]`... one), and a `(` or `[` after a space opens a new
 * element (`[a (1)]`, `[x [1 2]]`). */
static int starts_new_element(const ps_state *P)
{
    const lx_token *tk = peek(P);
    if (!P->in_literal || !tk->space_before) return 0;
    if (tk->kind == TK_PLUS || tk->kind == TK_MINUS) return !peek_at(P, 1)->space_before;
    return tk->kind == TK_LPAREN || tk->kind == TK_LBRACKET;
}

/* Subscript item: ':' alone, or an expression (a range a:b or a:s:b among them). */
static ast_node *parse_subscript(ps_state *P, int closer)
{
    if (is(P, TK_COLON) && (peek_at(P, 1)->kind == TK_COMMA || peek_at(P, 1)->kind == closer))
        return node_new(P, AST_COLON_ALL, next(P));
    return parse_expr(P);
}

/* Comma-separated items up to the closer; items go to n->kids. */
static int parse_list(ps_state *P, ast_node *n, int closer, const char *closetext,
                      const lx_token *opener, int subscripts)
{
    int saved = P->in_literal, rc;
    P->in_literal = 0;     /* `[f(1, -2) 3]`: white space means nothing inside the call */
    rc = parse_list_items(P, n, closer, closetext, opener, subscripts);
    P->in_literal = saved;
    return rc;
}

/* subscripts: 1 for A[...] (subscripts only), 2 for f(...) (a call, or
 * Octave's v(i) when f is a variable, which only the evaluator knows: strings,
 * ':' alone and `end` are all accepted), 0 for neither. */
static int parse_list_items(ps_state *P, ast_node *n, int closer, const char *closetext,
                            const lx_token *opener, int subscripts)
{
    if (is(P, closer) && subscripts != 1) return close_with(P, closer, closetext, opener, n);
    for (;;) {
        ast_node *item;
        if (subscripts == 1 || (subscripts == 2 && !is(P, TK_STRING))) {
            item = parse_subscript(P, closer);
        } else if (is(P, TK_STRING)) {
            const lx_token *tk = next(P);
            item = node_new(P, AST_STRING, tk);
            if (item && !(item->name = malloc(tk->len - 1))) {
                node_free(item);   /* a string node without its text would be cached */
                item = fail(P, tk, "out of memory while parsing");
            }
            if (item) {
                memcpy(item->name, P->src + tk->start + 1, tk->len - 2);
                item->name[tk->len - 2] = 0;
            }
        } else {
            item = parse_expr(P);
        }
        if (add_kid(P, n, item)) return -1;
        if (!is(P, TK_COMMA)) break;
        next(P);
    }
    return close_with(P, closer, closetext, opener, n);
}

/* Whether a token can begin an expression: in a literal's row such a token
 * after an element, with no comma between, begins the next element. */
static int can_start_expr(int k)
{
    return k == TK_NUMBER || k == TK_NAME || k == TK_LPAREN || k == TK_LBRACKET || k == TK_MINUS ||
           k == TK_PLUS || k == TK_NOT;
}

/* One row of a literal: elements separated by ',' or by white space. */
static int parse_row(ps_state *P, ast_node *row)
{
    for (;;) {
        if (add_kid(P, row, parse_expr(P))) return -1;
        if (is(P, TK_COMMA)) {
            next(P);
            if (is(P, TK_RBRACKET) || is(P, TK_SEMI)) return 0;   /* [1, 2, ] */
            continue;
        }
        if (!can_start_expr(peek(P)->kind)) return 0;
    }
}

/* [a, b; c, d] or [a b; c d]: rows separated by ';' or a line break (the
 * lexer turns it into ';'), elements by ',' or white space; an empty row
 * (`[1 2;]`, a trailing line break) adds nothing. */
static ast_node *parse_matrix(ps_state *P)
{
    const lx_token *open = next(P);
    ast_node *m = node_new(P, AST_MATRIX, open), *row = NULL;
    int saved = P->in_literal, saved_brackets = P->bracket_depth;
    if (!m) return NULL;
    P->in_literal = 1;
    P->bracket_depth = 0;  /* `end` in a literal inside a subscript is not the subscript's */
    while (is(P, TK_SEMI)) next(P);
    while (!is(P, TK_RBRACKET)) {
        row = node_new(P, AST_ROW, peek(P));
        if (!row || parse_row(P, row)) goto fail;
        if (add_kid(P, m, row)) {
            row = NULL;
            goto fail;
        }
        row = NULL;
        if (!is(P, TK_SEMI)) break;
        while (is(P, TK_SEMI)) next(P);
    }
    P->in_literal = saved;
    P->bracket_depth = saved_brackets;
    if (close_with(P, TK_RBRACKET, "]", open, m)) goto fail_restored;
    return m;
fail:
    P->in_literal = saved;
    P->bracket_depth = saved_brackets;
fail_restored:
    node_free(row);
    node_free(m);
    return NULL;
}

static ast_node *parse_primary(ps_state *P)
{
    const lx_token *tk = peek(P);
    ast_node *n;
    switch (tk->kind) {
    case TK_NUMBER:
        n = node_new(P, AST_NUM, next(P));
        if (n) n->num = tk->num, n->imag = tk->imag;
        return n;
    case TK_NAME:
        if (P->bracket_depth > 0 && tok_is_text(P, tk, "end")) return node_new(P, AST_END, next(P));
        n = node_new(P, AST_NAME, next(P));
        if (n && !(n->name = tok_text(P, tk))) {
            node_free(n);
            return fail(P, tk, "out of memory while parsing");
        }
        return n;
    case TK_LBRACKET:
        return parse_matrix(P);
    case TK_LPAREN: {
        int saved = P->in_literal;
        next(P);
        P->in_literal = 0;
        n = parse_expr(P);
        P->in_literal = saved;
        if (!n) return NULL;
        if (close_with(P, TK_RPAREN, ")", tk, NULL)) {
            node_free(n);
            return NULL;
        }
        /* the span covers the parentheses, so quoted operands read as written */
        n->start = tk->start;
        n->end = P->t[P->pos - 1].start + 1;
        return n;
    }
    default:
        return unexpected(P, tk);
    }
}

static ast_node *parse_postfix(ps_state *P)
{
    ast_node *n = parse_primary(P);
    while (n && !starts_new_element(P)) {
        const lx_token *tk = peek(P);
        ast_node *w;
        if (tk->kind == TK_QUOTE || tk->kind == TK_DOTQUOTE) {
            next(P);
            w = node_new(P, AST_TRANSPOSE, tk);
            if (w) w->op = tk->kind; /* ' conjugates, .' does not */
            if (!w || add_kid(P, w, n)) {
                if (!w) node_free(n);
                node_free(w);
                return NULL;
            }
            n = w;
        } else if (tk->kind == TK_LBRACKET) {
            next(P);
            w = node_new(P, AST_INDEX, tk);
            if (!w || add_kid(P, w, n)) {
                if (!w) node_free(n);
                node_free(w);
                return NULL;
            }
            P->bracket_depth++;
            n = w;
            if (parse_list(P, n, TK_RBRACKET, "]", tk, 1)) {
                P->bracket_depth--;
                node_free(n);
                return NULL;
            }
            P->bracket_depth--;
        } else if (tk->kind == TK_LPAREN && n->kind == AST_NAME) {
            int rc;
            next(P);
            n->kind = AST_CALL;
            P->bracket_depth++;  /* v(end): `end` is v's, if v is a variable */
            rc = parse_list(P, n, TK_RPAREN, ")", tk, 2);
            P->bracket_depth--;
            if (rc) {
                node_free(n);
                return NULL;
            }
        } else {
            break;
        }
    }
    return n;
}

static ast_node *parse_signed_power(ps_state *P);

static ast_node *parse_power(ps_state *P)
{
    ast_node *l = parse_postfix(P), *r;
    if (l && (is(P, TK_CARET) || is(P, TK_EPOW))) {
        const lx_token *op = next(P);
        if (enter(P)) {       /* 2^2^2^...: right-recursive */
            node_free(l);
            return NULL;
        }
        r = parse_signed_power(P);
        leave(P);
        return binary(P, op, l, r);
    }
    return l;
}

static ast_node *unary(ps_state *P, ast_node *(*operand)(ps_state *))
{
    const lx_token *tk = peek(P);
    if (tk->kind == TK_MINUS || tk->kind == TK_PLUS || tk->kind == TK_NOT) {
        ast_node *n, *k;
        next(P);
        if (enter(P)) return NULL;   /* ---...1: one level per sign */
        k = unary(P, operand);
        leave(P);
        if (!k) return NULL;
        n = node_new(P, AST_UNARY, tk);
        if (!n || add_kid(P, n, k)) {
            if (!n) node_free(k);
            node_free(n);
            return NULL;
        }
        n->op = tk->kind;
        return n;
    }
    return operand(P);
}

/* Right operand of ^: may be signed (2^-1), binds tighter than anything but postfix. */
static ast_node *parse_signed_power(ps_state *P)
{
    return unary(P, parse_power);
}

static ast_node *parse_unary(ps_state *P)
{
    return unary(P, parse_power);
}

static ast_node *parse_mul(ps_state *P)
{
    ast_node *l = parse_unary(P);
    while (l && (is(P, TK_STAR) || is(P, TK_SLASH) || is(P, TK_BACKSLASH) || is(P, TK_EMUL) ||
                 is(P, TK_EDIV))) {
        const lx_token *op = next(P);
        l = binary(P, op, l, parse_unary(P));
    }
    return l;
}

static ast_node *parse_add(ps_state *P)
{
    ast_node *l = parse_mul(P);
    while (l && (is(P, TK_PLUS) || is(P, TK_MINUS)) && !starts_new_element(P)) {
        const lx_token *op = next(P);
        l = binary(P, op, l, parse_mul(P));
    }
    return l;
}

static int is_comparison(int k)
{
    return k == TK_EQ || k == TK_NE || k == TK_LT || k == TK_LE || k == TK_GT || k == TK_GE;
}

/* a:b and a:s:b, between the comparisons and + - as in Octave (1:n+1 is
 * 1:(n+1)); kids from, to or from, step, to.  A value everywhere: a row
 * vector, or inside a subscript the indices it lists. */
static ast_node *parse_range(ps_state *P)
{
    ast_node *l = parse_add(P), *r;
    const lx_token *op;
    if (!l || !is(P, TK_COLON)) return l;
    op = next(P);
    r = node_new(P, AST_RANGE, op);
    if (!r || add_kid(P, r, l)) {
        if (!r) node_free(l);
        node_free(r);
        return NULL;
    }
    if (add_kid(P, r, parse_add(P))) {
        node_free(r);
        return NULL;
    }
    if (is(P, TK_COLON)) {
        next(P);
        if (add_kid(P, r, parse_add(P))) {
            node_free(r);
            return NULL;
        }
    }
    return r;
}

static ast_node *parse_cmp(ps_state *P)
{
    ast_node *l = parse_range(P);
    if (l && is_comparison(peek(P)->kind)) {
        const lx_token *op = next(P);
        l = binary(P, op, l, parse_range(P));
        if (l && is_comparison(peek(P)->kind)) {
            node_free(l);
            return fail(P, peek(P), "comparisons do not chain: use '&&' near '%.*s'",
                        (int)peek(P)->len, P->src + peek(P)->start);
        }
    }
    return l;
}

static ast_node *parse_and(ps_state *P)
{
    ast_node *l = parse_cmp(P);
    while (l && is(P, TK_AND)) {
        const lx_token *op = next(P);
        l = binary(P, op, l, parse_cmp(P));
    }
    return l;
}

static ast_node *parse_or(ps_state *P)
{
    ast_node *l = parse_and(P);
    while (l && is(P, TK_OR)) {
        const lx_token *op = next(P);
        l = binary(P, op, l, parse_and(P));
    }
    return l;
}

/* Every nested expression, (...), [...], f(...), subscript or condition,
 * comes through here: the one place that bounds their nesting. */
static ast_node *parse_expr(ps_state *P)
{
    ast_node *l;
    if (enter(P)) return NULL;
    l = parse_or(P);
    leave(P);
    return l;
}

/* ---- statements ---------------------------------------------------------- */

static ast_node *parse_statement(ps_state *P);

static int is_assign_op(int k)
{
    return k == TK_ASSIGN || k == TK_PLUSEQ || k == TK_MINUSEQ || k == TK_STAREQ || k == TK_SLASHEQ;
}

/* A statement ends at ';' (which also keeps its value from being shown),
 * ',' or a line break, as in Octave. */
static int is_separator(int k)
{
    return k == TK_SEMI || k == TK_NEWLINE || k == TK_COMMA;
}

static void skip_separators(ps_state *P)
{
    while (is_separator(peek(P)->kind)) next(P);
}

/* The words that close or continue an Octave-style block. */
static const char *const block_words[] = {"end", "endif", "endwhile", "endfor", "else", "elseif"};

static int is_block_word(const ps_state *P, const lx_token *tk)
{
    size_t i;
    for (i = 0; i < sizeof block_words / sizeof block_words[0]; i++)
        if (tok_is_text(P, tk, block_words[i])) return 1;
    return 0;
}

/* Statement lists end at '}' (a brace block), at the end of the text, or at
 * one of block_words (an Octave-style block, closer CLOSE_WORD). */
#define CLOSE_WORD (-1)

static int at_closer(const ps_state *P, int closer)
{
    if (closer == CLOSE_WORD) return is_block_word(P, peek(P)) && !is_assign_op(peek_at(P, 1)->kind);
    return is(P, closer);
}

/* Statements until closer, into n->kids.  A statement followed by ';' is
 * marked quiet: its value is not shown (core.display). */
static int parse_statements(ps_state *P, ast_node *n, int closer)
{
    skip_separators(P);
    while (!at_closer(P, closer) && !is(P, TK_EOF)) {
        ast_node *s = parse_statement(P);
        int k;
        if (!s || add_kid(P, n, s)) return -1;
        k = peek(P)->kind;
        if (k == TK_SEMI) s->quiet = 1;
        /* a block ends a statement by itself: `if (c) { } x = 1` */
        if (!is_separator(k) && !at_closer(P, closer) && k != TK_EOF && s->kind != ST_IF &&
            s->kind != ST_WHILE && s->kind != ST_FOR) {
            unexpected(P, peek(P));
            return -1;
        }
        skip_separators(P);
    }
    return 0;
}

static ast_node *parse_block(ps_state *P, ast_node *owner)
{
    const lx_token *open;
    ast_node *b;
    while (is(P, TK_NEWLINE)) next(P);    /* allow the brace on the next line */
    open = peek(P);
    if (!is(P, TK_LBRACE)) {
        char d[64];
        lx_describe(P->src, open, d, sizeof d);
        return fail(P, open, "expected '{' near %s", d);
    }
    next(P);
    b = node_new(P, ST_BLOCK, open);
    if (!b) return NULL;
    if (parse_statements(P, b, TK_RBRACE) || close_with(P, TK_RBRACE, "}", open, b)) {
        node_free(b);
        return NULL;
    }
    if (b->end > owner->end) owner->end = b->end;
    return b;
}

/* The statements of an Octave-style block, up to (not past) the word that
 * ends them; kw is the keyword that opened it, for the message when the
 * text ends first. */
static ast_node *parse_word_block(ps_state *P, ast_node *owner, const lx_token *kw)
{
    ast_node *b = node_new(P, ST_BLOCK, peek(P));
    if (!b) return NULL;
    if (parse_statements(P, b, CLOSE_WORD)) {
        node_free(b);
        return NULL;
    }
    if (is(P, TK_EOF)) {
        node_free(b);
        return fail(P, peek(P), "expected 'end' (to close '%.*s' at %d:%d) near end of input",
                    (int)kw->len, P->src + kw->start, kw->line, kw->col);
    }
    if (b->end > owner->end) owner->end = b->end;
    return b;
}

/* Consumes the `end` (or endif / endwhile / endfor, matching kw) of an
 * Octave-style block. */
static int close_word_block(ps_state *P, ast_node *owner, const lx_token *kw)
{
    const lx_token *tk = peek(P);
    char want[16];
    if (tok_is_text(P, kw, "elseif")) snprintf(want, sizeof want, "endif");
    else snprintf(want, sizeof want, "end%.*s", (int)(kw->len < 8 ? kw->len : 8), P->src + kw->start);
    if (tok_is_text(P, tk, "end") || tok_is_text(P, tk, want)) {
        next(P);
        owner->end = tk->start + tk->len;
        return 0;
    }
    {
        char d[64];
        lx_describe(P->src, tk, d, sizeof d);
        fail(P, tk, "expected 'end' (to close '%.*s' at %d:%d) near %s", (int)kw->len,
             P->src + kw->start, kw->line, kw->col, d);
    }
    return -1;
}

/* After the condition or the for header: a brace block `{ ... }` (the brace
 * may be on the next line), or statements up to the closing word.
 * *braced tells which. */
static ast_node *parse_body(ps_state *P, ast_node *owner, const lx_token *kw, int *braced)
{
    size_t save = P->pos;
    while (is(P, TK_NEWLINE)) next(P);
    *braced = is(P, TK_LBRACE);
    if (*braced) return parse_block(P, owner);
    P->pos = save;
    return parse_word_block(P, owner, kw);
}

/* A condition: any expression (Octave's `if x > 1`), parenthesised or not. */
static ast_node *parse_condition(ps_state *P)
{
    const lx_token *at = peek(P);
    if (at->kind == TK_EOF || is_separator(at->kind) || at->kind == TK_LBRACE) {
        char d[64];
        lx_describe(P->src, at, d, sizeof d);
        return fail(P, at, "expected a condition near %s", d);
    }
    return parse_expr(P);
}

/* if: kw is `if` (or `elseif`, continuing an Octave-style chain whose one
 * `end` closes it all). */
static ast_node *parse_if(ps_state *P, const lx_token *kw)
{
    ast_node *n = node_new(P, ST_IF, kw), *b;
    const lx_token *opener = kw;
    size_t save;
    int braced;
    if (!n) return NULL;
    if (!(n->cond = parse_condition(P)) || !(b = parse_body(P, n, opener, &braced)) ||
        add_kid(P, n, b)) {
        node_free(n);
        return NULL;
    }
    if (!braced) {
        const lx_token *w = peek(P);
        if (tok_is_text(P, w, "elseif")) {
            next(P);
            if (enter_block(P)) {           /* an elseif chain recurses */
                node_free(n);
                return NULL;
            }
            n->els = parse_if(P, w);
            leave_block(P);
            if (!n->els) {
                node_free(n);
                return NULL;
            }
            if (n->els->end > n->end) n->end = n->els->end;
            return n;
        }
        if (tok_is_text(P, w, "else")) {
            next(P);
            if (!(n->els = parse_word_block(P, n, kw))) {
                node_free(n);
                return NULL;
            }
        }
        /* `elseif` ends its chain with the `end` of the first `if` */
        if (close_word_block(P, n, kw)) {
            node_free(n);
            return NULL;
        }
        return n;
    }
    save = P->pos;
    while (is(P, TK_NEWLINE)) next(P);
    if (tok_is_text(P, peek(P), "else")) {
        next(P);
        if (tok_is_text(P, peek(P), "if")) {
            const lx_token *kw2 = next(P);
            if (enter_block(P)) {           /* an else-if chain recurses */
                node_free(n);
                return NULL;
            }
            n->els = parse_if(P, kw2);
            leave_block(P);
        } else {
            n->els = parse_block(P, n);
        }
        if (!n->els) {
            node_free(n);
            return NULL;
        }
        if (n->els->end > n->end) n->end = n->els->end;
    } else {
        P->pos = save;
    }
    return n;
}

/* name (NULL: any name) is bound by a statement of the body b collects. */
static void note_binding(ast_binds *b, const char *name)
{
    size_t i;
    if (!b || b->any) return;
    if (!name || b->n == AST_LOOP_BINDS_MAX) {
        b->any = 1;
        return;
    }
    for (i = 0; i < b->n; i++)
        if (!strcmp(b->names[i], name)) return;
    b->names[b->n++] = name;
}

/* What statement s, parsed whole, binds, noted by the loop whose body is
 * being parsed: a nested loop's names (its variable included) are bound
 * in the loop around it too.  Only once s is whole, since the names are
 * its nodes' (a failed statement's are freed). */
static void note_statement(ps_state *P, const ast_node *s)
{
    ast_binds *b = P->loop ? P->loop->binds : NULL;
    size_t i;
    switch (s->kind) {
    case ST_ASSIGN: case ST_OPASSIGN: case ST_INDEX_ASSIGN:
        note_binding(b, s->name);
        break;
    case ST_CLEAR: case ST_LOAD: /* without names: every name */
        if (!s->nkids) note_binding(b, NULL);
        for (i = 0; i < s->nkids; i++) note_binding(b, s->kids[i]->name);
        break;
    case ST_FOR: case ST_WHILE:
        if (s->binds->any) note_binding(b, NULL);
        for (i = 0; i < s->binds->n; i++) note_binding(b, s->binds->names[i]);
        break;
    default:
        break;
    }
}

/* The body of loop n (kw its keyword), parsed with n collecting the names
 * it binds. */
static ast_node *parse_loop_body(ps_state *P, ast_node *n, const lx_token *kw, int *braced)
{
    ast_node *outer = P->loop, *b;
    if (!(n->binds = calloc(1, sizeof *n->binds))) return fail(P, kw, "out of memory while parsing");
    if (n->kind == ST_FOR) note_binding(n->binds, n->name);
    P->loop = n;
    P->loop_depth++;
    b = parse_body(P, n, kw, braced);
    P->loop_depth--;
    P->loop = outer;
    return b;
}

int ps_loop_binds(const ast_node *loop, const char *name)
{
    size_t i;
    if (!loop->binds || loop->binds->any) return 1;
    for (i = 0; i < loop->binds->n; i++)
        if (!strcmp(loop->binds->names[i], name)) return 1;
    return 0;
}

static ast_node *parse_while(ps_state *P, const lx_token *kw)
{
    ast_node *n = node_new(P, ST_WHILE, kw), *b;
    int braced;
    if (!n) return NULL;
    if (!(n->cond = parse_condition(P))) {
        node_free(n);
        return NULL;
    }
    b = parse_loop_body(P, n, kw, &braced);
    if (!b || add_kid(P, n, b) || (!braced && close_word_block(P, n, kw))) {
        node_free(n);
        return NULL;
    }
    return n;
}

static ast_node *parse_for(ps_state *P, const lx_token *kw)
{
    ast_node *n = node_new(P, ST_FOR, kw), *b;
    const lx_token *open = NULL, *var;
    int braced;
    if (!n) return NULL;
    /* for i = e  or  for (i = e) */
    if (is(P, TK_LPAREN) && peek_at(P, 1)->kind == TK_NAME && peek_at(P, 2)->kind == TK_ASSIGN)
        open = next(P);
    var = peek(P);
    if (var->kind != TK_NAME || peek_at(P, 1)->kind != TK_ASSIGN) {
        char d[64];
        lx_describe(P->src, var, d, sizeof d);
        node_free(n);
        return fail(P, var, "for needs 'name = values', as in 'for i = 1:n', near %s", d);
    }
    if (!(n->name = tok_text(P, var))) {
        node_free(n);
        return fail(P, var, "out of memory while parsing");
    }
    next(P);
    next(P);
    if (!(n->cond = parse_expr(P)) || (open && close_with(P, TK_RPAREN, ")", open, NULL))) {
        node_free(n);
        return NULL;
    }
    b = parse_loop_body(P, n, kw, &braced);
    if (!b || add_kid(P, n, b) || (!braced && close_word_block(P, n, kw))) {
        node_free(n);
        return NULL;
    }
    return n;
}

static ast_node *name_node(ps_state *P, int kind)
{
    const lx_token *tk = peek(P);
    ast_node *n;
    if (tk->kind != TK_NAME) {
        char d[64];
        lx_describe(P->src, tk, d, sizeof d);
        return fail(P, tk, "expected a name near %s", d);
    }
    n = node_new(P, kind, next(P));
    if (n && !(n->name = tok_text(P, tk))) {
        node_free(n);
        return fail(P, tk, "out of memory while parsing");
    }
    return n;
}

static ast_node *num_node(ps_state *P)
{
    const lx_token *tk = next(P);
    ast_node *x = node_new(P, AST_NUM, tk);
    if (x) x->num = tk->num;
    return x;
}

/* The text of a string token, quotes off, malloc'd; NULL after fail(). */
static char *string_text(ps_state *P, const lx_token *tk)
{
    char *s = malloc(tk->len - 1);
    if (!s) {
        fail(P, tk, "out of memory while parsing");
        return NULL;
    }
    memcpy(s, P->src + tk->start + 1, tk->len - 2);
    s[tk->len - 2] = 0;
    return s;
}

/* save "file" [names] and load "file" [names]: name is the file, kids the
 * names (none: all). */
static ast_node *parse_file_names(ps_state *P, const lx_token *kw, int kind, const char *word)
{
    ast_node *n;
    if (!is(P, TK_STRING))
        return fail(P, peek(P), "%s needs a file name in quotes, as in %s \"run.h5\" x y", word, word);
    n = node_new(P, kind, kw);
    if (n && !(n->name = string_text(P, next(P)))) {
        node_free(n);
        return NULL;
    }
    while (n && peek(P)->kind == TK_NAME)
        if (add_kid(P, n, name_node(P, AST_NAME))) {
            node_free(n);
            return NULL;
        }
    return n;
}

/* tune [on [STEPS] | off | status | step | forget | report ["file.svg"] |
 * fit P:T P:T ...]; a bare `tune` is `tune status`. */
static ast_node *parse_tune(ps_state *P, const lx_token *kw)
{
    static const char *const words[] = {"on", "off", "status", "step", "forget", "report", "fit"};
    const lx_token *at = peek(P);
    ast_node *n;
    size_t i;
    if (at->kind == TK_EOF || is_separator(at->kind)) {
        n = node_new(P, ST_TUNE, kw);
        if (n && !(n->name = util_strdup("status"))) {
            node_free(n);
            return fail(P, kw, "out of memory while parsing");
        }
        return n;
    }
    n = name_node(P, ST_TUNE);
    if (!n) return NULL;
    n->start = kw->start;
    for (i = 0; i < sizeof words / sizeof words[0]; i++)
        if (!strcmp(n->name, words[i])) break;
    if (i == sizeof words / sizeof words[0]) {
        const char *best = util_closest(n->name, words, sizeof words / sizeof words[0]);
        node_free(n);
        if (best) return fail(P, at, "unknown tune command '%.*s'; did you mean '%s'?", (int)at->len,
                              P->src + at->start, best);
        return fail(P, at, "unknown tune command '%.*s' (on, off, status, step, forget, report, fit)",
                    (int)at->len, P->src + at->start);
    }
    if (!strcmp(n->name, "fit")) {
        while (is(P, TK_NUMBER)) {
            if (add_kid(P, n, num_node(P))) goto bad;
            if (!is(P, TK_COLON)) {
                node_free(n);
                return fail(P, peek(P), "tune fit takes points written p:seconds, as in 1:13.5");
            }
            next(P);
            if (!is(P, TK_NUMBER)) {
                node_free(n);
                return fail(P, peek(P), "tune fit: expected the seconds after ':'");
            }
            if (add_kid(P, n, num_node(P))) goto bad;
        }
    } else if (!strcmp(n->name, "on") && is(P, TK_NUMBER)) {
        if (add_kid(P, n, num_node(P))) goto bad;
    } else if (!strcmp(n->name, "report") && is(P, TK_STRING)) {
        const lx_token *tk = next(P);
        ast_node *x = node_new(P, AST_STRING, tk);
        if (x && !(x->name = string_text(P, tk))) {
            node_free(x);
            x = NULL;
        }
        if (add_kid(P, n, x)) goto bad;
    }
    return n;
bad:
    node_free(n);
    return NULL;
}

static ast_node *parse_keyword(ps_state *P, const lx_token *kw)
{
    ast_node *n;
    if (tok_is_text(P, kw, "if")) return parse_if(P, kw);
    if (tok_is_text(P, kw, "while")) return parse_while(P, kw);
    if (tok_is_text(P, kw, "for")) return parse_for(P, kw);
    if (is_block_word(P, kw))
        return fail(P, kw, "'%.*s' with no open if, while or for", (int)kw->len, P->src + kw->start);
    if (tok_is_text(P, kw, "format")) {
        /* format long | short (Octave's), a shorthand for set core.format */
        const lx_token *w = peek(P);
        const char *style = "short";
        n = node_new(P, ST_SET, kw);
        if (!n) return NULL;
        if (w->kind == TK_NAME) {
            next(P);
            if (tok_is_text(P, w, "long")) style = "long";
            else if (!tok_is_text(P, w, "short")) {
                node_free(n);
                return fail(P, w, "format takes 'long' or 'short', not '%.*s'", (int)w->len,
                            P->src + w->start);
            }
            n->end = w->start + w->len;
        }
        if (!(n->name = malloc(32))) {
            node_free(n);
            return fail(P, kw, "out of memory while parsing");
        }
        snprintf(n->name, 32, "core.format = %s", style);
        return n;
    }
    if (tok_is_text(P, kw, "break") || tok_is_text(P, kw, "continue")) {
        if (P->loop_depth == 0)
            return fail(P, kw, "'%.*s' outside a loop", (int)kw->len, P->src + kw->start);
        return node_new(P, tok_is_text(P, kw, "break") ? ST_BREAK : ST_CONTINUE, kw);
    }
    if (tok_is_text(P, kw, "who")) return node_new(P, ST_WHO, kw);
    if (tok_is_text(P, kw, "save")) return parse_file_names(P, kw, ST_SAVE, "save");
    if (tok_is_text(P, kw, "load")) return parse_file_names(P, kw, ST_LOAD, "load");
    if (tok_is_text(P, kw, "help")) {
        n = node_new(P, ST_HELP, kw);
        if (n && peek(P)->kind == TK_RAW) {
            const lx_token *w = next(P);
            size_t len = w->len;
            while (len && (P->src[w->start + len - 1] == ' ' || P->src[w->start + len - 1] == '\t' ||
                           P->src[w->start + len - 1] == '\r'))
                len--;
            if (!(n->name = malloc(len + 1))) {
                node_free(n);
                return fail(P, w, "out of memory while parsing");
            }
            memcpy(n->name, P->src + w->start, len);
            n->name[len] = 0;
            n->end = w->start + w->len;
        }
        return n;
    }
    if (tok_is_text(P, kw, "tune")) return parse_tune(P, kw);
    if (tok_is_text(P, kw, "profile")) {
        n = node_new(P, ST_PROFILE, kw);
        if (n && tok_is_text(P, peek(P), "clear")) {
            const lx_token *w = next(P);
            if (!(n->name = tok_text(P, w))) {
                node_free(n);
                return fail(P, w, "out of memory while parsing");
            }
            n->end = w->start + w->len;
        }
        return n;
    }
    if (tok_is_text(P, kw, "clear")) {
        n = node_new(P, ST_CLEAR, kw);
        while (n && peek(P)->kind == TK_NAME)
            if (add_kid(P, n, name_node(P, AST_NAME))) {
                node_free(n);
                return NULL;
            }
        return n;
    }
    if (tok_is_text(P, kw, "info")) {
        ast_node *x = name_node(P, ST_INFO);
        if (x) x->start = kw->start;
        return x;
    }
    if (tok_is_text(P, kw, "set")) {
        n = node_new(P, ST_SET, kw);
        if (n && is(P, TK_RAW)) {
            const lx_token *raw = next(P);
            if (!(n->name = tok_text(P, raw))) {
                node_free(n);
                return fail(P, raw, "out of memory while parsing");
            }
            n->end = raw->start + raw->len;
        }
        return n;
    }
    /* explain */
    n = node_new(P, ST_EXPLAIN, kw);
    if (n) {
        const lx_token *at = peek(P);
        ast_node *s;
        if (at->kind == TK_EOF || is_separator(at->kind)) {
            node_free(n);
            return fail(P, at, "explain needs a statement, as in 'explain x = A \\ b'");
        }
        s = parse_statement(P);
        if (s && s->kind != ST_EXPR && s->kind != ST_ASSIGN && s->kind != ST_OPASSIGN &&
            s->kind != ST_INDEX_ASSIGN) {
            node_free(s);
            node_free(n);
            return fail(P, at, "explain takes an assignment or an expression");
        }
        if (add_kid(P, n, s)) {
            node_free(n);
            return NULL;
        }
    }
    return n;
}


static const char *const keywords[] = {"if", "while", "for", "break", "continue", "who", "clear",
                                       "info", "set", "explain", "tune", "help", "save", "load",
                                       "format", "profile", "end", "endif", "endwhile", "endfor", "else",
                                       "elseif"};

static ast_node *parse_statement_body(ps_state *P);

/* Statements nest through if/while blocks and explain: bounded here. */
static ast_node *parse_statement(ps_state *P)
{
    ast_node *s;
    if (enter_block(P)) return NULL;
    s = parse_statement_body(P);
    leave_block(P);
    if (s) note_statement(P, s);
    return s;
}

static ast_node *parse_statement_body(ps_state *P)
{
    const lx_token *tk = peek(P);
    ast_node *n, *e;
    if (tk->kind == TK_NAME) {
        int nk = peek_at(P, 1)->kind;
        size_t i;
        if (!is_assign_op(nk) && nk != TK_LBRACKET)
            for (i = 0; i < sizeof keywords / sizeof keywords[0]; i++)
                if (tok_is_text(P, tk, keywords[i])) return parse_keyword(P, next(P));
        if (is_assign_op(nk)) {
            const lx_token *op;
            n = node_new(P, nk == TK_ASSIGN ? ST_ASSIGN : ST_OPASSIGN, tk);
            if (!n || !(n->name = tok_text(P, tk))) {
                node_free(n);
                return fail(P, tk, "out of memory while parsing");
            }
            next(P);
            op = next(P);
            n->op = op->kind;
            if (add_kid(P, n, parse_expr(P))) {
                node_free(n);
                return NULL;
            }
            return n;
        }
    }
    e = parse_expr(P);
    if (!e) return NULL;
    if (is(P, TK_ASSIGN) && ((e->kind == AST_INDEX && e->kids[0]->kind == AST_NAME) || e->kind == AST_CALL)) {
        /* x[...] = value, x(...) = value: kids are the value, then the subscripts */
        size_t i, first = e->kind == AST_CALL ? 0 : 1;
        next(P);
        n = node_new(P, ST_INDEX_ASSIGN, tk);
        if (!n || !(n->name = util_strdup(first ? e->kids[0]->name : e->name)) ||
            add_kid(P, n, parse_expr(P))) {
            node_free(n);
            node_free(e);
            return n ? NULL : fail(P, tk, "out of memory while parsing");
        }
        for (i = first; i < e->nkids; i++) {
            ast_node *sub = e->kids[i];
            e->kids[i] = NULL;          /* moved: add_kid frees it on failure */
            if (add_kid(P, n, sub)) {
                node_free(e);
                node_free(n);
                return NULL;
            }
        }
        node_free(e);
        return n;
    }
    if (is_assign_op(peek(P)->kind)) {
        node_free(e);
        return fail(P, peek(P), "cannot assign to this expression near '%.*s'", (int)peek(P)->len,
                    P->src + peek(P)->start);
    }
    n = node_new(P, ST_EXPR, tk);
    if (!n || add_kid(P, n, e)) {
        if (!n) node_free(e);
        node_free(n);
        return NULL;
    }
    return n;
}

int ps_parse(const char *text, lang_program **out, char *err, size_t errlen)
{
    lx_tokens toks;
    ps_state P;
    ast_node root;
    lang_program *prog;
    *out = NULL;
    if (lx_tokenize(text, &toks, err, errlen)) return -1;
    memset(&P, 0, sizeof P);
    memset(&root, 0, sizeof root);
    root.kind = ST_BLOCK;
    P.src = text;
    P.t = toks.t;
    P.n = toks.n;
    P.err = err;
    P.errlen = errlen;
    if (parse_statements(&P, &root, TK_EOF) || P.failed) {
        size_t i;
        for (i = 0; i < root.nkids; i++) node_free(root.kids[i]);
        free(root.kids);
        lx_free(&toks);
        if (!P.failed) snprintf(err, errlen, "out of memory while parsing");
        return -1;
    }
    lx_free(&toks);
    prog = calloc(1, sizeof *prog);
    if (!prog || !(prog->text = util_strdup(text))) {
        size_t i;
        for (i = 0; i < root.nkids; i++) node_free(root.kids[i]);
        free(root.kids);
        free(prog);
        snprintf(err, errlen, "out of memory while parsing");
        return -1;
    }
    prog->stmts = root.kids;
    prog->nstmts = root.nkids;
    *out = prog;
    return 0;
}

void ps_free(lang_program *p)
{
    size_t i;
    if (!p) return;
    for (i = 0; i < p->nstmts; i++) node_free(p->stmts[i]);
    free(p->stmts);
    free(p->text);
    free(p);
}
