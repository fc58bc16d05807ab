#!/bin/sh
# `flexmbd sweep` under mpirun (docs/sweep.md, "On a cluster"):
#  1. rank-count independence: a random design run with -np 1, 2 and 4 (oversubscribed) and
#     different -j gives the same table sorted by index, but timings (wall_s, rank, cpu_s), and
#     rows from more than one rank; so do worker ranks with persistent runners (--runner serve);
#  2. SIGTERM to mpirun while every rank's children hang: no child is left running;
#  3. rank 0 failing before it hands anything out (no memory for its list, injected): every rank
#     ends, with a non-zero exit, instead of the workers waiting forever.
#   usage: test_mpi.sh FLEXMBD SOURCE_DIR WORKDIR FAULTY_PLUGIN MPIRUN
. "$(dirname "$0")/lib.sh"
MPIRUN=$5
export OMPI_ALLOW_RUN_AS_ROOT=1 OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1
MPI="$MPIRUN --oversubscribe --bind-to none"

SPEC="$SRC/scenes/fourbar.yaml --quiet --set solver.t_end=1 --random bodies.crank.mass=uniform(0.5,2)
  --random solver.rtol=lognormal(-16,1) --count 24 --seed 2026 --metric crank.theta:max"
for np_j in 1:1 2:1 4:1 2:2; do
  np=${np_j%:*}
  j=${np_j#*:}
  # shellcheck disable=SC2086
  $MPI -np "$np" "$F" sweep $SPEC -o "$D/np$np.j$j" -j "$j" > "$D/np$np.j$j.out" 2>&1 ||
    { cat "$D/np$np.j$j.out"; fail "mpirun -np $np -j $j failed"; }
  # index,run_id,attempt,status,exit_code,signal | the paths and stats but cpu_s | metrics, message
  cut -d, -f1-6,9-18,20- "$D/np$np.j$j/table.csv" > "$D/np$np.j$j.table"
  [ "$(tail -n +2 "$D/np$np.j$j.table" | wc -l)" = 24 ] || fail "-np $np: 24 rows expected"
  cmp -s "$D/np1.j1.table" "$D/np$np.j$j.table" || { diff "$D/np1.j1.table" "$D/np$np.j$j.table" | head; fail "-np $np -j $j: another table than -np 1"; }
done
# the worker ranks with persistent runners (--runner serve): the same table
# shellcheck disable=SC2086
$MPI -np 3 "$F" sweep $SPEC -o "$D/serve" -j 1 --runner serve > "$D/serve.out" 2>&1 ||
  { cat "$D/serve.out"; fail "mpirun -np 3 --runner serve failed"; }
cut -d, -f1-6,9-18,20- "$D/serve/table.csv" | cmp -s "$D/np1.j1.table" - || fail "--runner serve under mpirun: another table"
awk -F, 'NR > 1 && $4 != "ok" { exit 1 }' "$D/np1.j1/table.csv" || fail "a run that is not ok"
ranks=$(tail -n +2 "$D/np4.j1/table.csv" | cut -d, -f8 | sort -u | wc -l)
[ "$ranks" -ge 2 ] || fail "-np 4: every row from one rank ($ranks ranks worked)"

# 2. SIGTERM to mpirun: the hanging children of every rank die with it
# shellcheck disable=SC2086
$MPI -np 2 "$F" sweep "$SRC/tests/sweep/faulty.yaml" --plugin "$PLUGIN" -o "$D/term" --quiet -j 1 --timeout 600 \
  --grid bodies.f.fault=3 --grid solver.t_end=0.1,0.2,0.3,0.4 > "$D/term.out" 2>&1 &
pid=$!
n=0
for _ in $(seq 100); do # until both ranks have a child (MPI start-up takes ~0.5 s)
  n=$(pgrep -f -- "-o $D/term/series" | wc -l)
  [ "$n" -ge 2 ] && break
  sleep 0.1
done
[ "$n" -ge 2 ] || { cat "$D/term.out"; fail "the hanging runs did not start on both ranks ($n children)"; }
kill -TERM $pid
wait $pid || true
sleep 1
left=$(pgrep -f -- "-o $D/term/series" || true)
[ -z "$left" ] || { ps -o pid,ppid,pgid,args -p "$(echo $left | tr ' ' ',')"; fail "children left running after SIGTERM to mpirun"; }

# 3. rank 0 cannot make its list of runs: the job ends (timeout 60 s: a hang fails the test)
# shellcheck disable=SC2086
rc=0
timeout 60 $MPI -np 3 -x FMB_TEST_SWEEP_NO_MEMORY=1 "$F" sweep $SPEC -o "$D/nomem" -j 1 > "$D/nomem.out" 2>&1 || rc=$?
[ "$rc" != 124 ] || { cat "$D/nomem.out"; fail "rank 0 failed early and the job hung"; }
[ "$rc" != 0 ] || fail "rank 0 failed early and the job exited 0"
echo "test_mpi: ok"
