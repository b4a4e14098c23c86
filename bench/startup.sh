#!/bin/sh
# startup.sh -- what starting SILC costs (issue 30, item 6), two tables, each
# measured in one run, in alternating rounds (every program once per round,
# so a change of load on the shared machine falls on all rows alike), with
# the median of the rounds' wall and CPU times (CPU = the process's user +
# system time from wait4: on a loaded machine the wall time is mostly
# waiting for a core, and CPU is the steadier figure):
#
#   1. `silc -e 'x = 1;'` (a text that solves and saves nothing) against an
#      empty C program, with reference rows: the empty program linked to the
#      libraries silc links, and to those plus readline and tinfo (what silc
#      linked before the REPL opened readline at run time); `silc --version`
#      (the process and its libraries, no engine); an optional older silc
#      (its libsilc's directory given), measured in the same rounds.
#   2. bench/crank_nicolson.silc -- the seeds' 100-step Crank-Nicolson loop
#      on a 100 x 100 grid -- run by `silc run` as a whole process (start-up,
#      assembly, factorization, loop) against Octave's loop alone
#      (bench/crank_nicolson.m timed inside octave-cli with tic/toc and
#      cputime, Octave's own start and its assembly excluded); both print
#      sum(u).  silc's time is split into parts by running the script also
#      stopped after 0, 1 and 2 steps, and the optional older silc's whole
#      process is measured in the same rounds.  Skipped, saying so, without
#      octave-cli.
#
#     sh bench/startup.sh BUILD_DIR [ROUNDS [LOOP_ROUNDS [OLD_SILC OLD_LIBSILC_DIR]]]
#
# Defaults: 40 rounds for table 1, 5 for table 2.  Needs a C compiler and
# /usr/bin/python3 (the timing loop).
set -eu
BUILD=$1
ROUNDS=${2:-40} LOOP_ROUNDS=${3:-5} OLD=${4:-} OLD_LIB=${5:-}
HERE=$(cd "$(dirname "$0")" && pwd)
SILC=$BUILD/tools/silc
export OPENBLAS_NUM_THREADS="${OPENBLAS_NUM_THREADS:-1}" OMP_NUM_THREADS="${OMP_NUM_THREADS:-1}"
TMP=$(mktemp -d /tmp/silc-startup.XXXXXX)
trap 'rm -rf "$TMP"' EXIT
printf 'int main(void) { return 0; }\n' >"$TMP/empty.c"
cc -O2 "$TMP/empty.c" -o "$TMP/empty"
# the libraries silc links (ldd's paths), and with readline and tinfo
libs=$(ldd "$SILC" | awk '$3 ~ /^\// && $1 !~ /^(libc|ld-linux)/ {print $3}')
rpath=$(for l in $libs; do dirname "$l"; done | sort -u | tr '\n' ':' | sed 's/:$//')
cc -O2 "$TMP/empty.c" -o "$TMP/empty_silc_libs" -Wl,--no-as-needed $libs -Wl,-rpath,"$rpath"
cc -O2 "$TMP/empty.c" -o "$TMP/empty_silc_libs_rl" -Wl,--no-as-needed $libs -lreadline -Wl,-rpath,"$rpath"

/usr/bin/python3 - "$TMP" "$SILC" "$ROUNDS" "$LOOP_ROUNDS" "$HERE" "$OLD" "$OLD_LIB" <<'EOF'
import os, shutil, statistics, sys, time

tmp, silc, rounds, loop_rounds, here, old, old_lib = sys.argv[1:8]
rounds, loop_rounds = int(rounds), int(loop_rounds)


def run(argv, env=None, out=None):
    """Runs argv once: (wall s, CPU s of the process and its children, stdout)."""
    out = out or os.path.join(tmp, "out")
    actions = [(os.POSIX_SPAWN_OPEN, 0, "/dev/null", os.O_RDONLY, 0),
               (os.POSIX_SPAWN_OPEN, 1, out, os.O_WRONLY | os.O_CREAT | os.O_TRUNC, 0o600),
               (os.POSIX_SPAWN_OPEN, 2, "/dev/null", os.O_WRONLY, 0)]
    t0 = time.perf_counter()
    pid = os.posix_spawn(argv[0], argv, env or os.environ, file_actions=actions)
    _, status, ru = os.wait4(pid, 0)
    wall = time.perf_counter() - t0
    if status != 0:
        sys.exit("startup.sh: %s exited with status %d" % (" ".join(argv), status))
    with open(out) as f:
        return wall, ru.ru_utime + ru.ru_stime, f.read()


def measure(rows, n):
    """rows: (label, argv, env); n alternating rounds; medians per row."""
    times = {label: ([], []) for label, _, _ in rows}
    for _ in range(n):
        for label, argv, env in rows:
            wall, cpu, _ = run(argv, env)
            times[label][0].append(wall)
            times[label][1].append(cpu)
    return [(label, statistics.median(times[label][0]), statistics.median(times[label][1])) for label, _, _ in rows]


def load():
    with open("/proc/loadavg") as f:
        return f.read().split()[0]


# ---- 1. start-up -----------------------------------------------------------
rows = [("empty C program", [os.path.join(tmp, "empty")], None),
        ("empty C program linked to silc's libraries", [os.path.join(tmp, "empty_silc_libs")], None),
        ("  the same + readline, tinfo", [os.path.join(tmp, "empty_silc_libs_rl")], None),
        ("silc --version", [silc, "--version"], None)]
if old:
    env = dict(os.environ, LD_LIBRARY_PATH=old_lib) if old_lib else None
    rows.append(("silc -e 'x = 1;' (old build)", [old, "-e", "x = 1;"], env))
rows.append(("silc -e 'x = 1;'", [silc, "-e", "x = 1;"], None))
before = load()
res = measure(rows, rounds)
print("start-up: medians of %d alternating rounds (%d cores, load average %s before, %s after)"
      % (rounds, os.cpu_count(), before, load()))
print("%-44s %9s %7s %9s %7s" % ("program", "wall ms", "ratio", "CPU ms", "ratio"))
base = res[0]
for label, wall, cpu in res:
    print("%-44s %9.2f %6.2fx %9.2f %6.2fx" % (label, wall * 1e3, wall / base[1], cpu * 1e3, cpu / base[2]))

# ---- 2. the Crank-Nicolson loop against Octave's ----------------------------
octave = shutil.which("octave-cli")
script = os.path.join(here, "crank_nicolson.silc")
print()
if not octave:
    print("loop: skipped: octave-cli is not installed (apt-get install octave)")
    sys.exit(0)
# Where silc's time goes: the same script stopped after 0, 1 and 2 steps
# (start-up and assembly; the first solve, with a matrix never seen; the
# second, the first that reuses it), measured in the same rounds.
partial = []
with open(script) as f:
    text = f.read()
for steps in (0, 1, 2):
    path = os.path.join(tmp, "cn_%d.silc" % steps)
    with open(path, "w") as f:
        # stopped by a break, not a shorter loop: the solves take the path
        # of the whole run's (a loop with passes left factors at its first
        # solve; a last pass is a one-shot solve, docs/backends.md)
        f.write(text.replace("for step = 1:100", "for step = 1:100\n  if step > %d\n    break\n  end" % steps))
    partial.append(([silc, "run", path], ([], [])))
before = load()
silc_t, oct_t, old_t = ([], []), ([], []), ([], [])
silc_sum = oct_sum = old_sum = None
old_env = dict(os.environ, LD_LIBRARY_PATH=old_lib) if old and old_lib else None
for _ in range(loop_rounds):
    wall, cpu, out = run([silc, "run", script])
    silc_t[0].append(wall), silc_t[1].append(cpu)
    silc_sum = out.split("=")[-1].strip()
    if old:  # the older silc's whole process, in the same rounds
        wall, cpu, out = run([old, "run", script], old_env)
        old_t[0].append(wall), old_t[1].append(cpu)
        old_sum = out.split("=")[-1].strip()
    for argv, (walls, cpus) in partial:
        wall, cpu, _ = run(argv)
        walls.append(wall), cpus.append(cpu)
    _, _, out = run([octave, "-q", os.path.join(here, "crank_nicolson.m")])
    words = out.split()  # octave loop WALL CPU SUM
    oct_t[0].append(float(words[2])), oct_t[1].append(float(words[3]))
    oct_sum = words[4]
sw, sc = statistics.median(silc_t[0]), statistics.median(silc_t[1])
ow, oc = statistics.median(oct_t[0]), statistics.median(oct_t[1])
print("Crank-Nicolson, 100 x 100 grid, 100 steps: medians of %d alternating rounds (load average %s before, %s after)"
      % (loop_rounds, before, load()))
print("%-44s %9s %9s %22s" % ("", "wall s", "CPU s", "sum(u)"))
print("%-44s %9.3f %9.3f %22s" % ("silc run crank_nicolson.silc (whole process)", sw, sc, silc_sum))
print("%-44s %9.3f %9.3f %22s" % ("Octave's loop alone (inside octave-cli)", ow, oc, oct_sum))
print("%-44s %8.1fx %8.1fx" % ("Octave's loop / silc's whole process", ow / sw, oc / sc))
if old:
    aw, ac = statistics.median(old_t[0]), statistics.median(old_t[1])
    print("%-44s %9.3f %9.3f %22s" % ("  the same, old build", aw, ac, old_sum))
    print("%-44s %8.1fx %8.1fx" % ("  Octave's loop / the old build's", ow / aw, oc / ac))
    print("%-44s %8.2fx %8.2fx" % ("  old build / silc", aw / sw, ac / sc))
print("silc's whole process by part (differences of medians: the script stopped after 0, 1, 2 steps)")
start = res[-1]  # silc -e 'x = 1;' of table 1
prev = (start[1], start[2])
print("%-44s %9.3f %9.3f" % ("  start-up (silc -e 'x = 1;', table 1)", prev[0], prev[1]))
for label, (_, (walls, cpus)) in zip(("  assembly (0 steps)", "  step 1 (first solve with A)",
                                       "  step 2 (second solve with A)"), partial):
    cur = (statistics.median(walls), statistics.median(cpus))
    print("%-44s %9.3f %9.3f" % (label, cur[0] - prev[0], cur[1] - prev[1]))
    prev = cur
print("%-44s %9.3f %9.3f" % ("  steps 3-100", sw - prev[0], sc - prev[1]))
EOF
