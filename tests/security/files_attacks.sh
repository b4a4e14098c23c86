#!/bin/sh
# files_attacks.sh -- the attacks of docs/security.md's "Settings" and
# "Files" rows, one case each, against a real silcd (MODE unix: a Unix socket
# in STATEDIR; tcp: 127.0.0.1 with a token file; mpi: `mpirun -np 2 silcd
# --mpi`), or against an embedded program (MODE embedded: the temporary-file
# race).  Every refusal is compared with its exact text; at the end nothing
# outside silcd's --data-dir may have changed (a canary file's hash, a canary
# symbolic link's target, the listing of the folder beside the data
# directory) and the canary plugin's constructor must not have run.
#
#     sh files_attacks.sh MODE SILC_CLI SILCD CANARY_PLUGIN_DIR STATEDIR [MPIRUN]
set -u
MODE=$1 CLI=$2 SILCD=$3 PLUGDIR=$4 D=$5 MPIRUN=${6:-}
fails=0 cases=0
fail() { echo "FAIL: $*"; fails=$((fails + 1)); }

[ -f "$PLUGDIR/libsilc_plugin_x.so" ] || { echo "canary plugin missing in $PLUGDIR (build silc_security_canary)"; exit 1; }
rm -rf "$D"
mkdir -p "$D/outside" "$D/data" "$D/shared" "$D/w" || exit 1
D=$(cd "$D" && pwd)
OUT=$D/outside
export SILC_CANARY_MARKER=$D/canary-ran
echo "the operator's file" >"$OUT/canary.txt"
ln -s "$OUT/canary.txt" "$OUT/canary-link"
SILC_WISDOM=$D/w/operator-wisdom
export SILC_WISDOM
echo "# the operator's wisdom" >"$SILC_WISDOM"

# The state of everything outside the data directory: names, types, link
# targets and contents.
outside_state() {
    (cd "$D" && find outside w -printf '%p %y %l\n' | sort && cat outside/canary.txt w/operator-wisdom) | md5sum
}

# run EXPECT STATEMENTS: runs them in one session; EXPECT "ok" wants success,
# anything else is the exact error line the CLI must print.
run() {
    want=$1 stmts=$2
    cases=$((cases + 1))
    got=$("$CLI" -e "$stmts" 2>&1 >/dev/null)
    rc=$?
    if [ "$want" = ok ]; then
        [ $rc -eq 0 ] || fail "'$stmts' failed: $got"
    elif [ $rc -eq 0 ]; then
        fail "'$stmts' succeeded; wanted: $want"
    elif [ "$got" != "silc: $want" ]; then
        fail "'$stmts'
   said: $got
  wants: silc: $want"
    fi
}

# ---- HDF5 in this build? (save/load say so without it) --------------------------
have_h5=1
if (cd "$D/w" && "$CLI" -e 'x = 1; save "probe.h5"' 2>&1 | grep -q "HDF5 support is not installed"); then have_h5=0; fi
rm -f "$D/w/probe.h5"

# ---- embedded: the temporary-file race (and the control for the canary) -----------
if [ "$MODE" = embedded ]; then
    cd "$D/w" || exit 1
    echo "victim" >"$OUT/victim.txt"
    # the control: an embedded program is its own operator, so the canary
    # plugin's constructor runs when it names its folder and then needs the
    # plugin (plugins open at first need: here its option set) (the test
    # could fail)
    "$CLI" -e "set core.plugin_path = $PLUGDIR; set x.probe = 1" >/dev/null 2>&1
    [ -f "$SILC_CANARY_MARKER" ] || fail "control: the canary plugin did not run when loaded embedded"
    rm -f "$SILC_CANARY_MARKER"
    before=$(md5sum <"$OUT/victim.txt")
    if [ $have_h5 -eq 1 ]; then
        # links planted at the names the old code used for its temporaries
        # (<target>.tmp<pid>, the pid being the one exec keeps) and at the
        # target itself
        cases=$((cases + 1))
        sh -c 'ln -s "$1" out.h5.tmp$$; ln -s "$1" linked.h5; exec "$2" -e "x = [1, 2]; save \"out.h5\"; save \"linked.h5\""' \
            _ "$OUT/victim.txt" "$CLI" || fail "save beside planted links failed"
        [ -f out.h5 ] && [ ! -L out.h5 ] || fail "out.h5 is not a regular file"
        [ -f linked.h5 ] && [ ! -L linked.h5 ] || fail "the link at linked.h5 was not replaced by the file"
        run ok 'load "out.h5"; load "linked.h5"'
        # embedded, a link of the user's own is still followed for reading
        ln -s out.h5 alias.h5
        run ok 'load "alias.h5"; if (x[1, 2] != 2) { error }'
    fi
    # the wisdom file and the plot of tune report, the same way
    cases=$((cases + 1))
    sh -c 'ln -s "$1" wisdom.tmp$$; ln -s "$1" plot.svg.tmp$$; ln -s "$1" plot.svg; exec "$2" -e "set tune.wisdom = wisdom; tune on 100000; n = 40; A = sparse(4 * eye(n) + 0.5 * ones(n, n)); b = ones(n, 1); i = 0; while (i < 40) { y = A \\ b; i = i + 1 }; tune report \"plot.svg\""' \
        _ "$OUT/victim.txt" "$CLI" >/dev/null || fail "tuning beside planted links failed"
    grep -q "silc wisdom v1" wisdom 2>/dev/null || fail "the wisdom file was not written"
    [ ! -L plot.svg ] && grep -q "<svg" plot.svg 2>/dev/null || fail "plot.svg was not written as a file"
    [ "$(md5sum <"$OUT/victim.txt")" = "$before" ] || fail "a write went through a planted link: victim.txt changed"
    [ ! -f "$SILC_CANARY_MARKER" ] || fail "the canary plugin ran"
    echo "security_files_embedded: $cases cases, $fails failed"
    [ $fails -eq 0 ]
    exit
fi

# ---- a silcd --------------------------------------------------------------------
head -c 32 /dev/urandom | od -An -tx1 | tr -d ' \n' >"$D/token"
chmod 600 "$D/token"
export SILC_TOKEN_FILE="$D/token"
pid=
start() {  # start NAME [silcd options]: a silcd, its address in SILC_SERVER
    name=$1
    shift
    rm -f "$D/$name.ready" "$D/$name.sock"
    case $MODE in
    unix) listen=unix:$D/$name.sock launch= ;;
    tcp) listen=tcp://127.0.0.1:0 launch= ;;
    mpi) listen=unix:$D/$name.sock launch="$MPIRUN -np 2" ;;
    esac
    # shellcheck disable=SC2086 # launch is a command with its arguments
    $launch "$SILCD" ${launch:+--mpi} --listen "$listen" --token-file "$D/token" --ready-file "$D/$name.ready" \
        --io-timeout 10 --log-level warn "$@" >"$D/$name.log" 2>&1 </dev/null &
    pid=$!
    i=0
    while [ ! -s "$D/$name.ready" ]; do
        i=$((i + 1))
        if [ $i -gt 300 ] || ! kill -0 $pid 2>/dev/null; then
            echo "silcd did not start:"
            cat "$D/$name.log"
            exit 1
        fi
        sleep 0.1
    done
    SILC_SERVER=$(cat "$D/$name.ready")
    export SILC_SERVER
}
stop() {
    kill $pid 2>/dev/null
    i=0
    while kill -0 $pid 2>/dev/null; do
        i=$((i + 1))
        [ $i -gt 300 ] && { kill -9 $pid; fail "silcd $pid did not stop within 30 s"; break; }
        sleep 0.1
    done
    wait $pid 2>/dev/null
}

state0=$(outside_state)
cd "$D/w" || exit 1
server="is a server setting: set it in silcd's config"
nofiles="this silcd keeps no files for sessions (the operator enables them with silcd --data-dir DIR)"
beneath="(files are named relative to the session's folder under silcd's --data-dir)"

# 1. Without --data-dir: no server setting, no file.
start plain
run "'core.plugin_path' $server" "set core.plugin_path = $PLUGDIR"
run "'core.plugin_path' $server" "x = solve([2, 0; 0, 2], [1; 1], \"core.plugin_path = $PLUGDIR\")"
run "'tune.wisdom' $server" "set tune.wisdom = $OUT/canary.txt"
run "'tune.wisdom' $server" "x = solve([2, 0; 0, 2], [1; 1], \"tune.wisdom = $OUT/canary.txt\")"
run "'tune.max_threads' $server" "set tune.max_threads = 4096"
run "'core.threads' $server" "set core.threads = 4096"
run "tune.threads = 4096 is over this server's cap of $(getconf _NPROCESSORS_ONLN) threads (tune.max_threads, a server setting, else the cores)" \
    "set tune.threads = 4096"
run "'mumps.icntl_1' $server" "set mumps.icntl_1 = 7"
run "'mumps.icntl_22' $server" "set mumps.icntl_22 = 1"
run "petsc.options: the character ':' is refused in a silcd session (it could name a file or a viewer); only letters, digits, spaces and _ . + , = - are allowed" \
    "set petsc.options = -ksp_type cg -log_view :$OUT/canary.txt"
run "petsc.options: '-options_file' is refused in a silcd session: options that view, monitor, log, dump, name a file, load code or set threads are server settings (set them in silcd's config)" \
    "set petsc.options = -options_file canary.txt"
run "petsc.options: '-malloc_dump' is refused in a silcd session: options that view, monitor, log, dump, name a file, load code or set threads are server settings (set them in silcd's config)" \
    "x = solve([2, 0; 0, 2], [1; 1], \"petsc.options = -malloc_dump canary.txt\")"
run "lis-style.options: '-omp_num_threads' is refused in a silcd session: options that view, monitor, log, dump, name a file, load code or set threads are server settings (set them in silcd's config)" \
    "set lis-style.options = -omp_num_threads 64"
run ok "set petsc.options = -ksp_type cg -pc_type jacobi -ksp_rtol 1e-10; set dispatch.solve.dense = reference; set tune.accuracy = 1e-8"
# tune forget keeps the operator's wisdom file (checked with the rest below)
run ok "tune forget"
run "statement 2: save: $nofiles" "x = 1; save \"out.h5\""
run "load: $nofiles" "load \"out.h5\""
run "tune report: $nofiles" "tune report \"$OUT/canary.txt\""
stop

# 2. --data-dir: each session in its own 0700 folder; nothing leaves it.
start perdir --data-dir "$D/data"
if [ $have_h5 -eq 1 ]; then
    run "statement 2: save: '$OUT/canary.txt' is refused: an absolute path is not allowed $beneath" \
        "x = 1; save \"$OUT/canary.txt\""
    run "statement 2: save: '../../outside/canary.txt' is refused: '..' is not allowed $beneath" \
        "x = 1; save \"../../outside/canary.txt\""
    run "load: '$OUT/canary.txt' is refused: an absolute path is not allowed $beneath" "load \"$OUT/canary.txt\""
    run "load: '../session-1/x.h5' is refused: '..' is not allowed $beneath" "load \"../session-1/x.h5\""
    run ok 'x = [1, 2; 3, 4]; save "mine.h5"; clear x; load "mine.h5"; if (x[2, 1] != 3) { error }'
    n=$(find "$D/data" -name mine.h5 | wc -l)
    [ "$n" -eq 1 ] || fail "save wrote $n files named mine.h5 under --data-dir"
    dir=$(dirname "$(find "$D/data" -name mine.h5)")
    case $dir in "$D"/data/session-*) ;; *) fail "mine.h5 is in $dir, not a session's folder" ;; esac
    [ "$(stat -c %a "$dir")" = 700 ] || fail "$dir is not 0700"
    # another session does not see it
    run "load: cannot read 'mine.h5': No such file or directory" 'load "mine.h5"'
fi
run "tune report: '$OUT/canary.txt' is refused: an absolute path is not allowed $beneath" \
    "tune report \"$OUT/canary.txt\""
run "tune report: '../../outside/canary.txt' is refused: '..' is not allowed $beneath" \
    "tune report \"../../outside/canary.txt\""
run "'core.plugin_path' $server" "set core.plugin_path = $PLUGDIR"
stop

# 3. --shared-data-dir with links planted in it by someone else: none is
# followed out, and a write replaces a link rather than going through it.
ln -s "$OUT" "$D/shared/esc"
ln -s "$OUT/canary.txt" "$D/shared/link.h5"
if [ $have_h5 -eq 1 ]; then
    (cd "$OUT" && env -u SILC_SERVER "$CLI" -e 'secret = 42; save "secret.h5"') || fail "making the secret file"
    ln -s "$OUT/secret.h5" "$D/shared/secret.h5"
    ln "$OUT/secret.h5" "$D/shared/hard.h5" 2>/dev/null || echo "(no hard link across these folders: that case is skipped)"
fi
state0=$(outside_state)
start shared --data-dir "$D/shared" --shared-data-dir
# links at the names the old code used for save's temporary (its session's
# pid is silcd's plus a few)
p=$((pid + 1))
while [ $p -le $((pid + 200)) ]; do
    ln -s "$OUT/canary.txt" "$D/shared/out.h5.tmp$p"
    p=$((p + 1))
done
symlink="it passes through a symbolic link, which is not followed"
if [ $have_h5 -eq 1 ]; then
    run "statement 2: save: 'esc/canary.txt' is refused: $symlink $beneath" 'x = 1; save "esc/canary.txt"'
    run "load: 'esc/secret.h5' is refused: $symlink $beneath" 'load "esc/secret.h5"'
    run "load: 'secret.h5' is refused: $symlink $beneath" 'load "secret.h5"'
    [ -f "$D/shared/hard.h5" ] &&
        run "load: 'hard.h5' is refused: it has other hard links, which could lead out of silcd's --data-dir" \
            'load "hard.h5"'
    run ok 'x = 5; save "out.h5"; save "link.h5"'
    [ -f "$D/shared/link.h5" ] && [ ! -L "$D/shared/link.h5" ] || fail "the link at link.h5 was not replaced"
    [ -f "$D/shared/out.h5" ] && [ ! -L "$D/shared/out.h5" ] || fail "out.h5 is not a regular file"
    run ok 'load "out.h5"; if (x != 5) { error }'
fi
run "tune report: 'esc/plot.svg' is refused: $symlink $beneath" 'tune report "esc/plot.svg"'
stop

# ---- what must not have happened ----------------------------------------------------
[ "$(outside_state)" = "$state0" ] || fail "something outside --data-dir changed: $(cd "$D" && find outside w -printf '%p %y %l\n')"
[ "$(readlink "$OUT/canary-link")" = "$OUT/canary.txt" ] || fail "the canary link's target changed"
[ "$(cat "$OUT/canary.txt")" = "the operator's file" ] || fail "canary.txt changed"
[ "$(cat "$SILC_WISDOM")" = "# the operator's wisdom" ] || fail "the operator's wisdom file changed"
[ ! -e "$SILC_CANARY_MARKER" ] || fail "foreign code ran in silcd: the canary plugin's marker exists"
echo "security_files_$MODE: $cases cases, $fails failed"
[ $fails -eq 0 ]
