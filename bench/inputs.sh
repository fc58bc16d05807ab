#!/usr/bin/env bash
# bench/inputs.sh — what a controller in the loop costs (issue 35, item 2: "a controller stepping at
# 1 kHz costs <= 2x the same run with a continuous law"). bench/inputs.c runs the hub and blade of
# bench/scenes/input_rotor.yaml (motor torque 1 N m x sin(2 pi t), 2 s, rtol 1e-6) three ways,
# interleaved, REPS times each, medians of the process CPU time:
#   law     the continuous law in the scene
#   hold    input_rotor_input.yaml, the law set from C every 1 ms by fmb_set_input (zero-order hold:
#           every setting is a jump, and the integrator restarts there through its reinit op)
#   motion  the same with fmb_set_input_motion (the law's value, rate and second rate): a setting
#           within the solver's tolerance of where the last one led keeps the step history
# and again with settings every 10 ms (100 Hz). diff_*: the largest difference of hub.omega (rad/s)
# from the continuous run (hold: the hold's lag; motion: the restarts' and the steps' own error).
# Each period twice: library_clock 1, the data objects as made (each advance reads the monotonic
# clock for fmb_data_stats, no system call; until e855c8a it read the thread's CPU clock twice, two
# system calls, ~19 % of the 1 kHz motion run on a virtual machine, perf at 66117f6), and 0, turned
# off by fmb_data_set_timing as a program that times itself would.
#
#   bash bench/inputs.sh [REPS]        (default 9; ~45 s)
#
# Results: bench/results/inputs.csv
#   scene,period_s,settings,steps_law,steps_hold,steps_motion,cpu_law_s,cpu_hold_s,cpu_motion_s,
#   ratio_hold,ratio_motion,diff_hold,diff_motion,library_clock
set -euo pipefail
REPS=${1:-9}
case $REPS in
  -h | --help) sed -n 2,22p "$0"; exit 0 ;;
  *[!0-9]* | '' | 0) echo "inputs.sh: expected a number of repeats, got '$REPS'" >&2; exit 2 ;;
esac
cd "$(dirname "$0")/.."
B=${BUILD_DIR:-build} RES=${RESULTS:-$PWD/bench/results}
mkdir -p "$RES"
cmake --build "$B" --target bench_inputs >/dev/null
OUT=$RES/inputs.csv
TMP=$(mktemp /tmp/flexmbd-inputs.XXXXXX)
trap 'rm -f "$TMP"' EXIT
R="$B/bench_inputs bench/scenes/input_rotor.yaml bench/scenes/input_rotor_input.yaml -l motor -f 6.283185307179586 -r $REPS"
{
  $R -H -p 0.001
  $R -p 0.001 -U
  $R -p 0.01
  $R -p 0.01 -U
} > "$TMP"
mv "$TMP" "$OUT"
cat "$OUT"
