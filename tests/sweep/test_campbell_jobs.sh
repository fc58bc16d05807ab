#!/bin/sh
# `flexmbd campbell -j K` (tools/modes_pool.c): the speeds in child processes give the diagram of
# one process byte for byte, with the dense eigen-solver and with the sparse one (ARPACK, which
# starts every computation from the same vector, engine/modes.c: before, its start vector depended
# on the calls made before in the same process and the two agreed to 1e-9), and each speed equals
# that speed computed alone; a bad --speed path is still exit 2.
#   usage: test_campbell_jobs.sh FLEXMBD SOURCE_DIR WORKDIR FAULTY_PLUGIN
. "$(dirname "$0")/lib.sh"
S="$SRC/scenes/campbell_beam.yaml --speed joints.spin.speed --speeds 0:30:16 --count 3"
# shellcheck disable=SC2086
"$F" campbell $S --eigen dense -o "$D/d1.csv" 2> /dev/null || fail "campbell -j 1 (dense)"
# shellcheck disable=SC2086
"$F" campbell $S --eigen dense -o "$D/d2.csv" -j 2 2> /dev/null || fail "campbell -j 2 (dense)"
cmp -s "$D/d1.csv" "$D/d2.csv" || { diff "$D/d1.csv" "$D/d2.csv"; fail "-j 2 differs from -j 1 (dense)"; }
# shellcheck disable=SC2086
"$F" campbell $S --eigen sparse -o "$D/s1.csv" 2> /dev/null || fail "campbell -j 1 (sparse)"
# shellcheck disable=SC2086
"$F" campbell $S --eigen sparse -o "$D/s3.csv" -j 3 2> /dev/null || fail "campbell -j 3 (sparse)"
cmp -s "$D/s1.csv" "$D/s3.csv" || { diff "$D/s1.csv" "$D/s3.csv"; fail "-j 3 differs from -j 1 (sparse)"; }
for sp in 6 22; do
  "$F" campbell "$SRC/scenes/campbell_beam.yaml" --speed joints.spin.speed --speeds $sp --count 3 --eigen sparse -o - \
    2> /dev/null | tail -1 > "$D/alone.txt"
  grep -qx "$(cat "$D/alone.txt")" "$D/s3.csv" || fail "speed $sp alone: $(cat "$D/alone.txt") is not -j 3's row"
done
rc=0
"$F" campbell "$SRC/scenes/campbell_beam.yaml" --speed joints.spin.sped --speeds 0:30:4 -j 2 -o "$D/bad.csv" 2> "$D/bad.err" || rc=$?
[ "$rc" = 2 ] && grep -q "unknown key 'sped'" "$D/bad.err" || fail "a bad --speed path with -j 2: exit $rc"
echo "test_campbell_jobs: ok"
