#!/usr/bin/env bash
# Bounded libFuzzer runs (targets in tests/fuzz, built with ASan + UBSan by tools/test.sh):
#   fuzz_scene       any bytes as a scene, for SECONDS; seeds: every scene under models/ and tests/fuzz/regressions/
#   fuzz_expression  any bytes as an equation's text, for SECONDS; seeds: every expr: of those scenes
#   tools/fuzz.sh [SECONDS] [BUILD_DIR]      default 60 s, build-asan
# Both run at once, each on one core. Exits non-zero on any crash, hang (> 10 s per input), leak or sanitizer report; the reproducer is left in
# BUILD_DIR/fuzz/<target>/. Prints the number of inputs tried.
set -euo pipefail
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
seconds="${1:-60}"
build="${2:-$root/build-asan}"

run() {  # run TARGET SECONDS DICT: fuzz in BUILD_DIR/fuzz/TARGET with its corpus/ and seeds/
  local target="$1" secs="$2" dict="$3" work="$build/fuzz/$1"
  cd "$work"
  set +e
  "$build/tests/fuzz/$target" -max_total_time="$secs" -timeout=10 -rss_limit_mb=2048 -max_len=8192 \
    -dict="$dict" -print_final_stats=1 corpus seeds > fuzz.log 2>&1
  local status=$?
  set -e
  local runs
  runs=$(grep -o 'stat::number_of_executed_units: *[0-9]*' fuzz.log | grep -o '[0-9]*$' || echo "?")
  if [ $status -ne 0 ]; then
    tail -n 40 fuzz.log >&2
    echo "fuzz.sh: $target FAILED after $runs inputs (log: $work/fuzz.log)" >&2
    exit 1
  fi
  echo "fuzz.sh: $target: $runs inputs in ${secs} s, no crash, hang, leak or sanitizer report"
}

scenes="$build/fuzz/fuzz_scene" expressions="$build/fuzz/fuzz_expression"
mkdir -p "$scenes/corpus" "$scenes/seeds" "$expressions/corpus" "$expressions/seeds"
find "$root/models" "$root/tests/fuzz/regressions" -type f -exec cp {} "$scenes/seeds/" \;
# one seed file per distinct double-quoted expression of those scenes
grep -rhoE 'expr: "[^"]*"' "$root/models" "$root/tests/fuzz/regressions" | sed -E 's/^expr: "(.*)"$/\1/' |
  sort -u | awk -v dir="$expressions/seeds" '{ f = dir "/seed" NR; printf "%s", $0 > f; close(f) }'

# The two targets side by side (libFuzzer runs on one core): the pass takes SECONDS, not twice that.
(run fuzz_scene "$seconds" "$root/tests/fuzz/scene.dict") &
scene_job=$!
status=0
(run fuzz_expression "$seconds" "$root/tests/fuzz/expression.dict") || status=1
wait "$scene_job" || status=1
exit "$status"
