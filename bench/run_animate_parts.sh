#!/bin/sh
# `phiq animate` with parts, as a user runs it: the page's size, the command's time and memory (/usr/bin/time), and
# how the page plays in headless Chromium (tests/browser/frame_time.js: frame interval and draw time), for
#   1. nfourbar N (default 10 000) with its derived parts (a link per crank and coupler, pins), 100 steps;
#   2. chain3d 100 with a meshed part on each of its 100 couplers (an STL sphere of about 2 000 triangles,
#      stretched along the link), 100 steps.
#
#   bench/run_animate_parts.sh [PHIQ] [N]
#
# Needs node and chromium (tools/install_deps.sh --test) for the frame times; without them prints the rest.
set -eu
phiq=${1:-build/tools/phiq}
n=${2:-10000}
here=$(cd "$(dirname "$0")/.." && pwd)
dir=$(mktemp -d "${TMPDIR:-/dev/shm}/phiq_animate_parts.XXXXXX")
trap 'rm -rf "$dir"' EXIT
chromium=$(command -v chromium || command -v chromium-browser || true)
echo "load: $(cut -d' ' -f1-3 /proc/loadavg)"

measure() {  # NAME SCENE
  /usr/bin/time -f '%e %M' -o "$dir/time" "$phiq" animate "$2" -o "$dir/$1.html"
  read -r wall kb <"$dir/time"
  echo "$1: page $(($(stat -c %s "$dir/$1.html") / 1000)) kB, phiq animate ${wall} s, peak $((kb / 1024)) MB"
  if [ -n "$chromium" ] && command -v node >/dev/null 2>&1; then
    node "$here/tests/browser/frame_time.js" "$chromium" "$dir/$1.html" 5 | sed "s/^/$1: /"
  fi
}

"$phiq" generate nfourbar "$n" --steps 100 -o "$dir/nfourbar.yaml"
measure "nfourbar_$n" "$dir/nfourbar.yaml"

# a UV sphere of 2 × 32 × 31 triangles, radius 0.5, as binary STL
/usr/bin/python3 - "$dir/sphere.stl" <<'PY'
import math, struct, sys
rings, segs = 32, 32
def at(i, j):
    if i in (0, rings): return (0.0, 0.0, 0.5 if i == 0 else -0.5)
    th, ph = math.pi * i / rings, 2 * math.pi * (j % segs) / segs
    return (0.5 * math.sin(th) * math.cos(ph), 0.5 * math.sin(th) * math.sin(ph), 0.5 * math.cos(th))
tris = []
for i in range(rings):
    for j in range(segs):
        a, b, c, d = at(i, j), at(i + 1, j), at(i + 1, j + 1), at(i, j + 1)
        if i != rings - 1: tris.append((a, b, c))
        if i != 0: tris.append((a, c, d))
with open(sys.argv[1], "wb") as f:
    f.write(b"\0" * 80 + struct.pack("<I", len(tris)))
    for t in tris:
        f.write(struct.pack("<3f", 0, 0, 0) + b"".join(struct.pack("<3f", *v) for v in t) + b"\0\0")
PY
"$phiq" generate chain3d 100 --steps 100 -o "$dir/chain.yaml"
{
  echo "parts:"
  i=0
  while [ "$i" -lt 100 ]; do
    echo "  link$i: {frame: {origin: P$i, x: P$((i + 1)), y: [0, 0, 1000]}, shapes: [{type: mesh, file: sphere.stl, at: [0.5, 0, 0], scale: 0.3}]}"
    i=$((i + 1))
  done
} >>"$dir/chain.yaml"
measure chain3d_100_meshes "$dir/chain.yaml"
