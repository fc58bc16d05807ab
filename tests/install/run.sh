#!/bin/sh
# run.sh SOURCE_DIR BUILD_DIR WORK_DIR — the installed package, as a user outside the tree has it:
#  1. `cmake --install` into a temporary prefix: the library (shared, soname = FMB_SOVERSION, and
#     static), the two public headers (flexmbd.h, flexmbd_plugin.h) and no private one, the program, the CMake package, flexmbd.pc;
#     the shared library exports only fmb_* API symbols;
#  2. each public header compiles alone, strictly, as C11 (and as C++ when g++ is there);
#  3. examples/plugin/ copied out of the tree and built with find_package(flexmbd) (plugin and the
#     embedding check program) and again with pkg-config;
#  4. the plugin loaded by `--plugin` and by the scene's `plugins:` list; `flexmbd types` lists it;
#     `flexmbd conform` passes on it and on every built-in type; its scene agrees with the analytic
#     solution (check_foundation);
#     docs/plugins.md's tutorial, extracted from the page, builds and passes conform the same way;
#  5. deliberately broken plugins (tests/install/broken.c) are each caught, with a clear message:
#     another plugin ABI major or a newer minor, a missing required op, no entry symbol, a name already taken (loader, exit 2), a wrong Jacobian, a mass
#     matrix that is not symmetric, energy that leaks (conform, exit 1);
#  6. the prefix moved elsewhere still works through pkg-config (relocatable .pc);
#  examples/joint_plugin and the spatial examples/plugin3d are built out of the tree too, each conform and
#  its check program against its closed form.
. "$(dirname "$0")/prefix.sh"
fails=0
fail() {
  echo "FAIL: $*" >&2
  fails=$((fails + 1))
}
# run CMD... expecting exit code $1 and a stderr/stdout line matching $2 (grep -E)
expect() {
  code=$1 pattern=$2
  shift 2
  "$@" >"$work/out" 2>&1
  rc=$?
  [ "$rc" = "$code" ] || fail "$* exited $rc, expected $code: $(tail -n 3 "$work/out")"
  grep -Eq -- "$pattern" "$work/out" || fail "$*: no line matching '$pattern' in: $(head -n 5 "$work/out")"
  echo "ok: $* -> exit $rc, '$(grep -E -m1 -- "$pattern" "$work/out")'"
}

abi=$(sed -n 's/^#define FMB_SOVERSION \([0-9]*\).*/\1/p' "$src/engine/flexmbd.h")
pmajor=$(sed -n 's/^#define FMB_PLUGIN_ABI_MAJOR \([0-9]*\).*/\1/p' "$src/engine/flexmbd_plugin.h")
pminor=$(sed -n 's/^#define FMB_PLUGIN_ABI_MINOR \([0-9]*\).*/\1/p' "$src/engine/flexmbd_plugin.h")

# 1. the installed tree
for f in include/flexmbd.h include/flexmbd_plugin.h bin/flexmbd; do [ -e "$T/$f" ] || fail "$f not installed"; done
[ -e "$libdir/libflexmbd.so.$abi" ] || fail "libflexmbd.so.$abi (soname = FMB_SOVERSION $abi) not installed"
[ -e "$libdir/libflexmbd.a" ] || fail "static libflexmbd.a not installed"
[ -e "$libdir/pkgconfig/flexmbd.pc" ] || fail "flexmbd.pc not installed"
[ -e "$libdir/cmake/flexmbd/flexmbdConfig.cmake" ] || fail "CMake package not installed"
[ "$(ls "$T/include" | tr '\n' ' ')" = "flexmbd.h flexmbd_plugin.h " ] ||
  fail "headers other than flexmbd.h, flexmbd_plugin.h installed: $(ls "$T/include")"
exported=$(nm -D --defined-only "$libdir/libflexmbd.so" | awk '$2 == "T" {print $3}')
n_exported=$(echo "$exported" | wc -l)
# xerbla_: LAPACK's error handler, replaced so that LAPACK never ends the calling program (engine/modes.c)
bad=$(echo "$exported" | grep -v '^fmb_' | grep -v '^xerbla_$' | tr '\n' ' ')
[ -z "$bad" ] || fail "the shared library exports non-API symbols: $bad"
echo "$exported" | grep -q '^fmb_system_residual$' && fail "the shared library exports engine internals (fmb_system_residual)"
echo "ok: installed into $T: $n_exported exported functions, all fmb_*; soname $abi"
# the docs, scenes and examples under share/flexmbd; the installed program runs an installed scene
share=$T/share/flexmbd
for f in README.md docs/tutorial.md docs/plugins.md scenes/paper/spinup_w4.yaml scenes/rotor_torque.csv \
         scenes/pendulum.ref.csv examples/plugin/CMakeLists.txt; do
  [ -f "$share/$f" ] || fail "share/flexmbd/$f not installed"
done
expect 0 "^flexmbd [0-9]+\.[0-9]+\.[0-9]+ \(commit [^,]+, plugin ABI $pmajor\.$pminor\)" "$T/bin/flexmbd" --version
expect 0 "stats: status=ok" "$T/bin/flexmbd" run "$share/scenes/rotor.yaml" -o "$work/rotor.csv" --set solver.t_end=0.05

# 2. each header alone (a program's needs no plugin table; a plugin's carries the program's too)
for h in flexmbd:FMB_SOVERSION flexmbd_plugin:FMB_PLUGIN_ABI; do
  echo "#include <${h%%:*}.h>
int main(void) { return ${h#*:} == 0; }" >"$work/hdr.c"
  cc -std=c11 -Wall -Wextra -Werror -pedantic -I"$T/include" -c "$work/hdr.c" -o "$work/hdr.o" ||
    fail "${h%%:*}.h does not compile alone as strict C11"
  if command -v g++ >/dev/null; then
    cp "$work/hdr.c" "$work/hdr.cpp"
    g++ -Wall -Wextra -Werror -I"$T/include" -c "$work/hdr.cpp" -o "$work/hdrpp.o" || fail "${h%%:*}.h does not compile as C++"
  fi
done
echo '#include <flexmbd.h>
int main(void) { fmbBodyType* t = 0; return t->abi; }' >"$work/opaque.c"
cc -std=c11 -I"$T/include" -c "$work/opaque.c" -o "$work/opaque.o" 2>/dev/null &&
  fail "flexmbd.h shows a type table's fields to programs (flexmbd_plugin.h's)"

# 3. the example out of the tree: CMake package, then pkg-config
ex=$work/example
mkdir -p "$ex"
cp "$src"/examples/plugin/*.c "$src"/examples/plugin/CMakeLists.txt "$src"/examples/plugin/*.yaml "$ex"/
(cmake -S "$ex" -B "$ex/build" -DCMAKE_PREFIX_PATH="$T" -DCMAKE_BUILD_TYPE=Release && cmake --build "$ex/build") \
  >"$work/cmake.log" 2>&1 || fail "examples/plugin does not build with find_package(flexmbd): $(tail -n 5 "$work/cmake.log")"
pc=$work/pkgconfig-build
mkdir -p "$pc"
export PKG_CONFIG_PATH="$libdir/pkgconfig"
mkdir -p "$pc/build"
cp "$ex/foundation.yaml" "$pc/" # its plugins: line names build/foundation.so beside it
cc -std=c11 -O2 -shared -fPIC "$ex/foundation.c" $(pkg-config --cflags --libs flexmbd) -lm -o "$pc/build/foundation.so" ||
  fail "the plugin does not build with pkg-config"
cc -std=c11 -O2 "$ex/check_foundation.c" $(pkg-config --cflags --libs flexmbd) -lm -o "$pc/check_foundation" ||
  fail "check_foundation does not build with pkg-config"
# static linking through pkg-config --static
cc -std=c11 -O2 "$ex/check_foundation.c" $(pkg-config --static --cflags --libs flexmbd) -o "$pc/check_foundation_static" ||
  fail "check_foundation does not link statically with pkg-config --static"

# 4. loading and using the plugin with the installed program
F=$T/bin/flexmbd
expect 0 'status=ok' "$F" run "$ex/foundation.yaml" -o "$work/plugins_list.csv"
grep -v '^plugins:' "$ex/foundation.yaml" >"$work/noplugins.yaml"
expect 0 'status=ok' "$F" run "$work/noplugins.yaml" --plugin "$pc/build/foundation.so" -o "$work/option.csv"
expect 2 "noplugins.yaml:[0-9]+:[0-9]+: error: .*foundation_bar" "$F" run "$work/noplugins.yaml" -o "$work/none.csv"
expect 0 "foundation_bar +\\($pc/build/foundation.so\\)" "$F" types --plugin "$pc/build/foundation.so"
expect 0 'N/m\^2 > 0, required' "$F" types --plugin "$pc/build/foundation.so"
expect 0 'ok   foundation_bar: 0 failed checks' "$F" conform --work "$work/conform" --plugin "$ex/build/foundation.so" foundation_bar
expect 0 'conform: 19 types, 0 failed checks' "$F" conform --work "$work/conform"
expect 0 'agrees with the analytic solution' "$ex/build/check_foundation" "$ex/foundation.yaml" "$work/check.csv"
expect 0 'agrees with the analytic solution' env LD_LIBRARY_PATH="$libdir" "$pc/check_foundation" "$pc/foundation.yaml" "$work/check_pc.csv"
cat "$work/out"
# the joint example (examples/joint_plugin: a torsional spring-damper) out of the tree, as a user
# copies it from the installed share/flexmbd/examples: built, conform, its check program against
# the damped oscillator, listed by types with its keys, drawn (its attachment) by view
# build_example NAME DIR: copy share/flexmbd/examples/NAME to DIR and build it with find_package(flexmbd)
build_example() {
  mkdir -p "$2"
  cp "$share/examples/$1"/*.c "$share/examples/$1/CMakeLists.txt" "$share/examples/$1"/*.yaml "$2"/
  (cmake -S "$2" -B "$2/build" -DCMAKE_PREFIX_PATH="$T" -DCMAKE_BUILD_TYPE=Release && cmake --build "$2/build") \
    >"$work/cmake_$1.log" 2>&1 || fail "examples/$1 does not build: $(tail -n 5 "$work/cmake_$1.log")"
}
jx=$work/joint_example
build_example joint_plugin "$jx"
expect 0 'ok   torsion_spring: 0 failed checks' "$F" conform --plugin "$jx/build/torsion.so" torsion_spring
expect 0 'agrees with the analytic solution' "$jx/build/check_torsion" "$jx/torsion.yaml" "$work/torsion.csv"
expect 0 'N m/rad >= 0, required' "$F" types --plugin "$jx/build/torsion.so"
"$F" run "$jx/torsion.yaml" -o "$work/torsion_draw.csv" --set solver.t_end=0.1 \
  --set 'outputs=[wheel.x, wheel.y, wheel.theta, spring.angle]' 2>/dev/null
expect 0 'wrote .*torsion.html \(11 rows, 1 of 1 bodies drawn' "$F" view "$work/torsion_draw.csv" "$jx/torsion.yaml" \
  -o "$work/torsion.html"
grep -q '"part":4,"points"' "$work/torsion.html" || fail "view: the torsion spring is not drawn as a force element"
# the spatial example (examples/plugin3d: a ball spring-damper for `dimension: 3` scenes) out of the
# tree the same way: built, conform in its spatial fixture, its check program against the 3D damped
# oscillator, refused in a planar scene at its `type:`
px=$work/plugin3d_example
build_example plugin3d "$px"
expect 0 'ok   ball_spring energy: a damped run loses energy' "$F" conform --plugin "$px/build/ball_spring.so" ball_spring
expect 0 'agrees with the analytic solution' "$px/build/check_ball_spring" "$px/ball_spring.yaml" "$work/ball_spring.csv"
printf 'plugins: [%s]\nsolver: {t_end: 1}\nbodies: [{name: a, type: rigid, mass: 1, inertia: 1}]\njoints: [{name: s, type: ball_spring, body1: ground, body2: a, stiffness: 1}]\n' \
  "$px/build/ball_spring.so" >"$work/ball_planar.yaml"
expect 2 'ball_planar.yaml:4:' "$F" check "$work/ball_planar.yaml"
# a scene naming a plugin that is not there: located error
printf 'plugins: [nowhere.so]\nsolver: {t_end: 1}\nbodies: [{name: a, type: rigid, mass: 1, inertia: 1}]\n' >"$work/missing.yaml"
expect 2 'missing.yaml:1:11: error: plugin .*nowhere.so: cannot load plugin' "$F" check "$work/missing.yaml"

# 4b. docs/plugins.md's tutorial, extracted verbatim (the blocks marked <!-- file: NAME -->), from an
# empty folder: CMake and pkg-config builds, its scene, conform
tut=$work/tutorial
mkdir -p "$tut"
awk -v dir="$tut" '
  /^<!-- file: .* -->$/ { name = $3; next }
  name != "" && /^```/ { if (out) { close(out); out = ""; name = "" } else out = dir "/" name; next }
  out { print > out }' "$src/docs/plugins.md"
for f in point_mass.c CMakeLists.txt throw.yaml; do [ -s "$tut/$f" ] || fail "docs/plugins.md: no block for $f"; done
(cmake -S "$tut" -B "$tut/build" -DCMAKE_PREFIX_PATH="$T" && cmake --build "$tut/build") >"$work/tut.log" 2>&1 ||
  fail "the tutorial does not build as written: $(tail -n 5 "$work/tut.log")"
expect 0 'status=ok' "$F" run "$tut/throw.yaml" -o "$work/throw.csv"
expect 0 'ok   point_mass: 0 failed checks' "$F" conform --work "$work/conform" --plugin "$tut/build/point_mass.so" point_mass
cc -std=c11 -O2 -shared -fPIC "$tut/point_mass.c" $(pkg-config --cflags --libs flexmbd) -o "$work/point_mass_pc.so" ||
  fail "the tutorial's pkg-config line"

# 5. broken plugins
for b in ABI ABI_MINOR OPS ENTRY NAME JACOBIAN MASS ENERGY PATTERN; do
  cc -std=c11 -shared -fPIC -DBREAK_$b "$src/tests/install/broken.c" $(pkg-config --cflags --libs flexmbd) -lm \
    -o "$work/broken_$b.so" 2>/dev/null || fail "broken.c does not build with BREAK_$b"
done
cc -std=c11 -shared -fPIC "$src/tests/install/broken.c" $(pkg-config --cflags --libs flexmbd) -lm -o "$work/unbroken.so"
expect 0 'ok   oscillator: 0 failed checks' "$F" conform --work "$work/conform" --plugin "$work/unbroken.so" oscillator
expect 2 "broken_ABI.so: error: plugin was built for flexmbd plugin ABI $((pmajor + 1))\.0; this flexmbd [0-9.]+ has plugin ABI $pmajor\.$pminor: rebuild it" \
  "$F" conform --plugin "$work/broken_ABI.so"
expect 2 "broken_ABI_MINOR.so: error: plugin was built for flexmbd plugin ABI $pmajor\.$((pminor + 1)); this flexmbd [0-9.]+ has plugin ABI $pmajor\.$pminor: it needs a newer flexmbd" \
  "$F" conform --plugin "$work/broken_ABI_MINOR.so"
expect 2 "broken_OPS.so: error: body type 'oscillator' has no residual op \\(required\\)" \
  "$F" run "$ex/foundation.yaml" --plugin "$work/broken_OPS.so"
expect 2 "broken_ENTRY.so: error: not a flexmbd plugin: it has no symbol fmb_plugin_descriptor" \
  "$F" types --plugin "$work/broken_ENTRY.so"
expect 1 'FAIL oscillator jacobian: analytic vs central differences: K 1, C 0, M 0' \
  "$F" conform --work "$work/conform" --plugin "$work/broken_JACOBIAN.so" oscillator
expect 1 'FAIL oscillator pattern: largest difference outside the declared pattern: 0.09' \
  "$F" conform --work "$work/conform" --plugin "$work/broken_PATTERN.so" oscillator
expect 1 'FAIL oscillator mass: M symmetric' "$F" conform --work "$work/conform" --plugin "$work/broken_MASS.so" oscillator
expect 1 'FAIL oscillator energy: a free run keeps the total energy' \
  "$F" conform --work "$work/conform" --plugin "$work/broken_ENERGY.so" oscillator
expect 2 "broken_NAME.so: error: body type 'rigid' is already registered \\(from built-in\\)" \
  "$F" types --plugin "$work/broken_NAME.so"
expect 0 'oscillator' "$F" types --plugin "$work/unbroken.so" --plugin "$work/unbroken.so" # the same file twice: a no-op
# conform's spatial fixture catches a wrong derivative too: examples/plugin3d's ball_spring with
# body1's columns of dd/dq left unnegated (its force is then not -dV/dq)
sed 's/D\[i \* ld + c\] = -D\[i \* ld + c\]/D[i * ld + c] = D[i * ld + c]/' "$px/ball_spring.c" >"$work/ball_broken.c"
grep -q 'D\[i \* ld + c\] = D\[i \* ld + c\]' "$work/ball_broken.c" || fail "ball_broken.c: the sign to break is not in ball_spring.c"
cc -std=c11 -shared -fPIC "$work/ball_broken.c" $(pkg-config --cflags --libs flexmbd) -lm -o "$work/ball_broken.so" ||
  fail "ball_broken.c does not build"
expect 1 'FAIL ball_spring force: generalized force vs -dV/dq' \
  "$F" conform --work "$work/conform" --plugin "$work/ball_broken.so" ball_spring

# 6. relocatable: the prefix moved, pkg-config still points into it
mv "$T" "$work/moved"
mlib=$work/moved/${libdir#"$T"/}
PKG_CONFIG_PATH="$mlib/pkgconfig" cc -std=c11 "$ex/check_foundation.c" \
  $(PKG_CONFIG_PATH="$mlib/pkgconfig" pkg-config --cflags --libs flexmbd) -lm -o "$work/moved_check" ||
  fail "pkg-config after moving the prefix"
expect 0 'agrees with the analytic solution' env LD_LIBRARY_PATH="$mlib" "$work/moved_check" "$pc/foundation.yaml" "$work/moved.csv"

echo "install: $fails failures"
[ "$fails" -eq 0 ]
