/*
 * lexer.c -- turns statement text into tokens with 1-based line:column.
 *
 * Newlines separate statements, so they are tokens, except inside () and
 * subscripts [], where an expression may span lines, and inside a matrix
 * literal, where a newline separates rows as `;` does (Octave's
 * `[1 2\n 3 4]` is 2x2).  A `[` opens a subscript when it follows what can
 * be subscripted (a name, a number, `)`, `]`, `'`) with no space between, or
 * with a space outside a literal; otherwise it opens a literal: the parser
 * (parse_postfix) makes the same choice from the same token facts.  `'` is always the transpose: strings use
 * double quotes and only appear as option arguments.  The argument of a `set`
 * keyword statement is not an expression but "key = value" with free-form
 * value text (backend option strings such as "-i cg -p ilu"), so the lexer
 * hands the rest of that statement over as one raw token; so does `help`,
 * whose word may be a setting's key (`help solve.verify`).
 */
#include "lang.h"

#include <ctype.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

/* Brackets deeper than this are past the parser's nesting limit anyway
 * (SILC_MAX_NESTING), so their kind no longer matters. */
#define LX_MAX_OPEN (2 * SILC_MAX_NESTING + 8)

typedef struct lx_state {
    const char *s;
    size_t pos;
    int line, col;
    int depth;             /* open ( and [ */
    char open[LX_MAX_OPEN]; /* what the innermost LX_MAX_OPEN of them are: '(' ,
                               's' a subscript, 'l' a literal */
    int space;             /* white space since the last token */
    lx_tokens *out;
    char *err;
    size_t errlen;
} lx_state;

static int push(lx_state *L, int kind, size_t start, int line, int col, double num)
{
    lx_tokens *o = L->out;
    if (o->n == o->cap) {
        size_t cap = o->cap ? 2 * o->cap : 64;
        lx_token *t = realloc(o->t, cap * sizeof *t);
        if (!t) {
            snprintf(L->err, L->errlen, "out of memory while reading the text");
            return -1;
        }
        o->t = t;
        o->cap = cap;
    }
    o->t[o->n].kind = kind;
    o->t[o->n].imag = 0;
    o->t[o->n].line = line;
    o->t[o->n].col = col;
    o->t[o->n].start = start;
    o->t[o->n].len = L->pos - start;
    o->t[o->n].num = num;
    o->t[o->n].space_before = L->space;
    L->space = 0;
    o->n++;
    return 0;
}

static void advance(lx_state *L, size_t k)
{
    while (k-- && L->s[L->pos]) {
        if (L->s[L->pos] == '\n') {
            L->line++;
            L->col = 1;
        } else {
            L->col++;
        }
        L->pos++;
    }
}

/* True when the previous token ends a statement (or there is none), i.e. a
 * name here is in keyword position. */
static int at_statement_start(const lx_state *L)
{
    int k;
    if (L->depth > 0) return 0; /* inside ( ) or [ ]: ';' separates matrix rows */
    if (L->out->n == 0) return 1;
    k = L->out->t[L->out->n - 1].kind;
    return k == TK_NEWLINE || k == TK_SEMI || k == TK_LBRACE || k == TK_RBRACE;
}

/* After `set` in keyword position: is the name used as a variable instead
 * (`set = 3`, `set[2] = 1`, `set += 1`)? */
static int name_is_assigned(const char *p)
{
    while (*p == ' ' || *p == '\t') p++;
    if (p[0] == '=' && p[1] != '=') return 1;
    if (p[0] == '[') return 1;
    return (p[0] == '+' || p[0] == '-' || p[0] == '*' || p[0] == '/') && p[1] == '=';
}

/* The rest of a `set` statement up to ';', newline, '#' or the end. */
static int lex_raw(lx_state *L)
{
    size_t start;
    int line, col;
    while (L->s[L->pos] == ' ' || L->s[L->pos] == '\t') advance(L, 1);
    start = L->pos;
    line = L->line;
    col = L->col;
    while (L->s[L->pos] && !strchr(";\n#", L->s[L->pos])) advance(L, 1);
    if (L->pos == start) return 0;
    return push(L, TK_RAW, start, line, col, 0);
}

static int lex_number(lx_state *L)
{
    const char *s = L->s;
    size_t p = L->pos, start = L->pos;
    int line = L->line, col = L->col;
    char buf[128];
    while (isdigit((unsigned char)s[p])) p++;
    /* "1.*x" is 1 .* x: the dot belongs to the operator */
    if (s[p] == '.' && !strchr("*/^", s[p + 1] ? s[p + 1] : 'x')) {
        p++;
        while (isdigit((unsigned char)s[p])) p++;
    }
    if ((s[p] == 'e' || s[p] == 'E') &&
        (isdigit((unsigned char)s[p + 1]) ||
         ((s[p + 1] == '+' || s[p + 1] == '-') && isdigit((unsigned char)s[p + 2])))) {
        p += 2;
        while (isdigit((unsigned char)s[p])) p++;
    }
    if (p - start >= sizeof buf) {
        snprintf(L->err, L->errlen, "%d:%d: number is too long", line, col);
        return -1;
    }
    memcpy(buf, s + start, p - start);
    buf[p - start] = 0;
    advance(L, p - start);
    /* 2i, 2.5j, 1e3i: an imaginary number (Octave's suffixes) */
    int imag = (s[p] == 'i' || s[p] == 'j') && !(isalnum((unsigned char)s[p + 1]) || s[p + 1] == '_');
    if (imag) advance(L, 1), p++;
    if (isalpha((unsigned char)s[p]) || s[p] == '_') {
        snprintf(L->err, L->errlen, "%d:%d: malformed number near '%s%c'", line, col, buf, s[p]);
        return -1;
    }
    if (push(L, TK_NUMBER, start, line, col, strtod(buf, NULL))) return -1;
    L->out->t[L->out->n - 1].imag = imag;
    return 0;
}

static int lex_string(lx_state *L)
{
    size_t start = L->pos;
    int line = L->line, col = L->col;
    advance(L, 1);
    while (L->s[L->pos] && L->s[L->pos] != '"' && L->s[L->pos] != '\n') advance(L, 1);
    if (L->s[L->pos] != '"') {
        snprintf(L->err, L->errlen, "%d:%d: unfinished string", line, col);
        return -1;
    }
    advance(L, 1);
    return push(L, TK_STRING, start, line, col, 0);
}

/* Operators, longest first so "*@" wins over "*". */
static const struct { const char *text; int kind; } ops[] = {
    {"*@", TK_EMUL}, {"/@", TK_EDIV}, {"^@", TK_EPOW},
    {".*", TK_EMUL}, {"./", TK_EDIV}, {".^", TK_EPOW}, {".'", TK_DOTQUOTE},
    {"+=", TK_PLUSEQ}, {"-=", TK_MINUSEQ}, {"*=", TK_STAREQ}, {"/=", TK_SLASHEQ},
    {"==", TK_EQ}, {"!=", TK_NE}, {"<=", TK_LE}, {">=", TK_GE},
    {"&&", TK_AND}, {"||", TK_OR},
    {"+", TK_PLUS}, {"-", TK_MINUS}, {"*", TK_STAR}, {"/", TK_SLASH},
    {"\\", TK_BACKSLASH}, {"^", TK_CARET}, {"'", TK_QUOTE},
    {"(", TK_LPAREN}, {")", TK_RPAREN}, {"[", TK_LBRACKET}, {"]", TK_RBRACKET},
    {"{", TK_LBRACE}, {"}", TK_RBRACE}, {",", TK_COMMA}, {";", TK_SEMI},
    {":", TK_COLON}, {"=", TK_ASSIGN}, {"<", TK_LT}, {">", TK_GT}, {"!", TK_NOT},
};

/* The kind of the innermost open bracket: '(' , 's', 'l', or 0 at the top. */
static char innermost(const lx_state *L)
{
    if (L->depth == 0) return 0;
    return L->depth <= LX_MAX_OPEN ? L->open[L->depth - 1] : '(';
}

/* Whether a `[` here opens a subscript (see the head of the file). */
static int opens_subscript(const lx_state *L)
{
    int k;
    if (L->out->n == 0) return 0;
    k = L->out->t[L->out->n - 1].kind;
    if (k != TK_NAME && k != TK_NUMBER && k != TK_RPAREN && k != TK_RBRACKET && k != TK_QUOTE &&
        k != TK_DOTQUOTE)
        return 0;
    return !(L->space && innermost(L) == 'l');
}

static int lex_operator(lx_state *L)
{
    size_t i, start = L->pos;
    int line = L->line, col = L->col;
    for (i = 0; i < sizeof ops / sizeof ops[0]; i++) {
        size_t k = strlen(ops[i].text);
        if (strncmp(L->s + L->pos, ops[i].text, k) != 0) continue;
        if (ops[i].kind == TK_LPAREN || ops[i].kind == TK_LBRACKET) {
            if (L->depth < LX_MAX_OPEN)
                L->open[L->depth] = ops[i].kind == TK_LPAREN ? '(' : opens_subscript(L) ? 's' : 'l';
            L->depth++;
        }
        if ((ops[i].kind == TK_RPAREN || ops[i].kind == TK_RBRACKET) && L->depth > 0) L->depth--;
        advance(L, k);
        return push(L, ops[i].kind, start, line, col, 0);
    }
    {
        unsigned char c = (unsigned char)L->s[L->pos];
        if (isprint(c))
            snprintf(L->err, L->errlen, "%d:%d: unexpected character '%c'", line, col, c);
        else
            snprintf(L->err, L->errlen, "%d:%d: unexpected character (byte 0x%02x)", line, col, c);
    }
    return -1;
}

int lx_tokenize(const char *text, lx_tokens *out, char *err, size_t errlen)
{
    lx_state L;
    L.s = text;
    L.pos = 0;
    L.line = L.col = 1;
    L.depth = 0;
    L.space = 0;
    L.out = out;
    L.err = err;
    L.errlen = errlen;
    out->t = NULL;
    out->n = out->cap = 0;
    for (;;) {
        char c = text[L.pos];
        int rc = 0;
        if (c == 0) break;
        if (c == ' ' || c == '\t' || c == '\r') {
            advance(&L, 1);
            L.space = 1;
            continue;
        }
        if (c == '#') {
            while (text[L.pos] && text[L.pos] != '\n') advance(&L, 1);
            continue;
        }
        if (c == '\n') {
            size_t start = L.pos;
            int line = L.line, col = L.col;
            advance(&L, 1);
            if (L.depth == 0) {
                rc = push(&L, TK_NEWLINE, start, line, col, 0);
            } else if (innermost(&L) == 'l') {
                int k = out->t[out->n - 1].kind; /* a literal's '[' is a token before */
                if (k != TK_LBRACKET && k != TK_COMMA && k != TK_SEMI)
                    rc = push(&L, TK_SEMI, start, line, col, 0);
            }
            L.space = 1;
        } else if (isdigit((unsigned char)c) ||
                   (c == '.' && isdigit((unsigned char)text[L.pos + 1]))) {
            rc = lex_number(&L);
        } else if (isalpha((unsigned char)c) || c == '_') {
            size_t start = L.pos;
            int line = L.line, col = L.col, kw = at_statement_start(&L);
            while (isalnum((unsigned char)text[L.pos]) || text[L.pos] == '_') advance(&L, 1);
            rc = push(&L, TK_NAME, start, line, col, 0);
            /* set's argument is "key = value"; help's a word that may be a
             * key (help solve.verify) */
            if (!rc && kw &&
                ((L.pos - start == 3 && !strncmp(text + start, "set", 3)) ||
                 (L.pos - start == 4 && !strncmp(text + start, "help", 4))) &&
                !name_is_assigned(text + L.pos))
                rc = lex_raw(&L);
        } else if (c == '"') {
            rc = lex_string(&L);
        } else {
            rc = lex_operator(&L);
        }
        if (rc) {
            lx_free(out);
            return -1;
        }
    }
    if (push(&L, TK_EOF, L.pos, L.line, L.col, 0)) {
        lx_free(out);
        return -1;
    }
    return 0;
}

void lx_free(lx_tokens *toks)
{
    free(toks->t);
    toks->t = NULL;
    toks->n = toks->cap = 0;
}

void lx_describe(const char *text, const lx_token *tk, char *out, size_t outlen)
{
    if (tk->kind == TK_EOF)
        snprintf(out, outlen, "end of input");
    else if (tk->kind == TK_NEWLINE)
        snprintf(out, outlen, "end of line");
    else
        snprintf(out, outlen, "'%.*s'", (int)(tk->len > 40 ? 40 : tk->len), text + tk->start);
}
