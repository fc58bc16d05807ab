#!/usr/bin/env bash
# bench/refine.sh — the flexible pendulum's refinement table (issue 32 item 5; docs/refine.md):
# `flexmbd refine scenes/paper/pendulum.yaml` over ELEMENTS (default 8,16,32,64) for its first
# T seconds (default 1) at rtol R (default 1e-6; the time reference at R/100), into
# bench/results/refine_pendulum.csv. 128 elements and more are slow (the time reference at rtol
# 1e-8 meets the fine-mesh Newton failures of docs/performance.md, "Fine meshes").
#   bash bench/refine.sh [--elements 8,16,32,64] [--t-end T] [--rtol R]
set -euo pipefail
cd "$(dirname "$0")/.."
ROOT=$PWD
F=${FLEXMBD:-$ROOT/build/flexmbd}
RES=${RESULTS:-$ROOT/bench/results}
ELEMENTS=8,16,32,64
TEND=1
RTOL=1e-6
while [ $# -gt 0 ]; do
  case $1 in
    --elements) ELEMENTS=$2; shift ;;
    --t-end) TEND=$2; shift ;;
    --rtol) RTOL=$2; shift ;;
    -h|--help) sed -n 2,7p "$0"; exit 0 ;;
    *) echo "refine.sh: unknown argument '$1'" >&2; exit 2 ;;
  esac
  shift
done
mkdir -p "$RES"
"$F" refine scenes/paper/pendulum.yaml --elements "$ELEMENTS" --set "solver.t_end=$TEND" --set "solver.rtol=$RTOL" \
  -o "$RES/refine_pendulum.csv"
