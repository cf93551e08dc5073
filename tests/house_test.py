"""The house rules that keep the tree tidy, checked on the whole tree (ctest `house`):

- every document within its budget (words or lines, DOCUMENT_BUDGETS);
- every path a README names exists, every `phiq COMMAND --option` a README writes is an option of that command, and
  tools/README.md names every option of every command (both ways, against `phiq COMMAND --help`);
- no source file over 600 lines (tests and scripts included), and no C++ function over 150 lines but those listed
  in LONG_FUNCTIONS, each at most as long as it is listed (the list only shrinks);
- every C++ file formatted as .clang-format says (clang-format 14 --dry-run), when clang-format is installed.

Run: PHIQ_CLI=build/tools/phiq /usr/bin/python3 -m pytest -q tests/house_test.py
"""
import glob
import os
import re
import shutil
import subprocess

import pytest

from function_lengths import function_lengths

ROOT = os.path.normpath(os.path.join(os.path.dirname(os.path.abspath(__file__)), ".."))
SKIP_DIRS = {".git", "build", "build-asan", "node_modules", "gltf_validator", "__pycache__"}
SOURCE_SUFFIXES = (".cpp", ".hpp", ".h", ".inc", ".py", ".sh", ".js", ".css", ".html", ".cmake", ".in")
CXX_SUFFIXES = (".cpp", ".hpp", ".h", ".inc")
MAX_SOURCE_LINES = 600
MAX_FUNCTION_LINES = 150
# Functions allowed over MAX_FUNCTION_LINES, with their length (none today): a function listed here may not grow, and
# one not listed may not pass the limit. The list only shrinks.
LONG_FUNCTIONS = {}

# (document, unit, budget): README.md and tests/README.md in words, bench/README.md in lines (issue "the first
# hour"); the reference documents get a ceiling near their size, so that a page that grows is cut, not appended to.
DOCUMENT_BUDGETS = [
    ("README.md", "words", 1500),
    ("tests/README.md", "words", 1500),
    ("bench/README.md", "lines", 300),
    ("tools/README.md", "words", 10000),
    ("models/README.md", "words", 9000),
    ("engine/README.md", "words", 4500),
    ("engine/python/README.md", "words", 1500),
]


def tree_files(suffixes=None, names=()):
    for dirpath, dirnames, filenames in os.walk(ROOT):
        dirnames[:] = sorted(d for d in dirnames if d not in SKIP_DIRS and not d.startswith("build"))
        for f in sorted(filenames):
            if (suffixes and f.endswith(suffixes)) or f in names:
                yield os.path.join(dirpath, f)


def readmes():
    return [p for p in tree_files(names=("README.md",))]


def rel(path):
    return os.path.relpath(path, ROOT)


@pytest.mark.parametrize("doc,unit,budget", DOCUMENT_BUDGETS, ids=[d for d, _, _ in DOCUMENT_BUDGETS])
def test_document_within_its_budget(doc, unit, budget):
    with open(os.path.join(ROOT, doc), encoding="utf-8") as f:
        text = f.read()
    size = len(text.split()) if unit == "words" else text.count("\n")
    assert size <= budget, f"{doc}: {size} {unit}, over its budget of {budget}: cut what a user does not need"


# A path in a README: a run of path characters with a slash, starting at a top-level folder of the tree, ending in
# a file name or a folder. Placeholders (NAME, OUT.csv) are skipped; globs and {a,b} are judged by what they match.
TOP = ("engine", "tools", "tests", "bench", "models", ".ci")
PATH = re.compile(r"(?<![\w./-])((?:" + "|".join(re.escape(t) for t in TOP) + r")/(?:[\w./*-]|\{[\w.,*-]+\})*"
                  r"(?:[\w*/]|\{[\w.,*-]+\}))")
# A path out of the repository (../something): a user's clone has nothing there. Only the tests read the project's
# shared test data beside the clone (tests/README.md says where).
OUTSIDE = re.compile(r"(?<![\w.])\.\./[\w.-]+/")


def named_paths(text):
    for m in PATH.finditer(text):
        p = m.group(1).rstrip(".,")
        if re.search(r"[A-Z]{3,}", p.split("/")[-1]) and not os.path.exists(os.path.join(ROOT, p)):
            continue  # a placeholder such as models/NAME.yaml or tools/OUT.csv
        yield p


def path_exists(p, doc_dir):
    for base in (ROOT, doc_dir):
        full = os.path.normpath(os.path.join(base, p))
        if "{" in p:
            head, alts, tail = re.match(r"(.*)\{([^}]*)\}(.*)", p).groups()
            return all(path_exists(head + a + tail, doc_dir) for a in alts.split(","))
        if "*" in p:
            if glob.glob(full, recursive=True):
                return True
        elif os.path.exists(full):
            return True
    return False


@pytest.mark.parametrize("doc", [rel(p) for p in readmes()])
def test_every_path_a_readme_names_exists(doc):
    full = os.path.join(ROOT, doc)
    with open(full, encoding="utf-8") as f:
        text = f.read()
    missing = sorted({p for p in named_paths(text) if not path_exists(p, os.path.dirname(full))})
    assert not missing, f"{doc} names paths that do not exist: {missing}"
    if doc != os.path.join("tests", "README.md"):
        outside = sorted({m.group(0) for m in OUTSIDE.finditer(text)
                          if not os.path.exists(os.path.normpath(os.path.join(os.path.dirname(full), m.group(0))))
                          or os.path.relpath(os.path.normpath(os.path.join(os.path.dirname(full), m.group(0))),
                                             ROOT).startswith("..")})
        assert not outside, f"{doc} points out of the repository, where a user's clone has nothing: {outside}"


def phiq_cli():
    cli = os.environ.get("PHIQ_CLI")
    if not cli or not os.access(cli, os.X_OK):
        pytest.skip("PHIQ_CLI (the built phiq) not given")
    return cli


def help_text(*args):
    return subprocess.run([phiq_cli(), *args, "--help"], capture_output=True, text=True, check=True).stdout


def commands_and_options():
    commands = []
    on = False
    for line in help_text().splitlines():
        if line.startswith("Subcommands:"):
            on = True
        elif on and line.strip():
            commands.append(line.split()[0])
    assert commands, "no commands in phiq --help"
    return {c: set(re.findall(r"^ +(?:-[a-zA-Z], ?)?(--[a-z][a-z0-9-]*)", help_text(c), re.M)) for c in commands}


def test_tools_readme_names_every_option_and_no_other():
    options = commands_and_options()
    with open(os.path.join(ROOT, "tools/README.md"), encoding="utf-8") as f:
        text = f.read()
    named = set(re.findall(r"(?<![\w-])(--[a-z][a-z0-9-]*)", text))
    every = set().union(*options.values()) | {"--help", "--version"}
    assert not (every - named), f"tools/README.md does not document {sorted(every - named)}"
    # An option a table of it documents (first cell of a row) belongs to a command or to one of tools/' scripts.
    scripts = ""
    for p in tree_files(suffixes=(".sh", ".py")):
        if rel(p).startswith("tools" + os.sep):
            with open(p, encoding="utf-8") as f:
                scripts += f.read()
    tabled = {o for line in text.splitlines() if line.startswith("|")
              for o in re.findall(r"(?<![\w-])(--[a-z][a-z0-9-]*)", line.split("|")[1])}
    unknown = sorted(o for o in tabled - every if o not in scripts)
    assert not unknown, f"tools/README.md documents options no command or script has: {unknown}"


def test_tools_readme_quotes_the_version_line_phiq_prints():
    # Harnesses read the format versions from tools/README.md's quote of `phiq --version`: it is the binary's line.
    printed = subprocess.run([phiq_cli(), "--version"], capture_output=True, text=True, check=True).stdout.strip()
    with open(os.path.join(ROOT, "tools/README.md"), encoding="utf-8") as f:
        quoted = re.search(r"`phiq --version` prints `([^`]*)`", " ".join(f.read().split()))
    assert quoted, "tools/README.md does not quote `phiq --version`"
    assert quoted.group(1) == " ".join(printed.split()), f"tools/README.md quotes {quoted.group(1)!r}, phiq prints {printed!r}"


# `phiq COMMAND ... --option` written on one line of a README (a command line in a code block or in the text)
COMMAND_LINE = re.compile(r"phiq (\w[\w-]*)((?: +[^\s`|;]+)*)")


def test_every_command_line_in_a_readme_uses_options_of_its_command():
    options = commands_and_options()
    wrong = []
    for path in readmes():
        with open(path, encoding="utf-8") as f:
            for n, line in enumerate(f, 1):
                for m in COMMAND_LINE.finditer(line):
                    command, rest = m.group(1), m.group(2)
                    if command not in options:
                        continue
                    for o in re.findall(r"(?<![\w-])(--[a-z][a-z0-9-]*)", rest):
                        if o not in options[command] and o not in ("--help", "--version"):
                            wrong.append(f"{rel(path)}:{n}: phiq {command} has no option {o}")
    assert not wrong, "\n".join(wrong)


def test_no_source_file_over_600_lines():
    long_files = []
    for p in tree_files(suffixes=SOURCE_SUFFIXES, names=("CMakeLists.txt",)):
        with open(p, encoding="utf-8", errors="replace") as f:
            n = sum(1 for _ in f)
        if n > MAX_SOURCE_LINES:
            long_files.append(f"{rel(p)}: {n} lines")
    assert not long_files, f"over {MAX_SOURCE_LINES} lines (split by subject): {long_files}"


def test_no_function_over_150_lines():
    long_functions = []
    for p in tree_files(suffixes=CXX_SUFFIXES):
        for name, line, n in function_lengths(p):
            allowed = LONG_FUNCTIONS.get((rel(p), name), MAX_FUNCTION_LINES)
            if n > allowed:
                long_functions.append(f"{rel(p)}:{line}: {name}, {n} lines (at most {allowed})")
    assert not long_functions, "functions too long (split them into named parts): " + "; ".join(long_functions)


def test_cxx_sources_are_formatted():
    exe = shutil.which("clang-format-14") or shutil.which("clang-format")
    if exe is None:
        pytest.skip("clang-format (Debian's clang-format) is not installed")
    files = [p for p in tree_files(suffixes=CXX_SUFFIXES)]
    done = subprocess.run([exe, "--dry-run", "-Werror", "--style=file", *files], capture_output=True, text=True,
                          cwd=ROOT)
    lines = sorted({rel(l.split(":")[0]) for l in done.stderr.splitlines() if ": error:" in l})
    assert done.returncode == 0, ("not formatted as .clang-format says (run tools/format.sh): " +
                                  ", ".join(lines[:20]) + (f" and {len(lines) - 20} more files" if len(lines) > 20 else ""))


def test_readme_cpp_tour_is_the_compiled_one():
    # README.md's C++ block (its #include aside) is the code tests/test_api_example.cpp compiles and checks.
    with open(os.path.join(ROOT, "tests", "test_api_example.cpp"), encoding="utf-8") as f:
        block = f.read().split("// ---- begin README ----\n")[1].split("// ---- end README ----")[0]
    compiled = [l[2:] if l.startswith("  ") else l for l in block.rstrip().split("\n")]
    with open(os.path.join(ROOT, "README.md"), encoding="utf-8") as f:
        shown = re.search(r"```cpp\n(.*?)```", f.read(), re.S).group(1).rstrip().split("\n")
    assert [l for l in shown if not l.startswith("#include")] == compiled, "README.md's C++ tour drifted"
