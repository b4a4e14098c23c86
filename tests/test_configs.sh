#!/bin/sh
# test_configs.sh -- one unchanged program, three configuration files, agreeing
# results.
#
#     sh tests/test_configs.sh path/to/silc SHARED_MATRICES_DIR CONFIG_DIR
#
# The program (a silc script) solves an unsymmetric sparse system (orsirr_1)
# and an SPD one (bcsstk13) with plain `\`.  It runs under SILC_CONFIG set to
# each of CONFIG_DIR/{reference,umfpack,mumps}.conf: the first routes every
# sparse solve to the reference plugin, the second to UMFPACK and CHOLMOD, the
# third names only solve.sparse = mumps, which must govern the SPD system too.
# Checks: `info` names the configured backend, the backward error is <= 1e-12,
# and each solution differs from the reference configuration's by at most
#     ||x - x_ref||_inf / ||x_ref||_inf <= 10 n eps cond
# (cond: the reference's estimate; see test_conformance.c for the constant).
# A configuration whose backend is not built is skipped with a message.
# Prints "N passed, N failed" last and exits 1 on a failure.
SILC=${1:?usage: test_configs.sh path/to/silc SHARED_MATRICES_DIR CONFIG_DIR}
MAT=${2:?missing SHARED_MATRICES_DIR}
CONF=${3:?missing CONFIG_DIR}
T=$(mktemp -d) || exit 1
trap 'rm -rf "$T"' EXIT

passed=0
failed=0
ok() { passed=$((passed + 1)); }
bad() { failed=$((failed + 1)); echo "FAIL: $*" >&2; }

cat >"$T/prog.silc" <<'EOF'
x0 = 1 + rand(cols(A), 1)
b = A * x0
c = S * ones(cols(S), 1)
x = A \ b
y = S \ c
info x
info y
EOF

# field FILE K LABEL: the number after "LABEL:" in the K-th `info` block
field() {
    awk -v k="$2" -v lab="  $3:" 'index($0, "statement:") { blk++ }
        blk == k && index($0, lab) == 1 { print substr($0, length(lab) + 1) + 0; exit }' "$1"
}
# word FILE K LABEL: the text after "LABEL: " in the K-th `info` block
word() {
    awk -v k="$2" -v lab="  $3: " 'index($0, "statement:") { blk++ }
        blk == k && index($0, lab) == 1 { print substr($0, length(lab) + 1); exit }' "$1"
}
# values FILE K: the entries of the K-th Matrix Market block, one per line
values() {
    awk -v k="$2" '/^%%MatrixMarket/ { blk++; size = 0; next } /^%/ { next }
        blk == k && !size { size = 1; next } blk == k { print $1 }' "$1"
}

for cfg in reference umfpack mumps; do
    SILC_CONFIG="$CONF/$cfg.conf" OPENBLAS_NUM_THREADS=1 "$SILC" \
        --put "A=$MAT/orsirr_1.mtx" --put "S=$MAT/bcsstk13.mtx" \
        run "$T/prog.silc" --get x --get y >"$T/$cfg.out" 2>"$T/$cfg.err"
    echo $? >"$T/$cfg.status"
done

if [ "$(cat "$T/reference.status")" -ne 0 ]; then
    bad "reference configuration failed: $(cat "$T/reference.err")"
    echo "$passed passed, $failed failed"
    exit 1
fi
values "$T/reference.out" 1 >"$T/ref.x"
values "$T/reference.out" 2 >"$T/ref.y"

for cfg in reference umfpack mumps; do
    out="$T/$cfg.out"
    case $cfg in
    reference) want_x=reference want_y=reference ;;
    umfpack) want_x=suitesparse.umfpack want_y=suitesparse.cholmod ;;
    mumps) want_x=mumps want_y=mumps ;;
    esac
    if [ "$(cat "$T/$cfg.status")" -ne 0 ]; then
        if grep -q "not installed" "$T/$cfg.err"; then
            echo "skipping $cfg.conf: $(cat "$T/$cfg.err")"
        else
            bad "$cfg.conf: $(cat "$T/$cfg.err")"
        fi
        continue
    fi
    k=1
    for pair in "x:$want_x" "y:$want_y"; do
        name=${pair%%:*}
        want=${pair#*:}
        got=$(word "$out" $k backend)
        if [ "$got" = "$want" ]; then ok; else bad "$cfg.conf: $name solved by '$got', want '$want'"; fi
        be=$(field "$out" $k "backward error")
        if awk -v be="$be" 'BEGIN { exit !(be != "" && be + 0 <= 1e-12) }'; then ok; else
            bad "$cfg.conf: backward error of $name is '$be' > 1e-12"
        fi
        cond=$(field "$T/reference.out" $k "condition estimate")
        values "$out" $k >"$T/got.$name"
        # max |x - x_ref| / max |x_ref| against 10 n eps cond
        if awk -v cond="$cond" -v cfg="$cfg" -v name="$name" '
            NR == FNR { ref[FNR] = $1; n = FNR; next }
            { d = $1 - ref[FNR]; if (d < 0) d = -d; if (d > dmax) dmax = d
              a = ref[FNR]; if (a < 0) a = -a; if (a > amax) amax = a; m = FNR }
            END { bound = 10 * n * 2.220446049250313e-16 * cond
                  rel = dmax / amax
                  printf "%-9s %s: rel. difference from reference %.2e (bound %.2e, n %d, cond %.2e)\n",
                         cfg, name, rel, bound, n, cond
                  exit !(m == n && n > 0 && cond > 0 && rel <= bound) }' \
            "$T/ref.$name" "$T/got.$name"; then ok; else
            bad "$cfg.conf: $name disagrees with the reference configuration"
        fi
        k=$((k + 1))
    done
done
echo "$passed passed, $failed failed"
[ "$failed" -eq 0 ]
