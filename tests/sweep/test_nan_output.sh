#!/bin/sh
# A type's output op that returns NaN from a finite state (faulty.so, fault 6): the run stops with
# exit 3, keeps the rows before, and its message names the column and blames the output op, with no
# advice about springs or tolerances (issue 27, "a NaN plugin output is reported without its column
# and with advice about springs"). A run that blows up still gets that advice (test_failures'
# infinite_energy).
set -u
flexmbd=$1 src=$2 out=$3 plugin=$4
mkdir -p "$out"
"$flexmbd" run "$src/tests/sweep/faulty.yaml" -o "$out/nan.csv" --plugin "$plugin" \
  --set bodies.f.fault=6 --set 'outputs=[bob.x, f.level]' 2>"$out/nan.err"
rc=$?
fail=0
[ "$rc" -eq 3 ] || { echo "FAIL: exit $rc, expected 3"; fail=1; }
grep -q "output 'f.level' is not finite" "$out/nan.err" || { echo "FAIL: the column is not named"; fail=1; }
grep -q "output op" "$out/nan.err" || { echo "FAIL: the output op is not blamed"; fail=1; }
if grep -q "spring\|rtol" "$out/nan.err"; then echo "FAIL: advice about springs or tolerances"; fail=1; fi
head -1 "$out/nan.csv" | grep -q '^t,bob.x,f.level$' || { echo "FAIL: header not kept"; fail=1; }
# the same scene without the fault runs to the end with the column at 0
"$flexmbd" run "$src/tests/sweep/faulty.yaml" -o "$out/ok.csv" --plugin "$plugin" \
  --set 'outputs=[bob.x, f.level]' 2>/dev/null || { echo "FAIL: fault 0 did not run"; fail=1; }
[ "$(tail -1 "$out/ok.csv" | cut -d, -f3)" = "0" ] || { echo "FAIL: level not 0 without the fault"; fail=1; }
cat "$out/nan.err" | tail -3
[ $fail -eq 0 ] && echo "nan_output: ok"
exit $fail
