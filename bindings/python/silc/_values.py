"""silc._values -- numpy and scipy values to SILC's storage and back, for
both back ends (_remote, _embedded): a value goes as its format, shape and
arrays (CSR: int64 indptr, int64 indices, float64 data; dense: float64
column-major), without a copy where the caller's arrays already are so.
"""
import numpy as np

DENSE, CSR, BAND = 0, 1, 2


class SilcError(Exception):
    """A request SILC refused (its message, the C API's text) or a lost
    connection: silc.Error."""


def to_parts(name, value):
    """(format, m, n, arrays) of value: numpy (0-D: 1x1, 1-D: n x 1, 2-D),
    a scipy.sparse matrix or an (indptr, indices, data, (m, n)) tuple."""
    if hasattr(value, "tocsr") and hasattr(value, "shape"):
        c = value.tocsr()
        c.sort_indices()
        value = (c.indptr, c.indices, c.data, c.shape)
    if isinstance(value, tuple):
        indptr, indices, data, (m, n) = value
        return CSR, m, n, [np.ascontiguousarray(indptr, dtype=np.int64),
                           np.ascontiguousarray(indices, dtype=np.int64),
                           np.ascontiguousarray(data, dtype=np.float64)]
    a = np.asarray(value, dtype=np.float64)
    if a.ndim == 0:
        a = a.reshape(1, 1)
    elif a.ndim == 1:
        a = a.reshape(-1, 1)
    elif a.ndim != 2:
        raise SilcError("'%s': only vectors and matrices can be stored" % name)
    m, n = a.shape
    # Column-major without a copy when it already is.
    return DENSE, m, n, [a.reshape(-1, order="F") if a.flags.f_contiguous else
                         np.asfortranarray(a).reshape(-1, order="F")]


def from_parts(fmt, m, n, kl, ku, arrays):
    """The Python value of SILC's arrays: dense and band as 2-D numpy, CSR
    as scipy.sparse.csr_matrix (the tuple when scipy is missing)."""
    if fmt == CSR:
        indptr, indices, data = arrays
        try:
            import scipy.sparse
            return scipy.sparse.csr_matrix((data, indices, indptr), shape=(m, n))
        except ImportError:
            return (indptr, indices, data, (m, n))
    vals = arrays[0]
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
