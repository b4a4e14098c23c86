#!/bin/sh
# readme.sh -- README.md as a test: every fenced code block runs as written,
# in a scratch directory laid out like the repository (build/, bindings/,
# core/include/ and ../shared/matrices are links to the real ones), with
# HOME there too, so a block that writes ~/.silc-token or silc.sock touches
# nothing outside it.  How a block runs:
#   sh       with sh -e (set -e: any failing command fails the block)
#   c, java  the block's first comment line is the shell command that builds
#            and runs it; the block is saved under the file name it compiles
#   python   with /usr/bin/python3
#   ini      as the configuration of `silc --config FILE`, which must start
#            and solve a system with it
#   text     not code: not run
# A comment "needs: NAME=VALUE ..." in a block is the environment it states it
# needs; SILC_SERVER=unix:PATH there also starts a silcd listening on PATH for
# the block.  A block right after "<!-- readme-test: skip (why) -->" is not run;
# the skipped ones are counted and listed with their reasons.  Each block is
# bounded by `timeout` and its leftover processes (servers it started with &)
# are killed with its process group.
#
#     sh tests/readme.sh SOURCE_DIR BUILD_DIR
set -u
SRC=$1 BUILD=$2
README=$SRC/README.md
WORK=$BUILD/readme-test
BLOCK_TIMEOUT=${SILC_README_BLOCK_TIMEOUT:-60}
rm -rf "$WORK"
mkdir -p "$WORK/blocks" "$WORK/repo/core" "$WORK/home" || exit 1
ln -s "$BUILD" "$WORK/repo/build"
ln -s "$SRC/bindings" "$WORK/repo/bindings"
ln -s "$SRC/examples" "$WORK/repo/examples"
ln -s "$SRC/core/include" "$WORK/repo/core/include"
ln -s "$(cd "$SRC/.." && pwd)/shared" "$WORK/shared"
REPO=$WORK/repo
export HOME="$WORK/home"
unset SILC_SERVER SILC_CONFIG SILC_PLUGIN_PATH SILC_LIBRARY SILC_TOKEN SILC_TOKEN_FILE

# Split README.md into blocks/N.LANG, with blocks/N.line (the fence's line)
# and, for a skipped block, blocks/N.skip (the reason).
awk -v dir="$WORK/blocks" '
  /^<!-- readme-test: skip/ { skip = $0; sub(/^<!-- readme-test: skip *\(?/, "", skip); sub(/\)? *-->$/, "", skip); next }
  !inblock && /^```/ {
    n++; lang = substr($0, 4); if (lang == "") lang = "none"
    file = sprintf("%s/%02d.%s", dir, n, lang)
    printf "" > file
    print NR > sprintf("%s/%02d.line", dir, n)
    if (skip != "") print skip > sprintf("%s/%02d.skip", dir, n)
    inblock = 1; skip = ""; next
  }
  inblock && /^```/ { inblock = 0; close(file); next }
  inblock { print > file; next }
  /[^ \t]/ { skip = "" }
' "$README"

ran=0 failed=0 skipped=0 notcode=0
skiplist=""
free_port() {
  /usr/bin/python3 -c 'import socket; s = socket.socket(); s.bind(("127.0.0.1", 0)); print(s.getsockname()[1])'
}
# The NAME=VALUE words after "needs:" in file $1, one a line.
needs() {
  sed -n 's/.*needs: *//p' "$1" | head -1 | tr ' ' '\n' | grep -E '^[A-Za-z_][A-Za-z0-9_]*=' || true
}
# run_block FILE COMMAND...: COMMAND in $REPO under the block's needs, in its
# own process group, bounded; the exit status is the command's.
run_block() {
  f=$1
  shift
  server_pid=
  env_words=$(needs "$f")
  sock=$(echo "$env_words" | sed -n 's/^SILC_SERVER=unix://p')
  if [ -n "$sock" ]; then
    (cd "$REPO" && rm -f "$sock" "$WORK/needs.ready" &&
      exec build/server/silcd --listen "unix:$sock" --ready-file "$WORK/needs.ready") >"$WORK/needs.log" 2>&1 &
    server_pid=$!
    tries=0
    while [ ! -s "$WORK/needs.ready" ] && [ $tries -lt 200 ]; do sleep 0.1; tries=$((tries + 1)); done
  fi
  # shellcheck disable=SC2086 # the needs are NAME=VALUE words
  (cd "$REPO" && exec env $env_words PORT="$(free_port)" setsid timeout "$BLOCK_TIMEOUT" "$@") \
    </dev/null >"$f.out" 2>&1 &
  pid=$!
  wait $pid
  rc=$?
  kill -TERM "-$pid" 2>/dev/null # what the block left running (its servers)
  [ -n "$server_pid" ] && kill "$server_pid" 2>/dev/null && wait "$server_pid" 2>/dev/null
  return $rc
}

for f in "$WORK"/blocks/*.*; do
  case "$f" in *.line|*.skip|*.out) continue ;; esac
  base=${f%.*} lang=${f##*.}
  line=$(cat "$base.line")
  if [ -f "$base.skip" ]; then
    skipped=$((skipped + 1))
    skiplist="$skiplist
  README.md:$line ($lang): $(cat "$base.skip")"
    continue
  fi
  case "$lang" in
    text|none) notcode=$((notcode + 1)); continue ;;
    sh)
      run_block "$f" sh -e "$f" ;;
    python)
      run_block "$f" /usr/bin/python3 "$f" ;;
    ini)
      run_block "$f" build/tools/silc --config "$f" -e 'A = sparse([1; 2; 2; 3], [1; 1; 2; 3], [4; 1; 4; 4], 3, 3); x = A \ ones(3, 1)' ;;
    c|java)
      # the first comment line: "/* CMD" or "// CMD"; the source file it names
      cmd=$(head -1 "$f" | sed 's|^ */[*/] *||; s| *\*/ *$||')
      src=$(echo "$cmd" | tr ' ' '\n' | grep -E "\.(c|java)\$" | head -1)
      if [ -z "$src" ]; then
        echo "readme: FAIL: README.md:$line ($lang): its first line names no command building a .c/.java file"
        failed=$((failed + 1))
        continue
      fi
      cp "$f" "$REPO/$src"
      run_block "$f" sh -ec "$cmd" ;;
    *)
      echo "readme: FAIL: README.md:$line: a '$lang' block, which this test cannot run (mark it skipped, saying why)"
      failed=$((failed + 1))
      continue ;;
  esac
  rc=$?
  ran=$((ran + 1))
  if [ $rc -ne 0 ]; then
    failed=$((failed + 1))
    echo "readme: FAIL: README.md:$line ($lang) exited with $rc:"
    sed 's/^/    /' "$f.out" | tail -30
  else
    echo "readme: ok: README.md:$line ($lang)"
  fi
done
echo "readme: $ran blocks run, $failed failed, $notcode not code, $skipped skipped:$skiplist"
[ $failed -eq 0 ] && [ $ran -gt 0 ]
