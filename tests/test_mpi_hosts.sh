#!/bin/sh
# test_mpi_hosts.sh -- SILC's MPI modes across two (simulated) hosts: two
# network namespaces joined by a veth pair, MPI between them over TCP only
# (`--mca btl tcp,self`: no shared-memory transport, and the namespaces share
# no loopback), Open MPI's daemon on the second "host" started through an
# rsh agent that enters its namespace, as ssh would log into a real node.
#
#  1. The SPMD example (examples/diffusion2d_mpi, one rank per host) prints
#     the embedded example's summary digit for digit.
#  2. `silcd --mpi` with rank 0 on host 1 and rank 1 on host 2, driven by
#     `silc` over silcd's Unix socket: a 40x40-grid Laplacian (1600 rows,
#     split in two row blocks) times a vector moves exactly the predicted
#     2 k (P - 1) = 80 ghost values (640 bytes) and gives the embedded
#     product bit for bit; A \ b agrees with the embedded solve.
#
# Each rank's namespace is checked (`ip netns identify`), so the test cannot
# pass on one host by accident.  Creating namespaces needs root (or
# CAP_NET_ADMIN) and iproute2: without them the test says why and exits 77,
# which ctest reports as skipped, never as passed.
#
#     sh tests/test_mpi_hosts.sh MPIRUN SILCD SILC DIFFUSION2D DIFFUSION2D_MPI OUTDIR
set -u
MPIRUN=$1 SILCD=$2 SILC=$3 SEQ=$4 PAR=$5 OUT=$6
mkdir -p "$OUT" || exit 1
OUT=$(cd "$OUT" && pwd)
H1=silc_h1_$$ H2=silc_h2_$$ V1=silcv1_$$ V2=silcv2_$$
A1=10.77.0.1 A2=10.77.0.2 NET=10.77.0.0/24
SOCK=$OUT/silcd.sock
server=

skip() { echo "SKIP: $*"; exit 77; }
cleanup() {
    [ -n "$server" ] && kill "$server" 2>/dev/null && wait "$server" 2>/dev/null
    ip netns del "$H1" 2>/dev/null
    ip netns del "$H2" 2>/dev/null
}
trap cleanup EXIT
trap 'exit 1' INT TERM

command -v ip >/dev/null 2>&1 || skip "iproute2's 'ip' is not installed (Debian: iproute2)"
ip netns add "$H1" 2>"$OUT/netns.err" ||
    skip "cannot create a network namespace (needs root or CAP_NET_ADMIN): $(cat "$OUT/netns.err")"
ip netns add "$H2" &&
ip link add "$V1" type veth peer name "$V2" &&
ip link set "$V1" netns "$H1" && ip link set "$V2" netns "$H2" &&
ip -n "$H1" addr add $A1/24 dev "$V1" && ip -n "$H2" addr add $A2/24 dev "$V2" &&
ip -n "$H1" link set "$V1" up && ip -n "$H2" link set "$V2" up &&
ip -n "$H1" link set lo up && ip -n "$H2" link set lo up ||
    { echo "FAIL: could not wire the two namespaces"; exit 1; }

# The rsh agent: mpirun calls it as `agent HOST COMMAND...` to start its
# daemon on HOST; here it enters HOST's namespace instead of logging in.
cat >"$OUT/agent.sh" <<EOF
#!/bin/sh
host=\$1; shift
case \$host in $A2) ns=$H2 ;; *) ns=$H1 ;; esac
echo "\$host \$ns" >>"$OUT/agent.log"
exec ip netns exec \$ns sh -c "\$*"
EOF
chmod +x "$OUT/agent.sh"
rm -f "$OUT/agent.log"
# Everything mpirun needs to treat the namespaces as two hosts on one
# network, ports pinned as docs/distributed.md tells a firewalled cluster;
# `timeout` turns a hang into a failure.
on_two_hosts() {
    timeout 120 ip netns exec "$H1" "$MPIRUN" --host $A1:1,$A2:1 -np 2 --mca plm_rsh_agent "$OUT/agent.sh" \
        --mca btl tcp,self --mca btl_tcp_if_include $NET --mca oob_tcp_if_include $NET \
        --mca btl_tcp_port_min_v4 40000 --mca btl_tcp_port_range_v4 100 \
        --mca oob_tcp_dynamic_ipv4_ports 40100-40199 \
        -x OPENBLAS_NUM_THREADS -x OMP_NUM_THREADS "$@"
}
export OPENBLAS_NUM_THREADS=${OPENBLAS_NUM_THREADS:-1} OMP_NUM_THREADS=${OMP_NUM_THREADS:-1}
passed=0 failed=0
ok() { passed=$((passed + 1)); }
bad() { echo "FAIL: $*"; failed=$((failed + 1)); }

# 1. SPMD across the hosts.
want=$("$SEQ" -n 40 -s 20 -o "$OUT/seq.pgm" | grep -E '^(steps|heat)' | sed 's/time=[^ ]* //')
got=$(on_two_hosts "$PAR" -n 40 -s 20 -o "$OUT/hosts.pgm" 2>"$OUT/spmd.err" | grep -E '^(steps|heat)' |
      sed 's/time=[^ ]* //')
if [ -n "$want" ] && [ "$got" = "$want" ]; then ok; else
    bad "SPMD on two hosts printed"; echo "$got"; echo "embedded printed"; echo "$want"; cat "$OUT/spmd.err"
fi
grep -q "^$A2 $H2\$" "$OUT/agent.log" 2>/dev/null && ok ||
    bad "mpirun never started a daemon in the second host's namespace"

# 2. silcd --mpi across the hosts.  The matrix: the 5-point Laplacian of a
# k x k grid, k = 40 (1600 rows: split, as --dist-min-rows is 1000).
k=40
awk -v k=$k 'BEGIN {
    n = k * k; nz = 0
    for (i = 0; i < k; i++) for (j = 0; j < k; j++) nz += 1 + (i > 0) + (i < k - 1) + (j > 0) + (j < k - 1)
    print "%%MatrixMarket matrix coordinate real general"; print n, n, nz
    for (i = 0; i < k; i++) for (j = 0; j < k; j++) {
        r = i * k + j + 1; print r, r, 4
        if (i > 0) print r, r - k, -1; if (i < k - 1) print r, r + k, -1
        if (j > 0) print r, r - 1, -1; if (j < k - 1) print r, r + 1, -1
    } }' >"$OUT/A.mtx"
awk -v n=$((k * k)) 'BEGIN { print "%%MatrixMarket matrix array real general"; print n, 1
    for (r = 0; r < n; r++) print (r % 7) + 1 }' >"$OUT/x.mtx"
STMT='y = A * x; u = A \ y;'   # ';': silc -e shows what a statement without one binds
SILC_SERVER= timeout 60 "$SILC" --put A="$OUT/A.mtx" --put x="$OUT/x.mtx" -e "$STMT" --get y --get u \
    >"$OUT/embedded.mtx" 2>"$OUT/embedded.err" || bad "embedded run: $(cat "$OUT/embedded.err")"

rm -f "$SOCK" "$OUT/ready"
on_two_hosts "$SILCD" --mpi --listen "unix:$SOCK" --ready-file "$OUT/ready" >"$OUT/silcd.log" 2>&1 &
server=$!
i=0
while [ ! -s "$OUT/ready" ] && [ $i -lt 300 ] && kill -0 $server 2>/dev/null; do sleep 0.1; i=$((i + 1)); done
if [ ! -s "$OUT/ready" ]; then
    bad "silcd --mpi on two hosts did not start:"; cat "$OUT/silcd.log"
else
    # Where the ranks run: one silcd in each namespace.
    in1=$(ip netns pids "$H1" | while read p; do grep -l silcd /proc/$p/cmdline 2>/dev/null; done | wc -l)
    in2=$(ip netns pids "$H2" | while read p; do grep -l silcd /proc/$p/cmdline 2>/dev/null; done | wc -l)
    [ "$in1" -ge 1 ] && [ "$in2" -ge 1 ] && ok ||
        bad "silcd's ranks are not one per host ($in1 in $H1, $in2 in $H2)"
    SILC_SERVER="unix:$SOCK" timeout 60 "$SILC" --put A="$OUT/A.mtx" --put x="$OUT/x.mtx" \
        -e "$STMT
info y" --get y --get u >"$OUT/hosts.out" 2>"$OUT/hosts.err" || bad "client of silcd on two hosts: $(cat "$OUT/hosts.err")"
    grep -q "ranks: 2; moved between ranks by the statement: 0 bytes of matrices, $((2 * k * 8)) bytes of vectors" \
        "$OUT/hosts.out" && ok || { bad "y = A * x did not move the predicted $((2 * k)) ghost values:"; cat "$OUT/hosts.out"; }
    # The values: y bit for bit (each row sums the same terms in the same
    # order), u to a relative 1e-12 of the embedded solve (cond(A) ~ 1e3).
    awk -v rows=$((k * k)) 'FNR == 1 { f++ } /^%/ || NF != 1 { next } { v[f, ++c[f]] = $1 }
         END { n = c[1]; if (n != c[2] || n != 2 * rows) { print "counts", c[1], c[2]; exit 1 }
               for (i = 1; i <= n; i++) {
                   d = v[1, i] - v[2, i]; if (d < 0) d = -d; s = v[1, i] < 0 ? -v[1, i] : v[1, i]
                   if (i <= rows && d != 0) { print "y differs at", i, v[1, i], v[2, i]; exit 1 }
                   if (i > rows && d > 1e-12 * (s > 1 ? s : 1)) { print "u differs at", i - rows, v[1, i], v[2, i]; exit 1 }
               } }' "$OUT/embedded.mtx" "$OUT/hosts.out" && ok || bad "silcd on two hosts and embedded disagree"
fi

echo "$passed passed, $failed failed"
[ $failed -eq 0 ]
