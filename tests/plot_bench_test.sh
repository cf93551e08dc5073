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

# the x axis says whose N it is: nfourbar alone, or the generators of the scenes plotted (never "nfourbar N" for
# chain3d and grid curves)
"$py" "$script" "$fixture" --filter 'phiq KLU' -o "$dir/nfourbar.svg" 2>/dev/null || fail "exit status $? on --filter"
grep -q 'nfourbar N (N + 1 cranks, 2N + 3 natural coordinates)' "$dir/nfourbar.svg" || fail "nfourbar x label missing"
printf '{"benchmarks": [{"name": "BM_Chain3dStep/N:10/manual_time", "us_per_step": 5},
  {"name": "BM_Chain3dStep/N:100/manual_time", "us_per_step": 50}, {"name": "BM_GridStep/N:10", "us_per_step": 7},
  {"name": "BM_GridStep/N:100", "us_per_step": 70}]}' >"$dir/scenes.json"
"$py" "$script" "$dir/scenes.json" -o "$dir/scenes.svg" 2>/dev/null || fail "exit status $? on chain3d and grid"
grep -q "size argument of each scene's generator (phiq generate chain3d|grid N)" "$dir/scenes.svg" ||
  fail "chain3d/grid x label missing"
grep -q 'nfourbar' "$dir/scenes.svg" && fail "chain3d and grid curves labelled nfourbar"

# errors: one line on stderr, exit status 1
expect_error "missing file" "$dir/no_such.json"
printf '{"benchmarks": [' >"$dir/truncated.json"
expect_error "invalid JSON" "$dir/truncated.json"
printf '{"context": {}}' >"$dir/nobench.json"
expect_error "no benchmarks list" "$dir/nobench.json"
expect_error "nothing matches" "$fixture" --filter 'no such curve'
echo "plot_bench_test: OK"
