"""A parameter study in a loop: the crank-slider's stroke for several crank lengths, each scene sharing the first
one's symbolic analysis (same structure, new numbers). The stroke of an in-line crank-slider is 2 r, and its
sensitivity to the crank, from ∂x_B/∂r at the stroke's ends (run_sweep's sensitivities), is 2.

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
    result = phiq.run_sweep(scene, steps=360, velocities=False, accelerations=False,
                            sensitivities=["L2"]).raise_for_status()
    stroke = result["xB"].max() - result["xB"].min()
    assert abs(stroke - 2 * r) < 1e-9, (r, stroke)
    xb = result.coordinate_names.index("xB")
    dx_dr = result.sensitivity("L2")[:, xb]
    d_stroke = dx_dr[result["xB"].argmax()] - dx_dr[result["xB"].argmin()]
    assert abs(d_stroke - 2.0) < 1e-9, (r, d_stroke)
    print(f"crank {r:.1f} m: stroke {stroke:.12f} m, d(stroke)/dr {d_stroke:.12f} "
          f"({result.summary['counters']['newton_iterations']} Newton iterations)")
