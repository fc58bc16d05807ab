#!/usr/bin/env bash
# bench/mesh_steps.sh — the shipped pendulum's steps, error and CPU against the mesh (issue 32,
# item 2: at a fixed rtol the steps stay bounded as the mesh is refined, each run within 1e-5 of
# the tip's range of that mesh's converged solution, CPU per simulated second <= n^1.5 over 8...128).
#
#   bash bench/mesh_steps.sh [--ns "8 16 32 64 128"] [--span T] [--tag NAME]
#
# scenes/paper/pendulum.yaml as shipped (rtol, max_step, integrator auto) with only
# bodies.beam.elements = n and solver.t_end = T (default 0.5 s) changed. Per mesh its converged
# solution: radau9 at rtol 1e-12 without max_step (the same mesh: the error is the time
# integration's, not the mesh's). Per run: steps, Newton iterations, convergence failures, CPU,
# CPU per simulated second, max |tip_v - reference| and that error over the reference's tip_v
# range (the goal: <= 1e-5). One run per mesh (the counts are exact, the CPU +-30 % on a shared
# machine). Results: bench/results/mesh_steps.csv and mesh_steps_exponents.txt (least-squares
# slopes of log steps and log CPU per simulated second against log n).
set -euo pipefail
cd "$(dirname "$0")/.."
ROOT=$PWD
F=${FLEXMBD:-$ROOT/build/flexmbd}
RES=${RESULTS:-$ROOT/bench/results}
WORK=$(mktemp -d /tmp/flexmbd-meshsteps.XXXXXX)
trap 'rm -rf "$WORK"' EXIT
NS="8 16 32 64 128"
SPAN=0.5
TAG=
while [ $# -gt 0 ]; do
  case $1 in
    --ns) NS=$2; shift 2 ;;
    --span) SPAN=$2; shift 2 ;;
    --tag) TAG=_$2; shift 2 ;;
    -h | --help) sed -n 2,15p "$0"; exit 0 ;;
    *) echo "bench/mesh_steps.sh: unknown argument '$1'" >&2; exit 2 ;;
  esac
done
. "$ROOT/bench/lib.sh" # stat_field, tip_err
S=scenes/paper/pendulum.yaml
OUT=$RES/mesh_steps$TAG.csv
mkdir -p "$RES"
echo "n,span_s,status,steps,newton_iters,conv_fails,cpu_s,cpu_per_sim_s,tip_err_m,ref_tip_range_m,err_over_range,ref_steps" > "$OUT"
for n in $NS; do
  "$F" run "$S" -o "$WORK/ref$n.csv" --quiet --set bodies.beam.elements="$n" --set solver.t_end="$SPAN" \
    --set solver.integrator=radau9 --set solver.rtol=1e-12 --set solver.max_step=0 2> "$WORK/ref$n.err" || true
  "$F" run "$S" -o "$WORK/run$n.csv" --quiet --set bodies.beam.elements="$n" --set solver.t_end="$SPAN" \
    2> "$WORK/run$n.err" || true
  e=$WORK/run$n.err
  err=$(tip_err "$WORK/ref$n.csv" "$WORK/run$n.csv")
  range=$(awk -F, 'NR == 1 { for (i = 1; i <= NF; ++i) if ($i == "beam.tip_v") c = i; next }
    NR == 2 || $c < lo { lo = $c } NR == 2 || $c > hi { hi = $c } END { printf "%.4g", hi - lo }' "$WORK/ref$n.csv")
  cpu=$(stat_field cpu_s < "$e")
  awk -v n="$n" -v sp="$SPAN" -v st="$(stat_field status < "$e")" -v s="$(stat_field steps < "$e")" \
    -v it="$(stat_field newton_iters < "$e")" -v cf="$(stat_field conv_fails < "$e")" -v cpu="$cpu" -v err="$err" \
    -v rg="$range" -v rs="$(stat_field steps < "$WORK/ref$n.err")" 'BEGIN {
      printf "%s,%s,%s,%s,%s,%s,%s,%.4g,%s,%s,%.3g,%s\n", n, sp, st, s, it, cf, cpu, cpu / sp, err, rg, err / rg, rs }' |
    tee -a "$OUT"
done
awk -F, 'NR > 1 && $3 == "ok" { x = log($1); k++; sx += x; sxx += x * x; y1 = log($4); y2 = log($8)
    s1 += x * y1; t1 += y1; s2 += x * y2; t2 += y2 }
  function slope(sxy, sy) { return (k * sxy - sx * sy) / (k * sxx - sx * sx) }
  END { if (k >= 2) printf "shipped pendulum: steps n^%.2f, CPU per simulated second n^%.2f (%d meshes)\n",
    slope(s1, t1), slope(s2, t2), k }' "$OUT" | tee "$RES/mesh_steps${TAG}_exponents.txt"
