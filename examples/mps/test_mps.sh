#!/bin/sh
# test_mps.sh -- the MPS example's CTest checks, each against its own silcd
# (started here on a Unix socket in a fresh directory, killed on exit, also
# on failure):
#
#   test_mps.sh SILCD CLASSPATH SRC_DIR RUN_DIR model
#       the model's unit test (mps.ModelTest), silcd with the built-in dispatch;
#   test_mps.sh SILCD CLASSPATH SRC_DIR RUN_DIR dambreak CONFIG PLUGIN
#       the default scene to T = 2.8 with silcd --config SRC_DIR/configs/CONFIG.conf:
#       `info x` must name the configured backend, the front must match
#       Martin & Moyce (mps.FrontCheck: a lead of at most 0.35 in T at every
#       measured point, Koshizuka & Oka's MPS curve shown alongside); the
#       curve goes to RUN_DIR/CONFIG.csv.
#       PLUGIN "none" (not built) or, for PETSc, no hypre: skipped (77);
#   test_mps.sh SILCD CLASSPATH SRC_DIR RUN_DIR agree
#       the curves in RUN_DIR agree with each other (and with the experiment);
#       their picture goes to RUN_DIR/front.svg.
set -u
SILCD=$1 CP=$2 SRC=$3 RUNS=$4 MODE=$5
DATA=$SRC/data/martin_moyce_1952_n2.dat
KO=$SRC/data/koshizuka_oka_1996_mps.dat
export OPENBLAS_NUM_THREADS=1 OMP_NUM_THREADS=1
unset SILC_SERVER SILC_CONFIG
. "$(dirname "$0")/../../tools/silcd_run.sh"
DIR=$SILCD_DIR

case $MODE in
model)
  silcd_start "$SILCD"
  java -cp "$CP" mps.ModelTest "$SILCD_URL"
  ;;
dambreak)
  CONFIG=$6 PLUGIN=$7
  mkdir -p "$RUNS" && rm -f "$RUNS/$CONFIG.csv"
  if [ "$PLUGIN" = none ]; then
    echo "test_mps: SKIPPED: the plugin $CONFIG.conf needs is not built"; exit 77
  fi
  case $CONFIG in
    iccg) WANT=lis-style ;;
    cholmod) WANT=suitesparse.cholmod ;;
    petsc-amg) WANT=petsc ;;
    *) echo "test_mps: unknown config $CONFIG"; exit 2 ;;
  esac
  silcd_start "$SILCD" --config "$SRC/configs/$CONFIG.conf"
  java -cp "$CP" mps.DamBreak --server "$SILCD_URL" --time 2.8 --csv "$DIR/$CONFIG.csv" \
    >"$DIR/out" 2>"$DIR/err"
  rc=$?
  cat "$DIR/out" "$DIR/err"
  if [ $rc -ne 0 ]; then
    if [ "$CONFIG" = petsc-amg ] && grep -qi hypre "$DIR/err"; then
      echo "test_mps: SKIPPED: this PETSc has no hypre (BoomerAMG)"; exit 77
    fi
    exit 1
  fi
  # The config must be what solved: info x names its backend, and explain
  # says the backend list came from the config (CHOLMOD is also the built-in
  # default, so only the second tells an ignored cholmod.conf).
  if ! grep -q "backend=$WANT\$" "$DIR/out"; then
    echo "test_mps: FAIL: $CONFIG.conf names $WANT, but info x reports another backend"; exit 1
  fi
  if ! grep -q "backends (config key dispatch.solve.sparse.spd): $WANT" "$DIR/out"; then
    echo "test_mps: FAIL: explain does not show $CONFIG.conf's backend list"; exit 1
  fi
  java -cp "$CP" mps.FrontCheck --ko "$KO" "$DATA" "$DIR/$CONFIG.csv" || exit 1
  cp "$DIR/$CONFIG.csv" "$RUNS/$CONFIG.csv"
  ;;
agree)
  set -- "$RUNS"/*.csv
  if [ $# -lt 2 ] || [ ! -f "$1" ]; then
    echo "test_mps: FAIL: fewer than two backend runs in $RUNS to compare"; exit 1
  fi
  echo "comparing: $*"
  java -cp "$CP" mps.FrontCheck --ko "$KO" --svg "$RUNS/front.svg" "$DATA" "$@"
  ;;
*)
  echo "test_mps: unknown mode $MODE"; exit 2
  ;;
esac
