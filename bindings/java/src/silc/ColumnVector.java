/*
 * ColumnVector.java -- an n x 1 vector of doubles, the seeds' helper type for
 * right-hand sides and solutions.  The array is the vector's own storage:
 * GET into an existing ColumnVector fills it without a new allocation.
 */
package silc;

/** An n x 1 vector; {@code v} is its storage, read and written directly. */
public final class ColumnVector implements Value {
    /** The entries; its length is the vector's length. */
    public final double[] v;

    /** A zero vector of length n. */
    public ColumnVector(int n) {
        if (n < 0) throw new IllegalArgumentException("ColumnVector: negative length " + n);
        v = new double[n];
    }

    /** A vector over the given array (not copied). */
    public ColumnVector(double[] values) {
        if (values == null) throw new IllegalArgumentException("ColumnVector: null array");
        v = values;
    }

    public int size() {
        return v.length;
    }

    public double get(int i) {
        return v[i];
    }

    public void set(int i, double x) {
        v[i] = x;
    }

    @Override
    public int rows() {
        return v.length;
    }

    @Override
    public int cols() {
        return 1;
    }
}
