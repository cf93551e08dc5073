#!/usr/bin/env bash
# ctest bash_completion: tools/completion/phiq.bash offers exactly the commands `phiq --help` lists, and for each
# command exactly the long options its `--help` lists (so that an option added to the program and not to the
# completion fails here), and completes the values of a few options.
# Usage: bash_completion_test.sh PHIQ COMPLETION_SCRIPT
set -uo pipefail
phiq="$1"; script="$2"
# shellcheck source=/dev/null
source "$script"
status=0

# COMPREPLY for the command line "$@" with the cursor on its last word, sorted, one line
complete_line() {
  COMP_WORDS=("$@")
  COMP_CWORD=$(($# - 1))
  COMPREPLY=()
  _phiq
  printf '%s\n' "${COMPREPLY[@]}" | sort | tr '\n' ' '
}
check() {  # what, expected, got
  if [ "$2" != "$3" ]; then
    echo "bash_completion: $1: expected '$2', got '$3'" >&2
    status=1
  fi
}

commands=$("$phiq" --help | awk '/^Subcommands:/ {on = 1; next} on && NF {print $1}' | sort | tr '\n' ' ')
[ -n "$commands" ] || { echo "bash_completion: no commands in phiq --help" >&2; exit 1; }
check "commands" "$(printf '%s\n' $commands --help --version | sort | tr '\n' ' ')" "$(complete_line phiq '')"
for c in $commands; do
  opts=$("$phiq" "$c" --help | grep -oE '^ +(-[a-zA-Z],)?--[a-z-]+' | sed 's/.*--/--/' | sort | tr '\n' ' ')
  check "phiq $c options" "$opts" "$(complete_line phiq "$c" --)"
done
check "run --progress values" "always auto never " "$(complete_line phiq run --progress '')"
check "run --names values" "dotted identifiers " "$(complete_line phiq run --names '')"
check "generate kinds" "chain3d grid nfourbar scissor " "$(complete_line phiq generate '')"
exit $status
