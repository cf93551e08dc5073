"""phiq.run_batch: each case the bits of run_sweep on the scene loaded with its values (any thread count), the
crank-slider's closed forms and their derivatives over a grid of cases, the same rows as `phiq batch`'s one file,
keyword fields on every case, the forms the cases may take, and bad input: unknown names, ragged cases, a case whose
values make the scene impossible or whose sweep fails (failing alone, named)."""
import math
import os
import subprocess

import numpy as np
import pytest

import phiq
from conftest import crank_slider_builder, seconds_to_interrupt


def crank_slider(models):
    return os.path.join(models, "seed", "crank_slider_mixed.yaml")


def test_each_case_is_run_sweep_of_the_scene_loaded_with_its_values(models):
    path = crank_slider(models)
    scene = phiq.load_scene(path, parameters={"L3": 1.2})  # a loaded value the cases keep
    cases = {"L2": [0.15, 0.2, 0.25, 0.3, 0.35]}
    batch = phiq.run_batch(scene, cases, threads=2)
    alone = phiq.run_batch(scene, cases, threads=1)
    assert batch.ok and len(batch) == 5 and batch.threads == 2 and alone.threads == 1
    assert batch.shared_analyses == 5
    for k, l2 in enumerate(cases["L2"]):
        one = phiq.run_sweep(phiq.load_scene(path, parameters={"L2": l2, "L3": 1.2}))
        assert batch.cases[k].columns == one.columns
        assert np.array_equal(batch.cases[k].table, one.table)
        assert np.array_equal(alone.cases[k].table, one.table)
        assert batch.messages[k] == ""


def test_closed_forms_and_their_derivatives_over_a_grid_of_cases(models):
    scene = phiq.load_scene(crank_slider(models))
    l2, l3 = np.meshgrid([0.1, 0.2, 0.3], [0.8, 1.0, 1.4])
    batch = phiq.run_batch(scene, {"L2": l2.ravel(), "L3": l3.ravel()}, sensitivities=["L2", "L3"])
    batch.raise_for_status()
    theta = 2 * batch.t                       # cases × rows
    L2, L3 = batch.values[:, :1], batch.values[:, 1:]
    root = np.sqrt(L3**2 - L2**2 * np.sin(theta) ** 2)
    assert batch["xB"].shape == (9, 181)
    assert np.max(np.abs(batch["xB"] - (L2 * np.cos(theta) + root))) < 1e-9
    xb = batch.cases[0].coordinate_names.index("xB")
    assert batch.sensitivity("L2").shape == (9, 181, 4)
    d_l2 = np.cos(theta) - L2 * np.sin(theta) ** 2 / root
    assert np.max(np.abs(batch.sensitivity("L2")[:, :, xb] - d_l2)) < 1e-9
    assert np.max(np.abs(batch.sensitivity("L3")[:, :, xb] - L3 / root)) < 1e-9
    # and the velocity's: d/dL2 of ẋB = θ̇ ∂/∂θ (∂xB/∂L2), θ̇ = 2
    dd_l2 = 2 * (-np.sin(theta) - L2 * np.sin(2 * theta) / root
                 - L2**3 * np.sin(theta) ** 3 * np.cos(theta) / root**3)
    assert np.max(np.abs(batch.sensitivity("L2", 1)[:, :, xb] - dd_l2)) < 1e-8


def test_the_rows_of_phiq_batch_one_file(models, phiq_cli, tmp_path):
    path = crank_slider(models)
    values = [(0.2, 1.0), (0.4, 0.3), (0.25, 0.9), (0.3, 1.1)]  # case 1: the rod is shorter than the crank
    (tmp_path / "cases.csv").write_text("L2,L3\n" + "".join(f"{a!r},{b!r}\n" for a, b in values))
    done = subprocess.run([phiq_cli, "batch", "-q", path, "cases.csv", "-o", "all.csv", "--threads", "2"],
                          cwd=tmp_path, capture_output=True, text=True)
    assert done.returncode == 1, done.stderr  # a case failed
    assert "case 1" in done.stderr
    with open(tmp_path / "all.csv") as f:
        header = f.readline().strip().split(",")
    rows = np.loadtxt(tmp_path / "all.csv", delimiter=",", skiprows=1)
    batch = phiq.run_batch(phiq.load_scene(path), [{"L2": a, "L3": b} for a, b in values], threads=2)
    assert batch.failed == [1] and not batch.ok
    assert batch.messages[1] in done.stderr
    assert header == ["case"] + batch.cases[0].columns
    expected = np.vstack([np.column_stack([np.full(len(c), k), c.table])
                          for k, c in enumerate(batch.cases) if c.ok])
    assert np.array_equal(rows, expected)  # the CSV's doubles, bit for bit
    assert np.isnan(batch["xB"][1, len(batch.cases[1]):]).all()  # after the rows the failed case delivered
    with pytest.raises(phiq.SolveError, match=r"^case 1: .*\(1 of 4 cases failed\)"):
        batch.raise_for_status()


def test_keyword_fields_set_every_cases_options(models):
    batch = phiq.run_batch(phiq.load_scene(crank_slider(models)), {"L2": [0.2, 0.3]}, steps=10, accelerations=False,
                           t_end=math.pi / 2)
    for case in batch.cases:
        assert len(case) == 11 and case.qdd is None and case.qd is not None
        assert case.t[-1] == math.pi / 2
    with pytest.raises(TypeError, match="run_batch.*'stepz'.*steps"):
        phiq.run_batch(phiq.load_scene(crank_slider(models)), {"L2": [0.2]}, stepz=10)


def test_the_forms_cases_may_take_give_the_same_batch(models):
    scene = phiq.load_scene(crank_slider(models))
    columns = phiq.run_batch(scene, {"L2": [0.2, 0.3], "L3": [1.0, 1.1]}, steps=20)
    rows = phiq.run_batch(scene, [{"L3": 1.0, "L2": 0.2}, {"L2": 0.3, "L3": 1.1}], steps=20)
    assert rows.parameters == ["L3", "L2"] and columns.parameters == ["L2", "L3"]
    assert np.array_equal(rows["xB"], columns["xB"])
    pandas = pytest.importorskip("pandas")
    frame = phiq.run_batch(scene, pandas.DataFrame({"L2": [0.2, 0.3], "L3": [1.0, 1.1]}), steps=20)
    assert np.array_equal(frame["xB"], columns["xB"])
    long = columns.to_pandas()
    assert list(long.columns) == ["case"] + columns.cases[0].columns
    assert len(long) == 42 and list(long["case"].unique()) == [0, 1]
    assert np.array_equal(long[long["case"] == 1]["xB"].to_numpy(), columns["xB"][1])
    empty = phiq.run_batch(scene, {"L2": []})
    assert len(empty) == 0 and empty.ok


def test_bad_cases_are_named(models):
    scene = phiq.load_scene(crank_slider(models))
    with pytest.raises(phiq.SceneError, match=r"run_batch: cases: 'L9' is not a parameter.*L2, L3"):
        phiq.run_batch(scene, {"L2": [0.2], "L9": [1.0]})
    with pytest.raises(phiq.SceneError, match="run_batch: sensitivities.*'L7'"):
        phiq.run_batch(scene, {"L2": [0.2]}, sensitivities=["L7"])
    with pytest.raises(ValueError, match=r"different numbers of values \(L2: 2, L3: 1\)"):
        phiq.run_batch(scene, {"L2": [0.2, 0.3], "L3": [1.0]})
    with pytest.raises(ValueError, match="case 1 gives L2; every case gives the names of case 0: L2, L3"):
        phiq.run_batch(scene, [{"L2": 0.2, "L3": 1.0}, {"L2": 0.3}])
    with pytest.raises(TypeError, match=r"run_batch: cases are a mapping of parameter names .* case 0 is 0\.4$"):
        phiq.run_batch(scene, [0.4, 0.3])
    # a case whose values make the scene impossible fails alone, named, and the others are swept
    batch = phiq.run_batch(scene, {"L3": [1.0, -1.0, 1.2]}, threads=2)
    assert batch.failed == [1] and batch.cases[1] is None
    assert batch.messages[1].endswith("constraints[1].length: must be positive, got L3 = -1")
    assert batch.cases[0].ok and batch.cases[2].ok
    assert np.isnan(batch["xB"][1]).all() and not np.isnan(batch["xB"][2]).any()
    with pytest.raises(phiq.SceneError, match=r"^case 1: .*\(1 of 3 cases failed\)"):
        batch.raise_for_status()


def test_ctrl_c_stops_every_case_promptly(models):
    """A batch of a minute on two threads, interrupted half a second after it starts, raises KeyboardInterrupt
    within a few seconds (every case stops at its next check)."""
    call = ('phiq.run_batch(scene, {"L2": [0.3] * 64}, threads=2, steps=10_000_000, every=100_000, '
            'velocities=False, accelerations=False)')
    assert seconds_to_interrupt(f"scene = phiq.load_scene({crank_slider(models)!r})", call) < 10.0


def test_a_scene_built_in_code_with_its_own_sensitivities():
    """A SceneBuilder's scene is read again from its text for each case, the sensitivities its output lists too."""
    b = crank_slider_builder(sensitivities=["L3"])
    batch = phiq.run_batch(b.build(), {"L3": [0.9, 1.3]}).raise_for_status()
    theta, l3 = 2 * batch.t, batch.values[:, :1]
    root = np.sqrt(l3**2 - 0.09 * np.sin(theta) ** 2)
    xb = batch.cases[0].coordinate_names.index("xB")
    assert np.max(np.abs(batch.sensitivity("L3")[:, :, xb] - l3 / root)) < 1e-9
