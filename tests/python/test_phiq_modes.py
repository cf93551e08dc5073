"""phiq.modes (engine/python/src/bind_modes.cpp): the four-bar's two assembly modes as arrays, each a placement that
solves the scene's equations (checked with the model's own residual), against Freudenstein's closed form, the start
system each solve tracked its paths from, the paths tracked against the total degree, a cam refused with its
constraint named, and failed paths named with why."""
import math
import os

import numpy as np
import pytest

import phiq

from conftest import MODELS


def test_fourbar_modes_are_two_placements_on_freudensteins_branches():
    scene = phiq.load_scene(os.path.join(MODELS, "seed", "fourbar_mixed.yaml"))
    r = phiq.modes(scene, 0.7, threads=1)
    assert r["q"].shape == (2, len(r["coordinates"]))
    assert r["paths"] == 4  # two circles' Bézout number: the total degree, every path tracked
    assert r["total_degree"] == 4
    assert r["method"] == "whole system"
    assert r["start_system"] == "total degree"  # its 4 paths are already the fewest
    assert not r["singular"].any()
    xb, yb = r["coordinates"].index("xB"), r["coordinates"].index("yB")
    # Freudenstein: the rocker's angles at crank 0.7 (a 0.4, b 1.2, c 1, d 1)
    a, b, c, d, th = 0.4, 1.2, 1.0, 1.0, 0.7
    k1, k2, k3 = d / a, d / c, (a * a - b * b + c * c + d * d) / (2 * a * c)
    A = math.cos(th) - k1 - k2 * math.cos(th) + k3
    B = -2 * math.sin(th)
    C = k1 - (k2 + 1) * math.cos(th) + k3
    root = math.sqrt(B * B - 4 * A * C)
    expected = sorted((1 + math.cos(2 * math.atan2(-B + s * root, 2 * A)), math.sin(2 * math.atan2(-B + s * root, 2 * A)))
                      for s in (1, -1))
    found = sorted((q[xb], q[yb]) for q in r["q"])
    assert np.allclose(found, expected, atol=1e-10)
    ws = phiq.Workspace(scene.model)
    for q in r["q"]:
        assert np.max(np.abs(scene.model.residual(q, 0.7))) < 1e-12
        ws.q = q  # a mode is a placement the workspace takes
    assert np.array_equal(ws.q, r["q"][-1])


def test_start_system_says_the_degrees_were_lowered_block_by_block():
    # the natural four-bar, solved block by block in 6 paths (its blocks' total degrees add up to 10): the last
    # block's start system is named with its degrees lowered
    scene = phiq.load_scene(os.path.join(MODELS, "seed", "fourbar_natural.yaml"))
    r = phiq.modes(scene, threads=1)
    assert r["method"] == "block by block"
    assert r["start_system"] == "total degree, degrees lowered"
    assert r["paths"] == 6
    assert r["total_degree"] == 10  # the blocks' own, before lowering: 2 + 2 · 4 (the lowered take 2 + 2 · 2)
    assert r["q"].shape[0] == 4
    for q in r["q"]:
        assert np.max(np.abs(scene.model.residual(q, 0.0))) < 1e-12


def test_a_cam_is_refused_with_its_constraint_named():
    scene = phiq.load_scene(os.path.join(MODELS, "cams", "eccentric_knife.yaml"))
    with pytest.raises(ValueError, match="constraint 'cam' is not polynomial"):
        phiq.modes(scene)


def test_options_out_of_range_are_value_errors_not_signals():
    """A thread count of 10**7 asked TBB for an arena of that many slots (SIGSEGV); a time that is not finite blamed
    the driver ("not polynomial"); max_paths below 1 and negative threads were taken."""
    scene = phiq.load_scene(os.path.join(MODELS, "seed", "fourbar_natural.yaml"))
    with pytest.raises(ValueError, match="threads must be from 0 \\(all cores\\) to 1000000, not 10000000"):
        phiq.modes(scene, threads=10**7)
    with pytest.raises(ValueError, match="threads must be from 0 \\(all cores\\) to 1000000, not -1"):
        phiq.modes(scene, threads=-1)
    with pytest.raises(ValueError, match="max_paths must be 1 or more, not 0"):
        phiq.modes(scene, max_paths=0)
    for t in (math.nan, math.inf):
        with pytest.raises(ValueError, match="ModesOptions: time (nan|inf) is not finite"):
            phiq.modes(scene, t)
    with pytest.raises(ValueError, match="SweepOptions: threads must be from 0 \\(all cores\\) to 1000000"):
        phiq.run_sweep(scene, threads=10**7)
    with pytest.raises(ValueError, match="run_batch: threads must be from 0 \\(all cores\\) to 1000000"):
        phiq.run_batch(scene, [{"L2": 0.4}], threads=10**7)
    assert phiq.modes(scene, threads=2)["q"].shape[0] == 4  # the bound leaves every real count alone


TRIPLE_ROOT = """phiq: 1
coordinates: {x: 0.5, y: 1.0}
constraints:
  - {name: triple, type: equation, expr: "(x - 1)^3"}
  - {name: level, type: equation, expr: "y - 2"}
time: {start: 0, end: 0, steps: 0}
"""


def test_failed_paths_are_named_with_why_as_the_cli_numbers_them():
    """(x − 1)³ = 0 in one unknown: its three paths close one cycle round t = 0 in three turns. Allowed one, each
    fails, numbered from 1 as `phiq modes` prints them, with why; allowed the default, none fails and the one mode is
    singular (a 1 × 1 Jacobian that vanishes)."""
    scene = phiq.parse_scene(TRIPLE_ROOT, "triple.yaml")
    r = phiq.modes(scene, threads=1, max_winding=1)
    assert r["failed_paths"] == 3
    assert [path for path, _ in r["failures"]] == [1, 2, 3]
    assert all("did not close within 1 turn" in why for _, why in r["failures"])
    assert r["q"].shape[0] == 0
    r = phiq.modes(scene, threads=1)
    assert r["failures"] == [] and r["failed_paths"] == 0
    assert r["singular"].tolist() == [True]
    assert abs(r["q"][0][r["coordinates"].index("x")] - 1.0) < 1e-6
    with pytest.raises(ValueError, match="max_winding must be 1 or more, not 0"):
        phiq.modes(scene, max_winding=0)
