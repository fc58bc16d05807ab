#!/bin/sh
# test_shorthand.sh FLEXMBD SOURCE_DIR OUTDIR — scenes short to write:
#   - named materials and sections: a beam naming them moves exactly like one with the numbers
#     written out (every CSV value identical); an item's own key wins over its material's; a
#     misspelt material is exit 2 at its file:line:column with the defined names; a bad value in a
#     material is reported where the material defines it;
#   - angles: `120 deg` is 2 pi / 3 to the last digit, `-240deg` is -4 pi / 3, `x rad` is x; a bare
#     120 is radians with a warning at its line and column; `30 degrees` is exit 2.
set -u
flexmbd=$1 src=$2 out=$3
rm -rf "$out" && mkdir -p "$out" && cd "$out" || exit 1
fail=0
scenes=$src/tests/ux/scenes

$flexmbd run "$scenes/materials.yaml" -o mat.csv 2>mat.err || { echo "FAIL: materials run: $(cat mat.err)"; fail=1; }
awk -F, 'NR > 1 && $2 != $3 { bad = 1; print "FAIL: row " NR ": " $2 " != " $3 } END { exit bad }' mat.csv || fail=1
awk -F, 'END { if ($2 + 0 == 0) { print "FAIL: the beams do not move"; exit 1 } }' mat.csv || fail=1
# the item's own key wins: a stiffer beam a deflects differently from b
$flexmbd run "$scenes/materials.yaml" -o own.csv --set bodies.a.youngs_modulus=1e12 2>/dev/null
awk -F, 'END { if ($2 == $3) { print "FAIL: the item'"'"'s own youngs_modulus was not used"; exit 1 } }' own.csv || fail=1
$flexmbd check "$scenes/materials.yaml" --set bodies.a.material=alu >/dev/null 2>typo.err
rc=$?
[ $rc -eq 2 ] || { echo "FAIL: unknown material: exit $rc"; fail=1; }
grep -q "no material named 'alu' (defined under 'materials' at the top level: aluminium, steel)" typo.err || { echo "FAIL: $(cat typo.err)"; fail=1; }
$flexmbd check "$scenes/materials.yaml" --set materials.aluminium.density=-1 >/dev/null 2>neg.err
grep -q "materials.aluminium.density=-1: expected a positive number for 'density'" neg.err || { echo "FAIL: bad material value: $(cat neg.err)"; fail=1; }
$flexmbd check "$scenes/materials.yaml" --set materials.aluminium.colour=red >/dev/null 2>unk.err
grep -q "unknown key 'colour' in material 'aluminium'" unk.err || { echo "FAIL: unknown material key: $(cat unk.err)"; fail=1; }

$flexmbd run "$scenes/angles.yaml" -o ang.csv 2>ang.err || { echo "FAIL: angles run: $(cat ang.err)"; fail=1; }
awk -F, 'NR == 2 { pi = atan2(0, -1)
  if ($2 != sprintf("%.12g", 2 * pi / 3)) { print "FAIL: 120 deg = " $2; bad = 1 }
  if ($3 != 120) { print "FAIL: bare 120 = " $3; bad = 1 }
  if ($4 != $2) { print "FAIL: rad = " $4; bad = 1 }
  if ($5 != sprintf("%.12g", -4 * pi / 3)) { print "FAIL: -240deg = " $5; bad = 1 } } END { exit bad }' ang.csv || fail=1
grep -q "angles.yaml:5:56: warning: 'angle: 120' is taken as radians (19.1 turns); write '120 deg'" ang.err || { echo "FAIL: no warning for a bare 120: $(cat ang.err)"; fail=1; }
[ "$(grep -c "warning:" ang.err)" -eq 1 ] || { echo "FAIL: warnings for angles with units"; fail=1; }
$flexmbd check "$scenes/angles.yaml" --set "bodies.a.angle=30 degrees" >/dev/null 2>deg.err
rc=$?
[ $rc -eq 2 ] || { echo "FAIL: '30 degrees': exit $rc"; fail=1; }
grep -q "expected an angle for 'angle' (radians, or with a unit: 120 deg, 2.1 rad), got '30 degrees'" deg.err || { echo "FAIL: $(cat deg.err)"; fail=1; }
[ $fail -eq 0 ] && echo "ok: materials and sections by name, angles with units"
exit $fail
