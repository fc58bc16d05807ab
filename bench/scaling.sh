#!/usr/bin/env bash
# bench/scaling.sh — cost and memory of the beam against the element count (docs/performance.md,
# "Scaling"), the banded assembly beside the dense one and beside the landed 0a88803.
#   1. per call, through the library (bench/scaling.c): beam residual, DAE residual, Jacobian (the
#      beam's analytic one, and with `jacobian: differences` the engine's differences: scaling_fd.csv),
#      Newton-matrix factorization and solve — banded 64..4096 elements, dense 8..256; the
#      exponents of cost against n fitted by least squares (banded: n >= 64);
#   2. short runs (the omega0 = 4 spin-up's first 0.05 s, 19 steps) through the command line:
#      CPU and peak resident memory, 64..4096 elements, against the landed 0a88803 (to 512: it
#      needs minutes beyond), median of 3;
#   3. whole runs: the omega0 = 15 spin-up 20 s at 16..256 elements (as before), and with --full
#      the omega0 = 4 spin-up 20 s at 2048 and 4096 elements (4096: ~15 s CPU, 207 MB,
#      docs/performance.md, "Analytic beam Jacobian").
# Output in bench/results/: scaling.csv (banded), scaling_fd.csv, scaling_dense.csv, scaling_exponents.txt,
# scaling_memory.csv, scaling_runs.csv, scaling.png. Needs a build (BUILD_DIR, default build);
# the landed binary is LANDED=path or built from git (0a88803) into $BUILD_DIR/landed-0a88803.
#   bash bench/scaling.sh [--quick] [--full]
set -euo pipefail
cd "$(dirname "$0")/.."
ROOT=$PWD
B=${BUILD_DIR:-build}
RES=${RESULTS:-$ROOT/bench/results}
QUICK=0; FULL=0
for a in "$@"; do case $a in --quick) QUICK=1 ;; --full) FULL=1 ;; esac; done
mkdir -p "$RES"
EXE=$B/bench_scaling
cc -std=c11 -O3 -DNDEBUG -D_DEFAULT_SOURCE -Wall -Wextra -Wpedantic -Wshadow -Iengine -Ibuiltin bench/scaling.c -o "$EXE" \
  "$B/libflexmbd.a" -lsundials_idas -lsundials_nvecserial -lsundials_sunlinsolklu \
  -lsundials_sunmatrixsparse -lsundials_sunlinsoldense -lsundials_sunmatrixdense -lklu -lyaml -lm
F=${FLEXMBD:-$B/flexmbd}
LANDED=${LANDED:-}
if [ -z "$LANDED" ]; then
  L=$B/landed-0a88803
  if [ ! -x "$L/build/flexmbd" ]; then
    rm -rf "$L" && mkdir -p "$L/src"
    git archive 0a88803 | tar -x -C "$L/src"
    cmake -S "$L/src" -B "$L/build" -DCMAKE_BUILD_TYPE=Release > /dev/null
    cmake --build "$L/build" -j2 --target flexmbd > /dev/null
  fi
  LANDED=$L/build/flexmbd
fi

# 1. per-call costs
NB="64 128 256 512 1024 2048 4096"; [ $QUICK = 1 ] && NB="64 256 1024"
ND="8 16 32 64 128 256"; [ $QUICK = 1 ] && ND="8 16 32 64"
"$EXE" scenes/paper/spinup_w15.yaml -s bodies.beam.assembly=banded $NB | tee "$RES/scaling.csv"
"$EXE" scenes/paper/spinup_w15.yaml -s bodies.beam.assembly=dense $ND | tee "$RES/scaling_dense.csv"
# the same banded calls with the engine's finite differences instead of the beam's analytic Jacobian
"$EXE" scenes/paper/spinup_w15.yaml -s bodies.beam.assembly=banded -s bodies.beam.jacobian=differences $NB | tee "$RES/scaling_fd.csv"
# least-squares slope of log(column) against log(n) over n >= nmin
fit() { # file nmin label column...
  local file=$1 nmin=$2 label=$3; shift 3
  awk -F, -v nmin="$nmin" -v label="$label" -v cols="$*" 'BEGIN { nc = split(cols, c, " ") }
    NR == 1 { for (i = 1; i <= NF; ++i) idx[$i] = i; next }
    $1 >= nmin { x = log($1); n++; sx += x; sxx += x * x
      for (k = 1; k <= nc; ++k) { y = log($(idx[c[k]])); sy[k] += y; sxy[k] += x * y } }
    END { if (n < 2) exit; d = n * sxx - sx * sx; printf "%s exponents (n >= %d):", label, nmin
          for (k = 1; k <= nc; ++k) printf " %s %.2f", c[k], (n * sxy[k] - sx * sy[k]) / d; printf "\n" }' "$file"
}
{
  fit "$RES/scaling.csv" 64 banded residual_us system_residual_us jacobian_us lsetup_us lsolve_us nnz
  fit "$RES/scaling_fd.csv" 64 "banded, FD Jacobian" jacobian_us
  fit "$RES/scaling_dense.csv" 32 dense residual_us system_residual_us jacobian_us lsetup_us lsolve_us nnz
} | tee "$RES/scaling_exponents.txt"

# 2. short runs: CPU and memory, this build against the landed one
short() { # binary n -> "cpu_s,maxrss_kb" (median of 3 by CPU)
  for r in 1 2 3; do
    /usr/bin/time -f "%M" -o "$B/scaling_time.txt" "$1" run scenes/paper/spinup_w4.yaml -o "$B/scaling_short.csv" --quiet \
      --set bodies.beam.elements=$2 --set solver.t_end=0.05 2> "$B/scaling_short.err" || true
    echo "$(grep -o 'cpu_s=[0-9.]*' "$B/scaling_short.err" | cut -d= -f2),$(tail -1 "$B/scaling_time.txt")"
  done | sort -t, -g -k1 | sed -n 2p
}
NM="64 128 256 512 1024 2048 4096"; [ $QUICK = 1 ] && NM="64 256 1024"
echo "elements,cpu_s,maxrss_kb,landed_cpu_s,landed_maxrss_kb,cpu_ratio,memory_ratio" > "$RES/scaling_memory.csv"
for n in $NM; do
  new=$(short "$F" $n)
  old=",,"
  if [ $n -le 512 ]; then old=$(short "$LANDED" $n); fi
  awk -F, -v n=$n -v new="$new" -v old="$old" 'BEGIN { split(new, a, ","); split(old, b, ",")
    r1 = b[1] != "" ? sprintf("%.1f", b[1] / a[1]) : ""; r2 = b[2] != "" ? sprintf("%.1f", b[2] / a[2]) : ""
    printf "%d,%s,%s,%s,%s,%s,%s\n", n, a[1], a[2], b[1], b[2], r1, r2 }' | tee -a "$RES/scaling_memory.csv"
done
for nmin in 64 256; do # 64..4096 (the goal's range) and 256..4096 (the ~8 MB program weighs less)
  fit <(awk -F, 'NR == 1 { print "n,cpu_s,maxrss_kb"; next } { print $1 "," $2 "," $3 }' "$RES/scaling_memory.csv") $nmin \
    "short runs (CPU includes setup; memory includes the ~8 MB program)" cpu_s maxrss_kb | tee -a "$RES/scaling_exponents.txt"
done

# 3. whole runs
RUNNS="16 32 64 128 256"; [ $QUICK = 1 ] && RUNNS="16 32"
echo "scene,elements,status,t_reached,steps,residuals,jacobians,newton_iters,cpu_s,maxrss_kb,tip_v_end" > "$RES/scaling_runs.csv"
whole() { # scene n
  /usr/bin/time -f "%M" -o "$B/scaling_time.txt" timeout 1800 "$F" run "scenes/paper/$1.yaml" -o "$B/scaling_$2.csv" --quiet \
    --set bodies.beam.elements=$2 2> "$B/scaling_$2.err" || true
  s=$(grep '^stats:' "$B/scaling_$2.err" | tail -1)
  tip=$(tail -1 "$B/scaling_$2.csv" | cut -d, -f2)
  # the stats line's fields by name (keys may be added before cpu_s)
  fields=$(awk '{ for (i = 2; i <= NF; ++i) { split($i, kv, "="); f[kv[1]] = kv[2] }
                  printf "%s,%s,%s,%s,%s,%s,%s", f["status"], f["t_reached"], f["steps"], f["residuals"], f["jacobians"], f["newton_iters"], f["cpu_s"] }' <<< "$s")
  echo "$1,$2,$fields,$(tail -1 "$B/scaling_time.txt"),$tip" | tee -a "$RES/scaling_runs.csv"
}
for n in $RUNNS; do whole spinup_w15 $n; done
if [ $FULL = 1 ]; then whole spinup_w4 2048; whole spinup_w4 4096; fi

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
plot '$RES/scaling.csv' using 1:5 skip 1 with linespoints lc 1 title 'banded: beam residual', \
     '' using 1:7 skip 1 with linespoints lc 2 title 'banded: Jacobian', \
     '' using 1:9 skip 1 with linespoints lc 3 title 'banded: factorization', \
     '' using 1:10 skip 1 with linespoints lc 4 title 'banded: solve', \
     '$RES/scaling_dense.csv' using 1:7 skip 1 with linespoints lc 2 dt 2 title 'dense: Jacobian', \
     '' using 1:9 skip 1 with linespoints lc 3 dt 2 title 'dense: factorization', \
     [64:4096] 0.2 * x dt 3 lc 0 title 'slope 1', [8:256] 0.5 * x * x dt 4 lc 0 title 'slope 2'
GP
fi
