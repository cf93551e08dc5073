#!/usr/bin/env bash
# Formats C++ sources as .clang-format says (Debian's clang-format 14). ctest house fails on a file it would change.
#   tools/format.sh          the files changed against HEAD (staged, unstaged and new)
#   tools/format.sh --all    every C++ file of the tree
set -euo pipefail
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
cd "$root"
if [ "${1:-}" = "--all" ]; then
  git ls-files -- '*.cpp' '*.hpp' '*.h' '*.inc' | xargs -r clang-format -i --style=file
else
  { git diff --name-only HEAD; git ls-files --others --exclude-standard; } | grep -E '\.(cpp|hpp|h|inc)$' |
    sort -u | while read -r f; do [ -f "$f" ] && clang-format -i --style=file "$f"; done
fi
