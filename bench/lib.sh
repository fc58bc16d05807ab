# bench/lib.sh — helpers the bench scripts share (sourced, not run).
#   median                  the median of the numbers on stdin, one per line
#   stat_field NAME         the value of NAME=... in the stats line(s) on stdin (the last one)
median() { sort -g | awk '{a[NR]=$1} END {print (NR % 2) ? a[(NR+1)/2] : (a[NR/2] + a[NR/2+1]) / 2}'; }
stat_field() { sed -n "s/.*[ :]$1=\([^ ]*\).*/\1/p" | tail -1; }
