#!/usr/bin/env bash
# bench/start.sh — what a run costs besides its steps: the w15 spin-up's start (setup, initial
# conditions, the integrator's creation) and rows, an old build beside this tree (issue 32, item 3;
# docs/performance.md, "The start and the rows").
#
#   bash bench/start.sh [--reps N] [--old COMMIT] [--tag NAME] [--instructions]
#
# scenes/paper/spinup_w15.yaml as shipped (84 steps, 2,001 rows) and cut to its first 5 steps
# (solver.t_end = output_step = 0.001: 2 rows, 1 Jacobian: nearly all of it the start), run by OLD
# (default 1f21dea, built beside the tree by bench/lib.sh's build_landed, on its own copy of the
# scene) and by this tree, repeats interleaved (one run of every build and case, then the next;
# default 11). Per build and case: the median of the runs' cpu_s (fmb_run's own clock: the start,
# the steps, the rows and the output file's close), and the median of the whole process's minor
# page faults (/usr/bin/time; on a virtual machine each first touch of a page is a fault costing
# microseconds). Results: bench/results/start.csv (--tag: start_NAME.csv). --instructions: also
# each build's instructions per function (valgrind's callgrind, inclusive: stable on a busy machine
# where times are not) for both cases, into bench/results/start_instructions.csv.
set -euo pipefail
cd "$(dirname "$0")/.."
ROOT=$PWD
F=${FLEXMBD:-$ROOT/build/flexmbd}
RES=${RESULTS:-$ROOT/bench/results}
WORK=$(mktemp -d /tmp/flexmbd-start.XXXXXX)
trap 'rm -rf "$WORK"' EXIT
REPS=11
OLD=1f21dea
TAG=
INSTR=0
while [ $# -gt 0 ]; do
  case $1 in
    --reps) REPS=$2; shift 2 ;;
    --old) OLD=$2; shift 2 ;;
    --tag) TAG=_$2; shift 2 ;;
    --instructions) INSTR=1; shift ;;
    -h | --help) sed -n 2,17p "$0"; exit 0 ;;
    *) echo "bench/start.sh: unknown argument '$1'" >&2; exit 2 ;;
  esac
done
. "$ROOT/bench/lib.sh" # median, stat_field, build_landed
build_landed "$OLD" "/tmp/fmb-$OLD"
OUT=$RES/start$TAG.csv
mkdir -p "$RES"
SCENE=scenes/paper/spinup_w15.yaml
args() { [ "$1" = five ] && echo "--set solver.t_end=0.001 --set solver.output_step=0.001" || true; }

one() { # build case rep
  local exe=$F scene=$ROOT/$SCENE
  if [ "$1" != new ]; then exe=/tmp/fmb-$1/build/flexmbd scene=/tmp/fmb-$1/$SCENE; fi
  # shellcheck disable=SC2046
  /usr/bin/time -f "stats: minor_faults=%R" -o "$WORK/$1.$2.$3.time" "$exe" run "$scene" -o "$WORK/$1.$2.csv" \
    $(args "$2") 2> "$WORK/$1.$2.$3.err" < /dev/null > /dev/null || true
}
for rep in $(seq "$REPS"); do
  for c in five full; do
    for b in "$OLD" new; do one "$b" "$c" "$rep"; done
  done
done
echo "case,build,steps,rows,cpu_s_median,process_minor_faults_median,reps" > "$OUT"
for c in five full; do
  for b in "$OLD" new; do
    cpu=$(for rep in $(seq "$REPS"); do stat_field cpu_s < "$WORK/$b.$c.$rep.err"; done | median)
    flt=$(for rep in $(seq "$REPS"); do stat_field minor_faults < "$WORK/$b.$c.$rep.time"; done | median)
    label=$b
    [ "$b" = new ] && label="this tree ($(git rev-parse --short HEAD))"
    echo "$c,$label,$(stat_field steps < "$WORK/$b.$c.1.err"),$(($(wc -l < "$WORK/$b.$c.csv") - 1)),$cpu,$flt,$REPS" >> "$OUT"
  done
done
column -s, -t < "$OUT"
awk -F, 'NR > 1 { if ($2 ~ /^this tree/) n[$1] = $5; else o[$1] = $5 }
  END { for (s in n) printf "%s: old / this tree = %.2fx\n", s, o[s] / n[s] }' "$OUT"
echo "results: $OUT"

[ "$INSTR" = 1 ] || exit 0
command -v valgrind > /dev/null || { echo "bench/start.sh: valgrind not found (--instructions)" >&2; exit 2; }
IOUT=$RES/start_instructions$TAG.csv
FUNCS="fmb_run fmb_data_new fmb_initial_conditions radau9_create fmb_schur_new radau_advance fmb_csv_row beam_integrals qsort_r"
echo "case,build,function,instructions" > "$IOUT"
for c in five full; do
  for b in "$OLD" new; do
    exe=$F scene=$ROOT/$SCENE label="this tree ($(git rev-parse --short HEAD))"
    if [ "$b" != new ]; then exe=/tmp/fmb-$b/build/flexmbd scene=/tmp/fmb-$b/$SCENE label=$b; fi
    # shellcheck disable=SC2046
    valgrind --tool=callgrind --callgrind-out-file="$WORK/cg.$b.$c" "$exe" run "$scene" -o "$WORK/cg.csv" \
      $(args "$c") > /dev/null 2>&1 < /dev/null || true
    callgrind_annotate --inclusive=yes --threshold=100 "$WORK/cg.$b.$c" 2> /dev/null > "$WORK/cg.$b.$c.txt"
    for fn in $FUNCS; do # a function and its AVX2 clone (.avx2) together
      n=$(awk -v f="$fn" 'NF >= 4 && $1 ~ /^[0-9,]+$/ { name = $(NF - 1); sub(/.*:/, "", name); sub(/\.avx2$/, "", name)
        if (name == f) { gsub(",", "", $1); s += $1 } } END { print s + 0 }' "$WORK/cg.$b.$c.txt")
      echo "$c,$label,$fn,$n" >> "$IOUT"
    done
  done
done
column -s, -t < "$IOUT"
echo "results: $IOUT"
