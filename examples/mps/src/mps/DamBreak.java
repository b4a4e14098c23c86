/*
 * DamBreak.java -- the seeds' MPS fluid example in Java: a water column
 * collapsing in a tank (Martin & Moyce's n^2 = 2 dam break), each step's
 * pressure Poisson equation solved through a SILC server.  The program never
 * names a backend: silcd's config decides, and the summary reports what
 * `info x` says solved.
 *
 *     java -cp silc.jar:mps.jar mps.DamBreak [--large] [--steps N | --time T]
 *          [--frames DIR] [--every K] [--csv FILE] [--server URL]
 *
 * Exit status: 0 done, 1 a SILC or I/O failure (the message on stderr),
 * 2 bad command line.
 */
package mps;

import java.io.File;
import java.io.IOException;
import java.io.PrintWriter;
import java.util.Locale;
import silc.SILC;
import silc.SILCException;

/** The command-line program. */
public final class DamBreak {
    private static final String USAGE = """
            usage: java -cp silc.jar:mps.jar mps.DamBreak [options]
              --large          the ~10 000-particle scene (default: ~1 000)
              --steps N        run N steps
              --time T         run to dimensionless time T = t sqrt(2g/L) (default 3)
              --frames DIR     write PNG frames into DIR
              --every K        a frame every K steps (default 20)
              --csv FILE       write the water front per step: t,front_x,T,Z_over_L
              --server URL     unix:/path or tcp://host:port (default: $SILC_SERVER)""";

    /** Command-line settings. */
    private record Options(boolean large, int steps, double time, File frames, int every, File csv, String server) {}

    /** A command line we cannot run (a null message: the user asked for --help). */
    private static final class UsageException extends Exception {
        private static final long serialVersionUID = 1L;

        UsageException(String message) {
            super(message);
        }
    }

    private DamBreak() {}

    public static void main(String[] args) {
        Locale.setDefault(Locale.ROOT); // '.' decimal point in the CSV whatever the locale
        Options o;
        try {
            o = parse(args);
        } catch (UsageException e) {
            if (e.getMessage() == null) { // --help
                System.out.println(USAGE);
                return;
            }
            System.err.println("mps: " + e.getMessage() + "\n" + USAGE);
            System.exit(2);
            return;
        }
        try {
            run(o);
        } catch (SILCException e) {
            System.err.println("mps: silc: " + e.getMessage());
            System.exit(1);
        } catch (IOException e) {
            System.err.println("mps: " + e.getMessage());
            System.exit(1);
        }
    }

    private static Options parse(String[] args) throws UsageException {
        boolean large = false;
        int steps = -1, every = 20;
        double time = -1;
        File frames = null, csv = null;
        String server = null;
        for (int k = 0; k < args.length; k++) {
            String a = args[k];
            switch (a) {
                case "--large" -> large = true;
                case "--steps" -> steps = (int) number(a, value(args, ++k, a), true);
                case "--time" -> time = number(a, value(args, ++k, a), false);
                case "--every" -> every = (int) number(a, value(args, ++k, a), true);
                case "--frames" -> frames = new File(value(args, ++k, a));
                case "--csv" -> csv = new File(value(args, ++k, a));
                case "--server" -> server = value(args, ++k, a);
                case "--help", "-h" -> throw new UsageException(null);
                default -> throw new UsageException("unknown option '" + a + "'");
            }
        }
        if (steps > 0 && time > 0) throw new UsageException("give --steps or --time, not both");
        if (server == null) server = System.getenv("SILC_SERVER");
        if (server == null || server.isEmpty()) throw new UsageException("no server: pass --server URL or set SILC_SERVER");
        return new Options(large, steps, steps > 0 ? -1 : time > 0 ? time : 3.0, frames, every, csv, server);
    }

    private static String value(String[] args, int k, String option) throws UsageException {
        if (k >= args.length) throw new UsageException(option + " needs a value");
        return args[k];
    }

    /* A positive number (an integer below 10^8 when integer is set). */
    private static double number(String option, String s, boolean integer) throws UsageException {
        String want = integer ? "a positive integer below 10^8" : "a positive number below 1000";
        double x;
        try {
            x = integer ? Long.parseLong(s) : Double.parseDouble(s);
        } catch (NumberFormatException e) {
            throw new UsageException(option + " '" + s + "': want " + want);
        }
        if (!(x > 0 && x < (integer ? 1e8 : 1e3))) throw new UsageException(option + " " + s + ": want " + want);
        return x;
    }

    private static void run(Options o) throws SILCException, IOException {
        Scene scene = o.large() ? Scene.large() : Scene.standard();
        Model m = new Model(scene);
        double L = scene.columnWidth(), toT = Math.sqrt(2 * Model.G / L);
        int steps = o.steps() > 0 ? o.steps() : (int) Math.ceil(o.time() / (toT * m.dt) - 1e-9);
        Frames frames = o.frames() != null ? new Frames(o.frames()) : null;
        try (SILC client = new SILC();
             PrintWriter csv = o.csv() != null ? new PrintWriter(o.csv(), "UTF-8") : null) {
            client.INIT(o.server());
            SilcSolver solver = new SilcSolver(client);
            if (csv != null) csv.println("t,front_x,T,Z_over_L");
            long stepNanos = 0, shown = 0;
            // A progress line on a terminal (System.console(): not when piped), ten a second at most.
            boolean progress = System.console() != null;
            for (int s = 0; s <= steps; s++) {
                if (s > 0) {
                    long t0 = System.nanoTime();
                    m.step(solver);
                    stepNanos += System.nanoTime() - t0;
                }
                if (progress && System.nanoTime() - shown > 100_000_000L) {
                    System.err.printf("\rmps: step %d of %d\033[K", s, steps);
                    shown = System.nanoTime();
                }
                double z = m.front();
                if (csv != null) csv.printf("%.6f,%.6f,%.4f,%.4f%n", m.time, z, m.time * toT, z / L);
                if (frames != null && s % o.every() == 0) frames.write(m);
            }
            if (progress) System.err.print("\r\033[K");
            if (csv != null && csv.checkError()) throw new IOException("cannot write " + o.csv());
            String[] solved = solver.lastSolver();
            double ms = 1e-6 / Math.max(steps, 1), step = stepNanos * ms, solve = solver.solveNanos * ms;
            double transfer = solver.transferNanos * ms;
            System.out.printf("mps: %s scene, %d fluid of %d particles, %d steps of dt %.3g s to T = %.3f "
                    + "(front Z/L = %.3f), %d unknowns per solve; solved by %s (%s, last solve %s iterations)%n", scene.name(),
                    scene.columnX() * scene.columnY(), m.n, steps, m.dt, m.time * toT, m.front() / L,
                    solver.unknowns / Math.max(solver.solves, 1), solved[0], solved[1], solved[2]);
            System.out.println("mps: dispatch of x = A \\ b: " + solver.dispatch());
            System.out.printf("summary: scene=%s steps=%d step_ms=%.3f java_ms=%.3f transfer_ms=%.3f solve_ms=%.3f "
                    + "solve_share=%.1f%% pressure_share=%.1f%% backend=%s%n", scene.name(), steps, step,
                    step - solve - transfer, transfer, solve, 100 * solve / step, 100 * (solve + transfer) / step,
                    solved[0]);
        }
    }
}
