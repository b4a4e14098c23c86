#!/bin/sh
# test_install.sh -- SILC as a user installs it: `cmake --install` into a
# temporary prefix, then an out-of-tree program (tests/install) built with
# find_package(SILC 1.0) -- C, and Fortran when there is a compiler -- and
# the C program again with pkg-config.  Each must solve its system, and the
# C program must have loaded its plugins from the prefix, found by the
# installed libsilc itself (no SILC_PLUGIN_PATH).
#
#     sh tests/install/test_install.sh BUILD_DIR SOURCE_DIR
set -u
BUILD=$1 SRC=$2
PREFIX=$(mktemp -d /tmp/silc-install-test.XXXXXX) || exit 1
trap 'rm -rf "$PREFIX"' EXIT
unset SILC_PLUGIN_PATH SILC_CONFIG SILC_SERVER
fail() { echo "test_install: FAIL: $*"; exit 1; }
cmake --install "$BUILD" --prefix "$PREFIX" >"$PREFIX/install.log" 2>&1 || { cat "$PREFIX/install.log"; fail "cmake --install"; }
[ -f "$PREFIX/lib/cmake/SILC/SILCConfig.cmake" ] || fail "no SILCConfig.cmake under $PREFIX/lib/cmake/SILC"
cmake -S "$SRC/tests/install" -B "$PREFIX/consumer" -DCMAKE_PREFIX_PATH="$PREFIX" >"$PREFIX/configure.log" 2>&1 ||
  { cat "$PREFIX/configure.log"; fail "find_package(SILC 1.0) in an out-of-tree project"; }
cmake --build "$PREFIX/consumer" >"$PREFIX/build.log" 2>&1 || { cat "$PREFIX/build.log"; fail "building against SILC::silc"; }
out=$("$PREFIX/consumer/consumer_c") || { echo "$out"; fail "the CMake-built C program"; }
echo "$out"
echo "$out" | grep -q "^plugin $PREFIX/lib/silc/plugins/libsilc_plugin_suitesparse.so" ||
  fail "the installed libsilc did not load the installed plugins"
if echo "$out" | grep "^plugin " | grep -v "^plugin $PREFIX/" | grep -q .; then
  fail "plugins from outside the prefix were loaded"
fi
if [ -x "$PREFIX/consumer/consumer_f" ]; then
  "$PREFIX/consumer/consumer_f" || fail "the CMake-built Fortran program"
else
  echo "test_install: no Fortran compiler or SILC::silc_fortran: the Fortran program skipped"
fi
PKG_CONFIG_PATH="$PREFIX/lib/pkgconfig" pkg-config --exists silc || fail "pkg-config does not find silc"
# shellcheck disable=SC2046 # pkg-config's output is meant to be split
cc -o "$PREFIX/consumer_pc" "$SRC/tests/install/consumer.c" \
  $(PKG_CONFIG_PATH="$PREFIX/lib/pkgconfig" pkg-config --cflags --libs silc) -lm \
  -Wl,-rpath,"$(PKG_CONFIG_PATH="$PREFIX/lib/pkgconfig" pkg-config --variable=libdir silc)" || fail "cc with pkg-config"
"$PREFIX/consumer_pc" | head -1 || fail "the pkg-config-built C program"
# The Python package, embedded, found by the interpreter under the prefix
# and finding libsilc by itself (no SILC_LIBRARY).
PYDIR=$(ls -d "$PREFIX"/lib/python3*/dist-packages 2>/dev/null | head -1)
if [ -n "$PYDIR" ] && [ -x /usr/bin/python3 ]; then
  PYTHONPATH=$PYDIR /usr/bin/python3 -c '
import numpy as np, silc
with silc.Session() as s:
    s["A"] = np.array([[4.0, 1.0], [1.0, 3.0]]); s["b"] = np.array([5.0, 4.0])
    s.exec("x = A \\ b")
    assert np.allclose(s["x"].ravel(), [1, 1], rtol=0, atol=1e-15), s["x"]
    print("python: embedded session from", silc.__file__)
' || fail "the installed Python package"
else
  echo "test_install: no Python package installed (no /usr/bin/python3 at configure)"
fi
echo "test_install: find_package(SILC), SILC::silc, SILC::silc_fortran, pkg-config and Python work from $PREFIX"
