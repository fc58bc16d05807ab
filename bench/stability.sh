#!/usr/bin/env bash
# bench/stability.sh [--quick] — the stability matrix of docs/stability.md: every case of
# tests/stability/run_case.sh with its outcome, cost, energy and constraint drift, and the
# physical checks the ctest versions apply. Output: bench/results/stability.txt (one line per
# case) and bench/results/pendulum200_energy.csv (energy drift against time, 200 s pendulum).
set -uo pipefail
cd "$(dirname "$0")/.."
ROOT=$PWD
F=${FLEXMBD:-$ROOT/build/flexmbd}
RES=${RESULTS:-$ROOT/bench/results}
OUT=${STAB_WORK:-/tmp/flexmbd-stability}
mkdir -p "$RES" "$OUT"
CASES=${CASES:-"slender_I1e-14 slender_I1e-12 slender_I1e-10 slender_I1e-8 slender_I1e-6 stiff_E100 omega30 omega50 abrupt_w1
abrupt_w15 overspeed flex_pendulum deadpoint pendulum5 tight_fine elements128 elements256 pendulum200"}
[ "${1:-}" = --quick ] && CASES="slender_I1e-12 slender_I1e-10 omega30 abrupt_w1 abrupt_w15 deadpoint"
[ -n "${APPEND:-}" ] || : > "$RES/stability.txt"
for c in $CASES; do
  timeout 1200 sh tests/stability/run_case.sh "$F" tests/stability "$OUT" "$c" --check > "$OUT/$c.out" 2> "$OUT/$c.check"
  line=$(grep "^case=" "$OUT/$c.out")
  verdict=$(cat "$OUT/$c.out" "$OUT/$c.check" | grep -E "^(FAIL|ok)" | head -1)
  [ -n "$line" ] || line="case=$c TIMEOUT (1200 s)"
  echo "$line check=\"${verdict:-$(tail -1 "$OUT/$c.check")}\"" | tee -a "$RES/stability.txt"
done
# energy drift against time for the 200 s pendulum
if [ -s "$OUT/pendulum200.csv" ]; then
  awk -F, 'NR == 1 { for (i = 1; i <= NF; ++i) c[$i] = i; print "t,energy_drift_rel,drift_max_so_far"; next }
    { e = $c["energy.total"]; k = $c["energy.kinetic"]; if (NR == 2) e0 = e; if (k > km) km = k
      d = e - e0; a = d < 0 ? -d : d; if (a > m) m = a
      if ((NR - 2) % 20 == 0) printf "%s,%.4e,%.4e\n", $1, (km > 0 ? d / km : d), (km > 0 ? m / km : m) }' \
    "$OUT/pendulum200.csv" > "$RES/pendulum200_energy.csv"
fi
