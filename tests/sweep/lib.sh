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
