#!/bin/sh
# run_case.sh FLEXMBD SOURCE_DIR OUT_DIR CASE [--check]
# One case of the stability matrix (docs/stability.md): runs it through the command line and
# prints one line of measurements
#   case=… exit=… status=… t_reached=… t_end=… steps=… jacobians=… cpu_s=… rows=… bad_rows=…
#   energy_err=… cpos=… cvel=… tip_max=… msg="…"
# energy_err: conservative cases max|E(t) - E(0)|, driven cases max|E(t) - E(0) - W(t)| with W the
# drive's work (trapezoidal integral of JOINT.power), both divided by the largest kinetic energy;
# cpos/cvel: largest constraint residual norms; tip_max: max |tip_v| / L (beam cases).
# With --check it also applies the case's physical checks and exits 1 when one fails (ctest).
# Every case must end with exit 0 or 3, a stats line, and no non-finite row.
set -eu
F=$1; SRC=$2; OUT=$3; CASE=$4; CHECK=${5:-}
mkdir -p "$OUT"
P=$SRC/../../scenes/paper
S=$SRC/scenes
SPIN_OUT='outputs=[beam.tip_v,beam.tip_u,beam.theta,beam.omega,spin.power,energy.kinetic,energy.strain,energy.total,constraint.position,constraint.velocity]'
PEND_OUT='outputs=[beam.tip_v,beam.tip_u,beam.theta,beam.omega,energy.kinetic,energy.strain,energy.gravity,energy.total,constraint.position,constraint.velocity]'
# per case: scene, overrides, kind (driven|conservative), expected exit (0, 3, or "0|3"),
# energy tolerance (relative), constraint tolerance, max tip deflection / L
KIND=driven; EXPECT=0; ETOL=1e-3; CTOL=1e-6; TIPMAX=1; POWER=spin.power; TIPU=""
set --
case $CASE in
  slender_I*)   # I from the name, e.g. slender_I1e-14, on the 4 rad/s spin-up
    I=${CASE#slender_I}; SCENE=$P/spinup_w4.yaml
    set -- --set "bodies.beam.second_moment=$I" --set "$SPIN_OUT"; EXPECT="0|3"; ETOL=2e-3; CTOL=1e-5; TIPMAX=1 ;;
  stiff_E100)   SCENE=$P/spinup_w15.yaml; set -- --set bodies.beam.youngs_modulus=68.95e11 --set "$SPIN_OUT"; TIPMAX=0.01 ;;
  omega30)      SCENE=$P/spinup_w15.yaml; set -- --set joints.spin.omega0=30 --set "$SPIN_OUT"; TIPMAX=0.2 ;;
  omega50)      SCENE=$P/spinup_w15.yaml; set -- --set joints.spin.omega0=50 --set "$SPIN_OUT"; TIPMAX=0.3 ;;
  abrupt_w1)    # Tn = 0.5 s to 1 rad/s: peak angular acceleration 4 rad/s^2, tip lag ~0.3 L
    SCENE=$P/spinup_w1.yaml; set -- --set joints.spin.ramp_time=0.5 --set solver.t_end=5 --set "$SPIN_OUT"; TIPMAX=0.4 ;;
  abrupt_w15)   # Tn = 0.5 s to 15 rad/s: 60 rad/s^2; the static lag estimate 11 q L^4 / (120 EI) is ~8 m,
    # far beyond a beam of 1.8 m: the run must stop cleanly (or, if the model could follow, balance energy)
    SCENE=$P/spinup_w15.yaml; EXPECT="0|3"; ETOL=2e-2
    set -- --set joints.spin.ramp_time=0.5 --set solver.t_end=5 --set "$SPIN_OUT"; TIPMAX=1 ;;
  overspeed)    # positions-only error control: the abrupt start rings every axial mode (docs/stability.md)
    SCENE=$S/constant_overspeed.yaml; ETOL=2e-3; TIPMAX=0.01; TIPU=1.2482e-4
    set -- --set solver.t_end=2 --set solver.error_control=positions --set solver.output_step=0.001 ;;
  flex_pendulum) SCENE=$P/pendulum.yaml; KIND=conservative
    set -- --set bodies.beam.second_moment=2.604e-11 --set "$PEND_OUT"; EXPECT="0|3"; ETOL=1e-2; TIPMAX=1 ;;
  elements128)  SCENE=$P/spinup_w15.yaml; set -- --set bodies.beam.elements=128 --set "$SPIN_OUT"; TIPMAX=0.2 ;;
  elements256)  SCENE=$P/spinup_w15.yaml; set -- --set bodies.beam.elements=256 --set "$SPIN_OUT"; TIPMAX=0.2 ;;
  pendulum200)  SCENE=$P/pendulum.yaml; KIND=conservative
    set -- --set solver.t_end=200 --set solver.output_step=0.05 --set "$PEND_OUT"; ETOL=1e-3; TIPMAX=0.2 ;;
  pendulum5)    SCENE=$P/pendulum.yaml; KIND=conservative; set -- --set "$PEND_OUT"; ETOL=1e-4; TIPMAX=0.1 ;;
  deadpoint)    SCENE=$S/deadpoint_fourbar.yaml; POWER=motor.power; ETOL=1e-4; CTOL=1e-7 ;;
  tight_fine)   # 64 elements at rtol 1e-9: a stall (docs/stability.md); bounded by max_steps
    SCENE=$P/spinup_w15.yaml; EXPECT="0|3"
    set -- --set bodies.beam.elements=64 --set solver.rtol=1e-9 --set solver.atol=1e-11 --set solver.t_end=8 \
           --set solver.max_steps=3000 --set "$SPIN_OUT"; TIPMAX=0.2 ;;
  *) echo "run_case.sh: unknown case '$CASE'" >&2; exit 2 ;;
esac
CSV=$OUT/$CASE.csv; ERR=$OUT/$CASE.err
rm -f "$CSV"
set +e
# The matrix's checks (constraint drift <= 1e-6, energy) were calibrated on the paper spin-ups'
# former solver settings, error_control: full with atol 1e-8; those scenes now run the beam
# default (positions, atol from rtol, issue 16), which leaves velocity errors untested: the drift
# then reaches 3e-6 to 3e-5 on omega30, stiff_E100, elements128/256, slender_I1e-6. The cases keep
# the settings they were built for; an override of the case itself still wins (it comes later).
# They were built on IDA, and keep it now that a beam scene's default is Radau (radau5, now radau9; solver.integrator:
# auto, issue 23): radau5 under full control with the small explicit atol of tight_fine (1e-11, 64
# elements) crawls through Newton failures (253k steps, 66k Jacobians, 146 s CPU against IDA's
# 0.7 s; docs/performance.md, "Integrator auto", limits).
# The flexible pendulum ships at rtol 1e-10 now (its accuracy, 5.5 s for 5 s); its cases (200 s,
# slender beams) keep the settings they were built with, rtol 1e-6, atol 1e-8, IDA.
case $SCENE in
  */paper/spinup_w*) set -- --set solver.error_control=full --set solver.atol=1e-8 --set solver.integrator=ida "$@" ;;
  */paper/pendulum.yaml) set -- --set solver.rtol=1e-6 --set solver.atol=1e-8 --set solver.integrator=ida "$@" ;;
esac
"$F" run "$SCENE" -o "$CSV" --quiet "$@" 2> "$ERR"
RC=$?
set -e
STATS=$(grep '^stats:' "$ERR" | tail -1 || true)
MSG=$(grep 'error:' "$ERR" | head -1 | sed 's/.*error: //; s/"/'"'"'/g' | cut -c1-400 || true)
T_END=$(sed -n "s/^ *t_end: *\([0-9.eE+-]*\).*/\1/p" "$SCENE" | head -1)
for a in "$@"; do case $a in solver.t_end=*) T_END=${a#solver.t_end=} ;; esac; done
kv() { echo "$STATS" | sed -n "s/.* $1=\([^ ]*\).*/\1/p"; }
METRICS=$( [ -s "$CSV" ] && awk -F, -v kind="$KIND" -v power="$POWER" '
  NR == 1 { for (i = 1; i <= NF; ++i) c[$i] = i; next }
  { for (i = 1; i <= NF; ++i) if ($i !~ /^[-+]?[0-9.]+([eE][-+]?[0-9]+)?$/) { bad++; next } }
  { rows++; t = $1; e = $c["energy.total"]; k = $c["energy.kinetic"]
    if (rows == 1) { e0 = e; w = 0 } else if (kind == "driven") w += 0.5 * (t - tp) * ($c[power] + pp)
    pp = (kind == "driven") ? $c[power] : 0; tp = t
    d = e - e0 - w; if (d < 0) d = -d; if (d > de) de = d
    if (k > km) km = k
    if (("constraint.position" in c) && $c["constraint.position"] > cp) cp = $c["constraint.position"]
    if (("constraint.velocity" in c) && $c["constraint.velocity"] > cv) cv = $c["constraint.velocity"]
    if ("beam.tip_v" in c) { v = $c["beam.tip_v"]; if (v < 0) v = -v; if (v > tm) tm = v }
    if ("beam.tip_u" in c) su += $c["beam.tip_u"] }
  END { printf "rows=%d bad_rows=%d energy_err=%.3e cpos=%.3e cvel=%.3e tip_max=%.4g tip_u_mean=%.5e last_t=%s", rows, bad, (km > 0 ? de / km : de), cp, cv, tm / 1.8, (rows ? su / rows : 0), t }' "$CSV" ||
  echo "rows=0 bad_rows=0 energy_err=nan cpos=nan cvel=nan tip_max=nan tip_u_mean=nan last_t=nan")
LINE="case=$CASE exit=$RC status=$(kv status) t_reached=$(kv t_reached) t_end=${T_END:-?} steps=$(kv steps) jacobians=$(kv jacobians) cpu_s=$(kv cpu_s) $METRICS msg=\"$MSG\""
echo "$LINE"
[ "$CHECK" = --check ] || exit 0

# ---- checks -----------------------------------------------------------------------------------
fail() { echo "FAIL $CASE: $*" >&2; exit 1; }
get() { echo "$LINE" | sed -n "s/.* $1=\([^ ]*\).*/\1/p"; }
[ -n "$STATS" ] || fail "no stats line (crash or hang?): $(tail -3 "$ERR")"
case "|$EXPECT|" in *"|$RC|"*) ;; *) fail "exit $RC, expected $EXPECT: $MSG" ;; esac
[ "$(get bad_rows)" = 0 ] || fail "$(get bad_rows) rows with a non-finite or non-numeric value"
le() { awk -v a="$1" -v b="$2" 'BEGIN { exit !(a + 0 <= b + 0 && a == a + 0) }'; }
# energy balance up to the end or the stop
[ "$(get rows)" = 0 ] || le "$(get energy_err)" "$ETOL" || fail "energy balance error $(get energy_err) > $ETOL"
if [ -n "$TIPU" ]; then # mean axial tip stretch of a rod spinning at 40 rad/s: rho Omega^2 L^3 / (3 E)
  awk -v a="$(get tip_u_mean)" -v b="$TIPU" 'BEGIN { d = (a - b) / b; exit !(d < 0.02 && d > -0.02) }' || fail "mean tip_u $(get tip_u_mean) vs centrifugal stretch $TIPU"
fi
if [ "$RC" = 0 ]; then
  le "$(get cpos)" "$CTOL" || fail "constraint drift $(get cpos) > $CTOL"
  awk -v a="$(get t_reached)" -v b="$T_END" 'BEGIN { d = a - b; exit !(d < 1e-9 && d > -1e-9) }' || fail "exit 0 but t_reached $(get t_reached) != t_end $T_END"
  le "$(get tip_max)" "$TIPMAX" || fail "tip deflection $(get tip_max) L > $TIPMAX L"
  awk -v a="$(get last_t)" -v b="$(get t_reached)" 'BEGIN { d = a - b; exit !(d < 1e-9 && d > -1e-9) }' || fail "last row not at t_reached"
else
  # a clean stop: says when, and every row up to there is on disk
  echo "$MSG" | grep -q 't = ' || fail "stop message does not say when: $MSG"
  awk -v a="$(get last_t)" -v b="$(get t_reached)" 'BEGIN { exit !(a <= b + 1e-9 && b - a < 0.05 + 0.01 * b) }' ||
    fail "last row $(get last_t) far from where it stopped ($(get t_reached))"
fi
echo "ok $CASE"
