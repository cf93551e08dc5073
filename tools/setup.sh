#!/usr/bin/env bash
# README command (1): install what phiq needs, build the library, the `phiq` command and the Python package (Release,
# in build/), install the package for /usr/bin/python3, and run the default scene. The tests and benchmarks are
# built by README command (2), tools/test.sh, in the same build directory.
set -euo pipefail
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
source "$root/tools/build_config.sh"
"$root/tools/install_deps.sh"
phiq_configure_release "$root"
cmake --build "$root/build" -j "$(nproc)" --target phiq phiq_python
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
