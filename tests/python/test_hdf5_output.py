"""`phiq run -o OUT.h5` read with h5py: every dataset holds the doubles of the CSV of the same run, bit for bit,
in the layout tools/README.md documents (format version 1). Run by ctest (tests/CMakeLists.txt) with PHIQ_CLI and
PHIQ_MODELS_DIR set; skipped there (exit 77) when h5py, numpy or pytest is missing."""
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
