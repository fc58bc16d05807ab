#!/usr/bin/env bash
# bench/steps.sh — where the flexible pendulum's steps go (issue 23, item 5: "profile where the steps
# go: the axial modes should be damped by an L-stable method, not resolved"). docs/performance.md,
# "Where it is hardest", paragraph "Where the steps go, by kind of coordinate", reads the results.
#
#   bash bench/steps.sh            (~25 s: a 16 s reference, then 11 runs of 0.2 .. 1.1 s)
#
# scenes/paper/pendulum.yaml (16 elements, complete, 5 s) at the rtol the default needs for a tip
# error near 1e-5 m (radau5: rtol 1e-8; radau9: rtol 3e-7), once as shipped and then with the
# absolute tolerances of one kind of the beam's coordinates (axial u, bending w and w', the frame,
# all) multiplied by a factor (bench/steps.c; the engine is the tree's, untouched). Each run's tip
# error is max |beam.tip_v - reference| over the rows (flexmbd compare), the reference radau5 at
# rtol 1e-11, atol 1e-14 (8e-8 m from rtol 1e-12, atol 1e-15: bench/hardest.sh). One run each: the
# step counts are exact and the CPU only says how the cost follows them.
# Results: bench/results/steps.csv
#   integrator,rtol,kind,factor,steps,newton_iters,cpu_s,tip_error_m,mean_step_s,steps_per_second
# (steps_per_second: the steps in each second of the 5 s, colon-separated).
set -euo pipefail
case ${1:-} in -h | --help) sed -n 2,16p "$0"; exit 0 ;; '') ;; *) echo "steps.sh: no arguments expected" >&2; exit 2 ;; esac
cd "$(dirname "$0")/.."
B=${BUILD_DIR:-build} RES=${RESULTS:-$PWD/bench/results}
F=$B/flexmbd
mkdir -p "$RES"
cmake --build "$B" --target bench_steps flexmbd >/dev/null
. bench/lib.sh # stat_field
WORK=$(mktemp -d /tmp/flexmbd-steps.XXXXXX)
trap 'rm -rf "$WORK"' EXIT
P=scenes/paper/pendulum.yaml
"$F" run "$P" -o "$WORK/ref.csv" --quiet --set solver.integrator=radau5 --set solver.rtol=1e-11 --set solver.atol=1e-14 2>/dev/null
OUT=$RES/steps.csv
TMP=$WORK/steps.csv
echo "integrator,rtol,kind,factor,steps,newton_iters,cpu_s,tip_error_m,mean_step_s,steps_per_second" > "$TMP"
one() { # integrator rtol [kind factor]
  local integ=$1 rtol=$2 kind=${3:-} factor=${4:-1} line err
  line=$("$B/bench_steps" "$P" -o "$WORK/run.csv" -s solver.integrator="$integ" -s solver.rtol="$rtol" \
    ${kind:+-k "$kind" -f "$factor"})
  err=$("$F" compare "$WORK/run.csv" "$WORK/ref.csv" --columns beam.tip_v 2>&1 | stat_field max_abs)
  local steps
  steps=$(echo "$line" | stat_field steps)
  echo "$integ,$rtol,${kind:-none},$factor,$steps,$(echo "$line" | stat_field newton_iters),$(echo "$line" | stat_field cpu_s),$err,$(awk -v s="$steps" -v T="$(echo "$line" | stat_field t_end)" 'BEGIN {printf "%.3e", T / s}'),$(echo "$line" | stat_field steps_per_period)" >> "$TMP"
}
one radau5 1e-8
one radau5 1e-8 axial 1e2
one radau5 1e-8 axial 1e4
one radau5 1e-8 frame 1e2
one radau5 1e-8 bending 10
one radau5 1e-8 bending 100
one radau5 1e-8 all 10
one radau5 1e-7
one radau9 3e-7
one radau9 3e-7 axial 1e4
one radau9 3e-7 bending 10
mv "$TMP" "$OUT"
column -s, -t < "$OUT"
echo "results: $OUT"
