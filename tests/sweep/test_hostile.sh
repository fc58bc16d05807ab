#!/bin/sh
# The hostile pass over `flexmbd sweep` (issue 36), one case per class, each failing on the sweep
# before it (13344e9):
#  1. code from data: a tab in a --samples value, a quote or bracket in a --grid value, a line break
#     and a tab in the output folder's name, a plugin that prints answer-shaped lines on stdout;
#  2. the folder is the sweep's own: a second sweep on it is refused naming pid and host, a lock
#     left by a dead sweep is no obstacle; plan.csv/table.csv of someone else (-o ., --dry-run),
#     an input in the folder, links planted for .plan.csv.tmp, logs/check.err, inflight.log, logs/;
#  3. a scene edited while its sweep runs: every row is of the scene as it was at the start;
#  4. a full disk (a small tmpfs, when this process may mount one): exit 3 saying so, no row for
#     the runs it cut, and a resume on a larger disk does exactly those;
#  5. plans: N of A:B:N whole, huge plans refused before they are built, FIFOs and devices as
#     inputs or journal refused at once, a 301-digit value refused, --metric checked first.
#   usage: test_hostile.sh FLEXMBD SOURCE_DIR WORKDIR FAULTY_PLUGIN
. "$(dirname "$0")/lib.sh"
SCENE=$SRC/scenes/fourbar.yaml
TAB=$(printf '\t')
NL='
'
# rows of a table, by column name: the value of column $2 in row index $3 of table $1
cell() { awk -F, -v c="$2" -v i="$3" 'NR == 1 { for (k = 1; k <= NF; k++) if ($k == c) n = k } NR > 1 && $1 == i { print $n }' "$1"; }
# a command that must end within $1 seconds (a hang is a failure, not a stuck test)
within() {
  t=$1
  shift
  timeout -s KILL "$t" "$@"
}

# ---- 1. code from data ---------------------------------------------------------------------------
# a tab inside a samples value (row 2: only run 0 was checked before the sweep) is refused with its
# place, before any run: it used to become a second override of the serve runner
printf 'solver.rtol\n1e-6\n1.5%splugins=[/nonexistent/x.so]\n' "$TAB" > "$D/inject.csv"
rc=0
"$F" sweep "$SCENE" -o "$D/inject" --quiet --set solver.t_end=0.2 --samples "$D/inject.csv" 2> "$D/inject.err" || rc=$?
[ "$rc" = 2 ] || { cat "$D/inject.err"; fail "a tab in a samples value: exit $rc, expected 2"; }
grep -q "inject.csv:3:1: .*not byte 0x09" "$D/inject.err" || { cat "$D/inject.err"; fail "the tab's place is not named"; }
[ ! -s "$D/inject/runs.csv" ] || fail "a run was made from a refused plan"
for v in '1,"x' '[1]' '{a}' "2${NL}3"; do
  rc=0
  "$F" sweep "$SCENE" -o "$D/inject2" --quiet --dry-run --grid "solver.rtol=1e-6,$v" 2> "$D/inject2.err" || rc=$?
  [ "$rc" = 2 ] && grep -q -- "--grid: a value is a number or a word" "$D/inject2.err" ||
    { cat "$D/inject2.err"; fail "--grid value '$v': exit $rc"; }
done
# the output folder's name holds a tab and a line break: one field of the runner's request, rows ok
# and equal to those of a plain folder
ODD="$D/odd${TAB}dir${NL}x"
"$F" sweep "$SCENE" -o "$ODD" -j 2 --quiet --runner serve --set solver.t_end=0.5 --grid solver.rtol=1e-6,1e-7,1e-8 \
  2> "$D/odd.err" || { cat "$D/odd.err"; fail "a folder name with a tab and a line break"; }
"$F" sweep "$SCENE" -o "$D/plain" -j 2 --quiet --runner spawn --set solver.t_end=0.5 --grid solver.rtol=1e-6,1e-7,1e-8 \
  2> "$D/plain.err" || { cat "$D/plain.err"; fail "the plain sweep"; }
for i in 0 1 2; do
  [ "$(cell "$ODD/table.csv" status $i)" = ok ] || { cat "$ODD/table.csv"; fail "odd folder: run $i not ok"; }
  [ "$(cell "$ODD/table.csv" steps $i)" = "$(cell "$D/plain/table.csv" steps $i)" ] || fail "odd folder: run $i steps differ"
done
# a plugin printing answer-shaped lines on stdout at every load: every row is still its own run's
# (the steps of the spawned runs, which stdout cannot reach) and ok
for runner in serve spawn; do
  "$F" sweep "$SRC/tests/sweep/faulty.yaml" --plugin "$PLUGIN" -o "$D/chatty_$runner" -j 1 --quiet --runner $runner \
    --grid "bodies.f.fault=7,0" --grid "solver.t_end=0.1,0.2,0.3" 2> "$D/chatty.err" ||
    { cat "$D/chatty.err"; fail "the chatty plugin's sweep ($runner)"; }
done
for i in 0 1 2 3 4 5; do
  [ "$(cell "$D/chatty_serve/table.csv" status $i)" = ok ] || { cat "$D/chatty_serve/table.csv"; fail "chatty: run $i not ok"; }
  for c in t_reached steps residuals; do
    [ "$(cell "$D/chatty_serve/table.csv" $c $i)" = "$(cell "$D/chatty_spawn/table.csv" $c $i)" ] ||
      { cat "$D/chatty_serve/table.csv"; fail "chatty plugin: run $i has another run's $c under --runner serve"; }
  done
done

# ---- 2. the folder is the sweep's own --------------------------------------------------------------
# a second sweep on a folder in use is refused, naming the first's pid and host
"$F" sweep "$SRC/tests/sweep/faulty.yaml" --plugin "$PLUGIN" -o "$D/busy" -j 1 --quiet --timeout 30 --runner spawn \
  --grid "bodies.f.fault=3" 2> "$D/busy1.err" &
first=$!
n=0
while [ ! -s "$D/busy/inflight.log" ] && [ $n -lt 100 ]; do sleep 0.1; n=$((n + 1)); done
rc=0
within 20 "$F" sweep "$SRC/tests/sweep/faulty.yaml" --plugin "$PLUGIN" -o "$D/busy" -j 1 --quiet --runner spawn \
  --grid "bodies.f.fault=3" 2> "$D/busy2.err" || rc=$?
kill -TERM $first
wait $first || true
[ "$rc" = 2 ] || { cat "$D/busy2.err"; fail "a second sweep on a folder in use: exit $rc, expected 2"; }
grep -q "in use by another sweep (pid $first on host $(hostname)" "$D/busy2.err" ||
  { cat "$D/busy2.err"; fail "the refusal does not name the first sweep's pid and host"; }
# a lock left by a sweep that died (kill -9: its pid gone) is no obstacle
mkdir -p "$D/stale"
echo "pid 999999 host $(hostname)" > "$D/stale/sweep.lock"
"$F" sweep "$SCENE" -o "$D/stale" --quiet --set solver.t_end=0.2 --grid solver.rtol=1e-6,1e-7 2> "$D/stale.err" ||
  { cat "$D/stale.err"; fail "a stale lock stopped the sweep"; }
grep -q "pid [0-9]* host" "$D/stale/sweep.lock" && ! grep -q "pid 999999" "$D/stale/sweep.lock" || fail "the lock was not taken over"
# someone's plan.csv and table.csv in the folder (-o ., --dry-run): refused, byte for byte kept
mkdir -p "$D/mine"
echo "my plan" > "$D/mine/plan.csv"
echo "my table" > "$D/mine/table.csv"
for dry in --dry-run ""; do
  rc=0
  (cd "$D/mine" && "$F" sweep "$SCENE" -o . --quiet $dry --set solver.t_end=0.2 --grid solver.rtol=1e-6,1e-7) \
    2> "$D/mine.err" || rc=$?
  [ "$rc" = 2 ] || { cat "$D/mine.err"; fail "-o . over my plan.csv ($dry): exit $rc"; }
  grep -q "plan.csv was not made by a sweep" "$D/mine.err" || { cat "$D/mine.err"; fail "-o .: the message"; }
  [ "$(cat "$D/mine/plan.csv")" = "my plan" ] && [ "$(cat "$D/mine/table.csv")" = "my table" ] ||
    fail "-o . replaced my files ($dry)"
done
# the samples file is the folder's plan.csv: an input, never replaced
mkdir -p "$D/own_input"
printf 'solver.rtol\n1e-6\n1e-7\n' > "$D/own_input/plan.csv"
cp "$D/own_input/plan.csv" "$D/own_input.keep"
rc=0
"$F" sweep "$SCENE" -o "$D/own_input" --quiet --set solver.t_end=0.2 --samples "$D/own_input/plan.csv" 2> "$D/own.err" || rc=$?
[ "$rc" = 2 ] && cmp -s "$D/own_input/plan.csv" "$D/own_input.keep" || { cat "$D/own.err"; fail "the samples file was replaced"; }
# the reference is the folder's table.csv: refused at the start, not after the runs
mkdir -p "$D/ref_in"
"$F" run "$SCENE" -o "$D/ref_in/table.csv" --quiet --set solver.t_end=0.2 2> /dev/null || fail "the reference run"
cp "$D/ref_in/table.csv" "$D/ref_in.keep"
rc=0
"$F" sweep "$SCENE" -o "$D/ref_in" --quiet --set solver.t_end=0.2 --grid solver.rtol=1e-6 --reference "$D/ref_in/table.csv" \
  2> "$D/ref_in.err" || rc=$?
[ "$rc" = 2 ] && cmp -s "$D/ref_in/table.csv" "$D/ref_in.keep" && [ ! -e "$D/ref_in/runs.csv" ] ||
  { cat "$D/ref_in.err"; fail "the reference as the folder's table.csv: exit $rc"; }
# links planted in a shared folder: .plan.csv.tmp and logs/check.err redirect nothing, a linked
# inflight.log or logs/ is refused; the victim stays as it was
echo "victim" > "$D/victim"
mkdir -p "$D/linked"
ln -s "$D/victim" "$D/linked/.plan.csv.tmp"
ln -s "$D/victim" "$D/linked/.table.csv.tmp"
"$F" sweep "$SCENE" -o "$D/linked" --quiet --set solver.t_end=0.2 --grid solver.rtol=1e-6,1e-7 2> "$D/linked.err" ||
  { cat "$D/linked.err"; fail "a sweep beside planted links"; }
[ "$(cat "$D/victim")" = victim ] || fail "a planted link redirected a write of the sweep"
for planted in logs/check.err series/0123456789abcdef.csv; do
  rm -rf "$D/linked_sub"
  mkdir -p "$D/linked_sub/logs" "$D/linked_sub/series"
  ln -s "$D/victim" "$D/linked_sub/$planted"
  rc=0
  "$F" sweep "$SCENE" -o "$D/linked_sub" --quiet --set solver.t_end=0.2 --grid solver.rtol=1e-6 2> "$D/linked.err" || rc=$?
  [ "$rc" = 2 ] && grep -q "is a symbolic link" "$D/linked.err" || { cat "$D/linked.err"; fail "a link as $planted: exit $rc"; }
  [ "$(cat "$D/victim")" = victim ] && [ -L "$D/linked_sub/$planted" ] || fail "a link as $planted: victim or link changed"
done
# someone's inflight.log (no journal beside it) is not appended to
mkdir -p "$D/their_log"
echo "their log" > "$D/their_log/inflight.log"
rc=0
"$F" sweep "$SCENE" -o "$D/their_log" --quiet --set solver.t_end=0.2 --grid solver.rtol=1e-6 2> "$D/their.err" || rc=$?
[ "$rc" = 2 ] && [ "$(cat "$D/their_log/inflight.log")" = "their log" ] || { cat "$D/their.err"; fail "someone's inflight.log: exit $rc"; }
mkdir -p "$D/linked2"
ln -s "$D/victim" "$D/linked2/inflight.log"
rc=0
"$F" sweep "$SCENE" -o "$D/linked2" --quiet --set solver.t_end=0.2 --grid solver.rtol=1e-6 2> "$D/linked2.err" || rc=$?
[ "$rc" = 2 ] && [ "$(cat "$D/victim")" = victim ] || { cat "$D/linked2.err"; fail "a linked inflight.log: exit $rc"; }
mkdir -p "$D/linked3" "$D/elsewhere"
ln -s "$D/elsewhere" "$D/linked3/logs"
rc=0
"$F" sweep "$SCENE" -o "$D/linked3" --quiet --set solver.t_end=0.2 --grid solver.rtol=1e-6 2> "$D/linked3.err" || rc=$?
[ "$rc" = 2 ] && [ -z "$(ls "$D/elsewhere")" ] || { cat "$D/linked3.err"; fail "a linked logs/: exit $rc"; }

# ---- 3. the scene is the one of the start -------------------------------------------------------
cp "$SRC/tests/sweep/faulty.yaml" "$D/edited.yaml"
"$F" sweep "$D/edited.yaml" --plugin "$PLUGIN" -o "$D/edited" -j 1 --quiet --timeout 3 --runner spawn \
  --grid "bodies.f.fault=3,0,0" --grid "solver.rtol=1e-6,1e-7" 2> "$D/edited.err" &
sweep=$!
n=0
while [ ! -s "$D/edited/inflight.log" ] && [ $n -lt 100 ]; do sleep 0.1; n=$((n + 1)); done
sed 's/t_end: 0.2/t_end: 0.1/' "$SRC/tests/sweep/faulty.yaml" > "$D/edited.yaml" # while run 0 hangs
wait $sweep || { cat "$D/edited.err"; fail "the sweep of the edited scene"; }
for i in 2 3 4 5; do
  [ "$(cell "$D/edited/table.csv" t_reached $i)" = 0.2 ] ||
    { cat "$D/edited/table.csv"; fail "run $i is of the scene edited during the sweep"; }
done

# the snapshot still finds what the scene names beside it (rotor.yaml's table rotor_torque.csv):
# the rows equal those of the scene run in place
"$F" sweep "$SRC/scenes/rotor.yaml" -o "$D/rotor" --quiet --keep series --set solver.t_end=0.2 --grid solver.rtol=1e-6 \
  2> "$D/rotor.err" || { cat "$D/rotor.err"; fail "a scene with a relative table file"; }
"$F" run "$SRC/scenes/rotor.yaml" -o "$D/rotor.csv" --quiet --set solver.t_end=0.2 --set solver.rtol=1e-06 2> /dev/null ||
  fail "the rotor run"
cmp -s "$D/rotor.csv" "$D/rotor/series/$(cell "$D/rotor/table.csv" run_id 0).csv" || fail "the snapshot's rotor run differs"

# ---- 5. plans ----------------------------------------------------------------------------------------
for n in 2.5 3abc 0 -4 1e3.5; do
  rc=0
  "$F" sweep "$SCENE" -o "$D/grid" --dry-run --grid "solver.rtol=1e-3:1e-6:$n" > /dev/null 2> "$D/grid.err" || rc=$?
  [ "$rc" = 2 ] && grep -q -- "--grid: N (the number of values) must be a whole number.*'$n'" "$D/grid.err" ||
    { cat "$D/grid.err"; fail "--grid A:B:$n: exit $rc"; }
done
"$F" sweep "$SCENE" -o "$D/grid" --dry-run --set solver.t_end=0.2 --grid "solver.rtol=1e-3:1e-6:1e3" > "$D/grid.out" 2> /dev/null ||
  fail "--grid A:B:1e3"
grep -q "sweep plan: 1000 runs" "$D/grid.out" || { cat "$D/grid.out"; fail "--grid A:B:1e3 is not 1000 runs"; }
# huge plans: refused (or sized by --dry-run) before anything is laid out: 1e8 values would take
# gigabytes, the limit here is 300 MB (not under ASan, whose shadow memory alone is larger: there
# the 20 s bound is what remains of the check)
vlimit=300000
[ -n "${FLEXMBD_SANITIZE:-}" ] && vlimit=unlimited
for spec in "--grid solver.rtol=1e-3:1e-6:100000000" "--random solver.rtol=uniform(1e-6,1e-5) --count 1e8"; do
  rc=0
  (ulimit -v $vlimit && within 20 "$F" sweep "$SCENE" -o "$D/huge" $spec) 2> "$D/huge.err" || rc=$?
  [ "$rc" = 2 ] && grep -q "add --yes" "$D/huge.err" || { cat "$D/huge.err"; fail "a huge plan ($spec): exit $rc"; }
  (ulimit -v $vlimit && within 20 "$F" sweep "$SCENE" -o "$D/huge" --dry-run $spec) > "$D/huge.out" 2>&1 ||
    { cat "$D/huge.out"; fail "--dry-run of a huge plan ($spec)"; }
  grep -q "100000000 runs" "$D/huge.out" || { cat "$D/huge.out"; fail "--dry-run of a huge plan: its size"; }
done
# FIFOs and devices as the samples, the journal or inflight.log: refused at once, never waited on
mkfifo "$D/fifo.csv"
for samples in "$D/fifo.csv" /dev/zero; do
  rc=0
  within 10 "$F" sweep "$SCENE" -o "$D/fifo" --samples "$samples" 2> "$D/fifo.err" || rc=$?
  [ "$rc" = 2 ] && grep -q "not a regular file" "$D/fifo.err" || { cat "$D/fifo.err"; fail "--samples $samples: exit $rc"; }
done
for name in runs.csv inflight.log; do
  rm -rf "$D/fifodir"
  mkdir -p "$D/fifodir"
  mkfifo "$D/fifodir/$name"
  rc=0
  within 10 "$F" sweep "$SCENE" -o "$D/fifodir" --quiet --set solver.t_end=0.2 --grid solver.rtol=1e-6 2> "$D/fifo.err" || rc=$?
  [ "$rc" = 2 ] && grep -q "not a regular file\|not made by a sweep" "$D/fifo.err" ||
    { cat "$D/fifo.err"; fail "a FIFO as $name: exit $rc"; }
  rc=0
  within 10 "$F" sweep --status "$D/fifodir" > /dev/null 2>&1 || rc=$?
  [ "$rc" != 137 ] || fail "--status waits on a FIFO $name"
done
# a value of 301 digits is refused, not cut to 255 characters
big=1$(printf '%0300d' 0)
printf 'solver.t_end\n%s\n' "$big" > "$D/big.csv"
rc=0
"$F" sweep "$SCENE" -o "$D/big" --dry-run --samples "$D/big.csv" > /dev/null 2> "$D/big.err" || rc=$?
[ "$rc" = 2 ] && grep -q "big.csv:2:1: a value of 301 characters (at most 255)" "$D/big.err" ||
  { cat "$D/big.err"; fail "a 301-digit value: exit $rc"; }
# --metric of a column the runs do not have: refused before any run
rc=0
"$F" sweep "$SCENE" -o "$D/metric" --quiet --set solver.t_end=0.2 --grid solver.rtol=1e-6,1e-7 --metric crank.thetaa:max \
  2> "$D/metric.err" || rc=$?
[ "$rc" = 2 ] && grep -q -- "--metric crank.thetaa: the runs have no column 'crank.thetaa'" "$D/metric.err" ||
  { cat "$D/metric.err"; fail "--metric of an unknown column: exit $rc"; }
[ ! -e "$D/metric/runs.csv" ] || [ "$(grep -c '^[0-9]' "$D/metric/runs.csv")" = 0 ] || fail "--metric: runs were made"

# ---- 4. a full disk (last: it may be skipped) ----------------------------------------------------
mkdir -p "$D/full"
if ! mount -t tmpfs -o size=160k tmpfs "$D/full" 2> /dev/null; then
  echo "test_hostile: cannot mount a tmpfs here (not root, or no CAP_SYS_ADMIN): the full-disk case is skipped"
  exit 77
fi
trap 'umount "$D/full" 2> /dev/null || true' EXIT
cp "$SCENE" "$D/fb.yaml"
rc=0
"$F" sweep "$D/fb.yaml" -o "$D/full/s" -j 2 --quiet --keep series --set solver.t_end=1 --grid "solver.rtol=1e-6:1e-7:40" \
  2> "$D/full.err" || rc=$?
[ "$rc" = 3 ] && grep -q "the disk is full" "$D/full.err" || { cat "$D/full.err"; fail "a full disk: exit $rc, expected 3"; }
grep -q "writing the output failed" "$D/full/s/runs.csv" && fail "a run cut by the disk was kept as a result"
rows=$(grep -c '^[0-9]' "$D/full/s/runs.csv" || true)
[ "$rows" -lt 40 ] || fail "the disk was not full after all ($rows rows)"
mount -o remount,size=8m "$D/full"
"$F" sweep "$D/fb.yaml" -o "$D/full/s" -j 2 --quiet --keep series --set solver.t_end=1 --grid "solver.rtol=1e-6:1e-7:40" \
  2> "$D/full2.err" || { cat "$D/full2.err"; fail "the resume on a larger disk"; }
[ "$(tail -n +2 "$D/full/s/table.csv" | cut -d, -f4 | sort | uniq -c | tr -s ' ')" = " 40 ok" ] ||
  { cat "$D/full/s/table.csv"; fail "after the resume: not 40 ok runs"; }
[ "$(grep '^[0-9]' "$D/full/s/runs.csv" | cut -d, -f2 | sort | uniq -d)" = "" ] || fail "a run has two rows"
echo "test_hostile: ok"
