#!/usr/bin/env bash
# bench/beam_jacobian.sh — the beam's analytic Jacobian against the engine's finite differences
# (docs/performance.md, "Analytic beam Jacobian"): CPU (the stats line's cpu_s, median of 3),
# IDA's residual and Jacobian counts and the peak resident memory of
#   - scenes/paper/spinup_w15.yaml as shipped (16 elements, complete, dense assembly, 20 s),
#   - the omega0 = 4 spin-up's first 0.05 s at 64, 256, 1024 elements (banded assembly),
# each with the analytic Jacobian and with `jacobian: differences` (the beam's Jacobian ops
# switched off at load: the engine differences the residual, as before this work).
# `residuals` counts IDA's calls only; the finite-difference Jacobian's own residual
# evaluations (engine/fd.c) are not in it.
#   bash bench/beam_jacobian.sh [flexmbd binary] > bench/results/beam_jacobian.csv
set -euo pipefail
cd "$(dirname "$0")/.."
F=${1:-build/flexmbd}
T=$(mktemp -d)
trap 'rm -rf "$T"' EXIT
one() { # fd(0/1) scene args... -> "cpu_s,residuals,jacobians,steps,maxrss_kb,status"
  local fd=$1; shift
  local jac=analytic
  if [ "$fd" = 1 ]; then jac=differences; fi
  /usr/bin/time -f "%M" -o "$T/time" "$F" run "$@" --set bodies.beam.jacobian=$jac -o "$T/out.csv" --quiet 2> "$T/err" || true
  awk -v rss="$(tail -1 "$T/time")" '/^stats:/ { for (i = 2; i <= NF; ++i) { split($i, kv, "="); f[kv[1]] = kv[2] }
    printf "%s,%s,%s,%s,%s,%s\n", f["cpu_s"], f["residuals"], f["jacobians"], f["steps"], rss, f["status"] }' "$T/err" | tail -1
}
median3() { for r in 1 2 3; do one "$@"; done | sort -t, -g -k1 | sed -n 2p; }
echo "case,elements,jacobian,cpu_s,residuals,jacobians,steps,maxrss_kb,status"
for fd in 0 1; do
  j=$([ $fd = 1 ] && echo fd || echo analytic)
  echo "spinup_w15,16,$j,$(median3 $fd scenes/paper/spinup_w15.yaml)"
  for n in ${NS:-64 256 1024}; do
    echo "spinup_w4_0.05s,$n,$j,$(median3 $fd scenes/paper/spinup_w4.yaml --set bodies.beam.elements=$n --set solver.t_end=0.05)"
  done
done
