#!/bin/sh
# code_from_data.sh FLEXMBD SOURCE_DIR WORK_DIR — data never reaches a shell (issue 27): gnuplot
# runs `backquotes` in double-quoted strings, so a CSV column, a file name or a scene name holding
# one once ran a command through `plot` and `campbell`. The numbers now go to gnuplot as a data
# file and every string single-quoted (a title with a line break is refused): no command runs,
# and the plot is still made. POSIX sh.
set -u
. "$(dirname "$0")/../file_test_lib.sh" "$@"
command -v gnuplot >/dev/null 2>&1 || {
  echo "SKIP: no gnuplot"
  exit 77
}
cd "$work" || exit 1
# a column named `touch PWNED1` (and one with a quote)
printf 't,`touch PWNED1`,it'"'"'s\n0,1,2\n1,2,3\n' >evil.csv
"$bin" plot evil.csv -o evil.png 2>err.txt || fail "plot of a column with backquotes" "exit $?: $(tail -n 1 err.txt)"
[ -s evil.png ] || fail "plot of a column with backquotes" "no figure"
# a file named with backquotes and a quote
cp evil.csv "q'\`touch PWNED2\`.csv"
"$bin" plot "q'\`touch PWNED2\`.csv" -o q.png 2>err.txt || fail "plot of a file named with backquotes" "exit $?"
[ -s q.png ] || fail "plot of a file named with backquotes" "no figure"
# a title and labels with backquotes
"$bin" plot evil.csv -o t.png --title '`touch PWNED3`' --xlabel '`touch PWNED4`' 2>err.txt ||
  fail "plot with a title in backquotes" "exit $?"
# campbell: the scene's name is the plot's title
cp "$src/scenes/campbell_beam.yaml" "c\`touch PWNED5\`.yaml"
"$bin" campbell "c\`touch PWNED5\`.yaml" --speed joints.spin.speed --speeds 0:2:2 --count 1 -o c.csv 2>err.txt ||
  fail "campbell on a scene named with backquotes" "exit $?: $(tail -n 1 err.txt)"
[ -s c.png ] || fail "campbell on a scene named with backquotes" "no figure"
# a line break: in a file name it never reaches gnuplot (the data go as a file of numbers); in a
# title it is refused, not passed on
printf 't,a\n0,1\n1,2\n' >"nl
!touch PWNED6
.csv"
"$bin" plot "nl
!touch PWNED6
.csv" -o nl.png 2>err.txt || fail "plot of a file named with a line break" "exit $?: $(tail -n 1 err.txt)"
"$bin" plot evil.csv -o nl2.png --title "a
!touch PWNED7" 2>err.txt
[ $? = 2 ] || fail "plot with a line break in the title" "not refused"
grep -q "control character" err.txt || fail "plot with a line break in the title" "$(tail -n 1 err.txt)"
for k in 1 2 3 4 5 6 7; do
  [ -e "PWNED$k" ] && fail "code from data" "PWNED$k was created: a command ran"
done
file_test_done code_from_data
