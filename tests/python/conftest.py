"""Shared fixtures of the Python tests: the phiq CLI and the models folder (set by ctest, tests/CMakeLists.txt)."""
import os

import pytest

PHIQ = os.environ.get("PHIQ_CLI", "phiq")
MODELS = os.environ.get("PHIQ_MODELS_DIR", os.path.join(os.path.dirname(__file__), "..", "..", "models"))


@pytest.fixture
def models():
    return MODELS


@pytest.fixture
def phiq_cli():
    return PHIQ


def package_env():
    """The environment for a child python3 that imports the same phiq package as this test process."""
    import phiq
    env = dict(os.environ)
    env["PYTHONPATH"] = os.path.dirname(os.path.dirname(os.path.abspath(phiq.__file__)))
    return env
