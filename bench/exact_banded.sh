#!/usr/bin/env bash
# bench/exact_banded.sh — the exact beam's banded assembly (bodies/beam_exact.c exact_pattern with
# its analytic values) against its dense block, by element count (docs/models.md, "Banded
# assembly"). The omega0 = 15 spin-up's first T seconds (default 0.5) with model: exact, kinematics: cable, rtol
# 1e-7, atol 1e-9, positions only, at 4 ... 512 elements (dense to 256: it is O(n^2) memory and
# O(n^3) factorization); per run CPU per step (median of REPS, default 3) and peak resident memory.
# The exponents of CPU/step and memory against n are fitted by least squares over n >= 64.
# Output: bench/results/exact_banded.csv and exact_banded_exponents.txt.
#   bash bench/exact_banded.sh [--reps N] [--t-end T]
set -euo pipefail
cd "$(dirname "$0")/.."
ROOT=$PWD
F=${FLEXMBD:-$ROOT/build/flexmbd}
RES=${RESULTS:-$ROOT/bench/results}
REPS=3
TEND=0.5
while [ $# -gt 0 ]; do
  case $1 in
    --reps) REPS=$2; shift ;;
    --t-end) TEND=$2; shift ;;
    -h|--help) sed -n 2,9p "$0"; exit 0 ;;
    *) echo "exact_banded.sh: unknown argument '$1'" >&2; exit 2 ;;
  esac
  shift
done
mkdir -p "$RES"
WORK=$(mktemp -d)
trap 'rm -rf "$WORK"' EXIT
CSV=$RES/exact_banded.csv
echo "assembly,elements,steps,cpu_s,cpu_per_step_us,peak_kb" > "$CSV"
for asm in dense banded; do
  for ne in 4 8 16 32 64 128 256 512; do
    [ "$asm" = dense ] && [ "$ne" -gt 256 ] && continue
    cpus=()
    for r in $(seq "$REPS"); do
      /usr/bin/time -f "%M" -o "$WORK/mem" "$F" run scenes/paper/spinup_w15.yaml -o "$WORK/out.csv" \
        --set bodies.beam.model=exact --set bodies.beam.kinematics=cable --set bodies.beam.elements="$ne" --set bodies.beam.assembly="$asm" \
        --set solver.t_end="$TEND" --set solver.rtol=1e-7 --set solver.atol=1e-9 \
        --set solver.error_control=positions 2> "$WORK/err"
      stats=$(tail -n 1 "$WORK/err")
      steps=$(echo "$stats" | sed -n 's/.*steps=\([0-9]*\).*/\1/p')
      cpus+=("$(echo "$stats" | sed -n 's/.*cpu_s=\([0-9.e+-]*\).*/\1/p')")
    done
    cpu=$(printf '%s\n' "${cpus[@]}" | sort -g | sed -n "$(( (REPS + 1) / 2 ))p")
    mem=$(cat "$WORK/mem")
    awk -v a="$asm" -v n="$ne" -v s="$steps" -v c="$cpu" -v m="$mem" \
      'BEGIN { printf "%s,%d,%d,%.4f,%.2f,%d\n", a, n, s, c, 1e6 * c / s, m }' | tee -a "$CSV"
  done
done
# least-squares slope of log(y) against log(n) over n >= 64
awk -F, 'NR > 1 && $2 >= 64 {
  k = $1; x = log($2); n[k]++; sx[k] += x; sxx[k] += x * x
  y = log($5); sy[k] += y; sxy[k] += x * y
  z = log($6); sz[k] += z; sxz[k] += x * z
}
END {
  for (k in n) {
    d = n[k] * sxx[k] - sx[k] * sx[k]
    printf "%s (n >= 64): CPU per step ~ n^%.2f, peak memory ~ n^%.2f\n", k,
      (n[k] * sxy[k] - sx[k] * sy[k]) / d, (n[k] * sxz[k] - sx[k] * sz[k]) / d
  }
}' "$CSV" | sort | tee "$RES/exact_banded_exponents.txt"
