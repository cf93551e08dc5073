"""Tolerance analysis in Python: the crank-slider's slider position xB with link lengths made to tolerance (L2 and L3
normal, standard deviations 2 mm and 5 mm), its spread over the cycle estimated twice — to first order from the
nominal sweep's sensitivities, σ² = (∂xB/∂L2 σ2)² + (∂xB/∂L3 σ3)², and by Monte Carlo, a batch of sampled cases swept
in parallel (run_batch) — which agree within the Monte Carlo estimate's own error, relative 1/√(2(n − 1)).

    python3 monte_carlo_tolerance.py [SCENE]   (default: models/seed/crank_slider_mixed.yaml)
"""
import os
import sys

import numpy as np

import phiq

here = os.path.dirname(os.path.abspath(__file__))
path = sys.argv[1] if len(sys.argv) > 1 else os.path.join(here, "..", "..", "..", "models", "seed",
                                                           "crank_slider_mixed.yaml")
scene = phiq.load_scene(path)
sigma = {"L2": 0.002, "L3": 0.005}  # m

nominal = phiq.run_sweep(scene, sensitivities=list(sigma)).raise_for_status()
xb = nominal.coordinate_names.index("xB")
linear = np.sqrt(sum((nominal.sensitivity(p)[:, xb] * s) ** 2 for p, s in sigma.items()))

n = 2000
rng = np.random.default_rng(25)  # reproducible
cases = {p: rng.normal(scene.parameters[p], s, n) for p, s in sigma.items()}
batch = phiq.run_batch(scene, cases, velocities=False, accelerations=False).raise_for_status()
monte_carlo = batch["xB"].std(axis=0, ddof=1)  # over the cases, at each row

error = np.abs(monte_carlo / linear - 1)
bound = 4.5 / np.sqrt(2 * (n - 1))  # 4.5 standard errors of a sample standard deviation
assert error.max() < bound, (error.max(), bound)
print(f"xB spread over the cycle: {linear.min() * 1e3:.3f} to {linear.max() * 1e3:.3f} mm to first order; "
      f"Monte Carlo of {n} cases ({batch.seconds:.2f} s on {batch.threads} threads) within "
      f"{error.max() * 100:.1f} % of it (its own error {100 / np.sqrt(2 * (n - 1)):.1f} %)")
