/*
 * FrontCheck.java -- compares dam-break front curves (DamBreak's --csv) with
 * Martin & Moyce's measurements (data/martin_moyce_1952_n2.dat) and with
 * each other, and prints the comparison as markdown tables.
 *
 *     java -cp ... mps.FrontCheck DATA RUN.csv [RUN.csv ...]
 *
 * Against the experiment the check is a time lead: for each measured point
 * (T_k, Z_k) of the a = 2.25 in column with T_k within the run, the run
 * reaches Z_k at T_run; lead = T_k - T_run must lie in [LEAD_MIN, LEAD_MAX].
 * MPS runs ahead of the experiment in the first phase (Koshizuka & Oka's own
 * curve, in the data file's source, leads it up to T ~ 2), and an
 * instantaneous start does not model how the experiment's column was
 * released; ours reaches each measured position 0.24-0.33 earlier at both
 * resolutions (docs/mps.md), a shift rather than a different curve.  So
 * the band says "same curve, at most 0.4 ahead, at most 0.1 behind" and
 * fails a run too slow, too fast or of another shape, where a band on Z at
 * fixed T would have to widen with the front's speed.
 *
 * Runs must agree with each other within AGREE (in Z/L) at every time of
 * the first curve, about one particle spacing of the default scene
 * (l0 = L/22): the backends solve the same systems to 1e-10 and differ
 * only by rounding amplified by the particle motion.  Curves of different
 * time steps are compared by interpolation.  Exit status 1 when a check
 * fails.
 */
package mps;

import java.io.IOException;
import java.nio.file.Files;
import java.nio.file.Path;
import java.util.ArrayList;
import java.util.List;
import java.util.Locale;

/** The front-curve checks. */
public final class FrontCheck {
    static final double LEAD_MIN = -0.1, LEAD_MAX = 0.4, AGREE = 0.05;
    /** The experiment used (the larger column of the two n^2 = 2 series). */
    static final double COLUMN_INCHES = 2.25;

    private FrontCheck() {}

    /** A front curve: T and Z/L per row. */
    private record Curve(String name, double[] t, double[] z) {
        /** Z/L at T (linear interpolation), NaN outside the curve. */
        double zAt(double tt) {
            if (tt <= t[0]) return tt == t[0] ? z[0] : Double.NaN;
            for (int k = 1; k < t.length; k++)
                if (t[k] >= tt) return z[k - 1] + (z[k] - z[k - 1]) * (tt - t[k - 1]) / (t[k] - t[k - 1]);
            return Double.NaN;
        }

        /** The first T at which Z/L reaches zz (interpolated), +inf if never. */
        double tReaching(double zz) {
            for (int k = 1; k < t.length; k++)
                if (z[k] >= zz) return t[k - 1] + (t[k] - t[k - 1]) * (zz - z[k - 1]) / (z[k] - z[k - 1]);
            return Double.POSITIVE_INFINITY;
        }

        double tEnd() {
            return t[t.length - 1];
        }
    }

    public static void main(String[] args) throws IOException {
        Locale.setDefault(Locale.ROOT);
        if (args.length < 2) {
            System.err.println("usage: mps.FrontCheck DATA RUN.csv [RUN.csv ...]");
            System.exit(2);
        }
        List<double[]> exp = new ArrayList<>();
        for (String line : Files.readAllLines(Path.of(args[0]))) {
            String s = line.strip();
            if (s.isEmpty() || s.startsWith("#")) continue;
            String[] f = s.split("\\s+");
            if (Double.parseDouble(f[0]) == COLUMN_INCHES)
                exp.add(new double[] {Double.parseDouble(f[1]), Double.parseDouble(f[2])});
        }
        List<Curve> runs = new ArrayList<>();
        for (int k = 1; k < args.length; k++) runs.add(read(Path.of(args[k])));
        boolean ok = true;

        System.out.print("| T | Martin & Moyce Z/L |");
        for (Curve c : runs) System.out.print(" " + c.name() + " Z/L | lead ΔT |");
        System.out.print("\n| --- | --- |");
        for (int k = 0; k < runs.size(); k++) System.out.print(" --- | --- |");
        System.out.println();
        int compared = 0;
        for (double[] e : exp) {
            if (e[0] > runs.get(0).tEnd()) continue;
            System.out.printf("| %.3f | %.3f |", e[0], e[1]);
            for (Curve c : runs) {
                double lead = e[0] - c.tReaching(e[1]);
                boolean in = lead >= LEAD_MIN && lead <= LEAD_MAX;
                ok &= in;
                System.out.printf(" %.3f | %+.3f%s |", c.zAt(e[0]), lead, in ? "" : " FAIL");
            }
            System.out.println();
            compared++;
        }
        if (compared < 3) {
            System.out.println("FAIL: fewer than 3 measured points within the runs (run to T >= 2.6)");
            ok = false;
        }
        System.out.printf("(lead ΔT = T_experiment - T_run at the same Z; allowed [%.2f, %.2f])%n", LEAD_MIN, LEAD_MAX);

        for (int a = 0; a < runs.size(); a++)
            for (int b = a + 1; b < runs.size(); b++) {
                Curve p = runs.get(a), q = runs.get(b);
                double worst = 0, at = 0;
                for (int k = 0; k < p.t().length && p.t()[k] <= q.tEnd(); k++) {
                    double d = Math.abs(p.z()[k] - q.zAt(p.t()[k]));
                    if (d > worst) {
                        worst = d;
                        at = p.t()[k];
                    }
                }
                boolean in = worst <= AGREE;
                ok &= in;
                System.out.printf("%s vs %s: max |ΔZ/L| = %.3f at T = %.2f (allowed %.2f)%s%n", p.name(), q.name(),
                        worst, at, AGREE, in ? "" : " FAIL");
            }
        System.out.println(ok ? "front check: passed" : "front check: FAILED");
        System.exit(ok ? 0 : 1);
    }

    private static Curve read(Path csv) throws IOException {
        List<String> lines = Files.readAllLines(csv);
        int n = lines.size() - 1;
        if (n < 2) throw new IOException(csv + ": no front curve");
        double[] t = new double[n], z = new double[n];
        for (int k = 0; k < n; k++) {
            String[] f = lines.get(k + 1).split(",");
            t[k] = Double.parseDouble(f[2]);
            z[k] = Double.parseDouble(f[3]);
        }
        String name = csv.getFileName().toString().replaceFirst("\\.csv$", "");
        return new Curve(name, t, z);
    }
}
