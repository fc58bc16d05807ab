#!/usr/bin/env bash
# bench/bench.sh — work–precision benchmark of flexmbd (docs/performance.md).
#
#   bash bench/bench.sh [--quick] [--reps N] [--only SCENE]
#
# For each scene (spin-up at omega0 = 4 and 15, the flexible pendulum, the rigid four-bar) it
#   1. builds a reference (finer mesh, tighter rtol) and measures the reference's own error
#      against one step coarser in mesh and in rtol (group "refconv");
#   2. sweeps rtol at 16 elements (complete model, KLU) — group "rtol";
#   3. runs FOAC and ZOAC on the same rtol sweep — groups "foac", "zoac" (error vs the complete
#      reference = the error each simplification carries);
#   4. sweeps the element count at a fixed tight rtol — group "elements";
#   5. repeats a subset with linear_solver=dense ("dense"), KLU on the whole GGL matrix instead of
#      the Schur complement ("klu_full"), the other error_control ("errctl")
#      and other BDF order caps ("order").
# Each group is one `flexmbd sweep` (docs/sweep.md), repeated REPS times for the runs that were ok
# (CPU time = median of cpu_s from the stats line; steps and counters are deterministic), each run
# compared with `flexmbd compare` against the reference.
# Results: bench/results/runs.csv (one row per run), refconv rows in the same file,
# work–precision plots bench/results/wp_SCENE.png, and bench/results/tables.md (bench/report.sh).
# Each run has a time limit (RUN_TIMEOUT s); one that exceeds it is recorded as status=timeout;
# a crash costs one row, never the benchmark.
set -euo pipefail
cd "$(dirname "$0")/.."
ROOT=$PWD
F=${FLEXMBD:-$ROOT/build/flexmbd}
RES=${RESULTS:-$ROOT/bench/results}
WORK=${BENCH_WORK:-$(mktemp -d /tmp/flexmbd-bench.XXXXXX)}
QUICK=0
REPS=3
ONLY=""
RUN_TIMEOUT=${RUN_TIMEOUT:-120}
while [ $# -gt 0 ]; do
  case $1 in
    --quick) QUICK=1 ;;
    --reps) REPS=$2; shift ;;
    --only) ONLY=$2; shift ;;
    -h|--help) sed -n 2,22p "$0"; exit 0 ;;
    *) echo "bench.sh: unknown argument '$1'" >&2; exit 2 ;;
  esac
  shift
done
[ -x "$F" ] || { echo "bench.sh: no flexmbd at $F (bash tools/build.sh, or FLEXMBD=...)" >&2; exit 2; }
mkdir -p "$RES" "$WORK"
RUNS=$RES/runs.csv
[ $QUICK = 1 ] && RUNS=$RES/runs_quick.csv
if [ -z "$ONLY" ] || [ ! -f "$RUNS" ]; then
  echo "scene,group,model,elements,rtol,atol,linear_solver,error_control,max_order,status,t_reached,steps,residuals,jacobians,newton_iters,error_test_fails,cpu_med,cpu_min,cpu_max,reps,tip_max,tip_end,angle_max,angle_end,energy_max,energy_end,tip_time_max" > "$RUNS"
else
  awk -F, -v s="$ONLY" 'NR == 1 || $1 != s' "$RUNS" > "$RUNS.tmp" && mv "$RUNS.tmp" "$RUNS"
fi

# ---- a group of runs as one `flexmbd sweep`, repeated; appends a row per run ---------------------
# run_cases SCENE_ID GROUP REF_CSV SAME_MESH_REF MODEL "ELEMENTS..." "RTOL..." LINSOLVER ERRCTL ORDER
#   one list holds several values (the swept one: rtol, paired with atol = rtol/100, or elements);
#   SAME_MESH_REF: a CSV of the same mesh at the tightest rtol (time-integration error alone) or -
#   MODEL/ELEMENTS/ORDER/ERRCTL: "-" = as in the scene file
# Every run is a child of the sweep (a crash or a hang is one row: statuses ok, solver_stopped ->
# failed, timeout at RUN_TIMEOUT); the sweep is done REPS times, the repeats only for the runs
# that were ok (a --samples plan of their values: the same run ids), CPU time = the median of
# cpu_s. BENCH_JOBS children at once (default 1: CPU times measured alone).
SCENE_FILE=""; TIP=""; ANGLE=""; KIN=""; SCENE_SETS=()
run_cases() {
  local id=$1 group=$2 ref=$3 sameref=$4 model=$5 nes=$6 rtols=$7 ls=$8 ec=$9 ord=${10}
  local sets=("${SCENE_SETS[@]}") plan=() r n
  [ "$model" != - ] && sets+=(--set "bodies.beam.model=$model")
  [ "$ls" != klu ] && sets+=(--set "solver.linear_solver=$ls")
  [ "$ec" != - ] && sets+=(--set "solver.error_control=$ec")
  [ "$ord" != - ] && sets+=(--set "solver.max_order=$ord")
  local rl="" al="" nl="" a
  local -A given_r given_a # the sweep prints numbers %.17g; the table keeps them as written here
  for r in $rtols; do
    a=$(awk -v r="$r" 'BEGIN { printf "%.3g", r / 100 }')
    rl+=${rl:+,}$r; al+=${al:+,}$a
    given_r[$(awk -v r="$r" 'BEGIN { printf "%.17g", r }')]=$r
    given_a[$(awk -v r="$a" 'BEGIN { printf "%.17g", r }')]=$a
  done
  for n in $nes; do [ "$n" != - ] && nl+=${nl:+,}$n; done
  plan=(--zip "solver.rtol=$rl" --zip "solver.atol=$al")
  [ -n "$nl" ] && plan+=(--grid "bodies.beam.elements=$nl")
  local tag="${id}_${group}_${model}_${ls}_${ec}_${ord}" rep
  local d1=$WORK/sw_${tag}_1
  "$F" sweep "$SCENE_FILE" -o "$d1" --fresh --quiet --keep series -j "${BENCH_JOBS:-1}" --timeout "$RUN_TIMEOUT" \
    "${sets[@]}" "${plan[@]}" 2> "$WORK/sw_$tag.err" || { cat "$WORK/sw_$tag.err" >&2; exit 3; }
  # the repeats: the runs that were ok, by their swept values (columns 9 on: rtol, atol[, elements])
  local npath=$((2 + (${#nl} > 0)))
  awk -F, -v np=$npath 'NR == 1 { h = $9; for (i = 10; i < 9 + np; ++i) h = h "," $i; print h; next }
    $4 == "ok" { v = $9; for (i = 10; i < 9 + np; ++i) v = v "," $i; print v }' "$d1/table.csv" > "$WORK/sw_${tag}_ok.csv"
  for ((rep = 2; rep <= REPS; ++rep)); do
    [ "$(wc -l < "$WORK/sw_${tag}_ok.csv")" -gt 1 ] || break
    "$F" sweep "$SCENE_FILE" -o "$WORK/sw_${tag}_$rep" --fresh --quiet -j "${BENCH_JOBS:-1}" --timeout "$RUN_TIMEOUT" \
      "${sets[@]}" --samples "$WORK/sw_${tag}_ok.csv" 2>> "$WORK/sw_$tag.err" || { cat "$WORK/sw_$tag.err" >&2; exit 3; }
  done
  # one row per run: the stats of the first sweep, CPU over the repeats (by run id), errors by compare
  local col; col() { head -1 "$d1/table.csv" | tr ',' '\n' | grep -n -x "$1" | cut -d: -f1; }
  local line
  tail -n +2 "$d1/table.csv" | while IFS= read -r line; do
    local f; f() { cut -d, -f"$(col "$1")" <<< "$line"; }
    local rid status ne rtol atol csv cpu reps
    rid=$(f run_id); rtol=${given_r[$(f solver.rtol)]}; atol=${given_a[$(f solver.atol)]}
    ne=$nes; [ -n "$nl" ] && ne=$(f bodies.beam.elements)
    case $(f status) in ok) status=ok ;; timeout) status=timeout ;; *) status=failed ;; esac
    cpu=$(for t in "$WORK"/sw_"${tag}"_[0-9]*/table.csv; do awk -F, -v id="$rid" -v c="$(col cpu_s)" '$2 == id && $4 == "ok" { print $c }' "$t"; done |
      sort -g | awk '{ v[NR] = $1 } END { if (NR) printf "%s,%s,%s,%d", v[int((NR + 1) / 2)], v[1], v[NR], NR }')
    [ -n "$cpu" ] || cpu="nan,nan,nan,0"
    [ "$status" = timeout ] && cpu="$RUN_TIMEOUT,$RUN_TIMEOUT,$RUN_TIMEOUT,0"
    # errors: tip and angle relative to the reference's max |value|; energy.total relative to the
    # reference's max kinetic energy (the energy that flows); "nan" when the run produced no rows
    csv=$d1/series/$rid.csv
    local e="nan,nan,nan,nan,nan,nan" et=nan
    if [ -s "$csv" ] && [ "$status" != timeout ] && [ "$ref" != - ]; then
      e=$("$F" compare "$csv" "$ref" --columns "$TIP,$ANGLE,energy.total,$KIN" 2>/dev/null | awk '
        { for (i = 2; i <= NF; ++i) { split($i, kv, "="); f[kv[1]] = kv[2] }
          n++; mx[n] = f["max_rel"]; en[n] = f["end_rel"]; ma[n] = f["max_abs"]; ea[n] = f["end_abs"]; sc[n] = f["ref_scale"] }
        END { if (n < 4) { print "nan,nan,nan,nan,nan,nan"; exit }
              s = sc[4] > 0 ? sc[4] : 1
              printf "%s,%s,%s,%s,%.6e,%.6e", mx[1], en[1], mx[2], en[2], ma[3] / s, ea[3] / s }')
      [ -n "$e" ] || e="nan,nan,nan,nan,nan,nan"
      if [ "$sameref" != - ] && [ -s "$sameref" ]; then
        et=$("$F" compare "$csv" "$sameref" --columns "$TIP" 2>/dev/null | sed -n 's/.* max_rel=\([^ ]*\).*/\1/p')
        [ -n "$et" ] || et=nan
      fi
    fi
    local st=",,,,,"
    [ "$status" = timeout ] || st="$(f t_reached),$(f steps),$(f residuals),$(f jacobians),$(f newton_iters),$(f error_test_fails)"
    echo "$id,$group,$model,$ne,$rtol,$atol,$ls,$ec,$ord,$status,$st,$cpu,$e,$et" >> "$RUNS"
    printf '  %-8s %-9s %-8s n=%-4s rtol=%-6s %-5s %-9s order=%-2s %-8s cpu=%-8s tip_err=%s\n' "$id" "$group" "$model" "$ne" "$rtol" "$ls" "$ec" "$ord" "$status" "${cpu%%,*}" "${e%%,*}" >&2
  done
}

# a reference run (not timed): ref SCENE_ID NAME MODEL ELEMENTS RTOL -> $WORK/ref_NAME.csv
ref_run() {
  local id=$1 name=$2 ne=$3 rtol=$4
  local atol; atol=$(awk -v r="$rtol" 'BEGIN { printf "%.3g", r / 100 }')
  local sets=("${SCENE_SETS[@]}" --set "solver.rtol=$rtol" --set "solver.atol=$atol")
  [ "$ne" != - ] && sets+=(--set "bodies.beam.elements=$ne")
  echo "  $id reference $name: elements=$ne rtol=$rtol" >&2
  timeout "${REF_TIMEOUT:-600}" "$F" run "$SCENE_FILE" -o "$WORK/${id}_ref_$name.csv" --quiet "${sets[@]}" 2> "$WORK/${id}_ref_$name.err" ||
    { echo "bench.sh: reference $id/$name failed:" >&2; cat "$WORK/${id}_ref_$name.err" >&2; exit 3; }
  local s; s=$(tail -1 "$WORK/${id}_ref_$name.err")
  # the stats line's fields by name (keys may be added before cpu_s)
  local fields; fields=$(awk '{ for (i = 2; i <= NF; ++i) { split($i, kv, "="); f[kv[1]] = kv[2] }
    printf "%s,%s,%s,%s,%s,%s,%s,%s,%s", f["t_reached"], f["steps"], f["residuals"], f["jacobians"], f["newton_iters"], f["error_test_fails"], f["cpu_s"], f["cpu_s"], f["cpu_s"] }' <<< "$s")
  echo "$id,reference,$name,$ne,$rtol,$atol,klu,-,-,ok,$fields,1,0,0,0,0,0,0,nan" >> "$RUNS"
}
# the reference's own convergence: a coarser reference compared with the finest one
refconv() {
  local id=$1 name=$2 ne=$3 rtol=$4
  "$F" compare "$WORK/${id}_ref_$name.csv" "$WORK/${id}_ref_best.csv" --columns "$TIP,$ANGLE,energy.total,$KIN" | awk -v id="$id" -v name="$name" -v ne="$ne" -v rtol="$rtol" '
      { for (i = 2; i <= NF; ++i) { split($i, kv, "="); f[kv[1]] = kv[2] }
        n++; mx[n] = f["max_rel"]; en[n] = f["end_rel"]; ma[n] = f["max_abs"]; ea[n] = f["end_abs"]; sc[n] = f["ref_scale"] }
      END { s = sc[4] > 0 ? sc[4] : 1
            printf "%s,refconv,%s,%s,%s,-,klu,-,-,ok,,,,,,,nan,nan,nan,0,%s,%s,%s,%s,%.6e,%.6e,nan\n", id, name, ne, rtol, mx[1], en[1], mx[2], en[2], ma[3] / s, ea[3] / s }' >> "$RUNS"
}

want() { [ -z "$ONLY" ] || [ "$ONLY" = "$1" ]; }

# ---- the scenes --------------------------------------------------------------------------------
if [ $QUICK = 1 ]; then
  RTOLS="1e-4 1e-6 1e-8"; ELEMS="8 16 32"; MODEL_RTOLS="1e-4 1e-6 1e-8"; SUB_RTOLS="1e-6"
  REPS=${REPS_QUICK:-1}
else
  RTOLS="1e-3 1e-4 1e-5 1e-6 1e-7 1e-8 1e-9 1e-10"; ELEMS="8 16 32 64 128"
  MODEL_RTOLS="1e-3 1e-4 1e-5 1e-6 1e-7 1e-8 1e-9 1e-10"; SUB_RTOLS="1e-4 1e-6 1e-8"
fi
echo "bench: flexmbd=$F reps=$REPS quick=$QUICK work=$WORK" >&2

spinup() {
  local w=$1 id=w$1
  want "$id" || return 0
  SCENE_FILE=$ROOT/scenes/paper/spinup_w$w.yaml
  TIP=beam.tip_v; ANGLE=beam.theta; KIN=energy.kinetic
  SCENE_SETS=(--set "outputs=[beam.tip_v,beam.theta,energy.total,energy.kinetic]")
  echo "== spin-up omega0 = $w" >&2
  # 32 elements at rtol 1e-9: finer meshes at tighter rtol stall (docs/stability.md, case S-tight)
  local refn=32 refr=1e-9 n2=16 r2=1e-8 erc=1e-7
  [ $QUICK = 1 ] && { refn=32; refr=1e-8; n2=16; r2=1e-7; erc=1e-7; }
  ref_run $id best $refn $refr
  ref_run $id coarse_mesh $n2 $refr
  ref_run $id coarse_rtol $refn $r2
  refconv $id coarse_mesh $n2 $refr
  refconv $id coarse_rtol $refn $r2
  local ref=$WORK/${id}_ref_best.csv same=$WORK/${id}_ref_same16.csv
  ref_run $id same16 16 1e-10
  run_cases $id rtol "$ref" "$same" complete 16 "$RTOLS" klu - -
  for m in foac zoac; do run_cases $id "$m" "$ref" - "$m" 16 "$MODEL_RTOLS" klu - -; done
  run_cases $id elements "$ref" - complete "$ELEMS" $erc klu - -
  run_cases $id dense "$ref" "$same" complete 16 "$SUB_RTOLS" dense - -
  run_cases $id klu_full "$ref" "$same" complete 16 "$SUB_RTOLS" klu_full - -
  [ $QUICK = 1 ] || run_cases $id dense "$ref" - complete 64 1e-6 dense - -
  [ $QUICK = 1 ] || run_cases $id klu64 "$ref" - complete 64 1e-6 klu - -
  run_cases $id errctl "$ref" "$same" complete 16 "$SUB_RTOLS" klu positions -
  if [ $QUICK = 0 ]; then
    for o in 1 3 5; do RUN_TIMEOUT=30 run_cases $id order "$ref" "$same" complete 16 1e-6 klu - $o; done
  fi
}

pendulum() {
  want pend || return 0
  SCENE_FILE=$ROOT/scenes/paper/pendulum.yaml
  TIP=beam.tip_v; ANGLE=beam.theta; KIN=energy.kinetic
  # the first second (the first swing down): BDF2 steps shrink like rtol^(1/2), and the full 5 s
  # at rtol 1e-9 alone would take minutes
  SCENE_SETS=(--set solver.t_end=1 --set "outputs=[beam.tip_v,beam.theta,energy.total,energy.kinetic]")
  echo "== pendulum (first second)" >&2
  local refn=32 refr=1e-8 n2=16 r2=1e-7 rt="1e-3 1e-4 1e-5 1e-6 1e-7" el="8 16 32 64"
  [ $QUICK = 1 ] && { refn=32; refr=1e-7; n2=16; r2=1e-6; rt="1e-4 1e-6"; el="8 16"; }
  ref_run pend best $refn $refr
  ref_run pend coarse_mesh $n2 $refr
  ref_run pend coarse_rtol $refn $r2
  refconv pend coarse_mesh $n2 $refr
  refconv pend coarse_rtol $refn $r2
  local ref=$WORK/pend_ref_best.csv same=$WORK/pend_ref_coarse_mesh.csv
  run_cases pend rtol "$ref" "$same" complete 16 "$rt" klu - -
  for m in foac zoac; do run_cases pend "$m" "$ref" - "$m" 16 "$rt" klu - -; done
  run_cases pend elements "$ref" - complete "$el" 1e-6 klu - -
  run_cases pend dense "$ref" "$same" complete 16 1e-6 dense - -
  run_cases pend klu_full "$ref" "$same" complete 16 1e-6 klu_full - -
  [ $QUICK = 1 ] || run_cases pend dense "$ref" "$same" complete 16 1e-4 dense - -
  # the pendulum's scene controls positions only; the full error test on velocities too:
  RUN_TIMEOUT=60 run_cases pend errctl "$ref" "$same" complete 16 1e-4 klu full -
  [ $QUICK = 1 ] || RUN_TIMEOUT=60 run_cases pend errctl "$ref" "$same" complete 16 1e-6 klu full -
  [ $QUICK = 1 ] || RUN_TIMEOUT=30 run_cases pend order "$ref" "$same" complete 16 1e-6 klu - 3
}

fourbar() {
  want fourbar || return 0
  SCENE_FILE=$ROOT/scenes/fourbar.yaml
  TIP=rocker.theta; ANGLE=coupler.theta; KIN=energy.kinetic
  SCENE_SETS=(--set "outputs=[rocker.theta,coupler.theta,energy.total,energy.kinetic]")
  echo "== four-bar (rigid)" >&2
  ref_run fourbar best - 1e-12
  ref_run fourbar coarse_rtol - 1e-11
  refconv fourbar coarse_rtol - 1e-11
  local ref=$WORK/fourbar_ref_best.csv
  run_cases fourbar rtol "$ref" - - - "$RTOLS" klu - -
  run_cases fourbar order "$ref" - - - "$RTOLS" klu - 2
  run_cases fourbar dense "$ref" - - - "$RTOLS" dense - -
  run_cases fourbar klu_full "$ref" - - - "$SUB_RTOLS" klu_full - -
  run_cases fourbar errctl "$ref" - - - "$SUB_RTOLS" klu positions -
}

spinup 4
spinup 15
pendulum
fourbar

bash "$ROOT/bench/report.sh" "$RUNS" "$RES" $([ $QUICK = 1 ] && echo --quick)
echo "bench: results in $RUNS, plots and tables in $RES (work files in $WORK)" >&2
