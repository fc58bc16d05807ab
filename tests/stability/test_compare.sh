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
awk 'BEGIN { print "t,energy.total,b"; for (t = 0; t <= 1.0; t += 0.035) printf "%.17g,%.17g,%.17g\n", t, 2 + t, t * t }' > "$D/coarse.csv"

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

"$F" compare "$D/coarse.csv" "$D/ref.csv" > "$D/coarse.txt" || fail "compare coarse exited $?"
near "$(field "$D/coarse.txt" energy.total max_abs)" 0 1e-14 || fail "linear column not interpolated exactly"
# linear interpolation of t^2 on a 0.01 grid: error <= h^2/4 = 2.5e-5, and > 0 off the grid
e=$(field "$D/coarse.txt" b max_abs)
awk -v e="$e" 'BEGIN { exit !(e > 1e-7 && e <= 2.5e-5 + 1e-15) }' || fail "quadratic column interpolation error $e"

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
echo "compare: all checks passed"
