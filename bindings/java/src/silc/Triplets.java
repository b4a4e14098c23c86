/*
 * Triplets.java -- the compressed-row logic CRS and ComplexCRS share: building
 * sorted rows from (i, j, v) entries in any order with duplicates summed, and
 * finding an entry by binary search within its row.  Entries are `width`
 * doubles each (1 real, 2 complex: real and imaginary part interleaved), so
 * one routine serves both fields.
 */
package silc;

import java.util.Arrays;

final class Triplets {
    private Triplets() {}

    /** Compressed rows: rowptr (m + 1), colind (nnz), val (width * nnz). */
    record Rows(int[] rowptr, int[] colind, double[] val) {}

    /**
     * Entry (i[k], j[k]) += v[width*k .. width*k + width - 1] for k < count,
     * duplicates summed, each row's columns sorted; O(count + m) plus the
     * sort within each row.  who names the caller in messages.
     */
    static Rows compress(String who, int m, int n, int[] i, int[] j, double[] v, int width, int count) {
        if (m < 0 || n < 0) throw new IllegalArgumentException(who + ": negative size " + m + "x" + n);
        if (count < 0 || count > i.length || count > j.length || (long) width * count > v.length)
            throw new IllegalArgumentException(who + ": " + count + " entries, arrays hold "
                    + Math.min(i.length, Math.min(j.length, v.length / width)));
        int[] start = new int[m + 1];
        for (int k = 0; k < count; k++) {
            if (i[k] < 0 || i[k] >= m || j[k] < 0 || j[k] >= n)
                throw new IllegalArgumentException(who + ": entry " + k + " at (" + i[k] + ", " + j[k]
                        + ") lies outside " + m + "x" + n);
            start[i[k] + 1]++;
        }
        for (int r = 0; r < m; r++) start[r + 1] += start[r];
        int[] fill = Arrays.copyOf(start, m);
        long[] keyed = new long[count]; // column << 32 | entry, sorted within each row
        for (int k = 0; k < count; k++) keyed[fill[i[k]]++] = ((long) j[k] << 32) | k;
        int[] rowptr = new int[m + 1], colind = new int[count];
        double[] val = new double[width * count];
        int at = 0;
        for (int r = 0; r < m; r++) {
            Arrays.sort(keyed, start[r], start[r + 1]);
            rowptr[r] = at;
            for (int q = start[r]; q < start[r + 1]; q++) {
                int col = (int) (keyed[q] >>> 32), k = (int) (keyed[q] & 0xffffffffL);
                if (at > rowptr[r] && colind[at - 1] == col) {
                    for (int w = 0; w < width; w++) val[width * (at - 1) + w] += v[width * k + w];
                } else {
                    colind[at] = col;
                    for (int w = 0; w < width; w++) val[width * at + w] = v[width * k + w];
                    at++;
                }
            }
        }
        rowptr[m] = at;
        return new Rows(rowptr, colind, val);
    }

    /** The position of entry (i, j) in colind, or -1 where nothing is stored. */
    static int find(int[] rowptr, int[] colind, int i, int j) {
        int lo = rowptr[i], hi = rowptr[i + 1] - 1;
        while (lo <= hi) {
            int mid = (lo + hi) >>> 1;
            if (colind[mid] == j) return mid;
            if (colind[mid] < j) lo = mid + 1;
            else hi = mid - 1;
        }
        return -1;
    }

    /** The checks of a CRS / ComplexCRS constructor: rowptr covers m rows and
     *  the arrays hold rowptr[m] entries of width doubles. */
    static void checkArrays(String who, int m, int n, int[] rowptr, int[] colind, double[] val, int width) {
        if (m < 0 || n < 0) throw new IllegalArgumentException(who + ": negative size " + m + "x" + n);
        if (rowptr == null || rowptr.length < m + 1)
            throw new IllegalArgumentException(who + ": rowptr needs " + (m + 1) + " entries, got "
                    + (rowptr == null ? "null" : rowptr.length));
        int nnz = rowptr[m];
        if (nnz < 0 || colind == null || val == null || colind.length < nnz || val.length < (long) width * nnz)
            throw new IllegalArgumentException(who + ": rowptr[m] = " + nnz + " entries, but colind has "
                    + (colind == null ? "null" : colind.length) + " and val "
                    + (val == null ? "null" : val.length) + (width == 2 ? " doubles (2 an entry)" : ""));
    }
}
