/*
 * ComplexMatrix.java -- an m x n complex matrix (or, n = 1, a complex column
 * vector) stored column-major with each entry's real and imaginary part
 * side by side: the layout SILC, LAPACK's complex*16 and C's double _Complex
 * use, so it travels without reordering.  Java has no complex type; re(i, j)
 * and im(i, j) read an entry's two parts.
 */
package silc;

/** A dense complex m x n matrix: entry (i, j) is {@code a[2*(i + j*m)] + i a[2*(i + j*m) + 1]}. */
public final class ComplexMatrix implements Value {
    public final int m, n;
    /** Column-major entries, real and imaginary part interleaved: 2 * m * n doubles. */
    public final double[] a;

    /** An m x n zero matrix. */
    public ComplexMatrix(int m, int n) {
        if (m < 0 || n < 0) throw new IllegalArgumentException("ComplexMatrix: negative size " + m + "x" + n);
        if (2L * m * n > Integer.MAX_VALUE - 8)
            throw new IllegalArgumentException("ComplexMatrix: " + m + "x" + n + " does not fit a Java array");
        this.m = m;
        this.n = n;
        this.a = new double[2 * m * n];
    }

    /** An m x n matrix over an interleaved column-major array of 2 * m * n doubles (not copied). */
    public ComplexMatrix(int m, int n, double[] interleaved) {
        if (m < 0 || n < 0) throw new IllegalArgumentException("ComplexMatrix: negative size " + m + "x" + n);
        if (interleaved == null || interleaved.length != 2L * m * n)
            throw new IllegalArgumentException("ComplexMatrix: " + m + "x" + n + " needs " + (2L * m * n)
                    + " doubles (real and imaginary part of each entry), got "
                    + (interleaved == null ? "null" : interleaved.length));
        this.m = m;
        this.n = n;
        this.a = interleaved;
    }

    /** The m x n matrix re + i im, both column-major arrays of m * n entries (copied). */
    public static ComplexMatrix ofParts(int m, int n, double[] re, double[] im) {
        ComplexMatrix z = new ComplexMatrix(m, n);
        if (re.length != (long) m * n || im.length != (long) m * n)
            throw new IllegalArgumentException("ComplexMatrix.ofParts: " + m + "x" + n + " needs " + ((long) m * n)
                    + " entries in each part, got " + re.length + " and " + im.length);
        for (int k = 0; k < m * n; k++) {
            z.a[2 * k] = re[k];
            z.a[2 * k + 1] = im[k];
        }
        return z;
    }

    /** Real part of entry (i, j). */
    public double re(int i, int j) {
        return a[2 * (i + j * m)];
    }

    /** Imaginary part of entry (i, j). */
    public double im(int i, int j) {
        return a[2 * (i + j * m) + 1];
    }

    /** Entry (i, j) = re + i im. */
    public void set(int i, int j, double re, double im) {
        a[2 * (i + j * m)] = re;
        a[2 * (i + j * m) + 1] = im;
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
