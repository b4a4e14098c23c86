"""test_h5.py -- SILC's HDF5 files against h5py, scipy and Octave, both
ways: a file SILC saves is read here without SILC (dense: column-major with
MATLAB_class, which h5py users transpose and Octave's `load -hdf5` reads
as it is; CSR as scipy's csr_matrix from data/indices/indptr/shape; band
with its attributes), and a file h5py writes in those layouts (as scipy /
anndata users do) is loaded by SILC and fetched back exactly, skipping
what is not SILC's.  Octave's part is skipped, saying so, without octave.

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
        # column-major: HDF5 shape (n, m), marked by MATLAB_class; an h5py
        # user transposes (docs/hdf5.md)
        dset = f["D"]
        check(dset.shape == (3, 2) and dset.attrs["MATLAB_class"] == "double",
              "dense as HDF5 shape (n, m) with MATLAB_class: %r %r" % (dset.shape, dict(dset.attrs)))
        check(np.array_equal(dset[()].T, [[1, 2, 3], [4, 5, 6.5]]), "dense, transposed by h5py's reader: %r"
              % dset[()])
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
        f["C"] = np.array([[1.0, 2.0, 3.0], [4.0, 5.0, 6.0]]).T   # (3, 2), as SILC writes 2x3
        f["C"].attrs["MATLAB_class"] = "double"
        f["title"] = "not a matrix"           # another program's objects: skipped, named
        f.create_group("obs")["x"] = np.arange(3.0)
    r = subprocess.run([silc, "-e", 'load "%s"; Md = dense(M);' % path2, "--get", "Md", "--get", "V", "--get", "w",
                        "--get", "C"], capture_output=True, text=True)
    check(r.returncode == 0, "load of a file with foreign objects: %s" % r.stderr)
    check("warning: load: skipped 2 objects of" in r.stderr and "'obs' (not a SILC value: a group needs" in r.stderr
          and "'title' (not a SILC value: a dataset must be" in r.stderr, "the skipped objects are named: %s" % r.stderr)
    md, v, w, c = mm_values(r.stdout)
    check(np.array_equal(np.array(c).reshape(3, 2).T, [[1, 2, 3], [4, 5, 6]]),
          "a column-major dataset with MATLAB_class loads as m x n: %r" % c)
    check(np.array_equal(np.array(md).reshape(4, 5).T, M.toarray()), "CSR from h5py loads exactly")
    check(np.array_equal(np.array(v).reshape(2, 3).T, V), "dense from h5py loads exactly")
    check(w == [1.0, 2.0, 3.0], "a 1-D dataset loads as a column vector: %r" % w)

    # Octave's load -hdf5 sees SILC's dense matrices as SILC has them, and
    # SILC loads what Octave saves in the plain layout (-hdf5 of a struct
    # is Octave's own: skipped here).
    octave = "/usr/bin/octave-cli"
    if os.access(octave, os.X_OK):
        path3 = os.path.join(d, "for_octave.h5")
        run('D = [1, 2, 3; 4, 5, 6.5]; v = [1; 2; 3]; r = [7, 8]; save "%s" D v r' % path3)
        r = subprocess.run([octave, "--no-gui", "--norc", "-q", "--eval",
                            "load('-hdf5', '%s'); assert(isequal(D, [1 2 3; 4 5 6.5])); assert(isequal(v, [1; 2; 3])); "
                            "assert(isequal(r, [7 8])); disp('octave: D, v and r as saved')" % path3],
                           capture_output=True, text=True, timeout=60)
        check(r.returncode == 0 and "octave: D, v and r as saved" in r.stdout,
              "Octave's load -hdf5 reads SILC's dense values in their orientation: %s %s" % (r.stdout, r.stderr))
    else:
        print("test_h5.py: no %s: Octave's reading of SILC's files not checked" % octave)

done()
