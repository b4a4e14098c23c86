/*
 * CRS.java -- a sparse matrix in compressed row storage, 0-based, the seeds'
 * helper type: row i holds colind[rowptr[i] .. rowptr[i+1]-1] with the values
 * at the same positions.  SILC wants each row's columns strictly increasing;
 * fromTriplets builds such a matrix from (i, j, v) entries in any order,
 * summing duplicates, as MATLAB's sparse(i, j, v, m, n) and SciPy's
 * coo_matrix do.
 */
package silc;

import java.util.Arrays;

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
        if (m < 0 || n < 0) throw new IllegalArgumentException("CRS: negative size " + m + "x" + n);
        if (rowptr == null || rowptr.length < m + 1)
            throw new IllegalArgumentException("CRS: rowptr needs " + (m + 1) + " entries, got "
                    + (rowptr == null ? "null" : rowptr.length));
        int nnz = rowptr[m];
        if (nnz < 0 || colind == null || val == null || colind.length < nnz || val.length < nnz)
            throw new IllegalArgumentException("CRS: rowptr[m] = " + nnz + " entries, but colind has "
                    + (colind == null ? "null" : colind.length) + " and val "
                    + (val == null ? "null" : val.length));
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
        if (m < 0 || n < 0) throw new IllegalArgumentException("CRS.fromTriplets: negative size " + m + "x" + n);
        if (count < 0 || count > i.length || count > j.length || count > v.length)
            throw new IllegalArgumentException("CRS.fromTriplets: " + count + " entries, arrays hold "
                    + Math.min(i.length, Math.min(j.length, v.length)));
        int[] start = new int[m + 1];
        for (int k = 0; k < count; k++) {
            if (i[k] < 0 || i[k] >= m || j[k] < 0 || j[k] >= n)
                throw new IllegalArgumentException("CRS.fromTriplets: entry " + k + " at (" + i[k] + ", " + j[k]
                        + ") lies outside " + m + "x" + n);
            start[i[k] + 1]++;
        }
        for (int r = 0; r < m; r++) start[r + 1] += start[r];
        int[] fill = Arrays.copyOf(start, m);
        long[] keyed = new long[count]; // column << 32 | entry, sorted within each row
        for (int k = 0; k < count; k++) keyed[fill[i[k]]++] = ((long) j[k] << 32) | k;
        int[] rowptr = new int[m + 1], colind = new int[count];
        double[] val = new double[count];
        int at = 0;
        for (int r = 0; r < m; r++) {
            Arrays.sort(keyed, start[r], start[r + 1]);
            rowptr[r] = at;
            for (int q = start[r]; q < start[r + 1]; q++) {
                int col = (int) (keyed[q] >>> 32), k = (int) (keyed[q] & 0xffffffffL);
                if (at > rowptr[r] && colind[at - 1] == col) {
                    val[at - 1] += v[k];
                } else {
                    colind[at] = col;
                    val[at++] = v[k];
                }
            }
        }
        rowptr[m] = at;
        return new CRS(m, n, rowptr, colind, val);
    }

    /** Entry (i, j); 0 where nothing is stored. */
    public double get(int i, int j) {
        int lo = rowptr[i], hi = rowptr[i + 1] - 1;
        while (lo <= hi) {
            int mid = (lo + hi) >>> 1;
            if (colind[mid] == j) return val[mid];
            if (colind[mid] < j) lo = mid + 1;
            else hi = mid - 1;
        }
        return 0;
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
