#!/usr/bin/env bash
# bench/exudyn_ancf.sh — issue 32 item 4: the exact beam (scenes/exact/spinup_w15_exact.yaml, its
# defaults) against Exudyn 1.11's ANCF cable (bench/exudyn_ancf.py) on the paper's spin-ups, at
# equal error against an exact reference, side by side on this machine (docs/performance.md,
# "The exact beam against Exudyn's ANCF cable").
#
#   bash bench/exudyn_ancf.sh [--reps N] [--omega "4 15"] [--targets "1e-4 1e-5 1e-6"]
#
# Needs Exudyn 1.11 importable (EXUDYN_PATH, default /tmp/exudyn/main/pythonDev). It is not in
# Debian or reachable PyPI; built from its source (github:jgerstmayr/EXUDYN, "final commit for
# Exudyn1.11.0", e44aca1b) with Debian's python3-pybind11 (apt-get install python3-pybind11):
#   cd EXUDYN/main && python3 setup.py build_ext --inplace --noglfw --parallel
# (~15 minutes on 2 cores: its checked module exudynCPP and its fast one exudynCPPfast, which
# bench/exudyn_ancf.py uses when present: Exudyn's fastest). Without Exudyn the script says so
# and exits 2.
#
# Per omega0 (default 4 and 15 rad/s, 20 s):
# - the reference: the exact beam at 160 elements, rtol 1e-11 (its own convergence printed: 20,
#   40, 80, 160 elements at rtol 1e-10 against it), and the ANCF cable's finest run against it (an
#   independent discretization of the same continuum, by another code);
# - flexmbd: the scene with only elements and rtol set (3, 5, 10, 20 elements; rtol 1e-3 .. 1e-9),
#   and its outputs cut to what Exudyn records (beam.tip_u, beam.tip_v);
#   Exudyn: 4, 8, 16, 32 elements, fixed steps 1.25e-2 .. 5e-4 s (generalized-alpha; Newton as
#   bench/exudyn_ancf.py says; 1.25e-2 s is the step that just meets 1e-4 m at 8 elements and
#   omega0 = 4, the others divide the 0.01 s output period: both codes are compared at the same
#   times, no interpolation);
# - error: max over the run of |beam.tip_v - reference| (the tip's transverse displacement in the
#   hub frame), every 0.01 s (Exudyn's step 1.25e-2 s: every 0.05 s, the times both have);
# - per target error: each code's cheapest setting that meets it (CPU of the grid's single run),
#   then those settings timed again REPS times (default 3), interleaved, median: the ratio. A
#   target no Exudyn run meets is reported with Exudyn's most accurate run, the ratio marked ">" (a
#   lower bound: meeting the target would cost Exudyn more).
# CPU: flexmbd's stats line cpu_s (the whole run); Exudyn's process CPU of Assemble() and
# SolveDynamic() (bench/exudyn_ancf.py); an Exudyn run stopped after EXU_LIMIT s (default 60: at
# omega0 = 15 a step of 1e-2 s fails Newton and is halved again and again) is a row "timeout".
# Results: bench/results/exudyn_ancf.csv (every run) and
# exudyn_ancf_summary.csv.
set -euo pipefail
cd "$(dirname "$0")/.."
ROOT=$PWD
F=${FLEXMBD:-$ROOT/build/flexmbd}
RES=${RESULTS:-$ROOT/bench/results}
EXUDYN_PATH=${EXUDYN_PATH:-/tmp/exudyn/main/pythonDev}
PY=${PYTHON:-/usr/bin/python3}
REPS=3
OMEGAS="4 15"
TARGETS="1e-4 1e-5 1e-6"
while [ $# -gt 0 ]; do
  case $1 in
    --reps) REPS=$2; shift ;;
    --omega) OMEGAS=$2; shift ;;
    --targets) TARGETS=$2; shift ;;
    -h | --help) sed -n 2,30p "$0"; exit 0 ;;
    *) echo "exudyn_ancf.sh: unknown argument '$1'" >&2; exit 2 ;;
  esac
  shift
done
if ! PYTHONPATH=$EXUDYN_PATH "$PY" -c "import exudyn" 2> /dev/null; then
  echo "exudyn_ancf.sh: Exudyn is not importable from EXUDYN_PATH=$EXUDYN_PATH (see the head of this script)" >&2
  exit 2
fi
WORK=$(mktemp -d /tmp/flexmbd-exudyn.XXXXXX)
trap 'rm -rf "$WORK"' EXIT
mkdir -p "$RES"
SCENE=scenes/exact/spinup_w15_exact.yaml
ALL=$RES/exudyn_ancf.csv
echo "omega0,code,elements,setting,cpu_s,steps,tip_v_error_m" > "$ALL"

# max |tip_v - reference| over the times both have (rounded to 1e-6 s)
err() { # file ref
  [ -s "$1" ] || { echo nan; return; }
  "$PY" - "$1" "$2" << 'EOF'
import sys, numpy as np
def load(p):
    d = np.genfromtxt(p, delimiter=',', names=True)
    return {round(t, 6): v for t, v in zip(d['t'], d['beamtip_v'])}
a, r = load(sys.argv[1]), load(sys.argv[2])
common = [t for t in a if t in r]
if len(common) < 0.19 * len(r):
    print('nan'); sys.exit()
print('%.4g' % max(abs(a[t] - r[t]) for t in common))
EOF
}
flex() { # omega elements rtol out -> "cpu steps"
  "$F" run "$SCENE" -o "$4" --quiet --set joints.spin.omega0="$1" --set bodies.beam.elements="$2" \
    --set solver.rtol="$3" --set "outputs=[beam.tip_u, beam.tip_v]" 2>&1 | tail -1 | tr ' ' '\n' | awk -F= '$1 == "cpu_s" { c = $2 } $1 == "steps" { s = $2 } END { print c, s }'
}
exu() { # omega elements step out -> "cpu steps", or "timeout" after EXU_LIMIT s (default 60)
  rm -f "$4"
  { PYTHONPATH=$EXUDYN_PATH timeout "${EXU_LIMIT:-60}" "$PY" "$ROOT/bench/exudyn_ancf.py" --omega0 "$1" \
    --elements "$2" --step "$3" --out "$4" || true; } |
    tr ' ' '\n' | awk -F= '$1 == "cpu_s" { c = $2 } $1 == "steps" { s = $2 } END { print (c == "" ? "timeout" : c), s }'
}

for W in $OMEGAS; do
  REF=$WORK/ref_$W.csv
  echo "omega0 = $W: reference (exact beam, 160 elements, rtol 1e-11) ..." >&2
  "$F" run "$SCENE" -o "$REF" --quiet --set joints.spin.omega0="$W" --set bodies.beam.elements=160 \
    --set solver.rtol=1e-11 2> /dev/null
  for n in 20 40 80 160; do
    flex "$W" $n 1e-10 "$WORK/conv.csv" > /dev/null
    echo "  reference check: $n elements, rtol 1e-10: $(err "$WORK/conv.csv" "$REF") m" >&2
  done
  for n in 3 5 10 20; do
    for r in 1e-3 1e-4 1e-5 1e-6 1e-7 1e-8 1e-9; do
      read -r c s < <(flex "$W" $n $r "$WORK/run.csv")
      echo "$W,flexmbd,$n,rtol $r,$c,$s,$(err "$WORK/run.csv" "$REF")" >> "$ALL"
    done
  done
  for n in 4 8 16 32; do
    for h in 1.25e-2 1e-2 5e-3 2e-3 1e-3 5e-4; do
      read -r c s < <(exu "$W" $n $h "$WORK/run.csv")
      echo "$W,exudyn,$n,step $h,$c,$s,$(err "$WORK/run.csv" "$REF")" >> "$ALL"
    done
  done
  echo "  ANCF's finest (32 elements, step 5e-4 s) against the reference: $(grep "^$W,exudyn,32,step 5e-4," "$ALL" | cut -d, -f7) m" >&2
done

# per omega0 and target: the cheapest setting of each code, re-timed
SUM=$RES/exudyn_ancf_summary.csv
echo "omega0,target_m,flexmbd_setting,flexmbd_error_m,flexmbd_cpu_s,exudyn_setting,exudyn_error_m,exudyn_cpu_s,ratio" > "$SUM"
for W in $OMEGAS; do
  for T in $TARGETS; do
    pick() { # code -> "elements,setting,error" of the cheapest run meeting T
      awk -F, -v w="$W" -v c="$1" -v t="$T" '$1 == w && $2 == c && $7 != "nan" && $7 + 0 <= t + 0 && $5 != "timeout" {
        if (best == "" || $5 + 0 < bc) { bc = $5 + 0; best = $3 "," $4 "," $7 } } END { print best }' "$ALL"
    }
    fp=$(pick flexmbd) ep=$(pick exudyn)
    if [ -z "$fp" ]; then
      echo "$W,$T,none,,,,,," >> "$SUM"
      continue
    fi
    bound="" # no Exudyn run meets T: its most accurate one, whose CPU the ratio is then a bound from
    if [ -z "$ep" ]; then
      ep=$(awk -F, -v w="$W" '$1 == w && $2 == "exudyn" && $7 != "nan" && $5 != "timeout" && (best == "" || $7 + 0 < be) { be = $7 + 0; best = $3 "," $4 "," $7 } END { print best }' "$ALL")
      bound=">"
    fi
    fn=${fp%%,*} fr=$(echo "$fp" | cut -d, -f2) fe=${fp##*,}
    en=${ep%%,*} es=$(echo "$ep" | cut -d, -f2) ee=${ep##*,}
    fc="" ec=""
    for i in $(seq "$REPS"); do
      read -r c _ < <(flex "$W" "$fn" "${fr#rtol }" "$WORK/run.csv")
      fc="$fc $c"
      read -r c _ < <(exu "$W" "$en" "${es#step }" "$WORK/run.csv")
      ec="$ec $c"
    done
    fm=$(echo $fc | tr ' ' '\n' | sort -g | awk '{ a[NR] = $1 } END { print a[int((NR + 1) / 2)] }')
    em=$(echo $ec | tr ' ' '\n' | sort -g | awk '{ a[NR] = $1 } END { print a[int((NR + 1) / 2)] }')
    echo "$W,$T,$fn el $fr,$fe,$fm,$en el $es,$ee,$em,$bound$(awk -v a="$em" -v b="$fm" 'BEGIN { printf "%.1f", a / b }')" >> "$SUM"
  done
done
column -s, -t < "$SUM"
echo "results: $ALL, $SUM"
