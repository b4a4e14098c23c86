/*
 * CellGrid.java -- neighbour search for MPS.  Particles are binned into
 * square cells as wide as the largest interaction radius (the Laplacian's
 * re = 4 l0), so every neighbour of a particle lies in its own cell or one of
 * the eight around it: finding neighbours costs O(N) per step instead of the
 * O(N^2) of comparing every pair.  Binning is a counting sort, rebuilt
 * whenever positions change.
 */
package mps;

import java.util.Arrays;

/** A uniform grid of cells over a fixed box, holding particle indices by cell. */
final class CellGrid {
    private final double x0, y0, h;
    private final int cx, cy;
    /** cellStart[c] .. cellStart[c + 1] - 1 index `sorted` for cell c. */
    private final int[] cellStart, sorted, cellOf;

    /** Neighbour indices of one query, reused from query to query. */
    static final class Neighbours {
        int[] index = new int[64];
        int count;

        private void add(int j) {
            if (count == index.length) index = Arrays.copyOf(index, 2 * count);
            index[count++] = j;
        }
    }

    /** A grid over [x0, x1] x [y0, y1] with cells of side h, for n particles. */
    CellGrid(double x0, double y0, double x1, double y1, double h, int n) {
        this.x0 = x0;
        this.y0 = y0;
        this.h = h;
        cx = (int) Math.ceil((x1 - x0) / h) + 1;
        cy = (int) Math.ceil((y1 - y0) / h) + 1;
        cellStart = new int[cx * cy + 1];
        sorted = new int[n];
        cellOf = new int[n];
    }

    /** True when (x, y) lies inside the box the grid covers. */
    boolean covers(double x, double y) {
        int i = (int) Math.floor((x - x0) / h), j = (int) Math.floor((y - y0) / h);
        return i >= 0 && i < cx && j >= 0 && j < cy;
    }

    /** Bins the particles for which `use` is true (the others are never neighbours). */
    void build(double[] x, double[] y, boolean[] use) {
        Arrays.fill(cellStart, 0);
        for (int p = 0; p < x.length; p++) {
            cellOf[p] = use[p] ? (int) ((x[p] - x0) / h) + cx * (int) ((y[p] - y0) / h) : -1;
            if (cellOf[p] >= 0) cellStart[cellOf[p] + 1]++;
        }
        for (int c = 0; c < cx * cy; c++) cellStart[c + 1] += cellStart[c];
        int[] fill = Arrays.copyOf(cellStart, cx * cy);
        for (int p = 0; p < x.length; p++)
            if (cellOf[p] >= 0) sorted[fill[cellOf[p]]++] = p;
    }

    /**
     * Collects into nb every binned particle j != i closer than re (re <= h)
     * to particle i, which must be binned too.
     */
    void near(int i, double re, double[] x, double[] y, Neighbours nb) {
        nb.count = 0;
        int ci = cellOf[i] % cx, cj = cellOf[i] / cx;
        double re2 = re * re;
        for (int b = Math.max(cj - 1, 0); b <= Math.min(cj + 1, cy - 1); b++)
            for (int a = Math.max(ci - 1, 0); a <= Math.min(ci + 1, cx - 1); a++) {
                int c = a + cx * b;
                for (int q = cellStart[c]; q < cellStart[c + 1]; q++) {
                    int j = sorted[q];
                    double dx = x[j] - x[i], dy = y[j] - y[i];
                    if (j != i && dx * dx + dy * dy < re2) nb.add(j);
                }
            }
    }
}
