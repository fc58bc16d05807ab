#!/usr/bin/env bash
# bench/beam3d.sh — the spatial beam's cost (docs/spatial.md, "Spatial beam"): the paper's spin-ups at
# omega0 = 4 and 15 rad/s (16 elements, complete, 20 s) written in space (tests/spatial/scenes/
# beam_spinup.yaml) against the planar beam (scenes/paper/spinup_w*.yaml), both at the shipped rtol 1e-6:
# CPU (the stats line's cpu_s, median of 3), IDA's/Radau's residual and Jacobian counts, and the ratio
# spatial / planar. The spatial beam has no Jacobian op: the engine differences one dense block.
#   bash bench/beam3d.sh [flexmbd binary] > bench/results/beam3d.csv
set -euo pipefail
cd "$(dirname "$0")/.."
source bench/lib.sh
F=${1:-build/flexmbd}
T=$(mktemp -d)
trap 'rm -rf "$T"' EXIT
one() { # scene args... -> "cpu_s residuals jacobians"
  "$F" run "$@" -o "$T/out.csv" --quiet 2> "$T/err" || true
  echo "$(stat_field cpu_s < "$T/err") $(stat_field residuals < "$T/err") $(stat_field jacobians < "$T/err")"
}
med() { for r in 1 2 3; do one "$@"; done | sort -g -k1 | sed -n 2p; }
echo "omega0,dimension,cpu_s,residuals,jacobians,ratio"
for w in 4 15; do
  read -r c2 r2 j2 <<< "$(med scenes/paper/spinup_w$w.yaml)"
  read -r c3 r3 j3 <<< "$(med tests/spatial/scenes/beam_spinup.yaml --set joints.spin.omega0=$w)"
  echo "$w,2,$c2,$r2,$j2,1"
  echo "$w,3,$c3,$r3,$j3,$(awk -v a="$c3" -v b="$c2" 'BEGIN { printf "%.3g", a / b }')"
done
