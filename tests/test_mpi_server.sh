#!/bin/sh
# test_mpi_server.sh -- test_mpi.c's checks as a client of `mpirun -np NP
# silcd --mpi` (tests/mpi.cmake): starts the server with remote_server.sh
# (values of 100 rows or more split among the ranks), runs the client,
# stops the server, and fails if either failed.
#
#     sh tests/test_mpi_server.sh MPIRUN NP SILCD TEST_MPI_CLIENT STATEDIR
set -u
MPIRUN=$1 NP=$2 SILCD=$3 CLIENT=$4 DIR=$5
here=$(dirname "$0")
sock=/tmp/silcd-mpi-np$NP-$$.sock
SILC_LAUNCH="$MPIRUN -np $NP" sh "$here/remote_server.sh" start "$SILCD" "$sock" "$DIR" --mpi \
    --dist-min-rows 100 || exit 1
SILC_SERVER=unix:$sock "$CLIENT" server
rc=$?
sh "$here/remote_server.sh" stop "$SILCD" "$sock" "$DIR" || rc=1
exit $rc
