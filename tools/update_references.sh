#!/usr/bin/env bash
# Regenerates the reference results beside every scene that runs: models/<dir>/reference/<scene>.csv.
# Run it only when a change of numbers is intended and understood; say why in the commit. The regression tests
# (ctest -R regression) compare each scene's run against its reference with `phiq compare`. One thread, as the
# regression tests run them: a reference is the sequential sweep.
set -euo pipefail
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
phiq="${PHIQ:-$root/build/tools/phiq}"
for scene in "$root"/models/*/*.yaml; do
  dir="$(dirname "$scene")/reference"
  mkdir -p "$dir"
  # scenes that are meant to fail have no reference: models/redundant/door_misaligned (inconsistent),
  # models/hard/crank_rocker_rocker_driven (driven beyond its dead point)
  if "$phiq" run -q --threads 1 "$scene" -o "$dir/$(basename "${scene%.yaml}").csv"; then
    echo "updated $dir/$(basename "${scene%.yaml}").csv"
  else
    echo "no reference for $scene: it does not run (see the message above)"
  fi
done
