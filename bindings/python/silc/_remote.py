"""silc._remote -- the wire protocol (docs/protocol.md) in pure Python: a
session on a silcd server, with no C library, so that any machine with
Python and a socket can use SILC.  Arrays travel without extra copies: they
are sent from and received into their numpy buffers.  silc/__init__.py is
the package's front; this is one of its two back ends (_embedded.py the
other).
"""
import os
import signal
import socket
import struct
import sys
import threading

import numpy as np

from ._values import CSR, SilcError, from_parts, to_parts

PROTOCOL_VERSION = 1
PUT, GET, EXEC, DELETE, LIST, INFO, EXPLAIN, BYE, CANCEL = range(1, 10)
OK, ERROR, VALUE, TEXT, WARN = range(128, 133)
_HEADER = struct.Struct("<IIQ")
_HELLO = struct.Struct("<4sII")
_DESC = struct.Struct("<IIqqqqq")
_MAX_TEXT = 1 << 30

if sys.byteorder != "little":
    raise ImportError("silc.py: the wire protocol needs a little-endian host")




def _token_from_env():
    tok = os.environ.get("SILC_TOKEN")
    if tok:
        return tok
    path = os.environ.get("SILC_TOKEN_FILE")
    if path:
        with open(path) as f:
            return f.readline().rstrip("\r\n")
    return None


class RemoteSession:
    """One session on a silcd server: its own names, closed by close()."""

    def __init__(self, url=None, token=None):
        url = url or os.environ.get("SILC_SERVER")
        if not url:
            raise SilcError("no server address: pass one or set SILC_SERVER")
        token = token if token is not None else _token_from_env()
        self.url = url
        self.warnings = ""
        # cancel() writes only while an EXEC waits for its reply (_awaiting),
        # so its frame never lands inside another; reentrant because a
        # SIGINT handler runs on the main thread, maybe inside exec's own
        # critical section.
        self._cancel_lock = threading.RLock()
        self._awaiting = False
        self.sock = self._connect(url)
        tok = (token or "").encode()
        self.sock.sendall(_HELLO.pack(b"SILC", PROTOCOL_VERSION, len(tok)) + tok)
        magic, _version, _ = _HELLO.unpack(self._recv_exact(_HELLO.size))
        if magic != b"SILC":
            raise SilcError("%s is not a SILC server" % url)
        self._reply()

    @staticmethod
    def _connect(url):
        if url.startswith("unix:"):
            path = url[5:]
            if path.startswith("//"):
                path = path[2:]
            s = socket.socket(socket.AF_UNIX, socket.SOCK_STREAM)
            s.connect(path)
            return s
        if not url.startswith("tcp://"):
            raise SilcError("'%s': server address must be tcp://host:port or unix:/path" % url)
        host, _, port = url[6:].rpartition(":")
        host = host.strip("[]")
        s = socket.create_connection((host, int(port)))
        s.setsockopt(socket.IPPROTO_TCP, socket.TCP_NODELAY, 1)
        return s

    # ---- framing ----------------------------------------------------------
    def _recv_into(self, view):
        view = memoryview(view).cast("B")
        while len(view):
            n = self.sock.recv_into(view)
            if n == 0:
                raise SilcError("connection to silc server %s lost" % self.url)
            view = view[n:]

    def _recv_exact(self, n):
        buf = bytearray(n)
        self._recv_into(buf)
        return bytes(buf)

    def _send(self, op, *parts):
        parts = [memoryview(p).cast("B") for p in parts]
        self.sock.sendall(_HEADER.pack(op, 0, sum(len(p) for p in parts)))
        for p in parts:
            if len(p):
                self.sock.sendall(p)

    def _read_value(self, length):
        if length < _DESC.size:
            raise SilcError("VALUE reply shorter than its descriptor")
        fmt, _, m, n, nnz, kl, ku = _DESC.unpack(self._recv_exact(_DESC.size))
        if fmt == CSR:
            arrays = [np.empty(m + 1, dtype=np.int64), np.empty(nnz, dtype=np.int64),
                      np.empty(nnz, dtype=np.float64)]
        else:
            arrays = [np.empty(nnz, dtype=np.float64)]
        for a in arrays:
            self._recv_into(a)
        return from_parts(fmt, m, n, kl, ku, arrays)

    def _reply(self, out=None):
        """Reads replies up to the final one; returns its text or value."""
        while True:
            op, flags, length = _HEADER.unpack(self._recv_exact(_HEADER.size))
            if flags != 0:
                raise SilcError("malformed reply from %s" % self.url)
            if op == VALUE:
                return self._read_value(length)
            if length > _MAX_TEXT:
                raise SilcError("reply of %d bytes from %s is too long" % (length, self.url))
            text = self._recv_exact(length).decode("utf-8", "replace")
            if op == TEXT:
                if out is not None:
                    out.append(text)
                else:
                    sys.stdout.write(text)
            elif op == WARN:
                self.warnings += text
            elif op == OK:
                return text
            elif op == ERROR:
                raise SilcError(text)
            else:
                raise SilcError("unknown reply opcode %d from %s" % (op, self.url))

    # ---- the calls --------------------------------------------------------
    def put(self, name, value):
        """Deposits value under name."""
        nm = name.encode()
        fmt, m, n, arrays = to_parts(name, value)
        desc = _DESC.pack(fmt, len(nm), m, n, len(arrays[-1]), 0, 0)
        self._send(PUT, desc, nm, *arrays)
        self._reply()

    def get(self, name):
        """The value bound to name (numpy array, or CSR as described above)."""
        self._send(GET, name.encode())
        return self._reply()

    def exec(self, statements, out=None):
        """Runs statements.  Text printed by who/info/explain goes to out (a
        list) when given, else to stdout; warnings are in self.warnings.
        Ctrl-C (SIGINT, on the main thread) sends CANCEL, waits for the
        server's reply and raises KeyboardInterrupt; a second Ctrl-C gives
        up waiting and closes the session."""
        self.warnings = ""
        self._send(EXEC, statements.encode())
        presses = []

        def on_sigint(signum, frame):
            presses.append(signum)
            if len(presses) > 1:
                raise KeyboardInterrupt
            self.cancel()

        previous = None
        if (threading.current_thread() is threading.main_thread()
                and signal.getsignal(signal.SIGINT) is signal.default_int_handler):
            previous = signal.signal(signal.SIGINT, on_sigint)
        with self._cancel_lock:
            self._awaiting = True
        try:
            self._reply(out)
        except KeyboardInterrupt:
            self.sock.close()  # gave up inside a reply: the stream is lost
            self.sock = None
            raise
        except SilcError:
            if presses:
                raise KeyboardInterrupt from None
            raise
        finally:
            with self._cancel_lock:
                self._awaiting = False
            if previous is not None:
                signal.signal(signal.SIGINT, previous)
        if presses:
            raise KeyboardInterrupt

    def cancel(self):
        """Interrupts the exec running on this session (from another thread
        or a signal handler): the server stops it at its next check and it
        fails with "interrupted", the store as before the statement.  Does
        nothing when no exec is waiting for its reply."""
        with self._cancel_lock:
            if self._awaiting and self.sock is not None:
                self.sock.sendall(_HEADER.pack(CANCEL, 0, 0))

    def explain(self, statement):
        """What the statement would run and why, as text (nothing is run)."""
        out = []
        self._send(EXPLAIN, statement.encode())
        self._reply(out)
        return "".join(out)

    def info(self, name=None):
        """How name was last computed, or with no name the session's state."""
        out = []
        self._send(INFO, (name or "").encode())
        self._reply(out)
        return "".join(out)

    def names(self):
        self._send(LIST)
        text = self._reply()
        return text.split("\n") if text else []

    def delete(self, name):
        self._send(DELETE, name.encode())
        self._reply()

    def close(self):
        if self.sock is not None:
            try:
                self._send(BYE)
                self._reply()
            except (OSError, SilcError):
                pass
            self.sock.close()
            self.sock = None

    def __enter__(self):
        return self

    def __exit__(self, *exc):
        self.close()
