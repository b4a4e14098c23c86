"""test_h5.py -- SILC's HDF5 files against h5py and scipy, both ways:
a file SILC saves is read here without SILC (dense, CSR as scipy's
csr_matrix from data/indices/indptr/shape, band with its attributes), and
a file h5py writes in those layouts (as scipy / anndata users do) is loaded
by SILC and fetched back exactly.

    /usr/bin/python3 tests/test_h5.py path/to/silc

Prints "N passed, N failed" last and exits 1 on a failure.
"""
import os
import subprocess
import sys
import tempfile

import h5py
import numpy as np
import scipy.sparse as sp

silc = sys.argv[1]
from pychecks import check, done  # noqa: E402 (tests/, beside this file)


def run(statements, *gets):
    args = [silc, "-e", statements]
    for g in gets:
        args += ["--get", g]
    r = subprocess.run(args, capture_output=True, text=True)
    check(r.returncode == 0, "silc -e %r: %s" % (statements, r.stderr))
    return r.stdout


def mm_values(text):
    """The numbers of the Matrix Market blocks in text, one list per block."""
    blocks, cur, size_seen = [], None, False
    for line in text.splitlines():
        if line.startswith("%%MatrixMarket"):
            cur, size_seen = [], False
            blocks.append(cur)
        elif line.startswith("%") or not line.strip():
            continue
        elif not size_seen:
            size_seen = True
        else:
            cur.extend(float(x) for x in line.split())
    return blocks


with tempfile.TemporaryDirectory() as d:
    # SILC writes, h5py reads.
    path = os.path.join(d, "silc.h5")
    run('D = [1, 2, 3; 4, 5, 6.5]; S = sparse([1; 3; 2; 3], [1; 1; 2; 3], [1.5; -2; 3; 4], 3, 4); '
        'B = band(sparse([1; 2; 2; 3], [1; 1; 2; 3], [1; 2; 3; 4], 3, 3), 1, 0); save "%s"' % path)
    with h5py.File(path, "r") as f:
        check(np.array_equal(f["D"][()], [[1, 2, 3], [4, 5, 6.5]]), "dense as a (m, n) dataset: %r" % f["D"][()])
        g = f["S"]
        S = sp.csr_matrix((g["data"][()], g["indices"][()], g["indptr"][()]), shape=tuple(g.attrs["shape"]))
        want = np.array([[1.5, 0, 0, 0], [0, 3, 0, 0], [-2, 0, 4, 0]])
        check(np.array_equal(S.toarray(), want), "CSR group as scipy reads it: %r" % S.toarray())
        check(g.attrs["encoding-type"] == "csr_matrix", "anndata's encoding-type: %r" % g.attrs["encoding-type"])
        b = f["B"]
        check(b.attrs["silc-format"] == "band" and int(b.attrs["kl"][0]) == 1 and int(b.attrs["ku"][0]) == 0
              and b.shape == (2, 3), "band: LAPACK storage (kl+ku+1, n) with kl, ku: %r %r"
              % (b.shape, dict(b.attrs)))
        check(np.array_equal(b[()], [[1, 3, 4], [2, 0, 0]]), "band storage: %r" % b[()])

    # h5py writes (scipy's layout), SILC loads.
    path2 = os.path.join(d, "h5py.h5")
    M = sp.random(5, 4, density=0.5, format="csr", random_state=3)
    M.sort_indices()
    V = np.arange(6.0).reshape(3, 2) / 7
    with h5py.File(path2, "w") as f:
        g = f.create_group("M")
        g["data"], g["indices"], g["indptr"] = M.data, M.indices.astype(np.int32), M.indptr
        g.attrs["shape"] = M.shape
        f["V"] = V
        f["w"] = np.array([1.0, 2.0, 3.0])   # 1-D: a column vector
    out = run('load "%s"; Md = dense(M)' % path2, "Md", "V", "w")
    md, v, w = mm_values(out)
    check(np.array_equal(np.array(md).reshape(4, 5).T, M.toarray()), "CSR from h5py loads exactly")
    check(np.array_equal(np.array(v).reshape(2, 3).T, V), "dense from h5py loads exactly")
    check(w == [1.0, 2.0, 3.0], "a 1-D dataset loads as a column vector: %r" % w)

done()
