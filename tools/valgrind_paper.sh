#!/bin/sh
# tools/valgrind_paper.sh FLEXMBD [T_END] — valgrind memcheck over the paper scenes
# (scenes/paper/*.yaml), each run to T_END (default 0.5 s) with the complete and ZOAC models (FOAC
# on the spin-up scenes), plus a bad scene, a bad override and a solver failure (the error
# paths). Fails on any invalid access, use of uninitialised memory, or leak (--leak-check=full,
# every leak kind an error). Use a build without sanitizers.
# The flexible pendulum takes ~3e5 steps per simulated second (its axial modes ring); it runs to
# T_END / 10 so that memcheck (~50x slower) stays within minutes. FOAC on the pendulum needs
# 3e4 steps to reach its designed failure, a minute natively: not run here (ASan covers it).
set -u
if [ $# -lt 1 ]; then
  echo "usage: $0 FLEXMBD [T_END]" >&2
  exit 2
fi
bin=$1
tend=${2:-0.5}
src=$(cd "$(dirname "$0")/.." && pwd)
out=${TMPDIR:-/tmp}/flexmbd-valgrind.$$
mkdir -p "$out"
vg="valgrind --tool=memcheck --error-exitcode=99 --leak-check=full --show-leak-kinds=all --errors-for-leak-kinds=all --track-origins=yes --quiet"
fails=0
runs=0

# check NAME EXPECTED_EXIT ARGS...: one memcheck run, in the background, JOBS at a time; the
# verdict goes to $out/NAME.result
check() {
  (
    name=$1 want=$2
    shift 2
    # shellcheck disable=SC2086
    $vg "$bin" "$@" >/dev/null 2>"$out/$name.log"
    rc=$?
    if [ "$rc" = 99 ] || grep -q '^==[0-9]*== ' "$out/$name.log"; then
      { echo "FAIL $name: memcheck errors:"; grep '^==' "$out/$name.log" | head -40; } >"$out/$name.result"
    elif [ "$rc" != "$want" ]; then
      { echo "FAIL $name: exit code $rc, expected $want"; tail -3 "$out/$name.log"; } >"$out/$name.result"
    else
      echo "ok   $name: exit $rc, $(grep -o 'steps=[0-9]*' "$out/$name.log" | tail -n 1), no memcheck errors" \
        >"$out/$name.result"
    fi
  ) &
  running=$((running + 1))
  if [ "$running" -ge "$jobs" ]; then
    wait
    running=0
  fi
}
jobs=${JOBS:-2}
running=0

n=0
for scene in "$src"/scenes/paper/*.yaml; do
  [ -f "$scene" ] || continue
  n=$((n + 1))
  base=$(basename "$scene" .yaml)
  models="complete foac zoac"
  t=$tend
  case $base in pendulum*)
    models="complete zoac"
    t=$(awk "BEGIN { print $tend / 10 }")
    ;;
  esac
  for model in $models; do
    check "$base-$model" 0 run "$scene" -o "$out/$base-$model.csv" --quiet --set solver.t_end="$t" \
      --set bodies.beam.model="$model"
  done
done
if [ "$n" -eq 0 ]; then
  echo "FAIL: no scenes in $src/scenes/paper" >"$out/no-paper-scenes.result"
fi
check bad-scene 2 run "$src/tests/bad_scenes/63-negative-area.yaml" -o "$out/bad.csv"
check bad-override 2 run "$src/tests/bad_scenes/98-set-self-alias.yaml" -o "$out/bad-override.csv" --set 'bodies.beam.length=&a [*a]'
check solver-failure 3 run "$src/tests/failures/singular_fourbar.yaml" -o "$out/fail.csv"

wait
for r in "$out"/*.result; do
  runs=$((runs + 1))
  cat "$r"
  case $(sed -n 1p "$r") in FAIL*) fails=$((fails + 1)) ;; esac
done
rm -rf "$out"
echo "valgrind: $runs runs, $fails failures"
[ "$fails" -eq 0 ]
