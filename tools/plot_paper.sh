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
# Draws with `flexmbd plot` (gnuplot; Debian: gnuplot-nox). Runs from the repository root.
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
           END { d = 0.25 * (mx - mn); printf "%g:%g", mn - d, mx + d }' "$1"
}

for w in 1 4 15; do
  "$flexmbd" plot "$out/spinup_w${w}_complete.csv" "$out/spinup_w${w}_foac.csv" "$out/spinup_w${w}_zoac.csv" beam.tip_v \
    -o "$out/fig3_w$w.png" --legend complete,FOAC,ZOAC --xlabel "t (s)" --ylabel "tip transverse deformation (m)" \
    --title "Spin-up, omega0 = $w rad/s, Tn = 15 s (Fig. 3): beam.tip_v" --xrange 0:20 \
    --yrange "$(yrange "$out/spinup_w${w}_complete.csv")"
done

"$flexmbd" plot "$out/pendulum_complete.csv" energy.kinetic energy.strain energy.gravity energy.total \
  -o "$out/fig5_energy.png" --xlabel "t (s)" --ylabel "energy (J)" \
  --title "Flexible pendulum, complete model (Fig. 5): T + U_e + U_g = const"
"$flexmbd" plot "$out/pendulum_complete.csv" beam.tip_v -o "$out/fig4_tip.png" --xlabel "t (s)" \
  --ylabel "tip transverse deformation (m)" --title "Flexible pendulum, complete model (Fig. 4b): beam.tip_v"

echo "plot_paper.sh: wrote $out/fig3_w1.png $out/fig3_w4.png $out/fig3_w15.png $out/fig4_tip.png $out/fig5_energy.png"
