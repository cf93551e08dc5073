"""phiq.clearance (engine/python/src/bind_clearance.cpp): two balls on moving points against their closed forms, the
arrays (each minimum's sensitivities too) equal to the values `phiq clearance` writes (CSV and --summary JSON, numbers that read back to the same
doubles), and a threshold below zero refused as ValueError."""
import json
import math
import os
import subprocess

import numpy as np
import pytest

import phiq

from conftest import MODELS, PHIQ


def clearance_balls_text():
    """The four-bar with a ball (radius 0.05) on the crank's tip, (L2/2 + 0.2)(cos t, sin t), and one (radius 0.15)
    fixed at (0, -0.5): d = |tip - (0, -0.5)| - 0.2, least (-0.1) at t = 3 pi/2, with d d/d L2 = -1/2."""
    with open(os.path.join(MODELS, "seed", "fourbar_reference_point.yaml")) as f:
        text = f.read()
    return (text[:text.index("\ntime:")] + "\ntime: {start: 0, end: 2*pi, steps: 90}\n"
            "parts:\n"
            "  tip: {body: crank, shapes: [{type: sphere, radius: 0.05, at: [0.2, 0]}]}\n"
            "  ball: {body: ground, shapes: [{type: sphere, radius: 0.15, at: [0, -0.5]}]}\n"
            "output: {sensitivities: [L2], clearance: {pairs: [[tip, ball]], threshold: 0.01}}\n")


def test_two_balls_are_their_centres_distance_less_the_radii():
    r = phiq.clearance(phiq.parse_scene(clearance_balls_text(), "balls.yaml"))
    assert r["summary"].status == phiq.SolveStatus.SUCCESS
    assert r["pairs"] == [("tip", "ball")] and r["columns"] == ["tip.ball"]
    t = r["t"]
    assert r["distance"].shape == (91, 1)
    tip = 0.4 * np.stack([np.cos(t), np.sin(t)], axis=1)
    assert np.allclose(r["distance"][:, 0], np.hypot(tip[:, 0], tip[:, 1] + 0.5) - 0.2, atol=1e-9)
    assert abs(r["worst_t"][0] - 1.5 * math.pi) < 1e-6 and abs(r["worst_distance"][0] + 0.1) < 1e-10
    assert r["refined"][0] and r["bound_held"] and r["interferes"]
    # each ball's deepest point inside the other, on its own surface: the tip's lowest, the ball's highest
    assert np.allclose(r["point_a"][0], [0, -0.45, 0], atol=1e-9)
    assert np.allclose(r["point_b"][0], [0, -0.35, 0], atol=1e-9)
    assert abs(r["point_a"][0][0]) < 1e-6 and np.allclose(r["normal"][0], [0, -1, 0], atol=1e-9)
    assert r["parameters"] == ["L2"] and abs(r["sensitivities"][0, 0] + 0.5) < 1e-7
    # every minimum's own: at t = 0 (the first row; d rises) d = sqrt(r^2 + 0.25) - 0.2 with r = L2/2 + 0.2 = 0.4,
    # d d/d L2 = r / (2 sqrt(0.41)); then the worst's
    assert r["minima"][0].shape == (2, 2) and r["minima_sensitivities"][0].shape == (2, 1)
    assert r["minima"][0][0, 0] == 0.0 and abs(r["minima_sensitivities"][0][0, 0] - 0.2 / math.sqrt(0.41)) < 1e-9
    assert r["minima_sensitivities"][0][1, 0] == r["sensitivities"][0, 0]
    h = 2 * math.pi / 90
    (entry, exit_), = r["interference"][0]
    assert abs(entry - (math.pi + math.asin(0.925))) < 1e-9 * h
    assert abs(exit_ - (2 * math.pi - math.asin(0.925))) < 1e-9 * h
    assert r["unproven_intervals"].tolist() == [0]


def test_arrays_are_the_values_phiq_clearance_writes(tmp_path):
    scene = os.path.join(MODELS, "clearance", "fourbar_knee.yaml")
    csv, summary = tmp_path / "c.csv", tmp_path / "s.json"
    subprocess.run([PHIQ, "clearance", scene, "-q", "-o", str(csv), "--summary", str(summary)], check=True)
    r = phiq.clearance(phiq.load_scene(scene))
    table = np.loadtxt(csv, delimiter=",", skiprows=1)
    with open(csv) as f:
        assert f.readline().strip().split(",")[1:] == r["columns"]
    assert np.array_equal(table[:, 0], r["t"]) and np.array_equal(table[:, 1:], r["distance"])
    s = json.loads(summary.read_text())
    assert [(p["a"], p["b"]) for p in s["pairs"]] == r["pairs"]
    for i, p in enumerate(s["pairs"]):
        w = p["worst"]
        assert (w["t"], w["distance"], w["refined"]) == (r["worst_t"][i], r["worst_distance"][i], r["refined"][i])
        assert w["point_a"] == r["point_a"][i].tolist() and w["point_b"] == r["point_b"][i].tolist()
        assert [[iv["entry"], iv["exit"]] for iv in p["interference"]] == r["interference"][i].tolist()
    assert s["positions_solved"] == r["positions_solved"] and s["bound_held"] == r["bound_held"]


def test_a_threshold_below_zero_is_refused():
    scene = phiq.parse_scene(clearance_balls_text(), "balls.yaml")
    with pytest.raises(ValueError, match="threshold -0.001 must be 0 or more"):
        phiq.clearance(scene, threshold=-0.001)


def test_a_threshold_beyond_a_boxs_squared_size_measures_every_pair():
    """An infinite threshold (and 1e300, whose squares overflow) made the broad phase's boxes infinite, and FCL's
    tree read outside its nodes (SIGSEGV): every pair is then a candidate, measured as with explicit pairs."""
    with open(os.path.join(MODELS, "clearance", "fourbar_knee.yaml")) as f:
        text = f.read()
    scene = phiq.parse_scene(text, "knee.yaml")
    near = phiq.clearance(scene, threshold=10.0)  # the broad phase keeps every pair within 10 m: all of them
    for threshold in (1e300, math.inf):
        r = phiq.clearance(scene, threshold=threshold)
        assert r["columns"] == near["columns"]
        assert r["pairs_selected"] == near["pairs_selected"] == r["pairs_measured"]
        assert np.array_equal(r["distance"], near["distance"])
