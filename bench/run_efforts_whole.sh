#!/bin/sh
# What driver efforts and joint reactions cost in the whole command a user runs, `phiq run SCENE -o OUT`, timed as
# a process (/usr/bin/time): nfourbar N (`phiq generate`) with a unit mass on every crank and coupler (slender bars,
# families in `parts`) under gravity, written three ways: q, q̇, q̈ only; with `efforts: all, power: true`; and with
# `reactions: all` too (the joint points P{i}). Prints per format (CSV, HDF5) the median wall time of each with its
# spread (fastest and slowest repeat), the median CPU time and peak memory, and the ratios of the medians to the
# first, whose wall-time ratio the efforts target reads (bench/README.md).
#
#   bench/run_efforts_whole.sh [PHIQ] [N] [STEPS] [REPEATS] [THREADS]
#
# Defaults: build/tools/phiq, 10000, 100 steps, 5 repeats, 1 thread (0: every core). Results go to $TMPDIR
# (default /dev/shm: the disk's speed is not measured) and are removed. With INSTRUCTIONS=1 each scene runs once,
# to HDF5 on 1 thread, under `valgrind --tool=callgrind`, and the script prints the instructions of the whole
# process and their ratios instead: the same count on every run, whatever else the machine is doing.
set -eu
phiq=${1:-build/tools/phiq}
n=${2:-10000}
steps=${3:-100}
repeats=${4:-5}
threads=${5:-1}
dir=$(mktemp -d "${TMPDIR:-/dev/shm}/phiq_efforts_whole.XXXXXX")
trap 'rm -rf "$dir"' EXIT
"$phiq" generate nfourbar "$n" --steps "$steps" --outputs q,v,a -o "$dir/plain.yaml"
bar='mass: 1, center_of_mass: [0.5, 0], inertia: 0.08333333333333333'
{
  grep -v '^output:' "$dir/plain.yaml"
  printf 'parts:\n  for i in 0..N:\n    "crank{i}": {frame: {origin: [i, 0], x: "P{i}"}, %s}\n' "$bar"
  printf '  for i in 0..N-1:\n    "coupler{i}": {frame: {origin: "P{i}", x: "P{i+1}"}, %s}\n' "$bar"
  printf 'loads: {gravity: [0, -9.81]}\n'
} >"$dir/base.yaml"
out='output: {velocities: true, accelerations: true'
{ cat "$dir/base.yaml"; echo "$out}"; } >"$dir/plain.yaml"
{ cat "$dir/base.yaml"; echo "$out, efforts: all, power: true}"; } >"$dir/torques.yaml"
{ cat "$dir/base.yaml"; echo "$out, efforts: all, power: true, reactions: all}"; } >"$dir/reactions.yaml"
if [ "${INSTRUCTIONS:-0}" = 1 ]; then
  echo "phiq run nfourbar $n with masses, $steps steps, to HDF5 on 1 thread, under callgrind"
  for scene in plain torques reactions; do
    valgrind --tool=callgrind --callgrind-out-file="$dir/$scene.callgrind" \
      "$phiq" run -q "$dir/$scene.yaml" -o "$dir/out.h5" --threads 1 >/dev/null 2>&1
    rm -f "$dir/out.h5"
    echo "$scene $(sed -n 's/^summary: //p' "$dir/$scene.callgrind")"
  done | awk '{ if ($1 == "plain") base = $2
                printf "%-10s %15.0f instructions %6.3f\n", $1, $2, $2 / base }'
  exit 0
fi
echo "phiq run nfourbar $n with masses, $steps steps, $threads thread(s), $repeats repeats;" \
  "load: $(cut -d' ' -f1-3 /proc/loadavg)"
printf '%-5s %-10s %9s %15s %9s %8s %10s\n' format scene median_s min-max_s cpu_s peak_MB wall_ratio
for format in csv h5; do
  for scene in plain torques reactions; do : >"$dir/times.$scene"; done
  i=0
  while [ "$i" -lt "$repeats" ]; do  # the three scenes in turn: a drift of the machine's speed hits each alike
    for scene in plain torques reactions; do
      /usr/bin/time -f '%e %U %S %M' -a -o "$dir/times.$scene" \
        "$phiq" run -q "$dir/$scene.yaml" -o "$dir/out.$format" --threads "$threads"
      rm -f "$dir/out.$format"
    done
    i=$((i + 1))
  done
  for scene in plain torques reactions; do
    sort -n "$dir/times.$scene" | awk -v f="$format" -v s="$scene" '
      { wall[NR] = $1; cpu[NR] = $2 + $3; mem[NR] = $4 }
      END { m = int((NR + 1) / 2)
            printf "%s %s %.3f %.3f-%.3f %.3f %.0f\n", f, s, wall[m], wall[1], wall[NR], cpu[m], mem[m] / 1024 }'
  done
done | awk '{ if ($2 == "plain") base = $3
              printf "%-5s %-10s %9.3f %15s %9.3f %8.0f %10.2f\n", $1, $2, $3, $4, $5, $6, $3 / base }'
