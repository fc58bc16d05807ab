#!/usr/bin/env bash
# bench/beam_residual.sh — the beam's residual (and Jacobians) per second against the mesh, this
# tree's bodies/beam.c and OLD_COMMIT's side by side in one run (issue 32, item 3;
# docs/performance.md, "Fine meshes").
#
#   bash bench/beam_residual.sh [--ns "8 16 ... 1024"] [--repeats R] [--seconds S] [--pendulum N]
#
# bench/beam_residual.c is compiled twice with the same flags against this tree's library: once
# including this tree's bodies/beam.c, once OLD_COMMIT's (default 2a91686, the last with the
# per-Gauss-point residual; git show, the worktree list is untouched). Each then times the seed
# beam's (complete, default quadrature) residual, banded residual, dense Jacobian (to 256
# elements) and banded Jacobian blocks at one fixed state: the median of R timings of S CPU
# seconds each (default 7 x 0.2 s). The builds alternate per mesh (old, new, old, new ...), so a
# busy machine slows both alike. Results: bench/results/beam_residual.csv
#   n,what,old_per_s,new_per_s,speedup,old_checksum,new_checksum
# (checksum: sum |R| or |K| + |M| — equal to roundoff when both evaluate the same thing).
# Then each build's -g table (the residual's change with 3...9 Gauss points against 10, per model,
# over its largest inertial row) into bench/results/beam_residual_gauss.txt: the Gauss sums of the
# old build need 6 points for complete, 4 for FOAC and ZOAC; the moments of the new one none.
# --pendulum N (default 5; 0: skip): then the shipped scenes/paper/pendulum.yaml N times with each
# build, alternating (OLD_COMMIT's built beside the tree by bench/lib.sh build_landed in OLD_DIR,
# default /tmp/fmb-OLD_COMMIT): the median cpu_s of each, the steps and residual evaluations
# (equal when the residuals agree to roundoff), and max |beam.tip_v(new) - beam.tip_v(old)|.
# Results: bench/results/beam_residual_pendulum.csv
set -euo pipefail
cd "$(dirname "$0")/.."
ROOT=$PWD
B=${BUILD_DIR:-build}
RES=${RESULTS:-$ROOT/bench/results}
OLD_COMMIT=${OLD_COMMIT:-2a91686}
NS="8 16 32 64 128 256 512 1024"
REPEATS=7
SECONDS_EACH=0.2
PEND=5
while [ $# -gt 0 ]; do
  case $1 in
    --ns) NS=$2; shift 2 ;;
    --repeats) REPEATS=$2; shift 2 ;;
    --seconds) SECONDS_EACH=$2; shift 2 ;;
    --pendulum) PEND=$2; shift 2 ;;
    -h | --help) sed -n 2,21p "$0"; exit 0 ;;
    *) echo "bench/beam_residual.sh: unknown option $1" >&2; exit 2 ;;
  esac
done
WORK=$(mktemp -d /tmp/flexmbd-beamres.XXXXXX)
trap 'rm -rf "$WORK"' EXIT
mkdir -p "$RES" "$WORK/old/bodies"
cmake --build "$B" --target bench_beam_residual > /dev/null
# the library and its dependencies, as CMake links the bench program
LINK=$(sed 's/^.*-o [^ ]* *//' "$B/CMakeFiles/bench_beam_residual.dir/link.txt")
git show "$OLD_COMMIT:bodies/beam.c" > "$WORK/old/bodies/beam.c"
git show "$OLD_COMMIT:bodies/beam_section.h" > "$WORK/old/bodies/beam_section.h"
(cd "$B" && cc -O3 -DNDEBUG -std=c11 -D_DEFAULT_SOURCE -I"$ROOT/engine" -I"$ROOT/builtin" -I"$ROOT/bench" \
  -DBEAM_SOURCE="\"$WORK/old/bodies/beam.c\"" "$ROOT/bench/beam_residual.c" -o "$WORK/old.exe" $LINK)
NEW=$B/bench_beam_residual
for n in $NS; do
  "$WORK/old.exe" -n "$n" -r "$REPEATS" -t "$SECONDS_EACH" >> "$WORK/old.txt"
  "$NEW" -n "$n" -r "$REPEATS" -t "$SECONDS_EACH" >> "$WORK/new.txt"
done
{
  echo "# bench/beam_residual.sh: residual change with 3...9 Gauss points against 10 / largest inertial row (ng:change)"
  echo "old $OLD_COMMIT"
  "$WORK/old.exe" -g
  echo "new $(git rev-parse --short HEAD)"
  "$NEW" -g
} | tee "$RES/beam_residual_gauss.txt"
OUT=$RES/beam_residual.csv
{
  echo "# bench/beam_residual.sh old=$OLD_COMMIT new=$(git rev-parse --short HEAD)$(git diff --quiet HEAD -- bodies/beam.c || echo +dirty) repeats=$REPEATS seconds=$SECONDS_EACH"
  echo "n,what,old_per_s,new_per_s,speedup,old_checksum,new_checksum"
  awk 'function v(k,   i, a) { for (i = 1; i <= NF; ++i) { split($i, a, "="); if (a[1] == k) return a[2] } }
    NR == FNR { key = v("n") "," v("what"); rate[key] = v("per_s"); chk[key] = v("checksum"); next }
    { key = v("n") "," v("what"); if (key in rate)
        printf "%s,%s,%s,%.2f,%s,%s\n", key, rate[key], v("per_s"), v("per_s") / rate[key], chk[key], v("checksum") }' \
    "$WORK/old.txt" "$WORK/new.txt"
} | tee "$OUT"
[ "$PEND" -gt 0 ] || exit 0
. "$ROOT/bench/lib.sh" # median, stat_field, tip_err, build_landed
OLD_DIR=${OLD_DIR:-/tmp/fmb-$OLD_COMMIT}
build_landed "$OLD_COMMIT" "$OLD_DIR"
cmake --build "$B" --target flexmbd > /dev/null
P=scenes/paper/pendulum.yaml
for r in $(seq "$PEND"); do
  for b in old new; do
    exe=$B/flexmbd
    [ $b = old ] && exe=$OLD_DIR/build/flexmbd
    "$exe" run "$P" -o "$WORK/$b.csv" --quiet 2> "$WORK/$b.err"
    stat_field cpu_s < "$WORK/$b.err" >> "$WORK/$b.cpu"
  done
done
POUT=$RES/beam_residual_pendulum.csv
{
  echo "# bench/beam_residual.sh --pendulum $PEND: $P as shipped, old=$OLD_COMMIT new=$(git rev-parse --short HEAD)"
  echo "build,runs,median_cpu_s,min_cpu_s,max_cpu_s,steps,residuals,tip_v_diff_m"
  for b in old new; do
    printf "%s,%d,%s,%s,%s,%s,%s,%s\n" $b "$PEND" "$(median < "$WORK/$b.cpu")" "$(sort -g "$WORK/$b.cpu" | head -1)" \
      "$(sort -g "$WORK/$b.cpu" | tail -1)" "$(stat_field steps < "$WORK/$b.err")" \
      "$(stat_field residuals < "$WORK/$b.err")" "$(tip_err "$WORK/old.csv" "$WORK/$b.csv")"
  done
} | tee "$POUT"
