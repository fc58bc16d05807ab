# prefix.sh — sourced by run.sh and embed.sh (. prefix.sh SOURCE_DIR BUILD_DIR WORK_DIR): a fresh
# WORK_DIR and the build installed into it with `cmake --install`, as a user has it: $src, $build,
# $work, the prefix $T and its library folder $libdir.
set -u
src=$1
build=$2
work=$3
rm -rf "$work"
mkdir -p "$work" || exit 1
T=$work/prefix
cmake --install "$build" --prefix "$T" >/dev/null || { echo "FAIL: cmake --install" >&2; exit 1; }
libdir=$(ls -d "$T"/lib*/ | head -n 1)
libdir=${libdir%/}
