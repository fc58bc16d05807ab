#!/bin/sh
# campbell_paper.sh — the Campbell diagram of the paper's beam (Liu, Hong & Liu 2009) in its three
# models on one plot: the first two in-plane frequencies against the hub speed, from
# `flexmbd campbell` on scenes/campbell_beam.yaml (constant-speed hub, radius 0, no gravity).
# Complete and FOAC stiffen and lie on top of each other; ZOAC softens as omega1^2 - Omega^2 and
# crosses zero at its first bending frequency omega1 = 3.909 rad/s (negative values: the mode
# diverges at rate sqrt(Omega^2 - omega1^2)). The continuum's in-plane first frequency
# (formulation note §8, mu_c^2 = mu_f1^2 - lambda^2) is drawn as points.
#
# Usage: tools/campbell_paper.sh [OUTDIR] [FLEXMBD]   -> OUTDIR/campbell_{complete,foac,zoac}.csv,
#        OUTDIR/campbell_models.png (default OUTDIR: plots). Needs gnuplot (gnuplot-nox).
set -eu
out=${1:-plots}
flexmbd=${2:-build/flexmbd}
root=$(cd "$(dirname "$0")/.." && pwd)
cd "$root"
[ -x "$flexmbd" ] || { echo "campbell_paper.sh: no flexmbd at $flexmbd (build first)" >&2; exit 2; }
command -v gnuplot >/dev/null || { echo "campbell_paper.sh: gnuplot not found (apt-get install gnuplot-nox)" >&2; exit 2; }
mkdir -p "$out"
for model in complete foac zoac; do
  "$flexmbd" campbell scenes/campbell_beam.yaml --speed joints.spin.speed --speeds 0:16:65 --count 2 \
    --set bodies.beam.model=$model -o "$out/campbell_$model.csv" --plot "$out/campbell_$model.png"
done
# continuum: omega = sqrt(mu_f1^2 - lambda^2) * s, Omega = lambda * s, s = sqrt(EI / (rho A L^4))
cat > "$out/campbell_continuum.csv" <<CSV
lambda,mu_f1
0,3.516015269
1,3.681646814
2,4.137319573
4,5.585001421
8,9.256837601
12,13.17015049
CSV
gnuplot <<GP
set terminal pngcairo size 1000,700 noenhanced
set output '$out/campbell_models.png'
set datafile separator ','
set grid
set key left top
set xlabel 'hub speed Omega (rad/s)'
set ylabel 'in-plane frequency (rad/s); negative: divergence rate'
set title 'Campbell diagram of the paper beam (16 elements): complete and FOAC stiffen, ZOAC softens to zero at omega1'
s = sqrt(68.95e9 * 1.302e-10 / (2767.0 * 2.5e-4 * 1.8**4))
plot [0:16][-16:50] \
  '$out/campbell_complete.csv' using 1:2 with lines lw 3 lc rgb '#1f77b4' title 'complete, mode 1', \
  '$out/campbell_foac.csv' using 1:2 with lines lw 2 dt 2 lc rgb '#ff7f0e' title 'FOAC, mode 1', \
  '$out/campbell_zoac.csv' using 1:2 with lines lw 2 lc rgb '#d62728' title 'ZOAC, mode 1', \
  '$out/campbell_complete.csv' using 1:3 with lines lw 1 lc rgb '#1f77b4' title 'complete, mode 2', \
  '$out/campbell_foac.csv' using 1:3 with lines lw 1 dt 2 lc rgb '#ff7f0e' title 'FOAC, mode 2', \
  '$out/campbell_zoac.csv' using 1:3 with lines lw 1 lc rgb '#d62728' title 'ZOAC, mode 2', \
  '$out/campbell_continuum.csv' using (\$1*s):(sqrt(\$2**2 - \$1**2)*s) with points pt 7 ps 1.2 lc rgb 'black' title 'continuum (in-plane)', \
  x with lines dt 3 lc rgb 'gray' title '1x speed', 0 with lines lc rgb 'black' notitle
GP
echo "campbell_paper.sh: $out/campbell_models.png"
