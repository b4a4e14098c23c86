/*
 * SILC.java -- a pure-Java client of the SILC wire protocol
 * (docs/protocol.md), as the seeds' Java programs used SILC:
 *
 *     try (SILC client = new SILC()) {
 *         client.INIT("unix:/tmp/silcd.sock");       // or INIT(host, port), or INIT() for SILC_SERVER
 *         client.PUT("A", mat);                      // CRS, DenseMatrix or ColumnVector
 *         client.PUT("b", vec);
 *         client.EXEC("x = A \\ b");
 *         client.GET(sol, "x");                      // into an existing ColumnVector
 *     }
 *
 * No JNI and no C library: any JVM that can open a socket can use SILC, and
 * this file is a third implementation of the protocol beside the C one and
 * bindings/python/silc.py.  Every failure is a checked SILCException whose
 * message is the server's, the text the C API reports for the same call.
 * Values stream through one reused direct buffer, so a step's PUT of a large
 * matrix allocates nothing on the Java heap.  A SILC object is one session
 * and is not thread-safe (as a C context is not); open one per thread.
 */
package silc;

import java.io.IOException;
import java.net.InetSocketAddress;
import java.net.StandardProtocolFamily;
import java.net.StandardSocketOptions;
import java.net.UnixDomainSocketAddress;
import java.nio.ByteBuffer;
import java.nio.ByteOrder;
import java.nio.channels.SocketChannel;
import java.nio.charset.StandardCharsets;
import java.nio.file.Files;
import java.nio.file.Path;
import java.util.ArrayList;
import java.util.Arrays;
import java.util.List;
import java.util.function.Consumer;

/** One session on a silcd server. */
public final class SILC implements AutoCloseable {
    static final int PROTOCOL_VERSION = 1;
    static final int PUT = 1, GET = 2, EXEC = 3, DELETE = 4, LIST = 5, INFO = 6, EXPLAIN = 7, BYE = 8,
            CANCEL = 9;
    static final int OK = 128, ERROR = 129, VALUE = 130, TEXT = 131, WARN = 132;
    static final int DENSE = 0, CSR_FORMAT = 1, BAND = 2;
    static final int DESCRIPTOR_BYTES = 48;
    /** Longest text reply accepted (the server's own limit on text). */
    static final long MAX_TEXT = 64L << 20;
    private static final int BUFFER_BYTES = 1 << 20;

    private SocketChannel channel;
    private String url = "";
    private String warnings = "";
    private Consumer<String> output = System.out::print;
    /* One buffer for everything sent and received; values stream through it. */
    private final ByteBuffer buf = ByteBuffer.allocateDirect(BUFFER_BYTES).order(ByteOrder.LITTLE_ENDIAN);
    /* cancel() writes only while an EXEC waits for its reply, so its frame
     * never lands inside another request. */
    private final Object cancelLock = new Object();
    private boolean awaitingExec;

    public SILC() {}

    // ---- opening and closing --------------------------------------------------

    /** Opens a session on the server SILC_SERVER names. */
    public void INIT() throws SILCException {
        String u = System.getenv("SILC_SERVER");
        if (u == null || u.isEmpty()) throw new SILCException("no server address: pass one or set SILC_SERVER");
        INIT(u, null);
    }

    /** Opens a session on tcp://host:port. */
    public void INIT(String host, int port) throws SILCException {
        INIT("tcp://" + (host.contains(":") ? "[" + host + "]" : host) + ":" + port, null);
    }

    /** Opens a session on url: tcp://host:port or unix:/path; the token from SILC_TOKEN or SILC_TOKEN_FILE. */
    public void INIT(String url) throws SILCException {
        INIT(url, null);
    }

    /** Opens a session on url with the server's token (null: from SILC_TOKEN or SILC_TOKEN_FILE). */
    public void INIT(String url, String token) throws SILCException {
        if (channel != null) throw new SILCException("INIT: this client already has a session on " + this.url);
        if (url == null) throw new SILCException("INIT: null server address");
        this.url = url;
        byte[] tok = (token != null ? token : tokenFromEnv()).getBytes(StandardCharsets.UTF_8);
        if (tok.length > 4096) throw new SILCException("INIT: the token is longer than 4096 bytes");
        try {
            channel = connect(url);
            buf.clear();
            buf.put("SILC".getBytes(StandardCharsets.US_ASCII)).putInt(PROTOCOL_VERSION).putInt(tok.length).put(tok);
            flush();
            readFully(12);
            byte[] magic = new byte[4];
            buf.get(magic);
            if (!Arrays.equals(magic, "SILC".getBytes(StandardCharsets.US_ASCII)))
                throw new SILCException(url + " is not a SILC server");
            reply(null, null);
        } catch (IOException e) {
            drop();
            throw new SILCException("cannot connect to silc server " + url + ": " + e.getMessage(), e);
        } catch (SILCException e) {
            drop();
            throw e;
        }
    }

    /** Ends the session (the server frees its values) and closes the connection. */
    public void FINALIZE() throws SILCException {
        if (channel == null) return;
        try {
            request(BYE, null);
            reply(null, null);
        } finally {
            drop();
        }
    }

    /** FINALIZE, for try-with-resources: a connection already lost is not an error here. */
    @Override
    public void close() {
        try {
            FINALIZE();
        } catch (SILCException e) {
            // The session is gone either way; close() must not throw.
        }
    }

    // ---- the calls ------------------------------------------------------------

    /** Deposits v under name; on failure name keeps what it held. */
    public void PUT(String name, Value v) throws SILCException {
        if (v == null) throw new SILCException("PUT '" + name + "': null value");
        byte[] nm = text(name, "PUT");
        int format, nnz;
        long m = v.rows(), n = v.cols();
        if (v instanceof CRS a) {
            format = CSR_FORMAT;
            nnz = a.nnz();
        } else {
            format = DENSE;
            nnz = (int) (m * n);
        }
        long arrays = (format == CSR_FORMAT ? 8L * (m + 1) + 8L * nnz : 0) + 8L * nnz;
        try {
            header(PUT, DESCRIPTOR_BYTES + nm.length + arrays);
            buf.putInt(format).putInt(nm.length).putLong(m).putLong(n).putLong(nnz).putLong(0).putLong(0);
            putBytes(nm);
            if (v instanceof CRS a) {
                putInts(a.rowptr, m + 1);
                putInts(a.colind, nnz);
                putDoubles(a.val, nnz);
            } else if (v instanceof DenseMatrix d) {
                putDoubles(d.a, nnz);
            } else {
                putDoubles(((ColumnVector) v).v, nnz);
            }
            flush();
        } catch (IOException e) {
            throw lost(e);
        }
        reply(null, null);
    }

    /** Deposits a scalar (a 1 x 1 value). */
    public void PUT(String name, double x) throws SILCException {
        PUT(name, new DenseMatrix(1, 1, new double[] {x}));
    }

    /** The value bound to name: a CRS, or a DenseMatrix (band values come dense). */
    public Value GET(String name) throws SILCException {
        request(GET, text(name, "GET"));
        return (Value) reply(null, null);
    }

    /** Fills out with the n x 1 value bound to name (the seeds' GET(sol, "x")). */
    public void GET(ColumnVector out, String name) throws SILCException {
        request(GET, text(name, "GET"));
        reply(null, out);
    }

    /** The 1 x 1 value bound to name. */
    public double GETScalar(String name) throws SILCException {
        Value v = GET(name);
        if (v instanceof DenseMatrix d && d.m == 1 && d.n == 1) return d.a[0];
        throw new SILCException("GET '" + name + "': " + v.rows() + "x" + v.cols() + " is not a scalar");
    }

    /** Runs statements; who/info/explain text goes to the output (setOutput), warnings to warnings(). */
    public void EXEC(String statements) throws SILCException {
        warnings = "";
        request(EXEC, text(statements, "EXEC"));
        synchronized (cancelLock) {
            awaitingExec = true;
        }
        try {
            reply(output, null);
        } finally {
            synchronized (cancelLock) {
                awaitingExec = false;
            }
        }
    }

    /**
     * Interrupts the EXEC running on this session; call it from another thread.
     * The server stops the EXEC at its next check, which then throws
     * SILCException "interrupted" with the store as before the interrupted
     * statement. Does nothing when no EXEC is waiting for its reply.
     */
    public void cancel() throws SILCException {
        synchronized (cancelLock) {
            if (!awaitingExec || channel == null) return;
            ByteBuffer frame = ByteBuffer.allocate(16).order(ByteOrder.LITTLE_ENDIAN);
            frame.putInt(CANCEL).putInt(0).putLong(0).flip();
            try {
                while (frame.hasRemaining()) channel.write(frame);
            } catch (IOException e) {
                /* The EXEC's own read meets the broken connection and says so. */
                throw new SILCException("cancel: cannot write to silc server " + url + ": " + e.getMessage(), e);
            }
        }
    }

    /** The warnings of the last EXEC, one per line ("" when none). */
    public String warnings() {
        return warnings;
    }

    /** Where who/info/explain output goes (default System.out); null discards it. */
    public void setOutput(Consumer<String> sink) {
        output = sink != null ? sink : s -> {};
    }

    /** The session's state: backends, threads, names and bytes. */
    public String INFO() throws SILCException {
        return collect(INFO, new byte[0]);
    }

    /** How name was last computed (`info name`). */
    public String INFO(String name) throws SILCException {
        return collect(INFO, text(name, "INFO"));
    }

    /** What statement would run and why; nothing is run. */
    public String EXPLAIN(String statement) throws SILCException {
        return collect(EXPLAIN, text(statement, "EXPLAIN"));
    }

    /** The names of the session, sorted. */
    public List<String> LIST() throws SILCException {
        request(LIST, null);
        String t = (String) reply(null, null);
        return t.isEmpty() ? new ArrayList<>() : new ArrayList<>(Arrays.asList(t.split("\n")));
    }

    /** Unbinds name. */
    public void DELETE(String name) throws SILCException {
        request(DELETE, text(name, "DELETE"));
        reply(null, null);
    }

    // ---- the protocol ---------------------------------------------------------

    private static String tokenFromEnv() throws SILCException {
        String t = System.getenv("SILC_TOKEN");
        if (t != null && !t.isEmpty()) return t;
        String f = System.getenv("SILC_TOKEN_FILE");
        if (f == null || f.isEmpty()) return "";
        try {
            List<String> lines = Files.readAllLines(Path.of(f), StandardCharsets.UTF_8);
            return lines.isEmpty() ? "" : lines.get(0);
        } catch (IOException e) {
            throw new SILCException("SILC_TOKEN_FILE '" + f + "': " + e.getMessage(), e);
        }
    }

    private static SocketChannel connect(String url) throws IOException, SILCException {
        if (url.startsWith("unix:")) {
            String path = url.substring(5);
            if (path.startsWith("//")) path = path.substring(2);
            SocketChannel c = SocketChannel.open(StandardProtocolFamily.UNIX);
            try {
                c.connect(UnixDomainSocketAddress.of(path));
            } catch (IOException e) {
                c.close();
                throw e;
            }
            return c;
        }
        if (!url.startsWith("tcp://"))
            throw new SILCException("'" + url + "': server address must be tcp://host:port or unix:/path");
        String hp = url.substring(6);
        int colon = hp.lastIndexOf(':');
        if (colon <= 0) throw new SILCException("'" + url + "': server address must be tcp://host:port or unix:/path");
        String host = hp.substring(0, colon).replace("[", "").replace("]", "");
        int port;
        try {
            port = Integer.parseInt(hp.substring(colon + 1));
        } catch (NumberFormatException e) {
            throw new SILCException("'" + url + "': the port is not a number");
        }
        SocketChannel c = SocketChannel.open(new InetSocketAddress(host, port));
        c.setOption(StandardSocketOptions.TCP_NODELAY, true);
        return c;
    }

    private static byte[] text(String s, String call) throws SILCException {
        if (s == null) throw new SILCException(call + ": null text");
        byte[] b = s.getBytes(StandardCharsets.UTF_8);
        for (byte x : b)
            if (x == 0) throw new SILCException(call + ": the text holds a NUL character");
        return b;
    }

    private void need() throws SILCException {
        if (channel == null) throw new SILCException("no session: call INIT first");
    }

    private SILCException lost(IOException e) {
        drop();
        return new SILCException("connection to silc server " + url + " lost: " + e.getMessage(), e);
    }

    private void drop() {
        if (channel != null) {
            try {
                channel.close();
            } catch (IOException e) {
                // Closing a broken channel: nothing more to do.
            }
            channel = null;
        }
    }

    /* Starts a frame in buf (flushing is the caller's). */
    private void header(int op, long length) throws SILCException {
        need();
        buf.clear();
        buf.putInt(op).putInt(0).putLong(length);
    }

    private void request(int op, byte[] body) throws SILCException {
        try {
            header(op, body == null ? 0 : body.length);
            if (body != null) putBytes(body);
            flush();
        } catch (IOException e) {
            throw lost(e);
        }
    }

    private String collect(int op, byte[] body) throws SILCException {
        StringBuilder sb = new StringBuilder();
        request(op, body);
        reply(sb::append, null);
        return sb.toString();
    }

    private void flush() throws IOException {
        buf.flip();
        while (buf.hasRemaining()) channel.write(buf);
        buf.clear();
    }

    private void room(int bytes) throws IOException {
        if (buf.remaining() < bytes) flush();
    }

    private void putBytes(byte[] b) throws IOException {
        for (int at = 0; at < b.length;) {
            room(1);
            int k = Math.min(buf.remaining(), b.length - at);
            buf.put(b, at, k);
            at += k;
        }
    }

    private void putInts(int[] a, long count) throws IOException {
        for (int i = 0; i < count; i++) {
            room(8);
            buf.putLong(a[i]);
        }
    }

    private void putDoubles(double[] a, long count) throws IOException {
        for (int at = 0; at < count;) {
            room(8);
            int k = (int) Math.min(buf.remaining() / 8, count - at);
            buf.asDoubleBuffer().put(a, at, k);
            buf.position(buf.position() + 8 * k);
            at += k;
        }
    }

    /* Reads exactly n <= buf.capacity() bytes into buf, ready to get. */
    private void readFully(int n) throws IOException {
        buf.clear().limit(n);
        while (buf.hasRemaining())
            if (channel.read(buf) < 0) throw new IOException("the server closed the connection");
        buf.flip();
    }

    private void readInts(int[] a, long count) throws IOException {
        for (int at = 0; at < count;) {
            int k = (int) Math.min(buf.capacity() / 8, count - at);
            readFully(8 * k);
            for (int q = 0; q < k; q++) {
                long x = buf.getLong();
                if (x < Integer.MIN_VALUE || x > Integer.MAX_VALUE)
                    throw new IOException("an index " + x + " does not fit a Java int");
                a[at + q] = (int) x;
            }
            at += k;
        }
    }

    private void readDoubles(double[] a, long count) throws IOException {
        for (int at = 0; at < count;) {
            int k = (int) Math.min(buf.capacity() / 8, count - at);
            readFully(8 * k);
            buf.asDoubleBuffer().get(a, at, k);
            at += k;
        }
    }

    private void skip(long n) throws IOException {
        while (n > 0) {
            int k = (int) Math.min(buf.capacity(), n);
            readFully(k);
            n -= k;
        }
    }

    /*
     * Reads replies up to the final one: TEXT goes to out, WARN to warnings;
     * returns OK's text or VALUE's value (into `into` when given), throws
     * ERROR's message.
     */
    private Object reply(Consumer<String> out, ColumnVector into) throws SILCException {
        need();
        try {
            for (;;) {
                readFully(16);
                int op = buf.getInt(), flags = buf.getInt();
                long length = buf.getLong();
                if (flags != 0 || length < 0) throw new IOException("malformed reply header");
                if (op == VALUE) return readValue(length, into);
                if (length > MAX_TEXT) throw new IOException("a reply of " + length + " bytes is too long");
                byte[] t = new byte[(int) length];
                for (int at = 0; at < t.length;) {
                    int k = Math.min(buf.capacity(), t.length - at);
                    readFully(k);
                    buf.get(t, at, k);
                    at += k;
                }
                String s = new String(t, StandardCharsets.UTF_8);
                switch (op) {
                    case TEXT -> (out != null ? out : output).accept(s);
                    case WARN -> warnings += s;
                    case OK -> {
                        return s;
                    }
                    case ERROR -> throw new SILCException(s);
                    default -> throw new IOException("unknown reply opcode " + op);
                }
            }
        } catch (IOException e) {
            throw lost(e);
        }
    }

    private Value readValue(long length, ColumnVector into) throws IOException, SILCException {
        if (length < DESCRIPTOR_BYTES) throw new IOException("a VALUE reply shorter than its descriptor");
        readFully(DESCRIPTOR_BYTES);
        int format = buf.getInt();
        buf.getInt();
        long m = buf.getLong(), n = buf.getLong(), nnz = buf.getLong(), kl = buf.getLong(), ku = buf.getLong();
        long arrays = (format == CSR_FORMAT ? 8 * (m + 1) + 8 * nnz : 0) + 8 * nnz;
        boolean sane = m >= 0 && n >= 0 && nnz >= 0 && m <= (1L << 40) && n <= (1L << 40) && nnz <= (1L << 40)
                && (format == DENSE && nnz == m * n || format == CSR_FORMAT
                    || format == BAND && kl >= 0 && ku >= 0 && nnz == (kl + ku + 1) * n)
                && length == DESCRIPTOR_BYTES + arrays;
        if (!sane) throw new IOException("a malformed VALUE descriptor");
        String shape = m + "x" + n;
        String refuse = null;
        if (into != null && (format != DENSE || n != 1 || m != into.v.length))
            refuse = "GET: the value is " + shape + (format == CSR_FORMAT ? " sparse" : "")
                    + ", the ColumnVector has " + into.v.length + " rows";
        else if (nnz > Integer.MAX_VALUE - 8 || m > Integer.MAX_VALUE - 8
                || format != CSR_FORMAT && m * n > Integer.MAX_VALUE - 8)
            refuse = "GET: a " + shape + " value does not fit a Java array";
        if (refuse != null) {
            skip(arrays); // the stream stays in step; the session goes on
            throw new SILCException(refuse);
        }
        if (format == CSR_FORMAT) {
            int[] rowptr = new int[(int) m + 1], colind = new int[(int) nnz];
            double[] val = new double[(int) nnz];
            readInts(rowptr, m + 1);
            readInts(colind, nnz);
            readDoubles(val, nnz);
            return new CRS((int) m, (int) n, rowptr, colind, val);
        }
        if (format == DENSE) {
            if (into != null) {
                readDoubles(into.v, nnz);
                return into;
            }
            double[] a = new double[(int) nnz];
            readDoubles(a, nnz);
            return new DenseMatrix((int) m, (int) n, a);
        }
        // Band, LAPACK layout: A(i, j) = band[ku + i - j + j * ld].
        double[] band = new double[(int) nnz];
        readDoubles(band, nnz);
        DenseMatrix d = new DenseMatrix((int) m, (int) n);
        long ld = kl + ku + 1;
        for (int j = 0; j < n; j++)
            for (long i = Math.max(0, j - ku); i < Math.min(m, j + kl + 1); i++)
                d.a[(int) (i + (long) j * m)] = band[(int) (ku + i - j + j * ld)];
        return d;
    }
}
