#!/usr/bin/env bash
# README command (2): the whole test suite. .ci/run calls it.
#   tools/test.sh            0. the test-only packages (tools/install_deps.sh --test): those the Release build's
#                               configuration finds first, the others while it compiles;
#                            1. Release build (build/, as tools/setup.sh configures it) and its ctest suite, with the
#                               installed-package consumer, the regression comparisons, the Python package, the
#                               hostile-input catalogue, the size tests and the benchmark smoke run, but not the
#                               engine's GoogleTest suites (PHIQ_UNIT_TESTS=OFF: step 2 runs them, so that CI
#                               compiles them once);
#                            2. the whole suite built with clang under AddressSanitizer + UndefinedBehaviorSanitizer
#                               (build-asan/; its build starts at a lower priority while step 1's tests run),
#                               preceded by bounded libFuzzer runs side by side: the scene loader and the
#                               expression compiler, 10 s each.
#   tools/test.sh --quick    step 1 with the engine's GoogleTest suites in Release (the inner loop while developing)
#   PHIQ_FUZZ_SECONDS=N      each fuzzer's time (default 10)
set -euo pipefail
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
quick=0
if [ "${1:-}" = "--quick" ]; then quick=1; shift; fi
jobs="$(nproc)"

source "$root/tools/build_config.sh"
"$root/tools/install_deps.sh" --test-build
mkdir -p "$root/build"
set -m  # each background job in its own process group: the sanitizer build stops whole when a test fails
# The other test tools (Chromium, Node.js and the validator, clang, PHCpack, pytest) download and unpack while the
# Release build compiles: nothing before step 1's tests needs them.
deps_log="$root/build/install_test_tools.log"
"$root/tools/install_deps.sh" --test >"$deps_log" 2>&1 &
deps=$!
# (a failed build waits for it: apt and dpkg stopped halfway would leave the system's packages half-installed)
trap 'wait "$deps" 2>/dev/null || true' EXIT
# build/ as README command (1) configured it: what that command built is not compiled again.
phiq_configure_release "$root" -DPHIQ_UNIT_TESTS="$([ "$quick" = 1 ] && echo ON || echo OFF)"
cmake --build "$root/build" -j "$jobs"
if ! wait "$deps"; then cat "$deps_log" >&2; echo "test.sh: tools/install_deps.sh --test failed" >&2; exit 1; fi
trap - EXIT
cat "$deps_log"
if [ "$quick" = 1 ]; then
  (cd "$root/build" && ctest --output-on-failure -j "$jobs" "$@")
  exit 0
fi

# Step 2's build, at a lower priority, while step 1's tests run: they keep the two cores only 60–86 % busy
# (processes, a browser and MPI starting, files written), which the build takes; it goes on alone after them.
# Line tables only: file:line in every report's stack without full debug information, which cost compile time and
# nothing a report uses (the tests' own code at -O0: CMakeLists.txt, PHIQ_TEST_OPTIMIZATION)
asan_log="$root/build/build_asan.log"
(
  CC=clang CXX=clang++ cmake -S "$root" -B "$root/build-asan" $(phiq_generator "$root/build-asan") -DCMAKE_BUILD_TYPE=RelWithDebInfo \
    -DCMAKE_CXX_FLAGS_RELWITHDEBINFO="-O2 -gline-tables-only -DNDEBUG" \
    -DCMAKE_EXE_LINKER_FLAGS=-fuse-ld=lld -DCMAKE_SHARED_LINKER_FLAGS=-fuse-ld=lld \
    -DCMAKE_UNITY_BUILD=ON -DPHIQ_SANITIZE=ON -DPHIQ_FUZZ=ON -DPHIQ_BUILD_BENCH=OFF >/dev/null &&
    nice -n 10 cmake --build "$root/build-asan" -j "$jobs"
) >"$asan_log" 2>&1 &
asan=$!
stop_asan() { kill -- -"$asan" 2>/dev/null || true; }
trap stop_asan EXIT
(cd "$root/build" && ctest --output-on-failure -j "$jobs" "$@")

echo "== sanitizers: clang, AddressSanitizer + UndefinedBehaviorSanitizer (build-asan/)"
if ! wait "$asan"; then cat "$asan_log"; echo "test.sh: the sanitizer build failed" >&2; exit 1; fi
trap - EXIT
cat "$asan_log"
"$root/tools/fuzz.sh" "${PHIQ_FUZZ_SECONDS:-10}" "$root/build-asan"
# Reports unsymbolized (symbolize=0): LeakSanitizer starts llvm-symbolizer in every process to match its suppressions
# of third-party leaks (tests/sanitizer_defaults.cpp), which cost each phiq process 0.1 s of its 0.18 s. Whatever
# fails is run again symbolized, for a readable report.
if ! (cd "$root/build-asan" && ASAN_OPTIONS=symbolize=0 ctest --output-on-failure -j "$jobs" -LE not_sanitized "$@"); then
  echo "== the sanitizer suite's failures again, with symbolized reports"
  (cd "$root/build-asan" && ctest --rerun-failed --output-on-failure) || true
  exit 1
fi
