#!/bin/sh
# `flexmbd check` says which backend a run starts on (issue 23: auto's choice said out loud), and
# it is the one the run then reports: for every shipped scene, check's "solver: NAME" equals the
# stats line's integrator=NAME of a short run of the same scene (a run that leaves GGL at a singular
# position mid-way would name projected; none of the shipped scenes does in its first 10 ms).
#   usage: test_check_solver.sh FLEXMBD SOURCE_DIR WORKDIR
set -eu
F=$1 SRC=$2 D=$3
mkdir -p "$D"
fail() { echo "FAIL: $*"; exit 1; }
n=0
for scene in $(find "$SRC/scenes" -name '*.yaml' | sort); do
  said=$("$F" check "$scene" | sed -n 's/^solver: \([a-z0-9_]*\).*/\1/p')
  [ -n "$said" ] || fail "$scene: check prints no solver line"
  "$F" run "$scene" -o "$D/out.csv" --quiet --set solver.t_end=0.01 --set solver.output_step=0.005 2> "$D/err" || true
  ran=$(tail -n 1 "$D/err" | sed -n 's/.* integrator=\([a-z0-9_]*\) .*/\1/p')
  [ "$said" = "$ran" ] || fail "$scene: check says '$said', the run used '$ran'"
  n=$((n + 1))
done
# the reasons: a beam scene by the BDF cap, a rigid one by BDF order 5, a named one as named
"$F" check "$SRC/scenes/paper/spinup_w1.yaml" | grep -q '^solver: radau9 (integrator auto: a body caps the BDF order' ||
  fail "spin-up: no reason given"
"$F" check "$SRC/scenes/fourbar.yaml" | grep -q '^solver: ida (integrator auto: rigid bodies' || fail "four-bar: no reason"
"$F" check "$SRC/scenes/fourbar.yaml" --set solver.integrator=radau5 | grep -q '^solver: radau5 (solver.integrator names it)' ||
  fail "four-bar with radau5 named: not said"
"$F" check "$SRC/scenes/parallelogram.yaml" --set solver.formulation=auto | grep -q '^solver: projected .*finds a singular position' ||
  fail "parallelogram with formulation auto: the walk's choice not said"
echo "test_check_solver: ok ($n scenes)"
