#!/usr/bin/env bash
# ctest `regression.<scene>`: run the scene and compare with its reference result (phiq compare, default
# tolerances rtol 1e-9, atol 1e-12).
set -euo pipefail
phiq="$1"; scene="$2"; reference="$3"; scratch="$4"
mkdir -p "$scratch"
out="$scratch/$(basename "${scene%.yaml}").csv"
"$phiq" run -q "$scene" -o "$out"
"$phiq" compare "$reference" "$out"
