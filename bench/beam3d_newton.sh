#!/usr/bin/env bash
# bench/beam3d_newton.sh — why the spatial beam's Newton iteration fails while its frame turns
# (docs/spatial.md, "Not done yet"): a free beam (no joint, no gravity, 2 elements) spinning at
# 2 rad/s about z for 0.2 s at rtol 1e-6 (and at rest), both with the scene's small deformation rate
# tip_velocity [0, 0.002, 0.002], with the seed's section second moment and 100x, 10^4x it;
# then a rigid3d body on a spherical joint under GGL and projected. Counts are
# deterministic (one run each): steps, Jacobians, Newton convergence failures.
#   bash bench/beam3d_newton.sh [flexmbd binary] > bench/results/beam3d_newton.csv
set -euo pipefail
cd "$(dirname "$0")/.."
source bench/lib.sh
F=${1:-build/flexmbd}
T=$(mktemp -d)
trap 'rm -rf "$T"' EXIT
one() { # label scene args...
  local label=$1
  shift
  "$F" run "$@" -o "$T/out.csv" --quiet 2> "$T/err" || true
  echo "$label,$(stat_field steps < "$T/err"),$(stat_field jacobians < "$T/err"),$(stat_field conv_fails < "$T/err")"
}
echo "case,steps,jacobians,conv_fails"
B=(tests/spatial/scenes/beam_rotating.yaml --set 'joints=[]' --set solver.t_end=0.2 --set solver.output_step=0.01
  --set 'outputs=[beam.tip_w]' --set solver.rtol=1e-6 --set bodies.beam.elements=2)
for I in 1.302e-10 1.302e-8 1.302e-6; do
  one "beam I=$I spinning" "${B[@]}" --set "bodies.beam.second_moment=$I" --set 'bodies.beam.angular_velocity=[0, 0, 2]'
  one "beam I=$I at rest" "${B[@]}" --set "bodies.beam.second_moment=$I" --set 'bodies.beam.angular_velocity=[0, 0, 0]'
done
cat > "$T/ball.yaml" << 'YAML'
dimension: 3
solver: {t_end: 20.0, rtol: 1.0e-6, output_step: 0.01}
bodies:
  - {name: hub, type: rigid3d, mass: 1.2, inertia: [0.5, 1.3, 1.3], position: [0.9, 0, 0], velocity: [0, 3.6, 0], angular_velocity: [0, 0, 4]}
joints:
  - {name: ball, type: spherical, body1: ground, body2: hub, point2: [-0.9, 0, 0]}
YAML
one "rigid3d on a ball, ggl" "$T/ball.yaml"
one "rigid3d on a ball, projected" "$T/ball.yaml" --set solver.formulation=projected
