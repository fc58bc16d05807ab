#!/bin/sh
# test_engine_version.sh SOURCE_DIR OUT — the commit a build records (cmake/commit.cmake, run at
# every build) follows the tree: a sweep's run id hashes it, so a rebuild after a commit or an
# uncommitted edit must record something else, or a resumed sweep would keep rows an older engine
# computed (docs/sweep.md, "Nothing lost"). Checked on a scratch git repository against git's own
# answers: the header names HEAD's 12 hex; an edit adds +dirty.<8 hex>, a different edit other hex;
# a commit gives the new HEAD and no suffix; a rerun with nothing changed leaves the file untouched.
set -eu
src=$1
out=$2
rm -rf "$out"
mkdir -p "$out/repo"
cd "$out/repo"
git init -q .
git config user.email t@example.invalid
git config user.name test
echo one > f.c
git add f.c
git commit -q -m one
fail() { echo "FAIL: $*" >&2; exit 1; }
gen() { cmake -DSRC="$out/repo" -DOUT="$out/commit.h" -P "$src/cmake/commit.cmake"; }
recorded() { sed -n 's/^#define FLEXMBD_COMMIT "\(.*\)"$/\1/p' "$out/commit.h"; }

gen
[ "$(recorded)" = "$(git rev-parse --short=12 HEAD)" ] || fail "clean tree: recorded $(recorded), HEAD is $(git rev-parse --short=12 HEAD)"
touch -d '2000-01-01' "$out/commit.h"
gen
[ "$(find "$out/commit.h" -newermt '2001-01-01')" = "" ] || fail "a rerun with nothing changed rewrote the header (every tool would recompile)"

echo two > f.c
gen
first=$(recorded)
case $first in "$(git rev-parse --short=12 HEAD)+dirty."????????) ;; *) fail "an edit: recorded $first, no +dirty suffix" ;; esac
echo three > f.c
gen
[ "$(recorded)" != "$first" ] || fail "two different edits recorded the same $first"

git commit -q -am two
gen
[ "$(recorded)" = "$(git rev-parse --short=12 HEAD)" ] || fail "after a commit: recorded $(recorded), HEAD is $(git rev-parse --short=12 HEAD)"

rm -rf "$out/repo/.git"
gen
[ "$(recorded)" = unknown ] || fail "outside a git checkout: recorded $(recorded)"
echo "engine version follows the tree: clean, edited (two digests), committed, no git"
