/*
 * Model.java -- the Moving Particle Semi-implicit method of Koshizuka & Oka
 * (Nucl. Sci. Eng. 123, 1996) in two dimensions, for the dam break.  A step
 * is the method's fractional step:
 *
 *   1. explicit: viscosity and gravity give a temporary velocity, particles
 *      move with it; particles closer than the collision distance bounce;
 *   2. implicit: the particle number density n* at the temporary positions
 *      drives a pressure Poisson equation (PPE), assembled here as a sparse
 *      matrix and solved by whoever the caller passes (SILC in DamBreak);
 *   3. correction: the pressure gradient corrects velocities and positions.
 *
 * Kernel w(r) = re/r - 1 for r < re, re = 2.1 l0 for the number density and
 * the gradient, 4.0 l0 for the Laplacian; n0 and lambda come from the
 * initial lattice.  Constants follow the method's papers and the sample code
 * of Koshizuka's group where the papers leave a choice.
 */
package mps;

import java.util.Arrays;
import silc.CRS;
import silc.SILCException;

/** The particles of a Scene and the MPS time step. */
final class Model {
    static final int FLUID = 0, WALL = 1, DUMMY = 2, GHOST = 3;
    static final int DIM = 2;
    /** Water: density kg/m^3, kinematic viscosity m^2/s; gravity m/s^2. */
    static final double RHO = 1000, NU = 1.0e-6, G = 9.81;
    /** Interaction radii in units of l0. */
    static final double RE_DENSITY = 2.1, RE_LAPLACIAN = 4.0;
    /** A particle with n* < BETA n0 is on the free surface (p = 0). */
    static final double BETA = 0.97;
    /**
     * Under-relaxation of the PPE source term and water's compressibility
     * (1/Pa), both from the sample code of Koshizuka's group.  The
     * compressibility term alpha/dt^2 on the diagonal is our way to keep the
     * PPE matrix positive definite: a cluster of particles with no surface
     * particle (a drop in flight, a pocket sealed by walls) has no Dirichlet
     * row, and without it the cluster's block would be singular.  It is the
     * physical choice (water is that compressible) and keeps A symmetric,
     * where the alternative -- doubling the diagonal of such clusters, found
     * by a connectivity search -- needs an extra pass and is ad hoc.
     */
    static final double RELAXATION = 0.2, COMPRESSIBILITY = 0.45e-9;
    /** Particles closer than this (in l0) and approaching collide, with this restitution. */
    static final double COLLISION_DISTANCE = 0.5, RESTITUTION = 0.2;
    /** dt = COURANT l0 / u_max with u_max = sqrt(2 g H), the free-fall speed from the column top. */
    static final double COURANT = 0.2;

    /** Solves A x = b for the PPE; A is SPD. */
    interface PressureSolver {
        double[] solve(CRS a, double[] b) throws SILCException;
    }

    /** The PPE of one step: row[i] is particle i's unknown, -1 when p_i = 0 or has no pressure. */
    record PressureSystem(CRS a, double[] b, int[] row) {}

    final Scene scene;
    final int n;
    final double l0, reDensity, reLaplacian, n0Density, n0Laplacian, lambda, dt;
    final int[] type;
    final double[] x, y, u, v, p, density;
    final boolean[] surface;
    double time;
    int steps;

    private final CellGrid grid;
    private final boolean[] binned;
    private final CellGrid.Neighbours nb = new CellGrid.Neighbours();
    /*
     * The neighbours within re_Laplacian of each fluid and wall particle at
     * the implicit stage's positions, with their distances: pairIndex[q] and
     * pairDist[q] for q in pairStart[i] .. pairStart[i + 1] - 1.  Number
     * density, PPE and gradient all read this one list.
     */
    private final int[] pairStart;
    private int[] pairIndex = new int[1024];
    private double[] pairDist = new double[1024];
    /* Scratch per particle: accelerations or new velocities, minimum pressure. */
    private final double[] sx, sy, pMin;

    Model(Scene s) {
        scene = s;
        l0 = s.l0();
        // Every lattice site of the tank's bounding box; the empty ones are dropped.
        int b = Scene.border(), sites = (s.tankX() + 2 * b) * (s.tankY() + 2 * b), count = 0;
        int[] t = new int[sites];
        double[] px = new double[sites], py = new double[sites];
        for (int j = -b; j < s.tankY() + b; j++)
            for (int i = -b; i < s.tankX() + b; i++) {
                t[count] = s.typeAt(i, j);
                px[count] = (i + 0.5) * l0;
                py[count] = (j + 0.5) * l0;
                if (t[count] >= 0) count++;
            }
        type = Arrays.copyOf(t, count);
        x = Arrays.copyOf(px, count);
        y = Arrays.copyOf(py, count);
        n = count;
        u = new double[n];
        v = new double[n];
        p = new double[n];
        density = new double[n];
        surface = new boolean[n];
        binned = new boolean[n];
        sx = new double[n];
        sy = new double[n];
        pMin = new double[n];
        pairStart = new int[n + 1];

        reDensity = RE_DENSITY * l0;
        reLaplacian = RE_LAPLACIAN * l0;
        // n0 and lambda of a particle deep inside the initial lattice.
        double nd = 0, nl = 0, lam = 0;
        for (int j = -5; j <= 5; j++)
            for (int i = -5; i <= 5; i++) {
                double r = l0 * Math.sqrt(i * i + j * j);
                if (r == 0) continue;
                nd += weight(r, reDensity);
                nl += weight(r, reLaplacian);
                lam += r * r * weight(r, reLaplacian);
            }
        n0Density = nd;
        n0Laplacian = nl;
        lambda = lam / nl;
        dt = COURANT * l0 / Math.sqrt(2 * G * s.columnHeight());
        grid = new CellGrid(-b * l0, -b * l0, s.tankWidth() + b * l0, s.tankHeight() + b * l0, reLaplacian, n);
    }

    /** The MPS kernel. */
    static double weight(double r, double re) {
        return r < re ? re / r - 1 : 0;
    }

    /* |r_j - r_i|; sqrt rather than Math.hypot, which is several times slower. */
    private double distance(int i, int j) {
        double dx = x[j] - x[i], dy = y[j] - y[i];
        return Math.sqrt(dx * dx + dy * dy);
    }

    /** One time step; solver solves the pressure Poisson equation. */
    void step(PressureSolver solver) throws SILCException {
        rebin();
        viscosityAndGravity();
        rebin();
        collide();
        updateDensity();
        PressureSystem ppe = assemble();
        double[] sol = ppe.a().m > 0 ? solver.solve(ppe.a(), ppe.b()) : new double[0];
        for (int i = 0; i < n; i++) // negative pressure clamped: MPS has no tension
            p[i] = ppe.row()[i] >= 0 ? Math.max(sol[ppe.row()[i]], 0) : 0;
        pressureGradient();
        dropEscaped();
        time += dt;
        steps++;
    }

    /** Position of the water front: the rightmost fluid particle's right edge, in metres from the left wall. */
    double front() {
        double f = 0;
        for (int i = 0; i < n; i++)
            if (type[i] == FLUID) f = Math.max(f, x[i] + 0.5 * l0);
        return f;
    }

    /* Bins every particle still in the tank; called whenever positions changed. */
    private void rebin() {
        for (int i = 0; i < n; i++) binned[i] = type[i] != GHOST;
        grid.build(x, y, binned);
    }

    /* Explicit part: u* = u + dt (nu lap u + g), x* = x + dt u*; walls and dummies are at rest (no slip). */
    private void viscosityAndGravity() {
        double c = NU * 2 * DIM / (lambda * n0Laplacian);
        for (int i = 0; i < n; i++) {
            if (type[i] != FLUID) continue;
            grid.near(i, reLaplacian, x, y, nb);
            double lu = 0, lv = 0;
            for (int k = 0; k < nb.count; k++) {
                int j = nb.index[k];
                double w = weight(distance(i, j), reLaplacian);
                lu += (u[j] - u[i]) * w;
                lv += (v[j] - v[i]) * w;
            }
            sx[i] = c * lu;
            sy[i] = c * lv - G;
        }
        accelerateFluid(true);
    }

    /*
     * Particles closer than COLLISION_DISTANCE that approach each other
     * exchange momentum along their line of centres (equal masses, walls
     * included, restitution 0.2): MPS's guard against particles clumping,
     * which the pressure alone resolves too late at this resolution.
     */
    private void collide() {
        double d = COLLISION_DISTANCE * l0;
        for (int i = 0; i < n; i++) {
            sx[i] = u[i];
            sy[i] = v[i];
            if (type[i] != FLUID) continue;
            grid.near(i, d, x, y, nb);
            for (int k = 0; k < nb.count; k++) {
                int j = nb.index[k];
                double dx = x[j] - x[i], dy = y[j] - y[i], r = distance(i, j);
                double approach = ((u[i] - u[j]) * dx + (v[i] - v[j]) * dy) / r;
                if (approach <= 0) continue;
                double impulse = 0.5 * (1 + RESTITUTION) * approach; // per unit mass, equal masses
                sx[i] -= impulse * dx / r;
                sy[i] -= impulse * dy / r;
            }
        }
        for (int i = 0; i < n; i++) {
            if (type[i] != FLUID) continue;
            x[i] += (sx[i] - u[i]) * dt;
            y[i] += (sy[i] - v[i]) * dt;
            u[i] = sx[i];
            v[i] = sy[i];
        }
    }

    /*
     * At the current positions: bins the particles, lists the neighbour
     * pairs, and computes n*_i of the fluid and wall particles and which of
     * them are on the free surface.
     */
    void updateDensity() {
        rebin();
        int c = 0;
        for (int i = 0; i < n; i++) {
            pairStart[i] = c;
            density[i] = 0;
            surface[i] = false;
            if (type[i] != FLUID && type[i] != WALL) continue;
            grid.near(i, reLaplacian, x, y, nb);
            if (c + nb.count > pairIndex.length) {
                pairIndex = Arrays.copyOf(pairIndex, 2 * (c + nb.count));
                pairDist = Arrays.copyOf(pairDist, 2 * (c + nb.count));
            }
            double s = 0;
            for (int k = 0; k < nb.count; k++) {
                int j = nb.index[k];
                double r = distance(i, j);
                pairIndex[c] = j;
                pairDist[c++] = r;
                s += weight(r, reDensity);
            }
            density[i] = s;
            surface[i] = s < BETA * n0Density;
        }
        pairStart[n] = c;
    }

    /*
     * The PPE  -<lap p>_i / rho + alpha p_i / dt^2 = relax (n*_i - n0) / (n0 dt^2)
     * over the fluid and wall particles that are not on the surface; surface
     * particles have p = 0 (their terms vanish from the rows of their
     * neighbours) and dummies take no part.  Negating the Laplacian puts
     * sum_j c w_ij + alpha/dt^2 on the diagonal and -c w_ij off it: the
     * matrix is symmetric (w_ij = w_ji bit for bit) and strictly diagonally
     * dominant, hence SPD, and SILC dispatches it as solve.sparse.spd.
     */
    PressureSystem assemble() {
        int[] row = new int[n];
        int m = 0;
        for (int i = 0; i < n; i++) row[i] = (type[i] == FLUID || type[i] == WALL) && !surface[i] ? m++ : -1;
        int cap = 32 * m + 16, count = 0;
        int[] ti = new int[cap], tj = new int[cap];
        double[] tv = new double[cap], b = new double[m];
        double c = 2.0 * DIM / (lambda * n0Laplacian * RHO), dt2 = dt * dt;
        for (int i = 0; i < n; i++) {
            if (row[i] < 0) continue;
            int from = pairStart[i], to = pairStart[i + 1];
            if (count + to - from + 1 > cap) {
                cap = 2 * (count + to - from + 1);
                ti = Arrays.copyOf(ti, cap);
                tj = Arrays.copyOf(tj, cap);
                tv = Arrays.copyOf(tv, cap);
            }
            double diag = COMPRESSIBILITY / dt2;
            for (int q = from; q < to; q++) {
                int j = pairIndex[q];
                if (type[j] == DUMMY) continue;
                double a = c * weight(pairDist[q], reLaplacian);
                diag += a;
                if (row[j] >= 0) {
                    ti[count] = row[i];
                    tj[count] = row[j];
                    tv[count++] = -a;
                }
            }
            ti[count] = tj[count] = row[i];
            tv[count++] = diag;
            b[row[i]] = RELAXATION * (density[i] - n0Density) / (n0Density * dt2);
        }
        return new PressureSystem(CRS.fromTriplets(m, m, ti, tj, tv, count), b, row);
    }

    /*
     * a_i = -(d / (rho n0)) sum_j (p_j - pmin_i) / r_ij^2 (r_j - r_i) w_ij,
     * with pmin_i the least pressure around i (itself included): subtracting
     * it keeps the force between particles repulsive, MPS's standard
     * stabilisation.  Then u += dt a, x += dt^2 a.
     */
    private void pressureGradient() {
        for (int i = 0; i < n; i++) {
            if (type[i] != FLUID) continue;
            double m = p[i];
            for (int q = pairStart[i]; q < pairStart[i + 1]; q++) {
                int j = pairIndex[q];
                if (type[j] != DUMMY && pairDist[q] < reDensity) m = Math.min(m, p[j]);
            }
            pMin[i] = m;
        }
        double c = DIM / (n0Density * RHO);
        for (int i = 0; i < n; i++) {
            if (type[i] != FLUID) continue;
            double gx = 0, gy = 0;
            for (int q = pairStart[i]; q < pairStart[i + 1]; q++) {
                int j = pairIndex[q];
                double r = pairDist[q];
                if (type[j] == DUMMY || r >= reDensity) continue;
                double dx = x[j] - x[i], dy = y[j] - y[i];
                double f = (p[j] - pMin[i]) * weight(r, reDensity) / (r * r);
                gx += f * dx;
                gy += f * dy;
            }
            sx[i] = -c * gx;
            sy[i] = -c * gy;
        }
        accelerateFluid(false);
    }

    /*
     * u += dt s for the fluid; the explicit step then moves particles by
     * dt u (the new velocity), the correction by dt^2 s (the velocity change).
     */
    private void accelerateFluid(boolean explicit) {
        for (int i = 0; i < n; i++) {
            if (type[i] != FLUID) continue;
            u[i] += dt * sx[i];
            v[i] += dt * sy[i];
            x[i] += explicit ? dt * u[i] : dt * dt * sx[i];
            y[i] += explicit ? dt * v[i] : dt * dt * sy[i];
        }
    }

    /* A particle that left the tank's box (it cannot in a sound run) stops taking part. */
    private void dropEscaped() {
        for (int i = 0; i < n; i++)
            if (type[i] == FLUID && !grid.covers(x[i], y[i])) {
                type[i] = GHOST;
                u[i] = v[i] = p[i] = 0;
            }
    }
}
