#!/bin/sh
# test_model_range.sh FLEXMBD SOURCE_DIR OUT_DIR — the beam models' range said out loud (issue 23
# item 6; bodies/beam.c, beam_model_range; docs/models.md, "Each model's range"):
#  - the tutorial's rotor at omega0 = 15 with its 5 s ramp (complete model, tip at 43 % of L, 0.29 m
#    from the exact beam) warns once, with the time, the deflection and `model: exact`;
#  - the paper's scenes as shipped (peak deflection at most 10.9 % of L, complete within 1.9 %) and
#    the rotor starter (17.0 %, 4.3 %) do not; nor does the exact beam at omega0 = 15;
#  - ZOAC spun past 0.3 of its first bending frequency warns about the spin;
#  - `flexmbd check` states each model's range.
. "$(dirname "$0")/cli_lib.sh"

"$F" new rotor >"$OUT/rotor.yaml"
"$F" run "$OUT/rotor.yaml" -o "$OUT/fast.csv" --set joints.motor.omega0=15 --quiet 2>"$OUT/fast.err"
rc=$?
check "tutorial rotor at 15 rad/s in 5 s: runs (exit 0) and warns once" \
  "[ $rc -eq 0 ] && [ \$(grep -c 'warning:' '$OUT/fast.err') -eq 1 ]"
check "the warning gives the time, the deflection beyond 18 % and the suggestion" \
  "grep -q \"^warning: t = 1\\.[0-9]*: body 'beam' has left its model's range: its tip deflects 0\\.3[0-9]* m, 18\\.[0-9] % of its length, beyond the 18 % up to which the complete model .*use \\\`model: exact\\\`\" '$OUT/fast.err'"
"$F" run "$OUT/rotor.yaml" -o "$OUT/fast_exact.csv" --set joints.motor.omega0=15 --set bodies.beam.model=exact \
  --quiet 2>"$OUT/fast_exact.err"
check "the same with model: exact: no warning" "! grep -q 'warning:' '$OUT/fast_exact.err'"

: >"$OUT/quiet.err"
for s in scenes/paper/*.yaml; do
  "$F" run "$s" -o "$OUT/paper.csv" --quiet 2>>"$OUT/quiet.err"
done
"$F" run "$OUT/rotor.yaml" -o "$OUT/starter.csv" --quiet 2>>"$OUT/quiet.err"
check "the paper's 4 scenes and the rotor starter as shipped: no range warning" \
  "! grep -q \"left its model's range\" '$OUT/quiet.err'"

"$F" run "$OUT/rotor.yaml" -o "$OUT/zoac.csv" --set bodies.beam.model=zoac --set joints.motor.omega0=2 --quiet \
  2>"$OUT/zoac.err"
check "ZOAC at 2 rad/s (first bending frequency 3.91 rad/s): warns at 30 % of it, suggesting complete or exact" \
  "grep -q \"it turns at 1\\.1[0-9]* rad/s, 30 % of its first bending frequency 3\\.91 rad/s.*model: complete\" '$OUT/zoac.err'"

"$F" check "$OUT/rotor.yaml" >"$OUT/check.txt" 2>&1
"$F" check "$OUT/rotor.yaml" --set bodies.beam.model=foac >>"$OUT/check.txt" 2>&1
"$F" check "$OUT/rotor.yaml" --set bodies.beam.model=zoac >>"$OUT/check.txt" 2>&1
"$F" check "$OUT/rotor.yaml" --set bodies.beam.model=exact >>"$OUT/check.txt" 2>&1
check "check states each model's range" \
  "grep -q 'complete model.*accurate while the tip deflects less than 18 % of the length (0.324 m)' '$OUT/check.txt' &&
   grep -q 'foac model.*less than 40 % of the length (0.72 m), under prescribed rotation only' '$OUT/check.txt' &&
   grep -q 'zoac model.*18 % .* and it turns slower than 30 % of its first bending frequency (1.17 rad/s)' '$OUT/check.txt' &&
   grep -q 'exact model.*no range limit' '$OUT/check.txt'"
exit $fail
