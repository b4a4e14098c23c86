/*
 * ModelTest.java -- unit-level checks of the MPS model, each able to fail:
 *   1. the initial lattice: number density n0 wherever the kernel sees only
 *      full lattice, the column's top row on the free surface, rows deeper
 *      than re not;
 *   2. the PPE matrix, initially and after 40 dam-break steps: exactly
 *      symmetric, positive and strictly dominant diagonal (so SPD);
 *   3. a resting column: after it settles, the pressure is hydrostatic,
 *      rho g (h - y), within 10 % on average, and the water stays put;
 *   4. the collapse's start against the exact incompressible solution: the
 *      acceleration of the column's centre of mass over the first 40 steps
 *      (T = 0.26) within 5 % of the t = 0+ values a_x = 0.228 g,
 *      a_y = -0.730 g, which come from the series solution of the t = 0+
 *      pressure (startAcceleration) -- the pressure that pushes the column
 *      out is neither too weak nor too strong, whatever the experiment says.
 * The solves go through the SILC server given as the argument (any backend).
 *
 *     java -cp silc.jar:mps.jar:mps_test.jar mps.ModelTest unix:/path/sock
 */
package mps;

import silc.CRS;
import silc.SILC;
import silc.SILCException;

/** The model's unit test; exit status 1 on the first failed check. */
public final class ModelTest {
    private static int failures;

    private ModelTest() {}

    public static void main(String[] args) throws SILCException {
        if (args.length != 1) {
            System.err.println("usage: mps.ModelTest SERVER_URL");
            System.exit(2);
        }
        try (SILC client = new SILC()) {
            client.INIT(args[0]);
            SilcSolver solver = new SilcSolver(client);
            latticeDensity();
            Model m = new Model(Scene.standard());
            m.updateDensity();
            checkMatrix("initial PPE", m.assemble().a());
            for (int k = 0; k < 40; k++) m.step(solver);
            m.updateDensity();
            checkMatrix("PPE after 40 steps", m.assemble().a());
            restingColumn(solver);
            collapseStart(solver);
        }
        System.out.println(failures == 0 ? "mps model: all checks passed" : "mps model: " + failures + " failed");
        System.exit(failures == 0 ? 0 : 1);
    }

    private static void check(boolean ok, String what) {
        System.out.println((ok ? "ok   " : "FAIL ") + what);
        if (!ok) failures++;
    }

    private static void latticeDensity() {
        Model m = new Model(Scene.standard());
        Scene s = m.scene;
        m.updateDensity();
        double worst = 0;
        int inner = 0, top = 0, topSurface = 0, deepSurface = 0;
        for (int i = 0; i < m.n; i++) {
            if (m.type[i] != Model.FLUID) continue;
            // Distance to the column's free faces (its top and its right side).
            double free = Math.min(s.columnHeight() - m.y[i], s.columnWidth() - m.x[i]);
            if (free > m.reDensity + m.l0 / 2) {
                worst = Math.max(worst, Math.abs(m.density[i] - m.n0Density) / m.n0Density);
                inner++;
                if (m.surface[i]) deepSurface++;
            }
            if (m.y[i] > s.columnHeight() - m.l0) {
                top++;
                if (m.surface[i]) topSurface++;
            }
        }
        check(inner > 500 && worst < 1e-12,
                String.format("n_i = n0 = %.4f for the %d fluid particles away from the surface (worst %.1e)",
                        m.n0Density, inner, worst));
        check(top > 0 && topSurface == top, "all " + top + " top-row particles on the free surface");
        check(deepSurface == 0, "no particle deeper than re on the free surface (" + deepSurface + ")");
    }

    private static void checkMatrix(String what, CRS a) {
        int asym = 0, badDiag = 0;
        for (int r = 0; r < a.m; r++) {
            double diag = 0, off = 0;
            for (int q = a.rowptr[r]; q < a.rowptr[r + 1]; q++) {
                int c = a.colind[q];
                if (c == r) diag = a.val[q];
                else off += Math.abs(a.val[q]);
                if (a.get(c, r) != a.val[q]) asym++;
            }
            if (!(diag > off)) badDiag++;
        }
        check(a.m > 0 && asym == 0, what + ": " + a.m + "x" + a.m + ", " + a.nnz() + " entries, "
                + asym + " asymmetric");
        check(badDiag == 0, what + ": " + badDiag + " rows without a positive, strictly dominant diagonal");
    }

    /*
     * The exact start of the collapse.  At t = 0+ the water is at rest, so
     * div(a) = 0 with a = g - grad(p)/rho: p is harmonic in the column
     * 0 < x < L, 0 < y < H, with p = 0 on the free faces x = L and y = H,
     * dp/dx = 0 on the left wall and dp/dy = -rho g on the floor.  Cosine
     * modes k_n = (n + 1/2) pi / L solve it:
     *
     *     p = rho g sum_n c_n cos(k_n x) sinh(k_n (H - y)) / (k_n cosh(k_n H)),
     *     c_n = 2 (-1)^n / (k_n L)                (1 = sum_n c_n cos(k_n x)),
     *
     * so the floor carries F_y = rho g sum_n 2 tanh(k_n H) / (k_n^3 L) and
     * the left wall pushes with F_x = rho g sum_n 2 (-1)^n (1 - 1/cosh(k_n H)) / (k_n^3 L),
     * and the centre of mass of the column (mass rho L H) accelerates by
     * a_x = F_x / (rho L H), a_y = -g + F_y / (rho L H).  Returns {a_x, a_y} / g.
     */
    static double[] startAcceleration(double width, double height) {
        double fx = 0, fy = 0;
        for (int n = 0; n < 10000; n++) {
            double k = (n + 0.5) * Math.PI / width, k3 = k * k * k * width;
            fy += 2 * Math.tanh(k * height) / k3;
            fx += (n % 2 == 0 ? 2 : -2) * (1 - 1 / Math.cosh(k * height)) / k3;
        }
        return new double[] {fx / (width * height), -1 + fy / (width * height)};
    }

    /* The default dam break's first 40 steps against startAcceleration. */
    private static void collapseStart(SilcSolver solver) throws SILCException {
        Model m = new Model(Scene.standard());
        double[] exact = startAcceleration(m.scene.columnWidth(), m.scene.columnHeight());
        double[] start = centreOfMass(m);
        for (int k = 0; k < 40; k++) m.step(solver);
        double[] now = centreOfMass(m);
        double t2 = m.time * m.time / 2;
        double ax = (now[0] - start[0]) / t2 / Model.G, ay = (now[1] - start[1]) / t2 / Model.G;
        check(Math.abs(ax / exact[0] - 1) < 0.05, String.format(
                "collapse start: horizontal acceleration of the column %.3f g, exact t = 0+ value %.3f g", ax, exact[0]));
        check(Math.abs(ay / exact[1] - 1) < 0.05, String.format(
                "collapse start: vertical acceleration of the column %.3f g, exact t = 0+ value %.3f g", ay, exact[1]));
    }

    /* The fluid's centre of mass (equal particle masses). */
    private static double[] centreOfMass(Model m) {
        double sx = 0, sy = 0;
        int count = 0;
        for (int i = 0; i < m.n; i++)
            if (m.type[i] == Model.FLUID) {
                sx += m.x[i];
                sy += m.y[i];
                count++;
            }
        return new double[] {sx / count, sy / count};
    }

    private static void restingColumn(SilcSolver solver) throws SILCException {
        Model m = new Model(Scene.resting(20, 20));
        double h = m.scene.columnHeight(), front0 = m.front(), num = 0, den = 0, drift = 0;
        for (int k = 1; k <= 250; k++) {
            m.step(solver);
            if (k <= 150) continue; // let the start-up pressure wave settle
            for (int i = 0; i < m.n; i++) {
                if (m.type[i] != Model.FLUID || m.y[i] > h - 3 * m.l0) continue;
                num += m.p[i];
                den += Model.RHO * Model.G * (h - m.y[i]);
            }
            drift = Math.max(drift, Math.abs(m.front() - front0));
        }
        check(Math.abs(num / den - 1) < 0.10,
                String.format("resting column: mean p / (rho g (h - y)) = %.3f over steps 151-250", num / den));
        check(drift < 0.5 * m.l0, String.format("resting column: the water edge moved %.2f l0", drift / m.l0));
    }
}
