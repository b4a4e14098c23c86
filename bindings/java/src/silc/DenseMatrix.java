/*
 * DenseMatrix.java -- an m x n matrix stored column-major, as SILC stores
 * dense values (and as LAPACK does), so it travels without reordering.
 */
package silc;

/** A dense m x n matrix, column-major: entry (i, j) is {@code a[i + j * m]}. */
public final class DenseMatrix implements Value {
    public final int m, n;
    /** Column-major entries, m * n of them. */
    public final double[] a;

    /** An m x n zero matrix. */
    public DenseMatrix(int m, int n) {
        if (m < 0 || n < 0) throw new IllegalArgumentException("DenseMatrix: negative size " + m + "x" + n);
        if ((long) m * n > Integer.MAX_VALUE - 8)
            throw new IllegalArgumentException("DenseMatrix: " + m + "x" + n + " does not fit a Java array");
        this.m = m;
        this.n = n;
        this.a = new double[m * n];
    }

    /** An m x n matrix over a column-major array of m * n entries (not copied). */
    public DenseMatrix(int m, int n, double[] colMajor) {
        if (m < 0 || n < 0) throw new IllegalArgumentException("DenseMatrix: negative size " + m + "x" + n);
        if (colMajor == null || colMajor.length != (long) m * n)
            throw new IllegalArgumentException("DenseMatrix: " + m + "x" + n + " needs " + ((long) m * n)
                    + " entries, got " + (colMajor == null ? "null" : colMajor.length));
        this.m = m;
        this.n = n;
        this.a = colMajor;
    }

    /** From rows: {@code rows[i][j]} is entry (i, j); every row the same length. */
    public static DenseMatrix ofRows(double[][] rows) {
        int m = rows.length, n = m == 0 ? 0 : rows[0].length;
        DenseMatrix d = new DenseMatrix(m, n);
        for (int i = 0; i < m; i++) {
            if (rows[i].length != n)
                throw new IllegalArgumentException("DenseMatrix.ofRows: row " + i + " has " + rows[i].length
                        + " entries, row 0 has " + n);
            for (int j = 0; j < n; j++) d.a[i + j * m] = rows[i][j];
        }
        return d;
    }

    public double get(int i, int j) {
        return a[i + j * m];
    }

    public void set(int i, int j, double x) {
        a[i + j * m] = x;
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
