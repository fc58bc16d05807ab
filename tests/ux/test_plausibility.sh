#!/bin/sh
# test_plausibility.sh FLEXMBD SOURCE_DIR OUT_DIR — values outside the physical range of their unit
# draw one warning each at load, naming the key and the likely unit (engine/yaml_get.c,
# check_plausible): Young's modulus in GPa (68.95 for 68.95e9 Pa), a density in g/cm^3, a length in
# mm, and an exponent too large; none on any shipped scene or starter.
. "$(dirname "$0")/../exact/cli_lib.sh" # F, SRC, OUT, check
cd "$OUT" || exit 1

# the rotor's three blades, each with its modulus in GPa: one warning, not three
sed 's/youngs_modulus: 68.95e9/youngs_modulus: 68.95/' "$SRC/scenes/rotor.yaml" >gpa.yaml
cp "$SRC/scenes/rotor_torque.csv" .
"$F" check gpa.yaml >/dev/null 2>gpa.err
line=$(grep -n 'youngs_modulus: 68.95[,} ]' gpa.yaml | head -1 | cut -d: -f1) # the first blade's line
check "modulus in GPa: one warning at the first blade's key, naming it and GPa" \
  "[ \$(grep -c 'warning:' gpa.err) -eq 1 ] &&
   grep -q \"^gpa.yaml:$line:[0-9]*: warning: 'youngs_modulus: 68.95' is below 100000 Pa.*GPa or MPa given as Pa?\" gpa.err"

"$F" new rotor >rotor.yaml
sed -e 's/density: 2767.0/density: 2.767/' -e 's/length: 1.8 /length: 1800 /' \
  -e 's/youngs_modulus: 68.95e9/youngs_modulus: 68.95e19/' rotor.yaml >units.yaml
"$F" check units.yaml >/dev/null 2>units.err
check "density in g/cm^3 (from the materials entry), length in mm, modulus 6.9e20 Pa: three warnings" \
  "[ \$(grep -c 'warning:' units.err) -eq 3 ] &&
   grep -q \"units.yaml:[0-9]*:[0-9]*: warning: 'density: 2.767' is below 100 kg/m^3.*g/cm^3\" units.err &&
   grep -q \"warning: 'length: 1800' is above 100 m.*mm given as m?\" units.err &&
   grep -q \"warning: 'youngs_modulus: 6.895e+20' is above 1e+13 Pa.*exponent\" units.err"
"$F" check rotor.yaml --set bodies.beam.length=5e-5 >/dev/null 2>short.err
check "a 50 um beam: the warning names the override and km" \
  "grep -q \"^--set: warning: bodies.beam.length=5e-5: 'length: 5e-05' is below 0.0001 m.*km given as m?\" short.err"

n=0
for s in "$SRC"/scenes/*.yaml "$SRC"/scenes/*/*.yaml; do
  "$F" check "$s" >/dev/null 2>>shipped.err
  n=$((n + 1))
done
for st in pendulum beam rotor slider-crank; do
  "$F" new $st >"st_$st.yaml" && "$F" check "st_$st.yaml" >/dev/null 2>>shipped.err
done
check "no warning on the $n shipped scenes and 4 starters" "! grep -q 'warning:' shipped.err"
exit $fail
