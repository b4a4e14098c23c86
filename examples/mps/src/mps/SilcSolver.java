/*
 * SilcSolver.java -- the pressure solve done the seeds' "LTD" way: the Java
 * program assembles the PPE and hands it to a SILC server, which solves it
 * with whatever backend its config names:
 *
 *     client.PUT("A", mat); client.PUT("b", vec);
 *     client.EXEC("x = A \\ b"); client.GET(sol, "x");
 *
 * It times the two halves separately, transfer (PUT + GET) and solve (EXEC),
 * so the summary can say where a step's time goes.
 */
package mps;

import silc.CRS;
import silc.ColumnVector;
import silc.SILC;
import silc.SILCException;

/** A Model.PressureSolver backed by a SILC session. */
final class SilcSolver implements Model.PressureSolver {
    private final SILC client;
    long transferNanos, solveNanos;
    int solves;
    long unknowns;

    SilcSolver(SILC client) {
        this.client = client;
    }

    @Override
    public double[] solve(CRS a, double[] b) throws SILCException {
        ColumnVector sol = new ColumnVector(b.length);
        long t0 = System.nanoTime();
        client.PUT("A", a);
        client.PUT("b", new ColumnVector(b));
        long t1 = System.nanoTime();
        client.EXEC("x = A \\ b");
        long t2 = System.nanoTime();
        client.GET(sol, "x");
        long t3 = System.nanoTime();
        transferNanos += (t1 - t0) + (t3 - t2);
        solveNanos += t2 - t1;
        solves++;
        unknowns += b.length;
        if (!client.warnings().isEmpty()) System.err.print("mps: step solve warning: " + client.warnings());
        return sol.v;
    }

    /**
     * What SILC says solved the last system: the "backend:", "solve:" and
     * "iterations:" lines of `info x`, e.g. {"lis-style", "CG + IC(0)", "41"}.
     */
    String[] lastSolver() throws SILCException {
        String[] keys = {"backend:", "solve:", "iterations:"}, found = {"?", "?", "?"};
        for (String line : client.INFO("x").split("\n"))
            for (int k = 0; k < keys.length; k++)
                if (line.strip().startsWith(keys[k])) found[k] = line.strip().substring(keys[k].length()).strip();
        return found;
    }

    /**
     * Where the solve's backend list comes from, from `explain`: "backends
     * (config key dispatch.solve.sparse.spd): ..." when the server's config
     * set it, "backends (built-in default ...)" when it did not.
     */
    String dispatch() throws SILCException {
        for (String line : client.EXPLAIN("x = A \\ b").split("\n"))
            if (line.strip().startsWith("backends (")) return line.strip();
        return "?";
    }
}
