"""run_sweep from Python (engine/python/src/sweep_result.cpp, phiq/_results.py): the CLI's CSV bit for bit, every
thread count the same bits, output selection, failures as statuses, redundant and inconsistent scenes, pandas, the
arrays as views of one table, and Ctrl-C."""
import os
import re
import subprocess

import numpy as np
import pytest

import phiq

from conftest import EVERY_OUTPUT, MODELS, PHIQ, seconds_to_interrupt

# The four-bar with every kind of output, its columns selected: some coordinates by pattern, q̈ of two.
SELECTED_OUTPUT = EVERY_OUTPUT.replace("  accelerations: true\n", "  accelerations: [xB, yB]\n  coordinates: ['x*', psi3]\n")


def cli_csv(scene_path, tmp_path, *args):
    out = tmp_path / "cli.csv"
    subprocess.run([PHIQ, "run", scene_path, "-o", str(out), "--quiet", *args], check=True)
    with open(out) as f:
        header = f.readline().strip().split(",")
    return header, np.loadtxt(out, delimiter=",", skiprows=1, ndmin=2)


@pytest.mark.parametrize("scene_file", ["seed/crank_slider_mixed.yaml", "seed/fourbar_natural.yaml",
                                        "spatial/rssr.yaml", "redundant/parallelogram_fifth_bar.yaml",
                                        "hard/change_point_exact.yaml"])
def test_sweep_equals_the_cli_csv_bit_for_bit(scene_file, tmp_path):
    path = os.path.join(MODELS, scene_file)
    header, table = cli_csv(path, tmp_path)
    result = phiq.run_sweep(phiq.load_scene(path), threads=2)
    assert result.ok, result.message
    assert result.columns == header
    assert np.array_equal(result.table, table)  # every double, bit for bit (the CSV is shortest round-trip)
    assert [w.kind for w in result.warnings] == [w["kind"] for w in result.summary["warnings"]]


def test_output_selection_and_identifier_names(tmp_path):
    path = tmp_path / "outputs.yaml"
    path.write_text(SELECTED_OUTPUT)
    assert SELECTED_OUTPUT != EVERY_OUTPUT
    header, table = cli_csv(str(path), tmp_path, "--names", "identifiers")
    result = phiq.run_sweep(phiq.load_scene(str(path)), identifier_names=True)
    assert result.columns == header
    assert np.array_equal(result.table, table)
    assert result.coordinate_names == ["xA", "x3", "xB", "psi3"]
    assert result.velocity_names == ["xA__v", "x3__v", "xB__v", "psi3__v"]
    assert result.acceleration_names == ["xB__a", "yB__a"]
    assert result.point("P").shape == (73, 2)
    assert result.output_names[-1] == "rcond"
    # only the rows and outputs asked for are computed: two points per delivered row
    assert result.summary["counters"]["point_evaluations"] == 2 * 73


def test_parallel_sweep_equals_the_sequential():
    scene = phiq.load_scene(os.path.join(MODELS, "hard", "change_point_full_turn.yaml"))
    runs = [phiq.run_sweep(scene, threads=n, steps=720) for n in (1, 2, 3)]
    for r in runs[1:]:
        assert np.array_equal(r.table, runs[0].table)
        assert r.summary["counters"] == runs[0].summary["counters"]
        assert [(w.t, w.kind, w.message) for w in r.warnings] == [(w.t, w.kind, w.message) for w in runs[0].warnings]
    assert runs[1].summary["threads"] == 2
    assert any(w.kind == "bifurcation" for w in runs[0].warnings)


def test_arrays_are_views_of_one_table():
    result = phiq.run_sweep(phiq.load_scene(os.path.join(MODELS, "seed", "crank_slider_mixed.yaml")))
    for a in (result.t, result.q, result.qd, result.qdd):
        assert np.shares_memory(a, result.table)
    assert result.outputs.shape == (181, 0)
    assert result.table.base is not None and not result.table.flags.owndata
    assert result.q.shape == (181, 4) and result.table.shape == (181, 13)
    np.testing.assert_array_equal(result["xB.v"], result.qd[:, 3])
    with pytest.raises(KeyError, match="no column 'xC'"):
        result["xC"]


def test_a_failed_sweep_is_a_status_with_the_cli_message(tmp_path):
    path = os.path.join(MODELS, "hard", "crank_rocker_rocker_driven.yaml")
    result = phiq.run_sweep(phiq.load_scene(path))
    assert not result.ok
    assert result.status == phiq.SolveStatus.NOT_CONVERGED
    assert "no assembly beyond" in result.message
    t_star = np.arccos(-7 / 8) - 2.2
    assert 0 < len(result) < 101 and result.t[-1] <= t_star
    cli = subprocess.run([PHIQ, "run", path, "-o", str(tmp_path / "x.csv"), "--quiet"], capture_output=True, text=True)
    assert cli.returncode == 1
    assert result.message in cli.stderr
    with pytest.raises(phiq.SolveError) as e:
        result.raise_for_status()
    assert str(e.value) == result.message and e.value.status == result.status


def test_redundant_and_inconsistent_scenes():
    door = phiq.run_sweep(phiq.load_scene(os.path.join(MODELS, "redundant", "door_three_hinges.yaml")))
    assert door.ok and len(door) == door.summary["steps_completed"]
    bad = phiq.run_sweep(phiq.load_scene(os.path.join(MODELS, "redundant", "door_misaligned.yaml")))
    assert bad.status == phiq.SolveStatus.INCONSISTENT and len(bad) == 0
    assert "hinge3" in bad.message and bad.message.startswith("t = 0: ")


def test_options_and_errors():
    scene = phiq.load_scene(os.path.join(MODELS, "seed", "crank_slider_mixed.yaml"))
    opts = scene.options
    opts.steps, opts.accelerations, opts.every = 10, False, 5
    result = phiq.run_sweep(scene, opts)
    assert len(result) == 3 and result.qdd is None and result.qd is not None
    assert result.summary["counters"]["acceleration_solves"] == 0
    assert scene.options.steps == 180  # the scene's own options are unchanged
    with pytest.raises(TypeError, match="unexpected keyword argument 'thread'"):
        phiq.run_sweep(scene, thread=2)
    with pytest.raises(ValueError, match="SweepOptions: steps must be >= 0"):
        phiq.run_sweep(scene, steps=-1)
    with pytest.raises(ValueError, match="threads must be from 0 \\(all cores\\) to 1000000, not -2"):
        phiq.run_sweep(scene, threads=-2)


def test_to_pandas():
    pandas = pytest.importorskip("pandas")
    result = phiq.run_sweep(phiq.load_scene(os.path.join(MODELS, "seed", "crank_slider_mixed.yaml")))
    frame = result.to_pandas()
    assert isinstance(frame, pandas.DataFrame)
    assert list(frame.columns) == result.columns[1:]
    assert frame.index.name == "t"
    np.testing.assert_array_equal(frame["xB"].to_numpy(), result["xB"])


def test_ctrl_c_stops_a_long_sweep_promptly(tmp_path):
    """A sweep of some minutes, interrupted half a second after it starts, raises KeyboardInterrupt within a few
    seconds (it stops at its next delivered row)."""
    scene = tmp_path / "long.yaml"
    subprocess.run([PHIQ, "generate", "nfourbar", "1000", "--steps", "1000000", "--outputs", "q", "-o", str(scene)],
                   check=True)
    assert seconds_to_interrupt(f"scene = phiq.load_scene({str(scene)!r})",
                                "phiq.run_sweep(scene, threads=1, every=1000)") < 10.0


def test_the_gil_is_released_while_sweeping(tmp_path):
    """Python code runs in another thread while a sweep works: with the GIL held through the sweep, the loop below
    could not run until the sweep returned."""
    import threading
    path = tmp_path / "chain.yaml"
    subprocess.run([PHIQ, "generate", "nfourbar", "1000", "--steps", "400", "--outputs", "q", "-o", str(path)],
                   check=True)
    scene = phiq.load_scene(str(path))
    started, results = threading.Event(), []
    worker = threading.Thread(target=lambda: (started.set(), results.append(phiq.run_sweep(scene, threads=1))))
    worker.start()
    started.wait()
    spins = 0
    while worker.is_alive():
        spins += 1
    worker.join()
    assert results[0].ok and len(results[0]) == 401
    assert spins > 100_000, spins


def test_objects_keep_what_they_need_alive():
    import gc
    scene = phiq.load_scene(os.path.join(MODELS, "seed", "crank_slider_mixed.yaml"))
    model = scene.model
    ws = phiq.Workspace(model)
    result = phiq.run_sweep(scene)
    q = result.q
    del scene, model, result
    gc.collect()
    assert phiq.solve_position(ws.model, 0.2, ws).ok  # the workspace keeps its model and scene
    assert q.shape == (181, 4) and q[0, 0] == 0.0    # the view keeps its table


def test_sensitivities_reach_python_as_the_clis_columns(tmp_path):
    # output.sensitivities: the same columns and bits as the CLI's, and ∂x_B/∂L2, ∂x_B/∂L3 of the notes'
    # crank-slider against x_B = L2 cos θ + √(L3² − L2² sin² θ), θ = 2t.
    with open(os.path.join(MODELS, "seed/crank_slider_mixed.yaml")) as f:
        text = f.read()
    plain = "output: {velocities: true, accelerations: true}"
    assert plain in text
    path = tmp_path / "sensitivities.yaml"
    path.write_text(text.replace(plain, "output: {velocities: true, accelerations: true, sensitivities: [L2, L3]}"))
    header, table = cli_csv(str(path), tmp_path)
    result = phiq.run_sweep(phiq.load_scene(str(path)))
    assert result.ok, result.message
    assert result.columns == header
    assert np.array_equal(result.table, table)
    theta = 2 * table[:, 0]
    l2, l3 = 0.3, 1.0
    w = np.sqrt(l3**2 - (l2 * np.sin(theta)) ** 2)
    assert np.max(np.abs(table[:, header.index("xB.d_L2")] - (np.cos(theta) - l2 * np.sin(theta) ** 2 / w))) < 1e-9
    assert np.max(np.abs(table[:, header.index("xB.d_L3")] - l3 / w)) < 1e-9
    assert header[-1] == "xB.a.d_L3"
    xb = result.coordinate_names.index("xB")
    assert np.array_equal(result.sensitivity("L2")[:, xb], table[:, header.index("xB.d_L2")])
    assert np.array_equal(result.sensitivity("L3", 2)[:, xb], table[:, header.index("xB.a.d_L3")])
    assert result.sensitivity("L3", 1).shape == (181, 4)
    with pytest.raises(KeyError, match="no sensitivities of order 0 to 'L9'"):
        result.sensitivity("L9")
    with pytest.raises(ValueError, match="order must be 0, 1 or 2"):
        result.sensitivity("L2", 3)
    assert result.summary["counters"]["sensitivity_solves"] == 181 * 2 * 3
    assert result.summary["sensitivity_form"] == "direct"
    # the adjoint form asked for: the same values to 1e-10 (every coordinate written, so every column)
    options = phiq.load_scene(str(path)).options
    options.sensitivity_form = phiq.SensitivityForm.ADJOINT
    adjoint = phiq.run_sweep(phiq.load_scene(str(path)), options)
    assert adjoint.ok, adjoint.message
    assert adjoint.summary["sensitivity_form"] == "adjoint"
    assert adjoint.summary["counters"]["sensitivity_solves"] == 181 * 4 * 4
    first = header.index("xB.d_L2")
    assert np.max(np.abs(adjoint.table[:, first:] - table[:, first:])) < 1e-10 * np.max(np.abs(table[:, first:]))


def test_sensitivities_asked_for_in_python_at_the_scenes_loaded_values(tmp_path):
    # run_sweep(..., sensitivities=[...]) on a scene loaded with L2 = 0.35 (no output.sensitivities in its text):
    # the models along each parameter are read as the scene was (L2 given), so ∂x_B/∂L2 and ∂x_B/∂L3 meet the
    # closed form x_B = L2 cos θ + √(L3² − L2² sin² θ) at L2 = 0.35, θ = 2t, and L3 reaches the rod alone.
    path = os.path.join(MODELS, "seed/crank_slider_mixed.yaml")
    scene = phiq.load_scene(path, parameters={"L2": 0.35})
    assert scene.options.sensitivity_names == []
    result = phiq.run_sweep(scene, sensitivities=["L2", ("L3", 1e-2)])
    assert result.ok, result.message
    xb = result.coordinate_names.index("xB")
    theta = 2 * result.t
    l2, l3 = 0.35, 1.0
    w = np.sqrt(l3**2 - (l2 * np.sin(theta)) ** 2)
    assert np.max(np.abs(result.sensitivity("L2")[:, xb] - (np.cos(theta) - l2 * np.sin(theta) ** 2 / w))) < 1e-9
    assert np.max(np.abs(result.sensitivity("L3")[:, xb] - l3 / w)) < 1e-9
    # ∂ẋ_B/∂L3 = d/dt (L3 / w) = L3 L2² sin θ cos θ θ̇ / w³
    want = l3 * l2**2 * np.sin(theta) * np.cos(theta) * 2 / w**3
    assert np.max(np.abs(result.sensitivity("L3", 1)[:, xb] - want)) < 1e-9
    # the same through the options, and the names they hold
    options = scene.options
    options.set_sensitivities(scene, ["L3"])
    assert options.sensitivity_names == ["L3"]
    only_l3 = phiq.run_sweep(scene, options)
    by_keyword = phiq.run_sweep(scene, sensitivities=["L3"])
    assert np.array_equal(only_l3.sensitivity("L3")[:, xb], by_keyword.sensitivity("L3")[:, xb])
    with pytest.raises(KeyError, match="or pass it in run_sweep's sensitivities"):
        only_l3.sensitivity("L2")
    options.set_sensitivities(scene, [])
    assert options.sensitivity_names == []
    unknown = "sensitivities: 'L9' is not a parameter of .*crank_slider_mixed.yaml .its parameters: L2"
    with pytest.raises(phiq.SceneError, match=unknown):
        phiq.run_sweep(scene, sensitivities=["L9"])
    with pytest.raises(phiq.SceneError, match="sensitivities: parameter .L2. is asked for twice"):
        phiq.run_sweep(scene, sensitivities=["L2", "L2"])
    with pytest.raises(phiq.SceneError, match="sensitivities: the step of .L2. must be a positive finite number"):
        phiq.run_sweep(scene, sensitivities=[("L2", float("nan"))])
    with pytest.raises(TypeError, match="a name or a .name, step. tuple"):
        phiq.run_sweep(scene, sensitivities=[3])
    # a step that leaves L2 ± h on L2 would difference a parameter that did not move (every sensitivity 0)
    with pytest.raises(phiq.SceneError, match=r"sensitivity to 'L2': the difference step 1e-300 does not move L2 ="):
        phiq.run_sweep(scene, sensitivities=[("L2", 1e-300)])
    with pytest.raises(phiq.SceneError, match=r"the difference step 1e-17 does not move L2 ="):
        phiq.run_batch(scene, {"L3": [1.0]}, sensitivities=[("L2", 1e-17)])


def test_sensitivities_read_the_scene_again_with_its_loaded_parameters():
    # A pin in a circular slot of radius R = r k (models/slots/circular_slot.yaml with a factor k), loaded with
    # k = 1.2: along r the circle grows at the rate k, so the slot is differenced from the scene read at r ± h,
    # r ± 2h with k = 1.2 as loaded (read with the file's k = 1, those models would hold another circle).
    # y = cy + √(R² − (x − cx)²): ∂y/∂r = k R / √(R² − (x − cx)²).
    with open(os.path.join(MODELS, "slots/circular_slot.yaml")) as f:
        text = f.read()
    text = text.replace("v: 0.35}", "v: 0.35, k: 1}").replace("radius: r}", "radius: r*k}")
    assert "r*k" in text and "k: 1}" in text
    scene = phiq.parse_scene(text, "slot_k.yaml", parameters={"k": 1.2})
    result = phiq.run_sweep(scene, sensitivities=["r"])
    assert result.ok, result.message
    k, big_r, cx = 1.2, 0.6, 0.2
    x = result.q[:, result.coordinate_names.index("x")]
    want = k * big_r / np.sqrt(big_r**2 - (x - cx) ** 2)
    got = result.sensitivity("r")[:, result.coordinate_names.index("y")]
    assert np.max(np.abs(got - want)) < 1e-9


def test_options_of_another_scene_are_named_as_such():
    """Options hold indices into their scene's model: another scene's are refused naming the cause."""
    four_bar = phiq.parse_scene(EVERY_OUTPUT, "fourbar.yaml")
    crank_slider = phiq.load_scene(os.path.join(MODELS, "seed", "crank_slider_mixed.yaml"))
    with pytest.raises(phiq.SceneError, match=r"crank_slider_mixed\.yaml: the options name coordinates or "
                                              r"constraints this scene does not have .*made for another scene"):
        phiq.run_sweep(crank_slider, four_bar.options)


# A four-bar of a 10⁶ m ground and coupler (a body on two pins) on a 10⁻⁶ m crank and a 1.5·10⁻⁶ m rocker: its rows
# are known only to the rounding of coordinates near 10⁶ m (an ulp is 2⁻³³ m), and the summary says so at the
# coordinate, in its own unit: B is within a few ulps of 10⁶ m, i.e. well under 10⁻⁹ m (test_hard_cases.cpp checks
# the rocker's angle against the closed form).
BADLY_SCALED_PINNED = """phiq: 1
parameters: {L1: 1e6, L2: 1e-6, L3: 1e6, L4: 1.5e-6}
coordinates: {theta2: 0.0, xA: 1e-6, yA: 0.0, x3: 0.5e6, y3: 0.5e-6, psi3: 1e-12, xB: 1e6, yB: 1.1e-6}
points: {O: [0, 0], A: [xA, yA], B: [xB, yB], C: [L1, 0]}
bodies: {coupler: [x3, y3, psi3]}
constraints:
  - {name: crank, type: polar, point: A, origin: O, length: L2, angle: theta2}
  - {name: A, type: revolute, between: [{body: coupler, at: [-L3/2, 0]}, {point: A}]}
  - {name: B, type: revolute, between: [{body: coupler, at: [L3/2, 0]}, {point: B}]}
  - {name: rocker, type: distance, points: [C, B], length: L4}
drivers:
  - {name: motor, coordinate: theta2, law: {type: linear, initial: 0, rate: 1}}
time: {start: 0, end: 2*pi, steps: 360}
"""


def test_accuracy_is_stated_in_the_coordinates_unit():
    result = phiq.run_sweep(phiq.parse_scene(BADLY_SCALED_PINNED, "pinned.yaml"), threads=1)
    assert result.ok, result.message
    rounding = result.summary["accuracy"]["rounding_level"]
    assert rounding["rows"] > 0
    assert rounding["worst_coordinate"] in result.coordinate_names
    assert rounding["worst_unit"] == ("rad" if rounding["worst_coordinate"] in ("theta2", "psi3") else "m")
    assert 0 < rounding["worst_known_to"] < 1e-9
    converged = result.summary["accuracy"]["converged"]
    assert converged["worst_coordinate"] is None or converged["worst_coordinate"] in result.coordinate_names


# The same four-bar with every link a body (reference-point coordinates): the rocker's pin x4 − L4/2 cos ψ4 − L1 is a
# multiple of an ulp of 10⁶ m whatever ψ4 is, so Newton leaves it at its rounding (test_badly_scaled.cpp) and the
# position says how well q is known then, at a coordinate and in its unit.
BADLY_SCALED_REFERENCE_POINT = """phiq: 1
parameters: {L1: 1e6, L2: 1e-6, L3: 1e6, L4: 1.5e-6}
coordinates: {x2: 0.5e-6, y2: 0.0, psi2: 0.0, x3: 0.5e6, y3: 0.559e-6, psi3: 1.118e-12,
              x4: 1000000.0000005, y4: 0.559e-6, psi4: 0.8411}
points: {O: [0, 0], C: [L1, 0]}
bodies: {crank: [x2, y2, psi2], coupler: [x3, y3, psi3], rocker: [x4, y4, psi4]}
constraints:
  - {name: O, type: revolute, between: [{body: crank, at: [-L2/2, 0]}, {point: O}]}
  - {name: A, type: revolute, between: [{body: crank, at: [L2/2, 0]}, {body: coupler, at: [-L3/2, 0]}]}
  - {name: B, type: revolute, between: [{body: coupler, at: [L3/2, 0]}, {body: rocker, at: [L4/2, 0]}]}
  - {name: C, type: revolute, between: [{body: rocker, at: [-L4/2, 0]}, {point: C}]}
drivers:
  - {name: motor, coordinate: psi2, law: {type: linear, initial: 0, rate: 1}}
time: {start: 0, end: 2*pi, steps: 72}
"""


def test_a_position_at_its_rounding_says_how_well_in_the_coordinates_unit():
    model = phiq.parse_scene(BADLY_SCALED_REFERENCE_POINT, "reference_point.yaml").model
    ws = phiq.Workspace(model)
    p = phiq.solve_position(model, 0.5, ws)
    assert p.ok, p.message
    assert p.error_coordinate >= 0
    name = model.coordinate_names[p.error_coordinate]
    unit = "rad" if name.startswith("psi") else "m"
    assert re.fullmatch(r"'%s' known to ±\S+ %s" % (name, unit), p.known_to(model)), p.known_to(model)
    # an ulp of 10⁶ m over the rocker's 7.5·10⁻⁷ m arm is 1.5·10⁻⁴ rad: the estimate is of that order
    arm = 1.0 if unit == "rad" else 7.5e-7
    assert 1e-6 < p.error_size / arm < 1e-2
    assert "known to ±" in p.message and "tolerances" not in p.message
