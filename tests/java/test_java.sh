#!/bin/sh
# test_java.sh -- the Java client's test (TestClient.java): first against the
# fixture's silcd (SILC_SERVER, a Unix socket), then against a silcd this
# script starts on TCP (an ephemeral port) with a token, for INIT(host, port)
# and the token cases.
#
#     sh tests/java/test_java.sh JAVA JAR CLASSDIR SILCD
set -u
JAVA=$1 JAR=$2 CLASSES=$3 SILCD=$4
"$JAVA" -cp "$JAR:$CLASSES" TestClient || exit 1
# Time values outside 0 or [1 ms, a year] are refused, naming the bounds.
SILC_IO_TIMEOUT=1e30 "$JAVA" -cp "$JAR:$CLASSES" TestClient badenv \
    "SILC_IO_TIMEOUT = '1e30': expected 0 (no timeout) or seconds from 0.001 to 31536000" || exit 1
# A token file that is not a regular file (/dev/zero filled the JVM's memory).
SILC_TOKEN_FILE=/dev/zero timeout 60 "$JAVA" -cp "$JAR:$CLASSES" TestClient badenv \
    "SILC_TOKEN_FILE '/dev/zero' is not a regular file" || exit 1
. "$(dirname "$0")/../../tools/silcd_run.sh"
echo "java-test-token-1234" > "$SILCD_DIR/token"
chmod 600 "$SILCD_DIR/token"      # silcd refuses a token file others can read
SILCD_LISTEN=tcp://127.0.0.1:0 silcd_start "$SILCD" --token-file "$SILCD_DIR/token"
PORT=${SILCD_URL##*:}      # tcp://127.0.0.1:PORT
SILC_TOKEN=java-test-token-1234 "$JAVA" -cp "$JAR:$CLASSES" TestClient token 127.0.0.1 "$PORT" java-test-token-1234
