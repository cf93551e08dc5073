#!/usr/bin/env bash
# Regenerates reference results: models/<dir>/reference/<scene>.csv. Run it only when a change of numbers is
# intended and understood; say why in the commit. The regression tests (ctest -R regression) compare each scene's
# run against its reference with `phiq compare`.
#   update_references.sh            rewrites every existing reference from its scene
#   update_references.sh SCENE...   writes the references of these scenes (to add a new one)
# Scenes without a reference are left alone: some are not meant to be swept by `phiq run` (models/redundant/ have
# more equations than coordinates until the rank analysis solves through redundancy).
set -euo pipefail
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
phiq="${PHIQ:-$root/build/tools/phiq}"
scenes=()
if [ "$#" -gt 0 ]; then
  scenes=("$@")
else
  shopt -s nullglob
  for ref in "$root"/models/*/reference/*.csv; do
    scenes+=("$(dirname "$(dirname "$ref")")/$(basename "${ref%.csv}").yaml")
  done
fi
for scene in "${scenes[@]}"; do
  dir="$(dirname "$scene")/reference"
  mkdir -p "$dir"
  "$phiq" run -q "$scene" -o "$dir/$(basename "${scene%.yaml}").csv"
  echo "updated $dir/$(basename "${scene%.yaml}").csv"
done
