"""Shared fixtures of the Python tests: the phiq CLI and the models folder (set by ctest, tests/CMakeLists.txt)."""
import os

import pytest

PHIQ = os.environ.get("PHIQ_CLI", "phiq")
MODELS = os.environ.get("PHIQ_MODELS_DIR", os.path.join(os.path.dirname(__file__), "..", "..", "models"))


# A four-bar with every kind of output: points (one on a body), the driver, a constraint's residual, the largest
# residual and rcond (tests/cli_test_support.hpp, kFourbarOutputs).
EVERY_OUTPUT = """phiq: 1
name: fourbar_outputs
parameters: {L1: 1.0, L2: 0.4, L3: 1.2, L4: 1.0}
coordinates: {theta2: 0.0, xA: 0.4, yA: 0.0, x3: 0.7, y3: 0.5, psi3: 1.0, xB: 1.1, yB: 1.0}
points: {O: [0, 0], A: [xA, yA], B: [xB, yB], C: [L1, 0]}
bodies: {coupler: [x3, y3, psi3]}
constraints:
  - {name: crank, type: polar, point: A, origin: O, length: L2, angle: theta2}
  - {name: A, type: revolute, between: [{body: coupler, at: [-L3/2, 0]}, {point: A}]}
  - {name: B, type: revolute, between: [{body: coupler, at: [L3/2, 0]}, {point: B}]}
  - {name: rocker, type: distance, points: [C, B], length: L4}
drivers:
  - {name: motor, coordinate: theta2, law: {type: linear, initial: 0, rate: 1}}
time: {start: 0, end: 2*pi, steps: 72}
output:
  velocities: true
  accelerations: true
  points: [B, {name: P, body: coupler, at: [0, 0.3]}]
  drivers: [motor]
  residuals: [rocker]
  max_residual: true
  rcond: true
"""


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
