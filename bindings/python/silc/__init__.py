"""silc -- SILC from Python, embedded or remote, with one API:

    import numpy as np, scipy.sparse as sp, silc
    with silc.Session() as s:                  # in this process (libsilc, ctypes)
    # with silc.Session("unix:/tmp/s.sock")    # or on a silcd (also tcp://host:port,
    #                                          # or SILC_SERVER when no address is given)
        s["A"] = sp.csr_matrix(...)            # = s.put("A", ...): numpy, scipy.sparse
        s["b"] = np.ones(5)
        s.exec("x = A \\\\ b")
        x = s["x"]                             # = s.get("x"): numpy (dense, band),
        print(s.info("x")["backend"])          #   scipy.sparse.csr_matrix (CSR)

Errors raise silc.Error with SILC's message (the C API's text).
s.exec(text, out) collects who/info/explain output in the list out (else it
goes to stdout); s.warnings holds the last exec's warnings; s.names(),
del s["x"], "x" in s, s.explain(stmt) and s.close() (or `with`) complete it.
"""
import os

from ._values import SilcError

Error = SilcError


def _as_number(text):
    try:
        return float(text)
    except ValueError:
        return text


def _parse_info(text, name):
    """`info` text as a dict: each "key: value" line (numbers as floats);
    `info x`'s first line, "x: 3x1 dense, nnz 3", as "value"."""
    d = {}
    for k, line in enumerate(text.splitlines()):
        key, sep, value = line.strip().partition(": ")
        if not sep:
            continue
        if k == 0 and name and key == name:
            d["value"] = value
        else:
            d[key] = _as_number(value.strip())
    return d


class Session:
    """One SILC session: embedded (no address and no SILC_SERVER) or on the
    silcd that url (tcp://host:port or unix:/path) or SILC_SERVER names."""

    def __init__(self, url=None, token=None, config=None):
        url = url or os.environ.get("SILC_SERVER")
        if url:
            from ._remote import RemoteSession
            self._s = RemoteSession(url, token)
        else:
            from ._embedded import EmbeddedSession
            self._s = EmbeddedSession(config)
        self.remote = bool(url)

    @property
    def warnings(self):
        return self._s.warnings

    def put(self, name, value):
        """Deposits value under name."""
        self._s.put(name, value)

    def get(self, name):
        """The value bound to name."""
        return self._s.get(name)

    def exec(self, statements, out=None):
        """Runs statements; output to the list out if given, else stdout."""
        self._s.exec(statements, out)

    def cancel(self):
        """Interrupts the exec running on this session, from another thread
        (or, remote, a signal handler): it raises silc.Error "interrupted"
        and the interrupted statement leaves the store as before it.
        Remote, Ctrl-C during exec does this itself and raises
        KeyboardInterrupt once the server has answered."""
        self._s.cancel()

    def explain(self, statement):
        """What the statement would run and why, as text (nothing is run)."""
        return self._s.explain(statement)

    def info(self, name=None):
        """How name was last computed, as a dict ("backend", "backward error",
        ...); with no name, a server session's state (remote only)."""
        return _parse_info(self._s.info(name), name)

    def names(self):
        return self._s.names()

    def delete(self, name):
        self._s.delete(name)

    def close(self):
        self._s.close()

    __getitem__ = get
    __setitem__ = put
    __delitem__ = delete

    def __contains__(self, name):
        return name in self.names()

    def __enter__(self):
        return self

    def __exit__(self, *exc):
        self.close()


def connect(url=None, token=None):
    """A Session (kept for the remote-only client's callers)."""
    return Session(url, token)

