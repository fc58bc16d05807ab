#!/usr/bin/env bash
# bench/defaults.sh — the defaults matrix (issue 16, goal 3; docs/performance.md, "Tolerance defaults").
#
#   bash bench/defaults.sh [--reps N] [--ref-rtol R]
#
# For each benchmark scene x error_control (positions, full) x atol (1e-8 given, or derived from
# rtol: `auto`) x rtol (1e-6, 1e-8): CPU s (median of REPS runs' cpu_s, the stats line), steps, and
# the error of one tracked column, max |column - reference|, against a run of the same scene at
# rtol R (default 1e-11, atol derived; 10x looser when the scene cannot reach it: the csv says
# which). The pendulum's reference at 1e-11 takes minutes (more than 2 on the machine of
# docs/performance.md).
# Results: bench/results/defaults.csv.
set -euo pipefail
cd "$(dirname "$0")/.."
ROOT=$PWD
F=${FLEXMBD:-$ROOT/build/flexmbd}
RES=${RESULTS:-$ROOT/bench/results}
WORK=$(mktemp -d /tmp/flexmbd-defaults.XXXXXX)
REPS=3
REF_RTOL=1e-11
while [ $# -gt 0 ]; do
  case $1 in
    --reps) REPS=$2; shift ;;
    --ref-rtol) REF_RTOL=$2; shift ;;
    -h|--help) sed -n 2,14p "$0"; exit 0 ;;
    *) echo "defaults.sh: unknown argument '$1'" >&2; exit 2 ;;
  esac
  shift
done
mkdir -p "$RES"
. bench/lib.sh

# scene and its tracked column
SCENES="scenes/paper/spinup_w15.yaml:beam.tip_v scenes/paper/spinup_w4.yaml:beam.tip_v scenes/paper/pendulum.yaml:beam.tip_v
scenes/rotor.yaml:blade1.tip_v scenes/slider_crank.yaml:slider.x scenes/fourbar.yaml:rocker.theta"
OUT=$RES/defaults.csv
echo "scene,column,error_control,atol,rtol,cpu_s,steps,max_abs_error,reference_rtol" > "$OUT"
for sc in $SCENES; do
  S=${sc%%:*} C=${sc#*:} B=$WORK/$(basename "$S" .yaml)
  REF=$REF_RTOL
  if ! "$F" run "$S" -o "$B.ref.csv" --quiet --set solver.rtol=$REF --set solver.atol=auto 2>/dev/null; then
    REF=$(awk -v r="$REF" 'BEGIN { printf "%g", 10 * r }')
    "$F" run "$S" -o "$B.ref.csv" --quiet --set solver.rtol=$REF --set solver.atol=auto 2>/dev/null
  fi
  for ec in positions full; do for a in 1e-8 auto; do for r in 1e-6 1e-8; do
    cpus=""; line=""
    for _ in $(seq "$REPS"); do
      line=$("$F" run "$S" -o "$B.out.csv" --set solver.rtol=$r --set solver.atol=$a --set solver.error_control=$ec \
             --reference "$B.ref.csv" --columns "$C" 2>&1 | tail -1)
      cpus="$cpus $(echo "$line" | stat_field cpu_s)"
    done
    cpu=$(echo $cpus | tr ' ' '\n' | median)
    printf '%s,%s,%s,%s,%s,%s,%s,%s,%s\n' "$(basename "$S" .yaml)" "$C" $ec $a $r "$cpu" "$(echo "$line" | stat_field steps)" \
      "$(echo "$line" | stat_field max_abs)" $REF | tee -a "$OUT"
  done; done; done
done
rm -rf "$WORK"
echo "results: $OUT"
