#!/usr/bin/env bash
# mps.sh -- the MPS dam-break bench (examples/mps): for each backend config
# in examples/mps/configs, a silcd started here with that config, and the
# default and --large scenes run for a bounded number of steps through it.
# Prints one markdown table per config: the time of a step split into
# Java-side work (neighbours, PPE assembly, particle update), transfer
# (PUT A, PUT b, GET x) and solve (EXEC "x = A \ b"), and the pressure
# solve's share of the step (docs/mps.md records the tables with this command).
#
#     bench/mps.sh [BUILD_DIR] [STEPS] [LARGE_STEPS]     (build, 300, 60)
set -u
cd "$(dirname "$0")/.." || exit 1
BUILD=${1:-build}
STEPS=${2:-300}
LARGE_STEPS=${3:-60}
SILCD=$BUILD/server/silcd
CP=$BUILD/bindings/java/silc.jar:$BUILD/examples/mps/mps.jar
for f in "$SILCD" "$BUILD/bindings/java/silc.jar" "$BUILD/examples/mps/mps.jar"; do
  [ -e "$f" ] || { echo "mps.sh: $f not built (cmake --build $BUILD)" >&2; exit 1; }
done
export OPENBLAS_NUM_THREADS=1 OMP_NUM_THREADS=1
unset SILC_SERVER SILC_CONFIG
. tools/silcd_run.sh

# field NAME LINE: the value of NAME=... in a summary line.
field() { sed -n "s/.*[ ]$1=\([^ ]*\).*/\1/p" <<<"$2"; }

echo "MPS dam-break bench, $(date +%F), $(getconf _NPROCESSORS_ONLN) cores," \
  "$(java -version 2>&1 | head -1): bench/mps.sh $BUILD $STEPS $LARGE_STEPS"
rc=0
for conf in examples/mps/configs/*.conf; do
  name=$(basename "$conf" .conf)
  silcd_start "$SILCD" --config "$conf"
  echo
  echo "config \`$conf\`:"
  echo
  echo "| scene | particles (fluid) | unknowns | steps | step ms | Java ms | transfer ms | solve ms | solve share | solve + transfer share | backend (info x) |"
  echo "| --- | ---: | ---: | ---: | ---: | ---: | ---: | ---: | ---: | ---: | --- |"
  for scene in default large; do
    if [ $scene = large ]; then args=(--large --steps "$LARGE_STEPS"); else args=(--steps "$STEPS"); fi
    if ! out=$(java -cp "$CP" mps.DamBreak --server "$SILCD_URL" "${args[@]}" 2>&1); then
      echo "| $scene | failed: $(tail -1 <<<"$out") |"
      rc=1
      continue
    fi
    s=$(grep '^summary:' <<<"$out")
    head=$(grep '^mps:' <<<"$out")
    parts=$(sed -n 's/.*, \([0-9]*\) fluid of \([0-9]*\) particles.*/\2 (\1)/p' <<<"$head")
    unknowns=$(sed -n 's/.*, \([0-9]*\) unknowns per solve.*/\1/p' <<<"$head")
    solver=$(sed -n 's/.*solved by \(.*\)$/\1/p' <<<"$head")
    echo "| $scene | $parts | $unknowns | $(field steps "$s") | $(field step_ms "$s") | $(field java_ms "$s")" \
      "| $(field transfer_ms "$s") | $(field solve_ms "$s") | $(field solve_share "$s")" \
      "| $(field pressure_share "$s") | $solver |"
  done
  silcd_stop
done
exit $rc
