# Sourced by tools/setup.sh and tools/test.sh: the one configuration of build/. README command 1 builds the library,
# the `phiq` command and the Python package in it; command 2 builds the rest of the same tree (tests, benchmarks)
# without recompiling what command 1 built. Unity build: CMake joins each target's files in groups of 8, so that the
# headers (CLI11's and Eigen's inline code above all) are compiled once a group rather than once a file.
phiq_configure_release() {
  cmake -S "$1" -B "$1/build" -DCMAKE_BUILD_TYPE=Release -DCMAKE_UNITY_BUILD=ON "${@:2}" >/dev/null
}
