#!/usr/bin/env bash
# bench/sweep.sh — `flexmbd sweep` throughput on this machine (docs/performance.md, "Sweeps"),
# side by side in one run, the launchers interleaved in each of REPS rounds (the machine may be
# shared: medians and ratios, not single times):
#   serial   one process, the library called in a loop (bench/sweep_serial.c): the bar
#   xargs    `xargs -P2` over `flexmbd run` (the ideal local pool of separate processes)
#   sweep    `flexmbd sweep -j 2 --runner spawn` (a process per run)
#   serve    `flexmbd sweep -j 2`, the default runner (auto: a persistent runner per slot when alone)
# on three workloads: 400 four-bar runs (~4 ms each), 60 spin-up runs (omega0 = 10..15 of the
# omega0 = 15 spin-up as shipped, ~18 ms each now) and the same 60 at rtol 1e-9 (spinup45: ~45 ms
# each, the cost the issue's spin-up workload had). The bar (issue 26): sweep >= 1.4x (four-bar)
# and >= 1.85x (spin-up, ~45 ms runs) the serial loop.
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
cc -std=c11 -O3 -DNDEBUG -D_DEFAULT_SOURCE -Wall -Wextra -Iengine -Ibuiltin bench/sweep_serial.c -o "$W/serial" \
  -L"$B" -lflexmbd -Wl,-rpath,"$ROOT/$B" -lm
now() { date +%s.%N; }
# timed LABEL CMD...: wall time and CPU time (user + system, children included) of CMD as
# "wall,cpu" (the CPU time does not depend on what else the machine runs, the wall time does)
timed() {
  local t0 t1
  t0=$(now)
  /usr/bin/time -f "%U %S" -o "$W/time.txt" "$@" > /dev/null 2>&1
  t1=$(now)
  echo "$(echo "$t1 - $t0" | bc -l),$(awk '{ print $1 + $2 }' "$W/time.txt")"
}

declare -A SCENE GRID
SCENE[fourbar]=$ROOT/scenes/fourbar.yaml
GRID[fourbar]="bodies.crank.mass=1:2:400"
SCENE[spinup]=$ROOT/scenes/paper/spinup_w15.yaml
GRID[spinup]="joints.spin.omega0=10:15:60"
# the issue's spin-up workload was "~45 ms each" (the shipped scene cost that on the landed build of
# the time); the engine has since made that scene ~18 ms, so the same scene at rtol 1e-9 (~45 ms)
# keeps the workload the bar was set for, beside the shipped one
sed 's/^  rtol: 1.0e-6$/  rtol: 1.0e-9/' "$ROOT/scenes/paper/spinup_w15.yaml" > "$W/spinup45.yaml"
grep -q '^  rtol: 1.0e-9$' "$W/spinup45.yaml" || { echo "sweep.sh: spinup_w15.yaml has no 'rtol: 1.0e-6' line" >&2; exit 1; }
SCENE[spinup45]=$W/spinup45.yaml
GRID[spinup45]="joints.spin.omega0=10:15:60"

echo "workload,launcher,rep,runs,wall_s,cpu_s" > "$RES/sweep.csv"
for wl in fourbar spinup spinup45; do
  scene=${SCENE[$wl]}
  "$F" sweep "$scene" -o "$W/plan_$wl" --dry-run --grid "${GRID[$wl]}" > /dev/null
  plan=$W/plan_$wl/plan.csv
  runs=$(($(wc -l < "$plan") - 1))
  # xargs: one line of arguments per run, its own CSV
  path=$(head -1 "$plan" | cut -d, -f3)
  mkdir -p "$W/x_$wl"
  tail -n +2 "$plan" | awk -F, -v d="$W/x_$wl" -v p="$path" '{ print "-o", d "/" $1 ".csv", "--set", p "=" $3 }' > "$W/args_$wl"
  for rep in $(seq "$REPS"); do
    echo "$wl,serial,$rep,$runs,$(timed "$W/serial" "$scene" "$plan" "$W/serial_$wl.csv")" >> "$RES/sweep.csv"
    echo "$wl,xargs-P2,$rep,$runs,$(timed xargs -P2 -L1 -a "$W/args_$wl" "$F" run "$scene" --quiet)" >> "$RES/sweep.csv"
    echo "$wl,sweep-j2,$rep,$runs,$(timed "$F" sweep "$scene" -o "$W/s_$wl" --fresh --quiet -j 2 --runner spawn \
      --grid "${GRID[$wl]}")" >> "$RES/sweep.csv"
    echo "$wl,serve-j2,$rep,$runs,$(timed "$F" sweep "$scene" -o "$W/s_$wl" --fresh --quiet -j 2 \
      --grid "${GRID[$wl]}")" >> "$RES/sweep.csv"
  done
  # dispatch cost: a sweep with one child; its own CPU per run (the manager's serial work: plan,
  # dispatch, journal, rows) from its summary line, and the wall time outside the children
  t0=$(now); "$F" sweep "$scene" -o "$W/d_$wl" --fresh --quiet -j 1 --runner spawn --grid "${GRID[$wl]}" 2> "$W/d_$wl.err"; t1=$(now)
  own=$(sed -n 's/.*this process: \([0-9.]*\) ms of CPU per run.*/\1/p' "$W/d_$wl.err")
  awk -F, -v total="$(echo "$t1 - $t0" | bc -l)" -v wl="$wl" -v own="$own" 'NR > 1 { s += $7; n++ }
    END { printf "%s: sweep -j 1: its own CPU %.3f ms per run; wall %.3f s, in children %.3f s: %.3f ms per run outside them\n",
          wl, own, total, s, 1000 * (total - s) / n }' "$W/d_$wl/table.csv" | tee -a "$W/dispatch.txt"
  cut -d, -f7 "$W/d_$wl/table.csv" | tail -n +2 > "$RES/sweep_costs_$wl.txt"
  [ "$wl" = fourbar ] && DISPATCH_MS=$own
done

# medians and ratios
{
  echo "flexmbd sweep throughput, $(date -u +%Y-%m-%d), $(nproc) cores, load $(cut -d' ' -f1-3 /proc/loadavg), $REPS rounds"
  for wl in fourbar spinup spinup45; do
    med() { awk -F, -v w="$wl" -v l="$1" -v c="$2" '$1 == w && $2 == l { print $c }' "$RES/sweep.csv" | sort -g |
      awk '{ a[NR] = $1 } END { print (NR % 2) ? a[(NR + 1) / 2] : (a[NR / 2] + a[NR / 2 + 1]) / 2 }'; }
    s=$(med serial 5); x=$(med xargs-P2 5); w=$(med sweep-j2 5); v=$(med serve-j2 5)
    cs=$(med serial 6); cx=$(med xargs-P2 6); cw=$(med sweep-j2 6); cv=$(med serve-j2 6)
    awk -v wl="$wl" -v s="$s" -v x="$x" -v w="$w" -v v="$v" -v cs="$cs" -v cx="$cx" -v cw="$cw" -v cv="$cv" 'BEGIN {
      printf "%-9s median wall: serial %.3f s, xargs -P2 %.3f s, sweep --runner spawn %.3f s, sweep (default: runners) %.3f s; over serial: xargs %.2fx, spawn %.2fx, default %.2fx\n",
        wl, s, x, w, v, s / x, s / w, s / v
      printf "%-9s median CPU (user+sys): serial %.3f s, xargs -P2 %.3f s, sweep --runner spawn %.3f s, sweep (default: runners) %.3f s; on 2 free cores at most: xargs %.2fx, spawn %.2fx, default %.2fx the serial loop\n",
        wl, cs, cx, cw, cv, 2 * cs / cx, 2 * cs / cw, 2 * cs / cv }'
  done
  cat "$W/dispatch.txt"
} | tee "$RES/sweep.txt"
python3 bench/sweep_model.py "$RES/sweep_costs_fourbar.txt" "$RES/sweep_costs_spinup.txt" "$ROOT/bench/results/runs.csv" \
  "$DISPATCH_MS" | tee "$RES/sweep_model.csv"
