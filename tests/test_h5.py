"""test_h5.py -- SILC's HDF5 files against h5py, scipy and Octave, both
ways: a file SILC saves is read here without SILC (dense: column-major with
MATLAB_class, which h5py users transpose and Octave's `load -hdf5` reads
as it is; CSR as scipy's csr_matrix from data/indices/indptr/shape; band
with its attributes), and a file h5py writes in those layouts (as scipy /
anndata users do) is loaded by SILC and fetched back exactly, skipping
what is not SILC's.  Complex values both ways as h5py's compound {r, i}
(complex64 promoted), bit for bit; compounds that are not complex
numbers skipped or refused, by name.  Octave's part (real values, and what
Octave 7.3 makes of complex ones) is skipped, saying so, without octave.

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

    # Complex both ways, as h5py writes numpy's complex: the compound
    # {r, i}.  h5py writes, SILC loads (row-major complex128, complex64
    # promoted exactly, column-major with MATLAB_class, scipy's complex
    # CSR), and SILC's save of them and of a value it computed is read back
    # by h5py bit for bit.
    rng = np.random.default_rng(31)
    Zr = rng.standard_normal((3, 4)) + 1j * rng.standard_normal((3, 4))
    Z64 = (rng.standard_normal((2, 3)) + 1j * rng.standard_normal((2, 3))).astype(np.complex64)
    Zm = rng.standard_normal((2, 5)) + 1j * rng.standard_normal((2, 5))
    Mc = sp.random(5, 4, density=0.5, format="csr", random_state=5)
    Mc.sort_indices()
    Mc = sp.csr_matrix((Mc.data + 1j * rng.standard_normal(Mc.nnz), Mc.indices, Mc.indptr), shape=Mc.shape)
    Ar, Ai = rng.standard_normal((2, 2)), rng.standard_normal((2, 2))
    path4, path5 = os.path.join(d, "complex_h5py.h5"), os.path.join(d, "complex_silc.h5")
    with h5py.File(path4, "w") as f:
        f["Zr"], f["Z64"], f["Ar"], f["Ai"] = Zr, Z64, Ar, Ai
        f["Zm"] = Zm.T                           # column-major 2x5, as MATLAB -v7.3 lays it out
        f["Zm"].attrs["MATLAB_class"] = "double"
        g = f.create_group("Mc")
        g["data"], g["indices"], g["indptr"] = Mc.data, Mc.indices, Mc.indptr
        g.attrs["shape"] = Mc.shape
    with h5py.File(path4, "r") as f:
        t = f["Zr"].id.get_type()
        check(t.get_class() == h5py.h5t.COMPOUND and [t.get_member_name(k) for k in range(t.get_nmembers())]
              == [b"r", b"i"], "h5py writes complex as the compound {r, i}")
    r = subprocess.run([silc, "-e", 'load "%s"; W = complex(Ar, Ai); save "%s"' % (path4, path5), "--get", "Zr"],
                       capture_output=True, text=True)
    check(r.returncode == 0, "load and save of complex values: %s" % r.stderr)
    zr = mm_values(r.stdout)[0] if r.returncode == 0 else []
    got = np.array(zr[0::2]) + 1j * np.array(zr[1::2])
    check(got.size == Zr.size and np.array_equal(got.reshape(4, 3).T, Zr),
          "complex128 from h5py loads exactly (fetched as Matrix Market): %r" % got)
    with h5py.File(path5, "r") as f:
        def dense(name):
            dset = f[name]
            check(dset.dtype == np.complex128 and dset.attrs.get("MATLAB_class") == "double",
                  "%s saved as complex128 {r, i}, column-major: %r %r" % (name, dset.dtype, dict(dset.attrs)))
            return dset[()].T

        check(np.array_equal(dense("Zr"), Zr), "complex128 row-major: back bit for bit")
        check(np.array_equal(dense("Z64"), Z64.astype(np.complex128)), "complex64 promoted exactly")
        check(np.array_equal(dense("Zm"), Zm), "column-major complex with MATLAB_class: back bit for bit")
        check(np.array_equal(dense("W"), Ar + 1j * Ai), "complex(Ar, Ai) computed by SILC, read by h5py")
        g = f["Mc"]
        back = sp.csr_matrix((g["data"][()], g["indices"][()], g["indptr"][()]), shape=tuple(g.attrs["shape"]))
        check(g["data"].dtype == np.complex128 and (back != Mc).nnz == 0 and np.array_equal(back.data, Mc.data),
              "complex CSR as scipy reads it: back bit for bit")

    # Compounds that are not h5py's complex: another program's records are
    # skipped by a load of the whole file (named in the warning); r/i
    # members that are not float32/float64 are refused; by name, each fails
    # with its name and changes nothing.
    path6 = os.path.join(d, "compounds.h5")
    with h5py.File(path6, "w") as f:
        f["ab"] = np.zeros(3, dtype=[("a", "<f8"), ("b", "<f8")])
        f["rix"] = np.zeros(3, dtype=[("r", "<f8"), ("i", "<f8"), ("x", "<f8")])
        f["ints"] = np.zeros(3, dtype=[("r", "<i4"), ("i", "<i4")])
        f["half"] = np.zeros(3, dtype=[("r", "<f2"), ("i", "<f2")])
        f["ok"] = np.array([1 + 2j])
        g = f.create_group("Q")
        g["data"] = np.zeros(1, dtype=[("re", "<f8"), ("im", "<f8")])
        g["indices"], g["indptr"] = np.array([0]), np.array([0, 1])
        g.attrs["shape"] = (1, 1)
    for name, want in [("ab", "'ab' in '%s' is not a SILC value: a compound dataset must be a complex number as "
                              "h5py writes it, members exactly r and i (it has: a, b)" % path6),
                       ("rix", "(it has: r, i, x)"),
                       ("ints", "'ints' in '%s' is a compound {r, i} whose members are not both float32 or float64"
                        % path6),
                       ("half", "'half' in '%s' is a compound {r, i} whose members are not both" % path6),
                       ("Q", "'Q/data' in '%s' is not a SILC value: a compound dataset must be a complex number"
                        % path6)]:
        r = subprocess.run([silc, "-e", 'ok = 7; load "%s" ok %s' % (path6, name), "--get", "ok"],
                           capture_output=True, text=True)
        check(r.returncode == 1 and want in r.stderr, "load of compound %s refused: %s" % (name, r.stderr))
    r = subprocess.run([silc, "-e", 'load "%s" ok rix ab' % path6], capture_output=True, text=True)
    check(r.returncode == 1 and "'rix' in" in r.stderr, "records asked for by name fail the load: %s" % r.stderr)
    with h5py.File(path6, "a") as f:
        del f["ints"], f["half"], f["Q"]
    r = subprocess.run([silc, "-e", 'load "%s"' % path6, "--get", "ok"], capture_output=True, text=True)
    check(r.returncode == 0 and "skipped 2 objects" in r.stderr and "'ab' (not a SILC value: a compound" in r.stderr
          and "'rix' (not a SILC value" in r.stderr and mm_values(r.stdout) == [[1.0, 2.0]],
          "a load of the whole file skips other programs' records, naming them: %s %s" % (r.stdout, r.stderr))

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
        # Complex: Octave 7.3 reads and writes its own compound {real, imag}.
        # It takes h5py's {r, i} for complex but, HDF5 converting members by
        # name, reads every entry as 0 (docs/hdf5.md says so: if this check
        # fails, Octave changed and the docs must too); the real and
        # imaginary parts saved as two values reach Octave exactly.
        path7 = os.path.join(d, "complex_for_octave.h5")
        run('z = [1 + 2i, 3; -4i, 5.5]; zr = real(z); zi = imag(z); save "%s" z zr zi' % path7)
        r = subprocess.run([octave, "--no-gui", "--norc", "-q", "--eval",
                            "load('-hdf5', '%s'); assert(isequal(complex(zr, zi), [1+2i, 3; -4i, 5.5])); "
                            "printf('octave: parts exact; z complex %%d, nonzeros %%d\\n', iscomplex(z), nnz(z))"
                            % path7], capture_output=True, text=True, timeout=60)
        check(r.returncode == 0 and "octave: parts exact; z complex 1, nonzeros 0" in r.stdout,
              "Octave reads real(z), imag(z) exactly and h5py's complex z as zeros: %s %s" % (r.stdout, r.stderr))
        # Octave's own -hdf5 layout (a group with type and value) is not
        # SILC's: a load of the whole file skips it, naming it.
        path8 = os.path.join(d, "from_octave.h5")
        subprocess.run([octave, "--no-gui", "--norc", "-q", "--eval",
                        "w = [1+2i, 3]; save('-hdf5', '%s', 'w')" % path8], capture_output=True, timeout=60)
        r = subprocess.run([silc, "-e", 'load "%s"' % path8], capture_output=True, text=True)
        check(r.returncode == 0 and "skipped 1 object" in r.stderr and "'w' (not a SILC value: a group needs" in r.stderr,
              "Octave's own complex layout is skipped, named: %s" % r.stderr)
    else:
        print("test_h5.py: no %s: Octave's reading of SILC's files not checked" % octave)

done()
