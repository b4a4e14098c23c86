/*
 * SILCException.java -- what a SILC call that failed throws: the server's
 * message (exactly the text the C API reports for the same failure), or what
 * went wrong with the connection.
 */
package silc;

/** A request the server refused, or a lost connection; the message says which. */
public class SILCException extends Exception {
    private static final long serialVersionUID = 1L;

    public SILCException(String message) {
        super(message);
    }

    public SILCException(String message, Throwable cause) {
        super(message, cause);
    }
}
