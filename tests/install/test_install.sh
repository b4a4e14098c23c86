#!/bin/sh
# test_install.sh -- SILC as a user installs it, and as a packager stages it:
# `cmake --install` into a DESTDIR staging tree, the prefix then moved
# elsewhere (as a package manager or a user's `mv` would), and everything run
# from where it landed:
#   - the installed `silc` and `silcd` with no environment at all (env -i):
#     they find libsilc through their relative RUNPATH and the plugins beside
#     it; silc solves a system, silcd serves one client call on a Unix socket;
#   - an out-of-tree program (tests/install) built with find_package(SILC 1.0)
#     -- C, Fortran when there is a compiler, MPI with SILC::silc_mpi when
#     SILC has it -- and the C and MPI programs again with pkg-config;
#   - the Python package, finding libsilc relative to itself;
#   - the Java client's jar under share/java.
#
#     sh tests/install/test_install.sh BUILD_DIR SOURCE_DIR [MPIEXEC]
set -u
BUILD=$1 SRC=$2 MPIEXEC=${3:-}
TOP=$(mktemp -d /tmp/silc-install-test.XXXXXX) || exit 1
SILCD_PID=
cleanup() {
  [ -n "$SILCD_PID" ] && kill "$SILCD_PID" 2>/dev/null
  rm -rf "$TOP"
}
trap cleanup EXIT
unset SILC_PLUGIN_PATH SILC_CONFIG SILC_SERVER SILC_LIBRARY
fail() { echo "test_install: FAIL: $*"; exit 1; }
# The prefix the build is installed for is a name that does not exist: were
# anything to record it, it would not be found after the move.
STAGED_PREFIX=/silc-install-test-never-there
DESTDIR="$TOP/stage" cmake --install "$BUILD" --prefix "$STAGED_PREFIX" >"$TOP/install.log" 2>&1 ||
  { cat "$TOP/install.log"; fail "cmake --install into DESTDIR"; }
mv "$TOP/stage$STAGED_PREFIX" "$TOP/moved" || fail "moving the staged prefix"
PREFIX=$TOP/moved
echo "test_install: installed with DESTDIR=$TOP/stage --prefix $STAGED_PREFIX, moved to $PREFIX"

# ---- silc and silcd from the moved prefix, with no environment ----------
for exe in silc silcd; do
  [ -x "$PREFIX/bin/$exe" ] || fail "no $PREFIX/bin/$exe"
  runpath=$(readelf -d "$PREFIX/bin/$exe" | sed -n 's/.*(RUNPATH).*\[\(.*\)\]/\1/p')
  case "$runpath" in
    *"$BUILD"*|*"$STAGED_PREFIX"*) fail "$exe's RUNPATH names an absolute path: $runpath" ;;
  esac
done
runpath=$(readelf -d "$PREFIX/bin/silc" | sed -n 's/.*(RUNPATH).*\[\(.*\)\]/\1/p')
case "$runpath" in '$ORIGIN/'*) ;; *) fail "silc's RUNPATH is '$runpath', not relative to \$ORIGIN" ;; esac
# The loader resolves libsilc to the moved prefix's (not the build tree's).
env -i LD_TRACE_LOADED_OBJECTS=1 "$PREFIX/bin/silc" | grep -q "libsilc.so.1 => $PREFIX/\(bin/\.\./\)\{0,1\}lib/libsilc.so.1 " ||
  { env -i LD_TRACE_LOADED_OBJECTS=1 "$PREFIX/bin/silc"; fail "silc does not load $PREFIX/lib/libsilc.so.1"; }
# A system whose solution is exact in binary: [4 1; 1 3] x = [5; 4] has x = [1; 1].
out=$(env -i "$PREFIX/bin/silc" -e 'A = [4, 1; 1, 3]; x = A \ [5; 4]; info x' --get x 2>&1) ||
  { echo "$out"; fail "the installed silc did not run with no environment"; }
echo "$out" | grep -qx '1' && [ "$(echo "$out" | grep -cx '1')" -eq 2 ] ||
  { echo "$out"; fail "the installed silc computed a wrong x (want 1 and 1)"; }
if [ -f "$PREFIX/lib/silc/plugins/libsilc_plugin_lapack.so" ]; then
  echo "$out" | grep -q "backend: *lapack" ||
    { echo "$out"; fail "the installed silc did not use the installed lapack plugin"; }
fi
echo "test_install: silc -e from the moved prefix, no environment: x = [1; 1]"

# HDF5: libsilc does not link it; the installed module beside the plugins
# is opened by the first save / load (found from the moved prefix), and
# without it both say so, naming the directory searched.
if readelf -d "$PREFIX/lib/libsilc.so.1" | grep -q "NEEDED.*libhdf5"; then
  fail "libsilc links libhdf5 (save / load must open libsilc_h5.so on first use)"
fi
if [ -f "$PREFIX/lib/silc/plugins/libsilc_h5.so" ]; then
  out=$(cd "$TOP" && env -i "$PREFIX/bin/silc" -e 'z = [1/3 + 2i; -7]; save "h5.h5" z; w = z; clear z; load "h5.h5"; d = max(abs(z - w))' --get d 2>&1) ||
    { echo "$out"; fail "save / load from the moved prefix"; }
  echo "$out" | grep -qx '0' || { echo "$out"; fail "a complex z saved and loaded from the moved prefix changed"; }
  mv "$PREFIX/lib/silc/plugins/libsilc_h5.so" "$TOP/libsilc_h5.so.away"
  out=$(cd "$TOP" && env -i "$PREFIX/bin/silc" -e 'z = 1; save "h5.h5" z' 2>&1) && fail "save without the module succeeded"
  echo "$out" | grep -qF "save: HDF5 support is not installed (libsilc_h5.so not found in $PREFIX/lib/silc/plugins)" ||
    { echo "$out"; fail "save without the module: wrong message"; }
  mv "$TOP/libsilc_h5.so.away" "$PREFIX/lib/silc/plugins/libsilc_h5.so"
  echo "test_install: save / load open the installed libsilc_h5.so from the moved prefix; without it, they say so"
else
  echo "test_install: SILC built without HDF5: the module's install not checked"
fi

SOCK=$TOP/silcd.sock
env -i "$PREFIX/bin/silcd" --listen "unix:$SOCK" --ready-file "$TOP/ready" >"$TOP/silcd.log" 2>&1 &
SILCD_PID=$!
tries=0
while [ ! -s "$TOP/ready" ] && [ $tries -lt 300 ]; do # 30 s, generous under a loaded machine
  kill -0 "$SILCD_PID" 2>/dev/null || { cat "$TOP/silcd.log"; fail "the installed silcd exited at start"; }
  sleep 0.1
  tries=$((tries + 1))
done
[ -s "$TOP/ready" ] || { cat "$TOP/silcd.log"; fail "the installed silcd never became ready"; }
out=$(env -i SILC_SERVER="unix:$SOCK" "$PREFIX/bin/silc" -e 'A = [2, 0; 0, 4]; y = A \ [1; 2]' --get y 2>&1) ||
  { echo "$out"; cat "$TOP/silcd.log"; fail "a client call to the installed silcd"; }
[ "$(echo "$out" | grep -cx '0.5')" -eq 2 ] || { echo "$out"; fail "silcd computed a wrong y (want 0.5 and 0.5)"; }
kill "$SILCD_PID"
wait "$SILCD_PID" 2>/dev/null
SILCD_PID=
echo "test_install: silcd from the moved prefix, no environment, served a client on a Unix socket"

# ---- programs built against the moved prefix --------------------------
[ -f "$PREFIX/lib/cmake/SILC/SILCConfig.cmake" ] || fail "no SILCConfig.cmake under $PREFIX/lib/cmake/SILC"
cmake -S "$SRC/tests/install" -B "$TOP/consumer" -DCMAKE_PREFIX_PATH="$PREFIX" >"$TOP/configure.log" 2>&1 ||
  { cat "$TOP/configure.log"; fail "find_package(SILC 1.0) in an out-of-tree project"; }
cmake --build "$TOP/consumer" >"$TOP/build.log" 2>&1 || { cat "$TOP/build.log"; fail "building against SILC::silc"; }
out=$("$TOP/consumer/consumer_c") || { echo "$out"; fail "the CMake-built C program"; }
echo "$out"
echo "$out" | grep -q "^plugin $PREFIX/lib/silc/plugins/libsilc_plugin_suitesparse.so" ||
  fail "the installed libsilc did not load the installed plugins"
if echo "$out" | grep "^plugin " | grep -v "^plugin $PREFIX/" | grep -q .; then
  fail "plugins from outside the prefix were loaded"
fi
if [ -x "$TOP/consumer/consumer_f" ]; then
  "$TOP/consumer/consumer_f" || fail "the CMake-built Fortran program"
else
  echo "test_install: no Fortran compiler or SILC::silc_fortran: the Fortran program skipped"
fi
export PKG_CONFIG_PATH="$PREFIX/lib/pkgconfig"
pkg-config --exists silc || fail "pkg-config does not find silc"
# shellcheck disable=SC2046 # pkg-config's output is meant to be split
cc -o "$TOP/consumer_pc" "$SRC/tests/install/consumer.c" $(pkg-config --cflags --libs silc) -lm \
  -Wl,-rpath,"$(pkg-config --variable=libdir silc)" || fail "cc with pkg-config"
"$TOP/consumer_pc" | head -1 || fail "the pkg-config-built C program"

# ---- MPI: SILC::silc_mpi and silc_mpi.pc --------------------------------
if [ -f "$PREFIX/lib/libsilc_mpi.so.1" ]; then
  [ -x "$TOP/consumer/consumer_mpi" ] || fail "SILC has libsilc_mpi but find_package gave no SILC::silc_mpi"
  pkg-config --exists silc_mpi || fail "pkg-config does not find silc_mpi"
  # shellcheck disable=SC2046
  cc -o "$TOP/consumer_mpi_pc" "$SRC/tests/install/consumer_mpi.c" $(pkg-config --cflags --libs silc_mpi) -lm \
    -Wl,-rpath,"$(pkg-config --variable=libdir silc_mpi)" || fail "cc with pkg-config silc_mpi"
  if [ -n "$MPIEXEC" ]; then
    for prog in "$TOP/consumer/consumer_mpi" "$TOP/consumer_mpi_pc"; do
      "$MPIEXEC" -np 2 "$prog" || fail "$prog under $MPIEXEC -np 2"
    done
  else
    echo "test_install: no mpiexec: the MPI programs were built, not run"
  fi
else
  echo "test_install: SILC built without MPI: SILC::silc_mpi and silc_mpi.pc skipped"
fi

# ---- Python: the package finds libsilc relative to itself ----------------
PYDIR=$(ls -d "$PREFIX"/lib/python3*/dist-packages 2>/dev/null | head -1)
if [ -n "$PYDIR" ] && [ -x /usr/bin/python3 ]; then
  grep -q "$STAGED_PREFIX\|$BUILD" "$PYDIR/silc/_paths.py" && fail "_paths.py records an absolute path"
  env -i PYTHONPATH="$PYDIR" /usr/bin/python3 -c '
import numpy as np, silc, silc._embedded as e
with silc.Session() as s:
    s["A"] = np.array([[4.0, 1.0], [1.0, 3.0]]); s["b"] = np.array([5.0, 4.0])
    s.exec("x = A \\ b")
    assert np.allclose(np.ravel(s["x"]), [1, 1], rtol=0, atol=1e-15), s["x"]
print("python: embedded session from", silc.__file__, "with", e._lib._name)
' >"$TOP/python.log" 2>&1 || { cat "$TOP/python.log"; fail "the installed Python package"; }
  cat "$TOP/python.log"
  grep -q "with $PREFIX/lib/libsilc.so.1\$" "$TOP/python.log" || fail "the Python package did not load the prefix's libsilc"
  # Without an install beside it (the source tree's package), by soname on
  # the loader's path.
  env -i PYTHONPATH="$SRC/bindings/python" LD_LIBRARY_PATH="$PREFIX/lib" /usr/bin/python3 -B -c '
import silc, silc._embedded as e
with silc.Session() as s:
    s.exec("x = 2 * 21")
print("python: by soname:", e._lib._name)
' >"$TOP/python2.log" 2>&1 || { cat "$TOP/python2.log"; fail "the Python package finding libsilc by soname"; }
  cat "$TOP/python2.log"
  grep -q "by soname: libsilc.so.1\$" "$TOP/python2.log" || fail "the Python package did not load libsilc by soname"
else
  echo "test_install: no Python package installed (no /usr/bin/python3 at configure)"
fi

# ---- Java: the jar under share/java --------------------------------------
if [ -f "$BUILD/bindings/java/silc.jar" ]; then
  [ -f "$PREFIX/share/java/silc.jar" ] || fail "no $PREFIX/share/java/silc.jar"
  /usr/bin/python3 -m zipfile -l "$PREFIX/share/java/silc.jar" >"$TOP/jar.txt" || fail "silc.jar is no zip"
  grep -q "silc/SILC.class" "$TOP/jar.txt" ||
    fail "$PREFIX/share/java/silc.jar holds no silc/SILC.class"
  echo "test_install: share/java/silc.jar installed"
fi
echo "test_install: silc, silcd, find_package(SILC), pkg-config, Python and Java work from the moved $PREFIX"
