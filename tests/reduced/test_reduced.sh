#!/bin/sh
# test_reduced.sh FLEXMBD SOURCE_DIR OUT_DIR — the beam in modal coordinates (`reduction:`,
# bodies/beam_modal.c, docs/models.md "The reduced beam"), each result against an independent value:
#  A  clamped-free frequencies of the reduced beam (modes at rest) against the Euler-Bernoulli
#     continuum (beta_n L = 1.8751, 4.6941, 7.8548, 10.9955), and `check` listing them with the
#     first dropped one;
#  B  every mode of the mesh kept (2 ne bending + ne axial): the reduced beam is the full mesh in
#     other coordinates, so the w15 spin-up agrees with the full mesh to solver tolerance, for
#     complete, FOAC and ZOAC;
#  C  the reduced complete beam keeps the dynamic stiffening: at w0 = 15 with k = 4 it stays
#     bounded and its deflection is within 1 % of the full complete mesh's;
#  D  the reduced ZOAC beam diverges at w0 = 15 as the full ZOAC does (exit 3, about the same time);
#  E  the reduced pendulum conserves T + U_e + U_g over 5 s;
#  F  the rotating beam's stiffened first frequency (modes) against the continuum at 4 and 15 rad/s,
#     and ZOAC's missing stiffening sqrt(w1^2 - W^2);
#  G  bad `reduction:` input: exit 2 at file:line:column;
#  H  the Campbell diagram of the reduced beam (default basis) against the full mesh's, 1e-3;
#  I  tools/campbell_reduced.sh: full, reduced and ZOAC reduced in one figure;
#  J  the default basis loads for every number of modes the mesh has.
. "$(dirname "$0")/../exact/cli_lib.sh" # F, SRC, OUT, check, near; in SRC
# largest |a - b| of column COL over two CSVs with the same rows; largest |a| of a column
maxdiff() {
  awk -F, -v col="$3" 'FNR == 1 { for (i = 1; i <= NF; i++) if ($i == col) c = i; next }
    NR == FNR { a[FNR] = $c; next } { d = $c - a[FNR]; if (d < 0) d = -d; if (d > m) m = d } END { print m + 0 }' "$1" "$2"
}
peak() {
  awk -F, -v col="$2" 'FNR == 1 { for (i = 1; i <= NF; i++) if ($i == col) c = i; next }
    { d = $c; if (d < 0) d = -d; if (d > m) m = d } END { print m + 0 }' "$1"
}
le() { awk -v a="$1" -v b="$2" 'BEGIN { exit !(a <= b) }'; }
stat() { tail -1 "$1" | tr ' ' '\n' | sed -n "s/^$2=//p"; }
W15=scenes/paper/spinup_w15.yaml

# A: clamped-free frequencies, 16 elements, k = 4, at rest (Euler-Bernoulli: formulation note §8)
"$F" modes scenes/campbell_beam.yaml --count 4 --set joints.spin.speed=0 --set 'bodies.beam.reduction={modes: 4}' \
  -o "$OUT/rest.csv" 2>"$OUT/rest.err"
i=0
for ref in 3.909343 24.499435 68.599127 134.426910; do
  i=$((i + 1))
  w=$(sed -n "$((i + 1))p" "$OUT/rest.csv" | cut -d, -f2)
  echo "A: mode $i: $w rad/s (Euler-Bernoulli $ref)"
  check "A: mode $i within 2e-4 relative of the continuum" "near '$w' $ref $(awk -v r=$ref 'BEGIN { print 2e-4 * r }')"
done
"$F" check $W15 --set 'bodies.beam.reduction={modes: 4}' >"$OUT/check.txt" 2>&1
grep "body 'beam'" "$OUT/check.txt"
check "A: check lists the retained frequencies (modes, then the stiffening vectors' Ritz values) and the first dropped one" \
  "grep -q 'reduced to 4 bending + 4 stiffening + 0 axial.*retained (rad/s): 3.90934 24.4995 68.6014 134.446 [0-9.]*s [0-9.]*s [0-9.]*s [0-9.]*s; first dropped: bending 222.30' '$OUT/check.txt'"

# B: every mode kept reproduces the full mesh (8 elements: 16 bending + 8 axial modes)
for model in complete foac zoac; do
  S="--set bodies.beam.elements=8 --set bodies.beam.model=$model --set solver.rtol=1e-9 --set solver.t_end=3"
  "$F" run $W15 $S -o "$OUT/full_$model.csv" 2>"$OUT/full_$model.err"
  "$F" run $W15 $S --set 'bodies.beam.reduction={modes: 16, axial_modes: 8}' -o "$OUT/all_$model.csv" \
    2>"$OUT/all_$model.err"
  d=$(maxdiff "$OUT/full_$model.csv" "$OUT/all_$model.csv" beam.tip_v)
  du=$(maxdiff "$OUT/full_$model.csv" "$OUT/all_$model.csv" beam.tip_u)
  de=$(maxdiff "$OUT/full_$model.csv" "$OUT/all_$model.csv" energy.total)
  echo "B: $model, all modes vs full mesh (rtol 1e-9): tip_v $d m (peak $(peak "$OUT/full_$model.csv" beam.tip_v)), tip_u $du m, energy $de J"
  check "B: $model all-modes tip_v within 3e-8 m of the full mesh" "le '$d' 3e-8"
  check "B: $model all-modes tip_u within 3e-8 m and energy within 1e-7 J" "le '$du' 3e-8 && le '$de' 1e-7"
done

# C: w0 = 15, k = 4, complete: bounded and within 1 % of the full complete mesh (16 elements)
"$F" run $W15 --set solver.rtol=1e-8 -o "$OUT/w15_full.csv" 2>"$OUT/w15_full.err"
"$F" run $W15 --set solver.rtol=1e-8 --set 'bodies.beam.reduction={modes: 4}' -o "$OUT/w15_k4.csv" 2>"$OUT/w15_k4.err"
rc=$?
p=$(peak "$OUT/w15_full.csv" beam.tip_v)
d=$(maxdiff "$OUT/w15_full.csv" "$OUT/w15_k4.csv" beam.tip_v)
echo "C: w0 = 15, k = 4: exit $rc, t_reached $(stat "$OUT/w15_k4.err" t_reached); max |tip_v - full| = $d m of a peak $p m"
check "C: the reduced complete beam runs the w0 = 15 spin-up to the end" "[ $rc -eq 0 ] && [ '$(stat "$OUT/w15_k4.err" t_reached)' = 20 ]"
check "C: its deflection is within 1 % of the full complete mesh's peak" "le '$d' $(awk -v p=$p 'BEGIN { print 0.01 * p }')"

# D: ZOAC reduced diverges at w0 = 15 as the full ZOAC does
"$F" run $W15 --set bodies.beam.model=zoac -o "$OUT/zoac_full.csv" 2>"$OUT/zoac_full.err"
rf=$?
"$F" run $W15 --set bodies.beam.model=zoac --set 'bodies.beam.reduction={modes: 4}' -o "$OUT/zoac_k4.csv" \
  2>"$OUT/zoac_k4.err"
rr=$?
tf=$(stat "$OUT/zoac_full.err" t_reached)
tr=$(stat "$OUT/zoac_k4.err" t_reached)
echo "D: ZOAC at w0 = 15: full mesh exit $rf at t = $tf s, reduced (k = 4) exit $rr at t = $tr s"
check "D: the reduced ZOAC beam diverges (exit 3) like the full one" "[ $rr -eq 3 ] && [ $rf -eq 3 ]"
check "D: it stops within 0.5 s of the full ZOAC" "near '$tr' '$tf' 0.5"

# E: energy balance of the reduced pendulum over 5 s (at rtol 1e-10 without max_step, the scene's
# former settings: the 1e-8 bound below is the drift of that tolerance)
"$F" run scenes/paper/pendulum.yaml --set 'bodies.beam.reduction={modes: 4}' --set solver.rtol=1e-10 --set solver.max_step=0 -o "$OUT/pend.csv" 2>"$OUT/pend.err"
drift=$(awk -F, 'NR == 1 { for (i = 1; i <= NF; i++) { if ($i == "energy.total") e = i; if ($i == "energy.gravity") g = i } next }
  NR == 2 { e0 = $e } { d = $e - e0; if (d < 0) d = -d; if (d > m) m = d; u = $g; if (u < 0) u = -u; if (u > G) G = u }
  END { print m / G }' "$OUT/pend.csv")
bend=$(peak "$OUT/pend.csv" beam.tip_v)
echo "E: reduced pendulum (k = 4), 5 s: energy drift $drift of max |U_g|, peak tip_v $bend m"
check "E: T + U_e + U_g constant to 1e-8 of max |U_g|" "le '$drift' 1e-8"
check "E: the beam bends (peak tip_v > 1 cm)" "le 0.01 '$bend'"

# F: the rotating beam's first frequency (formulation note §8: 4.26118 at 4 rad/s, 6.3351 at 15)
for case in "4 4 4.26118" "8 15 6.3351"; do
  set -- $case
  w=$("$F" modes scenes/campbell_beam.yaml --count 1 --set joints.spin.speed=$2 \
    --set "bodies.beam.reduction={modes: $1}" -o - 2>/dev/null | tail -1 | cut -d, -f2)
  echo "F: k = $1 at $2 rad/s: $w rad/s (continuum $3)"
  check "F: stiffened first frequency within 1e-3 relative (k = $1, $2 rad/s)" \
    "near '$w' $3 $(awk -v r=$3 'BEGIN { print 1e-3 * r }')"
done
w=$("$F" modes scenes/campbell_beam.yaml --count 1 --set joints.spin.speed=2 --set bodies.beam.model=zoac \
  --set 'bodies.beam.reduction={modes: 4}' -o - 2>/dev/null | tail -1 | cut -d, -f2)
echo "F: ZOAC reduced at 2 rad/s: $w rad/s (sqrt(w1^2 - W^2) = 3.359011)"
check "F: ZOAC reduced lacks the stiffening: sqrt(w1^2 - W^2) to 1e-5" "near '$w' 3.359011 3.4e-5"

# H: the Campbell diagram of the reduced spinning beam against the full mesh's (the same 16-element
#    mesh, complete model): with the default basis (4 bending modes + their 4 stiffening vectors)
#    every retained mode within 1e-3 relative at 0, 5, 10, 15 rad/s; the eigenmodes alone
#    (stiffening_modes: 0, the basis before) miss it at 15 rad/s (8.5e-3 on mode 1), so the check
#    can fail
CB="scenes/campbell_beam.yaml --speed joints.spin.speed --speeds 0:15:4 --count 4"
"$F" campbell $CB -o - >"$OUT/campbell_full.csv" 2>"$OUT/campbell_full.err"
"$F" campbell $CB --set 'bodies.beam.reduction={modes: 4}' -o - >"$OUT/campbell_k4.csv" 2>"$OUT/campbell_k4.err"
"$F" campbell $CB --set 'bodies.beam.reduction={modes: 4, stiffening_modes: 0}' -o - >"$OUT/campbell_k4e.csv" \
  2>"$OUT/campbell_k4e.err"
# largest relative difference of modes 1..4 over the speeds (rows must match: same speeds)
reldiff() {
  awk -F, 'FNR == 1 { next } NR == FNR { for (i = 2; i <= NF; i++) a[FNR, i] = $i; n = NF; next }
    { if ($1 != a[FNR, 1] && FNR > 1) bad = 1; for (i = 2; i <= NF; i++) { d = ($i - a[FNR, i]) / a[FNR, i];
      if (d < 0) d = -d; if (d > m) m = d } r++ }
    END { if (r != 4 || n != 5) print 1; else print m + 0 }' "$1" "$2"
}
dk=$(reldiff "$OUT/campbell_full.csv" "$OUT/campbell_k4.csv")
de=$(reldiff "$OUT/campbell_full.csv" "$OUT/campbell_k4e.csv")
echo "H: Campbell 0..15 rad/s, modes 1-4, reduced k = 4 vs full mesh: default basis $dk, eigenmodes alone $de (relative)"
check "H: the reduced beam's Campbell diagram within 1e-3 of the full mesh's (retained modes)" "le '$dk' 1e-3"
check "H: the eigenmodes alone do not meet 1e-3 at 15 rad/s (the check discriminates)" "le 1e-3 '$de'"

# I: the documented plot of full, reduced and ZOAC reduced (tools/campbell_reduced.sh) runs and
#    the figure holds the three series; ZOAC's first frequency goes negative (divergent) above
#    omega1 while the reduced complete one stiffens
rm -rf "$OUT/cplot"
sh tools/campbell_reduced.sh "$OUT/cplot" "$F" "$OUT/cplot/campbell_reduced.svg" >"$OUT/cplot.log" 2>&1
rc=$?
n=0
for label in 'full mesh (16 el.): mode1' 'reduced k = 4: mode1' 'ZOAC reduced k = 4: mode1'; do
  grep -qF "$label" "$OUT/cplot/campbell_reduced.svg" 2>/dev/null && n=$((n + 1))
done
zl=$(tail -1 "$OUT/cplot/campbell_zoac_reduced.csv" | cut -d, -f2)
rl=$(tail -1 "$OUT/cplot/campbell_reduced.csv" | cut -d, -f2)
echo "I: campbell_reduced.sh exit $rc, $n of 3 series in the figure; mode 1 at 15 rad/s: reduced $rl, ZOAC reduced $zl rad/s"
check "I: tools/campbell_reduced.sh draws full, reduced and ZOAC reduced in one figure" "[ $rc -eq 0 ] && [ $n -eq 3 ]"
check "I: in it ZOAC lacks the stiffening (mode 1 negative at 15 rad/s) and the reduced complete has it (> 6 rad/s)" \
  "le '$zl' 0 && le 6 '$rl'"

# J: the default basis loads for every `modes:` the mesh allows (16 elements: 1 ... 32), the
#    stiffening vectors already in the span of many modes left out, never an error
nload=0
for k in $(seq 1 32); do
  "$F" check $W15 --set "bodies.beam.reduction={modes: $k}" >"$OUT/j.txt" 2>&1 && nload=$((nload + 1))
done
echo "J: modes 1 ... 32 of 16 elements with the default basis: $nload of 32 load; modes: 31 -> $("$F" check $W15 --set 'bodies.beam.reduction={modes: 31}' 2>&1 | grep -o 'reduced to [^,]*modes')"
check "J: every modes: 1 ... 32 loads with the default stiffening vectors" "[ $nload -eq 32 ]"

# G: bad input in the scene file (a copy of the w15 scene with lines after `model: complete`): exit 2
# at file:line:column (line 19, the first line added)
for bad in "reduction: 4|19:16:.*expected a mapping for .reduction." \
  "reduction: {modes: 33}|19:24:.*.modes." \
  "reduction: {modes: 2, mods: 1}|19:27:.*unknown key .mods." \
  "reduction: {modes: 0}|19:24:.*at least one mode" \
  "reduction: {modes: 2, stiffening_modes: 3}|19:45:.*from 0 to 2 for .stiffening_modes." \
  "assembly: banded\n    reduction: {modes: 2}|19:15:.*does not apply with .reduction."; do
  lines=${bad%%|*}
  msg=${bad#*|}
  sed "s/^    model: complete/    model: complete\n    $lines/" $W15 >"$OUT/bad.yaml"
  "$F" check "$OUT/bad.yaml" >"$OUT/bad.txt" 2>&1
  rc=$?
  echo "G: $lines: exit $rc: $(grep -m1 'bad.yaml:' "$OUT/bad.txt")"
  check "G: '$lines' refused with exit 2 at its line and column" "[ $rc -eq 2 ] && grep -q 'bad.yaml:$msg' '$OUT/bad.txt'"
done
exit $fail
