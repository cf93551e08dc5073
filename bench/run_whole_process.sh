#!/bin/sh
# The whole command a user runs, `phiq run SCENE -o OUT`, timed as a process (/usr/bin/time): the load, the sweep,
# the rows' formatting and their writing, to CSV and to HDF5, on 1 and on 2 threads. Prints, per format and thread
# count, the minimum and median wall time, user + system CPU time and peak memory over the repeats, then the ratio
# of 1 thread's wall time to 2 threads' (minimum over minimum, median over median).
#
#   bench/run_whole_process.sh [PHIQ] [N] [STEPS] [REPEATS]
#
# PHIQ: the phiq binary (default build/tools/phiq); the scene is `phiq generate nfourbar N --steps STEPS --outputs
# q,v,a` (defaults 10000, 1000: 1.2 GB of CSV); REPEATS per case (default 5). Results go to $TMPDIR (default
# /dev/shm, memory: the disk's speed is not measured) and are removed. Check the load first (uptime): other
# processes on the cores show as a lower ratio.
set -eu
phiq=${1:-build/tools/phiq}
n=${2:-10000}
steps=${3:-1000}
repeats=${4:-5}
dir=$(mktemp -d "${TMPDIR:-/dev/shm}/phiq_whole_process.XXXXXX")
trap 'rm -rf "$dir"' EXIT
"$phiq" generate nfourbar "$n" --steps "$steps" --outputs q,v,a -o "$dir/scene.yaml"
echo "phiq run nfourbar $n, $steps steps, q, v, a; $repeats repeats; load: $(cut -d' ' -f1-3 /proc/loadavg)"
printf '%-5s %7s %9s %9s %9s %9s\n' format threads min_s median_s cpu_s peak_MB
for format in csv h5; do
  for threads in 1 2; do
    : >"$dir/times"
    i=0
    while [ "$i" -lt "$repeats" ]; do
      /usr/bin/time -f '%e %U %S %M' -a -o "$dir/times" \
        "$phiq" run -q "$dir/scene.yaml" -o "$dir/out.$format" --threads "$threads"
      rm -f "$dir/out.$format"
      i=$((i + 1))
    done
    # wall times sorted: the minimum and the median; the CPU time and the memory of the median run
    sort -n "$dir/times" | awk -v f="$format" -v t="$threads" '
      { wall[NR] = $1; cpu[NR] = $2 + $3; mem[NR] = $4 }
      END { m = int((NR + 1) / 2)
            printf "%-5s %7d %9.2f %9.2f %9.2f %9.0f\n", f, t, wall[1], wall[m], cpu[m], mem[m] / 1024 }'
  done
done | tee "$dir/table"
awk '{ min[$1 "," $2] = $3; med[$1 "," $2] = $4 }
     END { n = split("csv h5", fs, " ")
           for (i = 1; i <= n; ++i)
             printf "%s: 1 thread / 2 threads: %.2fx (minimum), %.2fx (median)\n", fs[i],
               min[fs[i] ",1"] / min[fs[i] ",2"], med[fs[i] ",1"] / med[fs[i] ",2"] }' "$dir/table"
