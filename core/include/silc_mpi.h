/*
 * silc_mpi.h -- SILC in MPI programs: one engine per rank over the program's
 * communicator (SPMD mode).  Link with libsilc_mpi and libsilc.
 *
 *     MPI_Init(&argc, &argv);
 *     silc_open_mpi(&ctx, MPI_COMM_WORLD, NULL);     (or SILC_MODE=spmd SILC_INIT())
 *     silc_put_rows(ctx, "A", first_row, &my_rows);  each rank its own rows
 *     silc_put_rows(ctx, "b", first_row, &my_b);
 *     silc_exec(ctx, "x = A \\ b");                  collective
 *     silc_get_rows(ctx, &my_x, &first, "x");         each rank its rows back
 *                          (silc_get_rows_complex for a complex x: interleaved)
 *     silc_close(&ctx);
 *     MPI_Finalize();
 *
 * The context is an ordinary silc_context: every call of silc.h works on it
 * and is collective (silc.h, "MPI programs").  The communicator is
 * duplicated, so SILC's messages never mix with the program's.  MPI must be
 * initialised before and finalised after.
 */
#ifndef SILC_MPI_H
#define SILC_MPI_H

#include <mpi.h>

#include "silc.h"

#ifdef __cplusplus
extern "C" {
#endif

SILC_API int silc_open_mpi(silc_context **out, MPI_Comm comm, const char *config_path);
/* The table of MPI collectives on a duplicate of comm (silc_comm.h), for
 * silcd --mpi; NULL with msg set on failure. */
struct silc_comm_ops;
SILC_API struct silc_comm_ops *silc_mpi_comm_ops(MPI_Comm comm, char *msg, size_t msglen);

#ifdef __cplusplus
}
#endif
#endif /* SILC_MPI_H */
