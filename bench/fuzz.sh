#!/bin/sh
# fuzz.sh -- runs the libFuzzer builds of the fuzzers longer than the test
# suite does (its fuzz_*_libfuzzer tests stop after 20000 inputs), one after
# the other, and prints for each how many inputs ran and what it found.
#
#     bench/fuzz.sh [SECONDS] [BUILD_DIR] [HARNESS...]
#
# SECONDS per harness (default 600); BUILD_DIR (default build) must have been
# configured where clang builds libFuzzer targets (tests/fuzz.cmake says
# when); HARNESS is any of lang config frame (default all three).  Each run
# uses FUZZ_JOBS jobs on as many workers (default 2: this box has 2 cores),
# starts from the committed seeds and adds what it finds to a scratch corpus under
# BUILD_DIR/tests/fuzz-long-HARNESS, which the next run starts from too.
# Crashes, leaks and timeouts land as crash-*, leak-*, timeout-* files in
# BUILD_DIR/tests/fuzz-findings-HARNESS: reproduce one with
#     BUILD_DIR/tests/fuzz_HARNESS_libfuzzer FILE
# Exits 1 when any harness found something.
set -u
secs=${1:-600}
build=${2:-build}
shift 2 2>/dev/null || shift $#
harnesses=${*:-lang config frame}
src=$(cd "$(dirname "$0")/.." && pwd)
tests=$(cd "$build/tests" && pwd) || exit 2
export OPENBLAS_NUM_THREADS=1 OMP_NUM_THREADS=1
jobs=${FUZZ_JOBS:-2}
status=0
for h in $harnesses; do
    bin=$tests/fuzz_${h}_libfuzzer
    if [ ! -x "$bin" ]; then
        echo "fuzz.sh: $bin is not built (cmake --build $build --target fuzz_${h}_libfuzzer)" >&2
        status=1
        continue
    fi
    case $h in
        lang) seeds=$src/tests/fuzz/corpus-lang; extra="-max_len=4096 -dict=$src/tests/fuzz/lang.dict" ;;
        config) seeds=$src/tests/fuzz/corpus-config; extra="-max_len=1024" ;;
        frame) seeds=$src/tests/fuzz/corpus; extra="-max_len=4096" ;;
        *) echo "fuzz.sh: unknown harness '$h' (lang, config, frame)" >&2; status=1; continue ;;
    esac
    corpus=$tests/fuzz-long-$h
    found=$tests/fuzz-findings-$h
    mkdir -p "$corpus" "$found"
    log=$found/run-$(date +%Y%m%d-%H%M%S).log
    echo "== $h: $secs s, corpus $corpus, findings $found"
    # -jobs/-workers: fuzzing processes sharing the corpus, one per core;
    # each job runs for max_total_time.  Their logs go to fuzz-N.log in the
    # current directory, so run from the findings directory.
    (cd "$found" && "$bin" -max_total_time="$secs" -timeout=10 -rss_limit_mb=2048 \
        -jobs="$jobs" -workers="$jobs" -print_final_stats=1 -artifact_prefix="$found/" $extra \
        "$corpus" "$seeds" >"$log" 2>&1)
    rm -f "$found"/fuzz-*.log     # the parent has copied each job's log into its own
    runs=$(grep -h '^stat::number_of_executed_units' "$log" | awk '{s += $2} END {print s + 0}')
    cov=$(grep -h ' DONE \| cov: ' "$log" | tail -1 | sed -n 's/.*cov: \([0-9]*\).*/\1/p')
    n=$(ls "$found" | grep -c '^\(crash\|leak\|timeout\|oom\|slow-unit\)-')
    echo "   $runs inputs executed, coverage ${cov:-?} edges, corpus $(ls "$corpus" | wc -l) files, $n findings"
    if [ "$n" -gt 0 ]; then
        ls "$found" | grep '^\(crash\|leak\|timeout\|oom\|slow-unit\)-' | sed 's/^/   /'
        grep -h 'ERROR: \|SUMMARY: \|invariant broken' "$log" | sort | uniq -c | head -20
        status=1
    fi
done
exit $status
