#!/bin/sh
# startup.sh -- the start-up of `silc -e 'x = 1;'` (a text that solves and
# saves nothing) against an empty C program, measured in one run with
# `perf stat -r N`: wall time and CPU time (task-clock: on a shared, loaded
# machine the wall time is mostly waiting for a core), with the ratio of
# each to the empty program's.  Reference rows show what the dynamic
# libraries alone cost: an empty program linked to libhdf5 (what libsilc
# linked before save / load moved into libsilc_h5.so) and one linked to the
# libraries silc links now.  An optional second silc (an older build, with
# the directory of its libsilc) is measured in the same run.
#
#     sh bench/startup.sh BUILD_DIR [OLD_SILC OLD_LIBSILC_DIR] [N]
#
# Needs perf and a C compiler; HDF5's row needs pkg-config hdf5-serial.
set -eu
BUILD=$1
OLD=${2:-} OLD_LIB=${3:-} N=${4:-30}
SILC=$BUILD/tools/silc
TMP=$(mktemp -d /tmp/silc-startup.XXXXXX)
trap 'rm -rf "$TMP"' EXIT
printf 'int main(void) { return 0; }\n' >"$TMP/empty.c"
cc -O2 "$TMP/empty.c" -o "$TMP/empty"
have_h5=0
if pkg-config --exists hdf5-serial; then
  # shellcheck disable=SC2046 # pkg-config's output is meant to be split
  cc -O2 "$TMP/empty.c" -o "$TMP/empty_hdf5" -Wl,--no-as-needed $(pkg-config --libs hdf5-serial) && have_h5=1
fi
# the libraries silc itself links (ldd's names, the loader's paths)
libs=$(ldd "$SILC" | awk '$3 ~ /^\// && $1 !~ /^(libc|ld-linux)/ {print $3}')
rpath=$(for l in $libs; do dirname "$l"; done | sort -u | tr '\n' ':')
cc -O2 "$TMP/empty.c" -o "$TMP/empty_silc_libs" -Wl,--no-as-needed $libs -Wl,-rpath,"$rpath"

# measure LABEL ENV-ASSIGNMENT-OR-- COMMAND...: prints "label|wall_ms|cpu_ms"
# (perf's mean over N runs of the elapsed time and of the task-clock)
measure() {
  label=$1 envset=$2
  shift 2
  if [ "$envset" = - ]; then
    perf stat -e task-clock -r "$N" "$@" >/dev/null 2>"$TMP/stat" </dev/null
  else
    env "$envset" perf stat -e task-clock -r "$N" "$@" >/dev/null 2>"$TMP/stat" </dev/null
  fi
  cpu=$(awk '/msec task-clock/ {print $1}' "$TMP/stat")
  wall=$(awk '/seconds time elapsed/ {printf "%.2f", $1 * 1000}' "$TMP/stat")
  echo "$label|$wall|$cpu"
}

{
  measure "empty C program" - "$TMP/empty"
  [ $have_h5 = 1 ] && measure "empty C program linked to libhdf5" - "$TMP/empty_hdf5"
  measure "empty C program linked to silc's libraries" - "$TMP/empty_silc_libs"
  [ -n "$OLD" ] && measure "silc -e 'x = 1;' (old build)" "LD_LIBRARY_PATH=$OLD_LIB" "$OLD" -e 'x = 1;'
  measure "silc -e 'x = 1;'" - "$SILC" -e 'x = 1;'
} >"$TMP/rows"
base_wall=$(awk -F'|' 'NR == 1 {print $2}' "$TMP/rows")
base_cpu=$(awk -F'|' 'NR == 1 {print $3}' "$TMP/rows")
echo "start-up, $N runs each ($(nproc) cores, load average $(cut -d' ' -f1 /proc/loadavg))"
printf '%-46s %9s %7s %9s %7s\n' "program" "wall ms" "ratio" "CPU ms" "ratio"
awk -F'|' -v bw="$base_wall" -v bc="$base_cpu" \
  '{printf "%-46s %9.1f %6.2fx %9.1f %6.2fx\n", $1, $2, $2 / bw, $3, $3 / bc}' "$TMP/rows"
