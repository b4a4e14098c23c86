"""clients.py -- hostile replies against every client (docs/security.md,
"Replies a client gets"; issue 33): a fake silcd on a Unix socket in the
build directory speaks the handshake, then answers each request with the
case's hostile reply (complex values too: a complex descriptor whose arrays
have a real value's size, and a complex value sent to a plain GET, which
asks for real values only).  The client under test runs as its own process (the
C runner clients_c and the Fortran runner once per case, one Python child
and one JVM for all cases), does the calls the case names and prints one line per call, "OK ..." or
"ERROR <type>: <message>"; this script checks the exact error, that it is
the client's own type, that the message names the socket, that the
process exited by itself (no signal) and, for the Python client, that no
lying header made it allocate.

    python3 clients.py CLIENT WORKDIR [RUNNER ARGS...]
    CLIENT: c | fortran | python | java

Prints "N passed, N failed" last and exits 1 on a failure.
"""
import os
import resource
import socket
import struct
import subprocess
import sys
import threading
import time

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, os.path.join(HERE, ".."))
from pychecks import check, done  # noqa: E402

HEADER = struct.Struct("<IIQ")
DESC = struct.Struct("<IIqqqqq")
OK, ERROR, VALUE, TEXT = 128, 129, 130, 131
BYE = 8


def frame(op, body, length=None):
    return HEADER.pack(op, 0, len(body) if length is None else length) + body


def value(fmt, m, n, nnz, kl=0, ku=0, arrays=b"", length=None):
    body = DESC.pack(fmt, 0, m, n, nnz, kl, ku) + arrays
    return frame(VALUE, body, length)


def i64(*xs):
    return struct.pack("<%dq" % len(xs), *xs)


def f64(*xs):
    return struct.pack("<%dd" % len(xs), *xs)


SCALAR = value(0, 1, 1, 1, arrays=f64(7.0))
COMPLEX = 16                     # the format bit of a complex value
ZSCALAR = value(0 | COMPLEX, 1, 1, 1, arrays=f64(1.0, 2.0))
# 512 x 512 dense, 2 MiB: over the 1 MiB cap the runner sets for over_cap.
BIG = value(0, 512, 512, 512 * 512, arrays=bytes(8 * 512 * 512))

# case: (calls the client makes, replies to them in order (None: silence,
# "close": hang up), expected per call (a substring; "OK" for success),
# environment for the client).  Every hostile reply keeps the connection
# open afterwards, so a client that waits for more hangs (and the test's
# timeout says so) instead of passing.
CASES = {
    "csr_rowptr": (["get:A"], [value(1, 2, 3, 1, arrays=i64(0, 5, 1) + i64(0) + f64(1.0))],
                   ["rowptr decreases at row 1 (rowptr[1] = 5 > rowptr[2] = 1)"], {}),
    "csr_index": (["get:A"], [value(1, 2, 3, 1, arrays=i64(0, 1, 1) + i64(99) + f64(1.0))],
                  ["column index 99 out of range [0, 3) in row 0"], {}),
    "bad_nnz": (["get:A"], [value(0, 2, 2, -1, length=DESC.size + 32)],
                ["negative size in value descriptor (m = 2, n = 2, nnz = -1"], {}),
    "length_mismatch": (["get:A"], [value(0, 2, 2, 4, arrays=f64(1, 2), length=DESC.size + 16)],
                        ["VALUE reply carries 16 bytes of arrays, its descriptor needs 32"], {}),
    "huge_text": (["exec:x = 1"], [HEADER.pack(TEXT, 0, 1 << 30) + b"abc"],
                  ["TEXT reply of 1073741824 bytes exceeds the limit of 67108864 bytes"], {}),
    "band_huge": (["get:B"], [value(2, 30000, 30000, 30000, arrays=f64(*([1.0] * 30000)))],
                  ["OK band 30000x30000 kl=0 ku=0"], {}),
    "over_cap": (["get:big", "get:k"], [BIG, SCALAR],
                 ["(SILC_MAX_REPLY_BYTES", "OK dense 1x1 7"], {"SILC_MAX_REPLY_BYTES": "1M"}),
    "silent": (["get:A"], [None], ["sent nothing for 1 s (SILC_IO_TIMEOUT"],
               {"SILC_IO_TIMEOUT": "1"}),
    "silent_hello": (["get:A"], [], ["sent nothing for 1 s (SILC_IO_TIMEOUT"],
                     {"SILC_IO_TIMEOUT": "1"}),
    "stall": (["get:A"], [value(0, 2, 2, 4, arrays=f64(1.0) + b"\0\0\0", length=DESC.size + 32),
                          None],
              ["stopped sending in the middle of a reply"], {"SILC_IO_TIMEOUT": "1"}),
    "silent_exec": (["exec:x = 1"], [None], ["sent nothing for 1 s (SILC_EXEC_TIMEOUT"],
                    {"SILC_EXEC_TIMEOUT": "1"}),
    "unknown_op": (["get:A"], [frame(77, b"zz")], ["unknown reply opcode 77"], {}),
    # Complex values (issue 31): "getc:" asks GET_COMPLEX.  A complex
    # descriptor counts 16 bytes an entry, so arrays sized for a real value
    # contradict it; a plain GET must never receive a complex value.
    "complex_size": (["getc:Z"], [value(0 | COMPLEX, 2, 2, 4, arrays=f64(1, 2, 3, 4), length=DESC.size + 32)],
                     ["VALUE reply carries 32 bytes of arrays, its descriptor needs 64"], {}),
    "complex_csr_size": (["getc:Z"], [value(1 | COMPLEX, 2, 2, 1, arrays=i64(0, 1, 1) + i64(0) + f64(1.0),
                                            length=DESC.size + 40)],
                         ["VALUE reply carries 40 bytes of arrays, its descriptor needs 48"], {}),
    "complex_to_get": (["get:Z"], [ZSCALAR], ["a complex value in reply to a GET"], {}),
    "complex_ok": (["getc:Z"], [ZSCALAR], ["OK complex dense 1x1 1 2"], {}),
    # Not hostile: a server older than complex values refuses GET_COMPLEX;
    # Python's get, which always asks it, then asks the plain GET, and the
    # session goes on.
    "old_server": (["get:k", "get:k"], [frame(ERROR, b"unknown request opcode 10"), SCALAR, SCALAR],
                   ["OK dense 1x1 7", "OK dense 1x1 7"], {}),
    # Not hostile: an EXEC that computes longer than the I/O timeout must
    # not be cut off by it (only SILC_EXEC_TIMEOUT bounds that wait).
    "slow_exec": (["exec:x = 1"], [("delay", 1.5, frame(OK, b""))], ["OK exec"],
                  {"SILC_IO_TIMEOUT": "1"}),
    "closed": (["get:A"], [value(0, 2, 2, 4, arrays=f64(1.0), length=DESC.size + 32), "close"],
               ["connection closed by peer"], {}),
}


# Cases for some clients only (the others have no such behaviour to test).
ONLY = {"old_server": ("python",)}

# Where a client's answer differs by design: Java has no band type, so a
# band value comes back dense only under the cap, and this one (7.2 GB
# dense) is refused, the session going on.
WANT_FOR = {("java", "band_huge"): ["(SILC_MAX_REPLY_BYTES"],
            # The Python client's get always asks GET_COMPLEX (it takes
            # either field), so a complex reply to it is welcome.
            ("python", "complex_to_get"): ["OK complex dense 1x1 1 2"]}


class FakeServer:
    """One connection at a time on a Unix socket: the hello, then the
    case's replies, one per request (after them, silence until the client
    hangs up)."""

    def __init__(self, path, case):
        self.path = path
        self.case = case
        if os.path.exists(path):
            os.unlink(path)
        self.sock = socket.socket(socket.AF_UNIX, socket.SOCK_STREAM)
        self.sock.bind(path)
        self.sock.listen(4)
        self.thread = threading.Thread(target=self.serve, daemon=True)
        self.thread.start()

    @staticmethod
    def recv_exact(c, n):
        buf = b""
        while len(buf) < n:
            got = c.recv(n - len(buf))
            if not got:
                raise EOFError
            buf += got
        return buf

    def serve(self):
        while True:
            try:
                c, _ = self.sock.accept()
            except OSError:
                return
            try:
                self.session(c)
            except (EOFError, OSError):
                pass
            finally:
                c.close()

    def session(self, c):
        _magic, _version, toklen = struct.unpack("<4sII", self.recv_exact(c, 12))
        self.recv_exact(c, toklen)
        replies = list(CASES[self.case][1])
        if self.case == "silent_hello":
            while c.recv(4096):
                pass
            return
        c.sendall(struct.pack("<4sII", b"SILC", 1, 0) + frame(OK, b"fake silcd"))
        while True:
            op, _flags, length = HEADER.unpack(self.recv_exact(c, HEADER.size))
            self.recv_exact(c, length)
            if op == BYE:
                c.sendall(frame(OK, b""))
                return
            reply = replies.pop(0) if replies else None
            if reply == "close":
                return
            if reply is None:
                while c.recv(4096):      # silent until the client hangs up
                    pass
                return
            if isinstance(reply, tuple):          # ("delay", seconds, bytes)
                time.sleep(reply[1])
                reply = reply[2]
            c.sendall(reply)
            if replies and replies[0] == "close":
                return

    def stop(self):
        self.sock.close()
        os.unlink(self.path)


# The Python client runs every case in one interpreter (numpy and scipy
# load once): argv is BINDINGS, then per case "--case NAME URL K=V... CALL...";
# the case's variables are set for its session only.
PYTHON_RUNNER = r"""
import os, sys
sys.path.insert(0, sys.argv[1])
import silc
args, groups = sys.argv[2:], []
for a in args:
    if a == "--case":
        groups.append([])
    else:
        groups[-1].append(a)
for name, url, *rest in groups:
    print("CASE " + name, flush=True)
    env = dict(a.split("=", 1) for a in rest if "=" in a and ":" not in a)
    calls = [a for a in rest if ":" in a]
    os.environ.update(env)
    try:
        s = silc.Session(url)
    except silc.Error as e:
        print("ERROR %s: %s" % (type(e).__name__, e), flush=True)
        s = None
    for call in calls if s else []:
        op, _, arg = call.partition(":")
        try:
            if op == "exec":
                s.exec(arg, [])
                print("OK exec")
                continue
            v = s._s.get(arg)                # the back end: no shape convention (get and getc alike)
            if hasattr(v, "offsets"):
                print("OK band %dx%d kl=%d ku=%d" % (v.shape + (-min(v.offsets), max(v.offsets))))
            elif hasattr(v, "tocsr"):
                print("OK csr %dx%d nnz %d" % (v.shape + (v.nnz,)))
            elif v.dtype.kind == "c":
                print("OK complex dense %dx%d %g %g" % (v.shape + (v.flat[0].real, v.flat[0].imag)))
            else:
                print("OK dense %dx%d %g" % (v.shape + (v.flat[0],)))
        except silc.Error as e:
            print("ERROR %s: %s" % (type(e).__name__, e))
        except BaseException as e:
            print("ERROR not silc.Error %s: %s" % (type(e).__name__, e))
        sys.stdout.flush()
    if s:
        s.close()
    for k in env:
        del os.environ[k]
"""


def run(cmd, env):
    """(exit status or None if it hung, stdout, stderr, peak RSS in KiB of
    the children so far)."""
    scale = 4 if os.environ.get("ASAN_OPTIONS") else 1
    proc = subprocess.Popen(cmd, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True,
                            env=dict(os.environ, **env))
    try:
        out, err = proc.communicate(timeout=60 * scale)
    except subprocess.TimeoutExpired:
        proc.kill()
        out, err = proc.communicate()
        return None, out, err, 0
    return proc.returncode, out, err, resource.getrusage(resource.RUSAGE_CHILDREN).ru_maxrss


def judge(client, case, path, rc, out, err):
    what = "%s/%s" % (client, case)
    want = WANT_FOR.get((client, case), CASES[case][2])
    if rc is None:
        check(False, "%s: the client hung (killed after the test's timeout); output %r" % (what, out))
        return
    check(rc == 0, "%s: the client exited with %d (negative: a signal); stderr %s"
          % (what, rc, err[-2000:]))
    lines = [ln for ln in out.splitlines() if ln.startswith(("OK", "ERROR"))]
    check(len(lines) == len(want), "%s: %d result lines for %d calls: %r"
          % (what, len(lines), len(want), out))
    for line, expect in zip(lines, want):
        if expect.startswith("OK"):
            check(line.startswith(expect), "%s: got %r, want %r" % (what, line, expect))
        else:
            check(line.startswith("ERROR") and expect in line and path in line,
                  "%s: got %r, want an error with %r naming %s" % (what, line, expect, path))
            check("not silc.Error" not in line and "not SILCException" not in line,
                  "%s: not the client's own error type: %s" % (what, line))


def main(argv):
    client, workdir, tail = argv[1], argv[2], argv[3:]
    os.makedirs(workdir, exist_ok=True)
    cases = ([case for case in CASES if client in ONLY.get(case, (client,))] if client != "fortran"
             else ["csr_index", "complex_size", "complex_to_get"])
    paths = {case: os.path.join(workdir, "%s-%s.sock" % (client, case)) for case in cases}
    if client in ("python", "java"):
        # Every case in one process; Java's limits then come as setters, so
        # one case more runs alone with its limit in the environment.
        servers = [FakeServer(paths[case], case) for case in cases]
        cmd = [sys.executable, "-c", PYTHON_RUNNER, tail[0]] if client == "python" else list(tail)
        for case in cases:
            calls, _replies, _want, env = CASES[case]
            cmd += ["--case", case, "unix:" + paths[case]] + \
                ["%s=%s" % kv for kv in env.items()] + calls
        try:
            rc, out, err, peak = run(cmd, {})
        finally:
            for server in servers:
                server.stop()
        sections = dict((sec.split("\n", 1) + [""])[:2] for sec in out.split("CASE ")[1:])
        for case in cases:
            judge(client, case, paths[case], rc, sections.get(case, ""), err)
        if client == "python":
            # The interpreter with numpy and scipy is ~60 MB; the 1 GiB text
            # header or the band reply as a 7.2 GB dense array would show
            # far above 200 MB.
            check(peak < 200 * 1024, "python: peak memory %d KiB" % peak)
            done()
        cases = ["silent"]
    for case in cases:
        calls, _replies, _want, env = CASES[case]
        url = "unix:" + paths[case]
        if client == "fortran":
            env = dict(env, SILC_SERVER=url)
        server = FakeServer(paths[case], case)
        try:
            rc, out, err, _peak = run(tail + [url] + calls, env)
        finally:
            server.stop()
        judge(client, case, paths[case], rc, out, err)
    done()


if __name__ == "__main__":
    main(sys.argv)
