/*
 * Frames.java -- PNG pictures of a run: every particle as a disc, the water
 * coloured by pressure from blue (0) to red (rho g 2L, the hydrostatic
 * pressure at the foot of the initial column), walls grey, dummies darker.
 * Drawn with java.awt into a BufferedImage and written by javax.imageio, so
 * it runs headless (no display needed).
 */
package mps;

import java.awt.Color;
import java.awt.Graphics2D;
import java.awt.RenderingHints;
import java.awt.geom.Ellipse2D;
import java.awt.image.BufferedImage;
import java.io.File;
import java.io.IOException;
import javax.imageio.ImageIO;

/** Writes frames of a Model into a directory. */
final class Frames {
    private static final int WIDTH = 800;
    private final File dir;

    Frames(File dir) throws IOException {
        System.setProperty("java.awt.headless", "true");
        if (!dir.isDirectory() && !dir.mkdirs()) throw new IOException("cannot create frame directory " + dir);
        this.dir = dir;
    }

    /** Writes DIR/<scene>_<step, 5 digits>.png. */
    void write(Model m) throws IOException {
        Scene s = m.scene;
        double b = Scene.border() * m.l0, w = s.tankWidth() + 2 * b, h = s.tankHeight() + 2 * b;
        double scale = WIDTH / w;
        int height = (int) Math.ceil(h * scale);
        BufferedImage img = new BufferedImage(WIDTH, height, BufferedImage.TYPE_INT_RGB);
        Graphics2D g = img.createGraphics();
        g.setRenderingHint(RenderingHints.KEY_ANTIALIASING, RenderingHints.VALUE_ANTIALIAS_ON);
        g.setColor(Color.WHITE);
        g.fillRect(0, 0, WIDTH, height);
        double pScale = Model.RHO * Model.G * s.columnHeight(), d = Math.max(2, m.l0 * scale);
        for (int i = 0; i < m.n; i++) {
            switch (m.type[i]) {
                case Model.FLUID -> g.setColor(pressureColour(m.p[i] / pScale));
                case Model.WALL -> g.setColor(Color.GRAY);
                case Model.DUMMY -> g.setColor(Color.DARK_GRAY);
                default -> {
                    continue;
                }
            }
            double px = (m.x[i] + b) * scale, py = height - (m.y[i] + b) * scale; // y up
            g.fill(new Ellipse2D.Double(px - d / 2, py - d / 2, d, d));
        }
        g.dispose();
        File f = new File(dir, String.format("%s_%05d.png", s.name(), m.steps));
        if (!ImageIO.write(img, "png", f)) throw new IOException("no PNG writer in this JVM");
    }

    /* Blue -> cyan -> green -> yellow -> red for q from 0 to 1 (clamped). */
    private static Color pressureColour(double q) {
        q = Math.max(0, Math.min(1, q));
        double r = Math.min(1, Math.max(0, 4 * q - 2)), gr = Math.min(1, Math.max(0, q < 0.75 ? 4 * q : 4 - 4 * q));
        double bl = Math.min(1, Math.max(0, 2 - 4 * q));
        return new Color((float) r, (float) gr, (float) bl);
    }
}
