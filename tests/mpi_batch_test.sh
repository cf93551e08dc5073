#!/usr/bin/env bash
# ctest mpi_batch: `mpirun -np K phiq batch` (tools/cli/batch_ranks.hpp) on this machine's loopback, against the
# same command in one process:
#   1. 2 and 3 ranks (oversubscribed on 2 cores): the CSV and the HDF5 file are those of one process, byte for byte;
#   2. a case that cannot run (case 37: a crank longer than its rod): left out and named once, exit 1, same file;
#   3. rank 1 killed mid-run: rank 0 publishes the whole cases before the first unfinished one, in order, and names
#      the missing ones, exit non-zero; `--resume` on 2 ranks then completes the file, byte for byte the one of an
#      uninterrupted single process;
#   5. rank 1 out of memory (`ulimit -v` on that rank): one line from rank 0 naming the rank and the case, exit 1.
# Open MPI refuses to run as root unless told: the two variables are set here, for these runs only.
# Skipped (exit 77) when mpirun is absent or phiq was built without MPI.
# Usage: mpi_batch_test.sh PHIQ MODELS_DIR SCRATCH HAS_MPI
set -uo pipefail
phiq="$1"; models="$2"; dir="$3"; has_mpi="$4"
command -v mpirun >/dev/null || { echo "mpi_batch: no mpirun (tools/install_deps.sh installs openmpi-bin)"; exit 77; }
case "$has_mpi" in 1|ON|TRUE|true) ;; *) echo "mpi_batch: phiq built without MPI"; exit 77 ;; esac
export OMPI_ALLOW_RUN_AS_ROOT=1 OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1
export OMPI_MCA_rmaps_base_oversubscribe=1            # 3 ranks on 2 cores
export OMPI_MCA_btl=self,vader                         # this machine only: shared memory, no network
export OMPI_MCA_btl_vader_single_copy_mechanism=none   # containers forbid the cross-process copy (ptrace)
# Under AddressSanitizer, LeakSanitizer would report what MPI_Init keeps past MPI_Finalize, in frames of Open MPI's
# plugins it cannot name (so no suppression matches them): leaks are not looked for in these runs. phiq's own batch
# code is leak-checked in one process by test_cli_batch_file.cpp and test_cli_batch_resume.cpp.
export ASAN_OPTIONS="${ASAN_OPTIONS:+$ASAN_OPTIONS:}detect_leaks=0"
# a machine where mpirun cannot start two processes at all (no shared memory, a container without its launcher's
# needs) is no test of phiq: skipped, with mpirun's reason
if ! out=$(mpirun -np 2 true 2>&1); then
  echo "mpi_batch: mpirun cannot start 2 processes here: $(printf '%s' "$out" | grep -v '^-*$' | head -3 | tr '\n' ' ')"
  exit 77
fi
rm -rf "$dir" && mkdir -p "$dir" && cd "$dir" || exit 1
status=0
fail() { echo "mpi_batch: $*" >&2; status=1; }

sed 's/steps: 180/steps: 90/' "$models/seed/crank_slider_mixed.yaml" > cs.yaml
awk 'BEGIN { print "L2"; for (k = 0; k < 120; ++k) printf "%.6f\n", (k == 37 ? 5.0 : 0.2 + 1e-3 * k) }' > cases.csv
awk 'NR != 39' cases.csv > good.csv   # the same cases without case 37

# 1. the same bytes on 1, 2 and 3 ranks
for ext in csv h5; do
  "$phiq" batch -q cs.yaml good.csv -o "one.$ext" --threads 2 || fail "one process, $ext: exit $?"
  for np in 2 3; do
    mpirun -np $np "$phiq" batch -q cs.yaml good.csv -o "np$np.$ext" --threads 1 2>"np$np.$ext.err" ||
      fail "$np ranks, $ext: exit $? ($(grep '^phiq' "np$np.$ext.err"))"
    cmp -s "one.$ext" "np$np.$ext" || fail "$np ranks: np$np.$ext differs from one process's one.$ext"
  done
done
[ "$(wc -l < one.csv)" -eq $((119 * 91 + 1)) ] || fail "one.csv: $(wc -l < one.csv) lines, not 119 cases of 91 rows"

# 2. a failing case: named once (by rank 0), left out, exit 1; the file the one process writes
"$phiq" batch -q cs.yaml cases.csv -o fail1.csv --threads 2 2>fail1.err; code1=$?
mpirun -np 3 "$phiq" batch -q cs.yaml cases.csv -o fail3.csv --threads 1 --summary fail3.json 2>fail3.err; code3=$?
[ "$code1" -eq 1 ] && [ "$code3" -eq 1 ] || fail "a failing case: exit $code1 (one process), $code3 (3 ranks), not 1"
[ "$(grep -c '^phiq: cs.yaml: case 37: .*left out of fail3.csv$' fail3.err)" -eq 1 ] ||
  fail "case 37 not named exactly once: $(grep '^phiq' fail3.err)"
[ "$(grep -c '^phiq' fail3.err)" -eq 1 ] || fail "3 ranks: more than rank 0's one line: $(grep '^phiq' fail3.err)"
cmp -s fail1.csv fail3.csv || fail "a failing case: fail3.csv differs from one process's fail1.csv"
awk -F, 'NR > 1 { seen[$1] = 1 } END { n = 0; for (c in seen) ++n; exit !(n == 119 && !(37 in seen)) }' fail3.csv ||
  fail "a failing case: fail3.csv does not hold the other 119 cases"
grep -q '"ranks": 3,' fail3.json && grep -q '"failed": 1,' fail3.json || fail "fail3.json: not 3 ranks and 1 failure"

# 4. (before the long run) phiq tolerance: the Monte Carlo samples over the ranks, the same CSV and summary but
#    for its timings and thread count; samples that fail (a wide tolerance reaches dead points) named once
m="$models/seed/crank_slider_mixed.yaml"
"$phiq" tolerance "$m" --sd L2=0.05 --sd L3=0.3 --samples 200 -q -o tol1.csv --summary tol1.json --threads 2 2>tol1.err ||
  fail "tolerance, one process: exit $?"
for np in 2 3; do
  mpirun -np $np "$phiq" tolerance "$m" --sd L2=0.05 --sd L3=0.3 --samples 200 -q -o "tol$np.csv" \
    --summary "tol$np.json" --threads 1 2>"tol$np.err" || fail "tolerance, $np ranks: exit $?"
  cmp -s tol1.csv "tol$np.csv" || fail "tolerance, $np ranks: tol$np.csv differs from one process's tol1.csv"
  diff <(grep -v -e '"seconds"' -e '"threads"' tol1.json) <(grep -v -e '"seconds"' -e '"threads"' "tol$np.json") >/dev/null ||
    fail "tolerance, $np ranks: the summary differs from one process's beyond its timings and threads"
  [ "$(grep -c '^phiq' "tol$np.err")" -eq "$(grep -c '^phiq' tol1.err)" ] ||
    fail "tolerance, $np ranks: $(grep -c '^phiq' "tol$np.err") lines, one process $(grep -c '^phiq' tol1.err)"
done
grep -q '"failed": \[$' tol1.json && [ "$(grep -c '^phiq: .*: case [0-9]* (L2 = ' tol1.err)" -ge 1 ] ||
  fail "tolerance: no sample failed (the test needs some)"

# 5. (before the long run) rank 1 alone out of memory, in an address space of 290 000 KB (Open MPI starts in
#    250 000, and a case of 120 000 steps outgrows it while it runs) and of 380 000 KB (the case runs, and its result's
#    message to rank 0 outgrows it): rank 0 names the rank and the case in one line, exit 1, no file. Rank 1 takes
#    case 0 or 1, whichever it asks for first.
#    Before, the std::bad_alloc went to rank 1's silenced standard error and rank 0 waited for its worker for ever:
#    `timeout` turns a wait into a failure.
sed 's/steps: 180/steps: 120000/' "$models/seed/crank_slider_mixed.yaml" > oom.yaml
printf 'L2\n0.3\n0.31\n' > oom.csv
for limit in 290000 380000; do
  printf '%s\n' "[ \"\$OMPI_COMM_WORLD_RANK\" = 1 ] && ulimit -v $limit" 'exec "$@"' > rank1_limited.sh
  timeout -s KILL 60 mpirun -np 2 sh rank1_limited.sh "$phiq" batch -q oom.yaml oom.csv -o oom_out.csv --threads 1 \
    2>oom.err; code=$?
  [ "$code" -eq 1 ] || fail "rank 1 out of memory ($limit KB): exit $code, not 1 ($(tail -n 3 oom.err | tr "\n" " "))"
  [ "$(grep -c '^phiq' oom.err)" -eq 1 ] && grep -Eq '^phiq: oom\.yaml: out of memory after [01] of 2 cases on MPI rank 1 in case [01] \(fewer --threads\); no output written$' oom.err ||
    fail "rank 1 out of memory ($limit KB): not the one line naming rank 1 and its case: $(grep '^phiq' oom.err)"
  [ ! -e oom_out.csv ] || fail "rank 1 out of memory ($limit KB): oom_out.csv written"
done

# 3. rank 1 killed: the committed cases published, the missing named; --resume completes the same file
sed 's/steps: 180/steps: 2000/' "$models/seed/crank_slider_mixed.yaml" > long.yaml
awk 'BEGIN { print "L2"; for (k = 0; k < 1500; ++k) printf "%.6f\n", 0.2 + 1e-5 * k }' > long.csv
mpirun -np 2 "$phiq" batch -q long.yaml long.csv -o big.csv --threads 1 --summary kill.json 2>kill.err &
runner=$!
rank1=""
for _ in $(seq 100); do  # rank 1's process, by the rank Open MPI gives it in its environment
  for p in $(pgrep -x phiq); do  # this test's own (its folder): another checkout's mpi_batch may run beside it
    [ "$(readlink "/proc/$p/cwd")" = "$(pwd -P)" ] || continue
    tr '\0' '\n' 2>/dev/null < "/proc/$p/environ" | grep -qx 'OMPI_COMM_WORLD_RANK=1' && rank1=$p
  done
  [ -n "$rank1" ] && break
  sleep 0.1
done
sleep 1
[ -n "$rank1" ] && kill -KILL "$rank1" || fail "rank 1 not found (or gone) to be killed"
wait $runner; code=$?
[ "$code" -ne 0 ] || fail "a killed rank: exit 0"
line=$(grep '^phiq: ' kill.err)
kept=0
if [ -f big.csv ]; then
  written=$(printf '%s\n' "$line" | sed -n 's/.*); \([0-9]*\) of 1500 cases written to big.csv (the cases before the first unfinished one); cases \([0-9]*\) to 1499 missing: the same command with --resume runs only those$/\1 \2/p')
  kept=${written%% *}
  [ -n "$written" ] && [ "$kept" = "${written##* }" ] || fail "a killed rank: not the cases written and missing: $line"
  # whole cases, in order: case k is rows 2001 k + 2 … 2001 (k + 1) + 1
  awk -F, -v k="${kept:-x}" 'NR > 1 { c = int((NR - 2) / 2001); if ($1 != c) { print "row " NR ": case " $1 ", not " c; exit 1 } }
       END { if (NR != 2001 * k + 1) { print NR " lines for " k " cases"; exit 1 } }' big.csv || fail "big.csv: not whole cases in order"
  grep -q '"interrupted": "SIGTERM",' kill.json && [ "$(grep -c '"status": "missing"' kill.json)" -eq $((1500 - kept)) ] ||
    fail "kill.json: not interrupted by SIGTERM with $((1500 - kept)) cases missing"
else
  printf '%s\n' "$line" | grep -q 'interrupted (SIGTERM); no output written$' || fail "a killed rank, no file: $line"
fi
mpirun -np 2 "$phiq" batch -q long.yaml long.csv -o big.csv --threads 1 --resume --summary resume.json 2>resume.err ||
  fail "--resume: exit $? ($(grep '^phiq' resume.err))"
"$phiq" batch -q long.yaml long.csv -o full.csv --threads 2 || fail "one process, 1500 cases: exit $?"
cmp -s big.csv full.csv || fail "--resume: big.csv is not the file of one uninterrupted process"
earlier=$(grep -c '"status": "written earlier"' resume.json)
[ "$earlier" -eq "$kept" ] || fail "--resume: $earlier cases 'written earlier', not $kept"
exit $status
