/*
 * Value.java -- what can be PUT to and GOT from a SILC server: a sparse CRS
 * matrix, a dense matrix or a column vector, or their complex twins
 * (ComplexCRS, ComplexMatrix).  Every value knows its shape;
 * the client turns each into the wire protocol's value descriptor and arrays
 * (docs/protocol.md).
 */
package silc;

/** A matrix or vector that travels between a Java program and SILC. */
public sealed interface Value permits CRS, DenseMatrix, ColumnVector, ComplexCRS, ComplexMatrix {
    /** Rows. */
    int rows();

    /** Columns. */
    int cols();
}
