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
#       Martin & Moyce (mps.FrontCheck); the curve goes to RUN_DIR/CONFIG.csv.
#       PLUGIN "none" (not built) or, for PETSc, no hypre: skipped (77);
#   test_mps.sh SILCD CLASSPATH SRC_DIR RUN_DIR agree
#       the curves in RUN_DIR agree with each other (and with the experiment).
set -u
SILCD=$1 CP=$2 SRC=$3 RUNS=$4 MODE=$5
DATA=$SRC/data/martin_moyce_1952_n2.dat
export OPENBLAS_NUM_THREADS=1 OMP_NUM_THREADS=1
unset SILC_SERVER SILC_CONFIG
DIR=$(mktemp -d /tmp/silc-mps-test.XXXXXX) || exit 1
PID=
cleanup() {
  [ -n "$PID" ] && kill "$PID" 2>/dev/null && wait "$PID" 2>/dev/null
  rm -rf "$DIR"
}
trap cleanup EXIT
trap 'exit 1' INT TERM

# start_silcd [silcd options...]: a server on $DIR/s.sock, ready or exit 1.
start_silcd() {
  "$SILCD" --listen "unix:$DIR/s.sock" --ready-file "$DIR/ready" --log-level error "$@" 2>"$DIR/silcd.log" &
  PID=$!
  for _ in $(seq 100); do
    [ -f "$DIR/ready" ] && return 0
    kill -0 "$PID" 2>/dev/null || break
    sleep 0.1
  done
  echo "test_mps: silcd did not start:"; cat "$DIR/silcd.log"; exit 1
}

case $MODE in
model)
  start_silcd
  java -cp "$CP" mps.ModelTest "unix:$DIR/s.sock"
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
  start_silcd --config "$SRC/configs/$CONFIG.conf"
  java -cp "$CP" mps.DamBreak --server "unix:$DIR/s.sock" --time 2.8 --csv "$DIR/$CONFIG.csv" \
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
  java -cp "$CP" mps.FrontCheck "$DATA" "$DIR/$CONFIG.csv" || exit 1
  cp "$DIR/$CONFIG.csv" "$RUNS/$CONFIG.csv"
  ;;
agree)
  set -- "$RUNS"/*.csv
  if [ $# -lt 2 ] || [ ! -f "$1" ]; then
    echo "test_mps: FAIL: fewer than two backend runs in $RUNS to compare"; exit 1
  fi
  echo "comparing: $*"
  java -cp "$CP" mps.FrontCheck "$DATA" "$@"
  ;;
*)
  echo "test_mps: unknown mode $MODE"; exit 2
  ;;
esac
