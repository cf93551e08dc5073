#!/bin/sh
# ctest browser_viewer: `phiq animate -o OUT.html` on a planar crank-slider (mixed coordinates) and a spatial one
# (natural coordinates), each with its crank tip A traced and a sweep that does not close the cycle (the first and
# last poses differ), opened in headless Chromium by tests/browser/viewer_test.js (node, no npm package): no console
# error, first and last frames differ where the mechanism moved and agree on the ground, the middle frame matches
# tests/browser/reference/NAME.png; the parts of the Cardan joint, the roller cam and the gear train, their middle
# frames against parts_*.png; and the four-bar knee's output.clearance, marked and coloured. Skipped (exit 77) when
# chromium or node is absent.
# Usage: browser_viewer_test.sh PHIQ MODELS_DIR WORK_DIR [--update] [--timing]
#   --update rewrites the references (look at them, and say why in the commit).
set -u
phiq="$1"; models="$2"; work="$3"; shift 3
here="$(cd "$(dirname "$0")" && pwd)"
chromium="$(command -v chromium || command -v chromium-browser)" ||
  { echo "browser_viewer: chromium not found (tools/install_deps.sh installs it): skipped"; exit 77; }
command -v node >/dev/null 2>&1 || { echo "browser_viewer: node not found (tools/install_deps.sh installs it): skipped"; exit 77; }
rm -rf "$work" && mkdir -p "$work" || exit 1
# the crank turns 2.4 rad (not the scene's full turn); the spatial one 3 rad, as in its scene
sed -e 's/end: pi, steps: 180/end: 1.2, steps: 60/' \
    -e 's/output: {velocities: true, accelerations: true}/output: {velocities: true, points: [A]}/' \
    "$models/seed/crank_slider_mixed.yaml" > "$work/planar.yaml" || exit 1
sed -e 's/output: {velocities: true, accelerations: true}/output: {velocities: true, points: [A]}/' \
    "$models/spatial/crank_slider_natural.yaml" > "$work/spatial.yaml" || exit 1
for name in planar spatial; do
  grep -q 'points: \[A\]' "$work/$name.yaml" || { echo "browser_viewer: $name.yaml: the scene's output line changed"; exit 1; }
  "$phiq" run -q "$work/$name.yaml" -o "$work/$name.csv" || { echo "browser_viewer: phiq run $name failed"; exit 1; }
  "$phiq" animate "$work/$name.yaml" "$work/$name.csv" -o "$work/$name.html" ||
    { echo "browser_viewer: phiq animate $name failed"; exit 1; }
done
# the Cardan joint's parts (two shafts, two forks, the cross), a third of a turn
sed -e 's/end: 2\*pi, steps: 72/end: 2, steps: 24/' "$models/spatial/cardan.yaml" > "$work/cardan.yaml" || exit 1
grep -q 'end: 2, steps: 24' "$work/cardan.yaml" || { echo "browser_viewer: cardan.yaml: its time line changed"; exit 1; }
"$phiq" animate "$work/cardan.yaml" -o "$work/cardan.html" || { echo "browser_viewer: phiq animate cardan failed"; exit 1; }
# the roller cam (its disc, roller and follower) and the two-stage gear train (pitch circles), drawn by their
# derived parts
for name in cams/eccentric_roller transmissions/gear_train; do
  "$phiq" animate "$models/$name.yaml" -o "$work/$(basename "$name").html" ||
    { echo "browser_viewer: phiq animate $name failed"; exit 1; }
done
# the four-bar knee's output.clearance: witness points and the parts within the threshold coloured
"$phiq" animate "$models/clearance/fourbar_knee.yaml" -o "$work/knee.html" ||
  { echo "browser_viewer: phiq animate fourbar_knee failed"; exit 1; }
exec node "$here/browser/viewer_test.js" "$chromium" "$here/browser/reference" "$work/shots" "$@" \
  planar="$work/planar.html" spatial="$work/spatial.html" parts_cardan="$work/cardan.html" \
  parts_cam="$work/eccentric_roller.html" parts_gears="$work/gear_train.html" clearance_knee="$work/knee.html"
