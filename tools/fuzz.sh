#!/bin/sh
# tools/fuzz.sh SECONDS [BUILD_DIR] — run the libFuzzer harnesses (scene loader, --set override
# parser, compare, time-table files, regression references) side by side for SECONDS each, from a seed corpus of every scene in the tree.
#
# Builds BUILD_DIR (default build-fuzz) with clang and -DFLEXMBD_FUZZ=ON if needed. The corpus
# grows in BUILD_DIR/fuzz-corpus/{load,override} across runs; crashes land in
# BUILD_DIR/fuzz-artifacts/ and make the script fail. Prints executions and coverage per harness.
# Every crash found must become a regression input in tests/fuzz/regressions/{load,override}/
# (replayed by ctest -L fuzz) and, for the loader, a case in tests/bad_scenes/.
set -eu
if [ $# -lt 1 ]; then
  echo "usage: $0 SECONDS [BUILD_DIR]" >&2
  exit 2
fi
secs=$1
src=$(cd "$(dirname "$0")/.." && pwd)
build=${2:-$src/build-fuzz}
cc=${CC:-clang-14}
jobs=${JOBS:-2}

if [ ! -f "$build/CMakeCache.txt" ]; then
  CC=$cc cmake -S "$src" -B "$build" -DFLEXMBD_FUZZ=ON -DCMAKE_BUILD_TYPE=RelWithDebInfo >/dev/null
fi
cmake --build "$build" -j "$jobs" --target fuzz_load fuzz_override fuzz_compare fuzz_table fuzz_reference >/dev/null || {
  echo "fuzz.sh: building the harnesses failed (is tests/bad_scenes added from tests/CMakeLists.txt?)" >&2
  exit 1
}
bin=$build/tests/bad_scenes/fuzz

corpus=$build/fuzz-corpus
art=$build/fuzz-artifacts
mkdir -p "$corpus/load" "$corpus/override" "$corpus/compare" "$corpus/table" "$corpus/reference" "$corpus/seeds-load" "$art"
# seeds: every scene in the tree, good and bad (flattened; names made unique)
find "$src/scenes" "$src/tests" -name '*.yaml' | while read -r f; do
  rel=${f#"$src"/}
  cp "$f" "$corpus/seeds-load/$(printf '%s' "$rel" | tr '/' '_')"
done

run() { # NAME CORPUS... : one harness, SECONDS, log in $build/fuzz-NAME.log
  name=$1
  shift
  "$bin/fuzz_$name" -max_total_time="$secs" -timeout=10 -rss_limit_mb=2048 -max_len=8192 \
    -dict="$src/tests/fuzz/scene.dict" -artifact_prefix="$art/$name-" -print_final_stats=1 \
    "$@" >"$build/fuzz-$name.log" 2>&1
}
status=0
# three harnesses at a time: load, override, compare; then table, reference
for group in "load override compare" "table reference"; do
  pids=
  for name in $group; do
    seeds=$src/tests/fuzz/${name}_seeds
    [ "$name" = load ] && seeds=$corpus/seeds-load
    run "$name" "$corpus/$name" "$seeds" "$src/tests/fuzz/regressions/$name" &
    pids="$pids $!"
  done
  for p in $pids; do wait "$p" || status=1; done
done

for name in load override compare table reference; do
  log=$build/fuzz-$name.log
  execs=$(sed -n 's/^stat::number_of_executed_units: *//p' "$log" | tail -n 1)
  cov=$(grep -o 'cov: [0-9]*' "$log" | tail -n 1)
  ft=$(grep -o 'ft: [0-9]*' "$log" | tail -n 1)
  units=$(ls "$corpus/$name" | wc -l)
  echo "fuzz_$name: ${execs:-?} executions in ${secs} s, ${cov:-cov: ?} edges, ${ft:-ft: ?} features, corpus $units inputs"
done
crashes=$(ls "$art" | wc -l)
if [ "$status" -ne 0 ] || [ "$crashes" -ne 0 ]; then
  echo "fuzz.sh: FINDINGS: $crashes artifact(s) in $art; logs: $build/fuzz-NAME.log" >&2
  exit 1
fi
echo "fuzz.sh: no findings"
