/*
 * FrontCheck.java -- compares dam-break front curves (DamBreak's --csv) with
 * Martin & Moyce's measurements (data/martin_moyce_1952_n2.dat), with
 * Koshizuka & Oka's own MPS curve (data/koshizuka_oka_1996_mps.dat, shown,
 * not checked) and with each other; prints the comparisons as markdown
 * tables and can draw the curves as an SVG picture (docs/mps_front.svg).
 *
 *     java -cp ... mps.FrontCheck [--ko KO.dat] [--svg OUT.svg] DATA RUN.csv [RUN.csv ...]
 *
 * Against the experiment the check is a time lead: for each measured point
 * (T_k, Z_k) of the a = 2.25 in column with T_k within the run, the run
 * reaches Z_k at T_run; lead = T_k - T_run must lie in [LEAD_MIN, LEAD_MAX].
 * The run leads the experiment by a near-constant 0.24-0.31 (0.20-0.36 at
 * other resolutions and with every other numerical choice we tried;
 * docs/mps.md has the table): it is the same curve shifted in time, and the model's start
 * matches the exact incompressible one (ModelTest), so the shift lies
 * between an instantaneous, frictionless release and the 1952 experiment,
 * not in the numerics.  LEAD_MAX = 0.35 sits just above the largest lead
 * any of those variants of a sound model gave (0.355 at worst, 0.305 with
 * the program's settings), and fails a front that runs away (a broken
 * pressure gradient gives 0.45-0.63); LEAD_MIN = -0.1 fails one that is too
 * slow.  A band on the lead rather than on Z at fixed T, because a band on
 * Z would have to widen with the front's speed.
 *
 * Runs must agree with each other within AGREE (in Z/L) at every time of
 * the first curve, about one particle spacing of the default scene
 * (l0 = L/22): the backends solve the same systems to 1e-10 and differ
 * only by rounding amplified by the particle motion.  Curves of different
 * time steps are compared by interpolation.  Exit status 1 when a check
 * fails, 2 on a bad command line.
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
    static final double LEAD_MIN = -0.1, LEAD_MAX = 0.35, AGREE = 0.05;
    /** The experiment used (the larger column of the two n^2 = 2 series). */
    static final double COLUMN_INCHES = 2.25, SMALL_COLUMN_INCHES = 1.125;

    private FrontCheck() {}

    /** A front curve: T and Z/L per row. */
    record Curve(String name, double[] t, double[] z) {
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

    public static void main(String[] args) {
        Locale.setDefault(Locale.ROOT);
        try {
            System.exit(run(args));
        } catch (IOException | RuntimeException e) { // a missing file, a malformed row: say which, no stack trace
            System.err.println("mps.FrontCheck: " + (e instanceof java.nio.file.NoSuchFileException
                    ? "no such file: " : "") + e.getMessage());
            System.exit(2);
        }
    }

    /* The checks; returns the exit status. */
    private static int run(String[] args) throws IOException {
        Path ko = null, svg = null;
        List<Path> files = new ArrayList<>();
        for (int k = 0; k < args.length; k++) {
            if ((args[k].equals("--ko") || args[k].equals("--svg")) && k + 1 < args.length) {
                if (args[k].equals("--ko")) ko = Path.of(args[++k]);
                else svg = Path.of(args[++k]);
            } else if (args[k].startsWith("--")) {
                files.clear();
                break;
            } else {
                files.add(Path.of(args[k]));
            }
        }
        if (files.size() < 2) {
            System.err.println("usage: mps.FrontCheck [--ko KO.dat] [--svg OUT.svg] DATA RUN.csv [RUN.csv ...]");
            return 2;
        }
        List<double[]> exp = new ArrayList<>(), small = new ArrayList<>();
        for (double[] row : readColumns(files.get(0), 3)) {
            if (row[0] == COLUMN_INCHES) exp.add(new double[] {row[1], row[2]});
            else if (row[0] == SMALL_COLUMN_INCHES) small.add(new double[] {row[1], row[2]});
        }
        List<double[]> koPoints = ko != null ? readColumns(ko, 2) : List.of();
        Curve koCurve = koPoints.size() >= 2 ? curveOf("Koshizuka & Oka 1996", koPoints) : null;
        List<Curve> runs = new ArrayList<>();
        for (Path f : files.subList(1, files.size())) runs.add(read(f));
        boolean ok = true;

        System.out.print("| T | Martin & Moyce Z/L |");
        if (koCurve != null) System.out.print(" K&O 1996 MPS Z/L | K&O lead ΔT |");
        for (Curve c : runs) System.out.print(" " + c.name() + " Z/L | lead ΔT |");
        System.out.print("\n| --- | --- |");
        for (int k = 0; k < runs.size() + (koCurve != null ? 1 : 0); k++) System.out.print(" --- | --- |");
        System.out.println();
        int compared = 0;
        for (double[] e : exp) {
            if (e[0] > runs.get(0).tEnd()) continue;
            System.out.printf("| %.3f | %.3f |", e[0], e[1]);
            if (koCurve != null) System.out.printf(" %.3f | %+.3f |", koCurve.zAt(e[0]), e[0] - koCurve.tReaching(e[1]));
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

        if (koCurve != null) { // the runs against Koshizuka & Oka's curve: shown, not checked
            System.out.print("\n| T | K&O 1996 MPS Z/L |");
            for (Curve c : runs) System.out.print(" " + c.name() + " Z/L | lead over K&O ΔT |");
            System.out.print("\n| --- | --- |");
            for (int k = 0; k < runs.size(); k++) System.out.print(" --- | --- |");
            System.out.println();
            for (double[] e : koPoints) {
                if (e[0] <= 0 || e[0] > runs.get(0).tEnd()) continue;
                System.out.printf("| %.3f | %.3f |", e[0], e[1]);
                for (Curve c : runs) System.out.printf(" %s | %+.3f |", shown(c.zAt(e[0])), e[0] - c.tReaching(e[1]));
                System.out.println();
            }
        }

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
        if (svg != null) {
            FrontPlot.write(svg, runs, curveOf("Martin & Moyce 1952, a = 2.25 in", exp),
                    small.size() >= 2 ? curveOf("Martin & Moyce 1952, a = 1.125 in", small) : null, koCurve);
            System.out.println("picture: " + svg);
        }
        System.out.println(ok ? "front check: passed" : "front check: FAILED");
        return ok ? 0 : 1;
    }

    /* Z/L for a table, "-" where the curve does not reach. */
    private static String shown(double z) {
        return Double.isNaN(z) ? "-" : String.format("%.3f", z);
    }

    /* The rows of a whitespace-separated data file ('#' starts a comment), each with at least `columns` numbers. */
    private static List<double[]> readColumns(Path file, int columns) throws IOException {
        List<double[]> rows = new ArrayList<>();
        for (String line : Files.readAllLines(file)) {
            String s = line.strip();
            if (s.isEmpty() || s.startsWith("#")) continue;
            String[] f = s.split("\\s+");
            if (f.length < columns) throw new IOException(file + ": '" + s + "': want " + columns + " numbers");
            double[] row = new double[columns];
            try {
                for (int k = 0; k < columns; k++) row[k] = Double.parseDouble(f[k]);
            } catch (NumberFormatException e) {
                throw new IOException(file + ": '" + s + "': not a number");
            }
            rows.add(row);
        }
        return rows;
    }

    private static Curve curveOf(String name, List<double[]> points) {
        double[] t = new double[points.size()], z = new double[points.size()];
        for (int k = 0; k < t.length; k++) {
            t[k] = points.get(k)[0];
            z[k] = points.get(k)[1];
        }
        return new Curve(name, t, z);
    }

    private static Curve read(Path csv) throws IOException {
        List<String> lines = Files.readAllLines(csv);
        int n = lines.size() - 1;
        if (n < 2) throw new IOException(csv + ": no front curve");
        double[] t = new double[n], z = new double[n];
        for (int k = 0; k < n; k++) {
            String[] f = lines.get(k + 1).split(",");
            try {
                t[k] = Double.parseDouble(f[2]);
                z[k] = Double.parseDouble(f[3]);
            } catch (NumberFormatException | ArrayIndexOutOfBoundsException e) {
                throw new IOException(csv + " line " + (k + 2) + ": want t,front_x,T,Z_over_L");
            }
        }
        String name = csv.getFileName().toString().replaceFirst("\\.csv$", "");
        return new Curve(name, t, z);
    }
}
