"""pychecks.py -- the check counter of the Python tests (test_python.py,
test_h5.py), as tests/check.h is the C tests': check(cond, what) counts,
and prints what failed; done() prints "N passed, N failed" and exits 1 on a
failure.
"""
import sys

_count = {"passed": 0, "failed": 0}


def check(cond, what):
    if cond:
        _count["passed"] += 1
    else:
        _count["failed"] += 1
        print("FAIL: %s" % what, file=sys.stderr)


def done():
    print("%d passed, %d failed" % (_count["passed"], _count["failed"]))
    sys.exit(1 if _count["failed"] else 0)
