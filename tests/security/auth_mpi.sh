#!/bin/sh
# auth_mpi.sh -- the authentication rules under `mpirun -np 2 silcd --mpi`:
# TCP without a token is refused on every rank (the job ends with the
# message); with a token from `silcd --make-token`, a client presenting it
# computes, a wrong token is refused, and wrong tokens sent faster than the
# backoff allows are refused unchecked (rank 0 serves every session from one
# process, so it cannot hold a connection back: it refuses it without
# comparing), after which the right token gets in again.  Bounded by
# timeouts throughout.
#
#     sh tests/security/auth_mpi.sh MPIRUN SILCD SILC_CLI STATEDIR
set -u
MPIRUN=$1 SILCD=$2 CLI=$3 DIR=$4
rm -rf "$DIR"
mkdir -p "$DIR"
fail=0
unset SILC_TOKEN SILC_TOKEN_FILE

# 1. No token on TCP: every rank refuses before MPI starts; the job ends.
timeout 120 $MPIRUN -np 2 "$SILCD" --mpi --listen tcp://127.0.0.1:0 >"$DIR/refused.log" 2>&1 </dev/null
rc=$?
if [ $rc -eq 0 ] || [ $rc -eq 124 ] ||
   ! grep -q "silcd: refusing to listen on tcp://127.0.0.1:0 without --token-file" "$DIR/refused.log"; then
    echo "FAIL: silcd --mpi on TCP without a token (exit $rc):"; cat "$DIR/refused.log"; fail=$((fail + 1))
else
    echo "ok: silcd --mpi on TCP without a token is refused (exit $rc)"
fi

# 2. With a token.
tok=$DIR/token
"$SILCD" --make-token "$tok" >/dev/null || { echo "FAIL: silcd --make-token"; exit 1; }
$MPIRUN -np 2 "$SILCD" --mpi --listen tcp://127.0.0.1:0 --token-file "$tok" --ready-file "$DIR/ready" \
    --log-level warn >"$DIR/silcd.log" 2>&1 </dev/null &
launcher=$!
i=0
while [ ! -s "$DIR/ready" ]; do
    i=$((i + 1))
    if [ $i -gt 300 ] || ! kill -0 $launcher 2>/dev/null; then
        echo "FAIL: silcd --mpi with a token did not start"; cat "$DIR/silcd.log"; kill $launcher 2>/dev/null; exit 1
    fi
    sleep 0.1
done
export SILC_SERVER="$(cat "$DIR/ready")"
out=$(SILC_TOKEN_FILE=$tok timeout 60 "$CLI" -e 'x = 2 * 3' --get x 2>&1)
if [ "$(echo "$out" | tail -n 1)" = 6 ]; then echo "ok: the right token computes on silcd --mpi"
else echo "FAIL: the right token on silcd --mpi: $out"; fail=$((fail + 1)); fi
wrong=0000000000000000000000000000000000
out=$(SILC_TOKEN=$wrong timeout 60 "$CLI" -e 'x = 1' 2>&1)
case $out in
*"authentication failed: wrong token"*) echo "ok: a wrong token is refused" ;;
*) echo "FAIL: a wrong token on silcd --mpi: $out"; fail=$((fail + 1)) ;;
esac
# Wrong tokens one after another: the window doubles with each failure, so
# within 10 attempts one comes inside it (unless each attempt took seconds).
unchecked=0
for _ in 1 2 3 4 5 6 7 8 9 10; do
    out=$(SILC_TOKEN=$wrong timeout 60 "$CLI" -e 'x = 1' 2>&1)
    case $out in
    *"authentication refused unchecked: too many failed attempts from 127.0.0.1; retry in "*)
        unchecked=1; break ;;
    *"authentication failed: wrong token"*) ;;
    *) echo "FAIL: a wrong token on silcd --mpi: $out"; fail=$((fail + 1)); break ;;
    esac
done
if [ $unchecked -eq 1 ]; then echo "ok: wrong tokens faster than the backoff are refused unchecked"
else echo "FAIL: 10 wrong tokens in a row were all compared"; fail=$((fail + 1)); fi
# The right token gets in once the window has passed (at most 10 s).
ok=0
for _ in $(seq 60); do
    if out=$(SILC_TOKEN_FILE=$tok timeout 60 "$CLI" -e 'x = 1' 2>&1); then ok=1; break; fi
    sleep 0.5
done
if [ $ok -eq 1 ]; then echo "ok: the right token gets in after the backoff"
else echo "FAIL: the right token after the backoff: $out"; fail=$((fail + 1)); fi

kill -TERM $launcher
i=0
while kill -0 $launcher 2>/dev/null; do
    i=$((i + 1))
    if [ $i -gt 300 ]; then echo "FAIL: silcd --mpi did not stop within 30 s"; kill -KILL $launcher; fail=$((fail + 1)); break; fi
    sleep 0.1
done
[ $fail -eq 0 ] && echo "all cases passed" || { echo "$fail case(s) failed"; cat "$DIR/silcd.log"; }
exit $fail
