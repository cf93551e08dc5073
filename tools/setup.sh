#!/usr/bin/env bash
# README command (1): install the dependencies, build phiq (Release, in build/), install its Python package, and run
# the default scene.
set -euo pipefail
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
"$root/tools/install_deps.sh"
cmake -S "$root" -B "$root/build" -DCMAKE_BUILD_TYPE=Release >/dev/null
cmake --build "$root/build" -j "$(nproc)"
# The Python package, where Debian's /usr/bin/python3 finds it in a fresh shell: /usr/local as root, else the
# user's ~/.local (engine/python/README.md).
if [ "$(id -u)" -eq 0 ]; then py_prefix=/usr/local; else py_prefix="$HOME/.local"; fi
cmake --install "$root/build" --component python --prefix "$py_prefix" >/dev/null
echo "Python package installed under $py_prefix: /usr/bin/python3 -c 'import phiq'"
scene="${1:-$root/models/seed/crank_slider_mixed.yaml}"
out="$root/build/$(basename "${scene%.*}").csv"
"$root/build/tools/phiq" check "$scene"
"$root/build/tools/phiq" run "$scene" -o "$out"
echo "first rows of $out:"
head -n 4 "$out" | cut -c 1-160
