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

check() { # NAME EXPECTED_EXIT ARGS...
  name=$1 want=$2
  shift 2
  # shellcheck disable=SC2086
  $vg "$bin" "$@" >/dev/null 2>"$out/$name.log"
  rc=$?
  runs=$((runs + 1))
  if [ "$rc" = 99 ] || grep -q '^==[0-9]*== ' "$out/$name.log"; then
    echo "FAIL $name: memcheck errors:" >&2
    grep '^==' "$out/$name.log" | head -40 >&2
    fails=$((fails + 1))
  elif [ "$rc" != "$want" ]; then
    echo "FAIL $name: exit code $rc, expected $want" >&2
    tail -3 "$out/$name.log" >&2
    fails=$((fails + 1))
  else
    echo "ok   $name: exit $rc, $(grep -o 'steps=[0-9]*' "$out/$name.log" | tail -n 1), no memcheck errors"
  fi
}

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
  echo "FAIL: no scenes in $src/scenes/paper" >&2
  fails=$((fails + 1))
fi
check bad-scene 2 run "$src/tests/bad_scenes/63-negative-area.yaml" -o "$out/bad.csv"
check bad-override 2 run "$src/tests/bad_scenes/98-set-self-alias.yaml" -o "$out/bad.csv" --set 'bodies.beam.length=&a [*a]'
check solver-failure 3 run "$src/tests/failures/singular_fourbar.yaml" -o "$out/fail.csv"

rm -rf "$out"
echo "valgrind: $runs runs, $fails failures"
[ "$fails" -eq 0 ]
