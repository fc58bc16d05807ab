#!/usr/bin/env bash
# bench/exact_ratio.sh — the exact beam's CPU against the complete model's at the same settings
# (issue 32 item 4: at most 3x). The three paper spin-ups (w1, w4, w15) and the flexible pendulum
# (first T_PEND seconds, default 1) as shipped, with only bodies.beam.model changed, under the
# default integrator (auto) and, with --integrators, others; each run REPS times (default 5),
# interleaved, CPU the median of its stats line's cpu_s. `model: exact` is the default kinematics,
# intrinsic since issue 32 item 4; beside it the cable (kinematics: cable, the default before) and
# the cable in its displacement form (axial_form: displacement: its Newton before the mixed form).
# Output: bench/results/exact_ratio.csv (one row per scene, integrator and variant) and a table
# with the ratios on stdout.
# --sweep instead: rtol 1e-4 ... 1e-8 x backends (radau9 radau5 ida: every one auto may pick for a
# beam or that a user names) x {spin-up w4, spin-up w15, pendulum (first T_PEND s, default 0.2)} x
# {complete, exact} (exact: each build's default kinematics, intrinsic since issue 32 item 4), this
# build and a build BEFORE (default cf68845, the commit before radau judged the cable's Newton from
# its third iteration; cdf9298 is the last whose exact beam is the cable by default) side by side in
# one run, REPS times interleaved (default 3): steps, Jacobians, conv_fails, Newton iterations and
# the median CPU, into bench/results/exact_rtol.csv; per scene/backend/build the exact/complete CPU
# ratio per rtol (goal <= 3) and whether the exact beam's cost falls as rtol is loosened, judged
# twice: by counts, free of the machine's noise ("falls" when no looser rtol takes more steps or
# Newton iterations than the next tighter one; Jacobians are listed beside: the intrinsic beam's
# are dense differences, 3 residuals per column, which the stats' residual count leaves out); and by
# CPU, "falls" when each looser rtol costs at most 10 % more than the next tighter one (the noise of
# a shared machine on runs of a few hundredths of a second) and the loosest less than the tightest.
# The rows missing a goal are named. --summary: only this table, from the CSV a sweep left.
# FLEXMBD_BEFORE=path uses that binary instead of building BEFORE (bench/lib.sh); --before none
# runs this build only.
# --probe instead: why the cable's Newton (model: exact, kinematics: cable) is slow on the pendulum
# (docs/performance.md, "The exact beam's Newton"): the pendulum's first T_PEND s (default 0.2) as shipped and with one thing
# changed at a time (gravity, stiffness, EA alone at the same mass and EI, the axial form, the
# linear solver, the mesh, the step, the backend), and the omega0 = 4 spin-up and a clamped
# clamped cantilever with and without gravity (their first 0.2 s: the complete model leaves its
# range under gravity there after 0.22 s, its deflection 19 % of the length), complete and exact side by side: steps, Jacobians,
# conv_fails, Newton iterations per step (counts: one run each) and the median CPU of REPS
# (default 3), into bench/results/exact_probe.csv and a table on stdout.
#   bash bench/exact_ratio.sh [--reps N] [--integrators "auto radau5 ida"] [--t-pend T]
#   bash bench/exact_ratio.sh --sweep [--reps N] [--before COMMIT|none] [--rtols "1e-4 1e-6"] [--t-pend T]
#   bash bench/exact_ratio.sh --summary
#   bash bench/exact_ratio.sh --probe [--reps N] [--t-pend T]
set -euo pipefail
cd "$(dirname "$0")/.."
ROOT=$PWD
F=${FLEXMBD:-$ROOT/build/flexmbd}
RES=${RESULTS:-$ROOT/bench/results}
. bench/lib.sh
REPS=
INTEGRATORS="auto"
TPEND=
SWEEP=0
PROBE=0
BEFORE=cf68845
RTOLS="1e-4 1e-5 1e-6 1e-7 1e-8"
while [ $# -gt 0 ]; do
  case $1 in
    --reps) REPS=$2; shift ;;
    --integrators) INTEGRATORS=$2; shift ;;
    --t-pend) TPEND=$2; shift ;;
    --sweep) SWEEP=1 ;;
    --probe) PROBE=1 ;;
    --summary) SWEEP=2 ;;
    --before) BEFORE=$2; shift ;;
    --rtols) RTOLS=$2; shift ;;
    -h|--help) sed -n 2,35p "$0"; exit 0 ;;
    *) echo "exact_ratio.sh: unknown argument '$1'" >&2; exit 2 ;;
  esac
  shift
done
mkdir -p "$RES"
WORK=$(mktemp -d)
trap 'rm -rf "$WORK"' EXIT
if [ "$PROBE" = 1 ]; then
  REPS=${REPS:-3}
  TPEND=${TPEND:-0.2}
  CSV=$RES/exact_probe.csv
  echo "case,model,steps,jacobians,conv_fails,newton_iters,cpu_s_median" > "$CSV"
  P=scenes/paper/pendulum.yaml
  W=scenes/paper/spinup_w4.yaml
  # case|scene|settings (one --set each, space-separated)
  cases=(
    "pendulum as shipped|$P|solver.t_end=$TPEND"
    "gravity x0.01|$P|solver.t_end=$TPEND gravity=[0,-0.0981]"
    "gravity x0.1|$P|solver.t_end=$TPEND gravity=[0,-0.981]"
    "gravity x10|$P|solver.t_end=$TPEND gravity=[0,-98.1]"
    "no gravity; swinging at 3 rad/s|$P|solver.t_end=$TPEND gravity=[0,0] bodies.beam.angular_velocity=3"
    "E x100 (sag / 100)|$P|solver.t_end=$TPEND bodies.beam.youngs_modulus=68.95e11"
    "EA x0.01 (same mass and EI)|$P|solver.t_end=$TPEND bodies.beam.area=2.5e-6 bodies.beam.density=276700"
    "EA x10 (same mass and EI)|$P|solver.t_end=$TPEND bodies.beam.area=2.5e-3 bodies.beam.density=276.7"
    "axial_form displacement|$P|solver.t_end=$TPEND bodies.beam.axial_form=displacement"
    "linear_solver klu_full|$P|solver.t_end=$TPEND solver.linear_solver=klu_full"
    "1 element|$P|solver.t_end=$TPEND bodies.beam.elements=1"
    "4 elements|$P|solver.t_end=$TPEND bodies.beam.elements=4"
    "max_step 3e-5|$P|solver.t_end=$TPEND solver.max_step=3e-5"
    "radau5|$P|solver.t_end=$TPEND solver.integrator=radau5"
    "ida|$P|solver.t_end=$TPEND solver.integrator=ida"
    "hanging at rest (angle -90 deg)|$P|solver.t_end=$TPEND bodies.beam.angle=-1.5707963"
    "spin-up w4; first 0.2 s|$W|solver.error_control=positions solver.t_end=0.2"
    "spin-up w4 + gravity; first 0.2 s|$W|solver.error_control=positions solver.t_end=0.2 gravity=[0,-9.81]"
    "cantilever held; transverse gravity 0.2 s|$W|solver.error_control=positions joints.spin.omega0=0 solver.t_end=0.2 gravity=[0,-9.81]"
    "cantilever held; axial gravity 0.2 s|$W|solver.error_control=positions joints.spin.omega0=0 solver.t_end=0.2 gravity=[-9.81,0]"
  )
  for c in "${cases[@]}"; do
    name=${c%%|*}
    rest=${c#*|}
    scene=${rest%%|*}
    sets=()
    for kv in ${rest#*|}; do sets+=(--set "$kv"); done
    for m in complete exact; do
      : > "$WORK/cpu"
      cable=()
      [ "$m" = exact ] && cable=(--set bodies.beam.kinematics=cable)
      for ((k = 0; k < REPS; ++k)); do
        line=$("$F" run "$scene" -o "$WORK/out.csv" --quiet --set "bodies.beam.model=$m" "${cable[@]}" "${sets[@]}" 2>&1 | tail -1 || true)
        echo "$line" | stat_field cpu_s >> "$WORK/cpu"
      done
      echo "$name,$m,$(echo "$line" | stat_field steps),$(echo "$line" | stat_field jacobians),$(echo "$line" | stat_field conv_fails),$(echo "$line" | stat_field newton_iters),$(median < "$WORK/cpu")" >> "$CSV"
    done
  done
  echo "case: complete / exact  steps, Jacobians, conv_fails, Newton iterations per step, CPU s"
  awk -F, 'NR > 1 { k = $1; if (!(k in seen)) { seen[k] = 1; order[++n] = k }
      r[k, $2] = sprintf("%s, %s, %s, %.2f, %.4f", $3, $4, $5, $6 / ($3 > 0 ? $3 : 1), $7) }
    END { for (m = 1; m <= n; ++m) printf "%-42s %s  /  %s\n", order[m], r[order[m], "complete"], r[order[m], "exact"] }' "$CSV"
  exit 0
fi
if [ "$SWEEP" = 1 ] || [ "$SWEEP" = 2 ]; then
  REPS=${REPS:-3}
  TPEND=${TPEND:-0.2}
  FB=${FLEXMBD_BEFORE:-}
  builds="before after"
  if [ "$SWEEP" = 2 ]; then
    builds=none
  elif [ "$BEFORE" = none ]; then
    builds=after
  elif [ -z "$FB" ]; then
    build_landed "$BEFORE" "${BENCH_CACHE:-$ROOT/build/bench-landed}/$BEFORE"
    FB=${BENCH_CACHE:-$ROOT/build/bench-landed}/$BEFORE/build/flexmbd
  fi
  CSV=$RES/exact_rtol.csv
  [ "$builds" != none ] && echo "build,scene,integrator,model,rtol,steps,jacobians,conv_fails,newton_iters,cpu_s_median,residuals" > "$CSV"
  for s in spinup_w4 spinup_w15 pendulum; do
    [ "$builds" = none ] && break
    extra=()
    [ "$s" = pendulum ] && extra=(--set "solver.t_end=$TPEND")
    for i in radau9 radau5 ida; do
      for r in $RTOLS; do
        for b in $builds; do for m in complete exact; do : > "$WORK/cpu.$b.$m"; done; done
        for ((k = 0; k < REPS; ++k)); do
          for b in $builds; do
            bin=$F
            [ "$b" = before ] && bin=$FB
            for m in complete exact; do
              line=$("$bin" run "scenes/paper/$s.yaml" -o "$WORK/out.csv" --quiet --set "bodies.beam.model=$m" \
                --set "solver.integrator=$i" --set "solver.rtol=$r" "${extra[@]}" 2>&1 | tail -1)
              echo "$line" | stat_field cpu_s >> "$WORK/cpu.$b.$m"
              echo "$line" > "$WORK/stats.$b.$m"
            done
          done
        done
        for b in $builds; do
          for m in complete exact; do
            st=$(cat "$WORK/stats.$b.$m")
            echo "$b,$s,$i,$m,$r,$(echo "$st" | stat_field steps),$(echo "$st" | stat_field jacobians),$(echo "$st" | stat_field conv_fails),$(echo "$st" | stat_field newton_iters),$(median < "$WORK/cpu.$b.$m"),$(echo "$st" | stat_field residuals)" >> "$CSV"
          done
        done
      done
    done
  done
  echo "scene integrator build: per rtol (as given), exact then complete: steps / Jacobians / conv_fails / CPU s;"
  echo "the exact/complete CPU ratio per rtol (goal <= 3) and whether the exact beam's cost falls as rtol is loosened"
  echo "(by its steps and Newton iterations, counts; and by CPU, within 10 %)"
  awk -F, 'NR > 1 { k = $2 " " $3 " " $1; if (!(k in seen)) { seen[k] = 1; order[++n] = k }
      if ($4 == "exact") { e[k] = e[k] sprintf("  %s: %s/%s/%s/%.4f", $5, $6, $7, $8, $10); x[k, $5] = $10; nst[k, $5] = $6; nit[k, $5] = $9; r[k] = r[k] " " $5 }
      else { cc[k] = cc[k] sprintf("  %s: %s/%s/%s/%.4f", $5, $6, $7, $8, $10); c[k, $5] = $10 } }
    END { bad = ""; for (m = 1; m <= n; ++m) { k = order[m]; printf "%-30s exact   %s\n%-30s complete%s\n   ratio", k, e[k], "", cc[k]
      nr = split(r[k], rr, " "); worst = 0
      for (j = 1; j <= nr; ++j) { q = x[k, rr[j]] / c[k, rr[j]]; printf "  %.2f", q; if (q > worst) worst = q }
      falls = 1; counts = 1; loose = rr[1] + 0 > rr[nr] + 0 ? 1 : nr; tight = loose == 1 ? nr : 1
      for (j = 1; j < nr; ++j) { lj = rr[j] + 0 > rr[j + 1] + 0 ? j : j + 1; tj = lj == j ? j + 1 : j
        if (x[k, rr[lj]] > 1.1 * x[k, rr[tj]]) falls = 0
        if (nst[k, rr[lj]] + 0 > nst[k, rr[tj]] + 0 || nit[k, rr[lj]] + 0 > nit[k, rr[tj]] + 0) counts = 0 }
      if (!(x[k, rr[loose]] < x[k, rr[tight]])) falls = 0
      printf "   (worst %.2f%s); cost falls as rtol is loosened: counts %s, CPU %s\n", worst, worst <= 3 ? "" : ", above 3",
        counts ? "yes" : "NO", falls ? "yes" : "NO"
      if (!counts || !falls || worst > 3) bad = bad "\n  " k } if (bad != "") printf "rows missing a goal:%s\n", bad }' "$CSV"
  exit 0
fi
REPS=${REPS:-5}
TPEND=${TPEND:-1}
CSV=$RES/exact_ratio.csv
echo "scene,integrator,variant,steps,jacobians,conv_fails,newton_iters,cpu_s_median" > "$CSV"
scenes="spinup_w1 spinup_w4 spinup_w15 pendulum"
variants="complete exact exact_cable exact_displacement"
run_one() { # scene integrator variant -> the stats line
  local s=$1 i=$2 v=$3 extra=()
  [ "$s" = pendulum ] && extra=(--set "solver.t_end=$TPEND")
  local model=${v%%_*}
  case $v in
    exact_cable) extra+=(--set bodies.beam.kinematics=cable) ;;
    exact_displacement) extra+=(--set bodies.beam.kinematics=cable --set bodies.beam.axial_form=displacement) ;;
  esac
  "$F" run "scenes/paper/$s.yaml" -o "$WORK/out.csv" --quiet --set "bodies.beam.model=$model" \
    --set "solver.integrator=$i" "${extra[@]}" 2>&1 | tail -1
}
for s in $scenes; do
  for i in $INTEGRATORS; do
    for v in $variants; do : > "$WORK/cpu.$s.$i.$v"; done
    for ((r = 0; r < REPS; ++r)); do
      for v in $variants; do
        line=$(run_one "$s" "$i" "$v")
        echo "$line" | stat_field cpu_s >> "$WORK/cpu.$s.$i.$v"
        echo "$line" > "$WORK/stats.$s.$i.$v"
      done
    done
    for v in $variants; do
      st=$(cat "$WORK/stats.$s.$i.$v")
      med=$(median < "$WORK/cpu.$s.$i.$v")
      echo "$s,$i,$v,$(echo "$st" | stat_field steps),$(echo "$st" | stat_field jacobians),$(echo "$st" | stat_field conv_fails),$(echo "$st" | stat_field newton_iters),$med" >> "$CSV"
    done
  done
done
echo "scene integrator: complete / exact (intrinsic) / cable / cable displacement form CPU s, ratio to complete; Jacobians; conv_fails"
awk -F, 'NR > 1 { k = $1 " " $2; c[k, $3] = $8; j[k, $3] = $5; f[k, $3] = $6; if (!(k in seen)) { seen[k] = 1; order[++n] = k } }
  END { for (m = 1; m <= n; ++m) { k = order[m];
    printf "%-22s %.4f / %.4f / %.4f / %.4f s  ratio %.2f / %.2f / %.2f  Jacobians %s / %s / %s / %s  conv_fails %s / %s / %s / %s\n", k,
      c[k, "complete"], c[k, "exact"], c[k, "exact_cable"], c[k, "exact_displacement"], c[k, "exact"] / c[k, "complete"],
      c[k, "exact_cable"] / c[k, "complete"], c[k, "exact_displacement"] / c[k, "complete"], j[k, "complete"], j[k, "exact"],
      j[k, "exact_cable"], j[k, "exact_displacement"], f[k, "complete"], f[k, "exact"], f[k, "exact_cable"], f[k, "exact_displacement"] } }' "$CSV"
