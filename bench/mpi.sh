#!/usr/bin/env bash
# mpi.sh -- the SILC-over-MPI bench: runs bench/mpi (SILC as a client of
# `silcd --mpi`, as an SPMD program, and embedded) and bench/mpi_direct (the
# same PETSc/MUMPS solves without SILC) at the same numbers of ranks, in the
# same run, and prints markdown tables with each SILC row's ratio to its
# direct baseline and the bytes SILC moved between ranks (docs/distributed.md,
# "Measured: SILC over MPI").
#
#     bench/mpi.sh [--quick] [BUILD_DIR]       (default BUILD_DIR: build)
#     env: NPS="1 2" (rank counts; more than the cores is oversubscribed and
#          labelled so), ROUNDS (repetitions, default 3; quick 1), KEEP=dir
#          (keep the raw RESULT lines and logs there), METHODS (SILC's,
#          default mumps,petsc-mumps,petsc-cg-hypre; the direct rows run for
#          those given), LOOP=0 (one-shot rows only), NS (the one-shot
#          grid sides)
#
# Full: one-shot x = A \ b on 500^2 and 1000^2, the Crank-Nicolson loop on
# 400^2 for 100 steps; --quick: 100^2/200^2 and 100^2 for 10 steps.  Each
# round runs every configuration once, modes interleaved so that drift of the
# machine hits all of them alike; a table gives the best time of the rounds
# and the spread (max - min) / min.  One-shot rows also give the least CPU
# time over the rounds (its system part in parentheses) of every process
# that worked on the solve (the client
# and the server's ranks; the SPMD ranks; the direct program's ranks), its
# ratio to the direct row's and that round's page faults: on a machine
# shared with other work these move far less than the times.  "From arrays"
# is the best total from the program's arrays to the solution: SILC's PUTs
# plus the statement; a PETSc program's assembly of its Mat plus setup and
# solve (it too must put its data into a Mat); MUMPS's setup and solve alone
# (it takes the program's triplets as they are).  The silcd server runs only while its
# client runs (its idle ranks rest, but its start and end are not measured
# here).  bench/mpi_wake.py measures what resting ranks add to a request.
# A last table pairs each SILC one-shot row with its direct baseline round
# by round (an SPMD row runs right before its baseline) and gives the median
# and range of those ratios: on a shared host whose speed drifts within
# minutes, the best of each row alone can come from different moments.
set -u
cd "$(dirname "$0")/.." || exit 1
QUICK=0
if [ "${1:-}" = "--quick" ]; then QUICK=1; shift; fi
BUILD=${1:-build}
MPI_BIN=$BUILD/bench/mpi
DIRECT=$BUILD/bench/mpi_direct
SILCD=$BUILD/server/silcd
for f in "$MPI_BIN" "$DIRECT" "$SILCD"; do
  [ -x "$f" ] || { echo "mpi.sh: $f not built (cmake --build $BUILD)" >&2; exit 1; }
done

export OPENBLAS_NUM_THREADS=1 OMP_NUM_THREADS=1 OMPI_ALLOW_RUN_AS_ROOT=1 \
       OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1 OMPI_MCA_rmaps_base_oversubscribe=1
unset SILC_SERVER

if [ $QUICK = 1 ]; then
  NS=${NS:-"100 200"}; LOOP_N=100; STEPS=10; ROUNDS=${ROUNDS:-1}
else
  NS=${NS:-"500 1000"}; LOOP_N=400; STEPS=100; ROUNDS=${ROUNDS:-3}
fi
NPS=${NPS:-"1 2"}
CORES=$(getconf _NPROCESSORS_ONLN)  # not nproc: it honours OMP_NUM_THREADS
WORK=${TABLE_ONLY:-${KEEP:-$(mktemp -d /tmp/silc-mpi-bench.XXXXXX)}}
mkdir -p "$WORK"
RES=$WORK/results.txt
LOG=$WORK/log.txt
[ -n "${TABLE_ONLY:-}" ] || { : >"$RES"; : >"$LOG"; }
SOCK=$WORK/silcd.sock
SILC_METHODS=${METHODS:-mumps,petsc-mumps,petsc-cg-hypre}
LOOP=${LOOP:-1}
has_method() { case ",$SILC_METHODS," in *",$1,"*) return 0;; esac; return 1; }

# Runs a command, its RESULT lines to $RES, everything to $LOG.  A non-zero
# exit is logged, not fatal: a failed row simply has no RESULT line.
record() {
  echo "+ $*" >>"$LOG"
  "$@" >"$WORK/out" 2>&1
  local rc=$?
  cat "$WORK/out" >>"$LOG"
  grep '^RESULT ' "$WORK/out" >>"$RES"
  [ $rc = 0 ] || echo "  (exit status $rc)" >>"$LOG"
}

# mpi_direct's row as a RESULT line: columns method n np oneshot_s step_s
# err_inf asm_s setup_s solve_s its lsetup_s litis heat ord.
direct() { # np name kind n [mpi_direct options]
  local np=$1 name=$2 kind=$3 n=$4; shift 4
  local args=(-n "$n" -header 0)
  if [ "$kind" = loop ]; then args+=(-steps "$STEPS" -oneshot 0); else args+=(-steps 0); fi
  echo "+ mpirun -np $np $DIRECT ${args[*]} $*" >>"$LOG"
  mpirun -np "$np" "$DIRECT" "${args[@]}" "$@" >"$WORK/out" 2>&1
  cat "$WORK/out" >>"$LOG"
  awk -v name="$name" -v kind="$kind" -v steps="$STEPS" '
    $2 ~ /^[0-9]+$/ && NF >= 13 {
      if (kind == "oneshot")
        printf "RESULT mode=direct kind=oneshot method=%s n=%s np=%s status=ok time_s=%s err=%s asm_s=%s%s\n",
               name, $2, $3, $4, $6, $7, (NF >= 17 ? (" cpu_s=" $15 " faults=" $16 " sys_s=" $17) : "")
      else
        printf "RESULT mode=direct kind=loop method=%s n=%s np=%s status=ok time_s=%.4f first_s=%s step_s=%s heat=%s\n",
               name, $2, $3, $11 + steps * $5, $11, $5, $13
    }' "$WORK/out" >>"$RES"
}

start_server() { # np
  rm -f "$SOCK" "$WORK/ready"
  mpirun -np "$1" "$SILCD" --mpi --listen "unix:$SOCK" --dist-min-rows 1000 \
         --ready-file "$WORK/ready" >>"$WORK/silcd.log" 2>&1 &
  SERVER_PID=$!
  # The ranks (mpirun's children) by pid, for the client to count their CPU
  # time and page faults with its own (bench/mpi.c, usage_now).
  for _ in $(seq 300); do
    if [ -s "$WORK/ready" ]; then
      SILC_BENCH_SERVER_PIDS=$(pgrep -d ' ' -P "$SERVER_PID" silcd)
      export SILC_BENCH_SERVER_PIDS
      echo "silcd --mpi -np $1: ranks $SILC_BENCH_SERVER_PIDS" >>"$LOG"
      return 0
    fi
    sleep 0.1
  done
  echo "mpi.sh: silcd --mpi -np $1 did not start (see $WORK/silcd.log)" >&2
  return 1
}

stop_server() {
  kill -TERM "$SERVER_PID" 2>/dev/null
  wait "$SERVER_PID" 2>/dev/null
}

# Is the petsc plugin collective yet?  A small SPMD solve at 2 ranks that
# gathers its matrix (or fails) says no; then the petsc rows are "n/a" and
# not run, which saves their sequential solves on every rank.
PETSC=yes
if [ -n "${TABLE_ONLY:-}" ]; then
  ELAPSED="not measured (tables of $TABLE_ONLY)"
else
record mpirun -np 2 "$MPI_BIN" spmd -n 60 -methods petsc-mumps
if ! grep -q 'method=petsc-mumps .*status=ok' "$RES"; then
  PETSC="n/a (petsc collective not available)"
  SILC_METHODS=$(has_method mumps && echo mumps)
fi
: >"$RES"

T0=$(date +%s)
for round in $(seq "$ROUNDS"); do
  for np in $NPS; do
    echo "round $round/$ROUNDS, np=$np ($(( $(date +%s) - T0 )) s)" >&2
    if start_server "$np"; then
      for n in $NS; do
        record "$MPI_BIN" client -server "unix:$SOCK" -n "$n" -methods "$SILC_METHODS"
      done
      [ "$LOOP" = 1 ] && record "$MPI_BIN" client -server "unix:$SOCK" -n "$LOOP_N" -steps "$STEPS" -methods "$SILC_METHODS"
      stop_server
    fi
    # One process per method, as the direct rows: a solve that follows
    # another in the same process ran up to 1.6x slower here (hypre after
    # MUMPS or CHOLMOD at 1000^2, page faults and scheduler time in perf),
    # which measures the process's history, not SILC.  Each SPMD one-shot
    # row runs right before its direct baseline, so that the pair sees the
    # same state of a shared host (its speed drifted 3.4-5.4 s for the same
    # MUMPS factorization within minutes): the per-round ratios below pair them.
    for n in $NS; do
      for m in ${SILC_METHODS//,/ }; do
        record mpirun -np "$np" "$MPI_BIN" spmd -n "$n" -methods "$m"
        case $m in
          mumps) direct "$np" dmumps oneshot "$n" -method dmumps
                 direct "$np" mumps-chol oneshot "$n" -method mumps -pc_type cholesky ;;
          petsc-mumps) direct "$np" mumps oneshot "$n" -method mumps ;;
          petsc-cg-hypre) direct "$np" cg-hypre oneshot "$n" -method cg-hypre ;;
        esac
      done
    done
    for m in ${SILC_METHODS//,/ }; do
      [ "$LOOP" = 1 ] && record mpirun -np "$np" "$MPI_BIN" spmd -n "$LOOP_N" -steps "$STEPS" -methods "$m"
    done
    if [ "$LOOP" = 1 ]; then
      has_method petsc-mumps && direct "$np" mumps loop "$LOOP_N" -method mumps
      has_method mumps && direct "$np" mumps-chol loop "$LOOP_N" -method mumps -pc_type cholesky
      has_method petsc-cg-hypre && direct "$np" cg-hypre loop "$LOOP_N" -method cg-hypre
    fi
    if [ "$np" = 1 ]; then
      for n in $NS; do record "$MPI_BIN" embedded -n "$n" -methods default; done
      [ "$LOOP" = 1 ] && record "$MPI_BIN" embedded -n "$LOOP_N" -steps "$STEPS" -methods default
    fi
  done
done
ELAPSED="$(( $(date +%s) - T0 )) s"
fi

# ---- tables ----------------------------------------------------------------
echo
echo "SILC over MPI, $(date -u +%Y-%m-%d), $CORES cores, best of $ROUNDS round(s), run time ${ELAPSED}"
echo "(bench/mpi.sh $([ $QUICK = 1 ] && echo --quick) $BUILD; raw lines: $RES)"
echo "petsc collective: $PETSC"
awk -v cores="$CORES" -v petsc="$PETSC" -v nps="$NPS" -v steps="$STEPS" -v partial="${METHODS:+1}" -v loop="$LOOP" '
  function field(line, key,   i, s) {
    if (match(line, " " key "=\"[^\"]*\"")) { s = substr(line, RSTART + length(key) + 3, RLENGTH - length(key) - 4); return s }
    if (match(line, " " key "=[^ ]*")) return substr(line, RSTART + length(key) + 2, RLENGTH - length(key) - 2)
    return ""
  }
  /^RESULT / {
    k = field($0, "kind") "|" field($0, "n") "|" field($0, "np") "|" field($0, "mode") "|" field($0, "method")
    st = field($0, "status")
    if (st == "fail") { if (!(k in best)) failmsg[k] = field($0, "msg"); next }
    t = (field($0, "kind") == "loop") ? field($0, "step_s") + 0 : field($0, "time_s") + 0
    cnt[k]++
    if (!(k in best) || t < best[k]) { best[k] = t; line[k] = $0 }
    if (!(k in worst) || t > worst[k]) worst[k] = t
    # From the program arrays to the solution: the SILC PUTs and statement;
    # the PETSc assembly of its Mat and setup + solve (a PETSc program must
    # put its data into a Mat too); MUMPS setup + solve alone (it takes
    # the program triplets as they are; building them is the program work).
    if (field($0, "kind") == "oneshot") {
      a = t + (field($0, "mode") == "direct" ? (field($0, "method") == "dmumps" ? 0 : field($0, "asm_s") + 0) : field($0, "put_s") + 0)
      if (!(k in tot) || a < tot[k]) tot[k] = a
      rt[k, cnt[k]] = t; ra[k, cnt[k]] = a # this round, for the paired table
    }
    c = field($0, "cpu_s")
    if (c != "" && (!(k in cpu) || c + 0 < cpu[k])) { cpu[k] = c + 0; faults[k] = field($0, "faults"); sys[k] = field($0, "sys_s") }
    status[k] = st
  }
  function base_of(method, kind) {
    # one-shot: the mumps backend against MUMPS called directly, same ICNTLs
    if (method == "mumps" && kind == "oneshot") return "dmumps"
    if (method == "mumps" || method == "default") return "mumps-chol"
    if (method == "petsc-mumps") return "mumps"
    if (method == "petsc-cg-hypre") return "cg-hypre"
    return ""
  }
  function label(mode, method) {
    if (mode == "client") return "(a) silcd --mpi client, " method
    if (mode == "spmd") return "(b) SILC SPMD, " method
    if (mode == "embedded") return "(d) embedded SILC, default (CHOLMOD)"
    if (method == "dmumps") return "(c) direct MUMPS, dmumps_c (same ICNTLs as mumps)"
    return "(c) direct PETSc, " method
  }
  # "median [min-max]" of x[1..c] (sorted in place).
  function spread3(x, c,   i, j, t) {
    for (i = 2; i <= c; i++) for (j = i; j > 1 && x[j - 1] > x[j]; j--) { t = x[j]; x[j] = x[j - 1]; x[j - 1] = t }
    return sprintf("%.2f [%.2f-%.2f]", c % 2 ? x[(c + 1) / 2] : (x[c / 2] + x[c / 2 + 1]) / 2, x[1], x[c])
  }
  # A SILC one-shot row against its direct row, round by round.
  function paired(n, np, mode, method,   k, bk, i, c, xs, xa) {
    k = "oneshot|" n "|" np "|" mode "|" method
    bk = "oneshot|" n "|" np "|direct|" base_of(method, "oneshot")
    if (!(k in cnt) || !(bk in cnt)) return
    c = 0
    for (i = 1; i <= cnt[k] && i <= cnt[bk]; i++) {
      if (rt[bk, i] <= 0 || ra[bk, i] <= 0) continue
      c++; xs[c] = rt[k, i] / rt[bk, i]; xa[c] = ra[k, i] / ra[bk, i]
    }
    if (c) printf "| %s | %s | %s | %s | %s | %d |\n", n, np, label(mode, method), spread3(xs, c), spread3(xa, c), c
  }
  function row(kind, n, np, mode, method,   k, b, bk, r, sp, L, note) {
    k = kind "|" n "|" np "|" mode "|" method
    note = (np + 0 > cores + 0) ? " (oversubscribed: " np " ranks on " cores " cores)" : ""
    empty = kind == "loop" ? " | | | | |" : " | | | | | | | | |"
    if (method ~ /^petsc/ && petsc != "yes") {
      printf "| %s | %s | %s | %s%s\n", n, np, label(mode, method) note, petsc, empty; return
    }
    if (!(k in best) && !(k in failmsg) && partial) return # a method METHODS left out
    if (!(k in best)) {
      printf "| %s | %s | %s | %s%s\n", n, np, label(mode, method) note,
             (k in failmsg) ? "failed: " substr(failmsg[k], 1, 80) : "not run", empty; return
    }
    if (status[k] == "gathered") note = note " **not collective: matrix gathered**"
    L = line[k]
    sp = best[k] > 0 ? sprintf("%.0f%%", 100 * (worst[k] - best[k]) / best[k]) : "-"
    r = "-"; cr = "-"; tr = "-"
    if (mode != "direct") {
      bk = kind "|" n "|" np "|direct|" base_of(method, kind)
      if (bk in best) r = sprintf("%.2f (vs %s)", best[k] / best[bk], base_of(method, kind))
      if ((bk in tot) && (k in tot) && tot[bk] > 0) tr = sprintf("%.2f", tot[k] / tot[bk])
      if ((bk in cpu) && (k in cpu) && cpu[bk] > 0) cr = sprintf("%.2f", cpu[k] / cpu[bk])
    }
    if (kind == "oneshot")
      printf "| %s | %s | %s | %.3f | %s | %s | %.3f | %s | %s | %s | %s | %s | %s |\n", n, np, label(mode, method) note, best[k], sp, r, tot[k], tr,
             !(k in cpu) ? "-" : sys[k] == "" ? sprintf("%.2f", cpu[k]) : sprintf("%.2f (%s)", cpu[k], sys[k]), cr, (k in cpu) ? faults[k] : "-",
             field(L, "err"), (mode == "direct") ? "-" : field(L, "mbytes") " / " field(L, "vbytes")
    else
      printf "| %s | %s | %s | %.4f | %s | %s | %s | %s | %s |\n", n, np, label(mode, method) note, best[k], sp, r,
             field(L, "first_s"),
             (mode == "direct") ? "-" : field(L, "mbytes") " / " field(L, "vbytes") " (first step " field(L, "mbytes1") " / " field(L, "vbytes1") ")",
             field(L, "heat")
  }
  END {
    split(nps, P, " ")
    split("mumps petsc-mumps petsc-cg-hypre", M, " ")
    split("mumps mumps-chol cg-hypre dmumps", D, " ")
    for (kind = 1; kind <= (loop == 1 ? 2 : 1); kind++) {
      K = kind == 1 ? "oneshot" : "loop"
      delete Ns; nn = 0
      for (k in best) { split(k, f, "|"); if (f[1] == K && !(f[2] in Ns)) { Ns[f[2]] = 1; order[++nn] = f[2] + 0 } }
      for (i = 1; i <= nn; i++) for (j = i + 1; j <= nn; j++) if (order[j] < order[i]) { t = order[i]; order[i] = order[j]; order[j] = t }
      print ""
      if (K == "oneshot") {
        print "One-shot x = A \\ b (b = A*ones), seconds for the solve statement (direct: setup + solve);"
        print "from arrays: SILC PUTs + statement, direct PETSc assembly of its Mat + setup + solve, direct MUMPS setup + solve:"
        print ""
        print "| n | np | mode, method | time s | spread | ratio to direct | from arrays s | ratio | CPU s (sys) | CPU ratio | page faults | err_inf | bytes moved (matrices / vectors) |"
        print "|---:|---:|---|---:|---:|---|---:|---:|---:|---:|---:|---|---|"
      } else {
        print "Crank-Nicolson loop, " steps " steps, seconds per step after the first (direct: MatMult + KSPSolve):"
        print ""
        print "| n | np | mode, method | per step s | spread | ratio to direct | first step s (direct: lsetup) | bytes moved per step (matrices / vectors) | heat |"
        print "|---:|---:|---|---:|---:|---|---:|---|---|"
      }
      for (i = 1; i <= nn; i++) for (p = 1; p in P; p++) {
        n = order[i]; np = P[p]
        for (d = 1; d <= 4; d++) if (K == "oneshot" || D[d] != "dmumps") row(K, n, np, "direct", D[d])
        for (m = 1; m <= 3; m++) row(K, n, np, "client", M[m])
        for (m = 1; m <= 3; m++) row(K, n, np, "spmd", M[m])
        if (np == 1) row(K, n, np, "embedded", "default")
      }
      if (K == "oneshot") {
        print ""
        print "Paired by round: each SPMD row runs right before its direct baseline (the client rows earlier in"
        print "the round, while the server is up); median [range] of the per-round ratios:"
        print ""
        print "| n | np | mode, method | statement / direct | from arrays / direct | rounds |"
        print "|---:|---:|---|---|---|---:|"
        for (i = 1; i <= nn; i++) for (p = 1; p in P; p++) {
          for (m = 1; m <= 3; m++) paired(order[i], P[p], "client", M[m])
          for (m = 1; m <= 3; m++) paired(order[i], P[p], "spmd", M[m])
        }
      }
    }
  }' "$RES"
[ -n "${KEEP:-}" ] || echo "(raw results and logs in $WORK)"
