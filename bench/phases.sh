#!/usr/bin/env bash
# bench/phases.sh — where one run's instructions go, per phase, an old build beside this tree
# (issue 32, item 3: the ω0 = 15 spin-up's cost per step).
#
#   bash bench/phases.sh [--old COMMIT] [--scene SCENE.yaml] [--tag NAME]
#
# SCENE (default scenes/paper/spinup_w15.yaml) run once under valgrind's callgrind by OLD (default
# 1f21dea, built beside the tree by bench/lib.sh's build_landed) and by this tree; per build the
# inclusive instruction counts (callgrind_annotate --inclusive=yes) of the run, the integrator's
# steps (radau_advance) and its phases: the factorizations (fmb_schur_factor: S formed and its
# LU, dense_lu_*), the Schur solves (fmb_schur_solve, dense_solve_*), the residuals
# (system_residual: the beam's element_terms, the joints' joint_eval), the Jacobians
# (fmb_system_jacobian), radau's stage combinations and the rows (fmb_csv_row: the beam's energy
# pass beam_integrals); a kernel one build does not have (inlined, or new) shows as 0 for it.
# Instruction counts do not move with the machine's load (two
# runs of one build agree to a few hundred instructions), which timings on a shared machine do;
# bench/shipped.sh --scene spinup_w15 times the same builds. Results:
# bench/results/phases.csv (--tag: phases_NAME.csv).
set -euo pipefail
cd "$(dirname "$0")/.."
ROOT=$PWD
F=${FLEXMBD:-$ROOT/build/flexmbd}
RES=${RESULTS:-$ROOT/bench/results}
WORK=$(mktemp -d /tmp/flexmbd-phases.XXXXXX)
trap 'rm -rf "$WORK"' EXIT
OLD=1f21dea
SCENE=scenes/paper/spinup_w15.yaml
TAG=
while [ $# -gt 0 ]; do
  case $1 in
    --old) OLD=$2; shift 2 ;;
    --scene) SCENE=$2; shift 2 ;;
    --tag) TAG=_$2; shift 2 ;;
    -h | --help) sed -n 2,18p "$0"; exit 0 ;;
    *) echo "bench/phases.sh: unknown argument '$1'" >&2; exit 2 ;;
  esac
done
command -v valgrind > /dev/null || { echo "bench/phases.sh: needs valgrind (apt-get install valgrind)" >&2; exit 2; }
. "$ROOT/bench/lib.sh" # build_landed
build_landed "$OLD" "/tmp/fmb-$OLD"
OUT=$RES/phases$TAG.csv
mkdir -p "$RES"

PHASES="fmb_run radau_advance fmb_schur_factor(_pencil)? schur_form_real schur_form_complex dense_lu_real dense_lu_complex
fmb_schur_solve schur_solve_real schur_solve_complex dense_solve_real dense_solve_complex system_residual
element_terms element_state joint_eval fmb_system_jacobian beam_jacobian element_derivs stage_combination
dense_poly fmb_csv_row beam_integrals"
profile() { # binary label
  valgrind --tool=callgrind --callgrind-out-file="$WORK/$2.cg" "$1" run "$ROOT/$SCENE" -o "$WORK/$2.csv" --quiet \
    2> "$WORK/$2.err" < /dev/null
  callgrind_annotate --inclusive=yes --threshold=100 "$WORK/$2.cg" 2> /dev/null > "$WORK/$2.txt"
}
profile "/tmp/fmb-$OLD/build/flexmbd" old
profile "$F" new
count() { # label function (an ERE): its inclusive count, its AVX2 and default clones' summed
  { grep -E ":($2)(\.avx2|\.default)? \[" "$WORK/$1.txt" || true; } |
    awk '{ gsub(",", "", $1); s += $1 } END { printf "%.0f", s }'
}
NEW_LABEL="this tree ($(git rev-parse --short HEAD))"
echo "phase,$OLD,$NEW_LABEL,ratio" > "$OUT"
for p in $PHASES; do
  o=$(count old "$p")
  n=$(count new "$p")
  echo "$p,$o,$n,$(awk -v o="$o" -v n="$n" 'BEGIN { if (n > 0 && o > 0) printf "%.2f", o / n; else printf "-" }')" >> "$OUT"
done
cmp -s "$WORK/old.csv" "$WORK/new.csv" && same="cmp-equal" || same="DIFFERENT"
column -s, -t < "$OUT"
echo "$SCENE: the two builds' CSVs are $same"
echo "results: $OUT"
