"""Shared fixtures of the Python tests: the phiq CLI and the models folder (set by ctest, tests/CMakeLists.txt)."""
import math
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


def crank_slider_builder(**output):
    """The seed's crank-slider (models/seed/crank_slider_mixed.yaml) in a SceneBuilder, q̇ and q̈ in its output with
    `output`'s other entries."""
    import phiq
    b = phiq.SceneBuilder("crank_slider_mixed")
    b.parameters(L2=0.3, L3=1.0)
    b.coordinates(theta2=0.0, xA=0.28, yA=0.03, xB=1.25)
    b.point("O", [0, 0])
    b.point("A", ["xA", "yA"])
    b.point("B", ["xB", 0])
    b.constraint("crank", type="polar", point="A", origin="O", length="L2", angle="theta2")
    b.constraint("rod", type="distance", points=["A", "B"], length="L3")
    b.driver("motor", coordinate="theta2", law={"type": "linear", "initial": 0, "rate": 2})
    b.time(start=0, end=math.pi, steps=180)
    b.output(velocities=True, accelerations=True, **output)
    return b


def seconds_to_interrupt(load: str, call: str) -> float:
    """Runs `load` (Python statements making `scene`) then `call` (a long phiq call) in a child python3, sends it
    SIGINT half a second into the call, and returns how long after the call's start KeyboardInterrupt was raised
    (the test fails if the call finished or the child did not stop within 2 minutes)."""
    import signal
    import subprocess
    import sys
    import textwrap
    import time
    script = textwrap.dedent(f"""
        import time, phiq
        {load}
        print("sweeping", flush=True)
        start = time.monotonic()
        try:
            {call}
            print("finished", flush=True)
        except KeyboardInterrupt:
            print(f"interrupted after {{time.monotonic() - start:.2f}} s", flush=True)
    """)
    child = subprocess.Popen([sys.executable, "-c", script], stdout=subprocess.PIPE, text=True, env=package_env())
    assert child.stdout.readline().strip() == "sweeping"
    time.sleep(0.5)
    child.send_signal(signal.SIGINT)
    out, _ = child.communicate(timeout=120)
    assert out.startswith("interrupted after"), out
    return float(out.split()[2])
