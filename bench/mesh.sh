#!/usr/bin/env bash
# bench/mesh.sh — Newton's health and the cost against the mesh (issue 32, items 1 and 2;
# docs/performance.md, "Fine meshes").
#
#   bash bench/mesh.sh [--span T] [--ns "8 16 32 64 128 256"] [--integrators "ida radau5 radau9"]
#                      [--timeout S] [--no-old] [--tag NAME] [--scene FILE] [--fit-from N]
#
# The paper's pendulum as shipped (scenes/paper/pendulum.yaml: rtol 1e-10, positions error
# control; 64 elements and more are banded, assembly: auto) with bodies.beam.elements = n, for its
# first SPAN seconds (default 0.02), under each backend, with this tree's build and the landed
# OLD_COMMIT (default 13344e9, before the integrators eliminated the beam's auxiliary unknowns)
# side by side in one run. The old build is made beside this tree (bench/lib.sh build_landed, in
# OLD_DIR, default /tmp/fmb-<commit>) and runs the same scene file (unchanged since).
# Per run, from the stats line: steps, Newton iterations, Jacobians, convergence failures (and
# their share of the steps), iterations per step, cpu_s, and the cost per step and per Newton
# iteration in microseconds. A run still going after TIMEOUT s (default 120) is stopped
# (SIGTERM: it prints its stats with status=interrupted and how far it got, t_reached).
# One run per setting (the spread of cpu_s on this shared machine is +-30 %: the counts are exact,
# the times indicative). Results: bench/results/mesh.csv, and bench/results/mesh_exponents.txt
# (least-squares slopes of log cost per step and log steps against log n, n >= 32, new build);
# with --tag NAME, mesh_NAME.csv and mesh_NAME_exponents.txt. --scene runs another scene with a beam
# named `beam` (the spin-up, scenes/paper/spinup_w15.yaml: item 1 measures both); --fit-from N fits
# the slopes over n >= N (default 32; 8 for the whole 8...1024 range of item 1).
set -euo pipefail
cd "$(dirname "$0")/.."
ROOT=$PWD
F=${FLEXMBD:-$ROOT/build/flexmbd}
RES=${RESULTS:-$ROOT/bench/results}
WORK=$(mktemp -d /tmp/flexmbd-mesh.XXXXXX)
trap 'rm -rf "$WORK"' EXIT
OLD_COMMIT=${OLD_COMMIT:-13344e9}
OLD_DIR=${OLD_DIR:-/tmp/fmb-$OLD_COMMIT}
SPAN=0.02
NS="8 16 32 64 128 256"
INTS="ida radau5 radau9"
TIMEOUT=120
OLD=1
TAG=
S=scenes/paper/pendulum.yaml
FIT_FROM=32
while [ $# -gt 0 ]; do
  case $1 in
    --span) SPAN=$2; shift 2 ;;
    --ns) NS=$2; shift 2 ;;
    --integrators) INTS=$2; shift 2 ;;
    --timeout) TIMEOUT=$2; shift 2 ;;
    --no-old) OLD=0; shift ;;
    --tag) TAG=_$2; shift 2 ;;
    --scene) S=$2; shift 2 ;;
    --fit-from) FIT_FROM=$2; shift 2 ;;
    *) echo "bench/mesh.sh: unknown option $1" >&2; exit 2 ;;
  esac
done
. "$ROOT/bench/lib.sh" # median, stat_field, build_landed
BUILDS="new"
if [ $OLD = 1 ]; then
  build_landed "$OLD_COMMIT" "$OLD_DIR"
  BUILDS="old new"
fi
NEW_COMMIT=$(git rev-parse --short HEAD)
# output_step must not exceed the span
OSTEP=$(awk -v s="$SPAN" 'BEGIN { print (s < 0.005 ? s : 0.005) }')
OUT=$RES/mesh$TAG.csv
echo "build,commit,n,integrator,status,t_reached,steps,newton_iters,jacobians,conv_fails,conv_fail_pct,iters_per_step,cpu_s,us_per_step,us_per_iter" > "$OUT"
for b in $BUILDS; do
  if [ "$b" = old ]; then exe=$OLD_DIR/build/flexmbd; commit=$OLD_COMMIT; else exe=$F; commit=$NEW_COMMIT; fi
  for n in $NS; do
    for i in $INTS; do
      err=$WORK/$b-$n-$i.err
      timeout "$TIMEOUT" "$exe" run "$S" -o "$WORK/run.csv" --quiet --set bodies.beam.elements="$n" \
        --set solver.t_end="$SPAN" --set solver.output_step="$OSTEP" --set solver.integrator="$i" 2> "$err" || true
      st=$(stat_field status < "$err"); tr=$(stat_field t_reached < "$err"); steps=$(stat_field steps < "$err")
      it=$(stat_field newton_iters < "$err"); jac=$(stat_field jacobians < "$err"); cf=$(stat_field conv_fails < "$err")
      cpu=$(stat_field cpu_s < "$err")
      [ -n "$st" ] || { st=killed; tr=; steps=0; it=0; jac=0; cf=0; cpu=$TIMEOUT; }
      line=$(awk -v b="$b" -v c="$commit" -v n="$n" -v i="$i" -v st="$st" -v tr="$tr" -v s="$steps" -v it="$it" \
        -v j="$jac" -v cf="$cf" -v cpu="$cpu" 'BEGIN {
          printf "%s,%s,%s,%s,%s,%s,%d,%d,%d,%d,%.2f,%.2f,%.3f,%.1f,%.1f\n", b, c, n, i, st, tr, s, it, j, cf,
            (s > 0 ? 100 * cf / s : 0), (s > 0 ? it / s : 0), cpu, (s > 0 ? 1e6 * cpu / s : 0), (it > 0 ? 1e6 * cpu / it : 0) }')
      echo "$line" | tee -a "$OUT"
    done
  done
done
# slopes against n (n >= FIT_FROM) of the new build's cost per step, per iteration, and steps
awk -F, -v from="$FIT_FROM" -v scene="$S" 'NR > 1 && $1 == "new" && $3 >= from + 0 && $5 == "ok" {
    x = log($3); k = $4; n[k]++; sx[k] += x; sxx[k] += x * x
    y1 = log($14); y2 = log($15); y3 = log($7)
    s1[k] += x * y1; t1[k] += y1; s2[k] += x * y2; t2[k] += y2; s3[k] += x * y3; t3[k] += y3 }
  function slope(sxy, sy, k) { return (n[k] * sxy - sx[k] * sy) / (n[k] * sxx[k] - sx[k] * sx[k]) }
  END { for (k in n) if (n[k] >= 2)
    printf "%s: cost per step n^%.2f, per Newton iteration n^%.2f, steps n^%.2f (n >= %d, %d meshes, %s)\n", k,
      slope(s1[k], t1[k], k), slope(s2[k], t2[k], k), slope(s3[k], t3[k], k), from, n[k], scene }' "$OUT" | sort |
  tee "$RES/mesh${TAG}_exponents.txt"
