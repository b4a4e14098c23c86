#!/usr/bin/env python3
"""mpi_wake.py -- what resting ranks cost: CPU while idle, and latency added
to the first request after an idle period (docs/distributed.md, "An idle
server rests").

The ranks of `mpirun -np 2 silcd --mpi` other than 0 wait for the next
command in poll() on a wake-up socket that rank 0 writes a byte to before
each command (server/mpi_server.c, await_wake), after looking for it
without sleeping for 2 ms after the last command.  A request that comes
after an idle period therefore pays a wake-up of the resting rank; one
that follows another closely does not.  This bench
 - reads each rank's CPU time (utime + stime, /proc/PID/stat) over IDLE_S
   seconds with no request, after one session has computed;
 - times the same small collective request (`n = x' * x` on a vector split
   between the ranks) back to back ("under load") and after 0.2 s of
   idleness ("after idle"), and does the same against the forking silcd in
   the same run, whose difference is the cost of idleness that is not
   MPI's (the client's and the server's caches and scheduler wake-ups).
The table gives medians and the added latency after idle, MPI's share
being the difference of the two.

    /usr/bin/python3 bench/mpi_wake.py [BUILD_DIR]   (default build; ~50 s)
    env: LOAD (requests back to back, default 400), IDLE (requests after
         idle, default 40), IDLE_S (seconds of the CPU reading, default 10)
"""
import os
import statistics
import subprocess
import sys
import tempfile
import time

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
BUILD = sys.argv[1] if len(sys.argv) > 1 else os.path.join(ROOT, "build")
sys.path.insert(0, os.path.join(ROOT, "bindings", "python"))
import numpy as np  # noqa: E402
from silc._remote import RemoteSession  # noqa: E402

LOAD = int(os.environ.get("LOAD", "400"))
IDLE = int(os.environ.get("IDLE", "40"))
IDLE_S = float(os.environ.get("IDLE_S", "10"))
for k, v in (("OPENBLAS_NUM_THREADS", "1"), ("OMP_NUM_THREADS", "1"),
             ("OMPI_ALLOW_RUN_AS_ROOT", "1"), ("OMPI_ALLOW_RUN_AS_ROOT_CONFIRM", "1"),
             ("OMPI_MCA_rmaps_base_oversubscribe", "1")):
    os.environ.setdefault(k, v)
os.environ.pop("SILC_SERVER", None)


def start(work, mpi):
    sock = os.path.join(work, "mpi.sock" if mpi else "fork.sock")
    ready = sock + ".ready"
    cmd = [os.path.join(BUILD, "server", "silcd"), "--listen", "unix:" + sock,
           "--ready-file", ready, "--log-level", "warn", "--dist-min-rows", "2"]
    if mpi:
        cmd = ["mpirun", "-np", "2", cmd[0], "--mpi"] + cmd[1:]
    else:
        cmd = cmd[:-2]
    log = open(sock + ".log", "w")
    proc = subprocess.Popen(cmd, stdout=log, stderr=subprocess.STDOUT, stdin=subprocess.DEVNULL)
    end = time.monotonic() + 60
    while not os.path.exists(ready):
        if proc.poll() is not None or time.monotonic() > end:
            sys.exit("mpi_wake.py: %s did not start (see %s.log)" % (cmd[0], sock))
        time.sleep(0.1)
    return proc, "unix:" + sock


def measure(url):
    s = RemoteSession(url)
    s.put("x", np.ones((1000, 1)))
    for _ in range(20):
        s.exec("n = x' * x")
    if s.get("n")[0, 0] != 1000:
        sys.exit("mpi_wake.py: x'x is not 1000")
    load = []
    for _ in range(LOAD):
        t = time.perf_counter()
        s.exec("n = x' * x")
        load.append(time.perf_counter() - t)
    idle = []
    for _ in range(IDLE):
        time.sleep(0.2)
        t = time.perf_counter()
        s.exec("n = x' * x")
        idle.append(time.perf_counter() - t)
    s.close()
    return statistics.median(load), statistics.median(idle)


def rank_pids(proc):
    """{rank: pid} of the silcd ranks under mpirun proc."""
    out, todo = {}, [proc.pid]
    while todo:
        parent = todo.pop()
        for d in os.listdir("/proc"):
            if not d.isdigit():
                continue
            try:
                with open("/proc/%s/stat" % d) as f:
                    if int(f.read().rsplit(")", 1)[1].split()[1]) != parent:
                        continue
                with open("/proc/%s/environ" % d, "rb") as f:
                    env = f.read().split(b"\0")
            except OSError:
                continue
            todo.append(int(d))
            for e in env:
                if e.startswith(b"OMPI_COMM_WORLD_RANK="):
                    out[int(e.split(b"=")[1])] = int(d)
    return out


def cpu_seconds(pid):
    with open("/proc/%d/stat" % pid) as f:
        fields = f.read().rsplit(")", 1)[1].split()
    return (int(fields[11]) + int(fields[12])) / os.sysconf("SC_CLK_TCK")


def idle_cpu(proc, url):
    """Each rank's share of a core over IDLE_S seconds of rest."""
    s = RemoteSession(url)
    s.put("x", np.ones((1000, 1)))
    s.exec("n = x' * x")
    ranks = rank_pids(proc)
    time.sleep(0.5)
    before = {r: cpu_seconds(p) for r, p in ranks.items()}
    t = time.monotonic()
    time.sleep(IDLE_S)
    wall = time.monotonic() - t
    used = {r: (cpu_seconds(p) - before[r]) / wall for r, p in ranks.items()}
    s.close()
    return used


def main():
    work = tempfile.mkdtemp(prefix="silc-mpi-wake.")
    rows = {}
    for name, mpi in (("silcd (forking, baseline)", False), ("mpirun -np 2 silcd --mpi", True)):
        proc, url = start(work, mpi)
        try:
            if mpi:
                idle = idle_cpu(proc, url)
            rows[name] = measure(url)
        finally:
            proc.terminate()
            proc.wait(60)
    print("| rank of mpirun -np 2 silcd --mpi | CPU over %g s idle (%% of a core) |" % IDLE_S)
    print("| --- | --- |")
    for r in sorted(idle):
        print("| %d | %.2f |" % (r, 100 * idle[r]))
    print()
    print("| server | under load, median (ms) | after 0.2 s idle, median (ms) | added after idle (ms) |")
    print("| --- | --- | --- | --- |")
    for name, (load, idle_t) in rows.items():
        print("| %s | %.3f | %.3f | %+.3f |" % (name, load * 1e3, idle_t * 1e3, (idle_t - load) * 1e3))
    (fl, fi), (ml, mi) = rows.values()
    print("\nMPI's share of the latency added after idle: %+.3f ms (target < 1 ms); "
          "under load, --mpi / forking: %.2fx (%d and %d requests)"
          % (((mi - ml) - (fi - fl)) * 1e3, ml / fl, LOAD, IDLE))


main()
