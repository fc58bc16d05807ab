#!/bin/sh
# `flexmbd regress` against a hostile user (issue 27, one case per class):
#  inputs overwritten: --junit onto a scene or its reference is refused (exit 2, files unchanged);
#    a.yaml and a.yml that would share one reference are refused;
#  code run from data: a reference's '# set: plugins=[...]' and '# set: vtk=DIR' are not replayed
#    (nothing loaded, nothing written; a note says so);
#  hangs: a per-scene time limit (--timeout); SIGINT kills every child and removes the temporary
#    folder (exit 4);
#  silently wrong: a reference cut short, one whose rows lie outside the run's time span, and one
#    with a second (looser) tolerance line for a column fail; scenes deeper than 32 folders, scene
#    links and scenes without a reference are reported;
#  misleading: a crashed run's message quotes its last stderr line, not a file already deleted.
#   usage: test_regress_hostile.sh FLEXMBD SOURCE_DIR WORKDIR FAULTY_PLUGIN
. "$(dirname "$0")/../sweep/lib.sh" # F SRC D PLUGIN, fail()
mkdir -p "$D/s"
reg() { rc=0; "$F" regress "$@" > "$D/out.txt" 2> "$D/err.txt" || rc=$?; echo "$rc"; }
S=$D/s
cp "$SRC/scenes/fourbar.yaml" "$SRC/scenes/fourbar.ref.csv" "$S/"
[ "$(reg "$S/fourbar.yaml")" = 0 ] || { cat "$D/out.txt"; fail "the copied scene does not pass"; }

# --junit onto an input
for target in "$S/fourbar.yaml" "$S/fourbar.ref.csv"; do
  cp "$target" "$D/before"
  [ "$(reg "$S/fourbar.yaml" --junit "$target")" = 2 ] || fail "--junit onto $target not refused"
  cmp -s "$target" "$D/before" || fail "--junit replaced $target"
done

# a.yaml and a.yml: one reference
mkdir "$D/twin"
cp "$S/fourbar.yaml" "$D/twin/a.yaml"
cp "$S/fourbar.yaml" "$D/twin/a.yml"
cp "$S/fourbar.ref.csv" "$D/twin/a.ref.csv"
[ "$(reg "$D/twin")" = 2 ] && grep -q "would share one reference" "$D/err.txt" || fail "a.yaml + a.yml not refused"
[ "$(reg --bless "$D/twin")" = 2 ] || fail "--bless of a.yaml + a.yml not refused"
cmp -s "$D/twin/a.ref.csv" "$S/fourbar.ref.csv" || fail "--bless a.yaml + a.yml wrote the reference"

# '# set: plugins=[...]' and '# set: vtk=DIR' in a reference: not replayed
mkdir "$D/data"
cp "$S/fourbar.yaml" "$D/data/fourbar.yaml"
sed "s|^# status:|# set: plugins=[$D/evil.so]\n# set: vtk=$D/vtkdir\n# status:|" "$S/fourbar.ref.csv" > "$D/data/fourbar.ref.csv"
grep -q "set: vtk" "$D/data/fourbar.ref.csv" || fail "the edit of the reference did not take"
[ "$(reg "$D/data")" = 0 ] || { cat "$D/out.txt" "$D/err.txt"; fail "a reference with plugins/vtk sets should pass (keys ignored)"; }
[ ! -e "$D/vtkdir" ] || fail "'# set: vtk=DIR' was replayed: $D/vtkdir written"
grep -q "note: .*set: plugins=.*is not replayed" "$D/out.txt" || fail "no note about the plugins set line"

# per-scene time limit
cp "$SRC/scenes/paper/pendulum.yaml" "$SRC/scenes/paper/pendulum.ref.csv" "$S/"
[ "$(reg "$S/pendulum.yaml" --timeout 0.05)" = 1 ] && grep -q "no result within --timeout 0.05 s" "$D/out.txt" ||
  { cat "$D/out.txt"; fail "--timeout does not stop a long scene"; }

# SIGINT: children killed, temporary folder removed, exit 4
mkdir "$D/tmp"
TMPDIR=$D/tmp "$F" regress "$S/pendulum.yaml" "$S/fourbar.yaml" -j 2 > "$D/int.out" 2>&1 &
pid=$!
sleep 0.3
kill -INT $pid
rc=0
wait $pid || rc=$?
[ "$rc" = 4 ] || fail "SIGINT: exit $rc, expected 4"
[ -z "$(ls -A "$D/tmp")" ] || fail "SIGINT left the temporary folder: $(ls "$D/tmp")"
sleep 0.2
! pgrep -f "regress $S/pendulum.yaml" > /dev/null || fail "SIGINT left children running"

# a reference cut short: its last rows lost
mkdir "$D/short"
cp "$S/fourbar.yaml" "$D/short/"
head -n -5 "$S/fourbar.ref.csv" > "$D/short/fourbar.ref.csv"
[ "$(reg "$D/short/fourbar.yaml")" = 2 ] && grep -q "cut short" "$D/out.txt" || { cat "$D/out.txt"; fail "a reference cut short passes"; }

# rows outside the run's time span (all at t - 1000: nothing would be compared)
mkdir "$D/span"
cp "$S/fourbar.yaml" "$D/span/"
awk -F, 'BEGIN { OFS = "," } /^#/ { if ($0 ~ /^# t_reached:/) print "# t_reached: -995"; else print; next }
  /^t,/ { print; next } { $1 = $1 - 1000; print }' "$S/fourbar.ref.csv" > "$D/span/fourbar.ref.csv"
[ "$(reg "$D/span/fourbar.yaml")" = 1 ] && grep -q "outside the run's time span" "$D/out.txt" ||
  { cat "$D/out.txt"; fail "a reference outside the run's time span passes"; }

# a second, looser tolerance line for a column
mkdir "$D/dup"
cp "$S/fourbar.yaml" "$D/dup/"
line=$(grep -m1 "^# tolerance: crank.theta" "$S/fourbar.ref.csv")
sed "s|^$line\$|$line\n# tolerance: crank.theta atol=1e+06 rtol=1 override|" "$S/fourbar.ref.csv" > "$D/dup/fourbar.ref.csv"
[ "$(grep -c "^# tolerance: crank.theta" "$D/dup/fourbar.ref.csv")" = 2 ] || fail "the duplicate line was not added"
[ "$(reg "$D/dup/fourbar.yaml")" = 2 ] && grep -q "a second tolerance line for column 'crank.theta'" "$D/out.txt" ||
  { cat "$D/out.txt"; fail "a duplicated tolerance line is accepted"; }

# reported, not skipped silently: a folder 33 deep, a link to a scene, a scene without a reference
mkdir "$D/tree"
cp "$S/fourbar.yaml" "$S/fourbar.ref.csv" "$D/tree/"
deep=$D/tree
for i in $(seq 34); do deep=$deep/d; done
mkdir -p "$deep"
cp "$S/fourbar.yaml" "$S/fourbar.ref.csv" "$deep/"
ln -s "$D/tree/fourbar.yaml" "$D/tree/link.yaml"
cp "$S/fourbar.yaml" "$D/tree/noref.yaml"
[ "$(reg "$D/tree")" = 0 ] || { cat "$D/out.txt"; fail "the tree's one scene with a reference should pass"; }
grep -q "note: .*more than 32 folders deep" "$D/out.txt" || fail "the deep folder is not reported"
grep -q "note: .*link.yaml: a symbolic link" "$D/out.txt" || fail "the scene link is not reported"
grep -q "note: .*noref.yaml: no reference" "$D/out.txt" || fail "the scene without a reference is not reported"

# a crash: the message quotes the run's last stderr line (the file itself is gone with the tmp folder)
mkdir "$D/crash"
sed "s|^solver:|plugins: [$PLUGIN]\nsolver:|" "$SRC/tests/sweep/faulty.yaml" > "$D/crash/faulty.yaml"
"$F" regress --bless "$D/crash/faulty.yaml" > /dev/null 2>&1 || fail "--bless of the faulty scene (fault 0)"
sed -i 's/fault: 0/fault: 1/' "$D/crash/faulty.yaml"
[ "$(reg "$D/crash/faulty.yaml")" = 1 ] && grep -q "the run crashed (signal 11" "$D/out.txt" ||
  { cat "$D/out.txt"; fail "a crash is not reported as such"; }
grep -q "is in /" "$D/out.txt" && fail "the crash message points at a deleted file"
echo "test_regress_hostile: ok"
