#!/bin/sh
# layers.sh -- the engine's layering (docs/architecture.md) cannot regress:
# each folder of core/ may use only the folders its row of the table below
# names, all lower than itself, so calls go one way down the layers.
#
#   tests/layers.sh CORE_DIR [OBJECT...]
#
# Checked from the sources: every #include "x.h" of a folder's files names a
# header of its own folder or of an allowed one; every folder has exactly
# one header, its interface, named after it; no header declares a function
# that another folder's objects define.  Checked from the objects (the
# compiled silc_objects, when given): every function or variable a folder's
# objects use that another folder defines belongs to an allowed folder --
# this catches a call made without an include, through a declaration
# written by hand.  Callbacks that go up (the host API, dist_attach's run,
# refine_how's correct) are pointers, which neither check sees: that is the
# point of them.  Exits 1 naming every violation.
set -eu
export LC_ALL=C # sort and join must agree on the order
core=$1
shift

# folder: the folders it may use (its own is always allowed).  Lowest first.
allowed() {
    case $1 in
    util)     echo "" ;;
    store)    echo "util" ;;
    context)  echo "store util" ;;
    dist)     echo "context store util" ;;
    accuracy) echo "dist context store util" ;;
    dispatch) echo "accuracy dist context store util" ;;
    tune)     echo "dispatch context store util" ;;
    lang)     echo "tune dispatch accuracy dist context store util" ;;
    engine)   echo "lang tune dispatch dist context store util" ;;
    client)   echo "engine lang dist context store util" ;;
    *)        return 1 ;;
    esac
}
layers="util store context dist accuracy dispatch tune lang engine client"

fail=0
bad() {
    echo "layers: $*" >&2
    fail=1
}
may_use() { # may_use FROM TO
    [ "$1" = "$2" ] && return 0
    for a in $(allowed "$1"); do [ "$a" = "$2" ] && return 0; done
    return 1
}

# Every folder of core/ but the public headers is a layer of the table.
for d in "$core"/*/; do
    f=$(basename "$d")
    [ "$f" = include ] && continue
    allowed "$f" >/dev/null || bad "core/$f/ is not in the table of tests/layers.sh"
done

# One header per folder, named after it.
for f in $layers; do
    hs=$(cd "$core/$f" && ls *.h 2>/dev/null | tr '\n' ' ')
    [ "$hs" = "$f.h " ] || bad "core/$f/ must have one header, $f.h (has: $hs)"
done

# Includes.
for f in $layers; do
    for src in "$core/$f"/*.c "$core/$f"/*.h; do
        [ -e "$src" ] || continue
        for h in $(sed -n 's/^[[:space:]]*#[[:space:]]*include[[:space:]]*"\([^"]*\)".*/\1/p' "$src"); do
            to=""
            for g in $layers; do [ -e "$core/$g/$h" ] && to=$g; done
            [ -n "$to" ] || continue # public, plugin ABI or third-party header
            may_use "$f" "$to" || bad "core/$f/$(basename "$src") includes $h of core/$to/"
        done
    done
done

# Symbols, from the objects: OBJ's folder is the directory it sits in.
if [ $# -gt 0 ]; then
    tmp=$(mktemp -d)
    trap 'rm -rf "$tmp"' EXIT
    for o in "$@"; do
        f=$(basename "$(dirname "$o")")
        allowed "$f" >/dev/null || continue # the built-in reference plugin
        nm --defined-only -g "$o" | awk -v f="$f" 'NF == 3 && $2 ~ /[TDBRCGS]/ {print $3, f}' >>"$tmp/defs"
        nm -u "$o" | awk -v f="$f" -v o="$(basename "$o")" '{print $2, f, o}' >>"$tmp/uses"
    done
    sort -u "$tmp/defs" >"$tmp/defs.s"
    sort "$tmp/uses" >"$tmp/uses.s"
    join "$tmp/uses.s" "$tmp/defs.s" >"$tmp/edges" || true
    while read -r sym from obj to; do
        may_use "$from" "$to" || bad "core/$from/${obj%.o} uses $sym of core/$to/"
    done <"$tmp/edges"
    # A function is declared by the header of the folder that defines it.
    while read -r sym to; do
        for g in $layers; do
            [ "$g" = "$to" ] && continue
            grep -Eq "^[A-Za-z_].*[ *]$sym\(" "$core/$g/$g.h" 2>/dev/null &&
                bad "core/$g/$g.h declares $sym, defined in core/$to/"
        done
    done <"$tmp/defs.s"
fi

[ $fail -eq 0 ] && echo "layers: core/ calls go one way down the layers"
exit $fail
