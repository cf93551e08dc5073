"""phiq from Python, the model and the three problems (engine/python/src/bind_model.cpp, bind_solve.cpp): the
crank-slider's closed form through solve_position / solve_velocity / solve_acceleration, Φq against central
differences of Φ, Φt and γ against differences in time, and the one-line messages of the error paths."""
import math
import os

import numpy as np
import pytest
import scipy.sparse

import phiq

from conftest import MODELS

CRANK_SLIDER = os.path.join(MODELS, "seed", "crank_slider_mixed.yaml")


def crank_slider_exact(t):
    """x_B, ẋ_B, ẍ_B of the notes' crank-slider (r = 0.3, L = 1, θ = 2t) in closed form."""
    r, L, w = 0.3, 1.0, 2.0
    th = w * t
    s, c = math.sin(th), math.cos(th)
    root = math.sqrt(L * L - r * r * s * s)
    x = r * c + root
    dx_dth = -r * s - r * r * s * c / root
    d2x_dth2 = -r * c - r * r * (c * c - s * s) / root - r ** 4 * s * s * c * c / root ** 3
    return x, w * dx_dth, w * w * d2x_dth2


def test_crank_slider_closed_form_through_the_three_solves():
    scene = phiq.load_scene(CRANK_SLIDER)
    model = scene.model
    ws = phiq.Workspace(model)
    xb = model.coordinate_index("xB")
    for k in range(0, 101):
        t = 0.0314 * k
        p = phiq.solve_position(model, t, ws)
        assert p.ok, p.message
        assert phiq.solve_velocity(model, t, ws).ok
        assert phiq.solve_acceleration(model, t, ws).ok
        x, v, a = crank_slider_exact(t)
        assert abs(ws.q[xb] - x) < 1e-9
        assert abs(ws.qd[xb] - v) < 1e-9
        assert abs(ws.qdd[xb] - a) < 1e-9
    assert ws.counters.newton_iterations >= 101


@pytest.mark.parametrize("scene_file", ["seed/fourbar_reference_point.yaml", "seed/crank_slider_equations.yaml",
                                        "spatial/rssr.yaml", "spatial/crank_slider_natural.yaml"])
def test_jacobian_equals_central_differences_of_phi(scene_file):
    model = phiq.load_scene(os.path.join(MODELS, scene_file)).model
    rng = np.random.default_rng(7)
    q = model.initial_positions + 0.01 * rng.standard_normal(model.num_coordinates)
    t = 0.3
    J = model.jacobian(q, t)
    assert isinstance(J, scipy.sparse.csc_matrix)
    assert J.shape == (model.num_equations, model.num_coordinates)
    assert J.nnz == model.nonzeros
    dense = J.toarray()
    for j in range(model.num_coordinates):
        h = 1e-6 * max(1.0, abs(q[j]))
        e = np.zeros_like(q)
        e[j] = h
        fd = (model.residual(q + e, t) - model.residual(q - e, t)) / (2 * h)
        np.testing.assert_allclose(dense[:, j], fd, rtol=1e-6, atol=1e-7)


def test_phi_t_and_gamma_along_the_solved_motion():
    """Φt against the time difference of Φ at fixed q; γ = Φq q̈ at the solved q̈ (the acceleration equation), and
    q̈ against the time difference of the solved q̇."""
    scene = phiq.load_scene(os.path.join(MODELS, "seed", "crank_slider_equations.yaml"))
    model = scene.model
    ws = phiq.Workspace(model)
    t, h = 0.7, 1e-5
    assert phiq.solve_position(model, t, ws).ok
    q = ws.q.copy()
    fd_t = (model.residual(q, t + h) - model.residual(q, t - h)) / (2 * h)
    np.testing.assert_allclose(model.phi_t(q, t), fd_t, rtol=1e-7, atol=1e-8)
    assert phiq.solve_velocity(model, t, ws).ok and phiq.solve_acceleration(model, t, ws).ok
    J = model.jacobian(ws.q, t)
    np.testing.assert_allclose(J @ ws.qdd, model.gamma(ws.q, ws.qd, t), rtol=1e-10, atol=1e-10)
    qd = []
    for tt in (t - h, t + h):
        w2 = phiq.Workspace(model)
        w2.q = q
        assert phiq.solve_position(model, tt, w2).ok and phiq.solve_velocity(model, tt, w2).ok
        qd.append(w2.qd.copy())
    np.testing.assert_allclose(ws.qdd, (qd[1] - qd[0]) / (2 * h), rtol=1e-5, atol=1e-6)


def test_workspace_vectors_are_views_and_keep_their_size():
    model = phiq.load_scene(CRANK_SLIDER).model
    ws = phiq.Workspace(model)
    ws.q[3] = 1.3  # written in place
    assert ws.q[3] == 1.3
    with pytest.raises(ValueError, match=r"^q has 3 entries; the model has 4 coordinates$"):
        ws.q = np.zeros(3)
    with pytest.raises(ValueError, match=r"^qd has 5 entries; the model has 4 coordinates$"):
        model.gamma(np.zeros(4), np.zeros(5), 0.0)


def test_error_paths_name_what_is_wrong(tmp_path):
    scene = phiq.load_scene(CRANK_SLIDER)
    other = phiq.load_scene(CRANK_SLIDER)
    ws = phiq.Workspace(other.model)
    with pytest.raises(ValueError, match="^workspace was made for another model$"):
        phiq.solve_position(scene.model, 0.0, ws)
    with pytest.raises(ValueError, match="xC"):
        scene.model.coordinate_index("xC")
    with pytest.raises(TypeError):
        phiq.solve_position(scene.model, "zero", phiq.Workspace(scene.model))
    bad = tmp_path / "bad.yaml"
    bad.write_text("phiq: 1\ncoordinates: {x: 0}\nconstraints:\n  - {name: c, type: distance, points: [A, B], length: -1}\n"
                   "time: {start: 0, end: 1, steps: 1}\n")
    with pytest.raises(phiq.SceneError) as e:
        phiq.load_scene(str(bad))
    assert str(e.value).startswith(str(bad) + ":4:")
    assert "\n" not in str(e.value)
    assert isinstance(e.value, ValueError)
    with pytest.raises(phiq.SceneError, match="missing.yaml"):
        phiq.load_scene(str(tmp_path / "missing.yaml"))
    with pytest.raises(phiq.SceneError, match=r"'L9' \(given for this run\) is not a parameter of the scene"):
        phiq.load_scene(CRANK_SLIDER, parameters={"L9": 1.0})
    # the parameters, in file order, with the overrides applied
    assert list(phiq.load_scene(CRANK_SLIDER).parameters.items()) == [("L2", 0.3), ("L3", 1.0)]
    assert phiq.load_scene(CRANK_SLIDER, parameters={"L3": 1.5}).parameters == {"L2": 0.3, "L3": 1.5}
    with pytest.raises(ValueError, match="tolerance"):
        phiq.solve_position(scene.model, 0.0, phiq.Workspace(scene.model), phiq.NewtonOptions(tolerance=-1))


def test_check_reports_rank_dof_and_redundancy():
    door = phiq.check(phiq.load_scene(os.path.join(MODELS, "redundant", "door_three_hinges.yaml")))
    assert door.ok and door.consistent
    assert door.dof == 1 and door.driven_dof == 0
    assert door.grubler == -9
    assert door.redundant  # the third hinge's rows
    misaligned = phiq.check(phiq.load_scene(os.path.join(MODELS, "redundant", "door_misaligned.yaml")))
    assert misaligned.status == phiq.SolveStatus.INCONSISTENT and not misaligned.consistent
    assert any("hinge3" in c for c in misaligned.conflicts)
    cs = phiq.check(phiq.load_scene(CRANK_SLIDER))
    assert (cs.coordinates, cs.equations, cs.rank, cs.dof, cs.redundant) == (4, 4, 3, 1, [])


def test_the_registry_is_visible_from_python():
    kinds = phiq.constraint_kinds()
    types = {(k["type"], k["dimension"]) for k in kinds}
    assert ("distance", 2) in types and ("revolute", 3) in types and ("polar", 2) in types
    assert all(k["example"] for k in kinds)
    # one entry per scene form: as many as the kinds' forms, each type once per dimension and section
    assert len(types) == len({(k["type"], k["dimension"], k["section"]) for k in kinds})
    # the joint traits: what a driver drives is measured, a shaft measures its angle; a screw measures both
    assert all(set(k["drives"]) <= set(k["measures"]) for k in kinds)
    assert all("angle" in k["measures"] for k in kinds if k["shaft"])
    screw = [k for k in kinds if k["type"] == "screw"]
    both = ["angle", "distance"]
    assert [(k["measures"], k["drives"], k["shaft"]) for k in screw] == [(both, both, True)]


def test_everything_public_has_a_docstring():
    import inspect
    missing = []
    for name in phiq.__all__:
        obj = getattr(phiq, name)
        if not (obj.__doc__ or "").strip():
            missing.append(name)
        if inspect.isclass(obj) and obj is not phiq.CheckReport:
            for attr, value in vars(obj).items():
                if attr.startswith("_") or attr in ("value", "name") or not (callable(value) or isinstance(value, property)):
                    continue
                if not (getattr(value, "__doc__", None) or "").strip():
                    missing.append(f"{name}.{attr}")
    assert missing == []


def test_derivatives_at_an_unsolved_q_are_refused():
    model = phiq.load_scene(CRANK_SLIDER).model
    ws = phiq.Workspace(model)  # q is the rough placement: not a solution
    qd = ws.qd.copy()
    v = phiq.solve_velocity(model, 0.0, ws)
    assert v.status == phiq.SolveStatus.POSITION_NOT_SOLVED and not v.ok
    assert v.message.startswith("q does not solve the position problem at t = 0: constraint '")
    assert np.array_equal(ws.qd, qd)
    assert phiq.solve_velocity(model, 0.0, ws, tolerance=math.inf).ok  # the caller vouches for q
    assert phiq.solve_position(model, 0.0, ws).ok and phiq.solve_velocity(model, 0.0, ws).ok


def test_names_to_constraints_and_rows():
    model = phiq.load_scene(CRANK_SLIDER).model
    crank = model.constraint("crank")
    assert (crank.name, crank.kind, crank.rows) == ("crank", "polar", 2)
    assert model.constraints[model.constraint_index("rod")].name == "rod"
    assert model.row_index("crank[1]") == crank.first_row + 1
    assert model.row_name(model.row_index("rod")) == "rod"
    with pytest.raises(ValueError, match="hinge"):
        model.constraint("hinge")
