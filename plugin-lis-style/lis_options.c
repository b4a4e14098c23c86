/*
 * lis_options.c -- the Lis option string: `-i cg -p ilu -ilu_fill 1 -tol 1e-12
 * -maxiter 1000 -restart 40 -omega 1.9 -saamg_theta 0.05 -saamg_unsym false
 * -conv_cond nrm2_r -initx_zeros true -print none -f double`.
 *
 * Enumerations take Lis's names or Lis's numbers (see lis.h for the table).
 * Unlike Lis, which ignores what it does not know, every unknown option,
 * missing value or malformed value is an error naming the option, with the
 * closest valid spelling suggested: a typo in a solver setting otherwise
 * silently runs a different method.
 */
#include "lis.h"

#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

typedef struct named {
    const char *name;
    int number;                 /* Lis's number, -1 if none */
    int id;                     /* ours, 0 = recognised but not implemented */
} named;

static const named solvers[] = {
    {"cg", 1, LIS_CG},           {"bicg", 2, LIS_BICG},       {"cgs", 3, LIS_CGS},
    {"bicgstab", 4, LIS_BICGSTAB}, {"bicgstabl", 5, LIS_BICGSTABL}, {"gpbicg", 6, LIS_GPBICG},
    {"tfqmr", 7, LIS_TFQMR},     {"orthomin", 8, LIS_ORTHOMIN}, {"gmres", 9, LIS_GMRES},
    {"jacobi", 10, LIS_JACOBI},  {"gs", 11, LIS_GS},          {"sor", 12, LIS_SOR},
    {"bicgsafe", 13, 0},         {"cr", 14, LIS_CR},          {"bicr", 15, LIS_BICR},
    {"crs", 16, LIS_CRS},        {"bicrstab", 17, LIS_BICRSTAB}, {"gpbicr", 18, LIS_GPBICR},
    {"bicrsafe", 19, 0},         {"fgmres", 20, LIS_FGMRES},  {"idrs", 21, LIS_IDRS},
    {"idr1", 22, LIS_IDR1},      {"minres", 23, LIS_MINRES},  {"cocg", 24, LIS_COCG},
    {"cocr", 25, 0},             {NULL, 0, 0}};

static const named precons[] = {
    {"none", 0, LIS_PC_NONE + 1000}, {"jacobi", 1, LIS_PC_JACOBI}, {"ilu", 2, LIS_PC_ILU},
    {"ssor", 3, LIS_PC_SSOR},        {"hybrid", 4, 0},             {"is", 5, 0},
    {"sainv", 6, 0},                 {"saamg", 7, LIS_PC_SAAMG},   {"iluc", 8, 0},
    {"ilut", 9, LIS_PC_ILUT},        {"ic", -1, LIS_PC_IC},        {NULL, 0, 0}};
/* (none's id is offset by 1000 only so that 0 can mean "not implemented".) */

static const char *const option_names[] = {
    "-i", "-p", "-ilu_fill", "-ell", "-idrs_s", "-irestart", "-tol", "-maxiter", "-restart",
    "-omega", "-ssor_omega", "-ilut_drop", "-ilut_rate", "-saamg_theta", "-saamg_unsym", "-conv_cond",
    "-initx_zeros",
    "-print", "-f", NULL};

void lis_options_init(lis_options *o)
{
    memset(o, 0, sizeof *o);
    o->solver = 0;     /* chosen by class */
    o->precon = -1;    /* chosen by solver and class */
    o->ilu_fill = 0;
    o->ell = 2;
    o->idrs_s = 2;
    o->restart = 40;
    o->maxiter = 1000;
    o->tol = 1e-12;
    o->omega = 1.9;
    o->ssor_omega = 1.0;
    o->ilut_drop = 0.05;
    o->ilut_rate = 5.0;
    o->saamg_theta = 0.05;
    o->conv_cond = -1;  /* not given: ||r0||, or ||b|| from an initial guess (lis_style.c) */
    o->initx_zeros = -1; /* not given: start from the host's initial guess when there is one */
}

/* Levenshtein distance, for "did you mean". */
static size_t edit_distance(const char *a, const char *b)
{
    size_t la = strlen(a), lb = strlen(b), i, j, d[64];
    if (la > 62 || lb > 62) return 99;
    for (j = 0; j <= lb; j++) d[j] = j;
    for (i = 1; i <= la; i++) {
        size_t diag = d[0];
        d[0] = i;
        for (j = 1; j <= lb; j++) {
            size_t up = d[j], best = diag + (a[i - 1] != b[j - 1]);
            if (up + 1 < best) best = up + 1;
            if (d[j - 1] + 1 < best) best = d[j - 1] + 1;
            diag = up;
            d[j] = best;
        }
    }
    return d[lb];
}

/* The closest of names (first wins ties), or NULL if nothing is close. */
static const char *closest(const char *word, const char *const *names, size_t count)
{
    const char *best = NULL;
    size_t bd = 99, i, limit = strlen(word) / 2 + 1;
    for (i = 0; i < count; i++) {
        size_t d = edit_distance(word, names[i]);
        if (d < bd) bd = d, best = names[i];
    }
    return bd <= (limit > 2 ? limit : 2) ? best : NULL;
}

static const char *closest_named(const char *word, const named *t, int implemented_only)
{
    const char *names[32];
    size_t n = 0;
    for (; t->name && n < 32; t++)
        if (!implemented_only || t->id) names[n++] = t->name;
    return closest(word, names, n);
}

static void list_implemented(const named *t, char *buf, size_t len)
{
    size_t used = 0;
    buf[0] = '\0';
    for (; t->name; t++) {
        int k;
        if (!t->id) continue;
        k = snprintf(buf + used, len - used, "%s%s", used ? ", " : "", t->name);
        if (k < 0 || (size_t)k >= len - used) break;
        used += (size_t)k;
    }
}

static int parse_long(const char *s, long long *out)
{
    char *end;
    errno = 0;
    *out = strtoll(s, &end, 10);
    return end != s && *end == '\0' && errno != ERANGE;
}

static int parse_real(const char *s, double *out)
{
    char *end;
    errno = 0;
    *out = strtod(s, &end);
    return end != s && *end == '\0' && errno != ERANGE && isfinite(*out);
}

/* A name or a Lis number of table t; returns the id, 0 after writing err. */
static int parse_enum(const char *opt, const char *val, const named *t, const char *what,
                      char *err, size_t errlen)
{
    const named *e;
    long long num;
    char list[256];
    int by_number = parse_long(val, &num);
    for (e = t; e->name; e++)
        if (by_number ? e->number >= 0 && e->number == num : strcmp(e->name, val) == 0) break;
    list_implemented(t, list, sizeof list);
    if (!e->name) {
        const char *near = by_number ? NULL : closest_named(val, t, 1);
        if (near)
            snprintf(err, errlen, "%s: unknown %s '%s'; did you mean '%s'?", opt, what, val, near);
        else
            snprintf(err, errlen, "%s: unknown %s '%s' (choose %s)", opt, what, val, list);
        return 0;
    }
    if (!e->id) {
        snprintf(err, errlen, "%s: %s '%s' (Lis number %d) is not implemented by lis-style (choose %s)",
                 opt, what, e->name, e->number, list);
        return 0;
    }
    return e->id;
}

static int int_in(const char *opt, const char *val, long long lo, long long hi, long long *out,
                  char *err, size_t errlen)
{
    if (parse_long(val, out) && *out >= lo && *out <= hi) return 1;
    snprintf(err, errlen, "%s expects an integer from %lld to %lld, got '%s'", opt, lo, hi, val);
    return 0;
}

/* A real in (lo, hi) (open ends: lo_open/hi_open). */
static int real_in(const char *opt, const char *val, double lo, double hi, int lo_open,
                   double *out, char *err, size_t errlen)
{
    if (parse_real(val, out) && (lo_open ? *out > lo : *out >= lo) && *out < hi) return 1;
    if (hi >= 1e300)
        snprintf(err, errlen, "%s expects a %s number, got '%s'", opt,
                 lo_open ? "positive" : "non-negative", val);
    else
        snprintf(err, errlen, "%s expects a number %s %g and below %g, got '%s'", opt,
                 lo_open ? "above" : "from", lo, hi, val);
    return 0;
}

/* -x value pairs from a fixed small table of choices. */
static int choice(const char *opt, const char *val, const char *const *names, const int *codes,
                  int *out, char *err, size_t errlen)
{
    size_t i, n = 0;
    char list[160] = "";
    for (i = 0; names[i]; i++, n++)
        if (strcmp(names[i], val) == 0) {
            *out = codes[i];
            return 1;
        }
    for (i = 0; names[i]; i++) {
        size_t u = strlen(list);
        snprintf(list + u, sizeof list - u, "%s%s", i ? ", " : "", names[i]);
    }
    {
        const char *near = closest(val, names, n);
        if (near && !(val[0] >= '0' && val[0] <= '9'))
            snprintf(err, errlen, "%s: unknown value '%s'; did you mean '%s'?", opt, val, near);
        else
            snprintf(err, errlen, "%s: unknown value '%s' (choose %s)", opt, val, list);
    }
    return 0;
}

/* true / false, or Lis's 1 / 0. */
static int boolean(const char *opt, const char *val, int *out, char *err, size_t errlen)
{
    static const char *const n[] = {"true", "1", "false", "0", NULL};
    static const int v[] = {1, 1, 0, 0};
    return choice(opt, val, n, v, out, err, errlen);
}

static int set_option(lis_options *o, const char *opt, const char *val, char *err, size_t errlen)
{
    long long k;
    double x;
    int c;
    if (!strcmp(opt, "-i")) {
        if (!(c = parse_enum(opt, val, solvers, "solver", err, errlen))) return -1;
        o->solver = c;
    } else if (!strcmp(opt, "-p")) {
        if (!(c = parse_enum(opt, val, precons, "preconditioner", err, errlen))) return -1;
        o->precon = c == LIS_PC_NONE + 1000 ? LIS_PC_NONE : c;
    } else if (!strcmp(opt, "-ilu_fill")) {
        if (!int_in(opt, val, 0, 64, &k, err, errlen)) return -1;
        o->ilu_fill = (int)k;
    } else if (!strcmp(opt, "-ell")) {
        if (!int_in(opt, val, 1, 20, &k, err, errlen)) return -1;
        o->ell = (int)k;
    } else if (!strcmp(opt, "-idrs_s") || !strcmp(opt, "-irestart")) {
        if (!int_in(opt, val, 1, 64, &k, err, errlen)) return -1;
        o->idrs_s = (int)k;
    } else if (!strcmp(opt, "-tol")) {
        if (!real_in(opt, val, 0, 1e308, 1, &x, err, errlen)) return -1;
        o->tol = x;
    } else if (!strcmp(opt, "-maxiter")) {
        if (!int_in(opt, val, 0, 1000000000LL, &k, err, errlen)) return -1;
        o->maxiter = k;
    } else if (!strcmp(opt, "-restart")) {
        if (!int_in(opt, val, 1, 1000, &k, err, errlen)) return -1;
        o->restart = (int)k;
    } else if (!strcmp(opt, "-omega")) {
        if (!real_in(opt, val, 0, 2, 1, &x, err, errlen)) return -1;
        o->omega = x;
    } else if (!strcmp(opt, "-ssor_omega")) {
        if (!real_in(opt, val, 0, 2, 1, &x, err, errlen)) return -1;
        o->ssor_omega = x;
    } else if (!strcmp(opt, "-ilut_drop")) {
        if (!real_in(opt, val, 0, 1, 0, &x, err, errlen)) return -1;
        o->ilut_drop = x;
    } else if (!strcmp(opt, "-ilut_rate")) {
        if (!real_in(opt, val, 0, 1e308, 1, &x, err, errlen)) return -1;
        o->ilut_rate = x;
    } else if (!strcmp(opt, "-saamg_theta")) {
        if (!real_in(opt, val, 0, 1, 0, &x, err, errlen)) return -1;
        o->saamg_theta = x;
    } else if (!strcmp(opt, "-conv_cond")) {
        /* "backward" is SILC's own (Lis has no such criterion): lis.h. */
        static const char *const n[] = {"nrm2_r", "0", "nrm2_b", "1", "backward", NULL};
        static const int v[] = {0, 0, 1, 1, LIS_CONV_BACKWARD};
        if (!choice(opt, val, n, v, &o->conv_cond, err, errlen)) return -1;
    } else if (!strcmp(opt, "-initx_zeros")) {
        if (!boolean(opt, val, &o->initx_zeros, err, errlen)) return -1;
    } else if (!strcmp(opt, "-saamg_unsym")) {
        if (!boolean(opt, val, &o->saamg_unsym, err, errlen)) return -1;
    } else if (!strcmp(opt, "-print")) {
        static const char *const n[] = {"none", "0", "out", "2", NULL};
        static const int v[] = {0, 0, 1, 1};
        if (!choice(opt, val, n, v, &o->print, err, errlen)) return -1;
    } else if (!strcmp(opt, "-f")) {
        static const char *const n[] = {"double", "0", "quad", "1", NULL};
        static const int v[] = {0, 0, 1, 1};
        if (!choice(opt, val, n, v, &o->quad, err, errlen)) return -1;
    } else {
        const char *near = closest(opt, option_names, sizeof option_names / sizeof *option_names - 1);
        if (near) snprintf(err, errlen, "unknown option '%s'; did you mean '%s'?", opt, near);
        else snprintf(err, errlen, "unknown option '%s'", opt);
        return -1;
    }
    return 0;
}

static int is_option_name(const char *opt)
{
    size_t i;
    for (i = 0; option_names[i]; i++)
        if (!strcmp(option_names[i], opt)) return 1;
    return 0;
}

int lis_options_parse(const char *text, lis_options *o, char *err, size_t errlen)
{
    char tok[2][128];
    const char *p = text ? text : "";
    for (;;) {
        int t;
        for (t = 0; t < 2; t++) {
            size_t len;
            while (*p == ' ' || *p == '\t' || *p == '\n' || *p == '\r') p++;
            len = strcspn(p, " \t\n\r");
            if (len >= sizeof tok[t]) {
                snprintf(err, errlen, "option word too long near '%.32s'", p);
                return -1;
            }
            memcpy(tok[t], p, len);
            tok[t][len] = '\0';
            p += len;
            if (t == 0 && !len) return 0; /* end of text */
        }
        if (tok[0][0] != '-') {
            snprintf(err, errlen, "unexpected '%s' (options start with '-', as in '-i cg')", tok[0]);
            return -1;
        }
        /* "-p -tol 1e-8": a value that is itself an option name is missing. */
        if (!tok[1][0] || (is_option_name(tok[1]) && is_option_name(tok[0]))) {
            if (!is_option_name(tok[0])) return set_option(o, tok[0], "", err, errlen);
            snprintf(err, errlen, "%s needs a value", tok[0]);
            if (!strcmp(tok[0], "-i") || !strcmp(tok[0], "-p")) {
                char list[256];
                size_t u = strlen(err);
                list_implemented(strcmp(tok[0], "-i") ? precons : solvers, list, sizeof list);
                snprintf(err + u, errlen - u, " (%s)", list);
            }
            return -1;
        }
        if (set_option(o, tok[0], tok[1], err, errlen)) return -1;
        o->given++;
    }
}

void lis_options_finish(lis_options *o, int spd_class, int mmatrix_class)
{
    if (!o->given && mmatrix_class) {
        /* The first solve with a large symmetric M-matrix (core's
         * solve.sparse.mmatrix.spd): cheaper than a factorization when it
         * converges in few iterations, and soon handed to one when not. */
        o->solver = LIS_CG;
        o->precon = LIS_PC_SAAMG;
        o->conv_cond = LIS_CONV_BACKWARD;
        o->maxiter = LIS_MMATRIX_MAXITER;
        return;
    }
    if (!o->given) {
        o->solver = spd_class ? LIS_CG : LIS_BICGSTAB;
        o->precon = spd_class ? LIS_PC_IC : LIS_PC_ILU;
        return;
    }
    if (!o->solver) o->solver = LIS_BICG;
    if (o->precon < 0) o->precon = LIS_PC_NONE;
    if (o->solver == LIS_IDR1) o->idrs_s = 1; /* IDR(s) with s = 1, whatever -idrs_s says */
}

int lis_bicr_family(int solver)
{
    return solver == LIS_BICR || solver == LIS_CRS || solver == LIS_BICRSTAB || solver == LIS_GPBICR;
}

int lis_needs_transpose(int solver)
{
    return solver == LIS_BICG || lis_bicr_family(solver);
}

const char *lis_solver_name(int solver)
{
    switch (solver) {
    case LIS_CG: return "CG";
    case LIS_BICG: return "BiCG";
    case LIS_CGS: return "CGS";
    case LIS_BICGSTAB: return "BiCGSTAB";
    case LIS_BICGSTABL: return "BiCGSTAB(l)";
    case LIS_GPBICG: return "GPBiCG";
    case LIS_TFQMR: return "TFQMR";
    case LIS_GMRES: return "GMRES";
    case LIS_JACOBI: return "Jacobi";
    case LIS_GS: return "Gauss-Seidel";
    case LIS_SOR: return "SOR";
    case LIS_FGMRES: return "FGMRES";
    case LIS_IDRS: return "IDR(s)";
    case LIS_IDR1: return "IDR(1)";
    case LIS_MINRES: return "MINRES";
    case LIS_COCG: return "COCG";
    case LIS_ORTHOMIN: return "Orthomin(m)";
    case LIS_CR: return "CR";
    case LIS_BICR: return "BiCR";
    case LIS_CRS: return "CRS";
    case LIS_BICRSTAB: return "BiCRSTAB";
    case LIS_GPBICR: return "GPBiCR";
    default: return "?";
    }
}

void lis_solver_label(const lis_options *o, char *buf, size_t len)
{
    switch (o->solver) {
    case LIS_BICGSTABL: snprintf(buf, len, "BiCGSTAB(%d)", o->ell); break;
    case LIS_GMRES: snprintf(buf, len, "GMRES(%d)", o->restart); break;
    case LIS_FGMRES: snprintf(buf, len, "FGMRES(%d)", o->restart); break;
    case LIS_ORTHOMIN: snprintf(buf, len, "Orthomin(%d)", o->restart); break;
    case LIS_IDRS: snprintf(buf, len, "IDR(%d)", o->idrs_s); break;
    case LIS_SOR: snprintf(buf, len, "SOR(%g)", o->omega); break;
    default: snprintf(buf, len, "%s", lis_solver_name(o->solver)); break;
    }
}

void lis_precon_label(const lis_options *o, char *buf, size_t len)
{
    switch (o->precon) {
    case LIS_PC_JACOBI: snprintf(buf, len, "Jacobi"); break;
    case LIS_PC_ILU: snprintf(buf, len, "ILU(%d)", o->ilu_fill); break;
    case LIS_PC_SSOR: snprintf(buf, len, "SSOR(%g)", o->ssor_omega); break;
    case LIS_PC_ILUT: snprintf(buf, len, "ILUT(%g,%g)", o->ilut_drop, o->ilut_rate); break;
    case LIS_PC_SAAMG: snprintf(buf, len, "SA-AMG(%g)", o->saamg_theta); break;
    case LIS_PC_IC: snprintf(buf, len, "IC(0)"); break;
    default: snprintf(buf, len, "none"); break;
    }
}
