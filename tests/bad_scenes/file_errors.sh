#!/bin/sh
# file_errors.sh FLEXMBD SOURCE_DIR WORK_DIR — files that cannot be read or written.
# Each case checks the exit code, the first stderr line (path, "error:", the reason) and that no
# output file is left behind or an existing one is left untouched. POSIX sh + grep + sed only.
set -u
. "$(dirname "$0")/../file_test_lib.sh" "$@"

# expect NAME EXIT PREFIX FRAGMENT -- ARGS...: run $wrap flexmbd ARGS; the first stderr line with
# "error:" (or else the first line) must start with PREFIX and contain FRAGMENT
wrap=
expect() {
  name=$1 code=$2 prefix=$3 frag=$4
  shift 5
  $wrap "$bin" "$@" >"$work/stdout" 2>"$work/stderr"
  rc=$?
  first=$(grep -m 1 'error:' "$work/stderr" || sed -n 1p "$work/stderr")
  [ "$rc" = "$code" ] || fail "$name" "exit code $rc, expected $code ($first)"
  case $first in
    "$prefix"*) ;;
    *) fail "$name" "message does not start with '$prefix': $first" ;;
  esac
  case $first in
    *"$frag"*) ;;
    *) fail "$name" "message lacks '$frag': $first" ;;
  esac
}

out=$work/out.csv

# a scene that does not exist
expect missing-scene 2 "$work/none/scene.yaml: error: " "cannot open scene file: No such file or directory" -- \
  run "$work/none/scene.yaml" -o "$out"
[ ! -e "$out" ] || fail missing-scene "left $out behind"
! grep -q '^stats:' "$work/stderr" || fail missing-scene "a stats line although nothing ran"

# a directory given as the scene
expect directory 2 "$src/scenes: error: " "is a directory, expected a YAML scene file" -- run "$src/scenes" -o "$out"
[ ! -e "$out" ] || fail directory "left $out behind"
expect directory-check 2 "$src/scenes: error: " "is a directory" -- check "$src/scenes"

# a scene that cannot be read. root reads a mode-000 file anyway; then drop the capabilities
# that let it (setpriv), or skip and say so.
cp "$scene" "$work/unreadable.yaml" && chmod 000 "$work/unreadable.yaml"
if cat "$work/unreadable.yaml" >/dev/null 2>&1; then
  drop="setpriv --bounding-set=-dac_override,-dac_read_search --inh-caps=-all"
  if $drop cat "$work/unreadable.yaml" >/dev/null 2>&1 || ! $drop true 2>/dev/null; then
    echo "SKIP unreadable-scene: running as uid $(id -u), which reads mode-000 files, and setpriv cannot drop" \
      "CAP_DAC_OVERRIDE here" >&2
    skips=$((skips + 1))
  else
    echo "note: uid $(id -u) reads mode-000 files; testing the unreadable scene under setpriv without CAP_DAC_*" >&2
    wrap=$drop
    expect unreadable-scene 2 "$work/unreadable.yaml: error: " "cannot open scene file: Permission denied" -- \
      run "$work/unreadable.yaml" -o "$out"
    wrap=
  fi
else
  expect unreadable-scene 2 "$work/unreadable.yaml: error: " "cannot open scene file: Permission denied" -- \
    run "$work/unreadable.yaml" -o "$out"
fi
[ ! -e "$out" ] || fail unreadable-scene "left $out behind"
chmod 644 "$work/unreadable.yaml"

# an output path in a directory that does not exist, and an output path that is a directory
expect output-no-dir 2 "$work/none/out.csv: error: " "cannot write the output file: No such file or directory" -- \
  run "$scene" -o "$work/none/out.csv" --set solver.t_end=0.1
expect output-is-dir 2 "$work: error: " "cannot write the output file: Is a directory" -- \
  run "$scene" -o "$work" --set solver.t_end=0.1

# a full disk: the first row cannot be written
if [ -w /dev/full ]; then
  expect output-disk-full 3 "$scene: error: " "writing the output failed at t = 0" -- \
    run "$scene" -o /dev/full --set solver.t_end=0.1
else
  echo "SKIP output-disk-full: no writable /dev/full" >&2
  skips=$((skips + 1))
fi

# a bad scene must not touch an existing output file
printf 'previous,results\n1,2\n' >"$out"
expect keep-old-output 2 "$src/tests/bad_scenes/24-number-word.yaml:7:11: error: " "expected a number for 'mass'" -- \
  run "$src/tests/bad_scenes/24-number-word.yaml" -o "$out"
[ "$(cat "$out")" = "previous,results
1,2" ] || fail keep-old-output "the old output file was changed"
rm -f "$out"

# command-line mistakes
expect no-scene 2 "flexmbd run: no scene file given" "no scene file" -- run -o "$out"
expect o-without-name 2 "flexmbd run: -o needs a file name" "needs a file name" -- run "$scene" -o
expect set-without-value 2 "flexmbd run: --set needs PATH=VALUE" "PATH=VALUE" -- run "$scene" --set
expect two-scenes 2 "flexmbd check: one scene file at a time" "one scene file at a time" -- check "$scene" "$scene"
expect unknown-option 2 "flexmbd run: unknown option '--frobnicate'" "unknown option" -- run "$scene" --frobnicate
[ ! -e "$out" ] || fail cli "left $out behind"

# and a good run writes its rows (the checks above can tell success from failure)
expect good-run 0 "initial conditions:" "position correction" -- run "$scene" -o "$out" --set solver.t_end=0.1
rows=$(grep -c . "$out" 2>/dev/null || echo 0)
[ "$rows" = 12 ] || fail good-run "$rows lines in $out, expected a header and 11 rows"

file_test_done "file errors"
