#!/bin/sh
# test_plot.sh FLEXMBD SOURCE_DIR OUTDIR — `flexmbd plot` makes real figures:
#   one CSV, every column, default name OUT.png: a PNG (signature) of some size;
#   three CSVs overlaid into an SVG: one curve per CSV, each with its legend entry;
#   a log-scale error plot into a PDF; a column no CSV has: exit 2 and no figure;
#   units on the axes, a second dash pattern past 8 curves, --diff REF (a run minus itself is 0),
#   --shape BEAM --at t1,t2,t3 (one curve per time, y in m).
set -u
flexmbd=$1 src=$2 out=$3
rm -rf "$out" && mkdir -p "$out" && cd "$out" || exit 1
fail=0
scene=$src/scenes/paper/spinup_w4.yaml
for m in complete foac zoac; do
  $flexmbd run "$scene" -o "$m.csv" --quiet --set bodies.beam.model=$m --set solver.t_end=3 2>/dev/null
  [ $? -eq 0 ] || { echo "FAIL: run $m"; fail=1; }
done
$flexmbd plot complete.csv 2>plot1.err || { echo "FAIL: plot of one CSV: $(cat plot1.err)"; fail=1; }
[ "$(head -c 8 complete.png | od -An -tx1 | tr -d ' \n')" = "89504e470d0a1a0a" ] || { echo "FAIL: complete.png is not a PNG"; fail=1; }
[ "$(wc -c < complete.png)" -gt 5000 ] || { echo "FAIL: complete.png is nearly empty"; fail=1; }

# without column names: every column (the spin-up writes 10 besides t; gnuplot cycles 8 colours)
$flexmbd plot complete.csv -o all.svg 2>/dev/null || { echo "FAIL: plot of every column"; fail=1; }
nall=$(grep -o "stroke='rgb([0-9, ]*)'" all.svg | sort -u | wc -l)
[ "$nall" -ge 8 ] || { echo "FAIL: all.svg: $nall curve colours for 10 columns"; fail=1; }

$flexmbd plot complete.csv foac.csv zoac.csv beam.tip_v -o overlay.svg --legend complete,FOAC,ZOAC 2>plot2.err \
  || { echo "FAIL: overlay: $(cat plot2.err)"; fail=1; }
for label in complete FOAC ZOAC; do
  grep -q ">$label<" overlay.svg || { echo "FAIL: overlay.svg has no legend entry $label"; fail=1; }
done
# gnuplot's SVG draws each curve as a path of its own colour: three curves, three colours
ncurves=$(grep -o "stroke='rgb([0-9, ]*)'" overlay.svg | sort -u | wc -l)
[ "$ncurves" -ge 3 ] || { echo "FAIL: overlay.svg: $ncurves curve colours, expected 3"; fail=1; }

# an error plot: |complete - foac| is not in one CSV, so the log axis shows |tip_v| of two models
$flexmbd plot complete.csv foac.csv beam.tip_v --abs --logy -o errors.pdf 2>plot3.err || { echo "FAIL: log plot: $(cat plot3.err)"; fail=1; }
[ "$(head -c 4 errors.pdf)" = "%PDF" ] || { echo "FAIL: errors.pdf is not a PDF"; fail=1; }

# units on the axes (the library's: t in s), and past 8 curves a second dash pattern (10 columns)
grep -q ">t \[s\]<" all.svg || { echo "FAIL: all.svg: no 't [s]' axis label"; fail=1; }
ndash=$(grep -o "stroke-dasharray='[^']*'" all.svg | sort -u | wc -l)
[ "$ndash" -ge 2 ] || { echo "FAIL: all.svg: one dash pattern for 10 curves (colours repeat past 8)"; fail=1; }
# an error plot: |complete - foac| with --diff (the reference interpolated at the run's rows)
$flexmbd plot complete.csv --diff foac.csv beam.tip_v --abs --logy -o diff.svg 2>diff.err \
  || { echo "FAIL: --diff: $(cat diff.err)"; fail=1; }
grep -q "|beam.tip_v - reference|" diff.svg || { echo "FAIL: diff.svg: no '|beam.tip_v - reference|' label"; fail=1; }
$flexmbd plot complete.csv --diff complete.csv beam.omega -o same.svg 2>same.err \
  || { echo "FAIL: --diff against itself"; fail=1; }
# a run minus itself is zero everywhere: gnuplot says its y range is empty, [0:0]
grep -q "empty y range \[0:0\]" same.err || { echo "FAIL: complete - complete is not 0: $(cat same.err)"; fail=1; }
$flexmbd run "$scene" -o shape.csv --quiet --set solver.t_end=2 --set 'outputs=[beam.tip_v, beam.shape]' 2>/dev/null
$flexmbd plot shape.csv --shape beam --at 0,1,2 -o shape.svg 2>shape.err || { echo "FAIL: --shape: $(cat shape.err)"; fail=1; }
for label in "t = 0 s" "t = 1 s" "t = 2 s" "y [m]"; do
  grep -qF ">$label<" shape.svg || { echo "FAIL: shape.svg has no '$label'"; fail=1; }
done
$flexmbd plot complete.csv --shape beam --at 1 -o noshape.png 2>noshape.err
[ $? -eq 2 ] && grep -q "beam.shape" noshape.err || { echo "FAIL: --shape without shape columns: $(cat noshape.err)"; fail=1; }

$flexmbd plot complete.csv beam.no_such -o bad.png 2>bad.err
rc=$?
[ $rc -eq 2 ] || { echo "FAIL: unknown column: exit $rc, expected 2"; fail=1; }
grep -q "no CSV has a column 'beam.no_such'" bad.err || { echo "FAIL: unknown column message: $(cat bad.err)"; fail=1; }
[ ! -e bad.png ] || { echo "FAIL: a figure was written for an unknown column"; fail=1; }
# a plot gnuplot cannot draw (an empty y range) leaves an existing figure as it was, and no temporary file
cp complete.png keep.png
$flexmbd plot complete.csv beam.tip_v --yrange 1:1 -o keep.png 2>keep.err
[ $? -eq 2 ] || { echo "FAIL: an undrawable plot: exit not 2"; fail=1; }
cmp -s complete.png keep.png || { echo "FAIL: a failed plot changed the existing figure"; fail=1; }
[ -z "$(ls -a | grep '^\.keep\.png\.')" ] || { echo "FAIL: a temporary figure was left behind"; fail=1; }
$flexmbd plot complete.csv -o fig.jpg 2>/dev/null
[ $? -eq 2 ] || { echo "FAIL: .jpg accepted"; fail=1; }
[ $fail -eq 0 ] && echo "ok: PNG of one CSV ($(wc -c < complete.png) bytes), SVG overlay of 3 CSVs, log-scale PDF, bad column refused"
exit $fail
