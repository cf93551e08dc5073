#!/usr/bin/env bash
# ctest `regression.<scene>`: run the scene and compare with its reference result (phiq compare, rtol 1e-9,
# atol 1e-9). The absolute tolerance is ten times the scenes' Newton tolerance (1e-10 × length scale ~1 m): results
# are only defined to that, and modified Newton or parallel chunks may land anywhere within it.
set -euo pipefail
phiq="$1"; scene="$2"; reference="$3"; scratch="$4"
mkdir -p "$scratch"
out="$scratch/$(basename "${scene%.yaml}").csv"
"$phiq" run -q "$scene" -o "$out"
"$phiq" compare --atol 1e-9 "$reference" "$out"
