/*
 * CRS.java -- a sparse matrix in compressed row storage, 0-based, the seeds'
 * helper type: row i holds colind[rowptr[i] .. rowptr[i+1]-1] with the values
 * at the same positions.  SILC wants each row's columns strictly increasing;
 * fromTriplets builds such a matrix from (i, j, v) entries in any order,
 * summing duplicates, as MATLAB's sparse(i, j, v, m, n) and SciPy's
 * coo_matrix do.
 */
package silc;

/** A sparse m x n matrix in 0-based compressed rows; nnz = rowptr[m]. */
public final class CRS implements Value {
    public final int m, n;
    /** m + 1 row starts; rowptr[0] = 0, never decreasing. */
    public final int[] rowptr;
    /** Column of each stored entry (at least nnz of them; only nnz are used). */
    public final int[] colind;
    /** Value of each stored entry (at least nnz of them). */
    public final double[] val;

    /**
     * A matrix over the given arrays (not copied).  The arrays may be longer
     * than nnz = rowptr[m], so a program can keep them and refill them every
     * step; the server checks the columns (in range, strictly increasing per
     * row) and names the row that is wrong.
     */
    public CRS(int m, int n, int[] rowptr, int[] colind, double[] val) {
        Triplets.checkArrays("CRS", m, n, rowptr, colind, val, 1);
        this.m = m;
        this.n = n;
        this.rowptr = rowptr;
        this.colind = colind;
        this.val = val;
    }

    /** Stored entries. */
    public int nnz() {
        return rowptr[m];
    }

    /**
     * The m x n matrix with entry (i[k], j[k]) += v[k] for k < count:
     * duplicates are summed, each row's columns sorted.  O(count + m) time
     * (a counting sort by row, then a sort within each row).
     */
    public static CRS fromTriplets(int m, int n, int[] i, int[] j, double[] v, int count) {
        Triplets.Rows r = Triplets.compress("CRS.fromTriplets", m, n, i, j, v, 1, count);
        return new CRS(m, n, r.rowptr(), r.colind(), r.val());
    }

    /** Entry (i, j); 0 where nothing is stored. */
    public double get(int i, int j) {
        int at = Triplets.find(rowptr, colind, i, j);
        return at < 0 ? 0 : val[at];
    }

    /** y = A x. */
    public double[] times(double[] x) {
        if (x.length != n) throw new IllegalArgumentException("CRS.times: " + m + "x" + n + " times " + x.length);
        double[] y = new double[m];
        for (int r = 0; r < m; r++) {
            double s = 0;
            for (int q = rowptr[r]; q < rowptr[r + 1]; q++) s += val[q] * x[colind[q]];
            y[r] = s;
        }
        return y;
    }

    @Override
    public int rows() {
        return m;
    }

    @Override
    public int cols() {
        return n;
    }
}
