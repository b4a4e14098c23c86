#!/bin/sh
# test_exports.sh -- libsilc.so exports exactly the functions its headers
# (silc.h, silc_comm.h for transports such as libsilc_mpi) declare with SILC_API: the engine's internals (val_*, host_api, ref_*, ...) are
# hidden, so they cannot clash with a program's own names, and nothing
# public was hidden by mistake.
#
#     test_exports.sh LIBSILC.so silc.h [more headers...]
set -eu
lib=$1
shift
tmp=${TMPDIR:-/tmp}/silc-exports.$$
trap 'rm -f "$tmp".*' EXIT
nm -D --defined-only "$lib" | awk '$2 ~ /^[TtWw]$/ {print $3}' | sort -u >"$tmp.exported"
sed -n 's/^SILC_API[^(]*[ *]\([A-Za-z_][A-Za-z_0-9]*\)(.*/\1/p' "$@" | sort -u >"$tmp.declared"
if [ ! -s "$tmp.declared" ]; then
    echo "FAIL: no SILC_API declarations found in $*"
    exit 1
fi
if ! diff -u "$tmp.declared" "$tmp.exported"; then
    echo "FAIL: exported functions (+) differ from the headers' SILC_API declarations (-)"
    exit 1
fi
echo "$(wc -l <"$tmp.declared") functions exported, as declared; 1 passed, 0 failed"
