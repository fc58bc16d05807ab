#!/bin/sh
# `flexmbd compare`: a CSV against itself gives zero error; against a copy with a known value
# shift (column a + 0.001, column b - 0.25 from t = 0.5 on) gives exactly that shift; against a
# reference on a finer time grid it interpolates (a linear column is reproduced exactly); and it
# rejects an unknown column with exit 2.   usage: test_compare.sh FLEXMBD WORKDIR
set -eu
F=$1
D=$2
mkdir -p "$D"
fail() { echo "FAIL: $*" >&2; exit 1; }
# field VALUE of key K on the line of column C
field() { awk -v c="column=$2" -v k="$3" '$2 == c { for (i = 3; i <= NF; ++i) { split($i, kv, "="); if (kv[1] == k) print kv[2] } }' "$1"; }
near() { awk -v a="$1" -v b="$2" -v tol="$3" 'BEGIN { d = a - b; if (d < 0) d = -d; exit !(d <= tol) }'; }

awk 'BEGIN { print "t,a,b,energy.total"; for (k = 0; k <= 100; ++k) { t = k / 100; printf "%.17g,%.17g,%.17g,%.17g\n", t, sin(3 * t), t * t, 2 + t } }' > "$D/ref.csv"
awk -F, 'NR == 1 { print; next } { b = $3; if ($1 >= 0.5) b -= 0.25; printf "%.17g,%.17g,%.17g,%.17g\n", $1, $2 + 0.001, b, $4 }' "$D/ref.csv" > "$D/shift.csv"
# a coarse run on other times (every 0.035 s) of the linear column; the quadratic one gets a bounded error
awk 'BEGIN { print "t,energy.total,b"; for (t = 0; t <= 1.0; t += 0.035) printf "%.17g,%.17g,%.17g\n", t, 2 + t, t * t; print "1,3,1" }' > "$D/coarse.csv"

"$F" compare "$D/ref.csv" "$D/ref.csv" > "$D/self.txt" || fail "compare self exited $?"
[ "$(wc -l < "$D/self.txt")" -eq 3 ] || fail "expected 3 lines for 3 columns"
for c in a b energy.total; do
  [ "$(field "$D/self.txt" "$c" max_abs)" = "0.000000e+00" ] || fail "self $c max_abs not 0"
  [ "$(field "$D/self.txt" "$c" end_abs)" = "0.000000e+00" ] || fail "self $c end_abs not 0"
  [ "$(field "$D/self.txt" "$c" rows)" = "101" ] || fail "self $c rows"
done

"$F" compare "$D/shift.csv" "$D/ref.csv" --columns a,b > "$D/shift.txt" || fail "compare shift exited $?"
[ "$(wc -l < "$D/shift.txt")" -eq 2 ] || fail "--columns a,b: expected 2 lines"
near "$(field "$D/shift.txt" a max_abs)" 0.001 1e-12 || fail "a: max_abs != 0.001"
near "$(field "$D/shift.txt" a end_abs)" 0.001 1e-12 || fail "a: end_abs != 0.001"
near "$(field "$D/shift.txt" b max_abs)" 0.25 1e-12 || fail "b: max_abs != 0.25"
near "$(field "$D/shift.txt" b t_max)" 0.5 1e-12 || fail "b: t_max != 0.5"
near "$(field "$D/shift.txt" b max_rel)" 0.25 1e-12 || fail "b: max_rel != 0.25 (ref_scale 1)"
near "$(field "$D/shift.txt" a ref_scale)" "$(awk -F, 'NR > 1 && $2 > m { m = $2 } END { print m }' "$D/ref.csv")" 1e-6 || fail "a: ref_scale != max sin(3t)"

# coarse.csv lacks column a: a failure (exit 1) that names it, unless --common
rc=0; "$F" compare "$D/coarse.csv" "$D/ref.csv" > /dev/null 2> "$D/cols.err" || rc=$?
[ "$rc" -eq 1 ] || fail "a missing column: exit $rc, not 1"
grep -q "column 'a' of .*ref.csv is missing from .*coarse.csv" "$D/cols.err" || fail "missing column: message"
"$F" compare "$D/coarse.csv" "$D/ref.csv" --common > "$D/coarse.txt" || fail "compare coarse exited $?"
near "$(field "$D/coarse.txt" energy.total max_abs)" 0 1e-14 || fail "linear column not interpolated exactly"
# linear interpolation of t^2 on a 0.01 grid: error <= h^2/4 = 2.5e-5, and > 0 off the grid
e=$(field "$D/coarse.txt" b max_abs)
awk -v e="$e" 'BEGIN { exit !(e > 1e-7 && e <= 2.5e-5 + 1e-15) }' || fail "quadratic column interpolation error $e"

# tolerances: pass when max_abs <= atol + rtol * range(REF column), exit 1 beyond
ex() { rc=0; "$F" compare "$@" > "$D/tol.txt" 2> "$D/tol.err" || rc=$?; echo "$rc"; }
[ "$(ex "$D/shift.csv" "$D/ref.csv" --columns a --atol 0.0011)" = 0 ] || fail "a within atol: not exit 0"
grep -q "status=ok" "$D/tol.txt" || fail "within tolerance: no status=ok"
[ "$(ex "$D/shift.csv" "$D/ref.csv" --columns a --atol 0.0009)" = 1 ] || fail "a beyond atol: not exit 1"
grep -q "status=beyond" "$D/tol.txt" || fail "beyond tolerance: no status=beyond"
[ "$(ex "$D/shift.csv" "$D/ref.csv" --columns b --rtol 0.26)" = 0 ] || fail "b (range 1) within rtol 0.26: not exit 0"
[ "$(ex "$D/shift.csv" "$D/ref.csv" --columns b --rtol 0.24)" = 1 ] || fail "b (range 1) beyond rtol 0.24: not exit 1"
[ "$(ex "$D/shift.csv" "$D/ref.csv" --rtol 0.3 --atol 0.002)" = 0 ] || fail "all columns within: not exit 0"
# different time grids: interpolated, so the tolerance sees the interpolation error (<= 2.5e-5 on b)
[ "$(ex "$D/coarse.csv" "$D/ref.csv" --common --atol 2.6e-5)" = 0 ] || fail "coarse grid within 2.6e-5: not exit 0"
[ "$(ex "$D/coarse.csv" "$D/ref.csv" --common --atol 1e-7)" = 1 ] || fail "coarse grid beyond 1e-7: not exit 1"
# a shorter run fails with its own message; so does a renamed column
head -n 51 "$D/ref.csv" > "$D/short.csv"
[ "$(ex "$D/short.csv" "$D/ref.csv" --atol 1)" = 1 ] || fail "a shorter run: not exit 1"
grep -q "ends at t = 0.49.*a shorter run" "$D/tol.err" || fail "shorter run: message"
sed '1s/energy.total/energy.kinetic/' "$D/ref.csv" > "$D/renamed.csv"
[ "$(ex "$D/renamed.csv" "$D/ref.csv" --atol 1)" = 1 ] || fail "a renamed column: not exit 1"
grep -q "column 'energy.kinetic' .*an extra column" "$D/tol.err" && grep -q "column 'energy.total' .* missing" "$D/tol.err" ||
  fail "renamed column: messages"
[ "$(ex "$D/ref.csv" "$D/ref.csv" --rtol -1)" = 2 ] || fail "negative --rtol: not exit 2"
[ "$(ex "$D/ref.csv" "$D/ref.csv" --atol x)" = 2 ] || fail "--atol x: not exit 2"
# a line longer than the bound is refused, not read forever
awk 'BEGIN { printf "t"; for (i = 0; i < 200000; ++i) printf ",c%d", i; print "" }' > "$D/wide.csv"
[ "$(ex "$D/wide.csv" "$D/ref.csv")" = 2 ] || fail "an over-long line: not exit 2"
grep -q "line longer than" "$D/tol.err" || fail "over-long line: message"
[ "$(ex /dev/null "$D/ref.csv")" = 2 ] || fail "a device as input: not exit 2"
grep -q "not a regular file" "$D/tol.err" || fail "non-regular input: message"

if "$F" compare "$D/ref.csv" "$D/ref.csv" --columns nope > /dev/null 2>&1; then fail "unknown column accepted"; fi
"$F" compare "$D/ref.csv" "$D/ref.csv" --columns nope 2> "$D/err.txt" > /dev/null || [ $? -eq 2 ] || fail "unknown column: exit not 2"
grep -q "no column 'nope'" "$D/err.txt" || fail "unknown column: message"
if "$F" compare "$D/missing.csv" "$D/ref.csv" > /dev/null 2>&1; then fail "missing file accepted"; fi
# run --reference: a run compared with itself has zero error, and the line carries its cost
SC="$(dirname "$0")/../../scenes/pendulum.yaml"
"$F" run "$SC" -o "$D/run.csv" --quiet --set solver.t_end=0.5 2> /dev/null || fail "pendulum run exited $?"
"$F" run "$SC" -o "$D/run2.csv" --quiet --set solver.t_end=0.5 --reference "$D/run.csv" --columns bob.x \
  > "$D/runref.txt" 2> "$D/runref.err" || fail "run --reference exited $?"
[ "$(wc -l < "$D/runref.txt")" -eq 1 ] || fail "run --reference --columns bob.x: expected one line"
[ "$(field "$D/runref.txt" bob.x max_abs)" = "0.000000e+00" ] || fail "run --reference against itself: max_abs not 0"
grep -q " status=ok cpu_s=[0-9.]* steps=[0-9]*$" "$D/runref.txt" || fail "run --reference: the line lacks the run's cost"
tail -n 1 "$D/runref.err" | grep -q "^stats: status=ok" || fail "run --reference: the stats line is not last on stderr"
# a wrong tolerance shows up as a non-zero error
"$F" run "$SC" -o "$D/run3.csv" --quiet --set solver.t_end=0.5 --set solver.rtol=1e-3 --reference "$D/run.csv" \
  --columns bob.x > "$D/runref3.txt" 2> /dev/null || fail "run --reference (rtol 1e-3) exited $?"
awk -v e="$(field "$D/runref3.txt" bob.x max_abs)" 'BEGIN { exit !(e > 1e-8) }' || fail "a looser run shows no error"
# a spreadsheet's save of the reference (issue 36): a UTF-8 byte-order mark before 't', blanks and
# a tab around the cells, CRLF line ends: the same numbers, so zero error; a cell with text after
# its number is still refused
{ printf '\357\273\277'; sed 's/,/ ,\t/g; s/$/  \r/' "$D/ref.csv"; } > "$D/excel.csv"
head -c 3 "$D/excel.csv" | od -An -tx1 | grep -q "ef bb bf" || fail "the byte-order mark was not written"
"$F" compare "$D/excel.csv" "$D/ref.csv" > "$D/excel.txt" 2> "$D/excel.err" || fail "BOM/blanks: exit $?: $(cat "$D/excel.err")"
for c in a b energy.total; do
  [ "$(field "$D/excel.txt" "$c" max_abs)" = "0.000000e+00" ] || fail "BOM/blanks: $c max_abs not 0"
  [ "$(field "$D/excel.txt" "$c" rows)" = "101" ] || fail "BOM/blanks: $c rows"
done
sed '3s/$/x/' "$D/ref.csv" > "$D/junk.csv"
rc=0
"$F" compare "$D/junk.csv" "$D/ref.csv" > /dev/null 2> "$D/junk.err" || rc=$?
[ "$rc" = 2 ] && grep -q "junk.csv:3: expected 4 comma-separated numbers" "$D/junk.err" || fail "text after a number accepted (exit $rc)"
echo "compare: all checks passed"
