#!/bin/sh
# test_plugin_mumps_symbols.sh -- the mumps plugin keeps MUMPS and its stub MPI to itself.
#
# Debian's sequential MUMPS carries a stub MPI and exports the same dmumps_c as
# the MPI MUMPS that PETSc loads.  The plugin links both into itself hidden
# (plugin-mumps/CMakeLists.txt); this checks that it worked:
#   1. the module exports exactly one symbol, silc_plugin_init;
#   2. it imports no MUMPS, PORD or MPI symbol and needs no MUMPS or MPI
#      shared library, so nothing can bind it to another copy;
#   3. with the MPI MUMPS (and, separately, the shared sequential MUMPS)
#      preloaded into the global scope ahead of it -- the worst load order --
#      a solve through mumps still runs on the plugin's own copy: were it bound
#      to the preloaded dmumps_c, the MPI build would fail without MPI_Init.
#      The reverse order (the plugin first, another MUMPS after it, RTLD_LOCAL)
#      cannot interfere because of 1.
#
# usage: test_plugin_mumps_symbols.sh PLUGIN.so [SILC_CLI MATRIX.mtx]
# Step 3 runs when the silc CLI and a Matrix Market file are given and the
# libraries to preload are installed.
set -u
so=${1:?usage: $0 PLUGIN.so [SILC_CLI MATRIX.mtx]}
cli=${2:-}
mtx=${3:-}
passed=0
failed=0
ok() { passed=$((passed + 1)); }
fail() { failed=$((failed + 1)); echo "FAIL: $*" >&2; }

defined=$(nm -D --defined-only "$so" | awk '{print $NF}')
if [ "$defined" = "silc_plugin_init" ]; then ok; else fail "exported symbols of $so: $defined"; fi

leaked=$(nm -D --undefined-only "$so" | awk '{print $NF}' | grep -i -E '^(d|s|c|z)?mumps|^pord|^mpi_|^MPI_' || true)
if [ -z "$leaked" ]; then ok; else fail "imports MUMPS/MPI symbols: $leaked"; fi

needed=$(readelf -d "$so" | grep NEEDED | grep -E 'lib[sdcz]?mumps|mumps_common|pord|mpiseq|libmpi' || true)
if [ -z "$needed" ]; then ok; else fail "needs MUMPS/MPI libraries: $needed"; fi

if [ -n "$cli" ] && [ -n "$mtx" ] && [ -x "$cli" ] && [ -r "$mtx" ]; then
    libdir=/usr/lib/x86_64-linux-gnu
    [ -d "$libdir" ] || libdir=/usr/lib
    # An ASan-built CLI wants its runtime first; preloading ahead of it is the point here.
    ASAN_OPTIONS="${ASAN_OPTIONS:+$ASAN_OPTIONS:}verify_asan_link_order=0:detect_leaks=0"
    export ASAN_OPTIONS
    stmts='b = A * ones(cols(A), 1); x = solve(A, b, "backend = mumps"); r = norm(b - A * x) / norm(b); info x; r'
    for pre in "" "$libdir/libdmumps.so" "$libdir/libmpiseq_seq.so $libdir/libdmumps_seq.so"; do
        missing=
        for f in $pre; do [ -r "$f" ] || missing=$f; done
        if [ -n "$missing" ]; then
            echo "skip: $missing not installed"
            continue
        fi
        out=$(LD_PRELOAD="$pre" "$cli" --put A="$mtx" -e "$stmts" 2>&1)
        if [ $? -eq 0 ] && printf '%s\n' "$out" | grep -q 'backend: mumps'; then
            ok
        else
            fail "solve through mumps with LD_PRELOAD='$pre':
$out"
        fi
    done
fi

echo "$passed passed, $failed failed"
[ "$failed" -eq 0 ]
