#!/bin/sh
# What bearings' friction costs in the whole command a user runs, `phiq run SCENE -o OUT`, timed as a process
# (/usr/bin/time): nfourbar N in reference-point coordinates (`phiq generate --coords reference-point`, 3N + 1
# revolute joints) with a unit mass on every crank and coupler under gravity, its drivers' efforts and powers
# written to HDF5, plain and with a bearing (μ 0.15, journal radius 10 mm) at every joint, whose friction the
# efforts solve for with the reactions it changes (solve/friction_losses.hpp). Prints the median wall time of each
# with its spread (fastest and slowest repeat), peak memory, effort solves (passes) and the ratio to the plain run.
#
#   bench/run_bearings_whole.sh [PHIQ] [N] [STEPS] [REPEATS] [THREADS]
#
# Defaults: build/tools/phiq, 1000, 200 steps, 5 repeats, 1 thread (0: every core). Results go to $TMPDIR
# (default /dev/shm: the disk's speed is not measured) and are removed.
set -eu
phiq=${1:-build/tools/phiq}
n=${2:-1000}
steps=${3:-200}
repeats=${4:-5}
threads=${5:-1}
dir=$(mktemp -d "${TMPDIR:-/dev/shm}/phiq_bearings_whole.XXXXXX")
trap 'rm -rf "$dir"' EXIT
"$phiq" generate nfourbar "$n" --coords reference-point --steps "$steps" -o "$dir/generated.yaml"
bar='mass: 1, center_of_mass: [0, 0], inertia: 0.08333333333333333'
bearing='coefficient: 0.15, radius: 0.01'
{
  grep -v '^output:' "$dir/generated.yaml"
  printf 'parts:\n  for i in 0..N:\n    "crank{i}": {%s}\n  for i in 0..N-1:\n    "coupler{i}": {%s}\n' "$bar" "$bar"
  printf 'loads:\n  gravity: [0, -9.81]\n'
} >"$dir/base.yaml"
out='output: {velocities: true, accelerations: true, efforts: all, power: true}'
{ cat "$dir/base.yaml"; echo "$out"; } >"$dir/plain.yaml"
{
  cat "$dir/base.yaml"
  printf '  torsional_springs:\n    - for i in 0..N:\n'
  printf '        - {name: "pivot{i}_bearing", angle: "psi{i}", bearing: {joint: "pivot{i}", %s}}\n' "$bearing"
  printf '    - for i in 0..N-1:\n'
  printf '        - {name: "left{i}_bearing", angle: "phi{i} - psi{i}", bearing: {joint: "left{i}", %s}}\n' "$bearing"
  printf '        - {name: "right{i}_bearing", angle: "phi{i} - psi{i+1}", bearing: {joint: "right{i}", %s}}\n' \
    "$bearing"
  echo "$out"
} >"$dir/bearings.yaml"
echo "phiq run nfourbar $n (reference-point) with masses, $steps steps, $threads thread(s), $repeats repeats, to HDF5;" \
  "load: $(cut -d' ' -f1-3 /proc/loadavg)"
printf '%-9s %9s %15s %8s %14s %7s\n' scene median_s min-max_s peak_MB effort_solves ratio
for scene in plain bearings; do : >"$dir/times.$scene"; done
i=0
while [ "$i" -lt "$repeats" ]; do  # in turn: a drift of the machine's speed hits both alike
  for scene in plain bearings; do
    /usr/bin/time -f '%e %M' -a -o "$dir/times.$scene" \
      "$phiq" run "$dir/$scene.yaml" -o "$dir/out.h5" --threads "$threads" 2>"$dir/summary.$scene"
    rm -f "$dir/out.h5"
  done
  i=$((i + 1))
done
for scene in plain bearings; do
  solves=$(sed -n 's/.* \([0-9]*\) effort solves.*/\1/p' "$dir/summary.$scene")
  sort -n "$dir/times.$scene" | awk -v s="$scene" -v e="$solves" '
    { wall[NR] = $1; mem[NR] = $2 }
    END { m = int((NR + 1) / 2); printf "%s %.3f %.3f-%.3f %.0f %s\n", s, wall[m], wall[1], wall[NR], mem[m] / 1024, e }'
done | awk '{ if ($1 == "plain") base = $2
              printf "%-9s %9.3f %15s %8.0f %14s %7.2f\n", $1, $2, $3, $4, $5, $2 / base }'
