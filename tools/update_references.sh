#!/usr/bin/env bash
# Regenerates the reference results beside every scene that runs: models/<dir>/reference/<scene>.csv.
# Run it only when a change of numbers is intended and understood; say why in the commit. The regression tests
# (ctest -R regression) compare each scene's run against its reference with `phiq compare`. One thread, as the
# regression tests run them: a reference is the sequential sweep.
# Scenes that are meant to fail are listed below and get no reference; any other scene that fails stops the
# script with an error, so that a regressing scene cannot keep a stale reference unnoticed.
set -euo pipefail
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
phiq="${PHIQ:-$root/build/tools/phiq}"
expected_failures=(
  models/redundant/door_misaligned.yaml        # inconsistent redundant constraints
  models/hard/crank_rocker_rocker_driven.yaml  # driven beyond its dead point
)
status=0
for scene in "$root"/models/*/*.yaml; do
  rel="${scene#"$root"/}"
  dir="$(dirname "$scene")/reference"
  out="$dir/$(basename "${scene%.yaml}").csv"
  expected=0
  for f in "${expected_failures[@]}"; do [ "$f" = "$rel" ] && expected=1; done
  mkdir -p "$dir"
  if "$phiq" run -q --threads 1 "$scene" -o "$out"; then
    if [ "$expected" = 1 ]; then echo "error: $rel ran, but it is listed as failing by design" >&2; status=1; fi
    echo "updated ${out#"$root"/}"
  elif [ "$expected" = 1 ]; then
    echo "no reference for $rel: it fails by design (see the message above)"
  else
    echo "error: $rel does not run; its reference was left as it was" >&2
    status=1
  fi
done
exit "$status"
