"""The notes' crank-slider loaded from its scene, swept, and compared with its closed form:
x_B = r cos θ + sqrt(L² − r² sin² θ), and its first two time derivatives.

    python3 crank_slider_closed_form.py [SCENE]   (default: models/seed/crank_slider_mixed.yaml)
"""
import os
import sys

import numpy as np

import phiq

here = os.path.dirname(os.path.abspath(__file__))
path = sys.argv[1] if len(sys.argv) > 1 else os.path.join(here, "..", "..", "..", "models", "seed",
                                                           "crank_slider_mixed.yaml")
scene = phiq.load_scene(path)
result = phiq.run_sweep(scene, threads=2).raise_for_status()

r, L, w = 0.3, 1.0, 2.0  # the scene's L2, L3 and the motor's rate
th = w * result.t
s, c = np.sin(th), np.cos(th)
root = np.sqrt(L * L - (r * s) ** 2)
x = r * c + root
v = w * (-r * s - r * r * s * c / root)
a = w * w * (-r * c - r * r * (c * c - s * s) / root - r ** 4 * s * s * c * c / root ** 3)
errors = [np.abs(result["xB"] - x).max(), np.abs(result["xB.v"] - v).max(), np.abs(result["xB.a"] - a).max()]
assert max(errors) < 1e-9, errors
print(f"{len(result)} rows on {result.summary['threads']} threads: x_B, ẋ_B, ẍ_B within "
      f"{errors[0]:.1e}, {errors[1]:.1e}, {errors[2]:.1e} of the closed form")
