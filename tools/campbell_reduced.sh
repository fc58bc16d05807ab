#!/bin/sh
# campbell_reduced.sh — the Campbell diagram of the paper's spinning beam (scenes/campbell_beam.yaml,
# 16 elements, complete model) on the full mesh, reduced to 4 modes (`reduction: {modes: 4}`, the
# default basis: 4 bending modes + their 4 stiffening vectors, docs/models.md "The reduced beam") and
# reduced as linear-modal ZOAC (the same basis, w_c dropped) on one plot: the reduced complete beam
# lies on the full mesh's curves; ZOAC's first frequency falls to zero at omega1 = 3.909 rad/s
# (negative values: a divergent mode, rate sqrt(Omega^2 - omega1^2)) and its second softens.
#
# Usage: tools/campbell_reduced.sh [OUTDIR] [FLEXMBD] [FIGURE]
#        -> OUTDIR/campbell_{full,reduced,zoac_reduced}.csv and FIGURE (default
#        OUTDIR/campbell_reduced.png; .svg or .pdf by its extension), through `flexmbd plot`
#        (needs gnuplot: gnuplot-nox).
set -eu
out=${1:-plots}
flexmbd=${2:-build/flexmbd}
fig=${3:-$out/campbell_reduced.png}
root=$(cd "$(dirname "$0")/.." && pwd)
case $flexmbd in /*) ;; */*) flexmbd=$(pwd)/$flexmbd ;; esac
case $out in /*) ;; *) out=$(pwd)/$out ;; esac
case $fig in /*) ;; *) fig=$(pwd)/$fig ;; esac
cd "$root"
command -v "$flexmbd" >/dev/null || { echo "campbell_reduced.sh: no flexmbd at $flexmbd (build first)" >&2; exit 2; }
mkdir -p "$out"
campbell() {
  name=$1
  shift
  "$flexmbd" campbell scenes/campbell_beam.yaml --speed joints.spin.speed --speeds 0:15:31 --count 3 "$@" \
    -o - >"$out/campbell_$name.csv" 2>"$out/campbell_$name.err" ||
    { cat "$out/campbell_$name.err" >&2; exit 3; }
}
campbell full
campbell reduced --set 'bodies.beam.reduction={modes: 4}'
campbell zoac_reduced --set 'bodies.beam.reduction={modes: 4}' --set bodies.beam.model=zoac
"$flexmbd" plot "$out/campbell_full.csv" "$out/campbell_reduced.csv" "$out/campbell_zoac_reduced.csv" --x speed \
  --legend 'full mesh (16 el.),reduced k = 4,ZOAC reduced k = 4' --xlabel 'hub speed (rad/s)' \
  --ylabel 'in-plane frequency (rad/s); negative: divergence rate' \
  --title 'paper beam: full mesh, reduced complete and reduced ZOAC (linear modal)' -o "$fig"
