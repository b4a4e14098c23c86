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
DIR=$(mktemp -d /tmp/silc-java-test.XXXXXX)
trap 'kill "$PID" 2>/dev/null; wait "$PID" 2>/dev/null; rm -rf "$DIR"' EXIT
echo "java-test-token-1234" > "$DIR/token"
"$SILCD" --listen tcp://127.0.0.1:0 --token-file "$DIR/token" --ready-file "$DIR/ready" --log-level error &
PID=$!
i=0
while [ ! -s "$DIR/ready" ] && [ $i -lt 100 ]; do sleep 0.1; i=$((i + 1)); done
[ -s "$DIR/ready" ] || { echo "test_java.sh: silcd did not start" >&2; exit 1; }
ADDR=$(cat "$DIR/ready")          # tcp://127.0.0.1:PORT
PORT=${ADDR##*:}
SILC_TOKEN=java-test-token-1234 "$JAVA" -cp "$JAR:$CLASSES" TestClient token 127.0.0.1 "$PORT" java-test-token-1234
