"""phiq.Part from Python (engine/python/src/bind_parts.cpp): a scene's parts with their mass properties, and each
part's pose at the rows of a sweep against the body points the joints use."""
import math
import os

import numpy as np
import pytest

import phiq

from conftest import MODELS

FOURBAR = os.path.join(MODELS, "seed", "fourbar_reference_point.yaml")


def fourbar_with_parts():
    with open(FOURBAR, encoding="utf-8") as f:
        text = f.read()
    return phiq.parse_scene(text + "\nparts:\n"
                            "  coupler: {density: 7850, shapes: [{type: box, size: [1.2, 0.04, 0.01]}]}\n"
                            "  crank: {mass: 2.0, center_of_mass: [0.01, 0], inertia: 0.03}\n", "fourbar.yaml")


def test_mass_properties_are_the_boxs_closed_form():
    scene = fourbar_with_parts()
    parts = {p.name: p for p in scene.parts}
    coupler = parts["coupler"]
    m = 7850 * 1.2 * 0.04 * 0.01
    assert coupler.mass_source == "density"
    assert coupler.mass == pytest.approx(m, rel=1e-12)
    assert coupler.inertia[2, 2] == pytest.approx(m * (1.2 ** 2 + 0.04 ** 2) / 12, rel=1e-12)
    assert coupler.inertia[0, 0] == pytest.approx(m * (0.04 ** 2 + 0.01 ** 2) / 12, rel=1e-12)
    assert coupler.shapes[0]["type"] == "box"
    crank = parts["crank"]
    assert crank.mass_source == "stated"
    assert crank.mass == 2.0
    assert crank.center_of_mass[0] == 0.01


def test_poses_follow_the_bodies_at_every_row():
    """The coupler's end at +L3/2 in its frame is joint B: on the rocker's end, whose distance to C is L4."""
    scene = fourbar_with_parts()
    coupler = {p.name: p for p in scene.parts}["coupler"]
    result = phiq.run_sweep(scene)
    model = scene.model
    i_x, i_y, i_psi = (model.coordinate_index(n) for n in ("x3", "y3", "psi3"))
    worst = 0.0
    for q, t in zip(result.q, result.t):
        origin, rotation = coupler.pose(q, t)
        assert np.allclose(rotation @ rotation.T, np.eye(3), atol=1e-15)
        assert origin[0] == q[i_x] and origin[1] == q[i_y]
        assert rotation[0, 0] == pytest.approx(math.cos(q[i_psi]), abs=1e-15)
        b = origin + rotation @ np.array([0.6, 0.0, 0.0])
        worst = max(worst, abs(math.hypot(b[0] - 1.0, b[1]) - 1.0))
    assert worst < 1e-9


def test_a_short_q_is_refused_in_one_line():
    coupler = fourbar_with_parts().parts[0]
    with pytest.raises(ValueError, match="Part.pose: q has 2 entries"):
        coupler.pose(np.zeros(2))


def test_driver_efforts_of_the_crank_slider_are_the_closed_form():
    """A 2 kg slider and a 1 kg crank (centre at L2/2) under gravity, the crank turned at 2 rad/s: the motor's
    torque is m_s ẋ ẍ / θ̇ (the slider's kinetic energy; gravity does no work on it) plus m_c g (L2/2) cos θ (it holds
    the crank up; θ̈ = 0 and the crank's centre moves on a circle)."""
    with open(os.path.join(MODELS, "seed", "crank_slider_mixed.yaml"), encoding="utf-8") as f:
        text = f.read()
    scene = phiq.parse_scene(text + "\nloads: {gravity: [0, -9.81]}\nparts:\n"
                             "  slider: {frame: {at: B}, mass: 2.0, center_of_mass: [0, 0], inertia: 0.01}\n"
                             "  crank: {frame: {origin: O, x: A}, mass: 1.0, center_of_mass: [L2/2, 0], "
                             "inertia: 0.0075}\n", "crank_slider.yaml")
    result = phiq.run_sweep(scene)
    names, efforts = phiq.driver_efforts(scene, result)
    assert names == ["motor"]
    r, L, w = 0.3, 1.0, 2.0
    worst = 0.0
    for t, tau in zip(result.t, efforts[:, 0]):
        th = w * t
        s, c = math.sin(th), math.cos(th)
        root = math.sqrt(L * L - r * r * s * s)
        dx = -r * s - r * r * s * c / root
        d2x = -r * c - r * r * (c * c - s * s) / root - r ** 4 * s * s * c * c / root ** 3
        exact = 2.0 * (w * dx) * (w * w * d2x) / w + 1.0 * 9.81 * (r / 2) * c
        worst = max(worst, abs(tau - exact))
    assert worst < 1e-9
    assert np.max(np.abs(efforts)) > 1.0  # a torque of newton-metres: the check is not of zeros


def test_effort_and_power_columns_of_the_crank_slider_are_the_closed_form():
    """The scene's output.efforts: the `motor.effort` column is the torque of the test above, `motor.power` that
    torque times θ̇, and a Stepper delivers the same at a time it steps to."""
    with open(os.path.join(MODELS, "seed", "crank_slider_mixed.yaml"), encoding="utf-8") as f:
        text = f.read().replace("output: {velocities: true, accelerations: true}", "output: {efforts: all, power: true}")
    scene = phiq.parse_scene(text + "\nloads: {gravity: [0, -9.81]}\nparts:\n"
                             "  slider: {frame: {at: B}, mass: 2.0, center_of_mass: [0, 0], inertia: 0.01}\n"
                             "  crank: {frame: {origin: O, x: A}, mass: 1.0, center_of_mass: [L2/2, 0], "
                             "inertia: 0.0075}\n", "crank_slider.yaml")
    result = phiq.run_sweep(scene).raise_for_status()
    assert result.qd is None and result.qdd is None  # solved for the efforts, not written
    assert result.summary["counters"]["effort_solves"] == len(result)
    r, L, w = 0.3, 1.0, 2.0

    def exact(t):
        th = w * t
        s, c = math.sin(th), math.cos(th)
        root = math.sqrt(L * L - r * r * s * s)
        dx = -r * s - r * r * s * c / root
        d2x = -r * c - r * r * (c * c - s * s) / root - r ** 4 * s * s * c * c / root ** 3
        return 2.0 * (w * dx) * (w * w * d2x) / w + 1.0 * 9.81 * (r / 2) * c

    tau = result["motor.effort"]
    assert max(abs(v - exact(t)) for t, v in zip(result.t, tau)) < 1e-9
    assert np.max(np.abs(result["motor.power"] - w * tau)) < 1e-9
    stepper = phiq.Stepper(scene)
    stepper.step(result.t[7])
    effort, power = stepper.efforts["motor"]
    assert abs(effort - exact(result.t[7])) < 1e-9 and abs(power - w * effort) < 1e-9


def slider_pushed_by(force):
    """The notes' crank-slider (seed/crank_slider_mixed.yaml) with a force `force` on its slider, no masses."""
    with open(os.path.join(MODELS, "seed", "crank_slider_mixed.yaml"), encoding="utf-8") as f:
        text = f.read()
    return phiq.parse_scene(text + "\nparts:\n  slider: {frame: {at: B}}\n"
                            "loads:\n  forces: [{name: push, part: slider, force: " + force + "}]\n",
                            "crank_slider.yaml")


def test_driver_efforts_balance_a_force_on_the_slider():
    """No masses, a force F = -40 - 10 xB along x on the slider (the scene's loads.forces): the motor's power
    balances the force's, so its torque is -F dxB/dtheta."""
    scene = slider_pushed_by("[-40 - 10*xB, 0]")
    result = phiq.run_sweep(scene)
    _, efforts = phiq.driver_efforts(scene, result)
    r, L = 0.3, 1.0
    th = 2.0 * np.asarray(result.t)
    s, c = np.sin(th), np.cos(th)
    root = np.sqrt(L * L - r * r * s * s)
    exact = (40 + 10 * (r * c + root)) * (-r * s - r * r * s * c / root)
    assert np.max(np.abs(efforts[:, 0] - exact)) < 1e-9 * np.max(np.abs(exact))
    assert np.max(np.abs(exact)) > 10.0


def test_driver_efforts_need_velocities_and_accelerations():
    scene = fourbar_with_parts()
    options = scene.options
    options.velocities = options.accelerations = False
    result = phiq.run_sweep(scene, options)
    with pytest.raises(ValueError, match="no velocities or accelerations"):
        phiq.driver_efforts(scene, result)


def test_driver_efforts_name_a_load_that_is_not_finite():
    """A force of exp(1000 t) on the slider overflows to infinity within the sweep: an error naming the force and the
    time, not a row of NaN efforts."""
    scene = slider_pushed_by("[exp(1000*t), 0]")
    result = phiq.run_sweep(scene)
    with pytest.raises(ValueError, match=r"at t = [0-9.]+: force 'push' on part 'slider': its value is not "
                                         r"finite: \(inf, 0\)"):
        phiq.driver_efforts(scene, result)


def test_pendulum_pivot_reaction_is_the_closed_form():
    """A bar (mass m, centre l from its pivot) turned at a constant rate ω about a ground pin under gravity: the pin
    pushes the bar with F = m (a_G - g), a_G = -ω² l (cos θ, sin θ) pointing at the pivot, and no moment; the
    Stepper's reactions are the row's."""
    m, l, w, g = 2.0, 0.5, 3.0, 9.81
    scene = phiq.parse_scene(
        "phiq: 1\nname: pendulum\ncoordinates: {x: 0.5, y: 0, psi: 0}\nbodies: {bar: [x, y, psi]}\n"
        "constraints:\n  - {name: pivot, type: revolute, between: [{body: bar, at: [-0.5, 0]}, {body: ground}]}\n"
        "drivers:\n  - {name: motor, coordinate: psi, law: {type: linear, initial: 0, rate: 3}}\n"
        "parts:\n  bar: {mass: 2.0, center_of_mass: [0, 0], inertia: 0.1}\n"
        "loads: {gravity: [0, -9.81]}\ntime: {start: 0, end: 2, steps: 40}\n"
        "output: {coordinates: [psi], efforts: all, reactions: all}\n", "pendulum.yaml")
    result = phiq.run_sweep(scene).raise_for_status()
    th = w * np.asarray(result.t)
    fx = m * (-w * w * l * np.cos(th))
    fy = m * (-w * w * l * np.sin(th) + g)
    assert np.max(np.abs(result["pivot.Fx"] - fx)) < 1e-9
    assert np.max(np.abs(result["pivot.Fy"] - fy)) < 1e-9
    assert np.max(np.abs(result["pivot.Mz"])) < 1e-9
    assert np.max(np.abs(result["motor.effort"] - m * g * l * np.cos(th))) < 1e-9
    stepper = phiq.Stepper(scene)
    stepper.step(result.t[5])
    assert np.allclose(stepper.reactions["pivot"], (fx[5], fy[5], 0.0), rtol=0, atol=1e-9)


def test_a_scenes_limits_are_warned_as_its_columns_leave_them():
    # models/dynamics/fourbar_gearmotor.yaml: the motor's rated 25 N·m, left over one stretch of rows, said once
    # with its first and last row and its worst value, as the effort column shows them; the same on two threads
    scene = phiq.load_scene(os.path.join(MODELS, "dynamics", "fourbar_gearmotor.yaml"))
    runs = [phiq.run_sweep(scene, threads=n) for n in (1, 2)]
    assert [(w.t, w.message) for w in runs[0].warnings] == [(w.t, w.message) for w in runs[1].warnings]
    limits = [w for w in runs[0].warnings if w.kind == "limit"]
    assert [w.message.split(":")[0] for w in limits] == ["rocker_swing", "rated_torque"]
    t = runs[0].table[:, runs[0].columns.index("t")]
    effort = runs[0].table[:, runs[0].columns.index("motor.effort")]
    over = np.flatnonzero(effort > 25)
    assert len(over) > 1 and np.all(np.diff(over) == 1)  # one stretch
    message = limits[1].message
    assert f"above its maximum 25 from t = {t[over[0]]:.10g} to t = {t[over[-1]]:.10g} ({len(over)} rows)" in message
    assert f"at most {effort.max():.10g} (t = {t[np.argmax(effort)]:.10g})" in message


def test_a_stepper_lists_the_limits_outside_at_each_step():
    # the same scene stepped over its grid: the rated torque listed at exactly the rows whose effort is over 25,
    # and warned once, at the first of them
    scene = phiq.load_scene(os.path.join(MODELS, "dynamics", "fourbar_gearmotor.yaml"))
    result = phiq.run_sweep(scene)
    effort = result.table[:, result.columns.index("motor.effort")]
    stepper = phiq.Stepper(scene)
    listed, warned = [], []
    for t in result.t:
        summary = stepper.step(t)
        assert summary.ok, summary.message
        listed.append("rated_torque" in summary.limits)
        warned += [w.t for w in summary.warnings if w.kind == "limit" and w.message.startswith("rated_torque")]
    over = effort > 25
    assert listed == list(over) and over.sum() > 1
    assert warned == [result.t[np.flatnonzero(over)[0]]]


def test_a_gear_trains_losses_scale_the_motor_torque_each_way():
    # models/transmissions/gear_train.yaml (1/9), massless, its output held back by 2 N·m, with meshing losses of
    # 0.95 and 0.9: the motor pays (2/9)/(0.95 0.9) while it turns the output, (2/9)(0.95 0.9) while the load drives
    with open(os.path.join(MODELS, "transmissions", "gear_train.yaml"), encoding="utf-8") as f:
        text = f.read()
    text = text[:text.index("output: {")] + (
        "loads:\n  torques: [{name: load, part: output, torque: -2}]\n"
        "  gear_losses: [{gear: first_stage, efficiency: 0.95}, {gear: second_stage, efficiency: 0.9}]\n"
        "output: {velocities: true, accelerations: true, efforts: [motor]}\n")
    result = phiq.run_sweep(phiq.parse_scene(text, "train.yaml"))
    w = result.table[:, result.columns.index("psi1.v")]
    effort = result.table[:, result.columns.index("motor.effort")]
    eta = 0.95 * 0.9
    expected = np.where(w > 0, (2 / 9) / eta, np.where(w < 0, (2 / 9) * eta, 2 / 9))
    assert np.max(np.abs(effort - expected)) < 1e-12
    assert (w > 0).sum() > 30 and (w < 0).sum() > 30


def test_a_hoists_losses_are_written_and_stepped():
    # models/dynamics/hoist_gear_losses.yaml with `losses: all`: the motor's power is the load's, m (g + ÿ) ẏ, plus
    # the two stages' losses, each (1 - η) of the power its driven member passes on, raising or lowering; a Stepper
    # gives a row's losses by name
    with open(os.path.join(MODELS, "dynamics", "hoist_gear_losses.yaml"), encoding="utf-8") as f:
        text = f.read()
    text = text[:text.index("output: {")] + (
        "output: {coordinates: [hook], velocities: true, accelerations: true, efforts: all, power: true, "
        "losses: all}\n")
    scene = phiq.parse_scene(text, "hoist.yaml")
    result = phiq.run_sweep(scene).raise_for_status()
    col = lambda name: result.table[:, result.columns.index(name)]
    load = 20 * (9.81 + col("hook.a")) * col("hook.v")
    second = np.where(load > 0, load * (1 / 0.95 - 1), -load * (1 - 0.93))
    first = np.where(load > 0, load / 0.95 * (1 / 0.97 - 1), -load * 0.93 * (1 - 0.96))
    scale = 1e-11 * np.abs(load) + 1e-13
    assert np.all(np.abs(col("second_stage.loss") - second) <= scale)
    assert np.all(np.abs(col("first_stage.loss") - first) <= scale)
    assert np.all(np.abs(col("motor.power") - load - first - second) <= scale)
    assert (load > 1).sum() > 30 and (load < -1).sum() > 30
    assert result.columns[-2:] == ["first_stage.loss", "second_stage.loss"]
    stepper = phiq.Stepper(scene)
    for k in range(3):
        assert stepper.step(result.t[k]).ok
    assert stepper.losses == {"first_stage": (col("first_stage.loss")[2],),
                              "second_stage": (col("second_stage.loss")[2],)}


def test_driver_efforts_with_bearings_at_natural_points_are_the_sweeps():
    # models/seed/fourbar_natural.yaml with the links' angles as coordinates (segment_angle), masses and a journal at
    # each shared point: phiq.driver_efforts over the sweep's motion gives its motor torque, the bearings included
    with open(os.path.join(MODELS, "seed", "fourbar_natural.yaml"), encoding="utf-8") as f:
        text = f.read()
    text = text[:text.index("time:")].replace("  theta2: 0.0\n", "  theta2: 0.0\n  theta3: 1.0\n  theta4: 1.5\n")
    text = text.replace("drivers:", "  - {name: ca, type: segment_angle, segment: [A, B], angle: theta3}\n"
                        "  - {name: ra, type: segment_angle, segment: [C, B], angle: theta4}\ndrivers:")
    bar = "mass: {m}, center_of_mass: [{c}, 0], inertia: {i}"
    text += ("parts:\n"
             "  crank: {frame: {origin: O, x: A}, " + bar.format(m=1, c=0.2, i=0.0133) + "}\n"
             "  coupler: {frame: {origin: A, x: B}, " + bar.format(m=2, c=0.6, i=0.24) + "}\n"
             "  rocker: {frame: {origin: C, x: B}, " + bar.format(m=1.5, c=0.5, i=0.125) + "}\n"
             "loads:\n  gravity: [0, -9.81]\n  torsional_springs:\n")
    for name, angle in (("O", "theta2"), ("A", "theta3 - theta2"), ("B", "theta4 - theta3"), ("C", "theta4")):
        text += f"    - {{name: f{name}, angle: {angle}, bearing: {{joint: {name}, coefficient: 0.2, radius: 0.05}}}}\n"
    text += ("time: {start: 0, end: 2*pi, steps: 24}\n"
             "output: {velocities: true, accelerations: true, efforts: all}\n")
    scene = phiq.parse_scene(text, "natural.yaml")
    result = phiq.run_sweep(scene).raise_for_status()
    names, efforts = phiq.driver_efforts(scene, result)
    assert names == ["motor"]
    torque = result.table[:, result.columns.index("motor.effort")]
    assert np.max(np.abs(efforts[:, 0] - torque)) < 1e-9 * (1 + np.max(np.abs(torque)))
    # the journals are felt: the same motion without them needs another torque
    plain = phiq.parse_scene(text.replace("coefficient: 0.2", "coefficient: 0"), "plain.yaml")
    _, frictionless = phiq.driver_efforts(plain, result)
    assert np.max(np.abs(frictionless[:, 0] - torque)) > 0.1
