#!/bin/sh
# hangs_and_crashes.sh FLEXMBD SOURCE_DIR WORK_DIR — inputs built to hang or crash (issue 27):
# a time table that is a FIFO or /dev/zero (refused at once: not a regular file), one with a
# 5000-character line (refused: not two rows), one that grows while it loads (loaded or refused,
# never a crash); `conform` on 300 + the built-in registered types (a fixed list of 256
# overflowed); `plot` without gnuplot (a message, not SIGPIPE); `compare` on 60 000 columns. Every case must end by
# itself (a 60 s guard each) with exit 0, 1 or 2 and no sanitizer report. POSIX sh.
set -u
. "$(dirname "$0")/../file_test_lib.sh" "$@"

# expect NAME CODES ARGS...: runs with a 60 s guard; the exit code one of CODES ("0 2")
expect() {
  name=$1 codes=$2
  shift 2
  timeout 60 "$@" >"$work/.out" 2>"$work/.err"
  rc=$?
  case " $codes " in
  *" $rc "*) ;;
  *) fail "$name" "exit code $rc, expected one of $codes: $(tail -n 2 "$work/.err")" ;;
  esac
  grep -q "Sanitizer\|runtime error" "$work/.err" && fail "$name" "a sanitizer report: $(grep -m 1 Sanitizer "$work/.err")"
}
said() { grep -q -- "$2" "$work/.err" || fail "$1" "stderr lacks '$2': $(tail -n 1 "$work/.err")"; }

# a scene whose drive reads its torque from table.csv beside it
sed 's/rotor_torque.csv/table.csv/' "$src/scenes/rotor.yaml" >"$work/rotor.yaml"
short="--set solver.t_end=0.01"
mkfifo "$work/table.csv" 2>/dev/null || fail "mkfifo" "cannot make a FIFO"
expect "a FIFO as a table" 2 "$bin" run "$work/rotor.yaml" -o "$work/out.csv" -q $short
said "a FIFO as a table" "not a regular file"
rm -f "$work/table.csv"
ln -s /dev/zero "$work/table.csv"
expect "/dev/zero as a table" 2 "$bin" run "$work/rotor.yaml" -o "$work/out.csv" -q $short
said "/dev/zero as a table" "not a regular file"
rm -f "$work/table.csv"
awk 'BEGIN { print "t,torque"; print "0,0"; s = "1,"; for (i = 0; i < 5000; ++i) s = s "1"; print s; print "2,0" }' \
  >"$work/table.csv"
expect "a 5000-character line" 2 "$bin" run "$work/rotor.yaml" -o "$work/out.csv" -q $short
said "a 5000-character line" "longer than 4094 characters"
# a table that grows while it loads: loaded (a consistent prefix) or refused, never a crash
printf 't,torque\n' >"$work/table.csv"
awk 'BEGIN { for (i = 0; i < 1000000; ++i) printf "%d,%d\n", i, i % 7 }' >>"$work/table.csv" &
writer=$!
expect "a table that grows while it loads" "0 2" "$bin" check "$work/rotor.yaml"
kill "$writer" 2>/dev/null
wait "$writer" 2>/dev/null
rm -f "$work/table.csv"

# conform on every registered type: the test plugin's 300 and the built-ins
if [ -n "${FLEXMBD_TEST_PLUGIN:-}" ] && [ -f "$FLEXMBD_TEST_PLUGIN" ]; then
  expect "conform on 300 + the built-in types" 1 "$bin" conform --plugin "$FLEXMBD_TEST_PLUGIN"
  grep -Eq "^conform: 3[0-9][0-9] types, 300 failed checks" "$work/.out" ||
    fail "conform on 300 + the built-in types" "$(tail -n 1 "$work/.out")"
else
  skips=$((skips + 1))
fi

# plot without gnuplot on the PATH: a message and exit 2
"$bin" run "$scene" -o "$work/p.csv" -q --set solver.t_end=0.1 2>/dev/null || fail "a pendulum run" "failed"
expect "plot without gnuplot" 2 env PATH=/nonexistent "$bin" plot "$work/p.csv" -o "$work/p.png"
said "plot without gnuplot" "gnuplot is not installed"

# compare on 60 000 columns (names found through a hash: was 60 000^2 / 2 string compares)
awk 'BEGIN { n = 60000; s = "t"; for (i = 0; i < n; ++i) s = s ",c" i; print s
             for (r = 0; r < 3; ++r) { s = r; for (i = 0; i < n; ++i) s = s "," (i + r); print s } }' >"$work/wide.csv"
expect "compare on 60 000 columns" 0 "$bin" compare "$work/wide.csv" "$work/wide.csv"
grep -q "c59999" "$work/.out" || fail "compare on 60 000 columns" "the last column is not reported"
file_test_done hangs_and_crashes
