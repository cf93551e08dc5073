"""phiq: sparse, large-scale multibody kinematics, from Python.

A five-minute tour is in engine/python/README.md. In short::

    import phiq
    scene = phiq.load_scene("models/seed/crank_slider_mixed.yaml")
    result = phiq.run_sweep(scene, threads=2)      # t, q, qd, qdd: numpy arrays (rows × coordinates)
    xB = result["xB"]                              # a column by name
    report = phiq.check(scene)                     # rank, dof, Grübler, redundant and conflicting constraints
    batch = phiq.run_batch(scene, {"L2": [0.2, 0.3, 0.4]})   # the cases in parallel; batch["xB"]: cases × rows

Numerical outcomes are statuses (``SolveStatus``) in the returned summaries and results, never exceptions:
a sweep that fails returns the rows it delivered, with ``ok`` False and phiq's one-line ``message``;
``result.raise_for_status()`` turns that into ``SolveError`` when an exception is wanted. Programming errors
(wrong sizes, unknown names, settings no solve can honour) raise ValueError, and wrong types TypeError, with the
messages of phiq's C++ checks; a bad scene raises ``SceneError`` (a ValueError) naming file, line and field.
phiq releases the GIL while it works; Ctrl-C stops a sweep at its next delivered row (KeyboardInterrupt).
"""

from __future__ import annotations

import dataclasses
from typing import Any, Dict, List, Optional, Sequence, Tuple, Union

from . import _phiq
from ._phiq import (AssemblySummary, ConstraintInfo, JacobianUpdate, LinearSummary, Model, NewtonOptions, Part,
                    PositionSummary, Predictor, RankReport, Scene, SceneError, SensitivityForm, SolveStatus,
                    StepSummary, Stepper, SweepOptions, SweepSummary, SweepWarning, Unit, WorkCounters, Workspace,
                    analyse_rank, assemble, clearance, constraint_kinds, drawn_parts, load_scene, modes,
                    parse_scene, solve_acceleration, solve_position, solve_velocity)
from ._batch import BatchResult, run_batch_tables
from ._builder import SceneBuilder
from ._results import SolveError, SweepResult

__version__: str = _phiq.__version__
SceneError.__doc__ = ("A scene that cannot be used (a ValueError): one line 'FILE:LINE:COL: field.path: message', or "
                      "for a SceneBuilder the Python line of the entry at fault.")

__all__ = [
    "AssemblySummary", "BatchResult", "CheckReport", "ConstraintInfo", "JacobianUpdate", "LinearSummary", "Model",
    "NewtonOptions", "Part", "PositionSummary", "Predictor", "RankReport", "Scene", "SceneBuilder", "SceneError",
    "SensitivityForm", "SolveError", "SolveStatus", "StepSummary", "Stepper", "SweepOptions", "SweepResult",
    "SweepSummary", "SweepWarning", "Unit", "WorkCounters", "Workspace",
    "analyse_rank", "assemble", "check", "clearance", "constraint_kinds", "drawn_parts", "driver_efforts",
    "load_scene", "modes", "parse_scene", "run_batch", "run_sweep", "solve_acceleration", "solve_position",
    "solve_velocity",
]


def driver_efforts(scene: Scene, result: SweepResult) -> Tuple[List[str], Any]:
    """Each driver's effort along a sweep of ``scene`` (the motor torque or force, conjugate to what it drives), from
    the parts' mass and the scene's ``loads``: inverse dynamics at every row (engine/include/phiq/inverse_dynamics.hpp).
    ``result`` needs velocities, accelerations and every coordinate. Returns (driver names, rows × drivers array)."""
    if result.qd is None or result.qdd is None:
        raise ValueError("driver_efforts: the result has no velocities or accelerations (output velocities and "
                         "accelerations: true)")
    return _phiq.driver_efforts(scene, result.t, result.q, result.qd, result.qdd)


def run_sweep(scene: Scene, options: Optional[SweepOptions] = None, *, identifier_names: bool = False,
              sensitivities: Optional[Sequence[Union[str, Tuple[str, float]]]] = None, **overrides: Any) -> SweepResult:
    """Sweep a scene as ``phiq run`` does: the assembly from its rough placement (redundant constraints of a
    consistent model left out of the square solves), then every time point of the grid.

    ``options``: the SweepOptions to use (default: ``scene.options``); keyword arguments then set its fields, e.g.
    ``run_sweep(scene, threads=2, steps=1000, accelerations=False)`` (TypeError for a name SweepOptions lacks).
    ``identifier_names``: name the columns as Python identifiers (``theta2__v`` for ``theta2.v``).
    ``sensitivities``: parameters of the scene whose sensitivities ∂q/∂p (and ∂q̇/∂p, ∂q̈/∂p) to deliver instead of
    its ``output.sensitivities``, each a name or a ``(name, step)`` tuple (SweepOptions.set_sensitivities); read
    them with SweepResult.sensitivity.
    Every thread count gives the same bits. Returns a SweepResult (check ``ok``, or call ``raise_for_status()``).
    """
    opts = scene.options if options is None else options
    if overrides or sensitivities is not None:
        if options is not None:
            opts = _copy_options(options)
        if sensitivities is not None:
            opts.set_sensitivities(scene, list(sensitivities))
        _set_fields(opts, overrides, "run_sweep")
    return SweepResult(_phiq._sweep_scene(scene, opts, identifier_names))


def run_batch(scene: Scene, cases: Any, *, threads: int = 0, identifier_names: bool = False,
              sensitivities: Optional[Sequence[Union[str, Tuple[str, float]]]] = None,
              **overrides: Any) -> BatchResult:
    """Sweep a scene for many sets of parameter values, as ``phiq batch`` does: each case is the scene read again
    with its values (over the values ``scene`` was loaded with), sharing its pattern and symbolic analysis, and
    swept on one thread; the cases run in parallel on ``threads`` threads (0: all cores), every thread count giving
    the same bits, those of ``run_sweep`` on the scene loaded with the case's values.

    ``cases``: a mapping of parameter names to equally long sequences of values (a dict, a pandas.DataFrame), or a
    sequence of mappings of the same names; each name a parameter of the scene (SceneError otherwise).
    Keyword arguments set fields of every case's SweepOptions (its own: a time range or a point may depend on its
    values), as in run_sweep (TypeError for a name SweepOptions lacks). ``sensitivities``: as run_sweep's, at each
    case's values. A case whose values make the scene impossible, or whose sweep fails, fails alone: BatchResult's
    ``failed`` and ``messages`` name it. Ctrl-C stops every case at its next row (KeyboardInterrupt).
    """
    _set_fields(_copy_options(scene.options), overrides, "run_batch")  # a bad name or type before any case runs
    return run_batch_tables(scene, cases, sensitivities, overrides, identifier_names, threads)


def _set_fields(opts: SweepOptions, fields: Dict[str, Any], who: str) -> None:
    """Sets SweepOptions fields by name, TypeError naming ``who`` and listing the fields for a name it lacks."""
    for name, value in fields.items():
        if not hasattr(opts, name) or name.startswith("_"):
            names = sorted(n for n in dir(opts) if not n.startswith("_") and not callable(getattr(opts, n)))
            raise TypeError(f"{who}() got an unexpected keyword argument '{name}' (SweepOptions fields: "
                            f"{', '.join(names)})")
        setattr(opts, name, value)


def _copy_options(options: SweepOptions) -> SweepOptions:
    import copy
    return copy.copy(options)


@dataclasses.dataclass(frozen=True)
class CheckReport:
    """What ``phiq check`` reports: the counts, the assembly from the rough placement at ``time``, and the rank
    analysis there (rank is a property of a configuration)."""
    coordinates: int
    equations: int
    kinematic_equations: int
    driver_equations: int
    constraints: int
    nonzeros: int
    time: float
    status: SolveStatus
    message: str
    rank: int
    dof: int
    driven_dof: int
    grubler: Optional[int]
    redundant: List[str]
    consistent: bool
    conflicts: List[str]
    uncertain: bool
    q: Any  # numpy array: the assembled position (or where the assembly stopped)

    @property
    def ok(self) -> bool:
        """The scene assembles and its constraints are consistent."""
        return self.status == SolveStatus.SUCCESS


def check(scene: Scene, time: Optional[float] = None) -> CheckReport:
    """Count, assemble and analyse a scene as ``phiq check`` does: minimum-norm assembly from the rough placement
    at ``time`` (default: the sweep's start), then the rank there — degrees of freedom, Grübler count, redundant
    constraints (consistent) or conflicting ones (inconsistent)."""
    model = scene.model
    opts = scene.options
    t = opts.t_begin if time is None else time
    q, a = assemble(model, t, model.initial_positions, opts.assembly)
    drivers = sum(c.rows for c in model.constraints if c.depends_on_time)
    r = a.rank
    return CheckReport(coordinates=model.num_coordinates, equations=model.num_equations,
                       kinematic_equations=model.num_equations - drivers, driver_equations=drivers,
                       constraints=len(model.constraints), nonzeros=model.nonzeros, time=t, status=a.status,
                       message=a.message, rank=r.rank, dof=r.dof, driven_dof=r.driven_dof, grubler=model.grubler,
                       redundant=list(r.redundant), consistent=a.consistent, conflicts=list(a.conflicts),
                       uncertain=r.uncertain, q=q)
