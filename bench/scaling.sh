#!/usr/bin/env bash
# bench/scaling.sh — residual and Jacobian cost of the complete beam against the element count
# (8 ... 256), fitted exponents, a plot, and full runs of the 15 rad/s spin-up at 16 ... 256
# elements through the command line. Output: bench/results/scaling.csv, scaling_runs.csv,
# scaling.png. Needs a build (BUILD_DIR, default build) for the libraries.
#   bash bench/scaling.sh [--quick]
set -euo pipefail
cd "$(dirname "$0")/.."
ROOT=$PWD
B=${BUILD_DIR:-build}
RES=${RESULTS:-$ROOT/bench/results}
QUICK=0; [ "${1:-}" = --quick ] && QUICK=1
mkdir -p "$RES"
EXE=$B/bench_scaling
cc -std=c11 -O3 -DNDEBUG -D_DEFAULT_SOURCE -Wall -Wextra -Wpedantic -Wshadow -Iengine -Itools bench/scaling.c -o "$EXE" \
  "$B/libflexmbd.a" -lsundials_idas -lsundials_nvecserial -lsundials_sunlinsolklu \
  -lsundials_sunmatrixsparse -lsundials_sunlinsoldense -lsundials_sunmatrixdense -lklu -lyaml -lm
NS="8 16 32 64 128 256"; [ $QUICK = 1 ] && NS="8 16 32 64"
"$EXE" scenes/paper/spinup_w15.yaml $NS | tee "$RES/scaling.csv"
# least-squares slope of log(cost) against log(n) over n >= 32 (the asymptotic range)
awk -F, 'NR > 1 && $1 >= 32 { x = log($1); n++; sx += x; sxx += x * x
           for (k = 4; k <= 6; ++k) { y = log($k); sy[k] += y; sxy[k] += x * y } }
  END { if (n < 2) exit; d = n * sxx - sx * sx
        printf "exponents (n >= 32): body residual %.2f, system residual %.2f, Jacobian %.2f\n",
          (n * sxy[4] - sx * sy[4]) / d, (n * sxy[5] - sx * sy[5]) / d, (n * sxy[6] - sx * sy[6]) / d }' "$RES/scaling.csv" |
  tee "$RES/scaling_exponents.txt"
# whole runs: the spin-up at 15 rad/s, 20 s, rtol 1e-6 (256 elements must run)
F=${FLEXMBD:-$B/flexmbd}
RUNNS="16 32 64 128 256"; [ $QUICK = 1 ] && RUNNS="16 32"
echo "elements,status,t_reached,steps,residuals,jacobians,newton_iters,cpu_s,tip_v_end" > "$RES/scaling_runs.csv"
for n in $RUNNS; do
  timeout 900 "$F" run scenes/paper/spinup_w15.yaml -o "$B/scaling_$n.csv" --quiet --set bodies.beam.elements=$n 2> "$B/scaling_$n.err" || true
  s=$(grep '^stats:' "$B/scaling_$n.err" | tail -1)
  tip=$(tail -1 "$B/scaling_$n.csv" | cut -d, -f2)
  # the stats line's fields by name (keys may be added before cpu_s)
  fields=$(awk '{ for (i = 2; i <= NF; ++i) { split($i, kv, "="); f[kv[1]] = kv[2] }
                  printf "%s,%s,%s,%s,%s,%s,%s", f["status"], f["t_reached"], f["steps"], f["residuals"], f["jacobians"], f["newton_iters"], f["cpu_s"] }' <<< "$s")
  echo "$n,$fields,$tip" | tee -a "$RES/scaling_runs.csv"
done
if command -v gnuplot > /dev/null; then
  gnuplot <<GP
set terminal pngcairo size 800,560 font ',10'
set output '$RES/scaling.png'
set datafile separator ','
set logscale xy 2
set logscale y 10
set format y '10^{%L}'
set xlabel 'elements n'
set ylabel 'CPU time per call, microseconds (median)'
set title 'complete beam: cost per evaluation against the element count'
set key top left
set grid
f(x) = x
plot '$RES/scaling.csv' using 1:4 skip 1 with linespoints title 'beam residual', \
     '' using 1:5 skip 1 with linespoints title 'DAE residual', \
     '' using 1:6 skip 1 with linespoints title 'iteration matrix (Jacobian)', \
     [32:256] 0.5 * x title 'slope 1' dashtype 2, [32:256] 0.5 * x * x title 'slope 2' dashtype 3
GP
fi
