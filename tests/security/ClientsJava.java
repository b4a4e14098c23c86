/*
 * ClientsJava.java -- the Java client as tests/security/clients.py drives it
 * against its fake silcd: per case, INIT on URL, each call (get:NAME with
 * GET, getc:NAME with GETComplex, exec:TEXT), one line per call, "OK <format> <shape> ..." or "ERROR
 * <exception>: <message>"; anything but a SILCException (an
 * OutOfMemoryError, a runtime exception) is printed as "ERROR not
 * SILCException ..." for the test to catch.
 *
 *     java -cp silc.jar:. ClientsJava URL CALL...            one case, limits from the environment
 *     java -cp silc.jar:. ClientsJava --case NAME URL [K=V...] CALL... [--case ...]
 *
 * In the second form every case runs in this one JVM, its SILC_IO_TIMEOUT,
 * SILC_EXEC_TIMEOUT and SILC_MAX_REPLY_BYTES given as K=V and applied with
 * setTimeouts / setMaxValueBytes (a JVM cannot change its environment).
 */
import java.util.ArrayList;
import java.util.Arrays;
import java.util.List;

import silc.CRS;
import silc.ComplexMatrix;
import silc.DenseMatrix;
import silc.SILC;
import silc.SILCException;
import silc.Value;

public final class ClientsJava {
    private ClientsJava() {}

    private static String number(double x) {
        return x == Math.rint(x) ? Long.toString((long) x) : Double.toString(x);
    }

    private static long bytes(String v) {
        char last = Character.toLowerCase(v.charAt(v.length() - 1));
        int shift = last == 'k' ? 10 : last == 'm' ? 20 : last == 'g' ? 30 : 0;
        return Long.parseLong(shift > 0 ? v.substring(0, v.length() - 1) : v) << shift;
    }

    private static void runCase(String url, List<String> settings, List<String> calls) {
        SILC s = new SILC();
        try {
            double io = 300, exec = 0;
            for (String kv : settings) {
                String k = kv.substring(0, kv.indexOf('=')), v = kv.substring(kv.indexOf('=') + 1);
                switch (k) {
                    case "SILC_IO_TIMEOUT" -> io = Double.parseDouble(v);
                    case "SILC_EXEC_TIMEOUT" -> exec = Double.parseDouble(v);
                    case "SILC_MAX_REPLY_BYTES" -> s.setMaxValueBytes(bytes(v));
                    default -> throw new IllegalArgumentException("unknown setting " + k);
                }
            }
            if (!settings.isEmpty()) s.setTimeouts(io, exec);
            s.INIT(url);
        } catch (SILCException e) {
            System.out.println("ERROR SILCException: " + e.getMessage());
            return;
        }
        for (String call : calls) {
            try {
                if (call.startsWith("exec:")) {
                    s.setOutput(null);
                    s.EXEC(call.substring(5));
                    System.out.println("OK exec");
                    continue;
                }
                Value v = call.startsWith("getc:") ? s.GETComplex(call.substring(5)) : s.GET(call.substring(4));
                if (v instanceof CRS c)
                    System.out.println("OK csr " + c.m + "x" + c.n + " nnz " + c.nnz());
                else if (v instanceof ComplexMatrix z)
                    System.out.println("OK complex dense " + z.m + "x" + z.n + " "
                            + (z.a.length > 0 ? number(z.a[0]) + " " + number(z.a[1]) : "-"));
                else if (v instanceof DenseMatrix d)
                    System.out.println("OK dense " + d.m + "x" + d.n + " " + (d.a.length > 0 ? number(d.a[0]) : "-"));
                else
                    System.out.println("OK " + v.getClass().getSimpleName());
            } catch (SILCException e) {
                System.out.println("ERROR SILCException: " + e.getMessage());
            } catch (Throwable e) {
                System.out.println("ERROR not SILCException " + e);
            }
        }
        s.close();
    }

    public static void main(String[] args) {
        if (!args[0].equals("--case")) {
            runCase(args[0], List.of(), Arrays.asList(args).subList(1, args.length));
            return;
        }
        for (int k = 0; k < args.length;) {
            String name = args[k + 1], url = args[k + 2];
            List<String> settings = new ArrayList<>(), calls = new ArrayList<>();
            for (k += 3; k < args.length && !args[k].equals("--case"); k++)
                (args[k].contains(":") ? calls : settings).add(args[k]);
            System.out.println("CASE " + name);
            runCase(url, settings, calls);
        }
    }
}
