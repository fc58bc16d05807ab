#!/bin/sh
# run.sh FLEXMBD CATALOGUE_DIR WORK_DIR — check every bad scene of expected.txt.
#
# For each line FILE EXIT WHERE FRAGMENT [OVERRIDE] of the manifest, `flexmbd run FILE -o OUT`
# must: exit with EXIT; print exactly one "error:" line, first on stderr (after any warnings), starting with
# "FILE:WHERE: error: " (or "--set: error: OVERRIDE: ") and containing FRAGMENT; print no
# "stats:" line (nothing ran: the error is the last word); print nothing on stdout; and leave no
# OUT behind (nothing is written before the scene is valid). `flexmbd check FILE` must give the
# same first line and exit code (except for WHERE "-" or "run:LINE:COL": mistakes only a run can
# find, the latter located at the joint they are about). Every *.yaml in the directory must be in the manifest and the other way round.
# POSIX sh + grep + sed only.
set -u
if [ $# -ne 3 ]; then
  echo "usage: $0 FLEXMBD CATALOGUE_DIR WORK_DIR" >&2
  exit 2
fi
bin=$1
dir=$2
work=$3
manifest=$dir/expected.txt
mkdir -p "$work" || exit 1
tab=$(printf '\t')
fails=0
cases=0

fail() {
  echo "FAIL $1: $2" >&2
  fails=$((fails + 1))
}

# every catalogue file is listed, every listed file exists
for f in "$dir"/*.yaml; do
  b=${f##*/}
  grep -q "^$b$tab" "$manifest" || fail "$b" "not listed in expected.txt"
done

while IFS=$tab read -r file code where frag override; do
  case $file in '#'* | '') continue ;; esac
  cases=$((cases + 1))
  scene=$dir/$file
  if [ ! -f "$scene" ]; then
    fail "$file" "listed in expected.txt but missing"
    continue
  fi
  out=$work/${file%.yaml}.csv
  rm -f "$out" "$work/stdout" "$work/stderr"
  if [ -n "$override" ]; then
    "$bin" run "$scene" -o "$out" --set "$override" >"$work/stdout" 2>"$work/stderr"
  else
    "$bin" run "$scene" -o "$out" >"$work/stdout" 2>"$work/stderr"
  fi
  rc=$?
  first=$(grep -v "warning: " "$work/stderr" | sed -n 1p) # warnings (plausibility) may come first
  last=$(sed -n '$p' "$work/stderr")
  case $where in
    --set) prefix="--set: error: $override: " ;;
    -) prefix="$scene: error: " ;;
    run:*) prefix="$scene:${where#run:}: error: " ;;
    *) prefix="$scene:$where: error: " ;;
  esac
  [ "$rc" = "$code" ] || fail "$file" "exit code $rc, expected $code"
  case $first in
    "$prefix"*) ;;
    *) fail "$file" "message does not start with '$prefix': $first" ;;
  esac
  case $first in
    *"$frag"*) ;;
    *) fail "$file" "message lacks '$frag': $first" ;;
  esac
  n=$(grep -c 'error:' "$work/stderr")
  [ "$n" = 1 ] || fail "$file" "$n error lines on stderr, expected one"
  ! grep -q '^stats:' "$work/stderr" || fail "$file" "a stats line although nothing ran: $last"
  [ ! -s "$work/stdout" ] || fail "$file" "wrote to stdout"
  [ ! -e "$out" ] || fail "$file" "left an output file behind"

  case $where in -|run:*) continue ;; esac # found at run time: `check` accepts the file
  if [ -n "$override" ]; then
    "$bin" check "$scene" --set "$override" >"$work/stdout" 2>"$work/stderr"
  else
    "$bin" check "$scene" >"$work/stdout" 2>"$work/stderr"
  fi
  crc=$?
  cfirst=$(grep -v "warning: " "$work/stderr" | sed -n 1p)
  [ "$crc" = "$code" ] || fail "$file" "check: exit code $crc, expected $code"
  [ "$cfirst" = "$first" ] || fail "$file" "check says '$cfirst', run says '$first'"
done <"$manifest"

if [ "$cases" -lt 40 ]; then
  fail "expected.txt" "only $cases cases, the catalogue needs at least 40"
fi
echo "bad scenes: $cases cases, $fails failures"
[ "$fails" -eq 0 ]
