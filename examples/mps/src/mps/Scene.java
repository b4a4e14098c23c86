/*
 * Scene.java -- the geometry of a run: a rectangular water column in a tank,
 * laid out on the square lattice of spacing l0 that MPS starts from.  Lattice
 * site (i, j) sits at ((i + 1/2) l0, (j + 1/2) l0), so the tank's inner wall
 * surfaces are x = 0, y = 0, x = W, y = H and a column of nx x ny sites is
 * exactly nx l0 wide.  Around the inside go two layers of wall particles
 * (they carry pressure) and two of dummy particles (they only fill the
 * number density of the walls), as in the original MPS.
 */
package mps;

/** Tank and water column sizes, in lattice sites; spacing l0 in metres. */
record Scene(String name, int columnX, int columnY, int tankX, int tankY, double l0) {
    /** Wall layers (with pressure) and dummy layers (number density only). */
    static final int WALL_LAYERS = 2, DUMMY_LAYERS = 2;
    /** Width of the initial column in metres (Koshizuka & Oka's L). */
    static final double COLUMN_WIDTH = 0.146;

    /**
     * Martin & Moyce's n^2 = 2 dam break: a column L wide and 2L high at the
     * left of a closed tank 4L wide and 3L high; nx sites across the column.
     */
    static Scene damBreak(String name, int nx) {
        return new Scene(name, nx, 2 * nx, 4 * nx, 3 * nx, COLUMN_WIDTH / nx);
    }

    /** The default scene: 22 x 44 = 968 fluid particles. */
    static Scene standard() {
        return damBreak("default", 22);
    }

    /** The --large scene: 71 x 142 = 10 082 fluid particles. */
    static Scene large() {
        return damBreak("large", 71);
    }

    /** Water at rest filling a tank nx sites wide to a depth of ny sites (the hydrostatic test). */
    static Scene resting(int nx, int ny) {
        return new Scene("resting", nx, ny, nx, ny + 4, COLUMN_WIDTH / nx);
    }

    double columnWidth() {
        return columnX * l0;
    }

    double columnHeight() {
        return columnY * l0;
    }

    double tankWidth() {
        return tankX * l0;
    }

    double tankHeight() {
        return tankY * l0;
    }

    /** Lattice sites beyond the inner wall surface that hold wall or dummy particles. */
    static int border() {
        return WALL_LAYERS + DUMMY_LAYERS;
    }

    /**
     * The particle type at lattice site (i, j) (i, j may be negative: the
     * walls lie outside the tank), or -1 for an empty site.
     */
    int typeAt(int i, int j) {
        // How many layers outside the tank's inside the site lies (0 = inside).
        int depth = Math.max(Math.max(-i, i - (tankX - 1)), Math.max(-j, j - (tankY - 1)));
        if (depth > border()) return -1;
        if (depth > WALL_LAYERS) return Model.DUMMY;
        if (depth > 0) return Model.WALL;
        return i < columnX && j < columnY ? Model.FLUID : -1;
    }
}
