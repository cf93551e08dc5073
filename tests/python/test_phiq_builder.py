"""Models built in code (engine/python/phiq/_builder.py): the scene format's own words as keyword arguments, the
same model and the same bits as the scene file, and a message that points at the Python line at fault."""
import os

import numpy as np
import pytest

import phiq

from conftest import MODELS, crank_slider_builder


def test_built_in_code_equals_the_scene_file():
    built = phiq.run_sweep(crank_slider_builder().build())
    loaded = phiq.run_sweep(phiq.load_scene(os.path.join(MODELS, "seed", "crank_slider_mixed.yaml")))
    assert built.columns == loaded.columns
    assert np.array_equal(built.table, loaded.table)


def test_a_spatial_model_in_code():
    """A spatial crank-slider in natural coordinates: crank tip A on a unit circle about z, slider B on the x axis;
    x_B = r cos θ + sqrt(L² − r² sin² θ) as in the plane."""
    r, L = 0.2, 0.7
    b = phiq.SceneBuilder("crank_slider_3d", dimension=3)
    b.parameters(r=r, L=L)
    b.coordinates(xA=r, yA=0.0, zA=0.0, xB=r + L)
    b.point("O", [0, 0, 0])
    b.point("A", ["xA", "yA", "zA"])
    b.point("B", ["xB", 0, 0])
    b.constraint("crank", type="distance", points=["O", "A"], length="r")
    b.constraint("plane", type="equation", expr="zA", unit="length")
    b.constraint("rod", type="distance", points=["A", "B"], length="L")
    b.driver("motor", expr="atan2(yA, xA)", unit="angle", law={"type": "linear", "initial": 0, "rate": 2})
    b.time(start=0, end=0.7, steps=70)
    result = phiq.run_sweep(b.build())
    assert result.ok, result.message
    th = 2 * result.t
    np.testing.assert_allclose(result["xB"], r * np.cos(th) + np.sqrt(L * L - (r * np.sin(th)) ** 2), atol=1e-9)


def test_a_bad_entry_names_the_python_line():
    b = crank_slider_builder()
    line = test_a_bad_entry_names_the_python_line.__code__.co_firstlineno + 3
    b.constraint("stop", type="distance", points=["A", "Q"], length=1.0)
    with pytest.raises(phiq.SceneError) as e:
        b.build()
    message = str(e.value)
    assert message.startswith(f"{__file__}:{line}: constraints[2]"), message
    assert "Q" in message and "\n" not in message


def test_unknown_type_lists_the_registry():
    b = crank_slider_builder()
    b.constraint("g", type="sprocket", bodies=["A", "B"])
    with pytest.raises(phiq.SceneError, match="gear"):
        b.build()


def test_parameters_for_a_study():
    b = crank_slider_builder()
    for L3 in (0.8, 1.0, 1.5):
        result = phiq.run_sweep(b.build(parameters={"L3": L3}), steps=18)
        assert result.ok
        np.testing.assert_allclose(result["xB"].max(), 0.3 + L3, rtol=0, atol=1e-9)  # θ = 0: x_B = r + L
