"""The examples of engine/python/examples run as they are documented (each asserts its own closed form or
invariant and exits non-zero otherwise), and the package type-checks with mypy through its stubs: the examples
pass, a call with a wrong argument type is reported."""
import glob
import os
import shutil
import subprocess
import sys

import pytest

from conftest import package_env

EXAMPLES = os.path.join(os.path.dirname(__file__), "..", "..", "engine", "python", "examples")


@pytest.mark.parametrize("example", sorted(glob.glob(os.path.join(EXAMPLES, "*.py"))), ids=os.path.basename)
def test_example_runs(example, tmp_path):
    args = [sys.executable, example]
    if "plot" in example:
        pytest.importorskip("matplotlib")
        args.append(str(tmp_path / "figure.png"))
    done = subprocess.run(args, capture_output=True, text=True, cwd=tmp_path, env=package_env())
    assert done.returncode == 0, done.stderr
    assert done.stdout.strip()
    if "plot" in example:
        with open(tmp_path / "figure.png", "rb") as f:
            assert f.read(8) == b"\x89PNG\r\n\x1a\n"


def mypy(*files, cwd):
    if shutil.which("mypy") is None:
        pytest.skip("mypy (Debian's package mypy) is not installed")
    return subprocess.run(["mypy", "--no-incremental", "--cache-dir", os.devnull, "--ignore-missing-imports",
                           *files], capture_output=True, text=True, cwd=cwd, env=package_env())


def test_examples_type_check():
    done = mypy(*sorted(glob.glob(os.path.join(EXAMPLES, "*.py"))), cwd=EXAMPLES)
    assert done.returncode == 0, done.stdout


def test_a_wrong_argument_type_is_reported(tmp_path):
    bad = tmp_path / "bad.py"
    bad.write_text("import phiq\nscene = phiq.load_scene(3)\nws = phiq.Workspace(scene)\n")
    done = mypy(str(bad), cwd=tmp_path)
    assert done.returncode == 1
    assert 'Argument 1 to "load_scene" has incompatible type "int"' in done.stdout
    assert 'Argument 1 to "Workspace" has incompatible type "Scene"' in done.stdout
