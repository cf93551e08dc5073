"""A four-bar built in code (natural coordinates), swept through a full turn of its crank, with its coupler curve
plotted by matplotlib. Checks that every row keeps the rocker's length and the coupler's (loop closure).

    python3 fourbar_plot.py [OUT.png]
"""
import math
import sys

import matplotlib

matplotlib.use("Agg")  # files only: works without a display
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

import phiq  # noqa: E402

ground, crank, coupler, rocker = 1.0, 0.4, 1.2, 1.0  # a Grashof crank-rocker

b = phiq.SceneBuilder("fourbar", description="crank-rocker in natural coordinates")
b.parameters(L1=ground, L2=crank, L3=coupler, L4=rocker)
b.coordinates(theta=0.0, xA=0.4, yA=0.0, xB=1.1, yB=1.0)
b.point("O", [0, 0])
b.point("C", ["L1", 0])
b.point("A", ["xA", "yA"])
b.point("B", ["xB", "yB"])
b.constraint("crank", type="polar", point="A", origin="O", length="L2", angle="theta")
b.constraint("coupler", type="distance", points=["A", "B"], length="L3")
b.constraint("rocker", type="distance", points=["C", "B"], length="L4")
b.driver("motor", coordinate="theta", law={"type": "linear", "initial": 0, "rate": 1})
b.time(start=0, end=2 * math.pi, steps=360)
b.output(velocities=True, accelerations=True, points=["A", "B"])
result = phiq.run_sweep(b.build()).raise_for_status()

A, B = result.point("A"), result.point("B")
coupler_error = np.abs(np.hypot(*(B - A).T) - coupler).max()
rocker_error = np.abs(np.hypot(B[:, 0] - ground, B[:, 1]) - rocker).max()
assert coupler_error < 1e-9 and rocker_error < 1e-9, (coupler_error, rocker_error)

fig, ax = plt.subplots(figsize=(5, 4))
ax.plot(B[:, 0], B[:, 1], label="B (rocker tip)")
ax.plot(A[:, 0], A[:, 1], label="A (crank tip)")
for k in range(0, len(result), 45):  # a few poses
    ax.plot([0, A[k, 0], B[k, 0], ground], [0, A[k, 1], B[k, 1], 0], "k-", lw=0.8, alpha=0.5)
ax.set_aspect("equal")
ax.set_xlabel("x (m)")
ax.set_ylabel("y (m)")
ax.legend()
out = sys.argv[1] if len(sys.argv) > 1 else "fourbar.png"
fig.savefig(out)
print(f"{len(result)} rows; loop closure within {max(coupler_error, rocker_error):.1e} m; wrote {out}")
