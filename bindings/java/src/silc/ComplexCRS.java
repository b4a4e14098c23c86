/*
 * ComplexCRS.java -- a complex sparse matrix in 0-based compressed rows, as
 * CRS is for real values: row i holds colind[rowptr[i] .. rowptr[i+1]-1], and
 * entry k's real and imaginary parts are val[2k] and val[2k+1] (interleaved,
 * SILC's complex layout).  fromTriplets sums duplicates and sorts rows as
 * CRS.fromTriplets does (one routine, Triplets, serves both).
 */
package silc;

/** A complex sparse m x n matrix in 0-based compressed rows; nnz = rowptr[m]. */
public final class ComplexCRS implements Value {
    public final int m, n;
    /** m + 1 row starts; rowptr[0] = 0, never decreasing. */
    public final int[] rowptr;
    /** Column of each stored entry (at least nnz of them; only nnz are used). */
    public final int[] colind;
    /** Real and imaginary part of each stored entry, interleaved (at least 2 * nnz doubles). */
    public final double[] val;

    /** A matrix over the given arrays (not copied); val holds 2 doubles an entry. */
    public ComplexCRS(int m, int n, int[] rowptr, int[] colind, double[] val) {
        Triplets.checkArrays("ComplexCRS", m, n, rowptr, colind, val, 2);
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
     * The m x n matrix with entry (i[k], j[k]) += re[k] + i im[k] for k < count:
     * duplicates are summed, each row's columns sorted.
     */
    public static ComplexCRS fromTriplets(int m, int n, int[] i, int[] j, double[] re, double[] im, int count) {
        if (count < 0 || count > re.length || count > im.length)
            throw new IllegalArgumentException("ComplexCRS.fromTriplets: " + count + " entries, re holds "
                    + re.length + " and im " + im.length);
        double[] v = new double[2 * count];
        for (int k = 0; k < count; k++) {
            v[2 * k] = re[k];
            v[2 * k + 1] = im[k];
        }
        Triplets.Rows r = Triplets.compress("ComplexCRS.fromTriplets", m, n, i, j, v, 2, count);
        return new ComplexCRS(m, n, r.rowptr(), r.colind(), r.val());
    }

    /** Real part of entry (i, j); 0 where nothing is stored. */
    public double re(int i, int j) {
        int at = Triplets.find(rowptr, colind, i, j);
        return at < 0 ? 0 : val[2 * at];
    }

    /** Imaginary part of entry (i, j); 0 where nothing is stored. */
    public double im(int i, int j) {
        int at = Triplets.find(rowptr, colind, i, j);
        return at < 0 ? 0 : val[2 * at + 1];
    }

    /** y = A x, x and y interleaved (2 doubles an entry). */
    public double[] times(double[] x) {
        if (x.length != 2L * n)
            throw new IllegalArgumentException("ComplexCRS.times: " + m + "x" + n + " times " + x.length
                    + " doubles (an interleaved vector of " + n + " needs " + (2L * n) + ")");
        double[] y = new double[2 * m];
        for (int r = 0; r < m; r++) {
            double sr = 0, si = 0;
            for (int q = rowptr[r]; q < rowptr[r + 1]; q++) {
                double ar = val[2 * q], ai = val[2 * q + 1], xr = x[2 * colind[q]], xi = x[2 * colind[q] + 1];
                sr += ar * xr - ai * xi;
                si += ar * xi + ai * xr;
            }
            y[2 * r] = sr;
            y[2 * r + 1] = si;
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
