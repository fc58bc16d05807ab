#!/bin/sh
# tools/tsan.sh [BUILD_DIR] — the library from many threads under ThreadSanitizer (issue 35 item 3):
# configures BUILD_DIR (default build-tsan) with -DFLEXMBD_TSAN=ON (clang when installed, as
# Debian's gcc 12 TSan needs the same runtime), builds only tests/core/test_threads (8 threads
# loading, running and stepping 8 scenes at once against one thread's bytes; 4 computing sparse
# modes at once) and runs it.
# Any report fails it: halt_on_error=1 and a non-zero exit code (TSAN_OPTIONS exitcode=66).
set -eu
src=$(cd "$(dirname "$0")/.." && pwd)
build=${1:-$src/build-tsan}
jobs=${JOBS:-2}
cc=${CC:-}
if [ -z "$cc" ]; then
  if command -v clang-14 >/dev/null 2>&1; then cc=clang-14; else cc=cc; fi
fi
cmake -S "$src" -B "$build" -DFLEXMBD_TSAN=ON -DCMAKE_C_COMPILER="$cc" -DCMAKE_BUILD_TYPE=RelWithDebInfo >/dev/null
cmake --build "$build" -j "$jobs" --target test_threads >/dev/null
TSAN_OPTIONS=${TSAN_OPTIONS:-halt_on_error=1:exitcode=66:second_deadlock_stack=1}
export TSAN_OPTIONS
# a test that ran no thread would be clean for the wrong reason: the test prints 8 comparisons
out=$("$build/tests/core/test_threads") || {
  echo "$out"
  echo "tsan.sh: test_threads FAILED under ThreadSanitizer" >&2
  exit 1
}
echo "$out"
n=$(echo "$out" | grep -c "8 threads vs 1: identical" || true)
if [ "$n" != 8 ]; then
  echo "tsan.sh: expected 8 identical comparisons, got $n" >&2
  exit 1
fi
if ! echo "$out" | grep -q "sparse modes, 4 threads x 2 vs 1: 8 of 8 identical"; then
  echo "tsan.sh: the sparse modes from 4 threads did not all match one thread's" >&2
  exit 1
fi
echo "tsan.sh: clean (ThreadSanitizer, test_threads: 8 threads; sparse modes from 4)"
