#!/bin/sh
# ctest plot_bench: tools/plot/plot_bench.py on the hand-written fixture tests/data/bench_fixture.json.
# Usage: plot_bench_test.sh SCRIPT FIXTURE SCRATCH_DIR. Exit 77 (skipped) without python3 or matplotlib.
set -u
script=$1 fixture=$2 dir=$3
name=plot_bench_test
. "$(dirname "$0")/plot_test_common.sh"

mkdir -p "$dir" && rm -f "$dir"/*.svg "$dir"/*.png "$dir"/err.txt
fixture_rt=$(dirname "$fixture")/bench_fixture_real_time.json  # no per-step counter: real_time per step
"$py" "$script" "$fixture" "$fixture_rt" -o "$dir/fixture.svg" --png "$dir/fixture.png" ||
  fail "exit status $? on the fixtures"
[ -s "$dir/fixture.svg" ] || fail "no SVG written"
[ -s "$dir/fixture.png" ] || fail "no PNG written"
for label in 'phiq KLU, quadratic predictor' 'dense Eigen LU, from previous' 'Simbody, quadratic predictor' \
             'phiq UMFPACK (bench_fixture)' 'FixtureRealTime (bench_fixture_real_time)' 'time per drive step'; do
  grep -q "$label" "$dir/fixture.svg" || fail "label '$label' missing from the SVG"
done
for absent in FixtureAggregate FixtureBroken FixtureWithoutN FixtureNotPerStep; do
  grep -q "$absent" "$dir/fixture.svg" && fail "'$absent' should have been skipped"
done
# the same input writes the same file
"$py" "$script" "$fixture" "$fixture_rt" -o "$dir/again.svg" 2>/dev/null || fail "second run"
cmp -s "$dir/fixture.svg" "$dir/again.svg" || fail "the SVG differs between two runs on the same input"

# errors: one line on stderr, exit status 1
expect_error "missing file" "$dir/no_such.json"
printf '{"benchmarks": [' >"$dir/truncated.json"
expect_error "invalid JSON" "$dir/truncated.json"
printf '{"context": {}}' >"$dir/nobench.json"
expect_error "no benchmarks list" "$dir/nobench.json"
expect_error "nothing matches" "$fixture" --filter 'no such curve'
echo "plot_bench_test: OK"
