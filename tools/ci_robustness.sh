#!/bin/sh
# tools/ci_robustness.sh — the robustness steps of CI (issue 5), called from .ci/run:
#   1. the test suite under ASan + UBSan + LSan (tools/sanitize.sh; all tests but `long`), and the
#      8-thread test under ThreadSanitizer (tools/tsan.sh)
#   2. both libFuzzer harnesses side by side for FUZZ_SECONDS (default 60) (tools/fuzz.sh)
#   3. valgrind memcheck on the paper scenes and the error paths (tools/valgrind_paper.sh)
#   4. the scene regression suite under other compilers and optimization levels (tools/regress_builds.sh)
# Build directories go under CI_BUILD_ROOT (default: the source tree, build-ci-*). About 8-10
# minutes on 2 cores from a clean tree. Exits non-zero if any step fails; runs every step.
set -u
src=$(cd "$(dirname "$0")/.." && pwd)
root=${CI_BUILD_ROOT:-$src}
fuzz_secs=${FUZZ_SECONDS:-60}
jobs=${JOBS:-2}
export JOBS=$jobs
t0=$(date +%s)
failed=

step() {
  echo "== ci_robustness: $1 (at $(($(date +%s) - t0)) s)"
}

step "sanitizers: build and ctest -LE long"
sh "$src/tools/sanitize.sh" "$root/build-ci-sanitize" || failed="$failed sanitize"

step "ThreadSanitizer: 8 threads loading, running and stepping (test_threads)"
sh "$src/tools/tsan.sh" "$root/build-ci-tsan" || failed="$failed tsan"

step "fuzzing: ${fuzz_secs} s per harness"
sh "$src/tools/fuzz.sh" "$fuzz_secs" "$root/build-ci-fuzz" || failed="$failed fuzz"

step "valgrind memcheck: paper scenes"
if cmake -S "$src" -B "$root/build-ci-valgrind" -DCMAKE_BUILD_TYPE=RelWithDebInfo >/dev/null &&
  cmake --build "$root/build-ci-valgrind" -j "$jobs" --target flexmbd >/dev/null; then
  sh "$src/tools/valgrind_paper.sh" "$root/build-ci-valgrind/flexmbd" 0.5 || failed="$failed valgrind"
else
  failed="$failed valgrind-build"
fi

step "regression suite under gcc -O0/-O3, clang and FMA builds"
sh "$src/tools/regress_builds.sh" "$root" || failed="$failed regress-builds"

step "done"
if [ -n "$failed" ]; then
  echo "ci_robustness: FAILED:$failed" >&2
  exit 1
fi
echo "ci_robustness: all clean"
