#!/usr/bin/env bash
# bench/pendulum_wp.sh — the shipped pendulum's work-precision table (issue 32, item 3: the paper's
# pendulum as shipped <= 1 s with a tip error <= 2e-6 m; docs/performance.md, "The shipped pendulum").
#
#   bash bench/pendulum_wp.sh [--reps N] [--tag NAME]
#
# scenes/paper/pendulum.yaml (16 elements, complete, 5 s) with only solver.* set. The converged
# solution is made once per run: radau9 at rtol 1e-12 (the reference) and at 1e-11, whose
# difference (printed and written as the row "reference rtol 1e-11") shows the reference's own
# error. Each setting: CPU (median of REPS runs' cpu_s, default 3, interleaved: one repeat of every
# setting, then the next), steps, Newton iterations and max |beam.tip_v - reference| over the
# scene's rows. The settings: radau9 with positions error control at rtol 1e-7...1e-10 (1e-10 was
# the shipped one before the max_step), with error_control: full at 1e-6, and with max_step
# 3e-4...4e-4 s, the step that keeps the bending mode at 3,242 rad/s (1.6e-6 m of tip motion)
# at omega h ~ 1 (docs/performance.md, "Where it is hardest"), at rtol 1e-5...1e-7; "shipped" is
# the scene file as it is. Results: bench/results/pendulum_wp.csv (--tag: pendulum_wp_NAME.csv).
set -euo pipefail
cd "$(dirname "$0")/.."
ROOT=$PWD
F=${FLEXMBD:-$ROOT/build/flexmbd}
RES=${RESULTS:-$ROOT/bench/results}
WORK=$(mktemp -d /tmp/flexmbd-pendwp.XXXXXX)
trap 'rm -rf "$WORK"' EXIT
REPS=3
TAG=
while [ $# -gt 0 ]; do
  case $1 in
    --reps) REPS=$2; shift 2 ;;
    --tag) TAG=_$2; shift 2 ;;
    -h | --help) sed -n 2,17p "$0"; exit 0 ;;
    *) echo "bench/pendulum_wp.sh: unknown argument '$1'" >&2; exit 2 ;;
  esac
done
. "$ROOT/bench/lib.sh" # median, stat_field, tip_err
S=scenes/paper/pendulum.yaml
OUT=$RES/pendulum_wp$TAG.csv
mkdir -p "$RES"

"$F" run "$S" -o "$WORK/ref.csv" --quiet --set solver.integrator=radau9 --set solver.rtol=1e-12 2> "$WORK/ref.err"
"$F" run "$S" -o "$WORK/ref11.csv" --quiet --set solver.integrator=radau9 --set solver.rtol=1e-11 2> "$WORK/ref11.err"
echo "label,settings,steps,newton_iters,cpu_s_median,reps,tip_err_m" > "$OUT"
echo "reference rtol 1e-11,--set solver.integrator=radau9 --set solver.rtol=1e-11,$(stat_field steps < "$WORK/ref11.err"),$(stat_field newton_iters < "$WORK/ref11.err"),$(stat_field cpu_s < "$WORK/ref11.err"),1,$(tip_err "$WORK/ref.csv" "$WORK/ref11.csv")" | tee -a "$OUT"

SETTINGS=$WORK/settings
: > "$SETTINGS"
echo "shipped|" >> "$SETTINGS"
for r in 1e-7 1e-8 1e-9 1e-10; do echo "radau9 positions rtol $r|--set solver.integrator=radau9 --set solver.error_control=positions --set solver.rtol=$r --set solver.max_step=0" >> "$SETTINGS"; done
echo "radau9 full rtol 1e-6|--set solver.integrator=radau9 --set solver.error_control=full --set solver.rtol=1e-6 --set solver.max_step=0" >> "$SETTINGS"
for hm in 3e-4 3.5e-4 4e-4; do
  for r in 1e-5 1e-6 3e-7 1e-7; do
    echo "radau9 positions rtol $r max_step $hm|--set solver.integrator=radau9 --set solver.error_control=positions --set solver.rtol=$r --set solver.max_step=$hm" >> "$SETTINGS"
  done
done

for rep in $(seq "$REPS"); do
  n=0
  while IFS='|' read -r label args; do
    n=$((n + 1))
    # shellcheck disable=SC2086 # args are words
    "$F" run "$S" -o "$WORK/run$n.csv" --quiet $args 2> "$WORK/run$n.$rep.err" < /dev/null || true
  done < "$SETTINGS"
done
n=0
while IFS='|' read -r label args; do
  n=$((n + 1))
  cpus=$(for rep in $(seq "$REPS"); do stat_field cpu_s < "$WORK/run$n.$rep.err"; done)
  e=$WORK/run$n.1.err
  echo "$label,$args,$(stat_field steps < "$e"),$(stat_field newton_iters < "$e"),$(echo "$cpus" | median),$REPS,$(tip_err "$WORK/ref.csv" "$WORK/run$n.csv")" | tee -a "$OUT"
done < "$SETTINGS"
