#!/bin/sh
# cli_analysis.sh FLEXMBD SOURCE_DIR OUT_DIR — the commands `static`, `modes`, `campbell` as a user
# calls them: the CSV columns the issue names, values against closed forms (P L^3/3EI, Euler-
# Bernoulli, the rotating beam's 6.3357 rad/s at 15 rad/s), the stats line, the exit codes
# (2 bad input with file:line:column or the override, 3 no equilibrium), rows kept on failure.
set -u
flexmbd=$1 src=$2 out=$3
mkdir -p "$out"
cd "$src"
fail=0
check() { # description, then a command that must succeed
  what=$1
  shift
  if "$@"; then echo "ok: $what"; else echo "FAILED: $what"; fail=1; fi
}
near() { # value expected relative-tolerance
  awk -v a="$1" -v b="$2" -v r="$3" 'BEGIN { d = a - b; if (d < 0) d = -d; m = b < 0 ? -b : b; exit !(d <= r * m) }'
}
col() { # csv row(1-based data row) column-name
  awk -F, -v row="$2" -v name="$3" 'NR == 1 { for (i = 1; i <= NF; i++) if ($i == name) c = i } NR == row + 1 { print $c }' "$1"
}
cant=tests/analysis/scenes/cantilever.yaml

# static: tip load 1e-3 N -> P L^3 / 3EI = 2.165464188e-4 m
"$flexmbd" static $cant --set 'joints.load.force=[0, 1e-3]' -o "$out/static.csv" 2>"$out/static.err"
check "static exits 0" test $? -eq 0
check "static header" test "$(head -1 "$out/static.csv")" = "t,beam.tip_u,beam.tip_v"
check "static tip deflection P L^3/3EI" near "$(col "$out/static.csv" 1 beam.tip_v)" 2.165464188e-4 1e-6
check "static stats line last" sh -c "tail -1 '$out/static.err' | grep -q '^stats: status=ok .*iterations=[1-9].*residual='"

# modes: header, rows, Euler-Bernoulli first frequency, Hz = rad/s / 2 pi
"$flexmbd" modes $cant --count 4 -o "$out/modes.csv" --shapes "$out/shapes.csv" 2>"$out/modes.err"
check "modes exits 0" test $? -eq 0
check "modes header" test "$(head -1 "$out/modes.csv")" = "mode,frequency,frequency_hz,damping_ratio"
check "modes rows" test "$(wc -l < "$out/modes.csv")" -eq 5
check "modes omega1 (Euler-Bernoulli 3.90934308)" near "$(col "$out/modes.csv" 1 frequency)" 3.90934308 1e-6
check "modes Hz" near "$(col "$out/modes.csv" 2 frequency_hz)" "$(awk "BEGIN { printf \"%.12g\", $(col "$out/modes.csv" 2 frequency) / (8 * atan2(1, 1)) }")" 1e-9
check "mode shapes header" test "$(head -1 "$out/shapes.csv")" = "mode,beam.tip_u,beam.tip_v"
check "mode 1 moves the tip" awk -F, 'NR == 2 { v = $3 < 0 ? -$3 : $3; exit !(v > 0.1) }' "$out/shapes.csv"
"$flexmbd" modes $cant --at 1 --static >/dev/null 2>&1
check "modes --at with --static: exit 2" test $? -eq 2
"$flexmbd" modes scenes/paper/spinup_w4.yaml --at 5 >/dev/null 2>"$out/ramp.err"
check "modes during a spin-up ramp: exit 2" test $? -eq 2
check "... saying the drive accelerates" grep -q accelerating "$out/ramp.err"
"$flexmbd" modes $cant --set bodies.beam.elements=many >/dev/null 2>"$out/set.err"
check "modes with a bad --set: exit 2" test $? -eq 2
check "... quoting the override" grep -q "^--set: error: bodies.beam.elements=many" "$out/set.err"

# mode animation through the VTK writer: 24 frames over one period; the tip swings +A, 0, -A at
# frames 0, 6, 12 (time 0, T/4, T/2 with T = 2 pi / omega1) and shortens by w_c at both ends
"$flexmbd" modes $cant --count 2 --animate "$out/anim" --amplitude 0.1 -o /dev/null 2>/dev/null
check "modes --animate exits 0" test $? -eq 0
check "a collection per mode, 24 frames" test "$(grep -c '<DataSet' "$out/anim/mode2/cantilever.pvd")" -eq 24
check "mode 1 swings through +A, 0, -A over half a period" python3 - "$out/anim/mode1" <<'PY'
import math, re, struct, sys
def frame(j):  # the .vtu's arrays are raw binary appended data: a UInt64 byte count, then doubles
    s = open("%s/cantilever_%06d.vtu" % (sys.argv[1], j), "rb").read()
    t = float(re.search(rb'Name="TimeValue"[^>]*>([^<]*)<', s).group(1))
    off = int(re.search(rb'Name="deformation"[^>]*offset="([0-9]+)"', s).group(1))
    base = s.index(b"_", s.index(b'<AppendedData encoding="raw">')) + 1 + off
    (n,) = struct.unpack("<Q", s[base:base + 8])
    d = struct.unpack("<%dd" % (n // 8), s[base + 8:base + 8 + n])
    return t, max((d[i:i + 2] for i in range(0, len(d), 3)), key=lambda u: abs(u[1]))
(t0, a), (t6, b), (t12, c) = frame(0), frame(6), frame(12)
period = 2 * math.pi / 3.9093421
ok = abs(a[1] - 0.1) < 1e-9 and abs(b[1]) < 1e-12 and abs(c[1] + 0.1) < 1e-9 and a[0] < 0 and abs(a[0] - c[0]) < 1e-12
ok = ok and abs(t6 - period / 4) < 1e-6 and abs(t12 - period / 2) < 1e-6
sys.exit(0 if ok else 1)
PY

# no equilibrium: a free body under gravity
printf 'solver: {t_end: 1.0}\ngravity: [0, -9.81]\nbodies:\n  - {name: box, type: rigid, mass: 1.0, inertia: 0.1}\n' > "$out/free.yaml"
"$flexmbd" static "$out/free.yaml" >/dev/null 2>"$out/free.err"
check "static without supports: exit 3" test $? -eq 3
check "... saying nothing holds it" grep -q "held by nothing" "$out/free.err"

# campbell: columns, the stiffened frequency at 15 rad/s (6.3357, README), a PNG when gnuplot exists
"$flexmbd" campbell tests/analysis/scenes/rotating.yaml --speed joints.spin.speed --speeds 0:15:4 --count 2 \
  -o "$out/campbell.csv" 2>"$out/campbell.err"
check "campbell exits 0" test $? -eq 0
check "campbell header" test "$(head -1 "$out/campbell.csv")" = "speed,mode1,mode2"
check "campbell rows" test "$(wc -l < "$out/campbell.csv")" -eq 5
check "campbell mode1 at 15 rad/s" near "$(col "$out/campbell.csv" 4 mode1)" 6.3357 1e-4
if command -v gnuplot >/dev/null; then check "campbell PNG" test -s "$out/campbell.png"; fi
"$flexmbd" campbell tests/analysis/scenes/rotating.yaml --speeds 0:1:2 >/dev/null 2>&1
check "campbell without --speed: exit 2" test $? -eq 2
"$flexmbd" campbell tests/analysis/scenes/rotating.yaml --speed bodies.beam.elements --speeds 8,0 \
  -o "$out/partial.csv" >/dev/null 2>&1
check "campbell failing at the 2nd speed: exit 2" test $? -eq 2
check "... keeps the first row" test "$(wc -l < "$out/partial.csv")" -eq 2
# tracking by shape: ZOAC's first bending mode diverges ever faster (-sqrt(W^2 - w1^2)) and passes the
# second (which softens and diverges from 25 rad/s); sorted by |frequency| they swap near 16 rad/s,
# followed by MAC the columns stay with their shapes
"$flexmbd" campbell tests/analysis/scenes/rotating.yaml --set bodies.beam.model=zoac --speed joints.spin.speed \
  --speeds 10:30:11 --count 2 -o "$out/zoac.csv" --plot "$out/zoac.png" 2>/dev/null
check "campbell ZOAC exits 0" test $? -eq 0
check "mode1 at 30 rad/s is the first bending mode, -sqrt(W^2 - w1^2)" \
  near "$(col "$out/zoac.csv" 11 mode1)" "$(awk 'BEGIN { printf "%.12g", -sqrt(900 - 3.90934219^2) }')" 1e-3
check "mode2 at 30 rad/s is the second one" near "$(col "$out/zoac.csv" 11 mode2)" -17.3137 1e-4
"$flexmbd" modes tests/analysis/scenes/rotating.yaml --set bodies.beam.model=zoac --set joints.spin.speed=30 --count 2 \
  -o "$out/zoac30.csv" 2>/dev/null
check "... where modes, sorted by |frequency|, lists the second first" near "$(col "$out/zoac30.csv" 1 frequency)" -17.3137 1e-4

# initial: static — a misspelt value is bad input at its line and column
"$flexmbd" run $cant --set initial=statc >/dev/null 2>"$out/initial.err"
check "initial: statc: exit 2" test $? -eq 2
check "... naming the choices" grep -q "expected one of given, assemble, static for 'initial'" "$out/initial.err"
exit $fail
