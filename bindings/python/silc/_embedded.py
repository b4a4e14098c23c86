"""silc._embedded -- a session inside this process, through libsilc with
ctypes (no compiler at import): the engine, its plugins and the values live
here, as for a C program.  libsilc is found by SILC_LIBRARY (a path), else
relative to this package in its install (_paths.py, written by CMake), else
by its soname (_candidates says why in that order).  One of the
package's two back ends (_remote.py the other).
"""
import ctypes
import ctypes.util
import os
import signal
import threading

import numpy as np

from ._values import COMPLEX, CSR, SilcError, UndefinedName, entry_dtype, from_parts, to_parts


class _Envelope(ctypes.Structure):
    """silc_envelope_t (silc.h)."""
    _fields_ = [("m", ctypes.c_int64), ("n", ctypes.c_int64), ("format", ctypes.c_int),
                ("values", ctypes.POINTER(ctypes.c_double)), ("rowptr", ctypes.POINTER(ctypes.c_int64)),
                ("colind", ctypes.POINTER(ctypes.c_int64)), ("nnz", ctypes.c_int64),
                ("kl", ctypes.c_int64), ("ku", ctypes.c_int64)]


_OUTPUT = ctypes.CFUNCTYPE(None, ctypes.c_void_p, ctypes.c_char_p)
_lib = None


def _candidates():
    """Where libsilc may be, in the order tried: SILC_LIBRARY (a path the user
    names), then the libsilc of the install this package belongs to, found
    relative to the package itself (_paths.py, written by CMake: no absolute
    path, so a staged or moved prefix works), then the soname through the
    dynamic loader's own search (LD_LIBRARY_PATH, ld.so.cache), then
    ctypes.util.find_library."""
    path = os.environ.get("SILC_LIBRARY")
    if path:
        return [path]
    found = []
    try:
        from . import _paths
        here = os.path.dirname(os.path.abspath(__file__))
        beside = os.path.normpath(os.path.join(here, _paths.LIBSILC_DIR, _paths.LIBSILC_SONAME))
        if os.path.exists(beside):
            found.append(beside)
        found.append(_paths.LIBSILC_SONAME)
    except ImportError:  # the source tree's package: no install beside it
        found.append("libsilc.so.1")
    system = ctypes.util.find_library("silc")
    if system:
        found.append(system)
    return found


def _library():
    global _lib
    if _lib is not None:
        return _lib
    lib, tried = None, []
    for path in _candidates():
        try:
            lib = ctypes.CDLL(path)
            break
        except OSError as e:
            tried.append("%s (%s)" % (path, e))
    if lib is None:
        raise SilcError("libsilc not found: tried " + "; ".join(tried) + ". Set SILC_LIBRARY to its path "
                        "(build/lib/libsilc.so.1 in a build tree), install SILC (cmake --install), or "
                        "pass a server address for a remote session")
    vp, cp, env = ctypes.c_void_p, ctypes.c_char_p, ctypes.POINTER(_Envelope)
    for name, res, args in (("silc_open", ctypes.c_int, [ctypes.POINTER(vp), cp]),
                            ("silc_close", None, [ctypes.POINTER(vp)]),
                            ("silc_put", ctypes.c_int, [vp, cp, env]),
                            ("silc_get_complex", ctypes.c_int, [vp, env, cp]),
                            ("silc_exec", ctypes.c_int, [vp, cp]),
                            ("silc_cancel", ctypes.c_int, [vp]),
                            ("silc_context_errmsg", cp, [vp]),
                            ("silc_context_warnings", cp, [vp]),
                            ("silc_errmsg", cp, []),
                            ("silc_envelope_free", None, [env]),
                            ("silc_set_output", None, [vp, _OUTPUT, vp])):
        f = getattr(lib, name)
        f.restype, f.argtypes = res, args
    _lib = lib
    return lib


class _SigintCanceller:
    """Ctrl-C during an embedded exec.  The exec is one ctypes call that
    holds the main thread until the engine returns, so Python's SIGINT
    handler, which only runs between bytecodes on the main thread, would
    wait for the whole statement.  Python's C-level handler does run at
    once, and writes the signal's number to the wakeup fd
    (signal.set_wakeup_fd): while an exec runs on the main thread that fd is
    this pipe, and a daemon thread (one per process, started at the first
    such exec) reads it and calls silc_cancel.  The exec then fails with
    "interrupted" and, back in Python, the pending SIGINT raises
    KeyboardInterrupt as usual.  No thread is made per call."""

    _instance = None

    def __init__(self):
        self._r, self._w = os.pipe()
        os.set_blocking(self._w, False)          # set_wakeup_fd wants it so
        self._lock = threading.Lock()
        self._target = None                      # (lib, ctx) of the running exec
        threading.Thread(target=self._watch, name="silc-sigint", daemon=True).start()

    @classmethod
    def get(cls):
        if cls._instance is None:
            cls._instance = cls()
        return cls._instance

    def _watch(self):
        while True:
            signals = os.read(self._r, 64)
            if signal.SIGINT in signals:
                with self._lock:
                    if self._target is not None:
                        self._target[0].silc_cancel(self._target[1])

    def run(self, lib, ctx, text):
        """lib.silc_exec(ctx, text), cancelled by SIGINT."""
        with self._lock:
            self._target = (lib, ctx)
        previous = signal.set_wakeup_fd(self._w, warn_on_full_buffer=False)
        try:
            return lib.silc_exec(ctx, text)
        finally:
            signal.set_wakeup_fd(previous)
            with self._lock:
                self._target = None


def _sigint_cancels():
    """Whether Ctrl-C is Python's KeyboardInterrupt here: on the main thread,
    with Python's default SIGINT handler (a program's own handler is left
    alone, as the remote session does)."""
    return (threading.current_thread() is threading.main_thread()
            and signal.getsignal(signal.SIGINT) is signal.default_int_handler)


def _copy(pointer, count, dtype):
    if count == 0 or not pointer:
        return np.empty(count, dtype=dtype)
    return np.ctypeslib.as_array(pointer, shape=(count,)).astype(dtype, copy=True)


class EmbeddedSession:
    """A SILC context in this process: its own names, closed by close()."""

    def __init__(self, config=None):
        self._lib = _library()
        self._ctx = ctypes.c_void_p()
        self.warnings = ""
        self._sink = None
        if self._lib.silc_open(ctypes.byref(self._ctx), config.encode() if config else None):
            msg = (self._lib.silc_context_errmsg(self._ctx) if self._ctx else self._lib.silc_errmsg()) or b""
            raise SilcError(msg.decode())
        # who / info / explain print through this, to sys.stdout or a list
        self._output = _OUTPUT(self._print)
        self._lib.silc_set_output(self._ctx, self._output, None)

    def _print(self, _user, text):
        text = text.decode("utf-8", "replace")
        if self._sink is not None:
            self._sink.append(text)
        else:
            import sys
            sys.stdout.write(text)

    def _check(self, rc):
        if rc:
            msg = self._lib.silc_context_errmsg(self._ctx).decode("utf-8", "replace")
            raise (UndefinedName if msg.startswith("undefined name '") else SilcError)(msg)

    def put(self, name, value):
        fmt, m, n, arrays = to_parts(name, value)
        # A complex128 array is already silc.h's interleaved doubles.
        e = _Envelope(m=m, n=n, format=fmt, nnz=len(arrays[-1]))
        dbl, i64 = ctypes.POINTER(ctypes.c_double), ctypes.POINTER(ctypes.c_int64)
        e.values = arrays[-1].ctypes.data_as(dbl)
        if fmt & ~COMPLEX == CSR:
            e.rowptr, e.colind = arrays[0].ctypes.data_as(i64), arrays[1].ctypes.data_as(i64)
        # silc_put copies: the arrays only need to live through the call
        self._check(self._lib.silc_put(self._ctx, name.encode(), ctypes.byref(e)))

    def get(self, name, sparse="array"):
        # Either field: this client takes complex values (as complex128).
        e = _Envelope()
        self._check(self._lib.silc_get_complex(self._ctx, ctypes.byref(e), name.encode()))
        try:
            width = 2 if e.format & COMPLEX else 1
            values = _copy(e.values, width * e.nnz, np.float64).view(entry_dtype(e.format))
            if e.format & ~COMPLEX == CSR:
                arrays = [_copy(e.rowptr, e.m + 1, np.int64), _copy(e.colind, e.nnz, np.int64), values]
            else:
                arrays = [values]
            return from_parts(e.format, e.m, e.n, e.kl, e.ku, arrays, sparse)
        finally:
            self._lib.silc_envelope_free(ctypes.byref(e))

    def exec(self, statements, out=None):
        """Ctrl-C (SIGINT on the main thread) cancels the statement running
        (the store as before it) and raises KeyboardInterrupt; a library
        call that never asks for interrupts (a MUMPS or UMFPACK
        factorization) finishes first."""
        text = statements.encode()
        self._sink = out
        try:
            if _sigint_cancels():
                rc = _SigintCanceller.get().run(self._lib, self._ctx, text)
            else:
                rc = self._lib.silc_exec(self._ctx, text)
        finally:
            self._sink = None
        w = self._lib.silc_context_warnings(self._ctx)
        self.warnings = w.decode("utf-8", "replace") if w else ""
        self._check(rc)

    def cancel(self):
        # silc_cancel only sets the engine's flag: safe while another
        # thread is inside silc_exec (ctypes released the GIL there).
        if self._ctx:
            self._lib.silc_cancel(self._ctx)

    def text_of(self, statement):
        out = []
        self.exec(statement, out)
        return "".join(out)

    def explain(self, statement):
        return self.text_of("explain " + statement)

    def info(self, name=None):
        if not name:
            raise SilcError("info without a name describes a server's session; "
                            "an embedded session has `who` and `set`")
        return self.text_of("info " + name)

    def names(self):
        lines = self.text_of("who").splitlines()
        return [] if not lines or lines[0].startswith("no variables") else [ln.split()[0] for ln in lines[1:] if ln]

    def delete(self, name):
        if name not in self.names():
            raise UndefinedName("undefined name '%s'" % name)
        self.exec("clear " + name)

    def close(self):
        if self._ctx:
            self._lib.silc_close(ctypes.byref(self._ctx))
            self._ctx = ctypes.c_void_p()
