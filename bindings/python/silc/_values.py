"""silc._values -- numpy and scipy values to SILC's storage and back, for
both back ends (_remote, _embedded), and the package's errors.

A value goes as its format, shape and arrays (CSR: int64 indptr, int64
indices, float64 data; dense: float64 column-major), without a copy where
the caller's arrays already are so.  A complex value (any complex dtype,
promoted to complex128) goes with the format's COMPLEX bit and its entries
as NumPy stores complex128: real and imaginary part interleaved, SILC's own
layout (silc.h).  The dtype decides the field; other dtypes than bool,
integers, floats and complex (object, strings, dates) are refused, never
converted by guess (forcing every array to float64 is what once dropped
imaginary parts, issue 31).  What comes back is checked before any
array is allocated or trusted, as silcd checks what it receives (the same
rules and messages as core/client/protocol.c and core/store/envelope.c): a
descriptor's sizes against its format and the client's cap, CSR structure
(indptr from 0 to nnz, never decreasing, columns in range and increasing),
so that a hostile server cannot make scipy read out of bounds.
"""
import numpy as np

DENSE, CSR, BAND = 0, 1, 2
COMPLEX = 16               # the format bit of a complex value (docs/protocol.md)
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


def _stored_dtype(name, what, dtype):
    """float64 for bool, integer and float dtypes, complex128 for complex
    ones (complex64 promoted); anything else is refused naming it."""
    kind = np.dtype(dtype).kind
    if kind in "biuf":
        return np.float64
    if kind == "c":
        return np.complex128
    raise Error("'%s': cannot store a %s of dtype %s: SILC's values are float64 or complex128 "
                "(convert it with .astype(float) or .astype(complex))" % (name, what, np.dtype(dtype)))


def to_parts(name, value):
    """(format, m, n, arrays) of value: numpy (0-D: 1x1, 1-D: n x 1, 2-D),
    a Python number or list, a scipy.sparse matrix or array (any format,
    converted to CSR), or an (indptr, indices, data, (m, n)) tuple.  The
    values array is float64, or complex128 with format | COMPLEX."""
    what = type(value).__name__
    try:
        if hasattr(value, "tocsr") and hasattr(value, "shape"):
            c = value.tocsr()
            c.sort_indices()
            value = (c.indptr, c.indices, c.data, c.shape)
        if isinstance(value, tuple) and len(value) == 4:
            indptr, indices, data, (m, n) = value
            data = np.asarray(data)
            dtype = _stored_dtype(name, "sparse matrix", data.dtype)
            return (CSR | (COMPLEX if dtype is np.complex128 else 0), int(m), int(n),
                    [np.ascontiguousarray(indptr, dtype=np.int64),
                     np.ascontiguousarray(indices, dtype=np.int64),
                     np.ascontiguousarray(data, dtype=dtype)])
        a = np.asarray(value)
        a = a.astype(_stored_dtype(name, what, a.dtype), copy=False)
    except (TypeError, ValueError) as e:
        raise Error("'%s': cannot store a %s: %s" % (name, what, e)) from None
    if a.ndim == 0:
        a = a.reshape(1, 1)
    elif a.ndim == 1:
        a = a.reshape(-1, 1)
    elif a.ndim != 2:
        raise Error("'%s': only scalars, vectors and matrices can be stored (got %d "
                    "dimensions)" % (name, a.ndim))
    m, n = a.shape
    fmt = DENSE | (COMPLEX if a.dtype == np.complex128 else 0)
    # Column-major without a copy when it already is.
    return fmt, m, n, [a.reshape(-1, order="F") if a.flags.f_contiguous else
                       np.asfortranarray(a).reshape(-1, order="F")]


def as_doubles(a):
    """A values array as the doubles that travel: complex128 viewed as
    interleaved float64 (no copy), anything else as it is."""
    return a.view(np.float64) if a.dtype == np.complex128 else a


def entry_dtype(fmt):
    """The dtype of a value's entries: complex128 when fmt has COMPLEX."""
    return np.complex128 if fmt & COMPLEX else np.float64


def layout(fmt, m, n, nnz, kl, ku):
    """(rowptr, colind, values) byte counts of a value descriptor, checked
    as protocol.c's proto_layout_of checks it (same messages); a complex
    value (fmt | COMPLEX) has 16 bytes an entry; raises ProtocolError."""
    entry = 16 if fmt & COMPLEX else 8
    if fmt & ~COMPLEX not in _FORMAT_NAMES:
        raise ProtocolError("unknown value format %d" % fmt)
    fmt &= ~COMPLEX
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
        return 0, 0, entry * nnz
    if fmt == CSR:
        if kl or ku:
            raise ProtocolError("csr value with band widths")
        if nnz > (1 << 64) // 32:
            raise ProtocolError("csr value declares %d entries" % nnz)
        return 8 * (m + 1), 8 * nnz, entry * nnz
    if kl > 2**31 - 1 or ku > 2**31 - 1 or nnz != (kl + ku + 1) * n:
        raise ProtocolError("band %dx%d value with kl = %d, ku = %d declares %d entries"
                            % (m, n, kl, ku, nnz))
    return 0, 0, entry * nnz


def over_cap(fmt, m, n, nbytes, cap):
    """The message for a value of nbytes over the client's cap, or None."""
    if nbytes <= cap:
        return None
    return ("a %dx%d %s value of %d bytes, over the client's limit of %d bytes per value "
            "(SILC_MAX_REPLY_BYTES, Session(max_value_bytes=...))"
            % (m, n, _FORMAT_NAMES[fmt & ~COMPLEX], nbytes, cap))


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
    LAPACK band storage itself -- without scipy, dense only if m*n entries
    fit max_bytes.  The values array holds entry_dtype(fmt) entries
    (complex128 for a complex value: its interleaved doubles viewed)."""
    fmt &= ~COMPLEX
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
    dense_bytes = band.itemsize * m * n
    if dense_bytes > max_bytes:
        raise Error("a %dx%d band value is %d bytes dense, over the client's limit of %d "
                    "bytes (install scipy to get it as a dia_array)" % (m, n, dense_bytes, max_bytes))
    a = np.zeros((m, n), dtype=band.dtype)
    for j in range(n):
        for i in range(max(0, j - ku), min(m, j + kl + 1)):
            a[i, j] = band[ku + i - j, j]
    return a
