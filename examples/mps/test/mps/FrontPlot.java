/*
 * FrontPlot.java -- draws dam-break front curves as an SVG picture: the runs
 * as lines, Martin & Moyce's measured points as dots (filled: the a = 2.25 in
 * column that FrontCheck checks; open: the a = 1.125 in one), Koshizuka &
 * Oka's MPS curve as squares on a dashed line.  Plain SVG text, so the
 * picture is made by the same program that prints the tables and needs no
 * plotting library (docs/mps_front.svg is its output).
 */
package mps;

import java.io.IOException;
import java.io.PrintWriter;
import java.nio.file.Path;
import java.util.List;

/** Writes FrontCheck's curves into an SVG file. */
final class FrontPlot {
    private static final int WIDTH = 720, HEIGHT = 480, LEFT = 64, RIGHT = 20, TOP = 20, BOTTOM = 52;
    private static final String[] RUN_COLOURS = {"#1f77b4", "#2ca02c", "#9467bd", "#ff7f0e", "#8c564b"};

    private FrontPlot() {}

    /* The plotted window: T in [0, tMax], Z/L in [1, zMax]. */
    private record Frame(double tMax, double zMax) {
        double px(double t) {
            return LEFT + (WIDTH - LEFT - RIGHT) * t / tMax;
        }

        double py(double z) {
            return HEIGHT - BOTTOM - (HEIGHT - TOP - BOTTOM) * (z - 1) / (zMax - 1);
        }

        boolean inside(double t, double z) {
            return t >= 0 && t <= tMax && z >= 1 && z <= zMax;
        }
    }

    static void write(Path file, List<FrontCheck.Curve> runs, FrontCheck.Curve experiment,
            FrontCheck.Curve smallColumn, FrontCheck.Curve koshizukaOka) throws IOException {
        double tEnd = 0;
        for (FrontCheck.Curve c : runs) tEnd = Math.max(tEnd, c.tEnd());
        Frame f = new Frame(Math.max(1, Math.ceil(tEnd * 2) / 2), 4);
        try (PrintWriter out = new PrintWriter(file.toFile(), "UTF-8")) {
            out.printf("<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"%d\" height=\"%d\" viewBox=\"0 0 %d %d\" "
                    + "font-family=\"sans-serif\" font-size=\"13\">%n", WIDTH, HEIGHT, WIDTH, HEIGHT);
            out.printf("<rect width=\"%d\" height=\"%d\" fill=\"white\"/>%n", WIDTH, HEIGHT);
            for (double t = 0; t <= f.tMax() + 1e-9; t += 0.5) {
                out.printf("<line x1=\"%.1f\" y1=\"%.1f\" x2=\"%.1f\" y2=\"%.1f\" stroke=\"#ddd\"/>%n", f.px(t), f.py(1),
                        f.px(t), f.py(f.zMax()));
                out.printf("<text x=\"%.1f\" y=\"%.1f\" text-anchor=\"middle\">%.1f</text>%n", f.px(t), f.py(1) + 18, t);
            }
            for (double z = 1; z <= f.zMax() + 1e-9; z += 0.5) {
                out.printf("<line x1=\"%.1f\" y1=\"%.1f\" x2=\"%.1f\" y2=\"%.1f\" stroke=\"#ddd\"/>%n", f.px(0), f.py(z),
                        f.px(f.tMax()), f.py(z));
                out.printf("<text x=\"%.1f\" y=\"%.1f\" text-anchor=\"end\">%.1f</text>%n", f.px(0) - 6, f.py(z) + 4, z);
            }
            out.printf("<rect x=\"%d\" y=\"%d\" width=\"%d\" height=\"%d\" fill=\"none\" stroke=\"black\"/>%n", LEFT, TOP,
                    WIDTH - LEFT - RIGHT, HEIGHT - TOP - BOTTOM);
            out.printf("<text x=\"%.1f\" y=\"%d\" text-anchor=\"middle\">T = t sqrt(2g/L)</text>%n",
                    (LEFT + WIDTH - RIGHT) / 2.0, HEIGHT - 10);
            out.printf("<text x=\"16\" y=\"%.1f\" text-anchor=\"middle\" transform=\"rotate(-90 16 %.1f)\">"
                    + "front Z/L</text>%n", (TOP + HEIGHT - BOTTOM) / 2.0, (TOP + HEIGHT - BOTTOM) / 2.0);

            int legend = 0;
            for (int k = 0; k < runs.size(); k++) {
                String colour = RUN_COLOURS[k % RUN_COLOURS.length];
                out.print(polyline(f, runs.get(k), colour, ""));
                legend(out, legend++, "<line x1=\"0\" y1=\"0\" x2=\"24\" y2=\"0\" stroke=\"" + colour
                        + "\" stroke-width=\"2\"/>", "MPS run: " + escape(runs.get(k).name()));
            }
            if (koshizukaOka != null) {
                out.print(polyline(f, koshizukaOka, "#d62728", " stroke-dasharray=\"6 4\""));
                for (int k = 0; k < koshizukaOka.t().length; k++)
                    if (f.inside(koshizukaOka.t()[k], koshizukaOka.z()[k]))
                        out.printf("<rect x=\"%.1f\" y=\"%.1f\" width=\"8\" height=\"8\" fill=\"#d62728\"/>%n",
                                f.px(koshizukaOka.t()[k]) - 4, f.py(koshizukaOka.z()[k]) - 4);
                legend(out, legend++, "<line x1=\"0\" y1=\"0\" x2=\"24\" y2=\"0\" stroke=\"#d62728\" stroke-width=\"2\" "
                        + "stroke-dasharray=\"6 4\"/><rect x=\"8\" y=\"-4\" width=\"8\" height=\"8\" fill=\"#d62728\"/>",
                        "Koshizuka &amp; Oka 1996, their MPS");
            }
            points(out, f, experiment, "black");
            legend(out, legend++, "<circle cx=\"12\" cy=\"0\" r=\"4.5\" fill=\"black\"/>",
                    "Martin &amp; Moyce 1952, a = 2.25 in (checked)");
            if (smallColumn != null) {
                points(out, f, smallColumn, "none");
                legend(out, legend, "<circle cx=\"12\" cy=\"0\" r=\"4.5\" fill=\"none\" stroke=\"black\"/>",
                        "Martin &amp; Moyce 1952, a = 1.125 in");
            }
            out.println("</svg>");
            if (out.checkError()) throw new IOException("cannot write " + file);
        }
    }

    private static String polyline(Frame f, FrontCheck.Curve c, String colour, String extra) {
        StringBuilder sb = new StringBuilder("<polyline fill=\"none\" stroke=\"" + colour + "\" stroke-width=\"2\"" + extra
                + " points=\"");
        for (int k = 0; k < c.t().length; k++)
            if (f.inside(c.t()[k], c.z()[k])) sb.append(String.format("%.1f,%.1f ", f.px(c.t()[k]), f.py(c.z()[k])));
        return sb.append("\"/>\n").toString();
    }

    private static void points(PrintWriter out, Frame f, FrontCheck.Curve c, String fill) {
        for (int k = 0; k < c.t().length; k++)
            if (f.inside(c.t()[k], c.z()[k]))
                out.printf("<circle cx=\"%.1f\" cy=\"%.1f\" r=\"4.5\" fill=\"%s\" stroke=\"black\"/>%n", f.px(c.t()[k]),
                        f.py(c.z()[k]), fill);
    }

    /* Legend entry `row` in the top-left corner: a symbol drawn at its own origin, then the text. */
    private static void legend(PrintWriter out, int row, String symbol, String text) {
        double x = LEFT + 14, y = TOP + 18 + 20 * row;
        out.printf("<g transform=\"translate(%.1f %.1f)\">%s</g>%n", x, y, symbol);
        out.printf("<text x=\"%.1f\" y=\"%.1f\">%s</text>%n", x + 32, y + 4, text);
    }

    private static String escape(String s) {
        return s.replace("&", "&amp;").replace("<", "&lt;").replace(">", "&gt;");
    }
}
