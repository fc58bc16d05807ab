#!/bin/sh
# file_safety.sh FLEXMBD SOURCE_DIR WORK_DIR — a run never loses or damages a file (issue 12).
#   - a run that stops on bad input leaves an existing output as it was (and creates none);
#   - an output that is the scene or the reference (by device and inode, through another name
#     or a link) is refused before anything is written;
#   - --reference is opened and checked before the run;
#   - non-regular outputs are written through and kept; a symbolic link stays a link;
#   - SIGINT and SIGTERM: exit 4, `stats: status=interrupted`, the file ends in a complete row;
#   - disk full (a 64 KiB tmpfs when this user may mount one): exit 3, whole rows only;
#   - no temporary file is left beside the output in any case.
# POSIX sh + grep + sed + awk.
set -u
. "$(dirname "$0")/../file_test_lib.sh" "$@"
bad_run=$src/tests/bad_scenes/56-joints-unsatisfiable.yaml # fails after the output would be opened

# run NAME EXPECTED_EXIT ARGS...: stdout/stderr into $work
run() {
  name=$1 code=$2
  shift 2
  "$bin" "$@" >"$work/stdout" 2>"$work/stderr"
  rc=$?
  [ "$rc" = "$code" ] || fail "$name" "exit code $rc, expected $code: $(grep -m 1 error: "$work/stderr")"
}

# has NAME FRAGMENT: the stderr of the last run contains FRAGMENT
has() {
  grep -qF -- "$2" "$work/stderr" || fail "$1" "stderr lacks '$2': $(sed -n 1p "$work/stderr")"
}

# whole_rows NAME FILE: a header, at least one row, every line with the header's field count,
# the last line ending in a newline
whole_rows() {
  [ -s "$2" ] || {
    fail "$1" "$2 is missing or empty"
    return
  }
  [ "$(tail -c 1 "$2" | od -An -c | tr -d ' ')" = '\n' ] || fail "$1" "$2 does not end with a newline"
  awk -F, 'NR == 1 { n = NF } NF != n { bad = NR } END { if (bad || NR < 2) exit 1 }' "$2" ||
    fail "$1" "$2 has a line with a different field count (or no rows)"
}

no_temp_left() {
  ls -a "$1" | grep -q '^\..*\.[A-Za-z0-9]\{6\}$' && fail "$2" "a temporary file was left in $1: $(ls -a "$1")"
}

old='previous,results
1,2'

# 1. a run that stops on bad input (found after loading) keeps the existing output
printf '%s\n' "$old" >"$work/out.csv"
run keep-output 2 run "$bad_run" -o "$work/out.csv"
[ "$(cat "$work/out.csv")" = "$old" ] || fail keep-output "the existing output was changed or removed"
no_temp_left "$work" keep-output
# ... and creates none when there was none
run no-output 2 run "$bad_run" -o "$work/new.csv"
[ ! -e "$work/new.csv" ] || fail no-output "left $work/new.csv behind"

# 2. the output is the scene: by its name, another name (hard link) or a symbolic link
cp "$scene" "$work/scene.yaml"
cp "$scene" "$work/scene.orig"
ln "$work/scene.yaml" "$work/hardlink.csv"
ln -s "$work/scene.yaml" "$work/symlink.csv"
for o in scene.yaml hardlink.csv symlink.csv; do
  run "output-is-scene($o)" 2 run "$work/scene.yaml" -o "$work/$o" --set solver.t_end=0.1
  has "output-is-scene($o)" "error: the output file is the input '$work/scene.yaml'"
  cmp -s "$work/scene.yaml" "$work/scene.orig" || fail "output-is-scene($o)" "the scene was changed"
done
[ -L "$work/symlink.csv" ] || fail output-is-scene "the symbolic link was replaced"

# 3. --reference: the output may not be the reference, and a missing or non-regular reference
#    is refused before the run (no output written)
printf '%s\n' "$old" >"$work/ref.csv"
run output-is-reference 2 run "$scene" -o "$work/ref.csv" --reference "$work/ref.csv" --set solver.t_end=0.1
has output-is-reference "the output file is the input '$work/ref.csv'"
[ "$(cat "$work/ref.csv")" = "$old" ] || fail output-is-reference "the reference was changed"
run missing-reference 2 run "$scene" -o "$work/run.csv" --reference "$work/none.csv" --set solver.t_end=0.1
has missing-reference "$work/none.csv: error: cannot open the reference: No such file or directory"
[ ! -e "$work/run.csv" ] || fail missing-reference "ran before checking the reference"
run directory-reference 2 run "$scene" -o "$work/run.csv" --reference "$work" --set solver.t_end=0.1
has directory-reference "cannot open the reference: it is a directory"
if mkfifo "$work/fifo.csv" 2>/dev/null; then
  run fifo-reference 2 run "$scene" -o "$work/run.csv" --reference "$work/fifo.csv" --set solver.t_end=0.1
  has fifo-reference "cannot open the reference: it is not a regular file"
  # a FIFO as the scene is refused too, without waiting for a writer
  run fifo-scene 2 check "$work/fifo.csv"
  has fifo-scene "is not a regular file"
  # a FIFO as the output is written through (a reader is waiting) and is still a FIFO afterwards
  cat "$work/fifo.csv" >"$work/from_fifo.csv" &
  reader=$!
  run fifo-output 0 run "$scene" -o "$work/fifo.csv" --set solver.t_end=0.1 --quiet
  wait $reader
  [ -p "$work/fifo.csv" ] || fail fifo-output "the FIFO was replaced"
  [ "$(grep -c . "$work/from_fifo.csv")" = 12 ] || fail fifo-output "the reader got $(grep -c . "$work/from_fifo.csv") lines, expected 12"
  # a FIFO output when the run stops on bad input: never removed
  cat "$work/fifo.csv" >/dev/null &
  reader=$!
  run fifo-bad-run 2 run "$bad_run" -o "$work/fifo.csv"
  kill $reader 2>/dev/null
  wait $reader 2>/dev/null
  [ -p "$work/fifo.csv" ] || fail fifo-bad-run "the FIFO was removed"
  rm -f "$work/fifo.csv"
else
  echo "SKIP fifo cases: mkfifo failed" >&2
  skips=$((skips + 1))
fi
[ ! -e "$work/run.csv" ] || fail reference "an output was written although the run was refused"

# 4. a symbolic link as the output: the file it names gets the rows, the link stays
printf '%s\n' "$old" >"$work/real.csv"
ln -s real.csv "$work/link.csv"
run symlink-output 0 run "$scene" -o "$work/link.csv" --set solver.t_end=0.1 --quiet
[ -L "$work/link.csv" ] || fail symlink-output "the link was replaced by a file"
[ "$(grep -c . "$work/real.csv")" = 12 ] || fail symlink-output "the linked file has $(grep -c . "$work/real.csv") lines, expected 12"
no_temp_left "$work" symlink-output
# the old output's permissions are kept when a run replaces it
chmod 640 "$work/real.csv"
run keep-mode 0 run "$scene" -o "$work/real.csv" --set solver.t_end=0.1 --quiet
[ "$(stat -c %a "$work/real.csv")" = 640 ] || fail keep-mode "mode $(stat -c %a "$work/real.csv"), expected 640"

# 5. /dev/null: written through, still the device afterwards (also after a failed run)
run dev-null 0 run "$scene" -o /dev/null --set solver.t_end=0.1 --quiet
run dev-null-bad-run 2 run "$bad_run" -o /dev/null
[ -c /dev/null ] || fail dev-null "/dev/null is no longer a character device"

# 6. SIGINT and SIGTERM: stop at the next step, keep whole rows, say so, exit 4
for sig in INT TERM; do
  out=$work/interrupted_$sig.csv
  "$bin" run "$scene" -o "$out" --set solver.t_end=1e5 --set solver.output_step=0.001 --quiet \
    >"$work/stdout" 2>"$work/stderr" &
  pid=$!
  # wait until rows are being written (the temporary file grows), then signal
  i=0
  while [ $i -lt 100 ]; do
    [ -n "$(find "$work" -name ".interrupted_$sig.csv.*" -size +20k 2>/dev/null)" ] && break
    sleep 0.05
    i=$((i + 1))
  done
  kill -$sig $pid
  wait $pid
  rc=$?
  [ "$rc" = 4 ] || fail "sig$sig" "exit code $rc, expected 4"
  has "sig$sig" "interrupted at t = "
  last=$(sed -n '$p' "$work/stderr")
  case $last in
    "stats: status=interrupted "*) ;;
    *) fail "sig$sig" "last stderr line: $last" ;;
  esac
  whole_rows "sig$sig" "$out"
  rows=$(($(grep -c . "$out") - 1))
  case $(grep -m 1 error: "$work/stderr") in
    *"the $rows rows written so far are kept"*) ;;
    *) fail "sig$sig" "the message does not count the $rows rows in the file" ;;
  esac
  no_temp_left "$work" "sig$sig"
done

# 7. disk full on a small tmpfs: exit 3, the file ends in a complete row, no temporary left
mnt=$work/tmpfs
mkdir -p "$mnt"
if mount -t tmpfs -o size=64k tmpfs "$mnt" 2>/dev/null; then
  run disk-full 3 run "$scene" -o "$mnt/out.csv" --quiet
  has disk-full "writing the output failed at t = "
  whole_rows disk-full "$mnt/out.csv"
  no_temp_left "$mnt" disk-full
  umount "$mnt"
else
  echo "SKIP disk-full on tmpfs: cannot mount a tmpfs here (not root?); /dev/full is covered by file_errors" >&2
  skips=$((skips + 1))
fi

file_test_done "file safety"
