#!/bin/sh
# test_mpi_faults.sh -- a rank of `mpirun -np 2 silcd --mpi` killed under a
# live session: the client's next request fails with an error within
# seconds (never hangs), the job ends, and the server's log names the rank
# that died (Open MPI's report).  Bounded by timeouts throughout.
#
#     sh tests/test_mpi_faults.sh MPIRUN SILCD SILC_CLI STATEDIR
set -u
MPIRUN=$1 SILCD=$2 CLI=$3 DIR=$4
mkdir -p "$DIR"
sock=/tmp/silcd-mpi-faults-$$.sock
rm -f "$DIR/ready"
$MPIRUN -np 2 "$SILCD" --mpi --listen "unix:$sock" --ready-file "$DIR/ready" --log-level warn \
    >"$DIR/silcd.log" 2>&1 </dev/null &
launcher=$!
i=0
while [ ! -f "$DIR/ready" ]; do
    i=$((i + 1))
    if [ $i -gt 200 ]; then echo "FAIL: silcd --mpi did not start"; cat "$DIR/silcd.log"; kill $launcher; exit 1; fi
    sleep 0.1
done
fail=0
# The rank-1 process: the silcd whose environment says so.
victim=""
for p in $(pgrep -f "$SILCD --mpi --listen unix:$sock"); do
    if tr '\0' '\n' <"/proc/$p/environ" 2>/dev/null | grep -qx 'OMPI_COMM_WORLD_RANK=1'; then victim=$p; fi
done
if [ -z "$victim" ]; then echo "FAIL: no rank-1 silcd process found"; kill $launcher; exit 1; fi
# A session that works, then the rank dies, then the session's next request.
out=$( (echo 'A = eye(3); x = A \ ones(3,1)'; sleep 1; kill -KILL "$victim"; sleep 2;
        echo 'y = 2 * ones(3,1)') | SILC_SERVER=unix:$sock timeout 30 "$CLI" 2>&1)
rc=$?
if [ $rc -eq 124 ]; then echo "FAIL: the client hung after rank 1 died"; fail=$((fail + 1));
elif [ $rc -eq 0 ]; then echo "FAIL: the request after rank 1 died succeeded:"; echo "$out"; fail=$((fail + 1));
else echo "client after the rank died (exit $rc): $(echo "$out" | tail -1)"; fi
# The job ends: mpirun does not keep rank 0 serving a broken communicator.
i=0
while kill -0 $launcher 2>/dev/null; do
    i=$((i + 1))
    if [ $i -gt 300 ]; then echo "FAIL: the job did not end within 30 s"; kill -KILL $launcher; fail=$((fail + 1)); break; fi
    sleep 0.1
done
if ! grep -q "rank 1" "$DIR/silcd.log"; then
    echo "FAIL: the server's log does not name rank 1:"; cat "$DIR/silcd.log"; fail=$((fail + 1))
fi
rm -f "$sock"
echo "$((3 - fail)) passed, $fail failed"
[ $fail -eq 0 ]
