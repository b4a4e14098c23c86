#!/bin/sh
# ssh_tunnel.sh -- the remote setup docs/server.md and docs/security.md
# recommend, end to end: silcd on a Unix socket (mode 0600, with a token),
# reached through `ssh -N -L LOCAL.sock:SILCD.sock`.  The test starts its
# own sshd as the current user on 127.0.0.1 (a free port) with a generated
# host key and an authorized_keys of a generated client key, all in
# STATEDIR (under the build directory), then solves a small system through
# the tunnel with the silc command and checks x against the exact solution.
#
#     sh ssh_tunnel.sh SILCD SILC_CLI STATEDIR
#
# Without sshd, ssh or ssh-keygen (Debian: openssh-server, openssh-client)
# it says why and exits 77, which ctest reports as skipped (SKIP_RETURN_CODE),
# never as passed.
set -u
SILCD=$1 CLI=$2 D=$3
SKIP=77

SSHD=
for c in /usr/sbin/sshd /usr/local/sbin/sshd /sbin/sshd; do   # sshd wants an absolute path
    [ -x "$c" ] && { SSHD=$c; break; }
done
[ -n "$SSHD" ] || { echo "SKIP: no sshd (apt-get install openssh-server)"; exit $SKIP; }
for c in ssh ssh-keygen; do
    command -v $c >/dev/null 2>&1 || { echo "SKIP: no $c (apt-get install openssh-client)"; exit $SKIP; }
done
PY=$(command -v python3 || true)
[ -n "$PY" ] || { echo "SKIP: no python3 to find a free port"; exit $SKIP; }

rm -rf "$D"
mkdir -p "$D" || exit 1
D=$(cd "$D" && pwd)
SSHD_PID= SSH_PID= fails=0
cleanup() {
    [ -n "$SSH_PID" ] && kill "$SSH_PID" 2>/dev/null && wait "$SSH_PID" 2>/dev/null
    [ -n "$SSHD_PID" ] && kill "$SSHD_PID" 2>/dev/null && wait "$SSHD_PID" 2>/dev/null
}
fail() { echo "FAIL: $*"; fails=$((fails + 1)); }

# sshd run by root checks its privilege-separation directory, which the
# package's init script creates at boot; a container has none.
if [ "$(id -u)" -eq 0 ] && [ ! -d /run/sshd ]; then
    mkdir -p /run/sshd && chmod 0755 /run/sshd || { echo "SKIP: cannot create /run/sshd"; exit $SKIP; }
fi

# ---- keys and sshd's own config, all in D ------------------------------------------
ssh-keygen -q -t ed25519 -N '' -f "$D/host_key" || exit 1
ssh-keygen -q -t ed25519 -N '' -f "$D/client_key" || exit 1
cp "$D/client_key.pub" "$D/authorized_keys"
chmod 600 "$D/authorized_keys"
USER_NAME=$(id -un)

# silcd: a Unix socket in D, a token as the documented recipe has it.
"$SILCD" --make-token "$D/token" >/dev/null || { echo "FAIL: silcd --make-token"; exit 1; }
SILCD_LISTEN=unix:$D/silcd.sock
export SILCD_LISTEN
. "$(dirname "$0")/../../tools/silcd_run.sh"
trap 'cleanup; silcd_cleanup_' EXIT
silcd_start "$SILCD" --token-file "$D/token"

# sshd on a free port of 127.0.0.1 (a port taken between the probe and the
# bind is retried).  Forwarding a Unix socket needs AllowStreamLocalForwarding
# and, in OpenSSH's check, local TCP forwarding allowed too; nothing else.
started=0
for attempt in 1 2 3 4 5; do
    PORT=$("$PY" -c 'import socket; s = socket.socket(); s.bind(("127.0.0.1", 0)); print(s.getsockname()[1])')
    cat >"$D/sshd_config" <<EOF
Port $PORT
ListenAddress 127.0.0.1
HostKey $D/host_key
PidFile $D/sshd.pid
AuthorizedKeysFile $D/authorized_keys
StrictModes no
UsePAM no
PubkeyAuthentication yes
PasswordAuthentication no
KbdInteractiveAuthentication no
PermitRootLogin prohibit-password
AllowStreamLocalForwarding yes
AllowTcpForwarding local
X11Forwarding no
PermitTTY no
EOF
    rm -f "$D/sshd.log"
    "$SSHD" -D -e -f "$D/sshd_config" 2>"$D/sshd.log" &
    SSHD_PID=$!
    for _ in $(seq 50); do
        grep -q "Server listening on 127.0.0.1 port $PORT" "$D/sshd.log" 2>/dev/null && { started=1; break; }
        kill -0 "$SSHD_PID" 2>/dev/null || break
        sleep 0.1
    done
    [ $started -eq 1 ] && break
    kill "$SSHD_PID" 2>/dev/null
    wait "$SSHD_PID" 2>/dev/null
    SSHD_PID=
done
if [ $started -ne 1 ]; then
    echo "FAIL: sshd did not start:"
    cat "$D/sshd.log"
    exit 1
fi
echo "ok: sshd listening on 127.0.0.1:$PORT as $USER_NAME"

# ---- the tunnel: a local socket in D -> silcd's socket --------------------------------
ssh -N -F /dev/null -o BatchMode=yes -o StrictHostKeyChecking=no -o UserKnownHostsFile="$D/known_hosts" \
    -o ExitOnForwardFailure=yes -o ConnectTimeout=10 -i "$D/client_key" \
    -L "$D/local.sock:$D/silcd.sock" -p "$PORT" "$USER_NAME@127.0.0.1" 2>"$D/ssh.log" &
SSH_PID=$!
for _ in $(seq 100); do
    [ -S "$D/local.sock" ] && break
    kill -0 "$SSH_PID" 2>/dev/null || break
    sleep 0.1
done
if [ ! -S "$D/local.sock" ]; then
    echo "FAIL: the tunnel's local socket did not appear:"
    cat "$D/ssh.log" "$D/sshd.log"
    exit 1
fi
echo "ok: ssh -L $D/local.sock -> $D/silcd.sock"

# ---- a computation through it, against the exact solution ---------------------------
# A = [4 1 0; 1 3 1; 0 1 2], x = [1; -2; 3]: b = A x = [2; -2; 4].  The
# client names only the tunnel's socket; silcd's socket is never opened by it.
out=$(SILC_SERVER=unix:$D/local.sock SILC_TOKEN_FILE=$D/token timeout 60 "$CLI" \
      -e 'A = [4, 1, 0; 1, 3, 1; 0, 1, 2]; b = [2; -2; 4]; x = A \ b; r = norm(x - [1; -2; 3], inf);' \
      --get x --get r 2>&1)
rc=$?
if [ $rc -ne 0 ]; then
    fail "the solve through the tunnel failed (exit $rc): $out"
else
    # --get prints Matrix Market: x's three entries, then r.
    if echo "$out" | awk '
        /^%/ || NF == 0 { next }
        { line[++n] = $0 }
        END {
            # x: "3 1" then three values; r: "1 1" then one value
            if (n != 6 || line[1] != "3 1" || line[5] != "1 1") exit 1
            split("1 -2 3", want, " ")
            for (i = 1; i <= 3; i++) { d = line[i + 1] - want[i]; if (d < 0) d = -d; if (d > 1e-12) exit 1 }
            r = line[6] + 0
            exit !(r <= 1e-12)
        }'; then
        echo "ok: x = A \\ b through the tunnel is [1; -2; 3] to 1e-12"
    else
        fail "wrong result through the tunnel:
$out"
    fi
fi

# Without the token the same tunnel is refused by silcd, not by ssh: the
# tunnel reached silcd itself.
out=$(SILC_SERVER=unix:$D/local.sock SILC_TOKEN=0000000000000000000000000000000000 timeout 60 "$CLI" \
      -e 'x = 1' 2>&1)
case $out in
*"authentication failed: wrong token"*) echo "ok: a wrong token through the tunnel is refused by silcd" ;;
*) fail "a wrong token through the tunnel was not refused by silcd: $out" ;;
esac

[ $fails -eq 0 ] && echo "the SSH tunnel recipe works" || { echo "$fails case(s) failed"; cat "$D/ssh.log"; }
exit $fails
