#!/bin/sh
# test_exact_analysis.sh FLEXMBD SOURCE_DIR OUT_DIR — the analysis commands with `model: exact`:
# static against the elastica (alpha = 1: v = 0.30172077 L, Bisshopp & Drucker), modes about the
# steady rotation at 15 rad/s against the rotating cantilever's 6.33515 rad/s, campbell at 4 rad/s
# against 4.26118, and `initial: static` starting a beam spinning at 15 rad/s in its stretched
# steady state (tip stretch rho Omega^2 L^3/(3E) = 1.75531e-5 m held, no axial ringing) where the
# scene's unstretched start rings its axial mode with the stretch's amplitude.
. "$(dirname "$0")/cli_lib.sh"

"$F" static tests/exact/scenes/elastica_exact.yaml -o "$OUT/el.csv" 2>"$OUT/el.err"
v=$(tail -1 "$OUT/el.csv" | cut -d, -f3)
echo "static, elastica alpha = 1, 16 elements: tip_v = $v m (0.30172077 L = 0.543097394 m)"
check "static: elastica tip deflection within 5e-7 m" "near '$v' 0.543097394 5e-7"

"$F" modes scenes/paper/spinup_w15.yaml --at 20 --count 1 --set bodies.beam.model=exact --set bodies.beam.elements=32 \
  -o "$OUT/modes.csv" 2>"$OUT/modes.err"
w=$(tail -1 "$OUT/modes.csv" | cut -d, -f2)
echo "modes at 15 rad/s, 32 elements: first frequency $w rad/s (6.33515)"
check "modes: first in-plane frequency at 15 rad/s within 1e-4 relative" "near '$w' 6.33515 6.3e-4"

"$F" campbell scenes/campbell_beam.yaml --speed joints.spin.speed --speeds 4 --count 1 --set bodies.beam.model=exact \
  -o "$OUT/campbell.csv" 2>"$OUT/campbell.err"
c=$(tail -1 "$OUT/campbell.csv" | cut -d, -f2)
echo "campbell at 4 rad/s: $c rad/s (4.26118)"
check "campbell: first frequency at 4 rad/s within 1e-4 relative" "near '$c' 4.26118 4.3e-4"

for init in static given; do
  "$F" run scenes/campbell_beam.yaml -o "$OUT/spin_$init.csv" --set bodies.beam.model=exact --set joints.spin.speed=15 \
    --set initial=$init --quiet 2>"$OUT/spin_$init.err"
done
# largest departure of tip_u (column 2) from the steady stretch
dev() { awk -F, -v s=1.75531e-5 'NR > 1 { d = $2 - s; if (d < 0) d = -d; if (d > m) m = d } END { print m }' "$1"; }
ds=$(dev "$OUT/spin_static.csv")
dd=$(dev "$OUT/spin_given.csv")
echo "spinning at 15 rad/s: max |tip_u - stretch| = $ds m from initial: static, $dd m from the unstretched start"
check "initial: static holds the steady stretch (1e-4 of it)" "near '$ds' 0 1.8e-9"
check "the unstretched start rings with about the stretch's amplitude" "awk -v d='$dd' 'BEGIN { exit !(d > 0.5 * 1.75531e-5) }'"
exit $fail
