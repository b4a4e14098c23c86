"""silc -- SILC from Python, embedded or remote, with one API.

    import numpy as np, scipy.sparse as sp, silc
    with silc.Session() as s:                  # in this process (libsilc, ctypes)
    # with silc.Session("unix:/tmp/s.sock")    # or on a silcd (also tcp://host:port,
    #                                          # or SILC_SERVER when no address is given)
        s["A"] = sp.csr_array(...)             # = s.put("A", ...): numpy, scipy.sparse
        s["b"] = np.ones(5)
        s.exec("x = A \\\\ b")
        x = s["x"]                             # = s.get("x"): shape (5,), as b
        print(s.info("x")["backward error"])   # a float

Values come back as SciPy users expect: a 1-D array put comes back 1-D and a
computed n x 1 value is 1-D (as scipy.sparse.linalg.spsolve returns), a
1 x 1 value is a Python float (unless it was put as a 2-D array, which comes
back 2-D), CSR is a scipy.sparse csr_array (csr_matrix once the program
puts csr_matrix values, or Session(sparse="matrix")), band is a dia_array.
Complex values go in and come out as NumPy keeps them: a complex array
(complex64 promoted to complex128) or a scipy.sparse matrix with complex data
is stored complex, and a complex value comes back complex128 (a 1 x 1 one a
Python complex); real values stay float64.  Arrays of other dtypes (object,
strings) are refused, never converted by guess.  Errors are silc.Error (KeyError too for a missing
name: silc.UndefinedName); a remote session's errors name the server.
"""
import os

import numpy as np

from ._values import Error, ProtocolError, SilcError, Timeout, UndefinedName

__version__ = "1.0.0"      # the CMake project's VERSION (test_python checks they agree)
__all__ = ["Session", "Error", "SilcError", "UndefinedName", "ProtocolError", "Timeout",
           "connect", "__version__"]


def _typed(text):
    """An `info` value as Python: yes/no as bool, an integer as int, a
    number (with " s" or a parenthesised remark after it) as float, any
    other text as str."""
    if text in ("yes", "no"):
        return text == "yes"
    if text.isdigit():
        return int(text)
    # the number ends where the first of the two tails starts (a remark
    # may itself hold " s": "... deferred at solve time ...")
    cuts = [text.find(tail) for tail in (" s", " (") if tail in text]
    head = text[:min(cuts)] if cuts else text
    try:
        return float(head)
    except ValueError:
        return text


def _key_value(line):
    """("key", "value") of "key: value", the key's parentheses kept whole
    ("forward error bound (estimate: ...): 9e-17"); None without ": "."""
    depth = 0
    for i, c in enumerate(line):
        depth += (c == "(") - (c == ")")
        if depth == 0 and line.startswith(": ", i):
            return line[:i], line[i + 2:]
    return None


def _parse_info(text, name):
    """`info` text as a dict of typed values (_typed): each "key: value"
    line; `info x`'s first line, "x: 3x1 dense, nnz 3", as "value" (the
    text), "shape" (3, 1), "format" and "nnz"."""
    d = {}
    for k, line in enumerate(text.splitlines()):
        kv = _key_value(line.strip())
        if not kv:
            continue
        key, value = kv
        if k == 0 and name and key == name:
            d["value"] = value
            shape, _, rest = value.partition(" ")
            fmt, _, nnz = rest.partition(", nnz ")
            m, _, n = shape.partition("x")
            if m.isdigit() and n.isdigit():
                d["shape"] = (int(m), int(n))
            d["format"] = fmt
            if nnz.isdigit():
                d["nnz"] = int(nnz)
        else:
            d[key] = _typed(value.strip())
    return d


def _ndim_of(value):
    """The dimensions a dense value was put with (0, 1, 2), or None."""
    if hasattr(value, "tocsr") or isinstance(value, tuple):
        return None
    try:
        return np.ndim(value)
    except (TypeError, ValueError):
        return None


class Session:
    """One SILC session: its own names, values and settings.

    Embedded (no address and no SILC_SERVER): libsilc in this process.
    Remote: the silcd at url (tcp://host:port or unix:/path, else
    SILC_SERVER), token from the argument, SILC_TOKEN or SILC_TOKEN_FILE.

    A remote session trusts the server no more than the server trusts it:
    a reply is refused (silc.ProtocolError) when it breaks the protocol or
    its own format, or holds a value over max_value_bytes (default
    SILC_MAX_REPLY_BYTES, else 2 GiB; such a value is skipped and the
    session goes on); a server silent for `timeout` seconds inside a reply
    or before answering anything but exec (default SILC_IO_TIMEOUT, else
    300) raises silc.Timeout, and exec waits for ever unless exec_timeout
    (SILC_EXEC_TIMEOUT) is set.  0 means no timeout.  sparse = "array" or
    "matrix" fixes the kind of scipy.sparse results; by default it follows
    the program's last sparse put (csr_array before any).

    >>> import numpy as np, scipy.sparse as sp, silc
    >>> with silc.Session() as s:
    ...     s["A"] = sp.csr_array(np.array([[4.0, 1.0], [1.0, 3.0]]))
    ...     s["b"] = np.array([1.0, 2.0])
    ...     s.exec("x = A \\\\ b; r = norm(A * x - b)")
    ...     x, r = s["x"], s["r"]          # x.shape == (2,), r is a float
    ...     s.info("x")["backward error"] < 1e-15
    True
    """

    def __init__(self, url=None, token=None, config=None, *, timeout=None, exec_timeout=None,
                 max_value_bytes=None, sparse=None):
        url = url or os.environ.get("SILC_SERVER")
        if sparse not in (None, "array", "matrix"):
            raise Error("sparse must be 'array' or 'matrix', not %r" % (sparse,))
        self._sparse_fixed = sparse
        self._sparse = sparse or "array"
        self._ndim = {}
        if url:
            from ._remote import RemoteSession
            self._s = RemoteSession(url, token, timeout, exec_timeout, max_value_bytes)
        else:
            from ._embedded import EmbeddedSession
            self._s = EmbeddedSession(config)
        self.remote = bool(url)

    @property
    def warnings(self):
        """The warnings of the last exec, one per line ("" when none)."""
        return self._s.warnings

    def put(self, name, value):
        """Deposits value under name (a copy): a number, a 1-D or 2-D numpy
        array, a scipy.sparse matrix or array, or (indptr, indices, data,
        (m, n)); float64, or complex128 when the dtype is complex.
        ``s["A"] = value`` is the same.

        >>> s.put("b", np.ones(3))         # 3 x 1 in SILC, comes back 1-D
        >>> s.put("z", np.array([1 + 2j, 3 - 1j]))   # complex 2 x 1
        """
        self._s.put(name, value)
        self._ndim[name] = _ndim_of(value)
        if not self._sparse_fixed and hasattr(value, "tocsr"):
            try:
                import scipy.sparse as sp
                array_base = getattr(sp, "sparray", None)
                if array_base is None:          # scipy < 1.11
                    from scipy.sparse._arrays import _sparray as array_base
                self._sparse = "array" if isinstance(value, array_base) else "matrix"
            except ImportError:
                pass

    def get(self, name):
        """The value bound to name: dense as numpy (1-D for an n x 1 value
        unless it was put 2-D, a float for 1 x 1 unless put 2-D), CSR as
        csr_array (or csr_matrix, see the class), band as dia_array; a
        complex value as complex128 (1 x 1: a Python complex).
        ``s["x"]`` is the same; a missing name raises silc.UndefinedName,
        a KeyError.

        >>> s.exec("n = norm(b)"); s["n"]
        1.7320508075688772
        """
        v = self._s.get(name, self._sparse)
        if not hasattr(v, "ndim") or hasattr(v, "tocsr") or v.ndim != 2:
            return v
        put_ndim = self._ndim.get(name)
        if put_ndim == 2:
            return v
        if v.shape == (1, 1) and put_ndim != 1:
            return complex(v[0, 0]) if v.dtype.kind == "c" else float(v[0, 0])
        if v.shape[1] == 1:
            return v[:, 0]
        return v

    def exec(self, statements, out=None):
        """Runs statements; who/info/explain output is appended to the list
        out if given, else printed; warnings are in s.warnings.

        >>> s.exec("x = A \\\\ b")
        """
        self._s.exec(statements, out)

    def cancel(self):
        """Interrupts the exec running on this session, from another thread
        (or, remote, a signal handler): it raises silc.Error "interrupted"
        and the interrupted statement leaves the store as before it.
        Ctrl-C during exec (on the main thread, with Python's default SIGINT
        handler) does this itself and raises KeyboardInterrupt once the
        statement has stopped: embedded and remote alike."""
        self._s.cancel()

    def explain(self, statement):
        """What the statement would run and why, as text (nothing is run)."""
        return self._s.explain(statement)

    def info(self, name=None):
        """How name was last computed, as a dict of typed values:
        "backend" (str), "backward error" and "condition estimate" (float),
        "iterations" (int), "reused factorization" (bool), "wall time"
        (float seconds), "shape" ((m, n)), ...; with no name, a server
        session's state (remote only).

        >>> s.info("x")["iterations"]
        0
        """
        return _parse_info(self._s.info(name), name)

    def names(self):
        """The session's names, sorted."""
        return self._s.names()

    def delete(self, name):
        """Unbinds name (``del s[name]``); silc.UndefinedName if unbound."""
        self._s.delete(name)
        self._ndim.pop(name, None)

    def close(self):
        """Ends the session (a server frees its values); `with` calls it."""
        self._s.close()

    def __getitem__(self, name):
        return self.get(name)

    def __setitem__(self, name, value):
        self.put(name, value)

    def __delitem__(self, name):
        self.delete(name)

    def __contains__(self, name):
        return name in self.names()

    def __enter__(self):
        return self

    def __exit__(self, *exc):
        self.close()


def connect(url=None, token=None, **options):
    """A Session (kept for the remote-only client's callers)."""
    return Session(url, token, **options)
