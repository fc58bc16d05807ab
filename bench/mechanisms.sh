#!/usr/bin/env bash
# bench/mechanisms.sh — mechanisms (issue 11; docs/performance.md, "Mechanisms").
#
#   bash bench/mechanisms.sh [--reps N]
#
# 1. Size: CPU per simulated second for chains of N = 1, 2, 5, 10, 20, 50 parallelogram linkages
#    (each linkage hangs from the coupler above: two cranks and a coupler, 3 bodies, 9 coordinates,
#    8 constraint rows, one degree of freedom), swinging under gravity from 0.3 rad off the
#    vertical for 2 s at rtol 1e-8 (default formulation; they swing, they do not pass the flat
#    position). Reported: N, coordinates, steps, CPU s per simulated s.
# 1b. Rows of N linkages side by side that pass the flat position, with the default settings (only
#    rtol given: formulation auto finds the flat positions before the run, engine/singular.c), and
#    their crank-angle error over 10 s against the 1-DOF pendulum at rtol 1e-8, 1e-9, 1e-10 for
#    N = 1, 2, 5, 10, 20, 50 (bench/results/mechanisms_rows*.csv; issue 23 item 4: <= 1e-5/3 rad).
# 2. Work-precision of a rigid mechanism down to rtol 1e-12: the driven four-bar (scenes/fourbar.yaml)
#    at rtol = 1e-4 ... 1e-12 (atol = rtol / 100), error = max |rocker angle - closed form|
#    (the circle-intersection solution, as in tests/core/test_mechanisms.c), default solver and
#    klu_full.
# CPU = median of REPS runs' cpu_s (the stats line). Results: bench/results/mechanisms_chain.csv,
# bench/results/mechanisms_wp.csv.
set -euo pipefail
cd "$(dirname "$0")/.."
ROOT=$PWD
F=${FLEXMBD:-$ROOT/build/flexmbd}
RES=${RESULTS:-$ROOT/bench/results}
WORK=$(mktemp -d /tmp/flexmbd-mech.XXXXXX)
REPS=3
while [ $# -gt 0 ]; do
  case $1 in
    --reps) REPS=$2; shift ;;
    -h|--help) sed -n 2,18p "$0"; exit 0 ;;
    *) echo "mechanisms.sh: unknown argument '$1'" >&2; exit 2 ;;
  esac
  shift
done
mkdir -p "$RES"

# a chain of N parallelograms: linkage k hangs from coupler k-1 (the ground for k = 1); cranks of
# 1 m / 1 kg at the ends of a 2 m / 2 kg coupler, all cranks at angle -pi/2 + 0.3
chain_scene() {
  python3 - "$1" <<'PY'
import math, sys
n = int(sys.argv[1]); th = -math.pi / 2 + 0.3; c, s = math.cos(th), math.sin(th)
out = ["solver: {t_end: 2.0, rtol: 1.0e-8, atol: 1.0e-10, output_step: 0.01}", "gravity: [0.0, -9.81]", "bodies:"]
joints = ["joints:"]
y0 = 0.0; x0 = 0.0
for k in range(1, n + 1):
    for side, px in (("l", x0), ("r", x0 + 2.0)):
        out.append("  - {name: c%d%s, type: rigid, mass: 1.0, inertia: 0.0833333333333333, position: [%.15g, %.15g], angle: %.15g}"
                   % (k, side, px + 0.5 * c, y0 + 0.5 * s, th))
    x0 += c; y0 += s
    out.append("  - {name: k%d, type: rigid, mass: 2.0, inertia: 0.6666666666666667, position: [%.15g, %.15g]}" % (k, x0 + 1.0, y0))
    up = "ground" if k == 1 else "k%d" % (k - 1)
    for side, ux, cx in (("l", -1.0, -1.0), ("r", 1.0, 1.0)):
        p1 = "[%g, 0]" % ((ux + 1.0) if k == 1 else ux)  # ground points at 0 and 2; couplers at -1, +1
        joints.append("  - {name: o%d%s, type: revolute, body1: %s, body2: c%d%s, point1: %s, point2: [-0.5, 0]}" % (k, side, up, k, side, p1))
        joints.append("  - {name: a%d%s, type: revolute, body1: c%d%s, body2: k%d, point1: [0.5, 0], point2: [%g, 0]}" % (k, side, k, side, k, cx))
print("\n".join(out + joints + ["outputs: [c1l.theta, k%d.x, k%d.y, energy.total]" % (n, n)]))
PY
}

. bench/lib.sh
# run SCENE REPS times; sets $line (the last stats line) and $cpu (the median cpu_s)
timed_runs() {
  local cpus=() r
  for r in $(seq "$REPS"); do
    "$F" run "$1" -o "${1%.yaml}.csv" 2> "${1%.yaml}.err" || true
    line=$(tail -1 "${1%.yaml}.err")
    cpus+=("$(echo "$line" | stat_field cpu_s)")
  done
  cpu=$(printf '%s\n' "${cpus[@]}" | median)
}

echo "linkages,coordinates,constraint_rows,steps,cpu_s,cpu_per_simulated_s,status" > "$RES/mechanisms_chain.csv"
for n in 1 2 5 10 20 50; do
  chain_scene "$n" > "$WORK/chain$n.yaml"
  timed_runs "$WORK/chain$n.yaml"
  steps=$(echo "$line" | stat_field steps)
  status=$(echo "$line" | stat_field status)
  nq=$((9 * n)); nc=$((8 * n))
  echo "$n,$nq,$nc,$steps,$cpu,$(python3 -c "print($cpu / 2.0)"),$status" | tee -a "$RES/mechanisms_chain.csv"
done

# 1b. rows of N parallelograms side by side that pass the flat position ~20 times in 10 s (default
#     settings; 2 s here, rtol 1e-8), and the crank-angle error of 10 s against the 1-DOF pendulum
#     at rtol 1e-8, 1e-9 and 1e-10 for N = 1 ... 50 (CPU: one run each)
row_scene() {
  python3 - "$1" "$2" <<'PY'
import sys
n = int(sys.argv[1]); t_end = float(sys.argv[2]) if len(sys.argv) > 2 else 10.0
out = ["# A row of %d parallelogram linkages side by side: %d equal cranks (1 m, 1 kg) pinned to the ground" % (n, n + 1),
       "# at x = 0, 2, ..., %d and %d couplers (2 m, 2 kg) between neighbouring crank tips; rigid, under" % (2 * n, n),
       "# gravity, started upright turning at 5 rad/s. Every crank turns alike (1-DOF pendulum in the crank",
       "# angle, k = %d cranks, c = %d couplers: tests/mechanisms/test_parallelogram.c); the row goes flat" % (n + 1, n),
       "# about 20 times in 10 s. Generated by bench/mechanisms.sh (row_scene).",
       "solver: {t_end: %g, rtol: 1.0e-8, output_step: 0.01}" % t_end,
       "gravity: [0.0, -9.81]", "bodies:"]
for k in range(n + 1):
    out.append("  - {name: crank%d, type: rigid, mass: 1.0, inertia: 0.0833333333333333, position: [%d, 0.5], angle: 1.5707963267948966, velocity: [-2.5, 0.0], angular_velocity: 5.0}" % (k + 1, 2 * k))
for k in range(n):
    out.append("  - {name: coupler%d, type: rigid, mass: 2.0, inertia: 0.6666666666666667, position: [%d, 1.0], velocity: [-5.0, 0.0]}" % (k + 1, 2 * k + 1))
out.append("joints:")
for k in range(n + 1):
    out.append("  - {name: o%d, type: revolute, body1: ground, body2: crank%d, point1: [%d, 0.0], point2: [-0.5, 0.0]}" % (k + 1, k + 1, 2 * k))
for k in range(n):
    out.append("  - {name: a%d, type: revolute, body1: crank%d, body2: coupler%d, point1: [0.5, 0.0], point2: [-1.0, 0.0]}" % (k + 1, k + 1, k + 1))
    out.append("  - {name: b%d, type: revolute, body1: crank%d, body2: coupler%d, point1: [0.5, 0.0], point2: [1.0, 0.0]}" % (k + 1, k + 2, k + 1))
cols = ["crank1.theta", "crank1.omega", "crank2.theta", "crank%d.theta" % (n + 1), "coupler%d.theta" % n, "energy.total", "constraint.position"]
out.append("outputs: [%s]" % ", ".join(dict.fromkeys(cols)))
print("\n".join(out))
PY
}
row_error() { # CSV, N: max |crank angle - 1-DOF pendulum (RK4)|
  python3 - "$1" "$2" <<'PY'
import csv, math, sys
n = int(sys.argv[2]); K, C = n + 1, n
def acc(th):
    m, mc, l, g = 1.0, 2.0, 1.0, 9.81
    return -g * (K * m * l / 2 + C * mc * l) * math.cos(th) / (K * m * l * l / 3 + C * mc * l * l)
h = 1e-4; y = math.pi / 2; yd = 5.0; k = 0; worst = 0.0
for r in csv.DictReader(open(sys.argv[1])):
    while k < round(float(r["t"]) / h):
        k1 = yd; l1 = acc(y); k2 = yd + .5 * h * l1; l2 = acc(y + .5 * h * k1); k3 = yd + .5 * h * l2
        l3 = acc(y + .5 * h * k2); k4 = yd + h * l3; l4 = acc(y + h * k3)
        y += h / 6 * (k1 + 2 * k2 + 2 * k3 + k4); yd += h / 6 * (l1 + 2 * l2 + 2 * l3 + l4); k += 1
    worst = max(worst, abs(math.remainder(float(r["crank1.theta"]) - y, 2 * math.pi)))
print("%.2e" % worst)
PY
}
echo "linkages,coordinates,steps,cpu_s,cpu_per_simulated_s,status" > "$RES/mechanisms_rows.csv"
for n in 1 2 5 10 20 50; do
  row_scene "$n" 2 > "$WORK/row$n.yaml"
  timed_runs "$WORK/row$n.yaml"
  echo "$n,$((6 * n + 3)),$(echo "$line" | stat_field steps),$cpu,$(python3 -c "print($cpu / 2.0)"),$(echo "$line" | stat_field status)" \
    | tee -a "$RES/mechanisms_rows.csv"
done
echo "linkages,rtol,steps,cpu_s,max_crank_error_rad,status" > "$RES/mechanisms_rows_error.csv"
for n in 1 2 5 10 20 50; do
  row_scene "$n" 10 > "$WORK/row$n.yaml"
  for rtol in 1e-8 1e-9 1e-10; do
    "$F" run "$WORK/row$n.yaml" -o "$WORK/row$n.csv" --set solver.rtol="$rtol" 2> "$WORK/row$n.err" || true
    line=$(tail -1 "$WORK/row$n.err")
    echo "$n,$rtol,$(echo "$line" | stat_field steps),$(echo "$line" | stat_field cpu_s),$(row_error "$WORK/row$n.csv" "$n"),$(echo "$line" | stat_field status)" \
      | tee -a "$RES/mechanisms_rows_error.csv"
  done
done

echo "solver,rtol,steps,cpu_s,max_rocker_error_rad,status" > "$RES/mechanisms_wp.csv"
for ls in klu klu_full; do
  for rtol in 1e-4 1e-5 1e-6 1e-7 1e-8 1e-9 1e-10 1e-11 1e-12; do
    atol=$(python3 -c "print($rtol / 100)")
    cpus=()
    for r in $(seq "$REPS"); do
      "$F" run scenes/fourbar.yaml -o "$WORK/fb.csv" --set solver.rtol="$rtol" --set solver.atol="$atol" \
        --set solver.linear_solver="$ls" --set "outputs=[crank.theta, rocker.theta]" 2> "$WORK/fb.err" || true
      line=$(tail -1 "$WORK/fb.err")
      cpus+=("$(echo "$line" | stat_field cpu_s)")
    done
    cpu=$(printf '%s\n' "${cpus[@]}" | median)
    err=$(python3 - "$WORK/fb.csv" <<'PY'
import csv, math, sys
a, b, c, d = 1.0, 3.5, 3.0, 4.0
worst = 0.0
for row in csv.DictReader(open(sys.argv[1])):
    th2 = 2.0 * float(row["t"])
    ax, ay = a * math.cos(th2), a * math.sin(th2)
    dx, dy = d - ax, -ay; dist = math.hypot(dx, dy)
    aa = (b * b - c * c + dist * dist) / (2 * dist); h = math.sqrt(b * b - aa * aa)
    ux, uy = dx / dist, dy / dist
    bx, by = ax + aa * ux - h * uy, ay + aa * uy + h * ux
    ref = math.atan2(by, bx - d)
    e = math.remainder(float(row["rocker.theta"]) - ref, 2 * math.pi)
    worst = max(worst, abs(e))
print("%.3e" % worst)
PY
)
    echo "$ls,$rtol,$(echo "$line" | stat_field steps),$cpu,$err,$(echo "$line" | stat_field status)" | tee -a "$RES/mechanisms_wp.csv"
  done
done
rm -rf "$WORK"
