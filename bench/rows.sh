#!/usr/bin/env bash
# bench/rows.sh — what the output rows cost (issue 23 item 2: <= 10 % of a run): each scene
# stepped over its own output grid as fmb_run steps it, without rows, with the rows' values
# (fmb_outputs_eval), and with the rows written as fmb_run writes them (values, formatting, the
# CSV writer), repeats interleaved, medians (bench/rows.c says how). The step counts of the three
# must be equal (the outputs only read the state): the program fails otherwise.
#
#   bash bench/rows.sh [REPS]        (default 9; ~3 s)
#
# Cases: the w15 spin-up as shipped (2,001 rows, 10 outputs) and with a tenth of the rows
# (output_step 0.1), the w4 spin-up as shipped, the flexible pendulum's first second (its own
# output step). Results: bench/results/rows.csv
#   scene,rows,columns,steps,cpu_none_s,cpu_values_s,cpu_csv_s,rows_s,rows_share
# (columns counts t; rows_s = cpu_csv_s - cpu_none_s, rows_share = rows_s / cpu_csv_s).
set -euo pipefail
REPS=${1:-9}
case $REPS in
  -h | --help) sed -n 2,16p "$0"; exit 0 ;;
  *[!0-9]* | '' | 0) echo "rows.sh: expected a number of repeats, got '$REPS'" >&2; exit 2 ;;
esac
cd "$(dirname "$0")/.."
B=${BUILD_DIR:-build} RES=${RESULTS:-$PWD/bench/results}
mkdir -p "$RES"
cmake --build "$B" --target bench_rows >/dev/null
OUT=$RES/rows.csv
TMP=$(mktemp /tmp/flexmbd-rows.XXXXXX)
trap 'rm -f "$TMP" "$TMP.csv"' EXIT
R="$B/bench_rows -r $REPS -o $TMP.csv"
{
  $R -H scenes/paper/spinup_w15.yaml
  $R scenes/paper/spinup_w15.yaml -s solver.output_step=0.1
  $R scenes/paper/spinup_w4.yaml
  $R scenes/paper/spinup_w1.yaml
} > "$TMP"
mv "$TMP" "$OUT"
column -s, -t < "$OUT"
echo "results: $OUT"
