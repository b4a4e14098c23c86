#!/bin/sh
# silcd_missing_plugin.sh SILCD DIR -- issue 28: a backend that silcd's
# config names and that is not installed is an error at start (exit 2, the
# message naming the plugin, its file and the directories searched), never
# a silent substitute; marked optional ("template?") the server starts and
# stops cleanly on SIGTERM.  The template plugin is built outside the
# plugin path (build/plugins/template), as test_fallback's silc_open case
# uses it.  Scratch files go to DIR.
SILCD=$1
DIR=$2
conf=$DIR/silcd_missing_plugin.conf
sock=$DIR/silcd_missing_plugin.sock
err=$DIR/silcd_missing_plugin.err
fail() { echo "FAIL: $*"; cat "$err"; exit 1; }

printf '[dispatch]\nsolve.sparse = template\n' > "$conf"
rm -f "$sock"
timeout 60 "$SILCD" --listen "unix:$sock" --config "$conf" 2>"$err"
rc=$?
[ "$rc" = 2 ] || fail "a missing configured plugin: exit $rc, want 2"
grep -q "names backend 'template', which is not installed" "$err" || fail "the message does not name the backend"
grep -q "libsilc_plugin_template.so" "$err" || fail "the message does not name the plugin file"
grep -q "searched: " "$err" || fail "the message does not list the directories searched"
[ -e "$sock" ] && fail "silcd listened before failing"
echo "missing: $(cat "$err")"

printf '[dispatch]\nsolve.sparse = template?, suitesparse.umfpack\n' > "$conf"
"$SILCD" --listen "unix:$sock" --config "$conf" --log-level error 2>"$err" &
pid=$!
i=0
while [ ! -S "$sock" ] && [ $i -lt 600 ] && kill -0 $pid 2>/dev/null; do
    sleep 0.1
    i=$((i + 1))
done
[ -S "$sock" ] || { kill $pid 2>/dev/null; fail "optional missing plugin: silcd did not start"; }
kill -TERM $pid
wait $pid
rc=$?
[ "$rc" = 0 ] || fail "optional missing plugin: exit $rc after SIGTERM, want 0"
echo "optional: started and stopped"
rm -f "$conf" "$err"
