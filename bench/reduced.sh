#!/usr/bin/env bash
# bench/reduced.sh — the beam in modal coordinates (`reduction: {modes: k}`, bodies/beam_modal.c,
# docs/models.md "The reduced beam"): its truncation error against the full mesh, and its speed.
#
#   bash bench/reduced.sh [--reps N] [--ks "1 2 ... 12"] [--bases "k 0"] [--only accuracy|speed|campbell]
#                         [--cases "spinup_w1 ..."] [--pendulum-elements NE]
#
# accuracy  per case, the complete model on NE elements: the full mesh (the converged reference)
#           and the same beam reduced to k = 1 ... 12 of its clamped-free bending modes, both at
#           the case's rtol, in each basis of --bases: "k" the default (k modes + their k
#           stiffening vectors, 2k coordinates), "0" the eigenmodes alone (stiffening_modes: 0);
#           error = max over the run of |tip_v - reference| (blade1 for the rotor), CPU = cpu_s
#           of one run; and k = 4 (+ 4) with axial_modes: 1 (the stretch the default drops). Also
#           the shipped 16-element full mesh at the same rtol, for scale. Cases:
#           the paper's spin-ups (w0 = 1, 4, 15 rad/s, 20 s, rtol 1e-10, NE = 64), the pendulum
#           (1 s, rtol 1e-8, NE = --pendulum-elements, default 64: its sudden release rings every
#           mode, so the full mesh is slow) and scenes/rotor.yaml (three blades, 8 s, rtol 1e-9,
#           NE = 64). -> bench/results/reduced_accuracy.csv
# speed     bench/scenes/rotor4.yaml (four 64-element blades on a hub): full mesh against 6 modal
#           coordinates per blade at equal rtol (1e-6, 1e-8): {modes: 3} (3 modes + 3 stiffening
#           vectors, the default basis) and {modes: 6, stiffening_modes: 0} (6 eigenmodes), and
#           {modes: 6} (12 coordinates) for scale; REPS runs each, alternated, median cpu_s; each
#           reduced rotor's tip error (max over the four blades) against the full mesh's run at
#           the same rtol, relative to the tip's range. -> bench/results/reduced_speed.csv
# campbell  scenes/campbell_beam.yaml (16 elements, complete): the first four in-plane frequencies
#           at 0, 5, 10, 15, 30 rad/s on the full mesh, and the relative difference of the reduced
#           beam's for k = 4 and 8 in both bases, and k = 4 with axial_modes: 1 (no timing).
#           -> bench/results/reduced_campbell.csv
set -euo pipefail
cd "$(dirname "$0")/.."
ROOT=$PWD
F=${FLEXMBD:-$ROOT/build/flexmbd}
RES=${RESULTS:-$ROOT/bench/results}
. bench/lib.sh
REPS=3
KS="1 2 3 4 5 6 7 8 9 10 11 12"
BASES="k 0"
PEND_NE=64
ONLY=""
ONLY_CASES=""
while [ $# -gt 0 ]; do
  case $1 in
    --reps) REPS=$2; shift ;;
    --ks) KS=$2; shift ;;
    --bases) BASES=$2; shift ;;
    --pendulum-elements) PEND_NE=$2; shift ;;
    --only) ONLY=$2; shift ;;
    --cases) ONLY_CASES=$2; shift ;;
    -h|--help) sed -n 2,31p "$0"; exit 0 ;;
    *) echo "reduced.sh: unknown argument '$1'" >&2; exit 2 ;;
  esac
  shift
done
WORK=$(mktemp -d)
trap 'rm -rf "$WORK"' EXIT
mkdir -p "$RES"

# max |a - b| of column COL over two CSVs with the same rows; the largest |a| of a column
maxdiff() {
  awk -F, -v col="$3" 'FNR == 1 { for (i = 1; i <= NF; i++) if ($i == col) c = i; next }
    NR == FNR { a[FNR] = $c; next } { d = $c - a[FNR]; if (d < 0) d = -d; if (d > m) m = d } END { printf "%.3g\n", m }' "$1" "$2"
}
peak() {
  awk -F, -v col="$2" 'FNR == 1 { for (i = 1; i <= NF; i++) if ($i == col) c = i; next }
    { d = $c; if (d < 0) d = -d; if (d > m) m = d } END { printf "%.4g\n", m }' "$1"
}
# run OUT.csv ARGS...: the run, its stats line in OUT.err
run() {
  local out=$1
  shift
  "$F" run "$@" -o "$out" 2>"${out%.csv}.err" || { echo "reduced.sh: failed: $* ($(tail -1 "${out%.csv}.err"))" >&2; return 1; }
}
cpu() { stat_field cpu_s <"${1%.csv}.err"; }

if [ -z "$ONLY" ] || [ "$ONLY" = campbell ]; then
  CB=(scenes/campbell_beam.yaml --speed joints.spin.speed --speeds 0,5,10,15,30 --count 4)
  "$F" campbell "${CB[@]}" -o - >"$WORK/cfull.csv" 2>"$WORK/cfull.err"
  CSV=$RES/reduced_campbell.csv
  echo "basis,speed,mode1,mode2,mode3,mode4" >"$WORK/camp.csv"
  awk -F, 'NR > 1 { print "full mesh (rad/s)," $0 }' "$WORK/cfull.csv" >>"$WORK/camp.csv"
  for red in "{modes: 4}" "{modes: 4, stiffening_modes: 0}" "{modes: 8}" "{modes: 8, stiffening_modes: 0}" \
    "{modes: 4, axial_modes: 1}"; do
    "$F" campbell "${CB[@]}" --set "bodies.beam.reduction=$red" -o - >"$WORK/cred.csv" 2>"$WORK/cred.err"
    # the reduced frequency's relative difference from the full mesh's, speed by speed
    awk -F, -v b="$red" 'FNR == 1 { next } NR == FNR { for (i = 1; i <= NF; i++) a[FNR, i] = $i; next }
      { printf "\"%s\",%s", b, $1; for (i = 2; i <= NF; i++) printf ",%.2g", ($i - a[FNR, i]) / a[FNR, i]; print "" }' \
      "$WORK/cfull.csv" "$WORK/cred.csv" >>"$WORK/camp.csv"
  done
  cat "$WORK/camp.csv" >&2
  mv "$WORK/camp.csv" "$CSV.tmp" && mv "$CSV.tmp" "$CSV"
  echo "wrote $CSV" >&2
fi

if [ "$ONLY" != speed ] && [ "$ONLY" != campbell ]; then
  # case | scene | settings | bodies (beams) | tip column | elements of the reference
  CASES=(
    "spinup_w1|scenes/paper/spinup_w1.yaml|--set solver.rtol=1e-10|beam|beam.tip_v|64"
    "spinup_w4|scenes/paper/spinup_w4.yaml|--set solver.rtol=1e-10|beam|beam.tip_v|64"
    "spinup_w15|scenes/paper/spinup_w15.yaml|--set solver.rtol=1e-10|beam|beam.tip_v|64"
    "pendulum|scenes/paper/pendulum.yaml|--set solver.rtol=1e-8 --set solver.t_end=1|beam|beam.tip_v|$PEND_NE"
    "rotor|scenes/rotor.yaml|--set solver.rtol=1e-9|blade1 blade2 blade3|blade1.tip_v|64"
  )
  CSV=$RES/reduced_accuracy.csv
  # the cases not run keep their rows
  if [ -n "$ONLY_CASES" ] && [ -f "$CSV" ]; then
    awk -F, -v keep=" $ONLY_CASES " 'NR == 1 || index(keep, " " $1 " ") == 0' "$CSV" >"$WORK/acc.csv"
  else
    echo "case,model,elements,k,stiffening,axial,tip_error_m,tip_peak_m,cpu_s,steps" >"$WORK/acc.csv"
  fi
  for c in "${CASES[@]}"; do
    IFS='|' read -r name scene sets bodies tip NE <<<"$c"
    [ -z "$ONLY_CASES" ] || [[ " $ONLY_CASES " == *" $name "* ]] || continue
    mesh64=()
    mesh16=()
    for b in $bodies; do
      mesh64+=(--set "bodies.$b.elements=$NE")
      mesh16+=(--set "bodies.$b.elements=16")
    done
    # shellcheck disable=SC2086
    run "$WORK/$name-full64.csv" "$scene" $sets "${mesh64[@]}"
    ref=$WORK/$name-full64.csv
    p=$(peak "$ref" "$tip")
    echo "$name,full,$NE,-,-,-,0,$p,$(cpu "$ref"),$(stat_field steps <"${ref%.csv}.err")" >>"$WORK/acc.csv"
    # shellcheck disable=SC2086
    run "$WORK/$name-full16.csv" "$scene" $sets "${mesh16[@]}"
    echo "$name,full,16,-,-,-,$(maxdiff "$ref" "$WORK/$name-full16.csv" "$tip"),$p,$(cpu "$WORK/$name-full16.csv"),$(stat_field steps <"$WORK/$name-full16.err")" >>"$WORK/acc.csv"
    # k modes in each basis, then k = 4 (+ 4) with one axial mode: what the axially rigid default drops
    for basis in $BASES axial; do
      for k in $([ "$basis" = axial ] && echo 4 || echo "$KS"); do
        r=$([ "$basis" = k ] || [ "$basis" = axial ] && echo "$k" || echo "$basis")
        ax=$([ "$basis" = axial ] && echo 1 || echo 0)
        red=()
        for b in $bodies; do red+=(--set "bodies.$b.reduction={modes: $k, stiffening_modes: $r, axial_modes: $ax}"); done
        out=$WORK/$name-k$k-s$r-a$ax.csv
        # shellcheck disable=SC2086
        if run "$out" "$scene" $sets "${mesh64[@]}" "${red[@]}"; then
          echo "$name,reduced,$NE,$k,$r,$ax,$(maxdiff "$ref" "$out" "$tip"),$p,$(cpu "$out"),$(stat_field steps <"${out%.csv}.err")" >>"$WORK/acc.csv"
        else
          echo "$name,reduced,$NE,$k,$r,$ax,failed,$p,," >>"$WORK/acc.csv"
        fi
      done
    done
    tail -n +2 "$WORK/acc.csv" | grep "^$name," >&2
  done
  mv "$WORK/acc.csv" "$CSV.tmp" && mv "$CSV.tmp" "$CSV"
  echo "wrote $CSV" >&2
fi

if [ "$ONLY" != accuracy ] && [ "$ONLY" != campbell ]; then
  SCENE=bench/scenes/rotor4.yaml
  # the reduced rotors: label | reduction of every blade
  REDS=("3+3|{modes: 3}" "6+0|{modes: 6, stiffening_modes: 0}" "6+6|{modes: 6}")
  CSV=$RES/reduced_speed.csv
  echo "rtol,basis,full_cpu_s,reduced_cpu_s,speedup,full_steps,reduced_steps,tip_error_m,tip_range_m,tip_error_of_range" \
    >"$WORK/speed.csv"
  for rtol in 1e-6 1e-8; do
    : >"$WORK/full.t"
    for i in "${!REDS[@]}"; do : >"$WORK/red$i.t"; done
    for _ in $(seq "$REPS"); do
      run "$WORK/full.csv" "$SCENE" --set solver.rtol=$rtol
      cpu "$WORK/full.csv" >>"$WORK/full.t"
      for i in "${!REDS[@]}"; do
        red=()
        for b in 1 2 3 4; do red+=(--set "bodies.blade$b.reduction=${REDS[$i]#*|}"); done
        run "$WORK/red$i.csv" "$SCENE" --set solver.rtol=$rtol "${red[@]}"
        cpu "$WORK/red$i.csv" >>"$WORK/red$i.t"
      done
    done
    tf=$(median <"$WORK/full.t")
    for i in "${!REDS[@]}"; do
      tr=$(median <"$WORK/red$i.t")
      err=0
      range=0
      for b in 1 2 3 4; do
        e=$(maxdiff "$WORK/full.csv" "$WORK/red$i.csv" blade$b.tip_v)
        r=$(awk -F, -v col=blade$b.tip_v 'FNR == 1 { for (i = 1; i <= NF; i++) if ($i == col) c = i; next }
          NR == 2 { lo = hi = $c } { if ($c < lo) lo = $c; if ($c > hi) hi = $c } END { printf "%.4g\n", hi - lo }' "$WORK/full.csv")
        err=$(awk -v a="$err" -v b="$e" 'BEGIN { print (b > a) ? b : a }')
        range=$(awk -v a="$range" -v b="$r" 'BEGIN { print (b > a) ? b : a }')
      done
      line="$rtol,${REDS[$i]%%|*},$tf,$tr,$(awk -v a="$tf" -v b="$tr" 'BEGIN { printf "%.1f", a / b }'),$(stat_field steps <"$WORK/full.err"),$(stat_field steps <"$WORK/red$i.err"),$err,$range,$(awk -v a="$err" -v b="$range" 'BEGIN { printf "%.2g", a / b }')"
      echo "$line" >&2
      echo "$line" >>"$WORK/speed.csv"
    done
  done
  mv "$WORK/speed.csv" "$CSV.tmp" && mv "$CSV.tmp" "$CSV"
  echo "wrote $CSV" >&2
fi
