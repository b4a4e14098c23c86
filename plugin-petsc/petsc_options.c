/*
 * petsc_options.c -- the PETSc option string of a solve: a private database
 * per solver, and the check that PETSc read every option the user wrote.
 *
 * PETSc reads options from whichever database is current when an object
 * configures itself, and some packages (MUMPS, hypre) read them only while the
 * preconditioner is set up.  So each solver owns a PetscOptions object, filled
 * here once, which the plugin pushes as PETSc's default around every use of
 * that solver: options never leak from one solve into another, and PETSc's
 * own "used" marks tell afterwards which options nothing read.  PETSc itself
 * only warns about those at PetscFinalize (-options_left); here an unread
 * option is an error, because a misspelt -ksp_rtol silently gives the user
 * the default tolerance.  The suggestion comes from the option names the same
 * KSP/PC configuration prints under -help, captured through PetscHelpPrintf,
 * plus a short list of the options people type most.  On a collective solve
 * the check is collective too: the ranks agree on the unread option, so they
 * all return the same answer and all take part in rebuilding the
 * configuration for the suggestion.
 */
#include "petsc_plugin.h"

#include <ctype.h>
#include <stdarg.h>
#include <stdio.h>
#include <string.h>
#include <strings.h>

#define NAME_MAX_LEN 96

/* ---- the user's string ------------------------------------------------------- */

/* The next whitespace-separated token of *p (a double-quoted token keeps its
 * spaces, as PetscOptionsInsertString does), copied into tok; 0 at the end. */
static int next_token(const char **p, char *tok, size_t cap)
{
    const char *s = *p;
    size_t n = 0;
    while (*s && isspace((unsigned char)*s)) s++;
    if (!*s) return 0;
    if (*s == '"') {
        for (s++; *s && *s != '"'; s++)
            if (n + 1 < cap) tok[n++] = *s;
        if (*s) s++;
    } else {
        for (; *s && !isspace((unsigned char)*s); s++)
            if (n + 1 < cap) tok[n++] = *s;
    }
    tok[n] = '\0';
    *p = s;
    return 1;
}

/* PETSc's rule: "-name" is an option, "-1e-8" is a value. */
static int is_option(const char *tok)
{
    return tok[0] == '-' && isalpha((unsigned char)tok[1]);
}

/* petsc_plugin.h: whether text sets option name, and its value. */
int psc_find_option(const char *text, const char *name, char *value, size_t cap)
{
    char tok[NAME_MAX_LEN + 160];
    const char *p = text ? text : "";
    int found = 0, want_value = 0;
    while (next_token(&p, tok, sizeof tok)) {
        if (is_option(tok)) {
            want_value = strcasecmp(tok + 1, name) == 0;
            if (want_value) {
                found = 1;
                if (value && cap) value[0] = '\0';
            }
        } else if (want_value) {
            if (value && cap) {
                size_t len = strlen(tok) < cap ? strlen(tok) : cap - 1;
                memcpy(value, tok, len);
                value[len] = '\0';
            }
            want_value = 0;
        }
    }
    return found;
}

/* ---- the database -------------------------------------------------------------- */

/* Fills o: class defaults, then PETSc's process-wide options, then the user's. */
static int fill_options(silc_call *call, PetscOptions o, const char *user, int spd)
{
    PetscErrorCode ierr;
    char *global = NULL, solver[64] = "";
    int rc = SILC_OK;
    ierr = PetscOptionsGetAll(NULL, &global);
    if (ierr) return psc_fail(call, "PetscOptionsGetAll", ierr);
    /* CG, not PETSc's GMRES, is what a symmetric positive definite class asks for. */
    if (spd && (ierr = PetscOptionsInsertString(o, "-ksp_type cg"))) goto fail;
    /* This PETSc's MUMPS has neither METIS nor SCOTCH, and its fallback, PORD,
     * was 2.5x slower than AMF on 2-D grids. */
    if (!psc_find_option(user, "pc_factor_mat_solver_type", solver, sizeof solver))
        psc_find_option(global, "pc_factor_mat_solver_type", solver, sizeof solver);
    if (strcasecmp(solver, "mumps") == 0 && !psc_find_option(user, "mat_mumps_icntl_7", NULL, 0) &&
        !psc_find_option(global, "mat_mumps_icntl_7", NULL, 0) &&
        (ierr = PetscOptionsInsertString(o, "-mat_mumps_icntl_7 2")))
        goto fail;
    if (global && (ierr = PetscOptionsInsertString(o, global))) goto fail;
    if ((ierr = PetscOptionsInsertString(o, user))) {
        rc = psc_fail(call, "PetscOptionsInsertString", ierr);
        goto done;
    }
    goto done;
fail:
    rc = psc_fail(call, "PetscOptionsInsertString", ierr);
done:
    PetscFree(global);
    return rc;
}

int psc_options_create(silc_call *call, const char *user, int spd, PetscOptions *out)
{
    PetscOptions o = NULL;
    PetscErrorCode ierr = PetscOptionsCreate(&o);
    int rc;
    *out = NULL;
    if (ierr) return psc_fail(call, "PetscOptionsCreate", ierr);
    /* -help is answered by psc_options_print_help: PETSc's own printing
     * shows each options block once per process only. */
    if ((rc = fill_options(call, o, user, spd)) ||
        ((ierr = PetscOptionsClearValue(o, "-help")) && (rc = psc_fail(call, "PetscOptionsClearValue", ierr)))) {
        PetscOptionsDestroy(&o);
        return rc;
    }
    *out = o;
    return SILC_OK;
}

/* ---- suggestions --------------------------------------------------------------- */

typedef struct names {
    char (*name)[NAME_MAX_LEN];
    int n, cap;
    const char *strip; /* prefix removed from captured names */
} names;

static void names_add(names *L, const char *s, size_t len)
{
    int i;
    if (len == 0 || len >= NAME_MAX_LEN) return;
    for (i = 0; i < L->n; i++)
        if (strlen(L->name[i]) == len && strncasecmp(L->name[i], s, len) == 0) return;
    if (L->n == L->cap) {
        int cap = L->cap ? 2 * L->cap : 128;
        void *p = psc_host->realloc(L->name, (size_t)cap * sizeof *L->name);
        if (!p) return; /* a shorter candidate list only weakens the suggestion */
        L->name = p;
        L->cap = cap;
    }
    memcpy(L->name[L->n], s, len);
    L->name[L->n++][len] = '\0';
}

/* Options people type most: a floor under what -help shows. */
static const char *const common_options[] = {
    "ksp_type", "ksp_rtol", "ksp_atol", "ksp_divtol", "ksp_max_it", "ksp_norm_type", "ksp_pc_side",
    "ksp_initial_guess_nonzero", "ksp_gmres_restart", "ksp_monitor", "ksp_monitor_true_residual",
    "ksp_converged_reason", "ksp_view", "ksp_error_if_not_converged", "pc_type",
    "pc_factor_mat_solver_type", "pc_factor_levels", "pc_factor_fill", "pc_factor_mat_ordering_type",
    "pc_factor_shift_type", "pc_factor_shift_amount", "pc_factor_nonzeros_along_diagonal",
    "pc_jacobi_type", "pc_sor_omega", "pc_sor_its", "pc_hypre_type",
    "pc_hypre_boomeramg_strong_threshold", "pc_hypre_boomeramg_max_iter", "pc_gamg_type",
    "pc_gamg_threshold", "pc_gamg_agg_nsmooths", "pc_mg_levels", "pc_asm_overlap",
    "mat_mumps_icntl_7", "mat_mumps_icntl_14", "mat_mumps_icntl_24", "mat_mumps_cntl_1",
    "mat_umfpack_ordering", "mat_klu_ordering", "mat_superlu_colperm", "options_left", "help",
};

static names *capture_into;
static FILE *echo_to; /* also print the help text here, prefix removed (NULL: do not) */

/* line with every "-<prefix>" written as "-": the help of the throw-away KSP
 * as the user's options would show it. */
static void echo_text(const char *line, const char *prefix)
{
    size_t plen = strlen(prefix);
    const char *p = line, *hit;
    while (plen && (hit = strstr(p, prefix)) != NULL) {
        fwrite(p, 1, (size_t)(hit - p), echo_to);
        p = hit + plen;
    }
    fputs(p, echo_to);
}

/* Keeps every "-name" of a help text. */
static void capture_text(const char *line)
{
    const char *p;
    size_t skip;
    if (!capture_into) return;
    if (echo_to) echo_text(line, capture_into->strip);
    skip = strlen(capture_into->strip);
    for (p = line; (p = strchr(p, '-')) != NULL; p++) {
        size_t len = 0;
        if ((p > line && !isspace((unsigned char)p[-1])) || !isalpha((unsigned char)p[1])) continue;
        while (isalnum((unsigned char)p[1 + len]) || p[1 + len] == '_') len++;
        if (len > skip && strncasecmp(p + 1, capture_into->strip, skip) == 0)
            names_add(capture_into, p + 1 + skip, len - skip);
        p += len;
    }
}

/* Stand in for PetscHelpPrintf and PetscVFPrintf (lists of types are printed
 * through the latter) while the help text is collected: nothing reaches stdout. */
static PetscErrorCode capture_help(MPI_Comm comm, const char fmt[], ...)
{
    char line[4096];
    va_list ap;
    (void)comm;
    va_start(ap, fmt);
    vsnprintf(line, sizeof line, fmt, ap);
    va_end(ap);
    capture_text(line);
    return 0;
}

static PetscErrorCode capture_vfprintf(FILE *fd, const char fmt[], va_list ap)
{
    char line[4096];
    (void)fd;
    vsnprintf(line, sizeof line, fmt, ap);
    capture_text(line);
    return 0;
}

/* Collects the options a KSP configured from the user's string would read.
 * PETSc prints each options block's help once per process and prefix, so the
 * throw-away KSP gets a prefix of its own every time.  The KSP lives on A's
 * communicator comm (KSPSetOperators wants the same), so this is collective
 * over it; every rank captures the help text, whatever rank PETSc would
 * print it on. */
static void collect_names(silc_call *call, MPI_Comm comm, const char *user, int spd, Mat A, names *L)
{
    static unsigned serial;
    char prefix[40];
    PetscOptions o = NULL;
    KSP ksp = NULL;
    PetscErrorCode (*saved_help)(MPI_Comm, const char[], ...) = PetscHelpPrintf;
    PetscErrorCode (*saved_vfprintf)(FILE *, const char[], va_list) = PetscVFPrintf;
    int pushed = 0;
    size_t i;
    for (i = 0; i < sizeof common_options / sizeof common_options[0]; i++)
        names_add(L, common_options[i], strlen(common_options[i]));
    snprintf(prefix, sizeof prefix, "silc_help%u_", ++serial);
    L->strip = prefix;
    if (PetscOptionsCreate(&o) || PetscOptionsSetValue(o, "-help", NULL) ||
        PetscOptionsPrefixPush(o, prefix))
        goto done;
    if (fill_options(call, o, user, spd)) goto done;
    if (PetscOptionsPrefixPop(o) || PetscOptionsPush(o)) goto done;
    pushed = 1;
    capture_into = L;
    PetscHelpPrintf = capture_help;
    PetscVFPrintf = capture_vfprintf;
    if (!KSPCreate(comm, &ksp) && !KSPSetOptionsPrefix(ksp, prefix) &&
        !KSPSetOperators(ksp, A, A))
        KSPSetFromOptions(ksp);
    PetscHelpPrintf = saved_help;
    PetscVFPrintf = saved_vfprintf;
    capture_into = NULL;
done:
    KSPDestroy(&ksp);
    if (pushed) PetscOptionsPop();
    PetscOptionsDestroy(&o);
}

int psc_options_print_help(silc_call *call, MPI_Comm comm, const char *user, int spd, Mat A)
{
    names L = {NULL, 0, 0, ""};
    int rank = 0;
    MPI_Comm_rank(comm, &rank);
    fflush(stdout);
    echo_to = rank == 0 ? stdout : NULL;
    collect_names(call, comm, user, spd, A, &L);
    echo_to = NULL;
    fflush(stdout);
    psc_host->free(L.name);
    return SILC_OK;
}

/* Optimal string alignment distance (edits and transpositions), capped inputs. */
static int distance(const char *a, const char *b)
{
    int la = (int)strlen(a), lb = (int)strlen(b), i, j;
    int d[NAME_MAX_LEN + 1][NAME_MAX_LEN + 1];
    if (la > NAME_MAX_LEN || lb > NAME_MAX_LEN) return 1 << 20;
    for (i = 0; i <= la; i++) d[i][0] = i;
    for (j = 0; j <= lb; j++) d[0][j] = j;
    for (i = 1; i <= la; i++)
        for (j = 1; j <= lb; j++) {
            int cost = tolower((unsigned char)a[i - 1]) != tolower((unsigned char)b[j - 1]);
            int v = d[i - 1][j] + 1;
            if (d[i][j - 1] + 1 < v) v = d[i][j - 1] + 1;
            if (d[i - 1][j - 1] + cost < v) v = d[i - 1][j - 1] + cost;
            if (i > 1 && j > 1 && a[i - 1] == b[j - 2] && a[i - 2] == b[j - 1] && d[i - 2][j - 2] + 1 < v)
                v = d[i - 2][j - 2] + 1;
            d[i][j] = v;
        }
    return d[la][lb];
}

/* The closest known name to the unread one, or NULL if none is close. */
static const char *suggest(const names *L, const char *unread)
{
    const char *best = NULL;
    int i, bd = 1 << 20, len = (int)strlen(unread);
    int limit = len >= 12 ? 3 : len >= 6 ? 2 : 1;
    for (i = 0; i < L->n; i++) {
        int d = distance(unread, L->name[i]);
        if (d > 0 && d < bd) bd = d, best = L->name[i];
    }
    return bd <= limit ? best : NULL;
}

/* ---- the check ----------------------------------------------------------------- */

/* On several ranks, each checked its own database (alike, but a sub-block's
 * solver reads its options on its own rank only): all take the lowest rank
 * with an unread option, its name and whether it saw others, so every rank
 * returns the same and all or none enter collect_names. */
static int agree_unread(MPI_Comm comm, int size, char *unread, PetscInt *first, PetscInt *others)
{
    struct {
        int missing, rank;
    } in, out;
    struct {
        char name[NAME_MAX_LEN];
        int others;
    } what;
    if (size <= 1) return 0;
    MPI_Comm_rank(comm, &in.rank);
    in.missing = *first < 0;
    if (MPI_Allreduce(&in, &out, 1, MPI_2INT, MPI_MINLOC, comm) != MPI_SUCCESS) return -1;
    if (out.missing) {
        *first = -1;
        return 0;
    }
    memset(&what, 0, sizeof what);
    if (in.rank == out.rank) {
        memcpy(what.name, unread, NAME_MAX_LEN);
        what.others = *others > 0;
    }
    if (MPI_Bcast(&what, (int)sizeof what, MPI_BYTE, out.rank, comm) != MPI_SUCCESS) return -1;
    memcpy(unread, what.name, NAME_MAX_LEN);
    unread[NAME_MAX_LEN - 1] = '\0';
    *first = 0;
    *others = what.others;
    return 0;
}

int psc_options_check_used(silc_call *call, MPI_Comm comm, PetscOptions opts, const char *user,
                           int spd, Mat A)
{
    PetscInt n = 0, i, first = -1, others = 0;
    char **nm = NULL, **val = NULL, unread[NAME_MAX_LEN] = "";
    PetscBool strict = PETSC_TRUE, set = PETSC_FALSE;
    PetscErrorCode ierr;
    names L = {NULL, 0, 0, ""};
    const char *best;
    int rc, rank = 0, size = 1;
    MPI_Comm_size(comm, &size);
    MPI_Comm_rank(comm, &rank);
    /* -options_left no: PETSc's way of saying "unused options are fine". */
    if ((ierr = PetscOptionsGetBool(opts, NULL, "-options_left", &strict, &set)))
        return psc_fail(call, "PetscOptionsGetBool(-options_left)", ierr);
    if ((ierr = PetscOptionsLeftGet(opts, &n, &nm, &val))) return psc_fail(call, "PetscOptionsLeftGet", ierr);
    /* Only the user's own options count: the process-wide ones may be meant for other code. */
    for (i = 0; i < n; i++)
        if (psc_find_option(user, nm[i], NULL, 0)) {
            if (first < 0) {
                first = i;
                snprintf(unread, sizeof unread, "%s", nm[i]);
            } else {
                others++;
            }
        }
    PetscOptionsLeftRestore(opts, &n, &nm, &val);
    if (agree_unread(comm, size, unread, &first, &others))
        return psc_host->error(call, SILC_ELIB, "petsc: MPI failed agreeing on the unused options");
    if (first < 0) return SILC_OK;
    if (!strict) {
        /* Once, not once per rank. */
        if (rank == 0)
            psc_host->log(1, "petsc: option -%s was not used%s", unread,
                          others ? " (nor were others)" : "");
        return SILC_OK;
    }
    collect_names(call, comm, user, spd, A, &L);
    best = suggest(&L, unread);
    if (best)
        rc = psc_host->error(call, SILC_EARG, "option -%s was not used (misspelt? did you mean -%s?)%s",
                             unread, best, others ? "; other options were not used either" : "");
    else
        rc = psc_host->error(call, SILC_EARG,
                             "option -%s was not used (misspelt, or not read by this KSP/PC "
                             "configuration; -options_left no accepts it)%s",
                             unread, others ? "; other options were not used either" : "");
    psc_host->free(L.name);
    return rc;
}
