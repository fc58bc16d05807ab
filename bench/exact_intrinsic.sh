#!/usr/bin/env bash
# bench/exact_intrinsic.sh — issue 32 item 4's hypothesis put to the test: the exact beam's frozen
# Newton matrix goes stale because EA's stiff direction turns with the cable's slope. The same
# continuum in intrinsic coordinates (`model: exact`, `kinematics: intrinsic`, bodies/
# beam_intrinsic.c: constant stiffness; the default since issue 32 item 4) against the cable (`kinematics: cable`) and
# the complete model at the same settings: the pendulum's first 0.2 s and 0.5 s and the omega0 = 4
# and 15 spin-ups (20 s), under auto (radau9), radau5 and IDA. Per run: steps, Jacobians, Newton
# iterations, convergence failures (counts: the last of REPS runs, default 3) and the median CPU,
# and the exact variants' largest tip_v difference to the cable's run (the two discretizations of
# one continuum). Into bench/results/exact_intrinsic.csv and a table on stdout.
#   bash bench/exact_intrinsic.sh [--reps N] [--integrators "auto radau5 ida"]
set -euo pipefail
cd "$(dirname "$0")/.."
ROOT=$PWD
F=${FLEXMBD:-$ROOT/build/flexmbd}
RES=${RESULTS:-$ROOT/bench/results}
. bench/lib.sh
REPS=3
INTEGRATORS="auto radau5 ida"
while [ $# -gt 0 ]; do
  case $1 in
    --reps) REPS=$2; shift ;;
    --integrators) INTEGRATORS=$2; shift ;;
    -h|--help) sed -n 2,12p "$0"; exit 0 ;;
    *) echo "exact_intrinsic.sh: unknown argument '$1'" >&2; exit 2 ;;
  esac
  shift
done
mkdir -p "$RES"
WORK=$(mktemp -d)
trap 'rm -rf "$WORK"' EXIT
CSV=$RES/exact_intrinsic.csv
echo "case,integrator,variant,steps,jacobians,newton_iters,conv_fails,cpu_s_median,tip_v_diff_to_cable" > "$CSV"
# case|scene|settings
cases=(
  "pendulum 0.2 s|scenes/paper/pendulum.yaml|solver.t_end=0.2"
  "pendulum 0.5 s|scenes/paper/pendulum.yaml|solver.t_end=0.5"
  "spin-up w4|scenes/paper/spinup_w4.yaml|"
  "spin-up w15|scenes/paper/spinup_w15.yaml|"
)
variant_sets() { # variant -> its --set arguments
  case $1 in
    complete) echo "--set bodies.beam.model=complete" ;;
    cable) echo "--set bodies.beam.model=exact --set bodies.beam.kinematics=cable" ;;
    intrinsic) echo "--set bodies.beam.model=exact --set bodies.beam.kinematics=intrinsic" ;;
  esac
}
for c in "${cases[@]}"; do
  name=${c%%|*}
  rest=${c#*|}
  scene=${rest%%|*}
  sets=()
  for kv in ${rest#*|}; do sets+=(--set "$kv"); done
  for i in $INTEGRATORS; do
    for v in complete cable intrinsic; do : > "$WORK/cpu.$v"; done
    for ((k = 0; k < REPS; ++k)); do
      for v in complete cable intrinsic; do
        # shellcheck disable=SC2046
        line=$("$F" run "$scene" -o "$WORK/$v.csv" --quiet $(variant_sets $v) --set "solver.integrator=$i" \
          "${sets[@]}" 2>&1 | tail -1 || true)
        echo "$line" | stat_field cpu_s >> "$WORK/cpu.$v"
        echo "$line" > "$WORK/stats.$v"
      done
    done
    for v in complete cable intrinsic; do
      st=$(cat "$WORK/stats.$v")
      d=$(tip_err "$WORK/cable.csv" "$WORK/$v.csv" || echo nan)
      echo "$name,$i,$v,$(echo "$st" | stat_field steps),$(echo "$st" | stat_field jacobians),$(echo "$st" | stat_field newton_iters),$(echo "$st" | stat_field conv_fails),$(median < "$WORK/cpu.$v"),$d" >> "$CSV"
    done
  done
done
echo "case integrator: complete / cable / intrinsic -- steps; Jacobians; Newton iterations; conv_fails; CPU s (median of $REPS); intrinsic's max |tip_v - cable's| m"
awk -F, 'NR > 1 { k = $1 " " $2; if (!(k in seen)) { seen[k] = 1; order[++n] = k }
    s[k] = s[k] (s[k] == "" ? "" : " / ") $4; j[k] = j[k] (j[k] == "" ? "" : " / ") $5; it[k] = it[k] (it[k] == "" ? "" : " / ") $6
    f[k] = f[k] (f[k] == "" ? "" : " / ") $7; c[k] = c[k] (c[k] == "" ? "" : " / ") $8; if ($3 == "intrinsic") d[k] = $9 }
  END { for (m = 1; m <= n; ++m) { k = order[m]
    printf "%-22s steps %s; Jac %s; iters %s; cf %s; CPU %s; diff %s\n", k, s[k], j[k], it[k], f[k], c[k], d[k] } }' "$CSV"
