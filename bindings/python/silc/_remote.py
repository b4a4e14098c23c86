"""silc._remote -- the wire protocol (docs/protocol.md) in pure Python: a
session on a silcd server, with no C library, so that any machine with
Python and a socket can use SILC.  Arrays travel without extra copies: they
are sent from and received into their numpy buffers.  silc/__init__.py is
the package's front; this is one of its two back ends (_embedded.py the
other).

Replies are not trusted: every frame's length must agree with what it
carries, a value's descriptor is checked and held to the client's cap
(max_value_bytes, SILC_MAX_REPLY_BYTES, default 2 GiB) before anything is
allocated, text to 64 MiB (silcd's own cap on statements) and read as it
arrives, CSR arrays are checked before scipy sees them, and every wait for
the server is bounded: timeout (SILC_IO_TIMEOUT, default 300 s) between
the bytes of a reply and for the reply to every request but exec, whose
reply may take as long as its statements compute unless exec_timeout
(SILC_EXEC_TIMEOUT) is set.  Failures are silc.Error subclasses naming the
server; after one that leaves the stream out of step the connection is
closed and later calls say so.
"""
import os
import signal
import socket
import stat
import struct
import sys
import threading

import numpy as np

from ._values import (COMPLEX, CSR, DEFAULT_MAX_VALUE_BYTES, Error, ProtocolError, Timeout,
                      UndefinedName, as_doubles, check_csr, entry_dtype, from_parts, layout,
                      over_cap, to_parts)

SilcError = Error
PROTOCOL_VERSION = 1
PUT, GET, EXEC, DELETE, LIST, INFO, EXPLAIN, BYE, CANCEL, GET_COMPLEX = range(1, 11)
OK, ERROR, VALUE, TEXT, WARN = range(128, 133)
_HEADER = struct.Struct("<IIQ")
_HELLO = struct.Struct("<4sII")
_DESC = struct.Struct("<IIqqqqq")
_MAX_TEXT = 64 << 20                 # silcd's own cap on a statement
_TEXT_CHUNK = 1 << 20
_SEND_CHUNK = 16 << 20
DEFAULT_TIMEOUT = 300.0
_IO = object()                       # "the I/O timeout" for a first wait
_OPS = {OK: "OK", ERROR: "ERROR", VALUE: "VALUE", TEXT: "TEXT", WARN: "WARN"}

if sys.byteorder != "little":
    raise ImportError("silc.py: the wire protocol needs a little-endian host")


def _token_from_env():
    tok = os.environ.get("SILC_TOKEN")
    if tok:
        return tok
    path = os.environ.get("SILC_TOKEN_FILE")
    if path:
        # A regular file only, opened without blocking and read up to 8 KiB:
        # a FIFO with no writer hung the client, /dev/zero filled its memory.
        try:
            fd = os.open(path, os.O_RDONLY | os.O_NONBLOCK | os.O_CLOEXEC)
            try:
                if not stat.S_ISREG(os.fstat(fd).st_mode):
                    raise Error("SILC_TOKEN_FILE '%s' is not a regular file" % path)
                data = os.read(fd, 8192)
            finally:
                os.close(fd)
        except OSError as e:
            raise Error("cannot read SILC_TOKEN_FILE '%s': %s" % (path, e.strerror)) from None
        return data.decode("utf-8", "replace").split("\n", 1)[0].rstrip("\r")
    return None


# A timeout other than 0 (none) lies in [1 ms, a year], as in the C client:
# 1e30 reached the socket as an OverflowError.
TIMEOUT_MIN, TIMEOUT_MAX = 0.001, 31536000.0


def _seconds(value, var, default):
    """A timeout in seconds from the argument, else the variable var, else
    default; 0 means none (None to the socket)."""
    if value is None:
        text = os.environ.get(var)
        if not text:
            value = default
        else:
            try:
                value = float(text)
            except ValueError:
                value = -1
            if not (value == 0 or TIMEOUT_MIN <= value <= TIMEOUT_MAX):
                raise Error("%s = '%s': expected 0 (no timeout) or seconds from 0.001 to 31536000"
                            % (var, text))
    if value is not None and not (value == 0 or TIMEOUT_MIN <= value <= TIMEOUT_MAX):
        raise Error("a timeout must be 0 (none) or seconds from 0.001 to 31536000, not %r" % value)
    return value or None


def _size(value):
    """The value cap in bytes from the argument, else SILC_MAX_REPLY_BYTES
    ("123", "64K", "512M", "2G", as silcd's size options), else 2 GiB."""
    if value is not None:
        return int(value)
    text = os.environ.get("SILC_MAX_REPLY_BYTES")
    if not text:
        return DEFAULT_MAX_VALUE_BYTES
    shift = {"k": 10, "m": 20, "g": 30, "t": 40}.get(text[-1:].lower(), 0)
    digits = text[:-1] if shift else text
    if not digits.isdigit():
        raise Error("SILC_MAX_REPLY_BYTES = '%s': expected a size in bytes with an optional "
                    "K, M, G or T suffix" % text)
    return int(digits) << shift


def _fmt_seconds(t):
    return "%g" % t


class RemoteSession:
    """One session on a silcd server: its own names, closed by close()."""

    def __init__(self, url=None, token=None, timeout=None, exec_timeout=None,
                 max_value_bytes=None):
        url = url or os.environ.get("SILC_SERVER")
        if not url:
            raise Error("no server address: pass one or set SILC_SERVER")
        token = token if token is not None else _token_from_env()
        self.url = url
        self.warnings = ""
        self.sock = None
        self.broken = None
        self.timeout = _seconds(timeout, "SILC_IO_TIMEOUT", DEFAULT_TIMEOUT)
        self.exec_timeout = _seconds(exec_timeout, "SILC_EXEC_TIMEOUT", 0)
        self.max_value_bytes = _size(max_value_bytes)
        # cancel() writes only while an EXEC waits for its reply (_awaiting),
        # so its frame never lands inside another; reentrant because a
        # SIGINT handler runs on the main thread, maybe inside exec's own
        # critical section.
        self._cancel_lock = threading.RLock()
        self._awaiting = False
        # A CANCEL went out for the EXEC awaited: the output still on its
        # way is dropped (and counted in a warning), as the C client does,
        # so the interrupt shows at once, not after a loop's backlog.
        self._cancel_sent = False
        self._dropped = 0
        self._old_server = False          # answers GET_COMPLEX "unknown request opcode"
        try:
            self.sock = self._connect(url)
        except OSError as e:
            raise Error("cannot connect to silc server %s: %s"
                        % (url, e.strerror or e)) from None
        tok = (token or "").encode()
        try:
            self._sendall(_HELLO.pack(b"SILC", PROTOCOL_VERSION, len(tok)) + tok)
            magic, _version, _ = _HELLO.unpack(self._recv_exact(_HELLO.size, mid=False))
            if magic != b"SILC":
                raise ProtocolError("%s is not a SILC server (bad magic in its hello)" % url)
            self._reply()
        except Error:
            self._drop()
            raise

    def _connect(self, url):
        if url.startswith("unix:"):
            path = url[5:]
            if path.startswith("//"):
                path = path[2:]
            s = socket.socket(socket.AF_UNIX, socket.SOCK_STREAM)
            try:
                s.settimeout(self.timeout)
                s.connect(path)
            except OSError:
                s.close()
                raise
            return s
        if not url.startswith("tcp://"):
            raise Error("'%s': server address must be tcp://host:port or unix:/path" % url)
        host, _, port = url[6:].rpartition(":")
        host = host.strip("[]")
        if not host or not port.isdigit():
            raise Error("'%s': server address must be tcp://host:port or unix:/path" % url)
        s = socket.create_connection((host, int(port)), timeout=self.timeout)
        s.setsockopt(socket.IPPROTO_TCP, socket.TCP_NODELAY, 1)
        return s

    # ---- framing ----------------------------------------------------------
    def _drop(self):
        if self.sock is not None:
            self.sock.close()
            self.sock = None

    def _fail(self, exc):
        """Closes the connection (its stream is out of step) and raises exc;
        later calls say the connection was lost."""
        self.broken = str(exc)
        self._drop()
        raise exc

    def _usable(self):
        if self.sock is None:
            raise Error("connection to silc server %s was lost earlier (%s); open a new session"
                        % (self.url, self.broken) if self.broken else
                        "the session on %s is closed" % self.url)

    def _recv_into(self, view, first_wait=_IO, mid=True):
        """Fills view.  Inside a frame (mid) every wait is the I/O timeout;
        the first byte of a frame may take first_wait seconds (_IO: the I/O
        timeout, None: for ever, else exec_timeout)."""
        view = memoryview(view).cast("B")
        while len(view):
            try:
                self.sock.settimeout(self.timeout if mid or first_wait is _IO else first_wait)
                n = self.sock.recv_into(view)
            except socket.timeout:
                if mid:
                    self._fail(Timeout("silc server %s stopped sending in the middle of a "
                                       "reply: nothing for %s s (SILC_IO_TIMEOUT; connection "
                                       "closed)" % (self.url, _fmt_seconds(self.timeout))))
                io = first_wait is _IO
                self._fail(Timeout("silc server %s sent nothing for %s s (%s; connection closed)"
                                   % (self.url, _fmt_seconds(self.timeout if io else first_wait),
                                      "SILC_IO_TIMEOUT" if io else "SILC_EXEC_TIMEOUT")))
            except OSError as e:
                self._fail(Error("connection to silc server %s lost: %s"
                                 % (self.url, e.strerror or e)))
            if n == 0:
                self._fail(Error("connection to silc server %s lost: connection closed by peer"
                                 % self.url))
            mid = True
            view = view[n:]

    def _recv_exact(self, n, first_wait=_IO, mid=True):
        buf = bytearray(n)
        self._recv_into(buf, first_wait, mid)
        return bytes(buf)

    def _recv_text(self, length):
        """length bytes as they arrive, so a header that lies costs nothing."""
        parts = []
        while length:
            k = min(length, _TEXT_CHUNK)
            parts.append(self._recv_exact(k))
            length -= k
        return b"".join(parts).decode("utf-8", "replace")

    def _sendall(self, data):
        # In chunks: sendall's timeout bounds the whole call, and a large
        # PUT over a slow link may rightly take longer than one timeout.
        data = memoryview(data).cast("B")
        try:
            self.sock.settimeout(self.timeout)
            for at in range(0, len(data), _SEND_CHUNK):
                self.sock.sendall(data[at:at + _SEND_CHUNK])
        except socket.timeout:
            self._fail(Timeout("silc server %s accepted nothing for %s s (SILC_IO_TIMEOUT; "
                               "connection closed)" % (self.url, _fmt_seconds(self.timeout))))
        except OSError as e:
            self._fail(Error("connection to silc server %s lost: %s" % (self.url, e.strerror or e)))

    def _send(self, op, *parts):
        self._usable()
        parts = [memoryview(p).cast("B") for p in parts]
        self._sendall(_HEADER.pack(op, 0, sum(len(p) for p in parts)))
        for p in parts:
            if len(p):
                self._sendall(p)

    def _bad(self, why):
        self._fail(ProtocolError("silc server %s sent a bad reply: %s (connection closed)"
                                 % (self.url, why)))

    def _skip(self, n):
        while n:
            k = min(n, _TEXT_CHUNK)
            self._recv_exact(k)
            n -= k

    def _read_value(self, length, sparse, complex_ok):
        if length < _DESC.size:
            self._bad("VALUE reply shorter than its descriptor")
        fmt, namelen, m, n, nnz, kl, ku = _DESC.unpack(self._recv_exact(_DESC.size))
        if namelen != 0:
            self._bad("VALUE reply with a name length")
        if fmt & COMPLEX and not complex_ok:
            self._bad("a complex value in reply to a GET, which asks for real values only")
        try:
            rowptr_bytes, colind_bytes, values_bytes = layout(fmt, m, n, nnz, kl, ku)
        except ProtocolError as e:
            self._bad(e)
        total = rowptr_bytes + colind_bytes + values_bytes
        if total != length - _DESC.size:
            self._bad("VALUE reply carries %d bytes of arrays, its descriptor needs %d"
                      % (length - _DESC.size, total))
        refusal = over_cap(fmt, m, n, total, self.max_value_bytes)
        if refusal:
            # Well framed: skipped, so that the session keeps its values.
            self._skip(total)
            raise ProtocolError("silc server %s: reply refused: %s" % (self.url, refusal))
        # Received as doubles (a complex value's interleaved), then viewed.
        values = np.empty(values_bytes // 8, dtype=np.float64)
        if fmt & ~COMPLEX == CSR:
            arrays = [np.empty(m + 1, dtype=np.int64), np.empty(nnz, dtype=np.int64), values]
        else:
            arrays = [values]
        for a in arrays:
            self._recv_into(a)
        arrays[-1] = values.view(entry_dtype(fmt))
        if fmt & ~COMPLEX == CSR:
            try:
                check_csr(arrays[0], arrays[1], m, n, nnz)
            except ProtocolError as e:
                self._bad("'VALUE': %s" % e)
        return from_parts(fmt, m, n, kl, ku, arrays, sparse, self.max_value_bytes)

    def _reply(self, out=None, first_wait=_IO, sparse="array", complex_ok=False):
        """Reads replies up to the final one; returns its text or value (a
        complex one only when complex_ok: the request was GET_COMPLEX).  The
        first byte of each reply may take first_wait seconds (exec)."""
        while True:
            op, flags, length = _HEADER.unpack(self._recv_exact(_HEADER.size, first_wait, False))
            if flags != 0:
                self._bad("frame flags %d are not 0 (protocol version 1)" % flags)
            if op == VALUE:
                return self._read_value(length, sparse, complex_ok)
            if op not in _OPS:
                self._bad("unknown reply opcode %d" % op)
            if length > _MAX_TEXT:
                self._bad("%s reply of %d bytes exceeds the limit of %d bytes"
                          % (_OPS[op], length, _MAX_TEXT))
            text = self._recv_text(length)
            if op == TEXT:
                if self._cancel_sent:
                    self._dropped += len(text.encode())
                elif out is not None:
                    out.append(text)
                else:
                    sys.stdout.write(text)
            elif op == WARN:
                self.warnings += text
            elif op == OK:
                return text
            else:
                if self._dropped:
                    self.warnings += ("interrupted: %d bytes of the statement's output, still on the "
                                      "way from the server, were not shown\n" % self._dropped)
                if text.startswith("undefined name '"):
                    raise UndefinedName(text)
                raise Error(text)

    # ---- the calls --------------------------------------------------------
    def put(self, name, value):
        """Deposits value under name."""
        nm = name.encode()
        fmt, m, n, arrays = to_parts(name, value)
        desc = _DESC.pack(fmt, len(nm), m, n, len(arrays[-1]), 0, 0)
        self._send(PUT, desc, nm, *[as_doubles(a) for a in arrays])
        self._reply()

    def get(self, name, sparse="array"):
        """The value bound to name (numpy array, or CSR as described above),
        complex128 when it is complex: asked with GET_COMPLEX, which takes
        either field.  A server older than complex values answers that
        "unknown request opcode 10"; then the plain GET is asked."""
        if not self._old_server:
            self._send(GET_COMPLEX, name.encode())
            try:
                return self._reply(sparse=sparse, complex_ok=True)
            except Error as e:
                if str(e) != "unknown request opcode %d" % GET_COMPLEX:
                    raise
                self._old_server = True
        self._send(GET, name.encode())
        return self._reply(sparse=sparse)

    def exec(self, statements, out=None):
        """Runs statements.  Text printed by who/info/explain goes to out (a
        list) when given, else to stdout; warnings are in self.warnings.
        Ctrl-C (SIGINT, on the main thread) sends CANCEL, waits for the
        server's reply and raises KeyboardInterrupt; a second Ctrl-C gives
        up waiting and closes the session."""
        self.warnings = ""
        self._cancel_sent = False
        self._dropped = 0
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
            self._reply(out, first_wait=self.exec_timeout)
        except KeyboardInterrupt:
            # gave up inside a reply: the stream is lost
            self.broken = "interrupted twice while waiting for a reply"
            self._drop()
            raise
        except SilcError:
            if presses:
                raise KeyboardInterrupt from None
            raise
        finally:
            with self._cancel_lock:
                self._awaiting = False
                self._cancel_sent = False  # the next request's text is shown
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
                self._cancel_sent = True  # before the frame: what answers it is backlog
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
                self.timeout = min(self.timeout or 5.0, 5.0)
                self._send(BYE)
                self._reply()
            except Error:
                pass
            self._drop()

    def __enter__(self):
        return self

    def __exit__(self, *exc):
        self.close()
