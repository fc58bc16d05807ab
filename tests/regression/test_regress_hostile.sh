#!/bin/sh
# `flexmbd regress` against a hostile user (issue 27, one case per class):
#  inputs overwritten: --junit onto a scene or its reference is refused (exit 2, files unchanged);
#    a.yaml and a.yml that would share one reference are refused;
#  code run from data: a reference's '# set: plugins=[...]' and '# set: vtk=DIR' are not replayed
#    (nothing loaded, nothing written; a note says so);
#  hangs: a per-scene time limit (--timeout); SIGINT kills every child and removes the temporary
#    folder (exit 4);
#  silently wrong: a reference cut short, one whose rows lie outside the run's time span, and one
#    with a second (looser) tolerance line for a column fail; scenes deep down and behind links
#    run, scenes without a reference are reported, a folder beyond the search's depth is refused;
#    a.yml blessed after a.yaml is refused; a bad --set is bad input (exit 2); '# status: OK' is ok
#    and an unknown status is refused;
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

# not skipped: a folder 34 deep is searched, links to scenes and folders are followed (each folder
# once, under its real name first, a loop noted), a scene without a reference is reported, and a
# folder deeper than the search goes (256) is refused rather than passed over
mkdir "$D/tree"
cp "$S/fourbar.yaml" "$S/fourbar.ref.csv" "$D/tree/"
deep=$D/tree
for i in $(seq 34); do deep=$deep/d; done
mkdir -p "$deep"
cp "$S/fourbar.yaml" "$S/fourbar.ref.csv" "$deep/"
ln -s "$D/tree/fourbar.yaml" "$D/tree/link.yaml"
ln -s "$D/tree/fourbar.yaml" "$D/tree/linked.yaml"
cp "$S/fourbar.ref.csv" "$D/tree/linked.ref.csv"
ln -s "$D/tree" "$D/tree/d/loop"
mkdir "$D/elsewhere"
cp "$S/fourbar.yaml" "$S/fourbar.ref.csv" "$D/elsewhere/"
ln -s "$D/elsewhere" "$D/tree/shared"
cp "$S/fourbar.yaml" "$D/tree/noref.yaml"
[ "$(reg "$D/tree")" = 0 ] || { cat "$D/out.txt" "$D/err.txt"; fail "the tree's scenes with a reference should pass"; }
grep -q "regress: 4 passed, 0 failed" "$D/out.txt" || { cat "$D/out.txt"; fail "not every scene of the tree ran"; }
grep -q "^$deep/fourbar.yaml " "$D/out.txt" || fail "the scene 34 folders deep did not run"
grep -q "^$D/tree/linked.yaml " "$D/out.txt" || fail "the link to a scene with a reference did not run"
grep -q "^$D/tree/shared/fourbar.yaml " "$D/out.txt" || fail "the scene in a linked folder did not run"
grep -q "note: .*link.yaml: no reference" "$D/out.txt" || fail "the link without a reference is not reported"
grep -q "note: .*loop: a symbolic link to a folder searched already" "$D/out.txt" || fail "the loop is not reported"
grep -q "note: .*noref.yaml: no reference" "$D/out.txt" || fail "the scene without a reference is not reported"
mkdir "$D/abyss"
abyss=$D/abyss
for i in $(seq 258); do abyss=$abyss/d; done
mkdir -p "$abyss"
cp "$S/fourbar.yaml" "$S/fourbar.ref.csv" "$abyss/"
[ "$(reg "$D/abyss")" = 2 ] && grep -q "more than 256 folders deep: not searched" "$D/err.txt" ||
  { cat "$D/out.txt" "$D/err.txt"; fail "a scene beyond the search's depth is passed over"; }

# a.yml blessed after a.yaml: one reference for two scenes, refused however they are named
mkdir "$D/twin2"
cp "$S/fourbar.yaml" "$D/twin2/a.yaml"
[ "$(reg --bless "$D/twin2/a.yaml")" = 0 ] || fail "--bless of a lone a.yaml"
cp "$D/twin2/a.ref.csv" "$D/twin2/before"
sed 's/speed: 2.0/speed: 2.5/' "$S/fourbar.yaml" > "$D/twin2/a.yml"
for cmdline in "--bless $D/twin2/a.yml" "$D/twin2/a.yml" "--bless $D/twin2/a.yaml" "$D/twin2/a.yaml"; do
  # shellcheck disable=SC2086
  [ "$(reg $cmdline)" = 2 ] && grep -q "would share one reference" "$D/err.txt" ||
    { cat "$D/out.txt" "$D/err.txt"; fail "regress $cmdline beside its twin not refused"; }
done
cmp -s "$D/twin2/a.ref.csv" "$D/twin2/before" || fail "a.yml's bless touched a.yaml's reference"

# a --set that is the caller's mistake: exit 2 (bad input), not 1 (a failed scene)
[ "$(reg "$S/fourbar.yaml" --set solver.rtol=abc)" = 2 ] && grep -q "set does not apply to this scene" "$D/out.txt" ||
  { cat "$D/out.txt" "$D/err.txt"; fail "a bad --set value is not bad input"; }
[ "$(reg "$S/fourbar.yaml" --set solver.rtol 1e-6)" = 2 ] && grep -q "solver.rtol: expected PATH=VALUE in one argument" "$D/err.txt" ||
  { cat "$D/err.txt"; fail "--set PATH VALUE (a space for =) is not named"; }

# '# status: OK ' (a reference edited by hand) is ok, not "stopped" (a good run then failed for
# completing); a status that is neither is a malformed reference
mkdir "$D/status"
cp "$S/fourbar.yaml" "$D/status/"
sed 's/^# status: ok$/# status: OK  /' "$S/fourbar.ref.csv" > "$D/status/fourbar.ref.csv"
grep -q "^# status: OK  $" "$D/status/fourbar.ref.csv" || fail "the status edit did not take"
[ "$(reg "$D/status/fourbar.yaml")" = 0 ] || { cat "$D/out.txt"; fail "'# status: OK' fails a good run"; }
sed -i 's/^# status: OK  $/# status: finished/' "$D/status/fourbar.ref.csv"
[ "$(reg "$D/status/fourbar.yaml")" = 2 ] && grep -q "expected '# status: ok' or '# status: stopped'" "$D/out.txt" ||
  { cat "$D/out.txt"; fail "an unknown status is not refused"; }

# a crash: the message quotes the run's last stderr line (the file itself is gone with the tmp folder)
mkdir "$D/crash"
sed "s|^solver:|plugins: [$PLUGIN]\nsolver:|" "$SRC/tests/sweep/faulty.yaml" > "$D/crash/faulty.yaml"
"$F" regress --bless "$D/crash/faulty.yaml" > /dev/null 2>&1 || fail "--bless of the faulty scene (fault 0)"
sed -i 's/fault: 0/fault: 1/' "$D/crash/faulty.yaml"
[ "$(reg "$D/crash/faulty.yaml")" = 1 ] && grep -q "the run crashed (signal 11" "$D/out.txt" ||
  { cat "$D/out.txt"; fail "a crash is not reported as such"; }
grep -q "is in /" "$D/out.txt" && fail "the crash message points at a deleted file"
echo "test_regress_hostile: ok"
