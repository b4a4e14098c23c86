"""silc.py -- a pure-Python client of the SILC wire protocol (docs/protocol.md).

It speaks to silcd directly, with no C library, to show that any language
that can open a socket can use SILC:

    import numpy as np, silc
    with silc.connect("tcp://127.0.0.1:7070") as s:     # or SILC_SERVER
        s.put("b", np.ones(5))
        s.exec("x = 2 * b")
        print(s.get("x"))                                # 5x1 numpy array

Values: numpy arrays go in (1-D -> n x 1 vector, 2-D -> dense matrix, sent
column-major), scipy.sparse matrices and (indptr, indices, data, shape) tuples
go in as CSR.  get() returns a 2-D numpy array for dense and band values, and
a scipy.sparse.csr_matrix for CSR (the tuple if scipy is missing).  Arrays
travel without extra copies: they are sent from and received into their
numpy buffers.  Errors raise SilcError with the server's message, the same
text the C API reports.
"""
import os
import socket
import struct
import sys

import numpy as np

PROTOCOL_VERSION = 1
PUT, GET, EXEC, DELETE, LIST, INFO, EXPLAIN, BYE = range(1, 9)
OK, ERROR, VALUE, TEXT, WARN = range(128, 133)
DENSE, CSR, BAND = 0, 1, 2
_HEADER = struct.Struct("<IIQ")
_HELLO = struct.Struct("<4sII")
_DESC = struct.Struct("<IIqqqqq")
_MAX_TEXT = 1 << 30

if sys.byteorder != "little":
    raise ImportError("silc.py: the wire protocol needs a little-endian host")


class SilcError(Exception):
    """A request the server refused (its message) or a lost connection."""


def _token_from_env():
    tok = os.environ.get("SILC_TOKEN")
    if tok:
        return tok
    path = os.environ.get("SILC_TOKEN_FILE")
    if path:
        with open(path) as f:
            return f.readline().rstrip("\r\n")
    return None


class Session:
    """One session on a silcd server: its own names, closed by close()."""

    def __init__(self, url=None, token=None):
        url = url or os.environ.get("SILC_SERVER")
        if not url:
            raise SilcError("no server address: pass one or set SILC_SERVER")
        token = token if token is not None else _token_from_env()
        self.url = url
        self.warnings = ""
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
            indptr = np.empty(m + 1, dtype=np.int64)
            indices = np.empty(nnz, dtype=np.int64)
            data = np.empty(nnz, dtype=np.float64)
            for a in (indptr, indices, data):
                self._recv_into(a)
            try:
                import scipy.sparse
                return scipy.sparse.csr_matrix((data, indices, indptr), shape=(m, n))
            except ImportError:
                return (indptr, indices, data, (m, n))
        vals = np.empty(nnz, dtype=np.float64)
        self._recv_into(vals)
        if fmt == DENSE:
            return vals.reshape((m, n), order="F")
        # Band, LAPACK layout: A(i, j) = band[ku + i - j, j].
        ld = kl + ku + 1
        band = vals.reshape((ld, n), order="F")
        a = np.zeros((m, n))
        for j in range(n):
            for i in range(max(0, j - ku), min(m, j + kl + 1)):
                a[i, j] = band[ku + i - j, j]
        return a

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
        if hasattr(value, "tocsr") and hasattr(value, "shape"):
            c = value.tocsr()
            c.sort_indices()
            value = (c.indptr, c.indices, c.data, c.shape)
        if isinstance(value, tuple):
            indptr, indices, data, (m, n) = value
            arrays = [np.ascontiguousarray(indptr, dtype=np.int64),
                      np.ascontiguousarray(indices, dtype=np.int64),
                      np.ascontiguousarray(data, dtype=np.float64)]
            desc = _DESC.pack(CSR, len(nm), m, n, len(arrays[2]), 0, 0)
        else:
            a = np.asarray(value, dtype=np.float64)
            if a.ndim == 0:
                a = a.reshape(1, 1)
            elif a.ndim == 1:
                a = a.reshape(-1, 1)
            elif a.ndim != 2:
                raise SilcError("'%s': only vectors and matrices can be stored" % name)
            m, n = a.shape
            # Column-major without a copy when it already is.
            arrays = [a.reshape(-1, order="F") if a.flags.f_contiguous else
                      np.asfortranarray(a).reshape(-1, order="F")]
            desc = _DESC.pack(DENSE, len(nm), m, n, m * n, 0, 0)
        self._send(PUT, desc, nm, *arrays)
        self._reply()

    def get(self, name):
        """The value bound to name (numpy array, or CSR as described above)."""
        self._send(GET, name.encode())
        return self._reply()

    def exec(self, statements, out=None):
        """Runs statements.  Text printed by who/info/explain goes to out (a
        list) when given, else to stdout; warnings are in self.warnings."""
        self.warnings = ""
        self._send(EXEC, statements.encode())
        self._reply(out)

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


def connect(url=None, token=None):
    """Opens a session: url tcp://host:port or unix:/path (default SILC_SERVER)."""
    return Session(url, token)
