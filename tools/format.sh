#!/usr/bin/env bash
# format.sh — the tree's C files through clang-format-14 with the committed .clang-format.
#   tools/format.sh [FILE...]    reformat in place (default: every tracked *.c and *.h)
#   tools/format.sh --check      change nothing: per file, the lines clang-format would change,
#                                then the total; exit 1 when any would change, 0 when none
# clang-format-14 is Debian 12's (tools/install_deps.sh --ci installs it); another version may
# lay the same code out differently, so the script insists on this one.
set -euo pipefail
cd "$(dirname "$0")/.."
CF=${CLANG_FORMAT:-clang-format-14}
command -v "$CF" >/dev/null || { echo "format.sh: $CF not found (apt-get install clang-format-14)" >&2; exit 2; }
check=0
if [ "${1:-}" = "--check" ]; then check=1; shift; fi
files=()
for f in "$@"; do # C sources only: clang-format would mangle a shell script given by mistake
  case "$f" in
    *.c | *.h) files+=("$f") ;;
    *) echo "format.sh: $f left alone (not a .c or .h file)" >&2 ;;
  esac
done
if [ $# -eq 0 ]; then mapfile -t files < <(git ls-files '*.c' '*.h'); fi
[ ${#files[@]} -gt 0 ] || exit 0
if [ $check -eq 0 ]; then
  "$CF" -i --style=file "${files[@]}"
  exit 0
fi
total=0
changed=0
for f in "${files[@]}"; do
  n=$("$CF" --style=file "$f" | diff "$f" - | grep -c '^<' || true)
  if [ "$n" -gt 0 ]; then
    printf '%6d %s\n' "$n" "$f"
    total=$((total + n))
    changed=$((changed + 1))
  fi
done
echo "format: $total lines in $changed of ${#files[@]} files would change"
[ $total -eq 0 ]
