/*
 * TestClient.java -- the pure-Java client (bindings/java) against the silcd
 * of the test fixture (SILC_SERVER): every value kind in and out, exact
 * round trips, the language cases tests/test_python.py runs (products,
 * norms, a sparse solve against its residual), errors as SILCException with
 * the server's message (and the session going on after each), output,
 * warnings, LIST/DELETE/INFO/EXPLAIN, GET into a ColumnVector, the seeds'
 * PUT/EXEC/GET loop on a 1-D diffusion against the exact solution, complex
 * values (ComplexCRS and ComplexMatrix in, a complex tridiagonal solve
 * against its exact solution, bit-exact round trips, the plain GET of a
 * complex value refused), and a connection the server refuses.
 *
 *     SILC_SERVER=unix:/path java -cp silc.jar:classes TestClient
 *
 * Prints "N passed, N failed" last and exits 1 on a failure.
 */
import java.util.ArrayList;
import java.util.List;
import java.util.Random;

import silc.CRS;
import silc.ColumnVector;
import silc.ComplexCRS;
import silc.ComplexMatrix;
import silc.DenseMatrix;
import silc.SILC;
import silc.SILCException;
import silc.Value;

public final class TestClient {
    private static int passed, failed;

    private static void check(boolean ok, String what) {
        if (ok) {
            passed++;
        } else {
            failed++;
            System.err.println("FAIL: " + what);
        }
    }

    private interface Call {
        void run() throws SILCException;
    }

    /* The call must fail with a message containing text. */
    private static void expectError(Call c, String text, String what) {
        try {
            c.run();
            check(false, what + ": no error");
        } catch (SILCException e) {
            check(e.getMessage().contains(text), what + ": message '" + e.getMessage() + "' lacks '" + text + "'");
        }
    }

    /* A thread that calls s.cancel() after 300 ms, as a user's Ctrl-C would
     * during a long EXEC; started, for the caller to join. */
    private static Thread cancelSoon(SILC s) {
        return cancelSoon(s, new java.util.concurrent.CountDownLatch(1));
    }

    /* As above; sent counts down once the CANCEL has gone out. */
    private static Thread cancelSoon(SILC s, java.util.concurrent.CountDownLatch sent) {
        Thread t = new Thread(() -> {
            try {
                Thread.sleep(300);
                s.cancel();
                sent.countDown();
            } catch (Exception e) {
                check(false, "cancel: " + e);
            }
        });
        t.start();
        return t;
    }

    /* The n x n tridiagonal (off, diag, off) matrix, built from triplets. */
    static CRS tridiagonal(int n, double diag, double off) {
        int[] i = new int[3 * n], j = new int[3 * n];
        double[] v = new double[3 * n];
        int k = 0;
        for (int r = 0; r < n; r++) {
            i[k] = r; j[k] = r; v[k++] = diag;
            if (r > 0) { i[k] = r; j[k] = r - 1; v[k++] = off; }
            if (r + 1 < n) { i[k] = r; j[k] = r + 1; v[k++] = off; }
        }
        return CRS.fromTriplets(n, n, i, j, v, k);
    }

    /*
     * Complex values (issue 31).  A Helmholtz-like complex tridiagonal A
     * (diagonal 2.5 + 0.5i, off-diagonals -1 + 0.1i: complex symmetric and
     * strictly diagonally dominant) with exact solution x_true = (1 + 2i, ...):
     * b = A x_true, x = A \\ b must match x_true within 10 n eps cond_1(A).
     * cond_1(A) is bounded without solving anything: ||A||_1 is the largest
     * column sum of moduli and, A = A.' being diagonally dominant by rows
     * and columns alike, ||A^-1||_1 <= 1 / min_i (|a_ii| - sum_j!=i |a_ij|)
     * (Varah's bound).
     */
    private static void complexCases(SILC s) throws SILCException {
        int n = 40;
        int[] i = new int[3 * n], j = new int[3 * n];
        double[] re = new double[3 * n], im = new double[3 * n];
        int k = 0;
        for (int r = 0; r < n; r++) {
            i[k] = r; j[k] = r; re[k] = 2.5; im[k++] = 0.5;
            if (r > 0) { i[k] = r; j[k] = r - 1; re[k] = -1; im[k++] = 0.1; }
            if (r + 1 < n) { i[k] = r; j[k] = r + 1; re[k] = -1; im[k++] = 0.1; }
        }
        ComplexCRS A = ComplexCRS.fromTriplets(n, n, i, j, re, im, k);
        double[] xt = new double[2 * n];
        for (int r = 0; r < n; r++) {
            xt[2 * r] = 1 + r % 3;
            xt[2 * r + 1] = 2 - r % 5;
        }
        ComplexMatrix b = new ComplexMatrix(n, 1, A.times(xt));
        s.PUT("Az", A);
        s.PUT("bz", b);
        s.EXEC("xz = Az \\ bz");
        Value xv = s.GETComplex("xz");
        double offSum = 2 * Math.hypot(-1, 0.1), cond1 = (Math.hypot(2.5, 0.5) + offSum) / (Math.hypot(2.5, 0.5) - offSum);
        double err = 0, scale = 0;
        if (xv instanceof ComplexMatrix x && x.m == n && x.n == 1)
            for (int r = 0; r < n; r++) {
                err = Math.max(err, Math.hypot(x.re(r, 0) - xt[2 * r], x.im(r, 0) - xt[2 * r + 1]));
                scale = Math.max(scale, Math.hypot(xt[2 * r], xt[2 * r + 1]));
            }
        else
            err = Double.NaN;
        double bound = 10 * n * Math.ulp(1.0) * cond1;
        check(xv instanceof ComplexMatrix && err / scale <= bound,
              "complex solve: relative error " + err / scale + " bound " + bound + " (cond_1 " + cond1 + ")");

        // Bit-for-bit round trips, CSR and dense; a signed zero and a subnormal part survive.
        Value back = s.GETComplex("Az");
        check(back instanceof ComplexCRS c && c.nnz() == A.nnz() && java.util.Arrays.equals(c.rowptr, A.rowptr)
              && java.util.Arrays.equals(c.colind, A.colind) && java.util.Arrays.equals(c.val, A.val)
              && c.re(3, 3) == 2.5 && c.im(3, 4) == 0.1 && c.re(3, 5) == 0,
              "complex CSR round trip bit for bit");
        ComplexMatrix Z = ComplexMatrix.ofParts(2, 3, new double[] {-0.0, 1, 2, 3, 4, 5},
                                                new double[] {Double.MIN_VALUE, -1, 0.5, 1e300, -2, 0});
        s.PUT("Z", Z);
        back = s.GETComplex("Z");
        boolean same = back instanceof ComplexMatrix d && d.m == 2 && d.n == 3;
        if (same) {
            double[] got = ((ComplexMatrix) back).a;
            for (int q = 0; q < got.length; q++)
                same &= Double.doubleToRawLongBits(got[q]) == Double.doubleToRawLongBits(Z.a[q]);
        }
        check(same && Z.re(1, 2) == 5 && Z.im(0, 2) == -2, "complex dense round trip bit for bit");
        s.EXEC("Zt = Z.'; Zb = band(Az, 1, 1); zr = real(Z)");
        check(s.GETComplex("Zt") instanceof ComplexMatrix t && t.m == 3 && t.n == 2 && t.re(2, 1) == 5
              && t.im(2, 0) == -2, "a complex result comes back a ComplexMatrix");
        check(s.GETComplex("Zb") instanceof ComplexMatrix d && d.m == n && d.re(3, 3) == 2.5 && d.im(3, 3) == 0.5
              && d.im(4, 3) == 0.1 && d.re(5, 3) == 0, "a complex band value comes back dense");
        check(s.GETComplex("zr") instanceof DenseMatrix d && d.get(1, 2) == 5,
              "GETComplex of a real value is the real value");

        // The plain GET takes real values only: a complex one is the server's
        // error naming it, not half the data, and the session goes on.
        expectError(() -> s.GET("Z"), "'Z' is complex", "plain GET of a complex value");
        expectError(() -> s.GET(new ColumnVector(n), "xz"), "'xz' is complex", "GET into a vector of a complex value");
        expectError(() -> s.PUT("bad", new ComplexCRS(2, 2, new int[] {0, 2, 2}, new int[] {1, 0},
                                                        new double[] {1, 1, 2, 2})),
                    "row 0", "unsorted complex CSR row named by the server");
        check(s.GETComplex("Z") instanceof ComplexMatrix, "the session goes on");
    }

    /*
     * `TestClient token HOST PORT TOKEN`: against a silcd on TCP that wants
     * TOKEN -- INIT(host, port) with the token from SILC_TOKEN (the caller
     * sets it) works, a wrong or missing token is refused with the server's
     * message.
     */
    private static void tokenCases(String host, int port, String token) throws Exception {
        try (SILC s = new SILC()) {
            s.INIT(host, port);
            s.EXEC("a = 2 + 3");
            check(s.GETScalar("a") == 5, "a session over TCP with the token from SILC_TOKEN");
        }
        try (SILC s = new SILC()) {
            s.INIT("tcp://" + host + ":" + port, token);
            check(s.LIST().isEmpty(), "a session with the token given to INIT");
        }
        expectError(() -> new SILC().INIT("tcp://" + host + ":" + port, token + "x"), "authentication failed",
                    "a wrong token");
    }

    public static void main(String[] args) throws Exception {
        // `TestClient badenv MESSAGE`: the caller set a variable wrong; INIT
        // must refuse with MESSAGE before connecting.
        if (args.length == 2 && args[0].equals("badenv")) {
            expectError(() -> new SILC().INIT("unix:/nonexistent-dir/silc.sock"), args[1], "INIT with " + args[1]);
            System.out.println(passed + " passed, " + failed + " failed");
            System.exit(failed > 0 || passed == 0 ? 1 : 0);
        }
        if (args.length == 4 && args[0].equals("token")) {
            tokenCases(args[1], Integer.parseInt(args[2]), args[3]);
            System.out.println(passed + " passed, " + failed + " failed");
            System.exit(failed > 0 || passed == 0 ? 1 : 0);
        }
        Random rng = new Random(7);
        try (SILC s = new SILC()) {
            s.INIT();
            // Dense and vector in, product and norm out.
            DenseMatrix M = new DenseMatrix(6, 4);
            ColumnVector v = new ColumnVector(4);
            for (int q = 0; q < M.a.length; q++) M.a[q] = rng.nextGaussian();
            for (int q = 0; q < 4; q++) v.v[q] = rng.nextGaussian();
            s.PUT("M", M);
            s.PUT("v", v);
            s.EXEC("y = M * v; n = norm(v)");
            ColumnVector y = new ColumnVector(6);
            s.GET(y, "y");
            double worst = 0, nv = 0;
            for (int r = 0; r < 6; r++) {
                double e = 0;
                for (int c = 0; c < 4; c++) e += M.get(r, c) * v.v[c];
                worst = Math.max(worst, Math.abs(e - y.v[r]));
            }
            for (double x : v.v) nv += x * x;
            check(worst < 1e-14, "M * v off by " + worst);
            check(Math.abs(s.GETScalar("n") - Math.sqrt(nv)) < 1e-14, "norm(v)");
            Value back = s.GET("M");
            check(back instanceof DenseMatrix d && d.m == 6 && d.n == 4 && java.util.Arrays.equals(d.a, M.a),
                  "dense round trip is exact");
            s.PUT("k", 2.5);
            check(s.GETScalar("k") == 2.5, "scalar round trip");
            DenseMatrix R = DenseMatrix.ofRows(new double[][] {{1, 2, 3}, {4, 5, 6}});
            s.PUT("R", R);
            s.EXEC("Rt = R'");
            Value rt = s.GET("Rt");
            check(rt instanceof DenseMatrix d && d.m == 3 && d.n == 2 && d.get(2, 1) == 6 && d.get(0, 1) == 4,
                  "transpose of a matrix given by rows");

            // Sparse in, solve, sparse out.
            CRS A = tridiagonal(50, 4.0, -1.0);
            double[] ones = new double[50];
            java.util.Arrays.fill(ones, 1.0);
            s.PUT("A", A);
            s.PUT("b", new ColumnVector(ones));
            s.EXEC("x = A \\ b; r = norm(A * x - b)");
            check(s.GETScalar("r") < 1e-12, "sparse solve residual " + s.GETScalar("r"));
            ColumnVector x = new ColumnVector(50);
            s.GET(x, "x");
            double[] ax = A.times(x.v);
            double res = 0;
            for (int q = 0; q < 50; q++) res = Math.max(res, Math.abs(ax[q] - 1));
            check(res < 1e-13, "solution checked in Java: residual " + res);
            Value Ab = s.GET("A");
            check(Ab instanceof CRS c && c.nnz() == A.nnz() && c.get(3, 3) == 4.0 && c.get(3, 4) == -1.0
                  && c.get(3, 5) == 0, "CSR round trip");
            // Duplicates summed, rows sorted, by fromTriplets; as sparse() does on the server.
            CRS T = CRS.fromTriplets(2, 3, new int[] {1, 0, 1, 1}, new int[] {2, 1, 0, 2},
                                     new double[] {1, 2, 3, 4}, 4);
            check(T.nnz() == 3 && T.get(1, 2) == 5 && T.get(1, 0) == 3 && T.get(0, 1) == 2
                  && T.colind[1] == 0 && T.colind[2] == 2, "fromTriplets sums and sorts");
            s.PUT("T", T);
            s.EXEC("Td = dense(T)");
            Value td = s.GET("Td");
            check(td instanceof DenseMatrix d && d.get(1, 2) == 5 && d.get(0, 0) == 0, "sparse to dense on the server");
            // A band value comes back dense.
            s.EXEC("B = band(A, 1, 1)");
            Value bv = s.GET("B");
            check(bv instanceof DenseMatrix d && d.m == 50 && d.n == 50 && d.get(3, 3) == 4 && d.get(3, 4) == -1
                  && d.get(4, 3) == -1 && d.get(3, 5) == 0, "a band value comes back as the dense matrix");

            // Errors carry the server's message, and the session goes on.
            expectError(() -> s.GET("nosuch"), "undefined name 'nosuch'", "GET undefined");
            expectError(() -> s.EXEC("z = (1 + "), "expected", "parse error");
            expectError(() -> s.PUT("1bad", v), "invalid name '1bad'", "invalid name");
            expectError(() -> s.EXEC("q = M \\ b"), "'M' is 6x4, 'b' is 50x1", "a shape mismatch");
            expectError(() -> s.GET(new ColumnVector(3), "x"), "the ColumnVector has 3 rows",
                        "GET into a vector of the wrong length");
            expectError(() -> s.PUT("bad", new CRS(2, 2, new int[] {0, 2, 3}, new int[] {1, 0, 1},
                                                   new double[] {1, 2, 3})),
                        "row 0", "unsorted CSR row named by the server");
            check(s.GETScalar("k") == 2.5, "the session goes on after errors");
            check(!s.LIST().contains("bad"), "a refused PUT binds nothing");

            // Output, warnings, LIST, DELETE, INFO, EXPLAIN.
            StringBuilder out = new StringBuilder();
            s.setOutput(out::append);
            s.EXEC("who");
            check(out.toString().contains("M ") && out.toString().contains("x "), "who output: " + out);
            check(s.EXPLAIN("c = A \\ b").contains("would"), "explain");
            check(s.INFO().contains("bytes:"), "session info");
            check(s.INFO("x").contains("backend:"), "info x names the backend");
            List<String> names = s.LIST();
            check(names.contains("x") && names.contains("M"), "LIST " + names);
            s.DELETE("R");
            check(!s.LIST().contains("R"), "DELETE");
            expectError(() -> s.DELETE("R"), "undefined name 'R'", "DELETE undefined");
            s.EXEC("W = ones(2,2) + eye(2)*1e-14; w = W \\ ones(2,1)");
            check(s.warnings().contains("condition estimate"), "warnings: " + s.warnings());

            // The seeds' loop: PUT A and b, EXEC the solve, GET into the same vector, step after step.
            int n = 100, steps = 200;
            double h = Math.PI / (n + 1), dt = 0.5 / steps, c = dt / (h * h);
            double[] u = new double[n];
            for (int q = 0; q < n; q++) u[q] = Math.sin((q + 1) * h);
            CRS L = tridiagonal(n, 1 + 2 * c, -c);
            ColumnVector b = new ColumnVector(n), un = new ColumnVector(n);
            s.PUT("L", L);
            for (int step = 0; step < steps; step++) {
                System.arraycopy(step == 0 ? u : un.v, 0, b.v, 0, n);
                s.PUT("u0", b);
                s.EXEC("u1 = L \\ u0");
                s.GET(un, "u1");
            }
            double err = 0;
            for (int q = 0; q < n; q++) err = Math.max(err, Math.abs(un.v[q] - Math.exp(-0.5) * Math.sin((q + 1) * h)));
            double bound = 0.5 * h * h * Math.exp(-0.5) / 12 + 0.5 * dt * Math.exp(-0.5);
            check(err < 1.5 * bound, "diffusion error " + err + " vs estimate " + bound);

            // cancel() from another thread: a loop of 1e9 iterations (minutes) ends
            // "interrupted", the loop's assignments undone, the session going on.
            s.EXEC("ca = 7; cx = 1; ci = 0");
            Thread canceller = cancelSoon(s);
            expectError(() -> s.EXEC("while (ci < 1e9) { ci = ci + 1; cx = ci }"), "interrupted",
                        "EXEC cancelled from another thread");
            canceller.join();
            check(s.GETScalar("ca") == 7 && s.GETScalar("cx") == 1 && s.GETScalar("ci") == 0,
                  "the store as before the cancelled loop");
            // A loop that prints: what is still on its way when the CANCEL goes
            // out is dropped and counted in a warning, not shown afterwards.
            // The output handler holds the first piece until the CANCEL has
            // gone out, as a slow terminal would: what silcd streamed
            // meanwhile (a piece a poll, every 20 ms) is then surely on its
            // way. A fast reader may have taken everything before the CANCEL,
            // leaving nothing to drop (CI saw that once).
            StringBuilder shown = new StringBuilder();
            java.util.concurrent.CountDownLatch cancelOut = new java.util.concurrent.CountDownLatch(1);
            s.setOutput(text -> {
                if (shown.length() == 0) {
                    try {
                        check(cancelOut.await(30, java.util.concurrent.TimeUnit.SECONDS),
                              "the CANCEL went out within 30 s");
                    } catch (InterruptedException e) {
                        Thread.currentThread().interrupt();
                    }
                }
                shown.append(text);
            });
            s.EXEC("ci = 0");
            Thread canceller2 = cancelSoon(s, cancelOut);
            expectError(() -> s.EXEC("while (ci < 1e9) { ci = ci + 1; disp(ci) }"), "interrupted",
                        "printing loop cancelled");
            canceller2.join();
            check(shown.length() > 0, "a printing loop's output streams while it runs");
            check(s.warnings().contains("of the statement's output, still on the way from the server, were not shown"),
                  "a warning counts the output dropped after cancel(): '" + s.warnings() + "'");
            check(s.GETScalar("ci") == 0, "the store as before the cancelled printing loop");
            int before = shown.length();
            s.EXEC("disp(42)");
            check(shown.substring(before).trim().endsWith("42"), "the EXEC after cancel() shows its output");
            s.setOutput(System.out::print);
            s.cancel(); // nothing running: nothing sent
            s.EXEC("ci = 2");
            check(s.GETScalar("ci") == 2, "an EXEC after cancel()");

            complexCases(s);
        }

        // Names never leak between sessions; FINALIZE twice is harmless.
        SILC s2 = new SILC();
        s2.INIT();
        check(s2.LIST().isEmpty(), "a new session sees no names");
        s2.FINALIZE();
        s2.FINALIZE();
        expectError(() -> s2.EXEC("a = 1"), "no session: call INIT first", "a call after FINALIZE");

        // Addresses the client refuses, and a server that is not there.
        expectError(() -> new SILC().INIT("http://x:1"), "must be tcp://host:port or unix:/path", "bad scheme");
        expectError(() -> new SILC().INIT("unix:/nonexistent/silcd.sock"), "cannot connect", "no server");
        expectError(() -> new SILC().INIT("tcp://127.0.0.1:x"), "the port is not a number", "bad port");

        System.out.println(passed + " passed, " + failed + " failed");
        System.exit(failed > 0 ? 1 : 0);
    }
}
