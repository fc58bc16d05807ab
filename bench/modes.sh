#!/usr/bin/env bash
# bench/modes.sh — cost of `flexmbd static`, `modes` (4 modes, dense and sparse eigen-solver) and
# `campbell` (8 speeds, 2 modes, auto) against the element count of the rotating beam
# (tests/analysis/scenes/rotating.yaml, complete model, 4 rad/s), median of 3 runs each, from the
# commands' own cpu_s (static, modes) and wall time (campbell). modes - static is the modal part:
# the system Jacobian at two cj (the beam's difference blocks, O(n^2) residuals) plus the
# eigen-solution: dense LAPACK dgeev on the 2n first-order form, O(n^3) with a large constant, or
# shift-invert Arnoldi (ARPACK) on one KLU factorization of the saddle-point matrix.
# Output: bench/results/modes.csv and modes_exponents.txt.
#   bash bench/modes.sh [--quick]      (--quick: up to 64 elements; default up to 256)
set -euo pipefail
cd "$(dirname "$0")/.."
ROOT=$PWD
F=${FLEXMBD:-${BUILD_DIR:-build}/flexmbd}
RES=${RESULTS:-$ROOT/bench/results}
NS="8 16 32 64 128 256"; [ "${1:-}" = --quick ] && NS="8 16 32 64"
mkdir -p "$RES"
scene=tests/analysis/scenes/rotating.yaml
cpu() { # command...: cpu_s of the stats line
  "$@" 2>&1 >/dev/null | awk '/^stats:/ { for (i = 2; i <= NF; ++i) { split($i, kv, "="); if (kv[1] == "cpu_s") c = kv[2] } } END { print c }'
}
median3() { printf '%s\n' "$@" | sort -g | sed -n 2p; }
echo "elements,coordinates,static_cpu_s,modes_dense_cpu_s,modes_sparse_cpu_s,campbell8_wall_s" > "$RES/modes.csv"
for n in $NS; do
  s=(); m=(); p=(); c=()
  for r in 1 2 3; do
    s+=("$(cpu "$F" static $scene --set bodies.beam.elements=$n -q -o /dev/null)")
    m+=("$(cpu "$F" modes $scene --set bodies.beam.elements=$n -q --count 4 --eigen dense -o /dev/null)")
    p+=("$(cpu "$F" modes $scene --set bodies.beam.elements=$n -q --count 4 --eigen sparse -o /dev/null)")
    t0=$(date +%s.%N)
    "$F" campbell $scene --set bodies.beam.elements=$n --speed joints.spin.speed --speeds 0:14:8 --count 2 -o - >/dev/null 2>&1
    c+=("$(awk -v a="$t0" -v b="$(date +%s.%N)" 'BEGIN { printf "%.4f", b - a }')")
  done
  S=$(median3 "${s[@]}"); M=$(median3 "${m[@]}"); P=$(median3 "${p[@]}"); C=$(median3 "${c[@]}")
  echo "$n,$((3 + 3 * n)),$S,$M,$P,$C" | tee -a "$RES/modes.csv"
done
# least-squares slopes of log(cost) against log(n) over n >= 32
awk -F, 'NR > 1 && $1 >= 32 { x = log($1); n++; sx += x; sxx += x * x
           for (k = 3; k <= 6; ++k) { y = log($k > 0 ? $k : 1e-9); sy[k] += y; sxy[k] += x * y } }
  END { if (n < 2) exit; d = n * sxx - sx * sx
        printf "exponents (n >= 32): static %.2f, modes dense %.2f, modes sparse %.2f, campbell %.2f\n",
          (n * sxy[3] - sx * sy[3]) / d, (n * sxy[4] - sx * sy[4]) / d, (n * sxy[5] - sx * sy[5]) / d, (n * sxy[6] - sx * sy[6]) / d }' \
  "$RES/modes.csv" | tee "$RES/modes_exponents.txt"
