#!/usr/bin/env python3
"""make_seeds.py -- writes the seed corpora of fuzz_lang and fuzz_config from
the test suite's own cases, so the fuzzers start from every statement and
config file the tests know (and follow them when the tests grow).

    python3 tests/fuzz/make_seeds.py        (from anywhere; rewrites both dirs)

corpus-lang/: the statements of tests/test_lang.c (OK, ERR, silc_exec) and the
language and numeric rows of tests/test_reliability.c (LANG, NUM), one case
per file; the cases that succeed are grouped three to a file (newline
separated) so that a seed also carries state from one statement to the next.
corpus-config/: the config texts of test_reliability.c (CONF) and
test_config.c, and the conformance configurations.  Files are named by
content hash, so re-running adds nothing that is already there; regression
inputs (named regress-*) are kept.  The rules that fuzz_lang.c applies
(statements touching files or plugins are skipped) are applied here too, so
the corpus holds only inputs that run.
"""
import glob
import hashlib
import os
import re

HERE = os.path.dirname(os.path.abspath(__file__))
TESTS = os.path.dirname(HERE)

# Mirrors fuzz_lang.c's refused(): see the comment there.
LANG_REFUSED = ("plugin_path", "wisdom", "report")


def c_literals(text, pos):
    """Parses the comma-separated arguments of a call starting after '(' at pos;
    returns a list with the decoded string for arguments made only of string
    literals and None for others."""
    args, cur, lits, depth, i = [], [], [], 0, pos
    only_strings = True
    while i < len(text):
        ch = text[i]
        if ch == '"':
            j = i + 1
            buf = []
            while text[j] != '"':
                if text[j] == "\\":
                    buf.append(text[j:j + 2])
                    j += 2
                else:
                    buf.append(text[j])
                    j += 1
            lits.append("".join(buf))
            i = j + 1
            continue
        if ch in "([{":
            depth += 1
        elif ch in ")]}":
            if depth == 0:
                args.append(decode(lits) if lits and only_strings else None)
                return args
            depth -= 1
        elif ch == "," and depth == 0:
            args.append(decode(lits) if lits and only_strings else None)
            lits, only_strings = [], True
            i += 1
            continue
        if not ch.isspace():
            only_strings = False
        i += 1
    return args


def decode(parts):
    s = "".join(parts)
    return s.encode("latin-1").decode("unicode_escape")


def calls(path, name):
    text = open(path).read()
    for m in re.finditer(r"\b%s\(" % re.escape(name), text):
        yield c_literals(text, m.end())


def write(dirname, items):
    os.makedirs(dirname, exist_ok=True)
    keep = {f for f in os.listdir(dirname) if f.startswith("regress-")}
    for f in os.listdir(dirname):
        if f not in keep:
            os.remove(os.path.join(dirname, f))
    seen = set()
    for text in items:
        data = text.encode()
        h = hashlib.sha1(data).hexdigest()[:16]
        if h in seen:
            continue
        seen.add(h)
        with open(os.path.join(dirname, "seed-" + h), "wb") as f:
            f.write(data)
    return len(seen)


def lang_seeds():
    ok, single = [], []
    lang = os.path.join(TESTS, "test_lang.c")
    rel = os.path.join(TESTS, "test_reliability.c")
    for a in calls(lang, "OK"):
        if a and a[0] is not None:
            ok.append(a[0])
    for a in calls(lang, "ERR"):
        if a and a[0] is not None:
            single.append(a[0])
    for path in (lang, rel):
        for a in calls(path, "silc_exec"):
            if len(a) > 1 and a[1] is not None:
                single.append(a[1])
    for a in calls(rel, "LANG"):
        if a and a[0] is not None:
            single.append(a[0])
    for a in calls(rel, "NUM"):
        if len(a) > 1 and a[1] is not None:
            single.append(a[1])
    groups = ["\n".join(ok[i:i + 3]) for i in range(0, len(ok), 3)]
    return [s for s in groups + single if not any(r in s for r in LANG_REFUSED)]


# Config forms the tests do not write: the flat key form, every section,
# comments, continuation lines, every dispatch class.
EXTRA_CONFIG = [
    "tune.threads = 2\nsolve.refine = 3\ncore.threads = 1\n",
    "[solve]\nrefine = 2\nrefine_residual = extended\nbackward_error = always\n",
    "[core]\nthreads = 4096\n",
    "; comment\n[dispatch]\nsolve.dense = reference ; inline comment\n",
    "[tune]\nthreads = auto\naccuracy = 1e-8\nbudget = 0.5\n",
    "[dispatch]\nsolve.dense = reference, reference, reference\nsolve.band = reference\n",
    "[dispatch]\nsolve.sparse =\n",
    "[tune\nthreads = 1\n",
    "[dispatch]\nsolve.dense = reference\n    lapack\n",
    "[reference]\nverbose = 1\n",
    "".join("[dispatch]\n%s = reference\n" % c for c in (
        "solve.diag", "solve.triangular", "solve.band", "solve.dense", "solve.dense.spd",
        "solve.sparse", "solve.sparse.spd", "solve.rect", "matmul.sparse_sparse",
        "matmul.sparse_dense", "matmul.dense", "add", "elementwise", "transpose", "reduce",
        "convert", "diag")),
]


def config_seeds():
    out = list(EXTRA_CONFIG)
    for a in calls(os.path.join(TESTS, "test_reliability.c"), "CONF"):
        if a and a[0] is not None:
            out.append(a[0])
    conf = os.path.join(TESTS, "test_config.c")
    for fn in ("file_error", "load_text"):
        for a in calls(conf, fn):
            if len(a) > 1 and a[1] is not None:
                out.append(a[1])
    for path in sorted(glob.glob(os.path.join(TESTS, "conformance", "*.conf"))):
        out.append(open(path).read())
    return [s for s in out if "plugin_path" not in s]


if __name__ == "__main__":
    n = write(os.path.join(HERE, "corpus-lang"), lang_seeds())
    print("corpus-lang: %d seeds" % n)
    n = write(os.path.join(HERE, "corpus-config"), config_seeds())
    print("corpus-config: %d seeds" % n)
