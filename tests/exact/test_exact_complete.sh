#!/bin/sh
# test_exact_complete.sh FLEXMBD SOURCE_DIR OUT_DIR — the exact beam does what the other models do
# (docs/models.md, "What holds for every model"):
#  - `beam.shape`: at small deflection (the ω0 = 1 spin-up, peak tip_v 0.018 m, rtol 1e-8) the exact
#    beam's deformed centreline lies on the complete model's to within the complete model's own error
#    (about 1e-5 m against the exact beam, docs/models.md; measured 1.6e-6 m), at every station and row.
#    A straight (rigid) outline would be 0.018 m off, a mirrored one 0.036 m;
#  - `--vtk` draws it as a polyline through its nodes, like the complete model's;
#  - `tip_angle` of every model under a static tip load P = 1e-3 N: P L^2 / (2 E I) = 1.8045535e-4 rad;
#  - `run --models complete,exact` on every shipped scene with a beam and on the starters, exit 0,
#    except where a scene keeps a key the exact beam refuses (`damping`: exit 2 naming the key).
. "$(dirname "$0")/cli_lib.sh"

"$F" run scenes/paper/spinup_w1.yaml --models complete,exact -o "$OUT/shape.csv" --quiet \
  --set "outputs=[beam.shape, beam.tip_v]" --set solver.rtol=1e-8 2>"$OUT/shape.err"
rc=$?
check "spin-up w1 with beam.shape under complete and exact: exit 0" "[ $rc -eq 0 ]"
awk -F, 'NR == 1 { for (i = 1; i <= NF; i++) col[$i] = i; next }
  { for (k = 0; k <= 16; k++) {
      dx = $col["beam.shape" k "_x@exact"] - $col["beam.shape" k "_x@complete"]
      dy = $col["beam.shape" k "_y@exact"] - $col["beam.shape" k "_y@complete"]
      d = sqrt(dx * dx + dy * dy); if (d > mx) mx = d }
    v = $col["beam.tip_v@exact"]; if (v < 0) v = -v; if (v > peak) peak = v; rows++ }
  END { printf "%d %.6g %.6g\n", rows, mx, peak }' "$OUT/shape.csv" >"$OUT/shape.txt"
read rows dmax peak <"$OUT/shape.txt"
echo "  rows $rows, max |shape_exact - shape_complete| = $dmax m, peak tip_v = $peak m"
check "2001 rows, the exact beam deflects (peak tip_v > 0.015 m)" \
  "[ '$rows' = 2001 ] && awk -v p='$peak' 'BEGIN { exit !(p > 0.015) }'"
check "the exact beam's centreline within 1e-5 m of the complete model's at every station and row" \
  "awk -v d='$dmax' 'BEGIN { exit !(d < 1e-5) }'"

for model in complete exact; do
  "$F" run scenes/paper/spinup_w15.yaml -o "$OUT/v_$model.csv" --vtk "$OUT/vtk_$model" --quiet \
    --set solver.t_end=1 --set solver.output_step=0.5 --set bodies.beam.model=$model 2>/dev/null
done
npts() { grep -ao 'NumberOfPoints="[0-9]*"' "$1" | tr -dc 0-9; }  # -a: the .vtu holds binary appended data
check "--vtk: the exact beam is a polyline through its 17 nodes and the joint point, as the complete model's" \
  "[ \"\$(npts '$OUT/vtk_exact/spinup_w15_000002.vtu')\" = 18 ] &&
   [ \"\$(npts '$OUT/vtk_exact/spinup_w15_000002.vtu')\" = \"\$(npts '$OUT/vtk_complete/spinup_w15_000002.vtu')\" ]"

for model in zoac foac complete exact; do
  "$F" static tests/analysis/scenes/cantilever.yaml --set 'joints.load.force=[0, 1e-3]' --set bodies.beam.model=$model \
    --set "outputs=[beam.tip_angle]" -o "$OUT/angle_$model.csv" -q 2>/dev/null
  a=$(tail -1 "$OUT/angle_$model.csv" | cut -d, -f2)
  check "$model: static tip_angle $a = P L^2/(2EI) to 1e-6" "[ -n '$a' ] && near '$a' 1.8045534899730322e-4 1.8e-10"
done

# every shipped scene with a beam, and the starters, under both models (a short stretch of each)
"$F" new rotor >"$OUT/rotor.yaml" && "$F" new beam >"$OUT/beam.yaml" && "$F" new slider-crank >"$OUT/slider-crank.yaml"
n=0
for s in $(grep -l 'type: beam' scenes/*.yaml scenes/*/*.yaml) "$OUT/rotor.yaml" "$OUT/beam.yaml"; do
  "$F" run "$s" --models complete,exact -o "$OUT/models.csv" --set solver.t_end=0.1 --quiet 2>"$OUT/models.err"
  rc=$?
  check "$s: --models complete,exact exits 0 with an @exact column" \
    "[ $rc -eq 0 ] && head -1 '$OUT/models.csv' | grep -q '@exact'"
  n=$((n + 1))
done
check "9 or more scenes tried" "[ $n -ge 9 ]"
"$F" run "$OUT/rotor.yaml" --models zoac,foac,complete,exact -o "$OUT/tutorial.csv" --quiet 2>"$OUT/tutorial.err"
rc=$?
check "the tutorial's rotor under all four models: exit 3 only for ZOAC diverging, the three others run to the end" \
  "[ $rc -eq 3 ] && grep -q 'model zoac: .*diverging' '$OUT/tutorial.err' &&
   [ \$(grep -c 'status=ok t_reached=8 ' '$OUT/tutorial.err') -eq 3 ]"
"$F" run "$OUT/slider-crank.yaml" --models complete,exact -o "$OUT/sc.csv" --quiet 2>"$OUT/sc.err"
rc=$?
check "the slider-crank starter's damped rod under exact: exit 2 naming 'damping' at its line" \
  "[ $rc -eq 2 ] && grep -q 'slider-crank.yaml:[0-9]*:[0-9]*: error: .damping. is not available with model: exact' '$OUT/sc.err'"
exit $fail
