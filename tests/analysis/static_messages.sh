#!/bin/sh
# static_messages.sh FLEXMBD SOURCE_DIR OUT_DIR — statics says what is wrong, as `run` does:
#  - no load and a singular stiffness (a pendulum or a double pendulum without gravity: every
#    angle is an equilibrium): exit 2 "no unique equilibrium" whether the out-of-balance load is
#    roundoff (2e-15) or exactly 0 (before: exit 3 "no equilibrium found", resp. exit 0);
#  - poses that the joints would move (the pendulum's bob 0.3 m off its pin): exit 2 naming the
#    joint at its line, as `run` refuses the scene (before: moved silently); `initial: assemble`
#    lets it go on;
#  - joints that cannot all hold: exit 2 naming one at its line (before: exit 3 "singular");
#  - nan or inf in an option: exit 2 naming the option (before: exit 3 "not finite at t = nan");
#  - bad input ends with the error line, no stats line.
. "$(dirname "$0")/../exact/cli_lib.sh" # F, SRC, OUT, check; in SRC
last() { tail -1 "$OUT/$1.err"; }

for s in pendulum double_pendulum; do
  "$F" static scenes/$s.yaml --set "gravity=[0, 0]" -o "$OUT/$s.csv" -q 2>"$OUT/$s.err"
  rc=$?
  check "$s without gravity: exit 2, no unique equilibrium, no stats line" \
    "[ $rc -eq 2 ] && last $s | grep -q 'error: no unique equilibrium: nothing loads the system'"
done

"$F" static scenes/pendulum.yaml --set "bodies.bob.position=[0.47364817766693, 0.98480775301221]" -o "$OUT/off.csv" \
  -q 2>"$OUT/off.err"
rc=$?
"$F" run scenes/pendulum.yaml --set "bodies.bob.position=[0.47364817766693, 0.98480775301221]" -o "$OUT/off_run.csv" \
  -q 2>"$OUT/off_run.err"
pin=$(grep -n 'name: pin' scenes/pendulum.yaml | cut -d: -f1) # the joint's line
check "bob off its pin: static exits 2 with run's message, joint 'pin' at $pin:5" \
  "[ $rc -eq 2 ] && last off | grep -q \"^scenes/pendulum.yaml:$pin:5: error: joint 'pin' is not satisfied by the poses given\" &&
   [ \"\$(last off)\" = \"\$(last off_run)\" ]"
"$F" static scenes/pendulum.yaml --set "bodies.bob.position=[0.47364817766693, 0.98480775301221]" --set initial=assemble \
  -o "$OUT/assembled.csv" -q 2>"$OUT/assembled.err"
check "the same with initial: assemble: static solves it (exit 0)" "[ $? -eq 0 ]"

"$F" static tests/bad_scenes/56-joints-unsatisfiable.yaml -o "$OUT/unsat.csv" -q 2>"$OUT/unsat.err"
rc=$?
check "joints that cannot hold: exit 2, joint 'pa' named at 7:5" \
  "[ $rc -eq 2 ] && last unsat | grep -q \"56-joints-unsatisfiable.yaml:7:5: error: joint 'pa' cannot be satisfied\""

"$F" static scenes/pendulum.yaml --at nan -o "$OUT/nan.csv" 2>"$OUT/nan.err"
rc=$?
check "static --at nan: exit 2 naming --at" "[ $rc -eq 2 ] && last nan | grep -q -- '--at needs a finite time'"
"$F" modes scenes/campbell_beam.yaml --at inf -o "$OUT/inf.csv" 2>"$OUT/inf.err"
rc=$?
check "modes --at inf: exit 2 naming --at" "[ $rc -eq 2 ] && last inf | grep -q -- '--at needs a finite time'"
"$F" campbell scenes/campbell_beam.yaml --speed joints.spin.speed --speeds 0:inf:3 -o "$OUT/camp.csv" 2>"$OUT/camp.err"
rc=$?
check "campbell --speeds 0:inf:3: exit 2 naming --speeds" "[ $rc -eq 2 ] && last camp | grep -q -- '--speeds expects.*finite speeds'"
exit $fail
