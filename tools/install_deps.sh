#!/usr/bin/env bash
# Installs phiq's dependencies from Debian 12's packages (nothing else is downloaded).
#   tools/install_deps.sh          what the library, the `phiq` command and the Python package need to build and run
#                                  (README command 1, tools/setup.sh)
#   tools/install_deps.sh --test   the above and the test suite's tools: sanitizers, fuzzing, headless Chromium,
#                                  Node.js and the glTF validator, the benchmark peers (README command 2, tools/test.sh)
#   tools/install_deps.sh --test-build
#                                  the first list and what configuring the test build finds (the benchmark peers,
#                                  Doxygen): tools/test.sh installs the rest with --test while the Release build runs
# Idempotent: does nothing when every package is already installed. Needs root (or sudo).
set -euo pipefail

packages=(
  build-essential cmake pkg-config
  ninja-build          # the build's generator (tools/build_config.sh): compiles a target's files while those it links are still building
  libeigen3-dev        # Eigen 3.4: vectors, dense reference LU, splines for tabulated laws
  libsuitesparse-dev   # SuiteSparse 5.12: UMFPACK, CHOLMOD, KLU, SPQR
  libtbb-dev           # oneTBB: parallel drive steps
  libyaml-cpp-dev      # scene parser (YAML, with line/column of every node)
  libginac-dev         # exact symbolic derivatives of equation constraints
  libcli11-dev         # command line parser
  nlohmann-json3-dev   # JSON output (check --json, summaries)
  libhdf5-dev          # HDF5 1.10 (serial flavour, C interface): `phiq run -o OUT.h5`, `phiq compare` of HDF5
  libassimp-dev        # Assimp 5.2: the mesh files (STL, OBJ) of a body's parts (engine/src/parts/mesh_file.cpp)
  libfcl-dev libccd-dev  # FCL 0.7 and libccd: distances between parts (engine/src/clearance/, `phiq clearance`)
  liburdfdom-dev liburdfdom-headers-dev libtinyxml2-dev  # URDF (urdfdom 3) and MJCF (tinyxml2 9) files read as scenes
  libsdformat-dev      # SDFormat 12: SDF files read as scenes (engine/src/import/sdf_reader.cpp)
  libjs-three          # three.js r111 and its OrbitControls, embedded at build time into `phiq animate -o OUT.html`
  openmpi-bin libopenmpi-dev  # `mpirun -np K phiq batch` (tools/cli/batch_ranks.hpp); found at configure time
  python3-dev python3-pybind11 pybind11-dev  # the Python package phiq (engine/python/), for /usr/bin/python3
  python3-numpy python3-scipy  # phiq's arrays, and its Jacobian as a scipy.sparse.csc_matrix
  mypy                 # stubgen: the package's type stubs (_phiq.pyi), made at every build of the module
  help2man             # the man page phiq.1, generated from `phiq --help` at install
  libgtest-dev libbenchmark-dev  # GoogleTest and Google Benchmark: found when the tree is configured, so that
                                 # README command 2 builds in command 1's build directory without reconfiguring it
)
test_build_packages=(  # found when build/ is configured
  doxygen              # API reference (target phiq_docs, ctest api_docs)
  libsimbody-dev       # peer for the benchmark (bench/bench_peers.cpp); skipped with a message if absent
  libmumps-dev         # MUMPS, distributed sparse LU: bench/bench_mumps.cpp against KLU
)
test_packages=(
  "${test_build_packages[@]}"
  clang libclang-rt-14-dev  # libFuzzer + AddressSanitizer/UndefinedBehaviorSanitizer build (tests/fuzz)
  lld                  # the sanitizer build's linker: 1.1 s of CPU for phiq_tests against GNU ld's 4.7 s
  python3-matplotlib   # tools/plot/plot_bench.py (the figure of bench/README.md)
  python3-h5py python3-pytest python3-pandas  # the pytest suites (tests/python), HDF5 read back independently
  nodejs               # the Khronos glTF-Validator on `phiq animate`'s .glb files (ctest gltf_validator), and
                       # Chromium driven over its DevTools pipe (ctest browser_viewer)
  chromium             # headless browser of ctest browser_viewer (the HTML viewer's pages)
  phcpack              # PHCpack's `phc -b`: phiq modes checked against it (tests/test_modes_phc.cpp, bench/bench_modes.cpp)
)
test=0
case "${1:-}" in
  --test) test=1; packages+=("${test_packages[@]}") ;;
  --test-build) packages+=("${test_build_packages[@]}") ;;
esac
# npm (Debian's package, unless a node install already brings its own) installs the validator below
if [ "$test" = 1 ] && ! command -v npm >/dev/null 2>&1; then packages+=(npm); fi

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
[ "$test" = 1 ] || exit 0

# The Khronos glTF-Validator (npm package gltf-validator, a fixed version) into tools/gltf_validator/, beside the
# sources and ignored by git: the tests run it from there and download nothing themselves.
validator_dir="$(cd "$(dirname "$0")" && pwd)/gltf_validator"
if [ ! -f "$validator_dir/node_modules/gltf-validator/package.json" ]; then
  echo "install_deps.sh: installing gltf-validator into $validator_dir" >&2
  mkdir -p "$validator_dir"
  npm install --silent --no-audit --no-fund --prefix "$validator_dir" gltf-validator@2.0.0-dev.3.10
fi
