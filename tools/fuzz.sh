#!/usr/bin/env bash
# Bounded libFuzzer run of the scene loader (tests/fuzz/fuzz_scene, built with ASan + UBSan by tools/test.sh).
#   tools/fuzz.sh [SECONDS] [BUILD_DIR]      default 60 s, build-asan
# Seeds: every scene under models/. Exits non-zero on any crash, hang (> 10 s per input), leak or sanitizer report;
# the reproducer is left in BUILD_DIR/fuzz/. Prints the number of inputs tried.
set -euo pipefail
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
seconds="${1:-60}"
build="${2:-$root/build-asan}"
work="$build/fuzz"
mkdir -p "$work/corpus" "$work/seeds"
find "$root/models" "$root/tests/fuzz/regressions" -type f -exec cp {} "$work/seeds/" \;
cd "$work"
set +e
"$build/tests/fuzz/fuzz_scene" -max_total_time="$seconds" -timeout=10 -rss_limit_mb=2048 -max_len=8192 \
  -dict="$root/tests/fuzz/scene.dict" -print_final_stats=1 corpus seeds > fuzz.log 2>&1
status=$?
set -e
runs=$(grep -o 'stat::number_of_executed_units: *[0-9]*' fuzz.log | grep -o '[0-9]*$' || echo "?")
if [ $status -ne 0 ]; then
  tail -n 40 fuzz.log >&2
  echo "fuzz.sh: FAILED after $runs inputs (log: $work/fuzz.log)" >&2
  exit 1
fi
echo "fuzz.sh: $runs inputs in ${seconds} s, no crash, hang, leak or sanitizer report"
