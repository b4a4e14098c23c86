#!/bin/sh
# run.sh -- test_octave: SILC runs suite.m (silc run, values shown as the
# silc command shows them) and must print exactly what Octave printed for it
# (suite.octave-truth.txt, made by gen.sh).  Usage: run.sh SILC_BINARY
set -u
silc=$1
here=$(cd "$(dirname "$0")" && pwd)
out=${TMPDIR:-/tmp}/silc-octave.$$
trap 'rm -f "$out"' EXIT
if ! "$silc" run "$here/suite.m" > "$out" 2>&1; then
    echo "silc run suite.m failed:"; cat "$out"; exit 1
fi
if ! diff -u "$here/suite.octave-truth.txt" "$out"; then
    echo "FAIL: SILC's output differs from Octave's (- Octave, + SILC)"; exit 1
fi
echo "ok: $(grep -c . "$here/suite.octave-truth.txt") lines as Octave prints them"
