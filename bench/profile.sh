#!/usr/bin/env bash
# bench/profile.sh — where a run's CPU goes, by function (perf, sampling): the shares behind
# docs/performance.md's profiles (issue 32 item 3: "profile first").
#
#   bash bench/profile.sh [SCENE] [--set PATH=VALUE]...   (default scenes/paper/pendulum.yaml)
#
# Runs `flexmbd run SCENE` under `perf record` and writes the functions with >= 0.5 % of the
# samples (self time, no children) into bench/results/profile_NAME.txt (NAME: the scene's file name).
# Needs perf (Debian: linux-perf) and permission to sample (kernel.perf_event_paranoid <= 2).
set -euo pipefail
cd "$(dirname "$0")/.."
ROOT=$PWD
F=${FLEXMBD:-$ROOT/build/flexmbd}
RES=${RESULTS:-$ROOT/bench/results}
WORK=$(mktemp -d /tmp/flexmbd-profile.XXXXXX)
trap 'rm -rf "$WORK"' EXIT
S=scenes/paper/pendulum.yaml
if [ $# -gt 0 ] && [ "${1#--}" = "$1" ]; then S=$1; shift; fi
command -v perf > /dev/null || { echo "bench/profile.sh: perf not found (Debian: apt-get install linux-perf)" >&2; exit 2; }
mkdir -p "$RES"
OUT=$RES/profile_$(basename "$S" .yaml).txt
perf record -q -o "$WORK/perf.data" "$F" run "$S" -o "$WORK/run.csv" --quiet "$@" 2> "$WORK/run.err"
{
  echo "# bench/profile.sh $S $* @ $(git rev-parse --short HEAD)"
  tail -1 "$WORK/run.err"
  perf report -i "$WORK/perf.data" --no-children --stdio 2> /dev/null |
    awk '/^ *[0-9.]+%/ { p = $1; sub("%", "", p); if (p + 0 >= 0.5) print }'
} | tee "$OUT"
