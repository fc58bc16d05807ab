# tests/sweep/lib.sh — sourced by the sweep tests: F (flexmbd), SRC (the source tree), D (a fresh
# work folder), PLUGIN (tests/sweep/faulty.c built, absolute) from the arguments, and fail().
set -eu
F=$1
SRC=$2
D=$3
PLUGIN=$(realpath "$4")
rm -rf "$D"
mkdir -p "$D"
fail() { echo "FAIL: $*" >&2; exit 1; }
# In the sanitizer build (FLEXMBD_SANITIZE=1 from ctest) ASan would catch the injected segfault and
# abort itself (exit 1, not the signal) and cannot map its shadow memory under --mem-limit: the
# faults keep their signals, and the endless allocation is left out (FAULTS_ALLOC empty).
FAULTS_ALLOC=4
if [ -n "${FLEXMBD_SANITIZE:-}" ]; then
  export ASAN_OPTIONS="${ASAN_OPTIONS:-}:handle_segv=0:handle_abort=0"
  FAULTS_ALLOC=
fi
