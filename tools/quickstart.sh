#!/usr/bin/env bash
# The main job: install what is missing, build, and reproduce the paper's Fig. 3(c) — the tip
# transverse deformation of the beam spun up to omega0 = 15 rad/s with the complete, FOAC and
# ZOAC models — as CSVs and a plot in out/.
set -euo pipefail
cd "$(dirname "$0")/.."
bash tools/install_deps.sh
bash tools/build.sh
mkdir -p out
for model in complete foac zoac; do
  echo "== spin-up omega0 = 15 rad/s, $model model"
  ./build/flexmbd run scenes/paper/spinup_w15.yaml -o "out/spinup_w15_$model.csv" --set bodies.beam.model=$model || true
done
if [ -x tools/plot_paper.sh ] || [ -f tools/plot_paper.sh ]; then
  bash tools/plot_paper.sh fig3 15 out
fi
echo "CSV files and plots are in out/"
ls out
