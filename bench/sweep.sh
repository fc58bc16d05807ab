#!/usr/bin/env bash
# bench/sweep.sh — `flexmbd sweep` throughput on this machine (docs/performance.md, "Sweeps"),
# side by side in one run, the launchers interleaved in each of REPS rounds (the machine may be
# shared: medians and ratios, not single times):
#   serial   one process, the library called in a loop (bench/sweep_serial.c): the bar
#   xargs    `xargs -P2` over `flexmbd run` (the ideal local pool of separate processes)
#   sweep    `flexmbd sweep -j 2`
# on two workloads: 400 four-bar runs (~4 ms each) and 60 spin-up runs (omega0 = 10..15 of the
# omega0 = 15 spin-up, ~45 ms each). The bar (issue 26): sweep >= 1.4x and >= 1.85x the serial loop.
# Then the dispatch cost per run (sweep -j 1: wall time not spent inside a child, per run) and the
# scheduling efficiency at 16..1024 ranks modelled from the measured run costs
# (bench/sweep_model.py). Output: bench/results/sweep.csv, sweep_model.csv, sweep.txt.
#   bash bench/sweep.sh [REPS]     (default 3)
set -euo pipefail
cd "$(dirname "$0")/.."
ROOT=$PWD
B=${BUILD_DIR:-build}
RES=${RESULTS:-$ROOT/bench/results}
REPS=${1:-3}
F=$ROOT/$B/flexmbd
W=$(mktemp -d "${TMPDIR:-/tmp}/flexmbd-bench-sweep-XXXXXX")
trap 'rm -rf "$W"' EXIT
mkdir -p "$RES"
cc -std=c11 -O3 -DNDEBUG -D_DEFAULT_SOURCE -Wall -Wextra -Iengine -Itools bench/sweep_serial.c -o "$W/serial" \
  -L"$B" -lflexmbd -Wl,-rpath,"$ROOT/$B" -lm
now() { date +%s.%N; }

declare -A SCENE GRID
SCENE[fourbar]=$ROOT/scenes/fourbar.yaml
GRID[fourbar]="bodies.crank.mass=1:2:400"
SCENE[spinup]=$ROOT/scenes/paper/spinup_w15.yaml
GRID[spinup]="joints.spin.omega0=10:15:60"

echo "workload,launcher,rep,runs,wall_s" > "$RES/sweep.csv"
for wl in fourbar spinup; do
  scene=${SCENE[$wl]}
  "$F" sweep "$scene" -o "$W/plan_$wl" --dry-run --grid "${GRID[$wl]}" > /dev/null
  plan=$W/plan_$wl/plan.csv
  runs=$(($(wc -l < "$plan") - 1))
  # xargs: one line of arguments per run, its own CSV
  path=$(head -1 "$plan" | cut -d, -f3)
  mkdir -p "$W/x_$wl"
  tail -n +2 "$plan" | awk -F, -v d="$W/x_$wl" -v p="$path" '{ print "-o", d "/" $1 ".csv", "--set", p "=" $3 }' > "$W/args_$wl"
  for rep in $(seq "$REPS"); do
    t0=$(now); "$W/serial" "$scene" "$plan" "$W/serial_$wl.csv" > /dev/null; t1=$(now)
    echo "$wl,serial,$rep,$runs,$(echo "$t1 - $t0" | bc -l)" >> "$RES/sweep.csv"
    t0=$(now); xargs -P2 -L1 -a "$W/args_$wl" "$F" run "$scene" --quiet 2> /dev/null; t1=$(now)
    echo "$wl,xargs-P2,$rep,$runs,$(echo "$t1 - $t0" | bc -l)" >> "$RES/sweep.csv"
    t0=$(now); "$F" sweep "$scene" -o "$W/s_$wl" --fresh --quiet -j 2 --grid "${GRID[$wl]}" 2> /dev/null; t1=$(now)
    echo "$wl,sweep-j2,$rep,$runs,$(echo "$t1 - $t0" | bc -l)" >> "$RES/sweep.csv"
  done
  # dispatch cost: a sweep with one child, wall time outside the children per run
  t0=$(now); "$F" sweep "$scene" -o "$W/d_$wl" --fresh --quiet -j 1 --grid "${GRID[$wl]}" 2> /dev/null; t1=$(now)
  awk -F, -v total="$(echo "$t1 - $t0" | bc -l)" -v wl="$wl" 'NR > 1 { s += $7; n++ }
    END { printf "%s: sweep -j 1 wall %.3f s, children %.3f s: %.3f ms per run outside the children (dispatch, journal, row)\n",
          wl, total, s, 1000 * (total - s) / n }' "$W/d_$wl/table.csv" | tee -a "$W/dispatch.txt"
  cut -d, -f7 "$W/d_$wl/table.csv" | tail -n +2 > "$RES/sweep_costs_$wl.txt"
  [ "$wl" = fourbar ] && DISPATCH_MS=$(awk -F, -v total="$(echo "$t1 - $t0" | bc -l)" 'NR > 1 { s += $7; n++ }
    END { printf "%.4f", 1000 * (total - s) / n }' "$W/d_$wl/table.csv")
done

# medians and ratios
{
  echo "flexmbd sweep throughput, $(date -u +%Y-%m-%d), $(nproc) cores, load $(cut -d' ' -f1-3 /proc/loadavg), $REPS rounds"
  for wl in fourbar spinup; do
    med() { awk -F, -v w="$wl" -v l="$1" '$1 == w && $2 == l { print $5 }' "$RES/sweep.csv" | sort -g |
      awk '{ a[NR] = $1 } END { print (NR % 2) ? a[(NR + 1) / 2] : (a[NR / 2] + a[NR / 2 + 1]) / 2 }'; }
    s=$(med serial); x=$(med xargs-P2); w=$(med sweep-j2)
    awk -v wl="$wl" -v s="$s" -v x="$x" -v w="$w" 'BEGIN {
      printf "%-8s median wall: serial %.3f s, xargs -P2 %.3f s, sweep -j 2 %.3f s; speed-up over serial: xargs %.2fx, sweep %.2fx; sweep/xargs %.2fx\n",
        wl, s, x, w, s / x, s / w, x / w }'
  done
  cat "$W/dispatch.txt"
} | tee "$RES/sweep.txt"
python3 bench/sweep_model.py "$RES/sweep_costs_fourbar.txt" "$RES/sweep_costs_spinup.txt" "$ROOT/bench/results/runs.csv" \
  "$DISPATCH_MS" | tee "$RES/sweep_model.csv"
