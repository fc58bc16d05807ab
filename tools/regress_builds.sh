#!/bin/sh
# tools/regress_builds.sh — the scene regression suite under other builds (issue 13): the stored
# references were blessed with the default build (gcc -O2); gcc -O0, gcc -O3, clang, and (when the
# CPU has FMA) a build with fused multiply-adds must all pass `flexmbd regress scenes`, while a
# 1e-3 change of a physical parameter fails (tests/regression/test_regress.sh).
#   usage: tools/regress_builds.sh [BUILD_ROOT]     (default: build-regress-* in the source tree)
set -u
src=$(cd "$(dirname "$0")/.." && pwd)
root=${1:-$src}
jobs=${JOBS:-2}
failed=
variant() { # NAME CMAKE-ARGS...
  name=$1
  shift
  dir="$root/build-regress-$name"
  if ! cmake -S "$src" -B "$dir" "$@" > /dev/null || ! cmake --build "$dir" -j "$jobs" --target flexmbd > /dev/null; then
    echo "regress_builds: $name: build failed"
    failed="$failed $name"
    return
  fi
  echo "== regress_builds: $name"
  (cd "$src" && "$dir/flexmbd" regress scenes -j "$jobs") || failed="$failed $name"
}
variant gcc-O0 -DCMAKE_BUILD_TYPE=Debug -DCMAKE_C_FLAGS=-O0 -DCMAKE_C_COMPILER=gcc
variant gcc-O3 -DCMAKE_BUILD_TYPE=Release -DCMAKE_C_FLAGS_RELEASE=-O3 -DCMAKE_C_COMPILER=gcc
if command -v clang > /dev/null 2>&1; then
  variant clang -DCMAKE_BUILD_TYPE=Release -DCMAKE_C_COMPILER=clang
else
  echo "regress_builds: no clang, skipped"
fi
if grep -qw fma /proc/cpuinfo 2> /dev/null; then
  variant gcc-fma -DCMAKE_BUILD_TYPE=Release "-DCMAKE_C_FLAGS=-mfma -ffp-contract=fast" -DCMAKE_C_COMPILER=gcc
else
  echo "regress_builds: the CPU has no FMA, that variant skipped"
fi
if [ -n "$failed" ]; then
  echo "regress_builds: FAILED:$failed" >&2
  exit 1
fi
echo "regress_builds: every build passes the suite"
