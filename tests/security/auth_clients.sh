#!/bin/sh
# auth_clients.sh -- every client presents the token over TCP: silcd listens
# on 127.0.0.1 (kernel-chosen port) with a token that `silcd --make-token`
# wrote; the C client (the silc command), the Python client and the Fortran
# binding (through the C library) read it from SILC_TOKEN_FILE or
# SILC_TOKEN, and a wrong token is refused with the server's message.  (The
# Java client's token cases are tests/java/test_java.sh's.)
#
#     sh tests/security/auth_clients.sh SILCD SILC_CLI PYTHON PYBINDINGS [FORTRAN_EXAMPLE]
# PYTHON or FORTRAN_EXAMPLE may be "none" (not built here).
set -u
SILCD=$1 CLI=$2 PY=$3 PYDIR=$4 FEX=${5:-none}
. "$(dirname "$0")/../../tools/silcd_run.sh"
fail=0
check() {   # check WHAT COMMAND...: the command must succeed
    what=$1
    shift
    if out=$("$@" 2>&1); then echo "ok: $what"; else echo "FAIL: $what:"; echo "$out"; fail=$((fail + 1)); fi
}
refused() {   # refused WHAT COMMAND...: the command must fail naming the wrong token
    what=$1
    shift
    out=$("$@" 2>&1)
    case $out in
    *"authentication failed: wrong token"*) echo "ok: $what" ;;
    *) echo "FAIL: $what: not refused with 'authentication failed: wrong token':"; echo "$out"; fail=$((fail + 1)) ;;
    esac
}
says() {   # says WHAT TEXT COMMAND...: the command must fail printing TEXT
    what=$1 text=$2
    shift 2
    if out=$("$@" 2>&1); then echo "FAIL: $what: succeeded"; fail=$((fail + 1)); return; fi
    case $out in
    *"$text"*) echo "ok: $what" ;;
    *) echo "FAIL: $what: no '$text':"; echo "$out"; fail=$((fail + 1)) ;;
    esac
}
tok=$SILCD_DIR/token
# A token file that is not a regular file (a FIFO with no writer hung every
# client; /dev/zero read as an empty token in C, filled Python's and Java's
# memory): refused at once, naming it.  `timeout` turns a hang into a failure.
fifo=$SILCD_DIR/token-fifo
mkfifo "$fifo"
"$SILCD" --make-token "$tok" >/dev/null || { echo "FAIL: silcd --make-token"; exit 1; }
SILCD_LISTEN=tcp://127.0.0.1:0 silcd_start "$SILCD" --token-file "$tok"
export SILC_SERVER="$SILCD_URL"
unset SILC_TOKEN SILC_TOKEN_FILE
wrong=0000000000000000000000000000000000

# C: the silc command, through libsilc's SILC_TOKEN_FILE / SILC_TOKEN.
out=$(SILC_TOKEN_FILE=$tok timeout 60 "$CLI" -e 'x = 2 * 3' --get x 2>&1)
if [ "$(echo "$out" | tail -n 1)" = 6 ]; then echo "ok: C client with SILC_TOKEN_FILE"
else echo "FAIL: C client with SILC_TOKEN_FILE: $out"; fail=$((fail + 1)); fi
check "C client with SILC_TOKEN" env SILC_TOKEN="$(head -n 1 "$tok")" timeout 60 "$CLI" -e 'x = 1'
refused "C client with a wrong SILC_TOKEN" env SILC_TOKEN=$wrong timeout 60 "$CLI" -e 'x = 1'
for f in "$fifo" /dev/zero; do
    says "C client with SILC_TOKEN_FILE=$f" "SILC_TOKEN_FILE '$f' is not a regular file" \
        env SILC_TOKEN_FILE="$f" timeout 10 "$CLI" -e 'x = 1'
done

# Python: its own protocol implementation, the same variables.
if [ "$PY" != none ]; then
    pycode='import sys
sys.path.insert(0, sys.argv[1])
import numpy, silc
with silc.Session() as s:
    s.exec("x = 2 * 3")
    v = numpy.asarray(s.get("x")).ravel()[0]
    assert v == 6, v'
    check "Python client with SILC_TOKEN_FILE" env SILC_TOKEN_FILE="$tok" timeout 60 "$PY" -c "$pycode" "$PYDIR"
    check "Python client with SILC_TOKEN" env SILC_TOKEN="$(head -n 1 "$tok")" timeout 60 "$PY" -c "$pycode" "$PYDIR"
    refused "Python client with a wrong SILC_TOKEN" env SILC_TOKEN=$wrong timeout 60 "$PY" -c "$pycode" "$PYDIR"
    for f in "$fifo" /dev/zero; do
        says "Python client with SILC_TOKEN_FILE=$f" "SILC_TOKEN_FILE '$f' is not a regular file" \
            env SILC_TOKEN_FILE="$f" timeout 10 "$PY" -c "$pycode" "$PYDIR"
    done
fi

# Fortran, through the C library: the diffusion example exits 1 if its
# error exceeds the scheme's bound, so a run that finishes computed right.
if [ "$FEX" != none ]; then
    check "Fortran example with SILC_TOKEN_FILE" env SILC_TOKEN_FILE="$tok" timeout 120 "$FEX" 50 100 0.5
    refused "Fortran example with a wrong SILC_TOKEN" env SILC_TOKEN=$wrong timeout 120 "$FEX" 50 100 0.5
fi
[ $fail -eq 0 ] && echo "all clients passed" || echo "$fail case(s) failed"
exit $fail
