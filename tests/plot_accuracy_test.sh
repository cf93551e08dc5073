#!/bin/sh
# ctest plot_accuracy: tools/plot/plot_accuracy.py on the hand-written fixture tests/data/accuracy_fixture.csv, whose
# Pareto fronts are known: fixture_slider's default is on its front, fixture_fourbar's is dominated (by a setting
# at its own step count, 5 % faster, and over all step counts by one at 90 steps), fixture_positions has no
# velocities or accelerations, and one failed row is left out.
# Usage: plot_accuracy_test.sh SCRIPT FIXTURE SCRATCH_DIR. Exit 77 (skipped) without python3 or matplotlib.
set -u
script=$1 fixture=$2 dir=$3
name=plot_accuracy_test
. "$(dirname "$0")/plot_test_common.sh"

mkdir -p "$dir" && rm -f "$dir"/*.svg "$dir"/*.png "$dir"/*.md "$dir"/*.txt "$dir"/*.csv
"$py" "$script" "$fixture" -o "$dir/fixture.svg" --png "$dir/fixture.png" --markdown "$dir/front.md" 2>"$dir/log.txt" ||
  fail "exit status $? on the fixture: $(cat "$dir/log.txt")"
[ -s "$dir/fixture.svg" ] || fail "no SVG written"
[ -s "$dir/fixture.png" ] || fail "no PNG written"
for label in 'fixture_slider: positions' 'fixture_fourbar: accelerations' 'velocities not computed by this scene' \
             'Pareto front' 'scene default' 'tol 1e-14' 'quadratic' 'full Newton' 'UMFPACK'; do
  grep -q "$label" "$dir/fixture.svg" || fail "label '$label' missing from the SVG"
done
expect_log() { grep -qF "$1" "$dir/log.txt" || fail "expected on stderr: $1; got: $(cat "$dir/log.txt")"; }
expect_log 'fixture_slider: err_q: at 180 steps, the default (tol 1e-10, 180 steps, quadratic, modified Newton, KLU) is on the front'
expect_log 'fixture_slider: err_a: over all step counts, the default (tol 1e-10, 180 steps, quadratic, modified Newton, KLU) is on the front'
expect_log 'fixture_fourbar: err_q: at 360 steps, the default (tol 1e-10, 360 steps, quadratic, modified Newton, KLU; 2 us, 1e-10) is dominated by tol 1e-12, 360 steps, secant, full Newton, KLU (1.9 us, 1e-13): 5 % faster'
expect_log 'fixture_fourbar: err_q: over all step counts, the default (tol 1e-10, 360 steps, quadratic, modified Newton, KLU; 2 us, 1e-10) is dominated by tol 1e-12, 90 steps, secant, full Newton, KLU (1.8 us, 1e-13)'
expect_log '3 scenes, 11 settings'
expect_log '1 failed settings left out'
# the Markdown table: each scene's front at its default step count, the default marked, dominated rows left out
sed '/^$/,$d' "$dir/front.md" >"$dir/front_only.md"  # the first table: the fronts
[ "$(grep -c '^| fixture_' "$dir/front_only.md")" -eq 5 ] || fail "front.md: expected 5 front rows: $(cat "$dir/front.md")"
grep -q '^| fixture_slider | 1e-10 | 180 | quadratic | modified | KLU | 3.0e-11 | 2.0e-12 | 3.0e-12 | 2.40 | 1.00 | 1.5 | front, \*\*default\*\* |$' \
  "$dir/front.md" || fail "front.md: the slider's default row: $(cat "$dir/front.md")"
grep -q '^| fixture_fourbar | 1e-10 | 360 | .* | \*\*default\*\* |$' "$dir/front.md" || fail "front.md: the four-bar's dominated default"
grep -q 'umfpack\|UMFPACK' "$dir/front_only.md" && fail "front.md: a dominated UMFPACK row is listed on a front"
# the second table: the knobs at the default's tolerance and step count, with the time relative to the default
grep -q '^| fixture_slider | previous | full | UMFPACK | 5.0e-11 | 4.0e-12 | 6.0e-12 | 4.00 | 4.00 | 6 | 4.00 |$' \
  "$dir/front.md" || fail "front.md: the knobs table: $(cat "$dir/front.md")"
# the same input writes the same file
"$py" "$script" "$fixture" -o "$dir/again.svg" 2>/dev/null || fail "second run"
cmp -s "$dir/fixture.svg" "$dir/again.svg" || fail "the SVG differs between two runs on the same input"

# errors: one line on stderr, exit status 1, no SVG
expect_error "missing file" "$dir/no_such.csv"
printf 't,x\n0,1\n' >"$dir/other.csv"
expect_error "not a sweep-accuracy CSV" "$dir/other.csv"
head -1 "$fixture" >"$dir/empty.csv"
expect_error "no rows" "$dir/empty.csv"
{ head -1 "$fixture"; echo 'a,b,1e-6,10,previous,full,klu,x,1,1,1,1,1,ok,0'; } >"$dir/bad.csv"
expect_error "non-numeric error" "$dir/bad.csv"
echo "plot_accuracy_test: OK"
