# file_test_lib.sh — sourced by the file tests (bad_scenes/file_errors.sh, failures/file_safety.sh):
# their arguments FLEXMBD SOURCE_DIR WORK_DIR, a fresh work folder, the failure and skip tally.
#   . "$(dirname "$0")/../file_test_lib.sh" "$@"      then   fail NAME WHY ... file_test_done TITLE
if [ $# -ne 3 ]; then
  echo "usage: $0 FLEXMBD SOURCE_DIR WORK_DIR" >&2
  exit 2
fi
bin=$1
src=$2
work=$3
rm -rf "$work"
mkdir -p "$work" || exit 1
scene=$src/scenes/pendulum.yaml
fails=0
skips=0

fail() {
  echo "FAIL $1: $2" >&2
  fails=$((fails + 1))
}

# the closing line (N passed-style tally) and the exit code
file_test_done() {
  echo "$1: $fails failures, $skips skipped"
  [ "$fails" -eq 0 ]
}
