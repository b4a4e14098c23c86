"""limits.py -- the attack suite's cases for the limits a session cannot
pass (docs/security.md, "Limits"; registered by tests/security/limits.cmake):
hostile PUTs that announce 2 GiB and send nothing, a runaway `while` loop
against --max-request-seconds and --max-cpu, a client SIGKILLed during a
runaway, two orphaned runaways against --max-clients 2, SIGTERM with
runaways, a request's temporaries against --max-session-bytes, the memo's
kept results and their factorizations against it, the factorizations of
bound values (distributed ones under --mpi) against it, and a statement
text over the cap.  Each case starts its own silcd (or `mpirun
-np 2 silcd --mpi`) on a Unix socket in the build directory and stops it.

    python3 limits.py BINDINGS_DIR STATEDIR CASE SILCD [MPIRUN]

Every wait is bounded; the only time asserted is the requirement's own:
a session whose client is SIGKILLed is gone within 1 s (checked with 0.5 s
of slack, in 50 ms steps).
"""
import atexit
import os
import re
import select
import signal
import socket
import struct
import subprocess
import sys
import time

import numpy as np

BINDINGS, STATEDIR, CASE, SILCD = sys.argv[1:5]
MPIRUN = sys.argv[5] if len(sys.argv) > 5 else None
sys.path.insert(0, BINDINGS)
from silc._remote import GET, OK, PUT, RemoteSession, _DESC, _HEADER, _HELLO  # noqa: E402
from silc._values import DENSE, SilcError  # noqa: E402

RUNAWAY = "x = 1\nwhile (1) { x = 1 }"
MiB = 1 << 20


SERVERS = []


def fail(msg):
    print("FAIL: " + msg)
    sys.exit(1)


@atexit.register
def _no_server_left():
    """A failed case leaves no server behind (its sessions die with it)."""
    for p in SERVERS:
        if p.poll() is None:
            p.kill()
            p.wait()


# Under AddressSanitizer (CI's second pass, slow unwinder) a process's exit
# includes LeakSanitizer's scan of every rank: seconds, not milliseconds.  The
# claims below are "stops", not "stops fast"; exits get this much more time.
SANITIZED = "ASAN_OPTIONS" in os.environ
EXIT_SLACK = 4 if SANITIZED else 1


def wait_until(pred, seconds, step=0.05):
    end = time.monotonic() + seconds
    while time.monotonic() < end:
        if pred():
            return True
        time.sleep(step)
    return pred()


def proc_status(pid, field):
    """A /proc/PID/status field in bytes (kB fields), None if pid is gone."""
    try:
        with open("/proc/%d/status" % pid) as f:
            for line in f:
                if line.startswith(field + ":"):
                    return int(line.split()[1]) * 1024
    except (FileNotFoundError, ProcessLookupError):
        return None
    return None


def alive(pid):
    try:
        with open("/proc/%d/stat" % pid) as f:
            return f.read().rsplit(")", 1)[1].split()[0] != "Z"
    except (FileNotFoundError, ProcessLookupError):
        return False


def children(pid):
    out = []
    for d in os.listdir("/proc"):
        if not d.isdigit():
            continue
        try:
            with open("/proc/%s/stat" % d) as f:
                fields = f.read().rsplit(")", 1)[1].split()
        except OSError:
            continue
        if int(fields[1]) == pid and fields[0] != "Z":
            out.append(int(d))
    return sorted(out)


def descendants(pid):
    out, todo = [], [pid]
    while todo:
        kids = children(todo.pop())
        out += kids
        todo += kids
    return out


class Server:
    """silcd (or mpirun -np 2 silcd --mpi) on a Unix socket of its own."""

    def __init__(self, *args, mpi=False, listen=None):
        self.mpi = mpi
        os.makedirs(STATEDIR, exist_ok=True)
        self.sock = os.path.join(STATEDIR, CASE + ".sock")
        ready = os.path.join(STATEDIR, CASE + ".ready")
        self.logpath = os.path.join(STATEDIR, CASE + ".log")
        for p in (self.sock, ready):
            if os.path.exists(p):
                os.unlink(p)
        cmd = [SILCD, "--listen", listen or "unix:" + self.sock, "--ready-file", ready,
               "--log-level", "info"] + list(args)
        if mpi:
            cmd = [MPIRUN, "-np", "2"] + cmd[:1] + ["--mpi"] + cmd[1:]
        self.log = open(self.logpath, "w")
        self.proc = subprocess.Popen(cmd, stdout=self.log, stderr=subprocess.STDOUT,
                                     stdin=subprocess.DEVNULL)
        SERVERS.append(self.proc)
        if not wait_until(lambda: os.path.exists(ready) or self.proc.poll() is not None, 60):
            fail("silcd did not start")
        if self.proc.poll() is not None:
            fail("silcd exited at start:\n" + self.text())
        self.url = open(ready).read().strip() if listen else "unix:" + self.sock

    def text(self):
        self.log.flush()
        with open(self.logpath) as f:
            return f.read()

    def logged(self, line, seconds=None):
        """True once the log holds line.  Under mpirun a rank's lines reach
        the log through mpirun's forwarding, after the reply the client
        already has (seen in CI: the log still ended at session 1's 'open'
        after session 2 had been answered)."""
        return wait_until(lambda: line in self.text(), 5 * EXIT_SLACK if seconds is None else seconds)

    def session(self):
        return RemoteSession(self.url)

    def signal_server(self, sig):
        """To silcd; under mpirun, to rank 0 (which decides for all ranks:
        mpirun itself ends the job when signalled)."""
        if not self.mpi:
            self.proc.send_signal(sig)
            return
        for pid in descendants(self.proc.pid):
            try:
                with open("/proc/%d/environ" % pid, "rb") as f:
                    env = f.read().split(b"\0")
            except OSError:
                continue
            if b"OMPI_COMM_WORLD_RANK=0" in env:
                os.kill(pid, sig)
                return
        fail("rank 0 of silcd --mpi not found")

    def stop(self):
        if self.proc.poll() is None:
            self.signal_server(signal.SIGTERM)
            try:
                self.proc.wait(30 * EXIT_SLACK)
            except subprocess.TimeoutExpired:
                self.proc.kill()
                self.proc.wait()
                fail("silcd did not stop on SIGTERM within %d s:\n%s" % (30 * EXIT_SLACK, self.text()))
        self.log.close()
        return self.proc.returncode

    def stop_cleanly(self):
        """stop(), and fail unless silcd exited 0."""
        if self.stop() != 0:
            fail("silcd exited with %s" % self.proc.returncode)

    def expect_job_ended(self, reason, log_text):
        """The MPI job ends by itself (a rank or rank 0 ended it), with a
        non-zero status and log_text in the log saying why."""
        try:
            self.proc.wait(30 * EXIT_SLACK)
        except subprocess.TimeoutExpired:
            fail("the job still runs %s:\n%s" % (reason, self.text()))
        if self.proc.returncode == 0:
            fail("mpirun exited 0 %s" % reason)
        if log_text not in self.text():
            fail("the log does not say why the job ended:\n" + self.text())
        self.log.close()


def expect_error(fn, text, exact=True):
    try:
        fn()
    except SilcError as e:
        if (str(e) != text) if exact else (text not in str(e)):
            fail("expected the error %r, got %r" % (text, str(e)))
        return str(e)
    fail("expected the error %r, the call succeeded" % text)


def runaway_client(url):
    """A separate process that starts a runaway request and waits for it."""
    code = ("import sys; sys.path.insert(0, %r)\n"
            "from silc._remote import RemoteSession, EXEC\n"
            "s = RemoteSession(%r)\n"
            "s._send(EXEC, %r.encode())\n"
            "print('sent', flush=True)\n"
            "s._reply()\n") % (BINDINGS, url, RUNAWAY)
    p = subprocess.Popen([sys.executable, "-c", code], stdout=subprocess.PIPE,
                         stderr=subprocess.DEVNULL, text=True)
    if not select.select([p.stdout], [], [], 30)[0] or p.stdout.readline().strip() != "sent":
        p.kill()
        fail("the runaway client did not connect")
    # Its EXEC is in the server's socket: the pause lets silcd start it (on
    # a loaded machine the sleep alone, counted from the connection, was
    # once not enough: the EXEC had not been sent when the client died).
    time.sleep(0.3)
    return p


def session_pids(srv, n):
    if not wait_until(lambda: len(children(srv.proc.pid)) >= n, 10):
        fail("expected %d session processes, found %s" % (n, children(srv.proc.pid)))
    return children(srv.proc.pid)


# ---- the cases -----------------------------------------------------------------

def hostile_puts(srv, count):
    """count sessions, each sending a PUT header that announces a 2 GiB dense
    value (16384^2 doubles), 1 MiB of it, and then nothing."""
    m = n = 16384
    hostile = []
    for _ in range(count):
        s = srv.session()
        desc = _DESC.pack(DENSE, 1, m, n, m * n, 0, 0)
        s.sock.sendall(_HEADER.pack(PUT, 0, len(desc) + 1 + m * n * 8) + desc + b"h")
        s.sock.sendall(b"\0" * MiB)
        hostile.append(s)
    return hostile


def case_hostile_put():
    """3 PUTs announcing 2 GiB each, sending 1 MiB and then nothing: each
    session reserves the array (VmData grows by 2 GiB: the header was
    taken) but its resident memory grows by at most a 64 MiB chunk."""
    srv = Server("--max-session-bytes", "3G", "--max-value-bytes", "3G", "--io-timeout", "20")
    idle = srv.session()
    idle.exec("a = 1")
    base_pid = session_pids(srv, 1)[0]
    base_rss = proc_status(base_pid, "VmRSS")
    base_data = proc_status(base_pid, "VmData")
    hostile = hostile_puts(srv, 3)
    pids = [p for p in session_pids(srv, 4) if p != base_pid]
    for pid in pids:
        if not wait_until(lambda: (proc_status(pid, "VmData") or 0) > base_data + (2 << 30) - 64 * MiB, 20):
            fail("session %d never reserved the announced 2 GiB (VmData %s)" %
                 (pid, proc_status(pid, "VmData")))
        rss = proc_status(pid, "VmRSS")
        print("session %d: VmRSS %.1f MiB (an idle session: %.1f MiB)" % (pid, rss / MiB, base_rss / MiB))
        if rss > base_rss + 128 * MiB:
            fail("a PUT announcing 2 GiB made its session resident in %.0f MiB" % (rss / MiB))
    for s in hostile:
        s.sock.close()
    idle.exec("b = a + 1")
    if idle.get("b")[0, 0] != 2:
        fail("the idle session was disturbed")
    idle.close()
    srv.stop_cleanly()


def request_time(mpi):
    srv = Server("--max-request-seconds", "1", mpi=mpi)
    s = srv.session()
    s.exec("keep = 7")
    msg = "request took longer than 1 s: stopped; the store is as before the statement"
    expect_error(lambda: s.exec(RUNAWAY), msg)
    expect_error(lambda: s.exec("keep = keep + 1\nwhile (1) { }"), msg)   # an empty loop too
    if s.get("keep")[0, 0] != 7:
        fail("keep changed by the stopped request")
    if "x" in s.names():
        fail("'x', assigned in the stopped request, is bound")
    s.exec("y = keep * 2")       # the session goes on
    if s.get("y")[0, 0] != 14:
        fail("the session did not go on after a stopped request")
    s.close()
    srv.stop_cleanly()


def case_request_time():
    request_time(False)


def case_request_time_mpi():
    request_time(True)


def case_max_cpu():
    srv = Server("--max-cpu", "1")
    s = srv.session()
    s.exec("keep = 1")
    expect_error(lambda: s.exec(RUNAWAY), "CPU time a session may use (silcd --max-cpu)",
                 exact=False)
    s.sock.close()
    other = srv.session()      # the server and other sessions go on
    other.exec("z = 3")
    other.close()
    srv.stop_cleanly()


def case_disconnect():
    srv = Server()
    c = runaway_client(srv.url)
    pid = session_pids(srv, 1)[0]
    c.kill()
    t0 = time.monotonic()
    c.wait()
    if not wait_until(lambda: not alive(pid), 1.5):
        fail("the session of a SIGKILLed client still runs after 1.5 s")
    print("session gone %.2f s after its client was SIGKILLed" % (time.monotonic() - t0))
    srv.stop_cleanly()


def case_disconnect_mpi():
    """One process serves every session: the runaway must stop for another
    client to be answered at all."""
    srv = Server(mpi=True)
    c = runaway_client(srv.url)
    c.kill()
    c.wait()
    s = srv.session()
    s.exec("a = 41 + 1")
    if s.get("a")[0, 0] != 42:
        fail("wrong answer after the runaway stopped")
    s.close()
    if not srv.logged("the client disconnected: request stopped"):
        fail("the log does not say the runaway was stopped:\n" + srv.text())
    srv.stop_cleanly()


def case_max_clients():
    srv = Server("--max-clients", "2")
    runaways = [runaway_client(srv.url) for _ in range(2)]
    pids = session_pids(srv, 2)
    for c in runaways:
        c.kill()
        c.wait()
    if not wait_until(lambda: not any(alive(p) for p in pids), 1.5):
        fail("orphaned runaways still run after 1.5 s")
    s = srv.session()
    s.exec("a = 2 * 21")
    if s.get("a")[0, 0] != 42:
        fail("the third client got a wrong answer")
    s.close()
    srv.stop_cleanly()


def sigterm(mpi):
    """Two runaways (one under --mpi: its rank 0 serves one request at a
    time, so a second client would wait for the first)."""
    srv = Server(mpi=mpi)
    runaways = [runaway_client(srv.url) for _ in range(1 if mpi else 2)]
    kids = descendants(srv.proc.pid) if mpi else session_pids(srv, 2)
    srv.signal_server(signal.SIGTERM)
    try:
        srv.proc.wait(10 * EXIT_SLACK)
    except subprocess.TimeoutExpired:
        srv.proc.kill()
        fail("silcd still runs %d s after SIGTERM with runaways:\n%s" % (10 * EXIT_SLACK, srv.text()))
    if srv.proc.returncode != 0:
        fail("silcd exited with %s:\n%s" % (srv.proc.returncode, srv.text()))
    if any(alive(p) for p in kids):
        fail("session processes outlived silcd")
    if "stopped" not in srv.text().splitlines()[-1]:
        fail("silcd's last line is not 'stopped':\n" + srv.text())
    for c in runaways:
        try:
            c.wait(10 * EXIT_SLACK)   # told, or its connection closed
        except subprocess.TimeoutExpired:
            c.kill()
            fail("a runaway's client was left waiting after silcd stopped")
    srv.log.close()


def case_sigterm():
    sigterm(False)


def case_sigterm_mpi():
    sigterm(True)


def case_parent_killed():
    """A session process dies with silcd (PR_SET_PDEATHSIG)."""
    srv = Server()
    c = runaway_client(srv.url)
    pid = session_pids(srv, 1)[0]
    srv.proc.kill()
    srv.proc.wait()
    if not wait_until(lambda: not alive(pid), 5):
        fail("a session process outlived its SIGKILLed silcd")
    c.kill()
    c.wait()
    srv.log.close()


def peak(mpi):
    """Temporaries count: zeros(1000) holds 8 MB; with a 20 MB session
    limit, a statement that ends binding a scalar but holds 24 MB at once
    (a, d, ones(1000), their sum) is refused, and its whole request rolled
    back."""
    srv = Server("--max-session-bytes", "20M", mpi=mpi)
    s = srv.session()
    s.exec("a = zeros(1000)")
    expect_error(lambda: s.exec("d = 5\nb = sum(a + ones(1000) + ones(1000))"),
                 "session memory limit exceeded: statement 2: reference: a 1000x1000 dense value "
                 "would bring the values held at once (bound and temporary) to 24000008 bytes "
                 "(22.9 MiB), over the limit of 20971520 bytes (20.0 MiB) by 2.9 MiB (the "
                 "session's limit, silcd --max-session-bytes); the whole request was rolled back")
    if "b" in s.names() or "d" in s.names():
        fail("a name bound by a request refused at its peak")
    s.exec("c = sum(a + 1)")     # a and one temporary: 16 MB at once, under the limit
    if float(s.get("c").sum()) != 1e6:
        fail("the entries of sum(a + 1) do not add up to 1e6")
    s.close()
    srv.stop_cleanly()


def case_peak():
    peak(False)


def case_peak_mpi():
    peak(True)


def laplacian(k, i):
    """The i-th of the attached cases' distinct 2-D Laplacians (SPD, k^2
    rows; its Cholesky factor holds about 5 times its entries) and the
    right-hand side whose solution is 1, 2, ..., k^2."""
    import scipy.sparse
    T = scipy.sparse.diags([-1.0, 2.0 + 0.01 * i, -1.0], [-1, 0, 1], shape=(k, k))
    I = scipy.sparse.identity(k)
    A = (scipy.sparse.kron(T, I) + scipy.sparse.kron(I, T)).tocsr()
    return A, A @ np.arange(1.0, k * k + 1.0)


def info_bytes(s):
    """INFO's `bytes:`, what the session is charged."""
    info = dict(line.split(": ", 1) for line in s.info().splitlines() if ": " in line)
    return int(info["bytes"])


def case_memo():
    """Issue 33: the memo's results, and the factorizations attached to them,
    count against --max-session-bytes and go first when it is reached.
    30 rounds of `B = A * c` twice (the second is kept by the memo), a
    UMFPACK solve with B (its LU hangs off the memo's value), then `clear B`
    grew a 16 MiB session from 9 to 629 MiB.  Now the session's charge
    (INFO's bytes: bound values, the memo's results and what hangs off
    them) stays within the limit after every round, its resident memory
    stays bounded, and every x is right."""
    k = 100
    n = k * k
    A = laplacian(k, 0)[0]   # the 2-D Laplacian
    limit = 16 * MiB
    srv = Server("--max-session-bytes", str(limit))
    s = srv.session()
    s.put("A", A)
    s.exec("b = A * ones(%d, 1)" % n)   # x = ones / c exactly
    pid = session_pids(srv, 1)[0]
    rss = []
    for r in range(1, 31):
        s.exec('c = %d\nB = A * c\nB = A * c\nx = solve(B, b, "backend = suitesparse.umfpack")\n'
               'clear B\nerr = norm(x * c - ones(%d, 1), inf)' % (r, n))
        err = float(s.get("err")[0, 0])
        if not err < 1e-9:
            fail("round %d: |x c - 1| = %g" % (r, err))
        charge = info_bytes(s)
        if charge > limit:
            fail("round %d: the session holds %d bytes, over its limit of %d" % (r, charge, limit))
        if r == 1:
            # bound: A, b, x, c, err; the memo keeps B (no name holds it) and
            # its LU: the charge must count B's arrays at least
            csr = (n + 1) * 8 + A.nnz * 16
            bound = csr + 2 * n * 8 + 2 * 8
            if charge < bound + csr:
                fail("the memo's B is not charged: %d bytes, the bound values alone hold %d" % (charge, bound))
        rss.append(proc_status(pid, "VmRSS"))
        print("round %2d: charge %.1f MiB, VmRSS %.1f MiB" % (r, charge / MiB, rss[-1] / MiB))
    # Under AddressSanitizer freed memory sits in its quarantine (256 MiB):
    # resident memory says nothing there; the charge above still holds.
    if not SANITIZED and rss[-1] > rss[2] + 64 * MiB:
        fail("the session grew from %.0f MiB (round 3) to %.0f MiB (round 30)" %
             (rss[2] / MiB, rss[-1] / MiB))
    s.close()
    srv.stop_cleanly()


def check_resolves(s, count, n):
    """After the attached cases' rounds: a re-solve with the last matrix
    reuses its factorization; one with A0, whose factorization was
    released, factors again; both are right."""
    for i, reused in ((count - 1, "yes"), (0, "no")):
        s.exec("y = A%d \\ (2 * b%d)" % (i, i))
        y = s.get("y").ravel()
        if not np.abs(y - 2 * np.arange(1.0, n + 1.0)).max() < 1e-8 * n:
            fail("the re-solve of A%d is wrong" % i)
        if "reused factorization: %s" % reused not in s.info("y"):
            fail("re-solve of A%d: expected 'reused factorization: %s':\n%s" % (i, reused, s.info("y")))


def case_attached():
    """Issue 27: a factorization hung on a bound value counts against
    --max-session-bytes.  16 distinct 2-D Laplacians (SPD: CHOLMOD), each
    PUT under its own name and solved once, used to keep 16 factorizations
    (several times each matrix) that only RLIMIT_DATA bounded: the session
    grew past its limit with every value inside it.  Now the session's
    charge (INFO's bytes: values, memo, attached state) stays under the
    limit, the least recently used factorizations are released, every
    solve is right, a re-solve of a released one factors again and is
    right, and an estimate owed on a released factorization says so."""
    k, count = 60, 16
    n = k * k
    limit = 8 * MiB
    srv = Server("--max-session-bytes", str(limit))
    s = srv.session()
    s.exec("set accuracy.condest = on_request")    # every estimate owed until `info` reads it
    pid = session_pids(srv, 1)[0]
    values = 0
    rss = []
    for i in range(count):
        A, b = laplacian(k, i)
        s.put("A%d" % i, A)
        s.put("b%d" % i, b.reshape(-1, 1))
        s.exec("x%d = A%d \\ b%d" % (i, i, i))
        x = s.get("x%d" % i).ravel()
        res = np.abs(A @ x - b).max() / np.abs(b).max()
        if not res < 1e-12:
            fail("round %d: relative residual %g" % (i, res))
        csr = (n + 1) * 8 + A.nnz * 16
        values += csr + 2 * n * 8          # A, b and x, as the session stores them
        charge = info_bytes(s)
        if charge > limit:
            fail("round %d: the session holds %d bytes, over its limit of %d" % (i, charge, limit))
        if i == 0:
            # What the solve attached, as measured: the factorization is
            # several times the matrix; kept for all 16 matrices, the
            # session would hold far more than its limit.
            attached = charge - values
            unbounded = count * (csr + 2 * n * 8 + attached)
            print("one matrix: %d bytes, its factorization: %d bytes; kept for all: %.1f MiB"
                  % (csr, attached, unbounded / MiB))
            if attached < 2 * csr:
                fail("the factorization of A0 is charged %d bytes, under twice the matrix (%d)"
                     % (attached, csr))
            if unbounded < 2 * limit:
                fail("the case cannot fail: every factorization kept holds %d bytes" % unbounded)
        rss.append(proc_status(pid, "VmRSS"))
        print("round %2d: charge %.2f MiB (values %.2f), VmRSS %.1f MiB"
              % (i, charge / MiB, values / MiB, rss[-1] / MiB))
    # The estimate owed on A0's released factorization says so; the last
    # one, still attached, is computed when read.
    first = s.info("x0")
    if "deferred at solve time, and the factorization was released before the report was read" \
            not in first:
        fail("info x0 after its factorization was released:\n" + first)
    last = s.info("x%d" % (count - 1))
    if "computed when the report was first read" not in last:
        fail("info of the last solve, its factorization still attached:\n" + last)
    check_resolves(s, count, n)
    # Resident memory from round 1 on (CHOLMOD's workspace is made in round
    # 0): the values grow it, and every factorization kept would grow it
    # by as much again as they (measured 21 MiB, against 10 MiB now).  It
    # must stay under the values' growth plus half the factorizations'.
    # Under AddressSanitizer freed memory sits in its quarantine: the
    # charge above holds there.
    grown, kept_values = rss[-1] - rss[1], (count - 2) * (csr + 2 * n * 8)
    if not SANITIZED and grown > kept_values + (count - 2) * attached / 2:
        fail("the session grew by %.1f MiB from round 1, its values by %.1f MiB, the "
             "factorizations kept would add %.1f MiB" % (grown / MiB, kept_values / MiB,
                                                          (count - 2) * attached / MiB))
    s.close()
    srv.stop_cleanly()


def case_attached_huge():
    """A factorization on huge pages is charged as one on malloc's pages.
    SuiteSparse's work space of 4 MiB and more comes from SILC's large
    allocator (suitesparse.huge_pages = auto), whose mappings glibc's
    mallinfo2 does not see: uncounted, a session could hold any number of
    UMFPACK factorizations past --max-session-bytes.  The same matrix is
    solved by UMFPACK in two sessions, huge pages on and off, and each
    session's charge for what the solve attached must agree within 25 %
    and exceed the matrix itself."""
    k = 150
    n = k * k
    A, b = laplacian(k, 0)
    csr = (n + 1) * 8 + A.nnz * 16
    srv = Server("--max-session-bytes", str(256 * MiB))
    charged = {}
    for mode in ("auto", "off"):
        s = srv.session()
        s.exec("set accuracy.condest = on_request")
        s.put("A", A)
        s.put("b", b.reshape(-1, 1))
        before = info_bytes(s)
        s.exec('x = solve(A, b, "backend = suitesparse.umfpack; suitesparse.huge_pages = %s")' % mode)
        x = s.get("x").ravel()
        if not np.abs(A @ x - b).max() / np.abs(b).max() < 1e-12:
            fail("huge_pages = %s: the solve is wrong" % mode)
        charged[mode] = info_bytes(s) - before - n * 8
        print("huge_pages = %s: the factorization is charged %.1f MiB (the matrix %.1f MiB)"
              % (mode, charged[mode] / MiB, csr / MiB))
        s.close()
    if charged["off"] < 2 * csr:
        fail("the case cannot fail: UMFPACK's factorization is charged %d bytes with malloc's pages"
             % charged["off"])
    if not 0.75 * charged["off"] <= charged["auto"] <= 1.25 * charged["off"]:
        fail("the factorization is charged %d bytes on huge pages, %d on malloc's"
             % (charged["auto"], charged["off"]))
    srv.stop_cleanly()


def case_attached_mpi():
    """Issue 27 under `mpirun -np 2 silcd --mpi`: distributed factorizations
    count too.  16 distinct 2-D Laplacians of 2500 rows, PUT (so split in
    row blocks over the two ranks) and each solved once by MUMPS on both
    ranks' blocks, used to leave 16 factorizations in parts on both ranks,
    bounded by RLIMIT_DATA only.  Now each is charged the sum of its parts,
    rank 0 chooses what gives way (least recently used first) and both
    ranks let go of the same factorizations together (a MUMPS instance
    ends collectively: ranks that disagreed would hang): INFO's bytes stay
    under the limit after every round, every solve is right, and a re-solve
    of A0 factors again, collectively, and is right.  Under
    AddressSanitizer, whose slow unwinding of every malloc costs a MUMPS
    factorization about 5 s there, 9 of them under a 5 MiB limit (room for
    the values and one factorization, as 16 under 8 MiB)."""
    k = 50
    count, limit = (9, 5 * MiB) if SANITIZED else (16, 8 * MiB)
    n = k * k
    srv = Server("--max-session-bytes", str(limit), mpi=True)
    s = srv.session()
    pids = rank_pids(srv)
    rss = {rank: [] for rank in pids}
    for i in range(count):
        A, b = laplacian(k, i)
        s.put("A%d" % i, A)
        s.put("b%d" % i, b.reshape(-1, 1))
        before = info_bytes(s)
        s.exec("x%d = A%d \\ b%d" % (i, i, i))
        x = s.get("x%d" % i).ravel()   # rank 0 keeps the gathered x with its block: counted
        res = np.abs(A @ x - b).max() / np.abs(b).max()
        if not res < 1e-12:
            fail("round %d: relative residual %g" % (i, res))
        charge = info_bytes(s)
        if charge > limit:
            fail("round %d: the session holds %d bytes, over its limit of %d" % (i, charge, limit))
        if i == 0:
            report = s.info("x0")
            if "backend: mumps" not in report or "distributed" not in report:
                fail("x0 was not solved by MUMPS on distributed blocks:\n" + report)
            # Rank 0 holds A0 and b0 (each whole and its block) before the
            # solve; the solve adds x0 (its block and, after the GET, its
            # whole copy: under 2 n doubles) and the factorization's charge.
            csr = (n + 1) * 8 + A.nnz * 16
            attached = charge - before - 2 * n * 8
            unbounded = count * charge   # each round's values and factorization, all kept
            print("one matrix: %d bytes, its factorization (both ranks' parts): %d bytes; "
                  "kept for all: %.1f MiB" % (csr, attached, unbounded / MiB))
            if attached < 2 * csr:
                fail("the factorization of A0 is charged %d bytes, under twice the matrix (%d)"
                     % (attached, csr))
            if unbounded < 3 * limit:
                fail("the case cannot fail: every factorization kept holds %d bytes" % unbounded)
            # What each rank's values grow by in a round: rank 0's as
            # charged; rank 1 holds its row blocks of A, b and x.
            m1 = int(re.search(r"rank 1: (\d+) rows", report).group(1))
            first = n - m1
            rank_values = {0: charge - attached,
                           1: (m1 + 1) * 8 + A[first:].nnz * 16 + 2 * m1 * 8}
        for rank, pid in pids.items():
            rss[rank].append(proc_status(pid, "VmRSS"))
        print("round %2d: charge %.2f MiB, VmRSS rank 0 %.1f MiB, rank 1 %.1f MiB"
              % (i, charge / MiB, rss[0][-1] / MiB, rss[1][-1] / MiB))
    check_resolves(s, count, n)
    # Each rank lets go of its parts: from round 1 on (MUMPS's first
    # instance set up what the others reuse), each rank's resident memory
    # grows by its values and under half of the parts that keeping every
    # factorization would add (measured: 7.1 and 4.1 MiB, against 16 and
    # 13 MiB with every part kept; parts taken as half of each charge).
    # Under AddressSanitizer freed memory sits in its quarantine: the
    # charge above holds there.
    for rank in sorted(pids):
        grown = rss[rank][-1] - rss[rank][1]
        values, parts = (count - 2) * rank_values[rank], (count - 2) * attached / 2
        print("rank %d: grew %.1f MiB from round 1; values %.1f MiB, every part kept %.1f MiB more"
              % (rank, grown / MiB, values / MiB, parts / MiB))
        if not SANITIZED and grown > values + parts / 2:
            fail("rank %d grew by %.1f MiB from round 1: its values by %.1f MiB, and more than half "
                 "of the %.1f MiB of factorization parts it would keep without letting go"
                 % (rank, grown / MiB, values / MiB, parts / MiB))
    s.close()
    srv.stop_cleanly()


def data_limit(pid):
    """The soft RLIMIT_DATA of pid, in bytes (/proc/PID/limits)."""
    with open("/proc/%d/limits" % pid) as f:
        for line in f:
            if line.startswith("Max data size"):
                soft = line.split()[3]
                if soft == "unlimited":
                    fail("process %d has no RLIMIT_DATA" % pid)
                return int(soft)
    fail("no 'Max data size' in /proc/%d/limits" % pid)


def data_cap(mpi):
    """Issue 27, item 4: each session process (under --mpi, each rank) has
    an RLIMIT_DATA cap: what it had mapped at its start (at most its
    VmData now) + 2 x --max-session-bytes for each session it may hold
    + --array-pool + 256 MiB."""
    limit, pool, clients = 64 * MiB, 32 * MiB, 4
    srv = Server("--max-session-bytes", str(limit), "--array-pool", str(pool),
                 "--max-clients", str(clients), mpi=mpi)
    s = srv.session()
    s.exec("x = 1")
    pids = rank_pids(srv).values() if mpi else session_pids(srv, 1)
    for pid in pids:
        want = (clients if mpi else 1) * 2 * limit + pool + 256 * MiB
        cap, base = data_limit(pid), proc_status(pid, "VmData")
        if not want <= cap <= want + base:
            fail("process %d: RLIMIT_DATA %d, expected %d + its start's data (at most %d)"
                 % (pid, cap, want, base))
    s.close()
    srv.stop_cleanly()


def case_data_cap():
    data_cap(False)


def case_data_cap_mpi():
    data_cap(True)


def library_output(mpi):
    """What a library prints during a request goes to its client, not to
    silcd's standard output (the operator's log): PETSc's
    -ksp_converged_reason and a deprecated option's warning used to land
    in silcd's log.  -log_view and -help stay refused (a session must not
    read PETSc's process-wide table, nor name a file)."""
    srv = Server("--max-session-bytes", "64M", mpi=mpi)
    s = srv.session()
    s.exec("A = sparse(eye(50) * 4 - 1); b = ones(50, 1)")
    out = []
    s.exec('set petsc.options = -ksp_type cg -ksp_converged_reason -ksp_compute_eigenvalues\n'
           'x = solve(A, b, "backend = petsc")\nr = norm(A * x - b, inf)', out=out)
    text = "".join(out)
    for said in ("Linear solve converged due to", "-ksp_compute_eigenvalues is deprecated"):
        if said not in text:
            fail("the client did not get PETSc's %r: %r" % (said, text))
        if said in srv.text():
            fail("PETSc's %r reached silcd's log:\n%s" % (said, srv.text()))
    if not s.get("r")[0, 0] < 1e-8:
        fail("the PETSc solve is wrong: |A x - b| = %g" % s.get("r")[0, 0])
    # A request that prints nothing gets no library text.
    out = []
    s.exec("y = 2 * 3", out=out)
    if out:
        fail("library output for a request that printed nothing: %r" % out)
    for opt in ("-log_view", "-help"):
        expect_error(lambda: s.exec("set petsc.options = %s" % opt),
                     "petsc.options: '%s' is refused in a silcd session: options that "
                     "view, monitor, log, dump, name a file, load code or set threads are server "
                     "settings (set them in silcd's config)" % opt)
    s.close()
    srv.stop_cleanly()


def case_library_output():
    library_output(False)


def case_library_output_mpi():
    library_output(True)


def statement_cap(mpi):
    srv = Server(mpi=mpi)
    s = srv.session()
    text = "a = [" + ",".join(["1"] * (2 << 20)) + "]"    # 4 MiB of text
    expect_error(lambda: s.exec(text), "statement text of %d bytes is over the limit of %d "
                 "bytes: split it, or PUT large data as a value" % (len(text), 4 << 20))
    s.exec("a = [1, 2, 3]")
    s.close()
    srv.stop_cleanly()


def case_statement_cap():
    statement_cap(False)


def case_statement_cap_mpi():
    statement_cap(True)


def stuck_server(*args, mpi=False):
    """A server whose sessions have the "crash" plugin (tests/server/crash_plugin.c)
    first for scaling: `y = 17 * [1; 2]` never returns by itself."""
    conf = os.path.join(STATEDIR, CASE + ".conf")
    with open(conf, "w") as f:
        f.write("[core]\nplugin_path = %s\n[dispatch]\nadd = crash, reference\n"
                % os.environ["STUCK_PLUGIN_DIR"])
    return Server("--config", conf, *args, mpi=mpi)


def case_stuck_forced():
    """A call that never asks is ended by the session's timer 2 s past the
    limit: its process dies, and silcd tells the client which limit."""
    srv = stuck_server("--max-request-seconds", "1")
    s = srv.session()
    s.exec("y = 3 * [1; 2]")
    if s.get("y")[1, 0] != 6:
        fail("the crash plugin's scale is wrong")
    expect_error(lambda: s.exec("y = 17 * [1; 2]"),
                 "session 1 lost: the server process running it died of signal 14 (%s): its "
                 "request took longer than 1 s and did not stop within 2 s more (it was inside "
                 "a library call) (silcd --max-request-seconds); its values are gone, other "
                 "sessions are unaffected" % signal.strsignal(signal.SIGALRM))
    s.sock.close()
    other = srv.session()
    other.exec("z = 1")
    other.close()
    srv.stop_cleanly()


def case_stuck_cooperative():
    """A call that asks host->cancelled() stops at the limit; the session
    and its store go on as before the statement."""
    srv = stuck_server("--max-request-seconds", "1")
    s = srv.session()
    s.exec("y = 3 * [1; 2]")
    expect_error(lambda: s.exec("w = 1\ny = 19 * [1; 2]"),
                 "request took longer than 1 s: stopped; the store is as before the statement")
    if s.get("y")[1, 0] != 6 or "w" in s.names():
        fail("the store changed in a stopped request")
    s.close()
    srv.stop_cleanly()


def case_stuck_disconnect():
    """A client SIGKILLed while its session is stuck in a call that never
    asks: silcd kills the session, gone within 1 s (0.5 s slack)."""
    srv = stuck_server()
    code = ("import sys; sys.path.insert(0, %r)\n"
            "from silc._remote import RemoteSession\n"
            "s = RemoteSession(%r)\n"
            "print('connected', flush=True)\n"
            "s.exec('y = 17 * [1; 2]')\n") % (BINDINGS, srv.url)
    c = subprocess.Popen([sys.executable, "-c", code], stdout=subprocess.PIPE,
                         stderr=subprocess.DEVNULL, text=True)
    if not select.select([c.stdout], [], [], 30)[0] or c.stdout.readline().strip() != "connected":
        c.kill()
        fail("the client did not connect")
    pid = session_pids(srv, 1)[0]
    time.sleep(0.3)
    c.kill()
    c.wait()
    if not wait_until(lambda: not alive(pid), 1.5):
        fail("a stuck session of a SIGKILLed client still runs after 1.5 s")
    srv.stop_cleanly()


# ---- silcd --mpi: ranks at rest, limits that end the job, rank 0's reader ------

def rank_pids(srv):
    """{rank: pid} of the silcd ranks under mpirun."""
    out = {}
    for pid in descendants(srv.proc.pid):
        try:
            with open("/proc/%d/environ" % pid, "rb") as f:
                env = f.read().split(b"\0")
        except OSError:
            continue
        for e in env:
            if e.startswith(b"OMPI_COMM_WORLD_RANK="):
                out[int(e.split(b"=")[1])] = pid
    if len(out) != 2:
        fail("expected ranks 0 and 1 under mpirun, found %s" % out)
    return out


def cpu_seconds(pid):
    with open("/proc/%d/stat" % pid) as f:
        fields = f.read().rsplit(")", 1)[1].split()
    return (int(fields[11]) + int(fields[12])) / os.sysconf("SC_CLK_TCK")


def case_idle_cpu_mpi():
    """An idle `mpirun -np 2 silcd --mpi` rests: rank 1 waits in poll() on
    its wake-up socket from rank 0 (the log says it has one), so over 3 s
    with no request each rank uses under 0.05 s of CPU (utime + stime from
    /proc; spinning in MPI used 99 % of a core, testing MPI_Ibcast with
    naps 2-4 %, i.e. 0.06-0.12 s).  A request after the rest is answered
    rightly, and again after a second rest."""
    srv = Server("--dist-min-rows", "2", mpi=True)
    if not srv.logged("1 of 1 ranks rest on a wake-up socket"):
        fail("rank 1 has no wake-up socket:\n" + srv.text())
    s = srv.session()
    s.exec("x = [1; 2; 3; 4]")          # split among the ranks: both took part
    ranks = rank_pids(srv)
    for rest in range(2):
        time.sleep(0.5)
        before = {r: cpu_seconds(p) for r, p in ranks.items()}
        time.sleep(3)
        for r, p in sorted(ranks.items()):
            used = cpu_seconds(p) - before[r]
            print("rest %d, rank %d: %.3f s of CPU in 3 s" % (rest, r, used))
            if used > 0.05:
                fail("rank %d used %.3f s of CPU in 3 s idle (bound 0.05 s)" % (r, used))
        s.exec("n = x' * x + %d" % rest)
        if s.get("n")[0, 0] != 30 + rest:
            fail("x'x + %d of [1;2;3;4] after a rest is not %d" % (rest, 30 + rest))
    s.close()
    srv.stop_cleanly()


def case_max_cpu_mpi():
    """--max-cpu under --mpi caps each rank over the job's life: resting
    ranks do not reach it, a runaway does, and the rank that dies says why
    before mpirun ends the job."""
    cap = 5 if SANITIZED else 2   # rank start-up counts too
    srv = Server("--max-cpu", str(cap), mpi=True)
    s = srv.session()
    s.exec("a = 1")
    time.sleep(cap + 1)                  # longer than the cap, at rest
    s.exec("b = a + 1")
    if s.get("b")[0, 0] != 2:
        fail("the server was not serving after resting past --max-cpu")
    try:
        s.exec(RUNAWAY)
        fail("the runaway returned")
    except (SilcError, OSError):
        pass
    srv.expect_job_ended("after a rank reached --max-cpu",
                         "s of CPU time a rank may use (silcd --max-cpu): ending the MPI job")


def case_stuck_mpi():
    """A call stuck inside a library under --mpi cannot be stopped alone:
    rank 0 ends the job 2 s past --max-request-seconds and says why; the
    client's connection closes (the supervisor restarts silcd).  3 s: the
    small requests before it must not reach the limit on a busy machine."""
    srv = stuck_server("--max-request-seconds", "3", mpi=True)
    s = srv.session()
    s.exec("y = 3 * [1; 2]")
    if s.get("y")[1, 0] != 6:
        fail("the crash plugin's scale is wrong")
    try:
        s.exec("y = 17 * [1; 2]")
        fail("the stuck call returned")
    except (SilcError, OSError):
        pass
    srv.expect_job_ended("with a stuck request",
                         "took longer than 3 s and did not stop within 2 s more (it is inside a library "
                         "call) (silcd --max-request-seconds): ending the MPI job")


HELLO = b"SILC" + struct.pack("<II", 1, 0)


def raw(srv):
    c = socket.socket(socket.AF_UNIX, socket.SOCK_STREAM)
    c.connect(srv.sock)
    return c


def answered(c):
    """Whether the server has written to (or closed) c."""
    return bool(select.select([c], [], [], 0)[0])


def case_admission_mpi():
    """Rank 0 reads every connection at once: a stalled PUT, a connection
    that sends nothing and a hello trickling a byte at a time do not stop
    another session's EXEC, which is answered while the three still stall;
    then each of the three completes and is served; a PUT over
    --max-value-bytes is refused and its session goes on."""
    srv = Server("--io-timeout", "60", "--handshake-timeout", "60", "--max-value-bytes", "1M",
                 mpi=True)
    put = srv.session()
    put.exec("keep = 5")
    desc = _DESC.pack(DENSE, 1, 1000, 1, 1000, 0, 0)
    body = struct.pack("<1000d", *range(1000))
    put.sock.sendall(_HEADER.pack(PUT, 0, len(desc) + 1 + len(body)) + desc + b"v" + body[:100])
    silent = raw(srv)
    trickle = raw(srv)
    trickle.sendall(HELLO[:1])
    other = srv.session()                # its handshake, then its requests
    for k in range(2, 5):
        trickle.sendall(HELLO[k - 1:k])
        other.exec("a = 40 + %d" % k)
    if other.get("a")[0, 0] != 44:
        fail("the other session's answer is wrong")
    for name, c in (("stalled PUT", put.sock), ("silent connection", silent),
                    ("trickling hello", trickle)):
        if answered(c):
            fail("the %s was answered or closed before it completed" % name)
    put.sock.sendall(body[100:])         # the PUT completes: stored, in step
    put._reply()
    put.exec("s = sum(v)")
    if put.get("s")[0, 0] != sum(range(1000)) or put.get("keep")[0, 0] != 5:
        fail("the completed PUT was not stored rightly")
    trickle.sendall(HELLO[4:])
    reply = b""
    while len(reply) < 12:
        chunk = trickle.recv(12 - len(reply))
        if not chunk:
            fail("the trickled hello was refused:\n" + srv.text())
        reply += chunk
    if not reply.startswith(b"SILC"):
        fail("the trickled hello got %r" % reply)
    # A PUT refused from its descriptor: its 2 MB of arrays are dropped
    # unread as they come, and the session stays in step.
    expect_error(lambda: other.put("big", np.ones((1000, 250))), "per value (silcd "
                 "--max-value-bytes)", exact=False)
    other.exec("c = a + 1")
    if other.get("c")[0, 0] != 45 or "big" in other.names():
        fail("the session was not in step after a refused PUT")
    for c in (silent, trickle):
        c.close()
    put.close()
    other.close()
    srv.stop_cleanly()


def case_hostile_put_mpi():
    """Issue 27's hostile-PUT case under silcd --mpi: 3 sessions each announce
    a 2 GiB value (within the limits given), send 1 MiB and then nothing.
    One process (rank 0) reads every connection, so it must not take the
    announcement at its word: its peak memory grows with the bytes that
    arrived (3 MiB and the buffers' slack), not by 6 GiB, and a fourth
    session is served meanwhile."""
    srv = Server("--max-session-bytes", "3G", "--max-value-bytes", "3G", "--io-timeout", "20", mpi=True)
    r0 = rank_pids(srv)[0]
    idle = srv.session()
    idle.exec("a = 1")
    base = proc_status(r0, "VmHWM")
    hostile = hostile_puts(srv, 3)
    idle.exec("b = a + 1")                 # served while the three wait for their bytes
    if idle.get("b")[0, 0] != 2:
        fail("the idle session was disturbed")
    time.sleep(0.5)
    grown = proc_status(r0, "VmHWM") - base
    print("rank 0's VmHWM grew by %.1f MiB after 3 PUTs announcing 2 GiB each (1 MiB sent each)"
          % (grown / MiB))
    if grown > 3 * 64 * MiB + 16 * MiB:
        fail("3 PUTs announcing 2 GiB each raised rank 0's peak memory by %.0f MiB" % (grown / MiB))
    for s in hostile:
        s.sock.close()
    idle.exec("c = b + 1")
    if idle.get("c")[0, 0] != 3:
        fail("the idle session lost its values after the hostile PUTs closed")
    idle.close()
    srv.stop_cleanly()


def case_announce_mpi():
    """A PUT header announcing 256 MiB (81 bytes sent) does not raise rank
    0's peak memory by more than a few MiB: its buffer grows with the bytes
    that arrive.  A hello trickling a byte every 0.3 s is closed at
    --handshake-timeout, however long it would go on."""
    srv = Server("--handshake-timeout", "1", mpi=True)
    r0 = rank_pids(srv)[0]
    s = srv.session()
    s.exec("a = 1")
    base = proc_status(r0, "VmHWM")
    hostile = srv.session()
    m = (256 * MiB) // 8
    desc = _DESC.pack(DENSE, 17, m, 1, m, 0, 0)
    hostile.sock.sendall(_HEADER.pack(PUT, 0, len(desc) + 17 + m * 8) + desc + b"h" * 17)
    s.exec("b = a + 1")                  # served after the header was read
    time.sleep(0.5)
    grown = proc_status(r0, "VmHWM") - base
    print("rank 0's VmHWM grew by %.1f MiB after a header announcing 256 MiB" % (grown / MiB))
    if grown > 8 * MiB:
        fail("a header announcing 256 MiB raised rank 0's peak memory by %.0f MiB" % (grown / MiB))
    trickle = raw(srv)
    closed = False
    end = time.monotonic() + 20 * EXIT_SLACK
    k = 0
    while time.monotonic() < end and not closed:
        try:
            if k < len(HELLO) - 1:       # never the last byte
                trickle.sendall(HELLO[k:k + 1])
        except OSError:
            closed = True
            break
        k += 1
        if select.select([trickle], [], [], 0.3)[0]:
            closed = trickle.recv(64) == b""
    if not closed:
        fail("a trickling hello was not closed at --handshake-timeout:\n" + srv.text())
    # mpirun forwards the ranks' output: the line may come a little later.
    if not wait_until(lambda: "no handshake within 1 s, closed (--handshake-timeout)"
                      in srv.text(), 10 * EXIT_SLACK):
        fail("the log does not say why the trickling hello was closed:\n" + srv.text())
    if s.get("b")[0, 0] != 2:
        fail("the session's answer is wrong")
    hostile.sock.close()
    s.close()
    srv.stop_cleanly()


def stall_get(srv, rows):
    """A session that stores a rows x 1000 matrix, asks for it back and
    never reads the reply (the raw GET frame on its socket).  The matrix,
    for the caller to compare."""
    s = srv.session()
    x = np.arange(rows * 1000, dtype=np.float64).reshape(rows, 1000)
    s.put("big", x)
    s.sock.sendall(_HEADER.pack(GET, 0, 3) + b"big")
    return s, x


def recv_exact(sock, n, seconds):
    sock.settimeout(seconds)
    out = bytearray()
    while len(out) < n:
        chunk = sock.recv(min(n - len(out), 1 << 20))
        if not chunk:
            break
        out += chunk
    return bytes(out)


def case_unread_get_mpi():
    """Rank 0 writes replies as clients read them: a client that asks for
    a 16 MB value and does not read does not stall another client, whose
    handshake and requests are answered while the first still holds its
    reply unread; the first then reads its whole value, exact.  A client
    that never reads is dropped at --io-timeout and the server goes on."""
    srv = Server("--io-timeout", "60", mpi=True)
    stalled, x = stall_get(srv, 2000)
    time.sleep(0.5)                      # rank 0 has written what the socket takes
    other = RemoteSession(srv.url, timeout=30)
    other.exec("a = 6 * 7")
    if other.get("a")[0, 0] != 42:
        fail("the other client's answer is wrong")
    if "waiting for the peer to read a reply" in srv.text():
        fail("the stalled client was dropped before the other was served:\n" + srv.text())
    head = recv_exact(stalled.sock, _HEADER.size + _DESC.size, 30)
    op, _, length = _HEADER.unpack(head[:_HEADER.size])
    _fmt, _nl, m, n, _nnz, _kl, _ku = _DESC.unpack(head[_HEADER.size:])
    if (op, m, n, length) != (130, 2000, 1000, _DESC.size + x.nbytes):
        fail("the stalled GET's reply header: op %d, %d x %d, %d bytes" % (op, m, n, length))
    body = recv_exact(stalled.sock, x.nbytes, 30)
    got = np.frombuffer(body, dtype=np.float64)
    if got.size != x.size or not np.array_equal(got.reshape(1000, 2000).T, x):
        fail("the stalled GET's value, read late, differs from the one stored")
    stalled.sock.settimeout(30)
    stalled.exec("b = 1")                # the session goes on in step
    stalled.close()
    other.close()
    srv.stop_cleanly()
    # --io-timeout: a client that never reads is dropped; the server serves on.
    srv = Server("--io-timeout", "1", mpi=True)
    stalled, _ = stall_get(srv, 2000)
    if not wait_until(lambda: "timed out after 1000 ms waiting for the peer to read a reply "
                      "(--io-timeout): closed" in srv.text(), 20 * EXIT_SLACK):
        fail("a client that never read its GET was not dropped at --io-timeout:\n" + srv.text())
    s = srv.session()
    s.exec("c = 2 + 3")
    if s.get("c")[0, 0] != 5:
        fail("the server's answer after dropping the stalled client is wrong")
    s.close()
    stalled.sock.close()
    srv.stop_cleanly()


def case_idle_timeout_mpi():
    """--idle-timeout under --mpi: a session idle past it is closed (its
    engine on both ranks) and its client told why; an active session is
    not; a new one computes."""
    srv = Server("--idle-timeout", "1", mpi=True)
    idle = srv.session()
    idle.exec("x = 1")
    busy = srv.session()
    end = time.monotonic() + 2.5
    k = 0
    while time.monotonic() < end:        # requests closer than 1 s apart
        busy.exec("y = %d" % k)
        k += 1
        time.sleep(0.2)
    # What the idle client's next read finds (this client would write
    # first, into the closed socket): the reason, then the end.
    head = recv_exact(idle.sock, _HEADER.size, 10)
    op, _, n = _HEADER.unpack(head) if len(head) == _HEADER.size else (None, 0, 0)
    msg = recv_exact(idle.sock, n, 10).decode()
    if (op, msg) != (129, "session closed: idle for 1 s (silcd --idle-timeout); its values are gone"):
        fail("the idle client read %s %r" % (op, msg))
    if recv_exact(idle.sock, 1, 10) != b"":
        fail("the idle session's connection stayed open")
    if busy.get("y")[0, 0] != k - 1:
        fail("the active session lost its value")
    if not srv.logged("session 1: session closed: idle for 1 s (silcd --idle-timeout)"):
        fail("the log does not say why session 1 was closed:\n" + srv.text())
    busy.close()
    s = srv.session()
    s.exec("z = [1; 2] * 3")
    if s.get("z")[1, 0] != 6:
        fail("a new session after the timeout computes wrongly")
    s.close()
    srv.stop_cleanly()


def tcp_hello(port, token, source="127.0.0.1"):
    """A raw handshake from source: (socket, reply op, reply text)."""
    c = socket.create_connection(("127.0.0.1", port), timeout=30, source_address=(source, 0))
    tok = token.encode()
    c.sendall(_HELLO.pack(b"SILC", 1, len(tok)) + tok)
    recv_exact(c, _HELLO.size, 30)
    head = recv_exact(c, _HEADER.size, 30)
    if len(head) < _HEADER.size:
        return c, None, ""
    op, _, n = _HEADER.unpack(head)
    return c, op, recv_exact(c, n, 30).decode()


def case_peer_share_mpi():
    """--peer-share under --mpi, by the forking server's rules (srv_admit):
    300 silent connections from 127.0.0.1 hold at most its share, each
    newcomer closing the oldest silent one, so a real client from 127.0.0.1
    gets in; a peer whose share is all open sessions is refused with the
    reason, and another address still gets in."""
    tok = os.path.join(STATEDIR, CASE + ".token")
    if os.path.exists(tok):
        os.unlink(tok)
    subprocess.run([SILCD, "--make-token", tok], check=True, stdout=subprocess.DEVNULL)
    token = open(tok).readline().strip()
    os.makedirs(STATEDIR, exist_ok=True)
    srv = Server("--max-clients", "64", "--peer-share", "0.5", "--handshake-timeout", "60",
                 "--token-file", tok, mpi=True, listen="tcp://127.0.0.1:0")
    port = int(srv.url.rsplit(":", 1)[1])
    silent = [socket.create_connection(("127.0.0.1", port), timeout=30) for _ in range(300)]
    c, op, text = tcp_hello(port, token)
    if op != OK:
        fail("a real client behind 300 silent connections from its address: %s %r" % (op, text))
    c.close()
    if not wait_until(lambda: "closed unauthenticated to make room (--peer-share 0.5 of "
                      "--max-clients 64)" in srv.text(), 10 * EXIT_SLACK):
        fail("the log does not say silent connections made room:\n" + srv.text())
    open_now = sum(not answered(s) for s in silent[-10:])
    closed = sum(answered(s) and s.recv(1) == b"" for s in silent[:10])
    if (open_now, closed) != (10, 10):
        fail("of 300 silent connections, the newest 10: %d open; the oldest 10: %d closed"
             % (open_now, closed))
    for s in silent:
        s.close()
    sessions = [RemoteSession(srv.url, token=token, timeout=30) for _ in range(32)]
    expect_error(lambda: RemoteSession(srv.url, token=token, timeout=30),
                 "server busy: 127.0.0.1 holds 32 open sessions, its share of 32 (silcd "
                 "--peer-share 0.5 of --max-clients)", exact=False)
    c, op, text = tcp_hello(port, token, source="127.0.0.2")
    if op != OK:
        fail("127.0.0.2 while 127.0.0.1 holds its share: %s %r" % (op, text))
    c.close()
    sessions[0].exec("q = 4 * 4")
    if sessions[0].get("q")[0, 0] != 16:
        fail("a session at the share computes wrongly")
    for s in sessions:
        s.close()
    srv.stop_cleanly()


globals()["case_" + CASE]()
print("ok: " + CASE)
