#!/usr/bin/env bash
# bench/auto.sh — the matrix behind `solver.integrator: auto` and the shipped scenes' accuracy
# (issue 23; docs/performance.md, "Integrator auto").
#
#   bash bench/auto.sh [--reps N] [--rtols "1e-4 1e-6 1e-8 1e-10"] [--only NAME] [--timeout S]
#
# For every scene in scenes/ (except the parallelograms, which run on the projected formulation
# whatever the integrator: their rows are the scene as shipped) and one key output column each:
#   - a reference: the scene at a tight tolerance (beams: radau5 at rtol 1e-11, atol 1e-14;
#     rigid mechanisms: ida at rtol 1e-12, atol 1e-14; the parallelograms: their projected
#     formulation at rtol 1e-10 or, where it stops there, 1e-9, atol rtol/100), and the column's
#     range (max - min) in it;
#   - each integrator (ida, radau5) at each rtol with the derived atol (`atol: auto`, the default
#     when a scene gives none), and the scene as shipped with the default integrator and with each
#     one by name.
# Per run: CPU s (median of REPS runs' cpu_s, default 1: the matrix takes ~10 min of CPU on the
# machine of docs/performance.md), steps, the backend the stats line names, max |column -
# reference| and that divided by the range. A run over TIMEOUT seconds (default 60) is recorded as
# status=timeout. Results: bench/results/auto.csv.
set -euo pipefail
cd "$(dirname "$0")/.."
ROOT=$PWD
F=${FLEXMBD:-$ROOT/build/flexmbd}
RES=${RESULTS:-$ROOT/bench/results}
WORK=$(mktemp -d /tmp/flexmbd-auto.XXXXXX)
trap 'rm -rf "$WORK"' EXIT
REPS=1
RTOLS="1e-4 1e-6 1e-8 1e-10"
ONLY=""
TIMEOUT=60
while [ $# -gt 0 ]; do
  case $1 in
    --reps) REPS=$2; shift ;;
    --rtols) RTOLS=$2; shift ;;
    --only) ONLY=$2; shift ;;
    --timeout) TIMEOUT=$2; shift ;;
    -h|--help) sed -n 2,22p "$0"; exit 0 ;;
    *) echo "auto.sh: unknown argument '$1'" >&2; exit 2 ;;
  esac
  shift
done
mkdir -p "$RES"
. "$ROOT/bench/lib.sh" # median, stat_field

# scene:column:kind (beam, rigid, projected)
SCENES="scenes/campbell_beam.yaml:beam.tip_u:beam scenes/double_pendulum.yaml:rod2.theta:rigid
scenes/fourbar.yaml:rocker.theta:rigid scenes/pendulum.yaml:bob.x:rigid scenes/rotor.yaml:blade1.tip_v:beam
scenes/slider_crank.yaml:rod.tip_v:beam scenes/spinup_bar.yaml:bar.omega:rigid
scenes/exact/spinup_w15_exact.yaml:beam.tip_v:beam scenes/paper/pendulum.yaml:beam.tip_v:beam
scenes/paper/spinup_w1.yaml:beam.tip_v:beam scenes/paper/spinup_w4.yaml:beam.tip_v:beam
scenes/paper/spinup_w15.yaml:beam.tip_v:beam scenes/parallelogram.yaml:crank1.theta:projected
scenes/parallelogram_chain.yaml:crank3.theta:projected"

OUT=$RES/auto${ONLY:+_${ONLY//\//_}}.csv
echo "scene,column,range,integrator,rtol,atol,status,backend,cpu_s,steps,max_abs_error,error_over_range,reference" > "$OUT"

# one configuration, REPS times: the last stats/compare line's fields
measure() { # scene column ref range label rtol atol [overrides...]
  local S=$1 C=$2 REF=$3 RANGE=$4 LABEL=$5 R=$6 A=$7; shift 7
  local cpus="" line="" status=""
  for _ in $(seq "$REPS"); do
    # the whole output: the compare line (stdout) and the stats line (stderr), in either order
    if line=$(timeout "$TIMEOUT" "$F" run "$S" -o "$WORK/out.csv" --quiet "$@" --reference "$REF" --columns "$C" 2>&1); then :; fi
    if [[ $line != *status=* ]]; then status=timeout; break; fi
    cpus="$cpus $(echo "$line" | stat_field cpu_s)"
  done
  local err="" rel="" backend="" steps="" cpu=""
  if [ "$status" != timeout ]; then
    status=$(echo "$line" | stat_field status)
    err=$(echo "$line" | stat_field max_abs)
    rel=$(awk -v e="$err" -v r="$RANGE" 'BEGIN { if (r > 0 && e != "") printf "%.2e", e / r }')
    steps=$(echo "$line" | stat_field steps)
    cpu=$(echo $cpus | tr ' ' '\n' | median)
    backend=$(echo "$line" | stat_field integrator)
  fi
  printf '%s,%s,%s,%s,%s,%s,%s,%s,%s,%s,%s,%s,%s\n' "$NAME" "$C" "$RANGE" "$LABEL" "$R" "$A" "$status" \
    "$backend" "$cpu" "$steps" "$err" "$rel" "$REFDESC" | tee -a "$OUT"
}

for sc in $SCENES; do
  S=${sc%%:*} rest=${sc#*:} C=${rest%%:*} KIND=${rest#*:} NAME=${S#scenes/}
  NAME=${NAME%.yaml} # paper/pendulum apart from the rigid pendulum
  [ -n "$ONLY" ] && [ "$ONLY" != "$NAME" ] && continue
  REF=$WORK/${NAME//\//_}.ref.csv
  case $KIND in
    beam) REFDESC="radau5 rtol 1e-11 atol 1e-14"
          "$F" run "$S" -o "$REF" --quiet --set solver.integrator=radau5 --set solver.rtol=1e-11 --set solver.atol=1e-14 ;;
    rigid) REFDESC="ida rtol 1e-12 atol 1e-14"
          "$F" run "$S" -o "$REF" --quiet --set solver.integrator=ida --set solver.rtol=1e-12 --set solver.atol=1e-14 ;;
    projected) # its formulation stops at a flat position at rtol 1e-10 (h23s's item); 1e-9 then
          REFDESC=""
          for r in 1e-10 1e-9; do
            if "$F" run "$S" -o "$REF" --quiet --set solver.rtol=$r --set solver.atol=$(awk -v r=$r 'BEGIN { print r / 100 }') 2>/dev/null; then
              REFDESC="projected rtol $r atol rtol/100"; break
            fi
          done
          if [ -z "$REFDESC" ]; then echo "$NAME: no reference (the projected formulation stops at rtol 1e-9 and 1e-10)" >&2; continue; fi ;;
  esac
  RANGE=$(awk -F, -v c="$C" 'NR == 1 { for (i = 1; i <= NF; ++i) if ($i == c) k = i; next }
          k { v = $k + 0; if (NR == 2 || v < lo) lo = v; if (NR == 2 || v > hi) hi = v }
          END { printf "%.6g", hi - lo }' "$REF")
  measure "$S" "$C" "$REF" "$RANGE" shipped "" ""
  [ "$KIND" = projected ] && continue
  for integ in ida radau5; do
    measure "$S" "$C" "$REF" "$RANGE" "shipped:$integ" "" "" --set solver.integrator=$integ
  done
  for integ in ida radau5; do for r in $RTOLS; do
    measure "$S" "$C" "$REF" "$RANGE" "$integ" "$r" auto --set solver.integrator=$integ --set solver.rtol=$r --set solver.atol=auto
  done; done
done
echo "results: $OUT"
