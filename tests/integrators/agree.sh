#!/bin/sh
# radau5 and IDA agree on every shipped scene run on the GGL formulation (the parallelograms run
# the projected formulation whatever the integrator). Both at rtol 1e-9 with the derived atol (the
# slider-crank 1e-10: IDA's strain energy there errs 2.3e-4 of its range at 1e-9, 4.8e-5 at 1e-10,
# radau5's 6.8e-6), the scene otherwise as shipped (long runs cut short: t_end below); every
# solution column the scene writes must agree within 2e-4 of its range (flexmbd compare --rtol 2e-4
# --atol 1e-9), which both backends meet against a converged solution at these rtols
# (bench/auto.sh, key columns: IDA 4e-5 .. 5e-4 of the range at rtol 1e-8, below 1.3e-5 at 1e-10;
# radau5 below 4e-5 at 1e-8; measured here: at most 0.49 of the tolerance, the rotor), while a wrong stage,
# error estimate, dense output or Newton solve in either is off by orders more. Not compared, each
# for a measured reason: constraint.position and .velocity (drift, not solution: radau5's rows
# between steps, its collocation polynomial, hold it to ~2e-7, IDA's to 1e-9); energy.total and energy.balance (conserved: their range is roundoff, 1e-9); reactions
# and joint powers (multipliers: radau5 is of order 3 in them, slide.reaction_y 28x and
# motor.power 20x the tolerance on the slider-crank); the beams' velocity outputs, *_rate and
# beam.omega (out of the error test under the beams' positions control: the flexible pendulum's
# beam.omega 17x, where radau5 damps the axial and bending ringing that BDF2 keeps).
# spinup_bar (a rigid bar whose motion is all prescribed by its drive) gives radau5 max_step =
# output_step: its error estimate sees no error in a motion the constraints fix, its steps grow to
# seconds and the rows between them miss the drive's profile by 0.09 rad (max_step 0.5 s: 9e-6 rad,
# 0.05 s: 6e-9 rad). Under solver.integrator: auto a rigid model runs IDA.
#   agree.sh FLEXMBD SOURCE_DIR OUT_DIR
set -u
F=$1 SRC=$2 O=$3
mkdir -p "$O"
fail=0
for case in campbell_beam double_pendulum fourbar pendulum rotor slider_crank:0.02:1e-10 spinup_bar \
  exact/spinup_w15_exact paper/pendulum:0.5 paper/spinup_w1 paper/spinup_w4 paper/spinup_w15; do
  name=${case%%:*} rest=${case#*:} t_end="" rtol=1e-9
  if [ "$name" != "$case" ]; then
    t_end="--set solver.t_end=${rest%%:*}"
    [ "${rest#*:}" != "$rest" ] && rtol=${rest#*:}
  fi
  extra=""
  [ "$name" = spinup_bar ] && extra="--set solver.max_step=0.05"
  tag=$(echo "$name" | tr / _)
  # shellcheck disable=SC2086
  "$F" run "$SRC/scenes/$name.yaml" -o "$O/$tag.ida.csv" --quiet --set solver.integrator=ida --set solver.rtol=$rtol \
    --set solver.atol=auto $t_end 2>"$O/$tag.ida.err" || { echo "FAIL: $name: the IDA run"; fail=1; continue; }
  # shellcheck disable=SC2086
  "$F" run "$SRC/scenes/$name.yaml" -o "$O/$tag.radau5.csv" --quiet --set solver.integrator=radau5 --set solver.rtol=$rtol \
    --set solver.atol=auto $t_end $extra 2>"$O/$tag.radau5.err" || { echo "FAIL: $name: the radau5 run"; fail=1; continue; }
  cols=$(head -1 "$O/$tag.ida.csv" | tr ',' '\n' | grep -v -e '^t$' -e '^constraint\.' -e '^energy\.total$' \
    -e '^energy\.balance$' -e 'reaction' -e '\.power$' -e '_rate$' -e '^beam\.omega$' | paste -sd, -)
  if "$F" compare "$O/$tag.radau5.csv" "$O/$tag.ida.csv" --rtol 2e-4 --atol 1e-9 --columns "$cols" > "$O/$tag.cmp" 2>&1; then
    echo "ok: $name: $(grep -c 'status=ok' "$O/$tag.cmp") columns agree; largest difference / tolerance: $(sed -n \
      's/.*max_abs=\([^ ]*\).* tol=\([^ ]*\).*/\1 \2/p' "$O/$tag.cmp" | awk '{ r = $1 / $2; if (r > m) m = r } END { printf "%.2f", m }')"
  else
    echo "FAIL: $name: radau5 and IDA differ beyond 2e-4 of a column's range:"
    grep -v 'status=ok' "$O/$tag.cmp" | head -5
    fail=1
  fi
done
exit $fail
