"""`phiq run -o OUT.h5` read with h5py: every dataset holds the doubles of the CSV of the same run, bit for bit,
in the layout tools/README.md documents (format version 1). Run by ctest (tests/CMakeLists.txt) with PHIQ_CLI and
PHIQ_MODELS_DIR set; skipped there (exit 77) when h5py, numpy or pytest is missing."""
import json
import os
import subprocess

import h5py
import numpy as np
import pytest

PHIQ = os.environ.get("PHIQ_CLI", "phiq")
MODELS = os.environ.get("PHIQ_MODELS_DIR", os.path.join(os.path.dirname(__file__), "..", "..", "models"))

from conftest import EVERY_OUTPUT  # noqa: E402


ORDER = ["t", "q", "qd", "qdd", "points", "drivers", "residuals", "rcond"]


def read_csv(path):
    """Header and rows of a phiq CSV, numbers parsed with float() (phiq writes shortest round-trip doubles)."""
    with open(path) as f:
        header = f.readline().rstrip("\n").split(",")
        rows = [[float(x) for x in line.rstrip("\n").split(",")] for line in f if line.strip()]
    return header, np.array(rows, dtype=np.float64)


def run_both(scene, tmp_path):
    csv, h5 = tmp_path / "r.csv", tmp_path / "r.h5"
    for out in (csv, h5):
        subprocess.run([PHIQ, "run", "-q", "--threads", "1", str(scene), "-o", str(out)], check=True)
    return csv, h5


def scenes(tmp_path_factory):
    every = tmp_path_factory.mktemp("scene") / "every_output.yaml"
    every.write_text(EVERY_OUTPUT)
    return [every, os.path.join(MODELS, "hard/fourbar_m.yaml"), os.path.join(MODELS, "redundant/crank_slider_3d.yaml")]


@pytest.mark.parametrize("which", [0, 1, 2])
def test_every_dataset_equals_the_csv_bit_for_bit(which, tmp_path, tmp_path_factory):
    scene = scenes(tmp_path_factory)[which]
    csv, h5 = run_both(scene, tmp_path)
    header, values = read_csv(csv)
    with h5py.File(h5, "r") as f:
        assert f.attrs["format"] == "phiq results"
        assert f.attrs["format_version"] == 1
        assert f.attrs["scene_path"] == str(scene)
        with open(scene) as s:
            assert f.attrs["scene"] == s.read()
        assert set(f.keys()) <= set(ORDER)
        col = 0
        for name in [n for n in ORDER if n in f]:
            d = f[name]
            assert d.dtype == np.float64
            names = list(d.attrs["columns"])
            assert len(d.attrs["units"]) == len(names)
            data = d[()]
            if data.ndim == 1:
                assert names == [name]
                data = data.reshape(-1, 1)
            assert data.shape == (values.shape[0], len(names)), name
            assert names == header[col:col + len(names)], name
            # bit for bit: the same 64-bit patterns, not merely equal values (0.0 == -0.0, nan != nan)
            assert np.array_equal(data.view(np.uint64), values[:, col:col + len(names)].view(np.uint64)), name
            col += len(names)
        assert col == len(header)  # every CSV column is in some dataset


def test_every_output_kind_and_its_units(tmp_path, tmp_path_factory):
    _, h5 = run_both(scenes(tmp_path_factory)[0], tmp_path)
    with h5py.File(h5, "r") as f:
        assert list(f.keys()) == sorted(ORDER)  # all eight present
        assert f["q"].shape == (73, 8) and f["t"].shape == (73,) and f["rcond"].shape == (73,)
        assert list(f["q"].attrs["units"]) == ["rad", "m", "m", "m", "m", "rad", "m", "m"]
        assert list(f["qdd"].attrs["units"])[0] == "rad/s^2"
        assert list(f["points"].attrs["columns"])[:6] == ["B.x", "B.y", "B.vx", "B.vy", "B.ax", "B.ay"]
        assert list(f["drivers"].attrs["columns"]) == ["motor.f", "motor.df", "motor.ddf"]
        assert list(f["residuals"].attrs["columns"]) == ["rocker.residual", "residual"]
        assert f["q"].chunks is not None and f["q"].maxshape == (None, 8)  # extendible, chunked
        # the driver's law, exactly: theta2 = t
        assert np.array_equal(f["drivers"][:, 0], f["t"][()])


def test_identifier_names_are_the_files_column_names_too(tmp_path, tmp_path_factory):
    """`--names identifiers` names each dataset's columns as the CSV of the same option, and `phiq compare` of the
    two agrees column by column (none only in one file)."""
    scene = scenes(tmp_path_factory)[0]
    csv, h5 = tmp_path / "i.csv", tmp_path / "i.h5"
    for out in (csv, h5):
        subprocess.run([PHIQ, "run", "-q", "--threads", "1", "--names", "identifiers", str(scene), "-o", str(out)],
                       check=True)
    header, values = read_csv(csv)
    assert "B__vx" in header and "motor__ddf" in header
    with h5py.File(h5, "r") as f:
        names = []
        for name in [n for n in ORDER if n in f]:
            names += list(f[name].attrs["columns"])
        assert list(f["points"].attrs["columns"])[:3] == ["B__x", "B__y", "B__vx"]
    assert names == header
    r = subprocess.run([PHIQ, "compare", "--json", str(csv), str(h5)], capture_output=True, text=True)
    assert r.returncode == 0, r.stderr
    report = json.loads(r.stdout)
    assert report["only_in_a"] == [] and report["only_in_b"] == []


def test_a_batch_file_names_its_columns_as_its_csv(tmp_path):
    """`phiq batch --names identifiers -o OUT.h5`: the same names as the batch's CSV (`case` first)."""
    scene = os.path.join(MODELS, "seed/crank_slider_mixed.yaml")
    cases = tmp_path / "cases.csv"
    cases.write_text("L2\n0.3\n0.31\n")
    csv, h5 = tmp_path / "b.csv", tmp_path / "b.h5"
    for out in (csv, h5):
        subprocess.run([PHIQ, "batch", "-q", "--names", "identifiers", scene, str(cases), "-o", str(out)],
                       check=True)
    header, values = read_csv(csv)
    with h5py.File(h5, "r") as f:
        names = ["case"] + [c for n in ORDER if n in f for c in f[n].attrs["columns"]]
        assert list(f["qd"].attrs["columns"]) == ["theta2__v", "xA__v", "yA__v", "xB__v"]
        assert f["q"].shape[0] == values.shape[0]
    assert names == header


def test_the_parameters_a_run_used_are_in_the_file_and_the_summary(tmp_path):
    """`phiq run --set`: the file's root attributes parameter_names / parameter_values and the summary's
    `parameters` hold the values the run used (the scene's text alone says the file's), and the rows are those of
    the scene edited to say them."""
    scene = os.path.join(MODELS, "seed/crank_slider_mixed.yaml")
    h5, summary = tmp_path / "set.h5", tmp_path / "set.json"
    subprocess.run([PHIQ, "run", "-q", scene, "--set", "L3=1.1", "--set", "L2=0.25", "-o", str(h5),
                    "--summary", str(summary)], check=True)
    with open(scene) as s:
        edited = s.read().replace("L2: 0.3 ", "L2: 0.25").replace("L3: 1.0 ", "L3: 1.1 ")
    (tmp_path / "edited.yaml").write_text(edited)
    csv = tmp_path / "edited.csv"
    subprocess.run([PHIQ, "run", "-q", str(tmp_path / "edited.yaml"), "-o", str(csv)], check=True)
    header, rows = read_csv(csv)
    with h5py.File(h5, "r") as f:
        assert list(f.attrs["parameter_names"]) == ["L2", "L3"]  # in the scene's order
        assert f.attrs["parameter_values"].dtype == np.float64
        assert list(f.attrs["parameter_values"]) == [0.25, 1.1]
        q = f["q"][:]
        assert np.array_equal(q, rows[:, 1:1 + q.shape[1]])
    assert json.loads(summary.read_text())["parameters"] == {"L2": 0.25, "L3": 1.1}
    # without --set: the file's own values
    plain = tmp_path / "plain.h5"
    subprocess.run([PHIQ, "run", "-q", scene, "-o", str(plain)], check=True)
    with h5py.File(plain, "r") as f:
        assert list(f.attrs["parameter_values"]) == [0.3, 1.0]
