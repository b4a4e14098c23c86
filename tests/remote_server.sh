#!/bin/sh
# remote_server.sh -- starts or stops the silcd that the remote variants of the
# test suite talk to (a ctest fixture: tests/remote.cmake).
#
#     sh tests/remote_server.sh start SILCD SOCKET STATEDIR [EXTRA SILCD ARGS...]
#     sh tests/remote_server.sh stop  SILCD SOCKET STATEDIR
#
# With SILC_LAUNCH set (e.g. "mpirun -np 2"), silcd starts under it, for
# silcd --mpi (then pass --mpi among the extra arguments); stop signals the
# launcher, which forwards SIGTERM to the ranks.
#
# start waits until the server listens (its --ready-file appears) and fails if
# it does not within 20 s; stop sends SIGTERM, waits for a clean exit and fails
# if the server died earlier or shuts down with an error.
set -u
cmd=${1:?usage: remote_server.sh start|stop SILCD SOCKET STATEDIR}
SILCD=$2
SOCK=$3
DIR=$4
shift 4
mkdir -p "$DIR"
case $cmd in
start)
    if [ -f "$DIR/silcd.pid" ] && kill -0 "$(cat "$DIR/silcd.pid")" 2>/dev/null; then
        kill "$(cat "$DIR/silcd.pid")" 2>/dev/null
        sleep 1
    fi
    rm -f "$DIR/ready" "$DIR/silcd.pid"
    # shellcheck disable=SC2086 # SILC_LAUNCH is a command with its arguments
    ${SILC_LAUNCH:-} "$SILCD" --listen "unix:$SOCK" --ready-file "$DIR/ready" --io-timeout 10 \
        --log-level warn "$@" >"$DIR/silcd.log" 2>&1 </dev/null &
    echo $! >"$DIR/silcd.pid"
    i=0
    while [ ! -f "$DIR/ready" ]; do
        i=$((i + 1))
        if [ $i -gt 200 ] || ! kill -0 "$(cat "$DIR/silcd.pid")" 2>/dev/null; then
            echo "silcd did not start:" >&2
            cat "$DIR/silcd.log" >&2
            exit 1
        fi
        sleep 0.1
    done
    echo "silcd $(cat "$DIR/silcd.pid") listening on $(cat "$DIR/ready")"
    ;;
stop)
    pid=$(cat "$DIR/silcd.pid" 2>/dev/null) || { echo "no silcd.pid" >&2; exit 1; }
    if ! kill -0 "$pid" 2>/dev/null; then
        echo "silcd $pid died during the tests:" >&2
        cat "$DIR/silcd.log" >&2
        exit 1
    fi
    kill -TERM "$pid"
    i=0
    while kill -0 "$pid" 2>/dev/null; do
        i=$((i + 1))
        if [ $i -gt 300 ]; then
            echo "silcd $pid did not stop within 30 s of SIGTERM" >&2
            kill -KILL "$pid"
            exit 1
        fi
        sleep 0.1
    done
    rm -f "$DIR/silcd.pid"
    if [ -e "$SOCK" ]; then
        echo "silcd left its socket $SOCK behind" >&2
        exit 1
    fi
    echo "silcd stopped cleanly"
    ;;
*)
    echo "usage: remote_server.sh start|stop SILCD SOCKET STATEDIR" >&2
    exit 2
    ;;
esac
