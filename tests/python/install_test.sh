#!/bin/sh
# The Python package as README command (1) installs it: `cmake --install BUILD --component python` into a prefix,
# then `import phiq` from Debian's /usr/bin/python3 in a fresh environment (no PYTHONPATH). The prefix is a home
# directory's ~/.local, which Debian's python3 searches by itself (the user site directory): what a user without
# root gets; /usr/local (root) is the same file copy into lib/python3.11/dist-packages.
#   install_test.sh BUILD_DIR SCRATCH_DIR
set -eu
build="$1"
home="$2/home"
rm -rf "$2"
mkdir -p "$home"
cmake --install "$build" --component python --prefix "$home/.local" >/dev/null
test -f "$home/.local/lib/python3.11/site-packages/phiq/_phiq.pyi"
test ! -e "$home/.local/lib/python3.11/site-packages/phiq/__pycache__"
cd "$home"
env -i HOME="$home" PATH=/usr/bin:/bin /usr/bin/python3 -c '
import os, phiq
assert phiq.__file__.startswith(os.path.expanduser("~/.local/")), phiq.__file__
assert phiq.__version__
print("import phiq:", phiq.__file__, phiq.__version__)
'
