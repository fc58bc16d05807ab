#!/bin/sh
# embed.sh SOURCE_DIR BUILD_DIR WORK_DIR — examples/embed/ as a user outside the tree has it
# (issue 24): `cmake --install` into a temporary prefix, the example copied out of the tree and
# built with find_package(flexmbd) and again with pkg-config, then run: a PD controller stepping a
# flexible rotor through fmb_set_input/fmb_advance must agree with the same law as a spring-damper
# scene (pd_rotor.c says how: first order in the control step, Richardson to 1e-1 of it).
. "$(dirname "$0")/prefix.sh"
ex=$work/embed
mkdir -p "$ex"
cp "$src"/examples/embed/*.c "$src"/examples/embed/*.yaml "$src"/examples/embed/CMakeLists.txt "$ex"/
(cmake -S "$ex" -B "$ex/build" -DCMAKE_PREFIX_PATH="$T" -DCMAKE_BUILD_TYPE=Release && cmake --build "$ex/build") \
  >"$work/cmake.log" 2>&1 || { echo "FAIL: examples/embed does not build with find_package(flexmbd): $(tail -n 5 "$work/cmake.log")" >&2; exit 1; }
PKG_CONFIG_PATH="$libdir/pkgconfig" cc -std=c11 -O2 "$ex/pd_rotor.c" \
  $(PKG_CONFIG_PATH="$libdir/pkgconfig" pkg-config --cflags --libs flexmbd) -lm -o "$work/pd_rotor_pc" ||
  { echo "FAIL: examples/embed does not build with pkg-config" >&2; exit 1; }
cd "$ex" || exit 1
"$ex/build/pd_rotor" rotor_motor.yaml rotor_spring.yaml
