#!/bin/sh
# test_progress.sh -- long work's progress line (tools/progress.h), seen on
# the cloth program: on a terminal (a pseudo-terminal from script(1)) it
# redraws "cloth: step k of N" on stderr and erases it at the end; with
# stderr a file there is no trace of it.
#
#     sh tests/test_progress.sh path/to/cloth SCENE
set -u
CLOTH=$1 SCENE=$2
DIR=$(mktemp -d /tmp/silc-progress.XXXXXX) || exit 1
trap 'rm -rf "$DIR"' EXIT
"$CLOTH" "$SCENE" --steps 300 >"$DIR/out" 2>"$DIR/err" || { cat "$DIR/err"; exit 1; }
[ ! -s "$DIR/err" ] || { echo "FAIL: progress written to a file:"; cat "$DIR/err"; exit 1; }
command -v script >/dev/null || { echo "test_progress: no script(1): the terminal case skipped"; exit 0; }
script -qc "'$CLOTH' '$SCENE' --steps 300" /dev/null >"$DIR/tty" 2>&1 </dev/null || { cat "$DIR/tty"; exit 1; }
grep -q "$(printf '\rcloth: step ')" "$DIR/tty" || { echo "FAIL: no progress line on a terminal"; exit 1; }
grep -q "$(printf '\r\033\\[K')" "$DIR/tty" || { echo "FAIL: the progress line is not erased"; exit 1; }
echo "test_progress: a progress line on a terminal, none in a file"
