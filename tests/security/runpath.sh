#!/bin/sh
# runpath.sh -- what the dynamic loader may load into SILC's programs.  An
# empty RUNPATH entry (CMake's build tree used to end every installed
# target's RUNPATH with ':') or a relative one makes the loader search the
# current directory, or one below it, of whoever runs the program: a library
# planted there, named like one the program needs, would run inside it.
#   1. every ELF program and shared object under BUILD_DIR: each RUNPATH or
#      RPATH entry is an absolute path or starts with $ORIGIN;
#   2. a scratch directory holds the canary library (its constructor writes
#      $SILC_CANARY_MARKER) under the name of every library that silc, silcd,
#      libsilc and every plugin need; run from there, the loader resolves
#      none of them there (LD_TRACE_LOADED_OBJECTS) and neither silc -e, a
#      text that opens every plugin, nor silcd --version runs the canary.
#      Controls: with LD_LIBRARY_PATH set to the scratch directory the loader
#      does resolve them there, and the canary preloaded does write its marker.
#
#     sh tests/security/runpath.sh BUILD_DIR CANARY_LIB SCRATCH_DIR SILC SILCD
set -u
BUILD=$1 CANARY=$2 SCRATCH=$3 SILC=$4 SILCD=$5
failed=0
fail() { echo "runpath: FAIL: $*"; failed=1; }

# ---- 1. the RUNPATH of every ELF file in the build tree ---------------------
rm -rf "$SCRATCH"
mkdir -p "$SCRATCH" || exit 1
# (not readme-test/: test_readme's scratch copy of the repository, where
# the README's example program is compiled by the README's own command line)
find "$BUILD" \( -name CMakeFiles -o -path "$BUILD/readme-test" \) -prune -o -type f \( -name '*.so' -o -name '*.so.*' -o -perm -u+x \) -print \
  >"$SCRATCH/files"
# One readelf for all (a process per file is slow on a loaded machine); a
# file that is not ELF (a script) prints its name and an error only.
xargs readelf -d <"$SCRATCH/files" 2>/dev/null | awk -v silc="$SILC" -v count="$SCRATCH/count" '
  /^File: / { file = substr($0, 7); next }
  /^Dynamic section/ { elf++; if (file == silc) saw_silc = 1; next }
  /\((RUNPATH|RPATH)\)/ {
    tag = $0 ~ /RUNPATH/ ? "RUNPATH" : "RPATH"
    value = $0; sub(/^[^[]*\[/, "", value); sub(/\][[:space:]]*$/, "", value)
    n = split(value, entry, ":")
    if (value == "") { n = 1; entry[1] = "" }
    for (i = 1; i <= n; i++) {
      if (entry[i] == "")
        print "runpath: FAIL: " file ": " tag " [" value "] has an empty entry (the current directory)"
      else if (entry[i] !~ /^\// && entry[i] !~ /^\$(ORIGIN|\{ORIGIN\})(\/|$)/)
        print "runpath: FAIL: " file ": " tag " [" value "] has the relative entry " entry[i]
    }
  }
  END { print elf + 0, saw_silc + 0 > count }' >"$SCRATCH/runpaths"
if [ -s "$SCRATCH/runpaths" ]; then
  cat "$SCRATCH/runpaths"
  failed=1
fi
read -r checked saw_silc <"$SCRATCH/count"
[ "$saw_silc" = 1 ] || fail "the scan of $BUILD did not reach $SILC"
echo "runpath: $checked dynamic ELF files under $BUILD: $(grep -c FAIL "$SCRATCH/runpaths") bad RUNPATH entries"

# ---- 2. libraries planted in the current directory --------------------------
needed() { readelf -d "$1" | sed -n 's/.*(NEEDED) *Shared library: \[\(.*\)\]$/\1/p'; }
libsilc=$(LD_TRACE_LOADED_OBJECTS=1 "$SILC" </dev/null | sed -n 's/^[[:space:]]*libsilc\.so\.[0-9]* => \([^ ]*\) .*/\1/p')
[ -n "$libsilc" ] || fail "$SILC does not load a libsilc"
plants=$(for f in "$SILC" "$SILCD" $libsilc $(grep '/plugins/.*\.so$' "$SCRATCH/files"); do needed "$f"; done |
  grep -v '^libc\.so\|^ld-linux' | sort -u)
for name in $plants; do cp "$CANARY" "$SCRATCH/$name" || exit 1; done
echo "runpath: planted as $(echo $plants)"
# the libraries PROGRAM resolves in $SCRATCH or by a relative path, run from there
resolved_there() {
  (cd "$SCRATCH" && env "$@" LD_TRACE_LOADED_OBJECTS=1 "$prog" </dev/null) |
    awk -v dir="$SCRATCH/" '
      # "NAME => PATH (ADDRESS)", or "PATH (ADDRESS)" when the name was the
      # path: one found through an empty entry shows as a bare relative name
      { path = $2 == "=>" ? $3 : $1 }
      path == "not" || path ~ /^linux-(vdso|gate)/ { next }
      substr(path, 1, 1) != "/" || index(path, dir) == 1 { print $1 " => " path }'
}
for prog in "$SILC" "$SILCD"; do
  there=$(resolved_there LD_LIBRARY_PATH=)
  [ -z "$there" ] || fail "$prog, run in $SCRATCH, loads from there: $(echo $there)"
  there=$(resolved_there LD_LIBRARY_PATH="$SCRATCH")
  [ -n "$there" ] || fail "control: with LD_LIBRARY_PATH=$SCRATCH, $prog loads nothing from there (the planted names are wrong)"
done

marker=$SCRATCH/canary-ran
out=$(cd "$SCRATCH" && SILC_CANARY_MARKER=$marker "$SILC" -e 'x = 1' 2>&1)
[ "$out" = "x = 1" ] || fail "silc -e 'x = 1' in $SCRATCH printed: $out"
# A misspelt backend is answered with every backend's name: every plugin is opened.
out=$(cd "$SCRATCH" && SILC_CANARY_MARKER=$marker "$SILC" -e 'set dispatch.solve.sparse = lapak' 2>&1)
echo "$out" | grep -q "backend" || fail "the misspelt backend in $SCRATCH: $out"
out=$(cd "$SCRATCH" && SILC_CANARY_MARKER=$marker "$SILCD" --version 2>&1) || fail "silcd --version in $SCRATCH: $out"
[ ! -e "$marker" ] || fail "a planted library ran in silc or silcd: $(cat "$marker")"
rm -f "$marker"
# (from /: run in the scratch directory, a build that loads from there would
# fail before the preloaded canary's constructor)
(cd / && env LD_PRELOAD="$CANARY" SILC_CANARY_MARKER="$marker" \
  ASAN_OPTIONS="${ASAN_OPTIONS:+$ASAN_OPTIONS:}verify_asan_link_order=0" "$SILC" -e 'x = 1;') >/dev/null 2>&1
[ -e "$marker" ] || fail "control: the canary preloaded into silc left no marker"

if [ $failed = 0 ]; then
  echo "runpath: ok: no empty or relative RUNPATH entry; nothing planted in the current directory was loaded"
  rm -rf "$SCRATCH"
fi
exit $failed
