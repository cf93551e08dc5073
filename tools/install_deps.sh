#!/usr/bin/env bash
# Installs phiq's build and test dependencies from Debian 12's packages (nothing else is downloaded).
# Idempotent: does nothing when every package is already installed. Needs root (or sudo).
set -euo pipefail

packages=(
  build-essential cmake pkg-config
  libeigen3-dev        # Eigen 3.4: vectors, dense reference LU, splines for tabulated laws
  libsuitesparse-dev   # SuiteSparse 5.12: UMFPACK, CHOLMOD, KLU, SPQR
  libtbb-dev           # oneTBB: parallel drive steps
  libyaml-cpp-dev      # scene parser (YAML, with line/column of every node)
  libginac-dev         # exact symbolic derivatives of equation constraints
  libcli11-dev         # command line parser
  nlohmann-json3-dev   # JSON output (check --json)
  clang libclang-rt-14-dev  # libFuzzer + AddressSanitizer/UndefinedBehaviorSanitizer build (tests/fuzz)
  doxygen              # API reference (target phiq_docs)
  libgtest-dev         # GoogleTest
  libbenchmark-dev     # Google Benchmark
  libsimbody-dev       # optional peer for the benchmark (bench/bench_peers.cpp); skipped with a message if absent
  python3-matplotlib   # tools/plot/plot_bench.py (the figure of bench/README.md); its ctest is skipped if absent
  libhdf5-dev          # HDF5 1.10 (serial flavour, C interface): `phiq run -o OUT.h5`, `phiq compare` of HDF5
  python3-h5py python3-numpy python3-pytest  # tests/python/test_hdf5_output.py; its ctest is skipped if absent
  python3-dev python3-pybind11 pybind11-dev  # the Python package phiq (engine/python/), for /usr/bin/python3
  python3-scipy        # phiq's Jacobian in Python is a scipy.sparse.csc_matrix
  python3-pandas       # SweepResult.to_pandas() (optional for users; its test needs it)
  mypy                 # stubgen: the package's type stubs (_phiq.pyi); the type-checking test of tests/python
  help2man             # the man page phiq.1, generated from `phiq --help` at install (skipped with a note if absent)
  nodejs               # runs the Khronos glTF-Validator on `phiq animate`'s .glb files (ctest gltf_validator), and
                       # drives Chromium over its DevTools pipe in ctest browser_viewer
  libjs-three          # three.js r111 and its OrbitControls, embedded at build time into `phiq animate -o OUT.html`
  chromium             # headless browser of ctest browser_viewer (the HTML viewer's pages; skipped if absent)
  openmpi-bin libopenmpi-dev  # `mpirun -np K phiq batch` (tools/cli/batch_ranks.hpp) and its ctest mpi_batch
  libmumps-dev         # MUMPS, distributed sparse LU: bench/bench_mumps.cpp against KLU (engine/README.md)
)
# npm (Debian's package, unless a node install already brings its own) installs the validator below
command -v npm >/dev/null 2>&1 || packages+=(npm)

missing=()
for p in "${packages[@]}"; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done
if [ ${#missing[@]} -gt 0 ]; then
  SUDO=""
  if [ "$(id -u)" -ne 0 ]; then
    command -v sudo >/dev/null || { echo "install_deps.sh: run as root (missing: ${missing[*]})" >&2; exit 1; }
    SUDO=sudo
  fi
  echo "install_deps.sh: installing ${missing[*]}" >&2
  $SUDO apt-get update -q
  DEBIAN_FRONTEND=noninteractive $SUDO apt-get install -y -q --no-install-recommends "${missing[@]}"
fi

# The Khronos glTF-Validator (npm package gltf-validator, a fixed version) into tools/gltf_validator/, beside the
# sources and ignored by git: the tests run it from there and download nothing themselves.
validator_dir="$(cd "$(dirname "$0")" && pwd)/gltf_validator"
if [ ! -f "$validator_dir/node_modules/gltf-validator/package.json" ]; then
  echo "install_deps.sh: installing gltf-validator into $validator_dir" >&2
  mkdir -p "$validator_dir"
  npm install --silent --no-audit --no-fund --prefix "$validator_dir" gltf-validator@2.0.0-dev.3.10
fi
