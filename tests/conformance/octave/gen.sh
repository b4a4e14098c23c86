#!/bin/sh
# gen.sh -- regenerates suite.octave-truth.txt, Octave's own output for suite.m: the truth
# test_octave compares SILC's output with.  Run it where Octave is installed:
#   sh tests/conformance/octave/gen.sh
# (suite.octave-truth.txt was made with GNU Octave 7.3.0, Debian 12's octave package.)
set -eu
here=$(cd "$(dirname "$0")" && pwd)
cd "$here"
# Octave 7 prints a spurious line about an exception while exiting a script.
octave-cli -q --no-init-file suite.m 2>&1 | grep -v '^error: ignoring const execution_exception' > suite.octave-truth.txt
echo "wrote $here/suite.octave-truth.txt ($(octave-cli --version | head -1))"
