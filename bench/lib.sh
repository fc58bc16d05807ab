# bench/lib.sh — helpers the bench scripts share (sourced, not run).
#   median                  the median of the numbers on stdin, one per line
#   stat_field NAME         the value of NAME=... in the stats line(s) on stdin (the last one)
#   build_landed COMMIT DIR build COMMIT of the repository (git archive, so the worktree list is
#                           untouched) into DIR/build/flexmbd, once: reused when it is there
median() { sort -g | awk '{a[NR]=$1} END {print (NR % 2) ? a[(NR+1)/2] : (a[NR/2] + a[NR/2+1]) / 2}'; }
stat_field() { sed -n "s/.*[ :]$1=\([^ ]*\).*/\1/p" | tail -1; }
# tip_err REF RUN [COLUMN]: max |COLUMN(run) - COLUMN(ref)| (default beam.tip_v) over the rows both
# have (two runs of one scene at the same output_step)
tip_err() {
  awk -F, -v col="${3:-beam.tip_v}" 'FNR == 1 { for (i = 1; i <= NF; ++i) if ($i == col) c = i; next }
    NR == FNR { ref[FNR] = $c; next }
    (FNR in ref) { d = $c - ref[FNR]; if (d < 0) d = -d; if (d > m) m = d }
    END { printf "%.3g", m }' "$1" "$2"
}
build_landed() {
  local commit=$1 dir=$2 root
  root=$(git rev-parse --show-toplevel)
  [ -x "$dir/build/flexmbd" ] && return 0
  echo "building $commit in $dir ..." >&2
  mkdir -p "$dir"
  git -C "$root" archive "$commit" | tar -x -C "$dir"
  cmake -S "$dir" -B "$dir/build" -DCMAKE_BUILD_TYPE=Release >/dev/null
  cmake --build "$dir/build" -j2 --target flexmbd >/dev/null
}
