/*
 * petsc_plugin.h -- what the two source files of plugin-petsc share.
 *
 * petsc.c owns the plugin's life (PETSc and MPI start-up, the tables, the
 * SOLVE operation, sequential or collective on the host's communicator);
 * petsc_options.c turns the user's PETSc option string into a private options
 * database per solver and finds the options PETSc never read.  Internal to
 * the plugin: nothing here is exported.
 */
#ifndef SILC_PETSC_PLUGIN_H
#define SILC_PETSC_PLUGIN_H

#include "silc_plugin.h"

#include <petscksp.h>

/* The host table handed to silc_plugin_init. */
extern const silc_host_api *psc_host;

/* host->error, except during the rank-local phase of a collective solve
 * (petsc.c: local_begin .. agree): then the first message is kept back, so
 * that the agreement reports it on every rank instead of one rank leaving
 * while the others enter a collective PETSc call. */
int psc_error(silc_call *call, int status, const char *fmt, ...)
#if defined(__GNUC__)
    __attribute__((format(printf, 3, 4)))
#endif
    ;

/* Records "petsc <what>: <PETSc's message> (PETSc error <ierr>: <generic text>)"
 * for a PETSc call that returned ierr (through psc_error), and returns the
 * SILC status for it. */
int psc_fail(silc_call *call, const char *what, PetscErrorCode ierr);

/* Whether text (a PETSc option string) sets option name (without '-'), and
 * then its value in value (cap bytes; "" for none; the last setting wins, as
 * in PETSc).  value may be NULL. */
int psc_find_option(const char *text, const char *name, char *value, size_t cap);

/* A new options database for one solver: the plugin's defaults for this
 * class, then the process-wide PETSc options (PETSC_OPTIONS, ~/.petscrc),
 * then the user's string, later entries overriding earlier ones.  Local to
 * this process (no communication). */
int psc_options_create(silc_call *call, const char *user, int spd, PetscOptions *out);

/* -help in the user's string: PETSc's help for the KSP/PC configuration it
 * makes (every block, whatever was printed before in the process), on
 * standard output on rank 0.  Collective over A's communicator comm. */
int psc_options_print_help(silc_call *call, MPI_Comm comm, const char *user, int spd, Mat A);

/* After the first solve: SILC_OK when PETSc read every option of the user's
 * string, else an error naming the first one it ignored, with a suggestion
 * found among the option names the same KSP/PC configuration understands.
 * A, the solver's matrix on comm, lets that configuration be rebuilt.
 * Collective over comm (PETSC_COMM_SELF for a sequential solve): every rank
 * returns the same answer. */
int psc_options_check_used(silc_call *call, MPI_Comm comm, PetscOptions opts, const char *user,
                           int spd, Mat A);

#endif
