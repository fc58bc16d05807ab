# cli_lib.sh — sourced by the command-line tests (tests/exact, and static_messages, plausibility) with the arguments
# FLEXMBD SOURCE_DIR OUT_DIR: sets F, SRC, OUT, enters SOURCE_DIR, and offers
#   check WHAT CONDITION   prints ok/FAIL and records a failure in $fail
#   near A B TOL           true when |A - B| <= TOL
set -u
F=$1
SRC=$2
OUT=$3
mkdir -p "$OUT"
cd "$SRC" || exit 1
fail=0
check() { if eval "$2"; then echo "ok: $1"; else echo "FAIL: $1"; fail=1; fi; }
near() { awk -v a="$1" -v b="$2" -v t="$3" 'BEGIN { d = a - b; if (d < 0) d = -d; exit !(d <= t) }'; }
