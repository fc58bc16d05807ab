#!/bin/sh
# test_models_cli.sh FLEXMBD SOURCE_DIR OUT_DIR — `flexmbd run SCENE --models ...` (tools/run_models.c):
# each model's columns NAME@MODEL equal that model's own run, a stats line per model, exit 3 with
# nan cells after a model stops (ZOAC above its critical speed), exit 2 for bad use.
. "$(dirname "$0")/cli_lib.sh"

"$F" run scenes/paper/spinup_w1.yaml --models complete,exact -o "$OUT/m.csv" --set solver.t_end=2 --quiet 2>"$OUT/m.err"
rc=$?
check "two models run: exit 0" "[ $rc -eq 0 ]"
check "header has beam.tip_v@complete and beam.tip_v@exact" \
  "head -1 '$OUT/m.csv' | grep -q 'beam.tip_v@complete' && head -1 '$OUT/m.csv' | grep -q 'beam.tip_v@exact'"
check "one stats line per model, the last stderr line a stats line" \
  "[ \$(grep -c '^stats: model=' '$OUT/m.err') -eq 2 ] && tail -1 '$OUT/m.err' | grep -q '^stats: model=exact status=ok'"
"$F" run scenes/paper/spinup_w1.yaml -o "$OUT/e.csv" --set solver.t_end=2 --set bodies.beam.model=exact --quiet 2>/dev/null
col=$(head -1 "$OUT/m.csv" | tr , '\n' | grep -n '^beam.tip_v@exact$' | cut -d: -f1)
check "beam.tip_v@exact equals the exact model's own run" \
  "[ \"\$(cut -d, -f$col '$OUT/m.csv' | tail -n +2)\" = \"\$(cut -d, -f2 '$OUT/e.csv' | tail -n +2)\" ]"

"$F" run scenes/paper/spinup_w4.yaml --models zoac,complete -o "$OUT/z.csv" --quiet 2>"$OUT/z.err"
rc=$?
check "ZOAC diverging at omega0 = 4: exit 3, its message, the other model complete" \
  "[ $rc -eq 3 ] && grep -q 'model zoac: .*diverging' '$OUT/z.err' && grep -q '^stats: model=complete status=ok' '$OUT/z.err'"
check "ZOAC's cells after it stopped are nan, complete's are numbers" \
  "tail -1 '$OUT/z.csv' | cut -d, -f2 | grep -q nan && ! tail -1 '$OUT/z.csv' | cut -d, -f12- | grep -q nan"

"$F" run scenes/paper/spinup_w1.yaml --models complete 2>"$OUT/b1.err"; rc=$?
check "--models without -o: exit 2" "[ $rc -eq 2 ] && grep -q 'needs the CSV in a file' '$OUT/b1.err'"
"$F" run scenes/pendulum.yaml --models complete,exact -o "$OUT/b2.csv" 2>"$OUT/b2.err"; rc=$?
check "--models on a scene without a beam: exit 2" "[ $rc -eq 2 ] && grep -q 'no body of type beam' '$OUT/b2.err'"
"$F" run scenes/paper/spinup_w1.yaml --models complete,cubic -o "$OUT/b3.csv" 2>"$OUT/b3.err"; rc=$?
check "--models with an unknown model: exit 2 naming the choices" \
  "[ $rc -eq 2 ] && grep -q \"expected one of zoac, foac, complete, exact for 'model', got 'cubic'\" '$OUT/b3.err'"
# 33 beams: every one switched (a fixed table of 32 once left the 33rd on the scene's model, so its
# @zoac column held the complete model's numbers)
{
  echo "solver: {t_end: 0.3, output_step: 0.01}"
  echo "gravity: [0, -9.81]"
  echo "bodies:"
  i=1
  while [ $i -le 33 ]; do
    echo "  - {name: b$i, type: beam, length: 1, elements: 2, density: 2767, area: 2.5e-4, second_moment: 1.302e-10,"
    echo "     youngs_modulus: 68.95e9, position: [0, $i]}"
    i=$((i + 1))
  done
  echo "joints:"
  i=1
  while [ $i -le 33 ]; do
    echo "  - {name: p$i, type: revolute, body1: ground, body2: b$i, point1: [0, $i]}"
    i=$((i + 1))
  done
  echo "outputs: [b1.tip_v, b33.tip_v]"
} >"$OUT/many.yaml"
"$F" run "$OUT/many.yaml" --models complete,zoac -o "$OUT/many.csv" --quiet 2>"$OUT/many.err"
rc=$?
sets=""
i=1
while [ $i -le 33 ]; do sets="$sets --set bodies.b$i.model=zoac"; i=$((i + 1)); done
"$F" run "$OUT/many.yaml" -o "$OUT/many_zoac.csv" --quiet $sets 2>/dev/null
check "33 beams: exit 0, b33.tip_v@zoac equals an all-ZOAC run's and differs from @complete" \
  "[ $rc -eq 0 ] && [ \"\$(cut -d, -f5 '$OUT/many.csv' | tail -n +2)\" = \"\$(cut -d, -f3 '$OUT/many_zoac.csv' | tail -n +2)\" ] &&
   [ \"\$(cut -d, -f5 '$OUT/many.csv' | tail -n +2)\" != \"\$(cut -d, -f3 '$OUT/many.csv' | tail -n +2)\" ]"
# a model named twice (issue 36): two columns of one name once; now bad input before anything runs
rm -f "$OUT/dup.csv"
"$F" run scenes/paper/spinup_w1.yaml --models complete,complete -o "$OUT/dup.csv" 2>"$OUT/dup.err"; rc=$?
check "--models complete,complete: exit 2 naming the model, nothing written" \
  "[ $rc -eq 2 ] && grep -q \"names 'complete' twice\" '$OUT/dup.err' && [ ! -e '$OUT/dup.csv' ] &&
   ! grep -q '^stats:' '$OUT/dup.err'"
# --vtk with --models (issue 36): was ignored; now each model's animation in DIR/MODEL, the very
# frames of that model's own run with --vtk
rm -rf "$OUT/vtk" "$OUT/vtk_exact"
"$F" run scenes/paper/spinup_w1.yaml --models complete,exact -o "$OUT/v.csv" --set solver.t_end=0.2 --quiet \
  --vtk "$OUT/vtk" --vtk-every 5 2>"$OUT/v.err"; rc=$?
"$F" run scenes/paper/spinup_w1.yaml -o "$OUT/ve.csv" --set solver.t_end=0.2 --set bodies.beam.model=exact --quiet \
  --vtk "$OUT/vtk_exact" --vtk-every 5 2>/dev/null
check "--models with --vtk: exit 0, a collection per model" \
  "[ $rc -eq 0 ] && [ -f '$OUT/vtk/complete/spinup_w1.pvd' ] && [ -f '$OUT/vtk/exact/spinup_w1.pvd' ]"
check "--models --vtk-every 5: the exact model's frames are those of its own run" \
  "[ \$(ls '$OUT/vtk/exact' | wc -l) -eq \$(ls '$OUT/vtk_exact' | wc -l) ] &&
   cmp -s '$OUT/vtk/exact/spinup_w1_000004.vtu' '$OUT/vtk_exact/spinup_w1_000004.vtu'"
exit $fail
