#!/bin/sh
# Every scene the project ships (scenes/**/*.yaml) has a regression reference beside it.
#   usage: every_scene_has_reference.sh SCENES_DIR
set -eu
missing=0
for s in $(find "$1" -name '*.yaml' | sort); do
  r="${s%.yaml}.ref.csv"
  if [ ! -f "$r" ]; then
    echo "no reference for $s: make it with 'flexmbd regress --bless $s' and commit $r" >&2
    missing=$((missing + 1))
  fi
done
n=$(find "$1" -name '*.yaml' | wc -l)
[ "$n" -gt 0 ] || { echo "no scene under $1" >&2; exit 1; }
[ "$missing" -eq 0 ] || exit 1
echo "every scene has a reference: $n scenes"
