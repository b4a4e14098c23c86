/*
 * ClientsJava.java -- the Java client as tests/security/clients.py drives it
 * against its fake silcd: INIT on URL, each call (get:NAME, exec:TEXT), one
 * line per call, "OK <format> <shape> ..." or "ERROR <exception>: <message>";
 * anything but a SILCException (an OutOfMemoryError, a runtime exception) is
 * printed as "ERROR not SILCException ..." for the test to catch.
 *
 *     java -cp silc.jar:. ClientsJava URL CALL...
 */
import silc.CRS;
import silc.DenseMatrix;
import silc.SILC;
import silc.SILCException;
import silc.Value;

public final class ClientsJava {
    private ClientsJava() {}

    private static String number(double x) {
        return x == Math.rint(x) ? Long.toString((long) x) : Double.toString(x);
    }

    public static void main(String[] args) {
        SILC s = new SILC();
        try {
            s.INIT(args[0]);
        } catch (SILCException e) {
            System.out.println("ERROR SILCException: " + e.getMessage());
            return;
        }
        for (int k = 1; k < args.length; k++) {
            String call = args[k];
            try {
                if (call.startsWith("exec:")) {
                    s.setOutput(null);
                    s.EXEC(call.substring(5));
                    System.out.println("OK exec");
                    continue;
                }
                Value v = s.GET(call.substring(4));
                if (v instanceof CRS c)
                    System.out.println("OK csr " + c.m + "x" + c.n + " nnz " + c.nnz());
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
}
