"""silc._values -- numpy and scipy values to SILC's storage and back, for
both back ends (_remote, _embedded), and the package's errors.

A value goes as its format, shape and arrays (CSR: int64 indptr, int64
indices, float64 data; dense: float64 column-major), without a copy where
the caller's arrays already are so.  What comes back is checked before any
array is allocated or trusted, as silcd checks what it receives (the same
rules and messages as core/client/protocol.c and core/store/envelope.c): a
descriptor's sizes against its format and the client's cap, CSR structure
(indptr from 0 to nnz, never decreasing, columns in range and increasing),
so that a hostile server cannot make scipy read out of bounds.
"""
import numpy as np

DENSE, CSR, BAND = 0, 1, 2
_FORMAT_NAMES = {DENSE: "dense", CSR: "csr", BAND: "band"}
MAX_DIM = 1 << 40          # rows or columns of one value (docs/protocol.md)
DEFAULT_MAX_VALUE_BYTES = 2 << 30


class Error(Exception):
    """Everything the silc package raises: a request SILC refused (its
    message, the C API's text), a lost or silent connection, a bad reply.

    >>> try:
    ...     s.get("nope")
    ... except silc.Error as e:
    ...     print(e)                   # undefined name 'nope'
    """


SilcError = Error


class UndefinedName(Error, KeyError):
    """A name the session does not hold: also a KeyError, as for a dict
    (``s["nope"]``, ``del s["nope"]``)."""

    def __str__(self):
        return Exception.__str__(self)


class ProtocolError(Error):
    """A reply no well-behaved silcd sends (a malformed frame, a value that
    breaks its own format, more than the client accepts); the message names
    the server.  Unless the value was only over the client's cap (then it was
    skipped whole and the session goes on), the connection is closed."""


class Timeout(Error, TimeoutError):
    """The server sent nothing for the session's timeout (``timeout``,
    SILC_IO_TIMEOUT; ``exec_timeout``, SILC_EXEC_TIMEOUT for an exec's
    reply); the connection is closed."""


def _is_complex(value):
    dtype = getattr(value, "dtype", None)
    if dtype is not None:
        return np.dtype(dtype).kind == "c"
    if isinstance(value, complex):
        return True
    if isinstance(value, (list, tuple)):
        try:
            return np.asarray(value).dtype.kind == "c"
        except (TypeError, ValueError):
            return False
    return False


def to_parts(name, value):
    """(format, m, n, arrays) of value: numpy (0-D: 1x1, 1-D: n x 1, 2-D),
    a scipy.sparse matrix or array, or an (indptr, indices, data, (m, n))
    tuple.  Complex values are refused: SILC's values are real."""
    if _is_complex(value) or (isinstance(value, tuple) and len(value) == 4
                              and _is_complex(value[2])):
        raise Error("'%s': complex values are not supported (SILC's values are real); "
                    "pass the real and imaginary parts as two values" % name)
    try:
        if hasattr(value, "tocsr") and hasattr(value, "shape"):
            c = value.tocsr()
            c.sort_indices()
            value = (c.indptr, c.indices, c.data, c.shape)
        if isinstance(value, tuple) and len(value) == 4:
            indptr, indices, data, (m, n) = value
            return CSR, int(m), int(n), [np.ascontiguousarray(indptr, dtype=np.int64),
                                         np.ascontiguousarray(indices, dtype=np.int64),
                                         np.ascontiguousarray(data, dtype=np.float64)]
        a = np.asarray(value, dtype=np.float64)
    except (TypeError, ValueError) as e:
        raise Error("'%s': cannot store a %s: %s" % (name, type(value).__name__, e)) from None
    if a.ndim == 0:
        a = a.reshape(1, 1)
    elif a.ndim == 1:
        a = a.reshape(-1, 1)
    elif a.ndim != 2:
        raise Error("'%s': only scalars, vectors and matrices can be stored (got %d "
                    "dimensions)" % (name, a.ndim))
    m, n = a.shape
    # Column-major without a copy when it already is.
    return DENSE, m, n, [a.reshape(-1, order="F") if a.flags.f_contiguous else
                         np.asfortranarray(a).reshape(-1, order="F")]


def layout(fmt, m, n, nnz, kl, ku):
    """(rowptr, colind, values) byte counts of a value descriptor, checked
    as protocol.c's proto_layout_of checks it (same messages); raises
    ProtocolError."""
    if fmt not in _FORMAT_NAMES:
        raise ProtocolError("unknown value format %d" % fmt)
    if m < 0 or n < 0 or nnz < 0 or kl < 0 or ku < 0:
        raise ProtocolError("negative size in value descriptor (m = %d, n = %d, nnz = %d, "
                            "kl = %d, ku = %d)" % (m, n, nnz, kl, ku))
    if m > MAX_DIM or n > MAX_DIM:
        raise ProtocolError("dimensions %dx%d exceed the protocol's limit of 2^40" % (m, n))
    if fmt == DENSE:
        if nnz != m * n:
            raise ProtocolError("dense %dx%d value declares %d entries" % (m, n, nnz))
        if kl or ku:
            raise ProtocolError("dense value with band widths")
        return 0, 0, 8 * nnz
    if fmt == CSR:
        if kl or ku:
            raise ProtocolError("csr value with band widths")
        if nnz > (1 << 64) // 32:
            raise ProtocolError("csr value declares %d entries" % nnz)
        return 8 * (m + 1), 8 * nnz, 8 * nnz
    if kl > 2**31 - 1 or ku > 2**31 - 1 or nnz != (kl + ku + 1) * n:
        raise ProtocolError("band %dx%d value with kl = %d, ku = %d declares %d entries"
                            % (m, n, kl, ku, nnz))
    return 0, 0, 8 * nnz


def over_cap(fmt, m, n, nbytes, cap):
    """The message for a value of nbytes over the client's cap, or None."""
    if nbytes <= cap:
        return None
    return ("a %dx%d %s value of %d bytes, over the client's limit of %d bytes per value "
            "(SILC_MAX_REPLY_BYTES, Session(max_value_bytes=...))"
            % (m, n, _FORMAT_NAMES[fmt], nbytes, cap))


def check_csr(indptr, indices, m, n, nnz):
    """CSR arrays as envelope.c checks them, in its order and with its
    messages; raises ProtocolError.  Vectorised: one pass per rule."""
    if indptr[m] != nnz:
        raise ProtocolError("rowptr[m] = %d but the descriptor declares %d entries"
                            % (indptr[m], nnz))
    if indptr[0] != 0:
        raise ProtocolError("rowptr[0] is %d, must be 0" % indptr[0])
    down = np.flatnonzero(indptr[1:] < indptr[:-1])
    if down.size:
        i = int(down[0])
        raise ProtocolError("rowptr decreases at row %d (rowptr[%d] = %d > rowptr[%d] = %d)"
                            % (i, i, indptr[i], i + 1, indptr[i + 1]))
    if nnz == 0:
        return
    out = np.flatnonzero((indices < 0) | (indices >= n))
    # Entry k > 0 must exceed entry k-1 unless a row starts at k.
    starts = np.zeros(nnz, dtype=bool)
    starts[indptr[:-1][indptr[:-1] < nnz]] = True
    unsorted = np.flatnonzero((indices[1:] <= indices[:-1]) & ~starts[1:]) + 1
    first = min(int(out[0]) if out.size else nnz, int(unsorted[0]) if unsorted.size else nnz)
    if first == nnz:
        return
    row = int(np.searchsorted(indptr, first, side="right")) - 1
    if out.size and out[0] == first:
        raise ProtocolError("column index %d out of range [0, %d) in row %d"
                            % (indices[first], n, row))
    raise ProtocolError("columns of row %d are %s" % (
        row, "duplicated" if indices[first] == indices[first - 1] else "not sorted"))


def from_parts(fmt, m, n, kl, ku, arrays, sparse="array", max_bytes=DEFAULT_MAX_VALUE_BYTES):
    """The Python value of SILC's (checked) arrays: dense as a 2-D numpy
    array; CSR as scipy.sparse.csr_array (csr_matrix when sparse is
    "matrix"; the (indptr, indices, data, shape) tuple without scipy); band
    kept as band, scipy.sparse.dia_array (dia_matrix), whose data is the
    LAPACK band storage itself -- without scipy, dense only if m*n doubles
    fit max_bytes."""
    if fmt == CSR:
        indptr, indices, data = arrays
        try:
            import scipy.sparse as sp
        except ImportError:
            return (indptr, indices, data, (m, n))
        kind = sp.csr_matrix if sparse == "matrix" else sp.csr_array
        return kind((data, indices, indptr), shape=(m, n))
    vals = arrays[0]
    if fmt == DENSE:
        return vals.reshape((m, n), order="F")
    # Band, LAPACK layout: A(i, j) = band[ku + i - j, j], so storage row r
    # is the diagonal of offset j - i = ku - r.
    ld = kl + ku + 1
    band = vals.reshape((ld, n), order="F")
    try:
        import scipy.sparse as sp
        kind = sp.dia_matrix if sparse == "matrix" else sp.dia_array
        return kind((band, ku - np.arange(ld)), shape=(m, n))
    except ImportError:
        pass
    if 8 * m * n > max_bytes:
        raise Error("a %dx%d band value is %d bytes dense, over the client's limit of %d "
                    "bytes (install scipy to get it as a dia_array)" % (m, n, 8 * m * n, max_bytes))
    a = np.zeros((m, n))
    for j in range(n):
        for i in range(max(0, j - ku), min(m, j + kl + 1)):
            a[i, j] = band[ku + i - j, j]
    return a
