#!/usr/bin/env bash
# cloth.sh -- the cloth bench (bench/cloth.c) on the hanging and large scenes,
# embedded and through a silcd started here on a Unix socket, in one run, so
# every ratio to original has its baseline from the same run
# (docs/cloth.md records the tables with this command).  With
# --seed-statements first: the cmp mode's statements against the plain-C
# step (cloth_c_step.c, issue 30 item 1) instead of the three drivers.
#
#     bench/cloth.sh [--seed-statements] [BUILD_DIR] [STEPS] [ROUNDS]     (build, 50, 3; 5 with --seed-statements)
set -u
cd "$(dirname "$0")/.." || exit 1
MODE=()
if [ "${1:-}" = --seed-statements ]; then
  MODE=(--seed-statements)
  shift
fi
BUILD=${1:-build}
STEPS=${2:-50}
ROUNDS=${3:-$([ ${#MODE[@]} -gt 0 ] && echo 5 || echo 3)}
BENCH=$BUILD/bench/cloth_bench
SILCD=$BUILD/server/silcd
for f in "$BENCH" "$SILCD"; do
  [ -x "$f" ] || { echo "cloth.sh: $f not built (cmake --build $BUILD)" >&2; exit 1; }
done
export OPENBLAS_NUM_THREADS=1 OMP_NUM_THREADS=1
unset SILC_SERVER
SCENES=(examples/cloth/scenes/hanging.scene examples/cloth/scenes/large.scene)
echo "cloth bench, $(date +%F), $(getconf _NPROCESSORS_ONLN) cores: bench/cloth.sh ${MODE[*]:-}${MODE[*]:+ }$BUILD $STEPS $ROUNDS"
echo
"$BENCH" "${SCENES[@]}" "${MODE[@]}" --steps "$STEPS" --rounds "$ROUNDS" --label embedded || exit 1
. tools/silcd_run.sh
silcd_start "$SILCD"
echo
SILC_SERVER="$SILCD_URL" CLOTH_BENCH_SERVER_PID="$SILCD_PID" "$BENCH" "${SCENES[@]}" "${MODE[@]}" --steps "$STEPS" --rounds "$ROUNDS" --label silcd
