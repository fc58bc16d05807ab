#!/usr/bin/env bash
# The main job: install what is missing, build, and reproduce the paper's figures: Fig. 3 (tip
# transverse deformation of the spun-up beam, complete/FOAC/ZOAC, omega0 = 1, 4, 15 rad/s) and
# Figs. 4b/5 (the flexible pendulum's tip deformation and energy components), as CSVs and PNGs
# in out/.
set -euo pipefail
cd "$(dirname "$0")/.."
bash tools/install_deps.sh
bash tools/build.sh
bash tools/plot_paper.sh out build/flexmbd
echo "quickstart: CSV files and figures are in out/:"
ls out
echo "quickstart: from Python (docs/python.md): PYTHONPATH=python python3 -c 'import flexmbd'"
