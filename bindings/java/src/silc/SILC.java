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
 * Complex values go in as ComplexMatrix or ComplexCRS (real and imaginary
 * part interleaved, SILC's layout) and come out of GETComplex, which takes
 * either field; the plain GET takes real values only, and a complex one is
 * a SILCException naming it ("'z' is complex ..."), never half the data.
 *
 * No JNI and no C library: any JVM that can open a socket can use SILC, and
 * this file is a third implementation of the protocol beside the C one and
 * bindings/python/silc.py.  Every failure is a checked SILCException whose
 * message is the server's, the text the C API reports for the same call.
 * Values stream through one reused direct buffer, so a step's PUT of a large
 * matrix allocates nothing on the Java heap.  A SILC object is one session
 * and is not thread-safe (as a C context is not); open one per thread.
 *
 * Replies are not trusted: a frame's length must agree with its descriptor,
 * CSR arrays are checked (rowptr from 0 to nnz and never decreasing, columns
 * in range and increasing) with the C library's messages, a value over the
 * client's cap (setMaxValueBytes, SILC_MAX_REPLY_BYTES, default 2 GiB) is
 * skipped and refused while the session goes on, text is held to 64 MiB,
 * and a band value comes back dense only when m*n doubles fit that cap.  A
 * server that sends nothing for the I/O timeout (setTimeouts,
 * SILC_IO_TIMEOUT, default 300 s) inside a reply or before answering any
 * call but EXEC is an error naming it; EXEC waits as long as its
 * statements compute unless SILC_EXEC_TIMEOUT is set.
 */
package silc;

import java.io.IOException;
import java.net.InetSocketAddress;
import java.net.StandardProtocolFamily;
import java.net.StandardSocketOptions;
import java.net.UnixDomainSocketAddress;
import java.nio.ByteBuffer;
import java.nio.ByteOrder;
import java.nio.channels.SelectionKey;
import java.nio.channels.Selector;
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
            CANCEL = 9, GET_COMPLEX = 10;
    static final int OK = 128, ERROR = 129, VALUE = 130, TEXT = 131, WARN = 132;
    static final int DENSE = 0, CSR_FORMAT = 1, BAND = 2;
    /** The format bit of a complex value: 2 doubles (re, im) an entry. */
    static final int COMPLEX = 16;
    static final int DESCRIPTOR_BYTES = 48;
    /** Longest text reply accepted (the server's own limit on text). */
    static final long MAX_TEXT = 64L << 20;
    static final long DEFAULT_MAX_VALUE_BYTES = 2L << 30;
    static final double DEFAULT_IO_TIMEOUT = 300;
    private static final int BUFFER_BYTES = 1 << 20;

    private SocketChannel channel;
    private Selector selector;
    private SelectionKey key;
    /* Milliseconds; 0 = wait for ever (Selector.select's convention). */
    private long ioTimeoutMs, execTimeoutMs;
    private long maxValueBytes;
    private String url = "";
    private String warnings = "";
    private Consumer<String> output = System.out::print;
    /* One buffer for everything sent and received; values stream through it. */
    private final ByteBuffer buf = ByteBuffer.allocateDirect(BUFFER_BYTES).order(ByteOrder.LITTLE_ENDIAN);
    /* cancel() writes only while an EXEC waits for its reply, so its frame
     * never lands inside another request. */
    private final Object cancelLock = new Object();
    private boolean awaitingExec;
    /* A CANCEL went out for the EXEC awaited: the output still on its way
     * is dropped and its bytes counted in a warning, as the C and Python
     * clients do, so the interrupt shows at once, not after a loop's backlog.
     * Volatile: cancel() runs on another thread than the EXEC's reader. */
    private volatile boolean cancelSent;
    private long droppedBytes;

    /* A malformed SILC_* limit variable, reported by INIT. */
    private String envError;

    /** A client with the limits of SILC_IO_TIMEOUT, SILC_EXEC_TIMEOUT and
     *  SILC_MAX_REPLY_BYTES, else 300 s, none and 2 GiB (a malformed
     *  variable makes INIT fail, naming it). */
    public SILC() {
        try {
            setTimeouts(seconds("SILC_IO_TIMEOUT", DEFAULT_IO_TIMEOUT), seconds("SILC_EXEC_TIMEOUT", 0));
            setMaxValueBytes(size("SILC_MAX_REPLY_BYTES", DEFAULT_MAX_VALUE_BYTES));
        } catch (SILCException e) {
            envError = e.getMessage();
        }
    }

    /** The longest silence accepted inside a reply and before the reply to
     *  any call but EXEC, and before EXEC's replies; seconds, 0 for none. */
    public void setTimeouts(double ioSeconds, double execSeconds) throws SILCException {
        if (!timeoutInRange(ioSeconds) || !timeoutInRange(execSeconds))
            throw new SILCException("a timeout must be 0 (none) or seconds from 0.001 to 31536000");
        ioTimeoutMs = (long) Math.ceil(ioSeconds * 1000);
        execTimeoutMs = (long) Math.ceil(execSeconds * 1000);
    }

    /** The largest value (bytes of its arrays) a reply may hold. */
    public void setMaxValueBytes(long bytes) throws SILCException {
        if (bytes < 0) throw new SILCException("setMaxValueBytes: " + bytes + " is negative");
        maxValueBytes = bytes;
    }

    /* 0 (none) or [1 ms, a year], as the C and Python clients. */
    private static boolean timeoutInRange(double x) {
        return x == 0 || (x >= 0.001 && x <= 31536000);
    }

    private static double seconds(String var, double dflt) throws SILCException {
        String v = System.getenv(var);
        if (v == null || v.isEmpty()) return dflt;
        try {
            double x = Double.parseDouble(v);
            if (timeoutInRange(x)) return x;
        } catch (NumberFormatException e) {
            // reported below
        }
        throw new SILCException(var + " = '" + v + "': expected 0 (no timeout) or seconds from 0.001 to 31536000");
    }

    /* "123", "64K", "512M", "2G", "1T", as silcd's size options. */
    private static long size(String var, long dflt) throws SILCException {
        String v = System.getenv(var);
        if (v == null || v.isEmpty()) return dflt;
        int shift = switch (Character.toLowerCase(v.charAt(v.length() - 1))) {
            case 'k' -> 10;
            case 'm' -> 20;
            case 'g' -> 30;
            case 't' -> 40;
            default -> 0;
        };
        String digits = shift > 0 ? v.substring(0, v.length() - 1) : v;
        try {
            long x = Long.parseLong(digits);
            if (x >= 0 && x <= (Long.MAX_VALUE >> shift) && digits.chars().allMatch(Character::isDigit))
                return x << shift;
        } catch (NumberFormatException e) {
            // reported below
        }
        throw new SILCException(var + " = '" + v + "': expected a size in bytes with an optional K, M, G or T suffix");
    }

    /* A reply that breaks the protocol, or a silent server: the stream is
     * out of step, so the connection is closed; the message is complete. */
    private static final class BadReply extends IOException {
        private static final long serialVersionUID = 1L;

        BadReply(String message) {
            super(message);
        }
    }

    private BadReply bad(String why) {
        return new BadReply("silc server " + url + " sent a bad reply: " + why + " (connection closed)");
    }

    private static String secs(long ms) {
        return ms % 1000 == 0 ? Long.toString(ms / 1000) : Double.toString(ms / 1000.0);
    }

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
        if (envError != null) throw new SILCException(envError);
        this.url = url;
        byte[] tok = (token != null ? token : tokenFromEnv()).getBytes(StandardCharsets.UTF_8);
        if (tok.length > 4096) throw new SILCException("INIT: the token is longer than 4096 bytes");
        try {
            channel = connect(url);
            channel.configureBlocking(false);
            selector = Selector.open();
            key = channel.register(selector, 0);
            buf.clear();
            buf.put("SILC".getBytes(StandardCharsets.US_ASCII)).putInt(PROTOCOL_VERSION).putInt(tok.length).put(tok);
            flush();
            readFully(12, ioTimeoutMs, false);
            byte[] magic = new byte[4];
            buf.get(magic);
            if (!Arrays.equals(magic, "SILC".getBytes(StandardCharsets.US_ASCII)))
                throw new SILCException(url + " is not a SILC server");
            reply(null, null);
        } catch (BadReply e) {
            drop();
            throw new SILCException(e.getMessage(), e);
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
            if (ioTimeoutMs == 0 || ioTimeoutMs > 5000) ioTimeoutMs = 5000; // goodbye waits 5 s at most
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
        int format, nnz, width = v instanceof ComplexMatrix || v instanceof ComplexCRS ? 2 : 1;
        long m = v.rows(), n = v.cols();
        if (v instanceof CRS a) {
            format = CSR_FORMAT;
            nnz = a.nnz();
        } else if (v instanceof ComplexCRS a) {
            format = CSR_FORMAT | COMPLEX;
            nnz = a.nnz();
        } else {
            format = width == 2 ? DENSE | COMPLEX : DENSE;
            nnz = (int) (m * n);
        }
        long arrays = ((format & ~COMPLEX) == CSR_FORMAT ? 8L * (m + 1) + 8L * nnz : 0) + 8L * width * nnz;
        try {
            header(PUT, DESCRIPTOR_BYTES + nm.length + arrays);
            buf.putInt(format).putInt(nm.length).putLong(m).putLong(n).putLong(nnz).putLong(0).putLong(0);
            putBytes(nm);
            if (v instanceof CRS a) {
                putInts(a.rowptr, m + 1);
                putInts(a.colind, nnz);
                putDoubles(a.val, nnz);
            } else if (v instanceof ComplexCRS a) {
                putInts(a.rowptr, m + 1);
                putInts(a.colind, nnz);
                putDoubles(a.val, 2L * nnz);
            } else if (v instanceof DenseMatrix d) {
                putDoubles(d.a, nnz);
            } else if (v instanceof ComplexMatrix z) {
                putDoubles(z.a, 2L * nnz);
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

    /** The real value bound to name: a CRS, or a DenseMatrix (band values come
     *  dense); a complex value is refused (SILCException "'z' is complex ..."):
     *  fetch it with GETComplex. */
    public Value GET(String name) throws SILCException {
        request(GET, text(name, "GET"));
        return (Value) reply(null, null);
    }

    /** The value bound to name, either field: a ComplexCRS or ComplexMatrix
     *  (band values come dense) when it is complex, else as GET returns it.
     *  A server older than complex values answers "unknown request opcode 10". */
    public Value GETComplex(String name) throws SILCException {
        request(GET_COMPLEX, text(name, "GETComplex"));
        return (Value) reply(null, null, ioTimeoutMs, "SILC_IO_TIMEOUT", true);
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
            cancelSent = false;
            droppedBytes = 0;
        }
        try {
            reply(output, null, execTimeoutMs, "SILC_EXEC_TIMEOUT", false);
        } finally {
            synchronized (cancelLock) {
                awaitingExec = false;
                cancelSent = false; // the next request's text is shown
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
            cancelSent = true; // before the frame: what answers it is backlog
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
        // A regular file only, read up to 8 KiB: a FIFO with no writer hung
        // the client, /dev/zero filled its memory.
        Path p = Path.of(f);
        if (Files.exists(p) && !Files.isRegularFile(p))
            throw new SILCException("SILC_TOKEN_FILE '" + f + "' is not a regular file");
        try (java.io.InputStream in = Files.newInputStream(p)) {
            String text = new String(in.readNBytes(8192), StandardCharsets.UTF_8);
            int end = text.indexOf('\n');
            return (end < 0 ? text : text.substring(0, end)).replaceAll("\r$", "");
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
        if (e instanceof BadReply) return new SILCException(e.getMessage(), e);
        return new SILCException("connection to silc server " + url + " lost: " + e.getMessage(), e);
    }

    private void drop() {
        if (selector != null) {
            try {
                selector.close();
            } catch (IOException e) {
                // Nothing more to do.
            }
            selector = null;
        }
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

    /* Waits up to timeoutMs (0: for ever) for the channel to be ready for op. */
    private boolean await(int op, long timeoutMs) throws IOException {
        key.interestOps(op);
        int ready = selector.select(timeoutMs);
        selector.selectedKeys().clear();
        return ready > 0;
    }

    private void flush() throws IOException {
        buf.flip();
        while (buf.hasRemaining())
            if (channel.write(buf) == 0 && !await(SelectionKey.OP_WRITE, ioTimeoutMs))
                throw new BadReply("silc server " + url + " accepted nothing for " + secs(ioTimeoutMs)
                        + " s (SILC_IO_TIMEOUT; connection closed)");
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

    /* Reads exactly n <= buf.capacity() bytes into buf, ready to get.
     * Inside a frame (mid) every wait is the I/O timeout; the first byte of
     * a frame may take firstWaitMs (0: for ever; var names its setting). */
    private void readFully(int n, long firstWaitMs, boolean mid, String var) throws IOException {
        buf.clear().limit(n);
        while (buf.hasRemaining()) {
            int got = channel.read(buf);
            if (got < 0) throw new IOException("connection closed by peer");
            if (got > 0) {
                mid = true;
                continue;
            }
            if (!await(SelectionKey.OP_READ, mid ? ioTimeoutMs : firstWaitMs))
                throw new BadReply(mid ? "silc server " + url + " stopped sending in the middle of a reply: nothing for "
                        + secs(ioTimeoutMs) + " s (SILC_IO_TIMEOUT; connection closed)"
                        : "silc server " + url + " sent nothing for " + secs(firstWaitMs) + " s (" + var
                        + "; connection closed)");
        }
        buf.flip();
    }

    private void readFully(int n, long firstWaitMs, boolean mid) throws IOException {
        readFully(n, firstWaitMs, mid, "SILC_IO_TIMEOUT");
    }

    private void readFully(int n) throws IOException {
        readFully(n, ioTimeoutMs, true, "SILC_IO_TIMEOUT");
    }

    private void readInts(int[] a, long count) throws IOException {
        for (int at = 0; at < count;) {
            int k = (int) Math.min(buf.capacity() / 8, count - at);
            readFully(8 * k);
            for (int q = 0; q < k; q++) {
                long x = buf.getLong();
                if (x < Integer.MIN_VALUE || x > Integer.MAX_VALUE)
                    throw bad("an index " + x + " does not fit a Java int");
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
        return reply(out, into, ioTimeoutMs, "SILC_IO_TIMEOUT", false);
    }

    private static String opName(int op) {
        return switch (op) {
            case OK -> "OK";
            case ERROR -> "ERROR";
            case TEXT -> "TEXT";
            case WARN -> "WARN";
            default -> "VALUE";
        };
    }

    /* complexOk: the request was GET_COMPLEX (a complex VALUE is welcome). */
    private Object reply(Consumer<String> out, ColumnVector into, long firstWaitMs, String var, boolean complexOk)
            throws SILCException {
        need();
        try {
            for (;;) {
                readFully(16, firstWaitMs, false, var);
                int op = buf.getInt(), flags = buf.getInt();
                long length = buf.getLong();
                if (flags != 0) throw bad("frame flags " + flags + " are not 0 (protocol version 1)");
                if (op == VALUE) return readValue(length, into, complexOk);
                if (op != OK && op != ERROR && op != TEXT && op != WARN)
                    throw bad("unknown reply opcode " + op);
                if (length < 0 || length > MAX_TEXT)
                    throw bad(opName(op) + " reply of " + Long.toUnsignedString(length)
                            + " bytes exceeds the limit of " + MAX_TEXT + " bytes");
                // Read as it arrives: a header that lies about its length costs nothing.
                java.io.ByteArrayOutputStream t = new java.io.ByteArrayOutputStream();
                for (long at = 0; at < length;) {
                    int k = (int) Math.min(buf.capacity(), length - at);
                    readFully(k);
                    byte[] chunk = new byte[k];
                    buf.get(chunk);
                    t.write(chunk, 0, k);
                    at += k;
                }
                String s = t.toString(StandardCharsets.UTF_8);
                switch (op) {
                    case TEXT -> {
                        if (cancelSent) droppedBytes += length;
                        else (out != null ? out : output).accept(s);
                    }
                    case WARN -> warnings += s;
                    case OK -> {
                        return s;
                    }
                    case ERROR -> {
                        if (droppedBytes > 0)
                            warnings += "interrupted: " + droppedBytes + " bytes of the statement's output, still on "
                                    + "the way from the server, were not shown\n";
                        droppedBytes = 0;
                        throw new SILCException(s);
                    }
                    default -> throw new IOException("unknown reply opcode " + op);
                }
            }
        } catch (IOException e) {
            throw lost(e);
        }
    }

    /* A descriptor's array bytes, checked as protocol.c checks it (same
     * messages); a complex value (format | COMPLEX) has 16 bytes an entry. */
    private long layout(int format, long m, long n, long nnz, long kl, long ku) throws BadReply {
        long entry = (format & COMPLEX) != 0 ? 16 : 8;
        int base = format & ~COMPLEX;
        if (base < DENSE || base > BAND) throw bad("unknown value format " + Integer.toUnsignedString(format));
        if (m < 0 || n < 0 || nnz < 0 || kl < 0 || ku < 0)
            throw bad("negative size in value descriptor (m = " + m + ", n = " + n + ", nnz = " + nnz
                    + ", kl = " + kl + ", ku = " + ku + ")");
        if (m > (1L << 40) || n > (1L << 40))
            throw bad("dimensions " + m + "x" + n + " exceed the protocol's limit of 2^40");
        if (base == DENSE) {
            if (Math.multiplyHigh(m, n) != 0 || m * n != nnz || nnz > Long.MAX_VALUE / 16)
                throw bad("dense " + m + "x" + n + " value declares " + nnz + " entries");
            if (kl != 0 || ku != 0) throw bad("dense value with band widths");
            return entry * nnz;
        }
        if (base == CSR_FORMAT) {
            if (kl != 0 || ku != 0) throw bad("csr value with band widths");
            if (nnz > Long.MAX_VALUE / 32) throw bad("csr value declares " + nnz + " entries");
            return 8 * (m + 1) + (8 + entry) * nnz;
        }
        if (kl > Integer.MAX_VALUE || ku > Integer.MAX_VALUE || Math.multiplyHigh(kl + ku + 1, n) != 0
                || (kl + ku + 1) * n != nnz || nnz > Long.MAX_VALUE / 16)
            throw bad("band " + m + "x" + n + " value with kl = " + kl + ", ku = " + ku + " declares " + nnz + " entries");
        return entry * nnz;
    }

    /* CSR arrays as the C library checks them, in its order and words. */
    private void checkCsr(int[] rowptr, int[] colind, int m, int n, int nnz) throws BadReply {
        if (rowptr[m] != nnz)
            throw bad("'VALUE': rowptr[m] = " + rowptr[m] + " but the descriptor declares " + nnz + " entries");
        if (rowptr[0] != 0) throw bad("'VALUE': rowptr[0] is " + rowptr[0] + ", must be 0");
        for (int i = 0; i < m; i++)
            if (rowptr[i + 1] < rowptr[i])
                throw bad("'VALUE': rowptr decreases at row " + i + " (rowptr[" + i + "] = " + rowptr[i] + " > rowptr["
                        + (i + 1) + "] = " + rowptr[i + 1] + ")");
        for (int i = 0; i < m; i++)
            for (int k = rowptr[i]; k < rowptr[i + 1]; k++) {
                if (colind[k] < 0 || colind[k] >= n)
                    throw bad("'VALUE': column index " + colind[k] + " out of range [0, " + n + ") in row " + i);
                if (k > rowptr[i] && colind[k - 1] >= colind[k])
                    throw bad("'VALUE': columns of row " + i + " are "
                            + (colind[k - 1] == colind[k] ? "duplicated" : "not sorted"));
            }
    }

    private Value readValue(long length, ColumnVector into, boolean complexOk) throws IOException, SILCException {
        if (length < DESCRIPTOR_BYTES) throw bad("VALUE reply shorter than its descriptor");
        readFully(DESCRIPTOR_BYTES);
        int format = buf.getInt();
        int namelen = buf.getInt();
        long m = buf.getLong(), n = buf.getLong(), nnz = buf.getLong(), kl = buf.getLong(), ku = buf.getLong();
        if (namelen != 0) throw bad("VALUE reply with a name length");
        boolean complex = (format & COMPLEX) != 0;
        if (complex && !complexOk) throw bad("a complex value in reply to a GET, which asks for real values only");
        long arrays = layout(format, m, n, nnz, kl, ku);
        int width = complex ? 2 : 1;
        format &= ~COMPLEX;
        if (length - DESCRIPTOR_BYTES != arrays)
            throw bad("VALUE reply carries " + Long.toUnsignedString(length - DESCRIPTOR_BYTES)
                    + " bytes of arrays, its descriptor needs " + arrays);
        String shape = m + "x" + n;
        String name = format == CSR_FORMAT ? "csr" : format == BAND ? "band" : "dense";
        String refuse = null;
        if (arrays > maxValueBytes || format == BAND && 8.0 * width * m * n > maxValueBytes)
            refuse = "silc server " + url + ": reply refused: a " + shape + " " + name + " value of "
                    + (format == BAND ? (long) (8.0 * width * m * n) + " bytes as a "
                            + (complex ? "ComplexMatrix" : "DenseMatrix") : arrays + " bytes")
                    + ", over the client's limit of " + maxValueBytes
                    + " bytes per value (SILC_MAX_REPLY_BYTES, setMaxValueBytes)";
        else if (into != null && (format != DENSE || n != 1 || m != into.v.length))
            refuse = "GET: the value is " + shape + (format == CSR_FORMAT ? " sparse" : "")
                    + ", the ColumnVector has " + into.v.length + " rows";
        else if (width * nnz > Integer.MAX_VALUE - 8 || m > Integer.MAX_VALUE - 8
                || format != CSR_FORMAT && width * m * n > Integer.MAX_VALUE - 8)
            refuse = "GET: a " + shape + " value does not fit a Java array";
        if (refuse != null) {
            skip(arrays); // the stream stays in step; the session goes on
            throw new SILCException(refuse);
        }
        if (format == CSR_FORMAT) {
            int[] rowptr = new int[(int) m + 1], colind = new int[(int) nnz];
            double[] val = new double[(int) (width * nnz)];
            readInts(rowptr, m + 1);
            readInts(colind, nnz);
            readDoubles(val, width * nnz);
            checkCsr(rowptr, colind, (int) m, (int) n, (int) nnz);
            return complex ? new ComplexCRS((int) m, (int) n, rowptr, colind, val)
                           : new CRS((int) m, (int) n, rowptr, colind, val);
        }
        if (format == DENSE) {
            if (into != null) {
                readDoubles(into.v, nnz);
                return into;
            }
            double[] a = new double[(int) (width * nnz)];
            readDoubles(a, width * nnz);
            return complex ? new ComplexMatrix((int) m, (int) n, a) : new DenseMatrix((int) m, (int) n, a);
        }
        // Band, LAPACK layout: A(i, j) = band[ku + i - j + j * ld], dense under the cap (checked above);
        // each entry is width doubles.
        double[] band = new double[(int) (width * nnz)];
        readDoubles(band, width * nnz);
        double[] a = new double[(int) (width * m * n)];
        long ld = kl + ku + 1;
        for (int j = 0; j < n; j++)
            for (long i = Math.max(0, j - ku); i < Math.min(m, j + kl + 1); i++)
                for (int w = 0; w < width; w++)
                    a[(int) (width * (i + (long) j * m) + w)] = band[(int) (width * (ku + i - j + j * ld) + w)];
        return complex ? new ComplexMatrix((int) m, (int) n, a) : new DenseMatrix((int) m, (int) n, a);
    }
}
