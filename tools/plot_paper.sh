#!/bin/sh
# plot_paper.sh — redraw the figures of Liu, Hong & Liu (2009) from flexmbd runs.
#
#   Fig. 3: tip transverse deformation beam.tip_v against t for the spin-up at omega0 = 1, 4 and
#           15 rad/s, the three beam models on one panel per omega0 (fig3_w1.png, fig3_w4.png,
#           fig3_w15.png). ZOAC diverges at 4 and 15 rad/s: its run stops with exit 3 and its
#           curve leaves the panel.
#   Fig. 5: energy components of the flexible pendulum (complete model): kinetic, strain,
#           gravity and total (fig5_energy.png), plus Fig. 4's tip deformation (fig4_tip.png).
#
# Usage: tools/plot_paper.sh [OUTDIR] [FLEXMBD]
#   OUTDIR   where CSVs and PNGs go (default: plots)
#   FLEXMBD  the flexmbd program (default: build/flexmbd)
# Needs gnuplot (Debian: gnuplot-nox). Runs from the repository root.
set -eu

out=${1:-plots}
flexmbd=${2:-build/flexmbd}
root=$(cd "$(dirname "$0")/.." && pwd)
cd "$root"
[ -x "$flexmbd" ] || { echo "plot_paper.sh: no flexmbd at $flexmbd (build first: cmake --build build)" >&2; exit 2; }
command -v gnuplot >/dev/null || { echo "plot_paper.sh: gnuplot not found (apt-get install gnuplot-nox)" >&2; exit 2; }
mkdir -p "$out"

# runs: a diverging ZOAC stops with exit 3 and keeps its rows, which is what Fig. 3 shows
run() { # scene csv [--set ...]
  scene=$1 csv=$2
  shift 2
  if "$flexmbd" run "$scene" -o "$csv" --quiet "$@"; then :; else
    rc=$?
    [ "$rc" -eq 3 ] || exit "$rc"
    echo "plot_paper.sh: $scene $* stopped early (exit 3); plotting the rows it wrote" >&2
  fi
}

for w in 1 4 15; do
  for m in complete foac zoac; do
    run scenes/paper/spinup_w$w.yaml "$out/spinup_w${w}_$m.csv" --set bodies.beam.model=$m
  done
done
run scenes/paper/pendulum.yaml "$out/pendulum_complete.csv"

# y range of each Fig. 3 panel: the complete model's range with a margin, so ZOAC's divergence
# runs off the panel instead of flattening the other curves
yrange() { # csv
  awk -F, 'NR == 1 { for (i = 1; i <= NF; ++i) if ($i == "beam.tip_v") c = i; next }
           { if ($c > mx) mx = $c; if ($c < mn) mn = $c }
           END { d = 0.25 * (mx - mn); printf "[%g:%g]", mn - d, mx + d }' "$1"
}

for w in 1 4 15; do
  gnuplot <<EOF
set terminal pngcairo size 900,560 font "sans,11"
set output "$out/fig3_w$w.png"
set termoption noenhanced
set datafile separator ","
set key top right
set grid
set xlabel "t (s)"
set ylabel "tip transverse deformation (m)"
set title "Spin-up, omega0 = $w rad/s, Tn = 15 s (Fig. 3): beam.tip_v"
set xrange [0:20]
set yrange $(yrange "$out/spinup_w${w}_complete.csv")
plot "$out/spinup_w${w}_complete.csv" using "t":"beam.tip_v" with lines lw 2 lc rgb "#1f77b4" title "complete", \
     "$out/spinup_w${w}_foac.csv" using "t":"beam.tip_v" with lines lw 2 dt 2 lc rgb "#d62728" title "FOAC", \
     "$out/spinup_w${w}_zoac.csv" using "t":"beam.tip_v" with lines lw 2 dt 3 lc rgb "#2ca02c" title "ZOAC"
EOF
done

gnuplot <<EOF
set terminal pngcairo size 900,560 font "sans,11"
set output "$out/fig5_energy.png"
set datafile separator ","
set key outside right
set grid
set xlabel "t (s)"
set ylabel "energy (J)"
set title "Flexible pendulum, complete model (Fig. 5): T + U_e + U_g = const"
plot "$out/pendulum_complete.csv" using "t":"energy.kinetic" with lines lw 2 title "kinetic T", \
     "" using "t":"energy.strain" with lines lw 2 title "strain U_e", \
     "" using "t":"energy.gravity" with lines lw 2 title "gravity U_g", \
     "" using "t":"energy.total" with lines lw 2 lc rgb "black" title "total"
set output "$out/fig4_tip.png"
set key top right
set ylabel "tip transverse deformation (m)"
set termoption noenhanced
set title "Flexible pendulum, complete model (Fig. 4b): beam.tip_v"
plot "$out/pendulum_complete.csv" using "t":"beam.tip_v" with lines lw 2 title "complete"
EOF

echo "plot_paper.sh: wrote $out/fig3_w1.png $out/fig3_w4.png $out/fig3_w15.png $out/fig4_tip.png $out/fig5_energy.png"
