# Sourced by tests/plot_*_test.sh (POSIX sh): set `name`, `script` and `dir` before sourcing. Defines fail(),
# expect_error() and `py`, the first Python 3 that has matplotlib: $PYTHON, python3 on PATH (may be a pyenv or venv
# one without it), then Debian's /usr/bin/python3 (python3-matplotlib installs there); exits 77 (skipped) if none.
fail() { echo "$name: FAIL: $*" >&2; exit 1; }

py=""
for cand in ${PYTHON:-} python3 /usr/bin/python3; do
  if command -v "$cand" >/dev/null 2>&1 && "$cand" -c 'import matplotlib' 2>/dev/null; then py=$cand; break; fi
done
[ -n "$py" ] ||
  { echo "$name: SKIP: no python3 with matplotlib (Debian: python3-matplotlib, tools/install_deps.sh)"; exit 77; }

# expect_error WHAT ARGS...: the script on ARGS fails with one line on stderr, exit status 1, and no SVG.
expect_error() {
  what=$1; shift
  "$py" "$script" "$@" -o "$dir/error.svg" 2>"$dir/err.txt"; st=$?
  [ "$st" -eq 1 ] || fail "$what: exit status $st, expected 1"
  [ "$(wc -l <"$dir/err.txt")" -eq 1 ] || fail "$what: stderr is not one line: $(cat "$dir/err.txt")"
  [ -e "$dir/error.svg" ] && fail "$what: an SVG was written"
  return 0
}
