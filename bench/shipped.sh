#!/usr/bin/env bash
# bench/shipped.sh — the two shipped paper scenes' per-step cost, an old build beside this tree
# (issue 32, item 3: radau's per-step cost; docs/performance.md, "The shipped pendulum").
#
#   bash bench/shipped.sh [--reps N] [--old COMMIT] [--tag NAME] [--scene pendulum|spinup_w15]
#
# scenes/paper/pendulum.yaml and scenes/paper/spinup_w15.yaml as shipped, run by OLD (default
# 2a91686, built beside the tree by bench/lib.sh's build_landed, on its own copy of the scenes) and
# by this tree, repeats interleaved (one run of every build and scene, then the next; default 7),
# CPU the median of the runs' cpu_s. Per build and scene: steps, residuals, Newton iterations,
# Jacobians, the median CPU, CPU per step, and max |beam.tip_v - converged| at the scene's rows:
# the pendulum against tests/beam/data/pendulum_converged_16.csv (radau9 rtol 1e-12, stored for
# tests/beam/shipped_pendulum.sh), the spin-up against this tree's IDA at rtol 1e-12 (made here;
# bench/hardest.sh's reference). --scene: that scene only (the spin-up alone takes seconds, so
# --reps 21 is cheap). Results: bench/results/shipped.csv (--tag: shipped_NAME.csv).
set -euo pipefail
cd "$(dirname "$0")/.."
ROOT=$PWD
F=${FLEXMBD:-$ROOT/build/flexmbd}
RES=${RESULTS:-$ROOT/bench/results}
WORK=$(mktemp -d /tmp/flexmbd-shipped.XXXXXX)
trap 'rm -rf "$WORK"' EXIT
REPS=7
OLD=2a91686
TAG=
SCENES="pendulum spinup_w15"
while [ $# -gt 0 ]; do
  case $1 in
    --reps) REPS=$2; shift 2 ;;
    --old) OLD=$2; shift 2 ;;
    --tag) TAG=_$2; shift 2 ;;
    --scene) SCENES=$2; shift 2 ;;
    -h | --help) sed -n 2,16p "$0"; exit 0 ;;
    *) echo "bench/shipped.sh: unknown argument '$1'" >&2; exit 2 ;;
  esac
done
. "$ROOT/bench/lib.sh" # median, stat_field, tip_err (the references have the scenes' rows), build_landed
build_landed "$OLD" "/tmp/fmb-$OLD"
OUT=$RES/shipped$TAG.csv
mkdir -p "$RES"

case " $SCENES " in *" spinup_w15 "*)
  "$F" run scenes/paper/spinup_w15.yaml -o "$WORK/spin_ref.csv" --quiet --set solver.integrator=ida \
    --set solver.rtol=1e-12 --set solver.atol=auto 2> /dev/null ;;
esac
PEND_REF=$ROOT/tests/beam/data/pendulum_converged_16.csv

one() { # build scene out err
  if [ "$1" = new ]; then
    "$F" run "$2" -o "$3" --quiet 2> "$4" < /dev/null || true
  else
    (cd "/tmp/fmb-$1/build" && ./flexmbd run "/tmp/fmb-$1/$2" -o "$3" --quiet 2> "$4" < /dev/null || true)
  fi
}
for rep in $(seq "$REPS"); do
  for scene in $SCENES; do
    for b in "$OLD" new; do one "$b" "scenes/paper/$scene.yaml" "$WORK/$b.$scene.csv" "$WORK/$b.$scene.$rep.err"; done
  done
done
echo "scene,build,steps,residuals,newton_iters,jacobians,cpu_s_median,reps,cpu_us_per_step,tip_err_m" > "$OUT"
for scene in $SCENES; do
  ref=$WORK/spin_ref.csv
  [ "$scene" = pendulum ] && ref=$PEND_REF
  for b in "$OLD" new; do
    e=$WORK/$b.$scene.1.err
    cpu=$(for rep in $(seq "$REPS"); do stat_field cpu_s < "$WORK/$b.$scene.$rep.err"; done | median)
    steps=$(stat_field steps < "$e")
    label=$b
    [ "$b" = new ] && label="this tree ($(git rev-parse --short HEAD))"
    echo "$scene,$label,$steps,$(stat_field residuals < "$e"),$(stat_field newton_iters < "$e"),$(stat_field jacobians < "$e"),$cpu,$REPS,$(awk -v c="$cpu" -v s="$steps" 'BEGIN { printf "%.1f", 1e6 * c / s }'),$(tip_err "$ref" "$WORK/$b.$scene.csv")" >> "$OUT"
  done
done
column -s, -t < "$OUT"
awk -F, 'NR > 1 { if ($2 ~ /^this tree/) n[$1] = $7; else o[$1] = $7 }
  END { for (s in n) printf "%s: old / this tree = %.2fx\n", s, o[s] / n[s] }' "$OUT"
echo "results: $OUT"
