"""A parameter study in a loop: the crank-slider's stroke for several crank lengths, each scene sharing the first
one's symbolic analysis (same structure, new numbers). The stroke of an in-line crank-slider is 2 r.

    python3 parameter_study.py [SCENE]   (default: models/seed/crank_slider_mixed.yaml)
"""
import os
import sys

import phiq

here = os.path.dirname(os.path.abspath(__file__))
path = sys.argv[1] if len(sys.argv) > 1 else os.path.join(here, "..", "..", "..", "models", "seed",
                                                           "crank_slider_mixed.yaml")
base = phiq.load_scene(path)
for r in (0.1, 0.2, 0.3, 0.4):
    scene = phiq.load_scene(path, parameters={"L2": r}, share_analysis_with=base)
    result = phiq.run_sweep(scene, steps=360, velocities=False, accelerations=False).raise_for_status()
    stroke = result["xB"].max() - result["xB"].min()
    assert abs(stroke - 2 * r) < 1e-9, (r, stroke)
    print(f"crank {r:.1f} m: stroke {stroke:.12f} m ({result.summary['counters']['newton_iterations']} Newton "
          "iterations)")
