#!/bin/sh
# test_cli.sh -- end-to-end tests of the silc command: -e, run, the REPL on a
# pipe, --put/--get Matrix Market round trips (values compared numerically),
# exit statuses and error text on stderr.
#
#     sh tests/test_cli.sh path/to/silc
#
# Prints "N passed, N failed" last, like the C tests, and exits 1 on a failure.
SILC=${1:?usage: test_cli.sh path/to/silc}
case $SILC in /*) ;; *) SILC=$(pwd)/$SILC ;; esac
T=$(mktemp -d) || exit 1
trap 'rm -rf "$T"' EXIT
cd "$T" || exit 1   # no stray ./silc.conf from the caller's directory

passed=0
failed=0
check() { # check DESCRIPTION COMMAND...: one test case
    desc=$1
    shift
    if "$@"; then
        passed=$((passed + 1))
    else
        failed=$((failed + 1))
        echo "FAIL: $desc (status $st)" >&2
        sed 's/^/  stdout: /' out >&2
        sed 's/^/  stderr: /' err >&2
    fi
}
run() { "$@" >out 2>err; st=$?; }         # stdout -> out, stderr -> err, status -> $st
status_is() { [ "$st" -eq "$1" ]; }
has() { grep -q -F -- "$2" "$1"; }        # has FILE TEXT
starts() { head -n 1 "$1" | grep -q -F -x -- "$2"; }
empty() { [ ! -s "$1" ]; }
# values FILE: the data lines of Matrix Market files (after banner, comments, size)
values() { awk '/^%%MatrixMarket/ { size = 0 } /^%/ { next } !size { size = 1; next } { print }' "$1"; }
# same_numbers FILE "n1 n2 ...": the data lines of FILE are exactly these
# numbers (compared as doubles, so 0.1 == 0.10000000000000001)
same_numbers() {
    values "$1" | awk -v want="$2" 'BEGIN { n = split(want, w, " ") }
        { for (f = 1; f <= NF; f++) { k++; if (k > n || $f + 0 != w[k] + 0) bad = 1 } }
        END { exit (bad || k != n) }'
}

# ---- -e and --get ----------------------------------------------------------------
run "$SILC" -e 'x = 2 + 3;' --get x
check "-e exit status" status_is 0
check "-e --get banner" starts out "%%MatrixMarket matrix array real general"
check "-e --get value" same_numbers out "5"
check "-e nothing on stderr" empty err

run "$SILC" -e 'a = 1; b = 2;' --get b --get a
check "two --get in order" same_numbers out "2 1"

run "$SILC" -e 'x = 1; who'
check "who goes to stdout" has out "x"
check "who: nothing on stderr" empty err

# ---- --put / --get round trips ---------------------------------------------------
cat >a.mtx <<'MTX'
%%MatrixMarket matrix coordinate real general
% a small sparse matrix with awkward values
3 3 4
1 1 0.1
2 1 -2.5
3 2 1e-300
3 3 3.141592653589793
MTX
run "$SILC" --put A=a.mtx -e 'B = A;' --get B
check "sparse round trip status" status_is 0
check "sparse comes back as coordinate" starts out "%%MatrixMarket matrix coordinate real general"
check "sparse round trip values" same_numbers out "1 1 0.1  2 1 -2.5  3 2 1e-300  3 3 3.141592653589793"

cat >d.mtx <<'MTX'
%%MatrixMarket matrix array real general
2 2
1
2
3
4.5
MTX
run "$SILC" --put=D=d.mtx -e 'E = 2 * D;' --get=E
check "dense put, compute, get" same_numbers out "2 4 6 9"

# ---- run FILE: control flow across lines -------------------------------------------
cat >loop.silc <<'SILC'
# sum 1..5 with a loop
i = 0;
s = 0;
while (i < 5) {
  i = i + 1;
  s = s + i;
}
SILC
run "$SILC" run loop.silc --get s
check "run FILE with while" same_numbers out "15"

# ---- display: as Octave shows values -------------------------------------------------
run "$SILC" -e 'x = 2 + 3'
check "-e shows an assignment without ';'" [ "$(cat out)" = "x = 5" ]
run "$SILC" -e 'x = 2 + 3;'
check "';' keeps it quiet" empty out
run "$SILC" -e 'A = [1 2; 3 4]'
check "a matrix as Octave shows it" [ "$(cat out)" = "$(printf 'A =\n\n   1   2\n   3   4\n')" ]
run "$SILC" -e 'x = 1:3; x * 2'
check "an expression shows as ans" [ "$(tr '\n' '|' <out)" = "ans =||   2   4   6||" ]
run "$SILC" -e 'p = pi; format long; p, format short; p'
check "format long / short" [ "$(tr '\n' '|' <out)" = "p = 3.141592653589793|p = 3.1416|" ]
run "$SILC" -e 'disp(0.5); B = rand(500, 300);  B'
check "disp shows the value alone" [ "$(head -1 out)" = "0.5000" ]
check "a large value is summarised" has out "B = 500x300 dense, nnz 150000 (100%); the top-left corner:"
check "the summary is short" [ "$(wc -l <out)" -lt 12 ]
printf 'for i = 1:3\n  i\nend\n' >for.silc
run "$SILC" run for.silc
check "run FILE shows values in a for loop" [ "$(tr '\n' ' ' <out)" = "i = 1 i = 2 i = 3 " ]

printf 'k = 0;\nfor i = 1:3\n  k = k + i;\nend\nk\nif k > 5\n  big = 1\nend\n' >in
run "$SILC" <in
check "REPL waits for the end of a block" [ "$(tr '\n' ' ' <out)" = "k = 6 big = 1 " ]

# ---- settings: discoverable ----------------------------------------------------------
printf '[solve]\nrefine = 2\n' >s.conf
run "$SILC" --config s.conf -e 'set'
check "set lists a default with its origin" grep -q '^solve.verify  *= auto  (default)$' out
if [ -z "${SILC_SERVER:-}" ]; then   # remote, the server's configuration applies
    check "set lists a file setting with file:line" grep -q '^solve.refine  *= 2  (s.conf:2)$' out
fi
check "set lists the session's own setting" grep -q '^core.display  *= on  (session)$' out
check "set lists plugin options" grep -q '^lapack.precision  *= double  (default)$' out
run "$SILC" -e 'set solve.verify'
check "set KEY shows the value in force" grep -q '^solve.verify  *= auto  (default)$' out
run "$SILC" -e 'set solve.sparse = reference'
check "an unknown key names the real one" has err "did you mean 'dispatch.solve.sparse'?"
run "$SILC" -e 'help solve.verify'
check "help KEY describes it" has out "solve.verify: auto, off or a bound"
run "$SILC" -e 'help lapack'
check "help PLUGIN lists its options with defaults" has out "lapack.precision [double] (text): "
run "$SILC" --complete lapack.pre
check "--complete covers plugin options" [ "$(cat out)" = "lapack.precision" ]
# Every plugin: `help` names it, `help NAME` shows it with each of its
# options, and Tab offers exactly those options after `NAME.` (issue 29).
run "$SILC" -e 'help'
plugins=$(sed -n '/^plugins (/{n;p;}' out)
check "help lists the plugins (reference, lapack among them)" \
    sh -c 'echo " $1 " | grep -q " reference " && echo " $1 " | grep -q " lapack "' - "$plugins"
for p in $plugins; do
    run "$SILC" -e "help $p"
    check "help $p names it" sh -c 'head -n 1 out | grep -q -F "plugin $1 "' - "$p"
    sed -n "s/^    \($p\.[^ ]*\) \[.*/\1/p" out | sort >help_keys
    check "help $p: options, or 'no options'" sh -c '[ -s help_keys ] || grep -q "^  no options$" out'
    run "$SILC" --complete "$p."
    sort out >complete_keys
    check "--complete $p. offers the options help $p lists" cmp -s help_keys complete_keys
done
run "$SILC" --complete refer
check "--complete offers plugin names" [ "$(cat out)" = "reference" ]
run "$SILC" --complete solve.ver
check "--complete covers keys" [ "$(cat out)" = "solve.verify" ]
run "$SILC" -e 'alpha = 1; alpah'
check "did-you-mean takes a transposition" has err "undefined name 'alpah' (did you mean 'alpha'?)"

# ---- --profile: per statement and per plugin call, as PETSc's -log_view -------------
run "$SILC" --profile -e 'A = [4 1; 1 3]; b = [1; 2]; for i = 1:3
  x = A \ b;
end'
check "--profile status" status_is 0
check "--profile: statements" has err "for i = 1:3 ..."
check "--profile: three solves counted" grep -q '^  solve: [^ ]* *3 ' err
check "--profile: the table header" has err "bytes in"
# x is 2 doubles, 16 bytes, each time; A's factorization is made once and
# reused by the two later solves.
check "--profile: bytes out and reused factorizations" grep -q '^  solve: [^ ]* *3 .* 48 *2$' err

run "$SILC" run no-such-file.silc
check "run missing file status" status_is 1
check "run missing file message" has err "silc: cannot open 'no-such-file.silc'"

# ---- the REPL on a pipe (no readline, no prompts) ------------------------------------
printf 'a = (1 +\n2);\nb = a * 2;\n' >in
run "$SILC" --get b <in
check "REPL continues unclosed brackets" same_numbers out "6"
printf 'y = nosuch\nz = 7\nwho\n' >in
run "$SILC" <in
check "REPL goes on after an error" has out "z"
check "REPL reports the error" has err "silc: "
check "REPL on a pipe fails if a statement failed" status_is 1

# Nesting beyond the language's limit (silc.h: SILC_MAX_NESTING) is refused
# with a message, never a crash: 100000 '(' in a script, and on the REPL a line
# that opens more brackets than any text may hold runs at once instead of
# waiting for lines that could never make it valid.
awk 'BEGIN { s = "y = "; for (i = 0; i < 100000; i++) s = s "("; s = s "1";
             for (i = 0; i < 100000; i++) s = s ")"; print s }' >deep.silc
run "$SILC" run deep.silc
check "100000 nested parentheses: status 1" status_is 1
check "100000 nested parentheses: message" has err "silc: 1:261: expression nested deeper than 256 levels"
awk 'BEGIN { s = "y = 1"; for (i = 0; i < 100000; i++) s = s "+1"; print s }' >long.silc
run "$SILC" run long.silc
check "100000-term sum: message" has err "expression too long: more than 1024 operations in a chain"
awk 'BEGIN { s = "y = "; for (i = 0; i < 300; i++) s = s "("; print s; print "z = 5"; print "who" }' >in
run "$SILC" <in
check "REPL runs a line nested past the limit at once" has err "expression nested deeper than 256 levels"
check "REPL goes on after it" grep -q "^ *z " out

# ---- errors --------------------------------------------------------------------------
run "$SILC" -e 'x = (1 + 2'
check "syntax error status" status_is 1
check "syntax error text" has err "expected ')'"
check "syntax error prefix" grep -q '^silc: ' err
check "syntax error: nothing on stdout" empty out

run "$SILC" -e 'a = 1; b = u + 1' --get a
check "undefined name status" status_is 1
check "undefined name text" has err "undefined name 'u'"

run "$SILC" -e 'x = 1' --get nosuch
check "--get of an unknown name fails" status_is 1
check "--get error names the option" has err "silc: --get nosuch"

run "$SILC" --put A=missing.mtx -e 'x = 1'
check "--put of a missing file fails" status_is 1
check "--put error names the option" has err "silc: --put A=missing.mtx"

# Values Matrix Market does not allow in a real field (overflow to inf, inf,
# nan) are refused, naming line and column, unless the user asks.
printf '%%%%MatrixMarket matrix coordinate real general\n2 1 2\n1 1 1e400\n2 1 -inf\n' >inf.mtx
run "$SILC" --put A=inf.mtx -e 'x = 1'
check "--put of an overflowing value: status 1" status_is 1
check "--put of an overflowing value" has err "inf.mtx:3:5: value '1e400' overflows the doubles"
run "$SILC" --put-allow-nonfinite --put A=inf.mtx -e 'B = A;' --get B
check "--put-allow-nonfinite: status 0" status_is 0
check "--put-allow-nonfinite: 1e400 read as inf" grep -q -x '1 1 inf' out
check "--put-allow-nonfinite: -inf kept" grep -q -x '2 1 -inf' out

# A client's time values are 0 (none) or 1 ms to a year (1e-7 was rounded up
# to 1 ms without a word, 1e30 refused without naming the maximum).
if [ -n "${SILC_SERVER:-}" ]; then
    run env SILC_IO_TIMEOUT=1e30 "$SILC" -e 'x = 1'
    check "SILC_IO_TIMEOUT=1e30" has err "SILC_IO_TIMEOUT = '1e30': expected 0 (no timeout) or seconds from 0.001 to 31536000"
    run env SILC_EXEC_TIMEOUT=0.0000001 "$SILC" -e 'x = 1'
    check "SILC_EXEC_TIMEOUT=1e-7" has err "SILC_EXEC_TIMEOUT = '0.0000001': expected 0 (no timeout) or seconds"
    run env SILC_EXEC_TIMEOUT=0 "$SILC" -e 'x = 1;' --get x
    check "SILC_EXEC_TIMEOUT=0 is no timeout" same_numbers out "1"
fi

# ---- usage -----------------------------------------------------------------------------
run "$SILC" --bogus
check "unknown option is a usage error" status_is 2
check "unknown option message" has err "silc: unknown option '--bogus'"
run "$SILC" --put nonsense
check "--put without NAME=FILE" status_is 2
run "$SILC" run
check "run without a file" status_is 2
run "$SILC" -e 'x = 1' run loop.silc
check "-e and run together" status_is 2
run "$SILC" --help
check "--help status" status_is 0
check "--help text" has out "usage: silc"
run "$SILC" --version
check "--version" grep -q '^silc [0-9]' out

# Completion (what Tab completes in the REPL): bound names, statements and
# built-ins, the REPL's own commands; help and help NAME.
run "$SILC" -e 'alpha = 1; alps = [1; 2]; beta = 3;' --complete al
check "--complete: bound names" [ "$(cat out)" = "$(printf 'alpha\nalps')" ]
run "$SILC" -e 'x = 1;' --complete spa
check "--complete: built-ins" [ "$(cat out)" = "sparse" ]
run "$SILC" --complete e
check "--complete: keywords, built-ins and commands" [ "$(tr '\n' ' ' <out)" = "elseif else end explain eye exp eps exit " ]
run "$SILC" -e 'help solve'
check "help solve" has out 'solve(A, b, "options")'
run "$SILC" -e 'help sparce'
check "help of an unknown word" has err "no statement or built-in 'sparce' (did you mean 'sparse'?)"

# Inputs that are not plain files: a FIFO with no writer reads as empty (it
# hung), a device is refused at its first NUL byte, a script over 64 MiB is
# refused before it is held (/dev/zero reached 2.1 GB); a pipe with a writer
# still works.  `timeout` turns a hang into a failure, not a stuck test.
mkfifo fifo
run timeout 10 "$SILC" --put A=fifo -e 'x = 1'
check "--put of a fifo with no writer" has err "--put A=fifo: fifo:1: empty file (expected a %%MatrixMarket banner)"
mkdir adir
run "$SILC" --put A=adir -e 'x = 1'
check "--put of a directory" has err "--put A=adir: adir:1: cannot read: Is a directory"
run timeout 10 "$SILC" run fifo
check "run a fifo with no writer: nothing to run" status_is 0
run timeout 10 "$SILC" run /dev/zero
check "run /dev/zero" has err "'/dev/zero' is not a text file (it contains NUL bytes)"
head -c 68000000 /dev/zero | tr '\0' '\n' >big.silc
run timeout 20 "$SILC" run big.silc
check "a script over 64 MiB" has err "'big.silc' is over 64 MiB: not a script silc runs"
rm -f big.silc
# Embedded, `load` and the configuration read the caller's files the same
# way (a silcd session loads only beneath its --data-dir, and the server's
# configuration applies): a FIFO or a device is refused before any read, a
# directory as the configuration too (SILC_CONFIG=DIR was silently accepted).
if [ -z "${SILC_SERVER:-}" ]; then
    run timeout 10 "$SILC" -e 'load "fifo"'
    check "load of a fifo with no writer" has err "silc: load: 'fifo' is not a regular file"
    run timeout 10 "$SILC" -e 'load "/dev/zero"'
    check "load of a device" has err "silc: load: '/dev/zero' is not a regular file"
    mkdir confdir
    run env SILC_CONFIG=confdir timeout 10 "$SILC" -e 'x = 1'
    check "SILC_CONFIG a directory: status 1" status_is 1
    check "SILC_CONFIG a directory" has err "silc: config file confdir is not a regular file"
    run timeout 10 "$SILC" --config fifo -e 'x = 1'
    check "--config a fifo" has err "silc: config file fifo is not a regular file"
fi
printf 'x = 6 * 7\n' | (run timeout 10 "$SILC" run - --get x; same_numbers out "42")
check "run - from a pipe" [ $? -eq 0 ]

echo "$passed passed, $failed failed"
[ "$failed" -eq 0 ]
