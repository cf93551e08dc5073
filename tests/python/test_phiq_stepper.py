"""Stepper from Python (engine/python/src/bind_stepper.cpp): a simulator's own clock with the sweep's predictors —
run_sweep's rows to the bit over its grid with the same work, the closed form at uneven times, a failed step that
keeps the last good state, restart, and a redundant scene stepped on its independent rows."""
import math
import os

import numpy as np
import pytest

import phiq

from conftest import MODELS

CRANK_SLIDER = os.path.join(MODELS, "seed", "crank_slider_mixed.yaml")


def test_stepping_the_grid_gives_the_sweep_bit_for_bit():
    scene = phiq.load_scene(CRANK_SLIDER)
    opts = scene.options
    sweep = phiq.run_sweep(scene, threads=1, chunk_steps=opts.steps + 1)
    stepper = phiq.Stepper(scene)
    rows = []
    for k in range(opts.steps + 1):
        s = stepper.step(opts.time_of(k))
        assert s.ok, s.message
        assert s.assembled == (k == 0)
        rows.append(np.concatenate([[stepper.time], stepper.q, stepper.qd, stepper.qdd]))
    assert np.array_equal(np.array(rows), sweep.table)
    assert stepper.summary.counters.newton_iterations == sweep.summary["counters"]["newton_iterations"]
    assert stepper.summary.counters.factorizations == sweep.summary["counters"]["factorizations"]
    assert stepper.summary.steps_completed == opts.steps + 1


def test_uneven_times_against_the_closed_form():
    stepper = phiq.Stepper(phiq.load_scene(CRANK_SLIDER).model)
    xb = stepper.model.coordinate_index("xB")
    r, L = 0.3, 1.0
    for k in range(40):
        t = 0.002 * k * k
        assert stepper.step(t).ok
        th = 2 * t
        assert abs(stepper.q[xb] - (r * math.cos(th) + math.sqrt(L * L - (r * math.sin(th)) ** 2))) < 1e-9
    with pytest.raises(ValueError):
        stepper.q[0] = 1.0  # the state is read-only: a step writes it


def test_a_failed_step_keeps_the_last_good_state():
    scene = phiq.load_scene(os.path.join(MODELS, "hard", "crank_rocker_rocker_driven.yaml"))
    stepper = phiq.Stepper(scene)
    assert stepper.step(0.0).ok and stepper.step(0.3).ok
    q = stepper.q.copy()
    failed = stepper.step(0.6)  # beyond the dead point at t* = acos(-7/8) - 2.2 = 0.436
    assert not failed.ok and failed.status == phiq.SolveStatus.NOT_CONVERGED
    assert "t = 0.6" in failed.message
    assert stepper.time == 0.3 and np.array_equal(stepper.q, q)
    assert stepper.step(0.4).ok and stepper.time == 0.4


def test_restart_assembles_again_and_points_follow():
    scene = phiq.parse_scene(open(CRANK_SLIDER).read().replace(
        "output: {velocities: true, accelerations: true}",
        "output: {velocities: true, accelerations: true, points: [A]}"), "cs_points.yaml")
    stepper = phiq.Stepper(scene)
    assert stepper.step(0.1).ok
    placement = stepper.model.initial_positions
    stepper.restart(placement)
    again = stepper.step(0.5)
    assert again.ok and again.assembled
    r, v, a = stepper.points["A"]
    np.testing.assert_allclose(r, [0.3 * math.cos(1.0), 0.3 * math.sin(1.0)], atol=1e-10)
    np.testing.assert_allclose(v, [-0.6 * math.sin(1.0), 0.6 * math.cos(1.0)], atol=1e-9)
    np.testing.assert_allclose(a, [-1.2 * math.cos(1.0), -1.2 * math.sin(1.0)], atol=1e-9)
    with pytest.raises(ValueError, match="placement has 2 entries"):
        stepper.restart(np.zeros(2))


def test_redundant_and_inconsistent_scenes():
    door = phiq.Stepper(phiq.load_scene(os.path.join(MODELS, "redundant", "door_three_hinges.yaml")))
    assert door.step(0.0).ok and door.step(0.05).ok
    with pytest.raises(ValueError, match="hinge3"):
        phiq.Stepper(phiq.load_scene(os.path.join(MODELS, "redundant", "door_misaligned.yaml")))


def test_each_step_delivers_its_sensitivities():
    # A stepper on the crank-slider loaded with L2 = 0.35, asked for L2 and L3: at uneven times, forward and back,
    # ∂x_B/∂L2 = cos θ − L2 sin² θ / w and ∂x_B/∂L3 = L3 / w, w = √(L3² − L2² sin² θ), θ = 2t (1e-9); over the grid
    # the sweep's sensitivity columns to the bit.
    scene = phiq.load_scene(CRANK_SLIDER, parameters={"L2": 0.35})
    stepper = phiq.Stepper(scene, sensitivities=["L2", ("L3", 1e-2)])
    assert stepper.sensitivity_names == ["L2", "L3"]
    with pytest.raises(ValueError, match="no state yet"):
        stepper.sensitivity("L2")
    xb = stepper.model.coordinate_index("xB")
    l2, l3 = 0.35, 1.0
    for t in (0.0, 0.21, 0.5, 0.45, 1.3, 2.9, 2.2):
        assert stepper.step(t).ok
        th = 2 * t
        w = math.sqrt(l3**2 - (l2 * math.sin(th)) ** 2)
        assert abs(stepper.sensitivity("L2")[xb] - (math.cos(th) - l2 * math.sin(th) ** 2 / w)) < 1e-9
        assert abs(stepper.sensitivity("L3")[xb] - l3 / w) < 1e-9
        assert stepper.sensitivity("L3", 2).shape == (4,)
    with pytest.raises(KeyError, match="no sensitivities to 'omega'"):
        stepper.sensitivity("omega")
    with pytest.raises(ValueError, match="order must be 0, 1 or 2"):
        stepper.sensitivity("L2", 3)
    opts = scene.options
    sweep = phiq.run_sweep(scene, threads=1, chunk_steps=opts.steps + 1, sensitivities=["L2", ("L3", 1e-2)])
    gridded = phiq.Stepper(scene, sensitivities=["L2", ("L3", 1e-2)])
    for k in range(opts.steps + 1):
        assert gridded.step(opts.time_of(k)).ok
        for name in ("L2", "L3"):
            for order in (0, 1, 2):
                assert np.array_equal(gridded.sensitivity(name, order), sweep.sensitivity(name, order)[k]), (k, name)
    with pytest.raises(phiq.SceneError, match="sensitivities: 'L9' is not a parameter"):
        phiq.Stepper(scene, sensitivities=["L9"])
    with pytest.raises(TypeError, match="Stepper: each parameter is a name or a .name, step. tuple"):
        phiq.Stepper(scene, sensitivities=[1.5])
    assert phiq.Stepper(scene).sensitivity_names == []  # the scene lists none
