/*
 * ModelTest.java -- unit-level checks of the MPS model, each able to fail:
 *   1. the initial lattice: number density n0 wherever the kernel sees only
 *      full lattice, the column's top row on the free surface, rows deeper
 *      than re not;
 *   2. the PPE matrix, initially and after 40 dam-break steps: exactly
 *      symmetric, positive and strictly dominant diagonal (so SPD);
 *   3. a resting column: after it settles, the pressure is hydrostatic,
 *      rho g (h - y), within 10 % on average, and the water stays put.
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
