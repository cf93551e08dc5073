#!/usr/bin/env bash
# ctest `package_consumer`: install phiq from the build tree into a scratch prefix, then configure, build and run
# tests/consumer against that prefix only, exactly as an outside project would: with CMake (find_package), and
# with pkg-config (phiq.pc) and a bare compiler. Also checks that the install carries the man page, the bash
# completion and the HTML API reference.
set -euo pipefail
build="$1"; src="$2"; scratch="$3"
rm -rf "$scratch"
cmake --install "$build" --prefix "$scratch/prefix" >/dev/null
cmake -S "$src" -B "$scratch/build" -DCMAKE_PREFIX_PATH="$scratch/prefix" -DCMAKE_BUILD_TYPE=Release >/dev/null
cmake --build "$scratch/build" >/dev/null
"$scratch/build/consumer"

# pkg-config: the file beside lib/cmake/phiq, relocatable (found here under a prefix it was not configured for)
pc=$(find "$scratch/prefix" -name phiq.pc -path '*/pkgconfig/*')
[ -n "$pc" ] || { echo "package_consumer: no phiq.pc installed" >&2; exit 1; }
[ -d "$(dirname "$pc")/../cmake/phiq" ] || { echo "package_consumer: $pc is not beside lib/cmake/phiq" >&2; exit 1; }
export PKG_CONFIG_PATH="$(dirname "$pc")"
version=$(pkg-config --modversion phiq)
# shellcheck disable=SC2046  # the flags are words
c++ -O2 -o "$scratch/consumer_pc" "$src/main.cpp" $(pkg-config --cflags --libs phiq)
out=$("$scratch/consumer_pc")
echo "$out"
case "$out" in
  *"phiq $version,"*) ;;
  *) echo "package_consumer: pkg-config says $version, the program built with it: $out" >&2; exit 1 ;;
esac

# the rest of the install: man page, bash completion, API reference
for f in share/man/man1/phiq.1 share/bash-completion/completions/phiq share/doc/phiq/html/index.html; do
  [ -s "$scratch/prefix/$f" ] || { echo "package_consumer: $f not installed" >&2; exit 1; }
done
grep -q '^\.SS "phiq sweep-accuracy"' "$scratch/prefix/share/man/man1/phiq.1" ||
  { echo "package_consumer: the man page lacks the commands' help" >&2; exit 1; }
