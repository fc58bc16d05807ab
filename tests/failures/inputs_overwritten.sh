#!/bin/sh
# inputs_overwritten.sh FLEXMBD SOURCE_DIR WORK_DIR — no command replaces a file it read (issue 27).
# Every output of every command is compared (device and inode, through any name or link) with
# every input: the scene, its time-table files, plugins, CSVs; the output is refused (exit 2),
# and the input is byte for byte as it was. Also: a failed `campbell` leaves an earlier result as
# it was (no header-only file), and SIGINT on `campbell` and `run --models` keeps what was done
# (exit 4, the rows so far). POSIX sh.
set -u
. "$(dirname "$0")/../file_test_lib.sh" "$@"

# refused NAME ARGS...: exit 2, "refusing to overwrite" said, and every file of $work unchanged
refused() {
  name=$1
  shift
  (cd "$work" && md5sum ./*.yaml ./*.csv >"$work/.sums" 2>/dev/null)
  (cd "$work" && "$bin" "$@" >"$work/.out" 2>"$work/.err")
  rc=$?
  [ "$rc" = 2 ] || fail "$name" "exit code $rc, expected 2: $(tail -n 2 "$work/.err")"
  grep -q "refusing to overwrite" "$work/.err" || fail "$name" "no 'refusing to overwrite' in: $(tail -n 2 "$work/.err")"
  (cd "$work" && md5sum -c --quiet "$work/.sums" >/dev/null 2>&1) || fail "$name" "an input changed"
}

cp "$src/scenes/rotor.yaml" "$src/scenes/rotor_torque.csv" "$src/scenes/campbell_beam.yaml" "$work/"
ln -s rotor_torque.csv "$work/torque_link.csv"
short="--set solver.t_end=0.01"
refused "run -o onto the scene's time table" run rotor.yaml -o rotor_torque.csv -q $short
refused "run -o onto a link to the time table" run rotor.yaml -o torque_link.csv -q $short
refused "run -o onto the scene" run rotor.yaml -o rotor.yaml -q $short
refused "run --models -o onto the time table" run rotor.yaml --models zoac,complete -o rotor_torque.csv -q $short
refused "static -o onto the scene" static campbell_beam.yaml -o campbell_beam.yaml
refused "modes -o onto the scene" modes campbell_beam.yaml --count 2 -o campbell_beam.yaml
refused "modes --shapes onto the scene" modes campbell_beam.yaml --count 2 -o modes.csv --shapes campbell_beam.yaml
refused "campbell -o onto the scene" campbell campbell_beam.yaml --speed joints.spin.speed --speeds 0:2:2 --count 2 \
  -o campbell_beam.yaml
refused "campbell --plot onto the scene" campbell campbell_beam.yaml --speed joints.spin.speed --speeds 0:2:2 --count 2 \
  -o c.csv --plot campbell_beam.yaml
"$bin" run "$work/rotor.yaml" -o "$work/run.csv" -q $short 2>/dev/null || fail "a short rotor run" "failed"
refused "plot -o onto its CSV" plot run.csv -o run.csv
refused "view -o onto its CSV" view run.csv rotor.yaml -o run.csv
refused "view -o onto the time table" view run.csv rotor.yaml -o rotor_torque.csv

# a plugin is an input: run -o onto it is refused (the test plugin, FLEXMBD_TEST_PLUGIN)
plugin=${FLEXMBD_TEST_PLUGIN:-}
if [ -n "$plugin" ] && [ -f "$plugin" ]; then
  cp "$plugin" "$work/types.csv"
  refused "run -o onto a loaded plugin" run rotor.yaml --plugin ./types.csv -o types.csv -q $short
else
  skips=$((skips + 1))
fi

# a failed campbell (a typo in --speed) leaves the earlier result as it was
printf 'speed,mode1\n0,1\n' >"$work/earlier.csv"
(cd "$work" && "$bin" campbell campbell_beam.yaml --speed joints.spin.sped --speeds 0:2:2 --count 1 -o earlier.csv \
  >/dev/null 2>"$work/.err")
rc=$?
[ "$rc" = 2 ] || fail "campbell with a bad --speed" "exit code $rc, expected 2"
[ "$(cat "$work/earlier.csv")" = "$(printf 'speed,mode1\n0,1')" ] || fail "campbell with a bad --speed" "replaced the earlier result"

# SIGINT: the speeds (models) done so far are kept, exit 4
interrupt() { # NAME OUT ARGS...: start, SIGINT after 1.5 s, expect exit 4 and rows in OUT
  name=$1 out=$2
  shift 2
  (cd "$work" && exec "$bin" "$@" >/dev/null 2>"$work/.err") &
  pid=$!
  sleep 1.5
  kill -INT "$pid" 2>/dev/null
  wait "$pid"
  rc=$?
  [ "$rc" = 4 ] || fail "$name" "exit code $rc, expected 4: $(tail -n 2 "$work/.err")"
  [ "$(wc -l <"$work/$out")" -ge 2 ] 2>/dev/null || fail "$name" "no rows kept in $out"
  grep -q "interrupted" "$work/.err" || fail "$name" "the interruption is not said"
}
interrupt "SIGINT on campbell" camp.csv campbell campbell_beam.yaml --speed joints.spin.speed --speeds 0:20:4000 \
  --count 2 --eigen dense -o camp.csv --plot camp.png
interrupt "SIGINT on run --models" models.csv run rotor.yaml --models complete,zoac -o models.csv -q \
  --set solver.t_end=1e6
file_test_done inputs_overwritten
