#!/usr/bin/env bash
# cloth.sh -- the cloth bench (bench/cloth.c) on the hanging and large scenes,
# embedded and through a silcd started here on a Unix socket, in one run, so
# every ratio to original has its baseline from the same run
# (docs/cloth.md records the tables with this command).
#
#     bench/cloth.sh [BUILD_DIR] [STEPS] [ROUNDS]     (build, 50, 3)
set -u
cd "$(dirname "$0")/.." || exit 1
BUILD=${1:-build}
STEPS=${2:-50}
ROUNDS=${3:-3}
BENCH=$BUILD/bench/cloth_bench
SILCD=$BUILD/server/silcd
for f in "$BENCH" "$SILCD"; do
  [ -x "$f" ] || { echo "cloth.sh: $f not built (cmake --build $BUILD)" >&2; exit 1; }
done
export OPENBLAS_NUM_THREADS=1 OMP_NUM_THREADS=1
unset SILC_SERVER
SCENES=(examples/cloth/scenes/hanging.scene examples/cloth/scenes/large.scene)
echo "cloth bench, $(date +%F), $(getconf _NPROCESSORS_ONLN) cores: bench/cloth.sh $BUILD $STEPS $ROUNDS"
echo
"$BENCH" "${SCENES[@]}" --steps "$STEPS" --rounds "$ROUNDS" --label embedded || exit 1
DIR=$(mktemp -d /tmp/silc-cloth-bench.XXXXXX)
"$SILCD" --listen "unix:$DIR/s.sock" --ready-file "$DIR/ready" --log-level error 2>"$DIR/silcd.log" &
PID=$!
for _ in $(seq 100); do [ -f "$DIR/ready" ] && break; sleep 0.1; done
echo
SILC_SERVER="unix:$DIR/s.sock" "$BENCH" "${SCENES[@]}" --steps "$STEPS" --rounds "$ROUNDS" --label silcd
rc=$?
kill -TERM "$PID" 2>/dev/null
wait "$PID" 2>/dev/null
rm -rf "$DIR"
exit $rc
