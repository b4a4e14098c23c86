# silcd_run.sh -- sourced (". tools/silcd_run.sh") by the scripts that need a
# silcd of their own: tests and benches that start a server per config.
#
#     silcd_start SILCD [silcd options...]   start one, wait until it listens
#     silcd_stop                              stop it (the next start may follow)
#
# The server listens on a Unix socket in a fresh directory $SILCD_DIR (or on
# $SILCD_LISTEN when set, e.g. tcp://127.0.0.1:0, which needs --token-file among
# the options); once it is ready $SILCD_URL
# is the address it listens on (from its --ready-file, so port 0 resolves).
# A server that does not start within 10 s ends the script with its log and
# status 1.  An EXIT trap stops the server and removes $SILCD_DIR whatever
# happens, so no silcd outlives the script; scripts keep their own temporary
# files in $SILCD_DIR too.
SILCD_DIR=$(mktemp -d /tmp/silcd-run.XXXXXX) || exit 1
SILCD_PID=
SILCD_URL=
silcd_stop() {
  if [ -n "$SILCD_PID" ]; then
    kill "$SILCD_PID" 2>/dev/null && wait "$SILCD_PID" 2>/dev/null
  fi
  SILCD_PID=
  rm -f "$SILCD_DIR/ready"
}
silcd_cleanup_() {
  silcd_stop
  rm -rf "$SILCD_DIR"
}
trap silcd_cleanup_ EXIT
trap 'exit 1' INT TERM
silcd_start() {
  silcd_bin_=$1
  shift
  silcd_stop
  "$silcd_bin_" --listen "${SILCD_LISTEN:-unix:$SILCD_DIR/s.sock}" --ready-file "$SILCD_DIR/ready" \
    --log-level error "$@" 2>"$SILCD_DIR/silcd.log" &
  SILCD_PID=$!
  for _ in $(seq 100); do
    if [ -s "$SILCD_DIR/ready" ]; then
      SILCD_URL=$(cat "$SILCD_DIR/ready")
      return 0
    fi
    kill -0 "$SILCD_PID" 2>/dev/null || break
    sleep 0.1
  done
  echo "silcd did not start:" >&2
  cat "$SILCD_DIR/silcd.log" >&2
  exit 1
}
