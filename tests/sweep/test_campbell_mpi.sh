#!/bin/sh
# `flexmbd campbell` under mpirun (tools/farm.c: rank 0 hands the speeds out, gathers the modes,
# follows them and alone writes; docs/analysis.md, docs/sweep.md):
#  1. -np 2 and -np 3 (oversubscribed; -j 1 and -j 2 children per rank) give the CSV of -j 1
#     without MPI, byte for byte (dense eigen-solver);
#  2. the run under mpirun itself against the rotating-beam continuum: the first in-plane
#     frequency sqrt(mu_f1^2 - lambda^2) sqrt(EI / (rho A L^4)) at lambda = 0, 1, 2, 4, 8, 12
#     (mu_f1 from tests/analysis/test_modes_rotating.c), within 5e-4;
#  3. a speed whose computation segfaults (the test plugin faulty.so): exit 3, a message naming
#     that speed and the signal, the speeds before it written, no process of the job left;
#  4. SIGTERM to mpirun while a child of every rank hangs: the speeds were shared (a child on
#     each rank), and no child is left running.
#   usage: test_campbell_mpi.sh FLEXMBD SOURCE_DIR WORKDIR FAULTY_PLUGIN MPIRUN|none
. "$(dirname "$0")/lib.sh"
MPIRUN=$5
if [ "$MPIRUN" = none ] || ! command -v "$MPIRUN" > /dev/null 2>&1; then
  echo "SKIP: no mpirun (Debian's openmpi-bin) or flexmbd built without MPI: campbell under MPI not tested"
  exit 77
fi
export OMPI_ALLOW_RUN_AS_ROOT=1 OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1
MPI="$MPIRUN --oversubscribe --bind-to none"
left() { # the processes of a run, found by the output file only it names
  pgrep -f -- "-o $1" || true
}

# 1. byte for byte
S="$SRC/scenes/campbell_beam.yaml --speed joints.spin.speed --speeds 0:30:16 --count 3 --eigen dense"
# shellcheck disable=SC2086
"$F" campbell $S -o "$D/serial.csv" 2> "$D/serial.err" || { cat "$D/serial.err"; fail "campbell -j 1"; }
for np_j in 2:1 3:1 3:2; do
  np=${np_j%:*}
  j=${np_j#*:}
  # shellcheck disable=SC2086
  $MPI -np "$np" "$F" campbell $S -j "$j" -o "$D/np$np.j$j.csv" > "$D/np$np.j$j.out" 2>&1 ||
    { cat "$D/np$np.j$j.out"; fail "mpirun -np $np campbell -j $j failed"; }
  cmp -s "$D/serial.csv" "$D/np$np.j$j.csv" ||
    { diff "$D/serial.csv" "$D/np$np.j$j.csv" | head; fail "mpirun -np $np -j $j: another CSV than -j 1"; }
  [ "$(grep -c '^stats: status=ok speeds=16 of 16' "$D/np$np.j$j.out")" = 1 ] ||
    { cat "$D/np$np.j$j.out"; fail "-np $np: one stats line (rank 0's) expected"; }
  [ -f "$D/np$np.j$j.png" ] || ! command -v gnuplot > /dev/null || fail "-np $np: no plot beside the CSV"
done

# 2. against the continuum: speeds lambda * sqrt(EI / (rho A L^4)) of the scene's beam
scale=$(awk 'BEGIN { printf "%.17g", sqrt(68.95e9 * 1.302e-10 / (2767.0 * 2.5e-4 * 1.8 ^ 4)) }')
speeds=$(awk -v s="$scale" 'BEGIN { split("0 1 2 4 8 12", l, " "); for (i = 1; i <= 6; ++i) printf "%s%.17g", (i > 1 ? "," : ""), l[i] * s }')
$MPI -np 3 "$F" campbell "$SRC/scenes/campbell_beam.yaml" --speed joints.spin.speed --speeds "$speeds" --count 2 \
  --eigen dense -o "$D/continuum.csv" > "$D/continuum.out" 2>&1 || { cat "$D/continuum.out"; fail "mpirun -np 3 (continuum)"; }
awk -F, -v s="$scale" 'BEGIN { split("1.8751040687 3.681646814 4.137319573 5.585001421 9.256837601 13.17015049", m, " ");
    split("0 1 2 4 8 12", l, " "); m[1] = m[1] * m[1] }
  NR > 1 { i = NR - 1; exact = sqrt(m[i] * m[i] - l[i] * l[i]) * s; e = $2 / exact - 1; if (e < 0) e = -e;
    printf "speed %.6g: mode1 %.7f, continuum %.7f, error %.2e\n", $1, $2, exact, e; if (e > 5e-4) bad = 1; n++ }
  END { exit bad || n != 6 }' "$D/continuum.csv" || fail "mpirun -np 3: the first frequency is not the continuum's"

# 3. a segfault at the third of six speeds
rc=0
$MPI -np 3 "$F" campbell "$SRC/tests/sweep/faulty_campbell.yaml" --plugin "$PLUGIN" --speed bodies.f.fault \
  --speeds 0,0,1,0,0,0 --count 2 -o "$D/crash.csv" > "$D/crash.out" 2>&1 || rc=$?
[ "$rc" = 3 ] || { cat "$D/crash.out"; fail "a crash at one speed under mpirun: exit $rc, 3 expected"; }
grep -q "no modes at speed 1 (speed 3 of 6)" "$D/crash.out" && grep -q "signal 11" "$D/crash.out" ||
  { cat "$D/crash.out"; fail "the message does not name the speed and the signal"; }
[ "$(tail -n +2 "$D/crash.csv" | wc -l)" = 2 ] || fail "the two speeds before the crash are not written"
[ -z "$(left "$D/crash.csv")" ] || fail "processes of the crashed job left running"

# 4. SIGTERM while every rank's child hangs (fault 3)
$MPI -np 2 "$F" campbell "$SRC/tests/sweep/faulty_campbell.yaml" --plugin "$PLUGIN" --speed bodies.f.fault \
  --speeds 3,3,3,3 --count 2 -o "$D/hang.csv" > "$D/hang.out" 2>&1 &
pid=$!
n=0
for _ in $(seq 100); do # two children at once with -j 1: one on each rank (MPI start-up takes ~0.5 s)
  n=$(pgrep -f -- "-o $D/hang.csv .*--modes-out" | wc -l)
  [ "$n" -ge 2 ] && break
  sleep 0.1
done
[ "$n" -ge 2 ] || { kill -TERM $pid; cat "$D/hang.out"; fail "the hanging speeds did not start on both ranks ($n children)"; }
kill -TERM $pid
rc=0
wait $pid || rc=$?
sleep 1
lst=$(left "$D/hang.csv")
[ -z "$lst" ] || { ps -o pid,ppid,pgid,args -p "$(echo $lst | tr ' ' ',')"; fail "processes left running after SIGTERM to mpirun"; }
# (which rank's MPI_Abort ends the job first is a race: rank 0's message may not get out)
[ "$rc" != 0 ] || { cat "$D/hang.out"; fail "SIGTERM to mpirun: exit 0"; }
echo "test_campbell_mpi: ok"
