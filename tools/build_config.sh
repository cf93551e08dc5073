# Sourced by tools/setup.sh and tools/test.sh: the one configuration of build/. README command 1 builds the library,
# the `phiq` command and the Python package in it; command 2 builds the rest of the same tree (tests, benchmarks)
# without recompiling what command 1 built. Unity build: CMake joins each target's files in groups of 8, so that the
# headers (CLI11's and Eigen's inline code above all) are compiled once a group rather than once a file.
# Ninja rather than Make: Make starts a target's compiles only once every target it links is built (the command's
# files waited for the engine's link, the engine's hot files for its cold ones under the sanitizers, the tests for the
# command: about a quarter of the two cores idle in each build), Ninja waits only at the link. A build directory
# made with another generator keeps it (CMake cannot change it in place).
phiq_generator() {
  if [ -f "$1/CMakeCache.txt" ] && ! grep -qx 'CMAKE_GENERATOR:INTERNAL=Ninja' "$1/CMakeCache.txt"; then return; fi
  echo "-GNinja"
}
phiq_configure_release() {
  cmake -S "$1" -B "$1/build" $(phiq_generator "$1/build") -DCMAKE_BUILD_TYPE=Release -DCMAKE_UNITY_BUILD=ON "${@:2}" >/dev/null
}
