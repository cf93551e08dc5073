#!/usr/bin/env bash
# ctest `package_consumer`: install phiq from the build tree into a scratch prefix, then configure, build and run
# tests/consumer against that prefix only, exactly as an outside project would.
set -euo pipefail
build="$1"; src="$2"; scratch="$3"
rm -rf "$scratch"
cmake --install "$build" --prefix "$scratch/prefix" >/dev/null
cmake -S "$src" -B "$scratch/build" -DCMAKE_PREFIX_PATH="$scratch/prefix" -DCMAKE_BUILD_TYPE=Release >/dev/null
cmake --build "$scratch/build" >/dev/null
"$scratch/build/consumer"
