#!/usr/bin/env python3
"""mpi_wake.py -- what resting ranks cost a request (docs/distributed.md,
"An idle server rests").

The ranks of `mpirun -np 2 silcd --mpi` other than 0 wait for the next
command without spinning (server/mpi_server.c, await_header): they test an
MPI_Ibcast in a loop for 2 ms after a command, then nap from 50 us doubling
to 1 ms.  A request that comes after an idle period therefore waits for a
napping rank; one that follows another closely does not.  This bench times
the same small collective request (`n = x' * x` on a vector split between
the ranks) back to back ("under load") and after 0.2 s of idleness ("after
idle"), and does the same against the forking silcd in the same run, whose
difference is the cost of idleness that is not MPI's (the client's and the
server's caches and scheduler wake-ups).  The table gives medians and the
added latency after idle, MPI's share being the difference of the two.

    /usr/bin/python3 bench/mpi_wake.py [BUILD_DIR]   (default build; ~40 s)
    env: LOAD (requests back to back, default 400), IDLE (requests after
         idle, default 40)
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


def main():
    work = tempfile.mkdtemp(prefix="silc-mpi-wake.")
    rows = {}
    for name, mpi in (("silcd (forking, baseline)", False), ("mpirun -np 2 silcd --mpi", True)):
        proc, url = start(work, mpi)
        try:
            rows[name] = measure(url)
        finally:
            proc.terminate()
            proc.wait(60)
    print("| server | under load, median (ms) | after 0.2 s idle, median (ms) | added after idle (ms) |")
    print("| --- | --- | --- | --- |")
    for name, (load, idle) in rows.items():
        print("| %s | %.3f | %.3f | %+.3f |" % (name, load * 1e3, idle * 1e3, (idle - load) * 1e3))
    (fl, fi), (ml, mi) = rows.values()
    print("\nMPI's share of the latency added after idle: %+.3f ms (target < 1 ms); "
          "under load, --mpi / forking: %.2fx (%d and %d requests)"
          % (((mi - ml) - (fi - fl)) * 1e3, ml / fl, LOAD, IDLE))


main()
