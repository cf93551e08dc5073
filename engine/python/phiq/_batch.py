"""The result of a batch: one SweepResult per case (the scene swept with that case's parameter values), and the
cases' columns stacked into arrays with a case axis (cases × rows), as numpy and a Monte Carlo estimate want them."""

from __future__ import annotations

from typing import Any, Dict, List, Optional, Sequence, Tuple

import numpy as np

from . import _phiq
from ._results import SolveError, SweepResult


def case_table(cases: Any) -> Tuple[List[str], np.ndarray]:
    """The parameter names and the values (cases × names, float64) of run_batch's ``cases``: a mapping of names to
    equally long sequences of values (a dict, a pandas.DataFrame), or a sequence of mappings of the same names."""
    if hasattr(cases, "keys"):
        names = [str(k) for k in cases.keys()]
        columns = [np.atleast_1d(np.asarray(cases[k], dtype=float)) for k in cases.keys()]
        for name, c in zip(names, columns):
            if c.ndim != 1:
                raise ValueError(f"run_batch: the values of '{name}' are not one value per case (shape {c.shape})")
        lengths = {len(c) for c in columns}
        if len(lengths) > 1:
            sizes = ", ".join(f"{name}: {len(c)}" for name, c in zip(names, columns))
            raise ValueError(f"run_batch: the parameters have different numbers of values ({sizes})")
        n = lengths.pop() if lengths else 0
        return names, np.stack(columns, axis=1) if columns else np.zeros((n, 0))
    rows = list(cases)
    if not rows:
        return [], np.zeros((0, 0))
    if not hasattr(rows[0], "keys"):
        raise TypeError(f"run_batch: cases are a mapping of parameter names to one value per case ({{'L2': [0.4, "
                        f"0.3]}}, a pandas.DataFrame) or a sequence of such mappings, one per case; case 0 is "
                        f"{rows[0]!r}")
    names = [str(k) for k in rows[0].keys()]
    values = np.empty((len(rows), len(names)))
    for k, case in enumerate(rows):
        if not hasattr(case, "keys") or sorted(str(n) for n in case.keys()) != sorted(names):
            given = ", ".join(str(n) for n in case.keys()) if hasattr(case, "keys") else repr(case)
            raise ValueError(f"run_batch: case {k} gives {given}; every case gives the names of case 0: "
                             f"{', '.join(names)}")
        values[k] = [float(case[n]) for n in names]
    return names, values


class BatchResult:
    """The cases of ``run_batch``: the scene swept for each set of parameter values, as ``phiq batch`` sweeps them.

    ``cases``: one SweepResult per case, in the order given (each the bits of ``run_sweep`` on the scene loaded with
    that case's values), or None for a case whose values make the scene impossible (a negative length: its
    ``messages`` entry is the SceneError line). ``parameters`` and ``values`` (cases × parameters) are the cases as
    given. Columns stacked over the cases: ``batch["xB"]`` (cases × rows, NaN after the rows a failed case
    delivered), ``batch.t``, ``batch.sensitivity(name, order)`` (cases × rows × coordinates).
    ``threads``, ``seconds`` (wall time of the batch) and ``shared_analyses`` (cases on the scene's symbolic
    analysis) say how it ran.
    """

    def __init__(self, names: List[str], values: np.ndarray, raw: Dict[str, Any]):
        self.parameters: List[str] = names
        self.values: np.ndarray = values
        self.values.flags.writeable = False
        self.cases: List[Optional[SweepResult]] = [SweepResult(t) if t is not None else None for t in raw["tables"]]
        self.messages: List[str] = [error if result is None else result.message
                                    for result, error in zip(self.cases, raw["scene_errors"])]
        self.threads: int = raw["threads"]
        self.seconds: float = raw["seconds"]
        self.shared_analyses: int = raw["shared_analyses"]

    def __len__(self) -> int:
        return len(self.cases)

    @property
    def failed(self) -> List[int]:
        """The cases that did not deliver every row: their scene could not be read, or their sweep failed."""
        return [k for k, c in enumerate(self.cases) if c is None or not c.ok]

    @property
    def ok(self) -> bool:
        """True when every case was swept to its end."""
        return not self.failed

    def raise_for_status(self) -> "BatchResult":
        """Raise for the first failed case (SceneError when its values make the scene impossible, SolveError when
        its sweep failed), naming it and how many failed; return self when none did."""
        failed = self.failed
        if not failed:
            return self
        k = failed[0]
        message = f"case {k}: {self.messages[k]} ({len(failed)} of {len(self)} cases failed)"
        case = self.cases[k]
        if case is None:
            raise _phiq.SceneError(message)
        raise SolveError(message, case.status, case.summary)

    def _swept(self) -> List[Tuple[int, SweepResult]]:
        swept = [(k, c) for k, c in enumerate(self.cases) if c is not None]
        if not swept:
            raise KeyError("no case of this batch was swept (every case's scene failed: see messages)")
        return swept

    def _stack(self, one: Any) -> np.ndarray:
        """Each swept case's array `one(case)` (rows × …) in a cases × rows × … array, NaN where a case has no row."""
        swept = self._swept()
        arrays = {k: one(c) for k, c in swept}
        first = arrays[swept[0][0]]
        rows = max(len(a) for a in arrays.values())
        out = np.full((len(self.cases), rows) + first.shape[1:], np.nan)
        for k, a in arrays.items():
            out[k, :len(a)] = a
        return out

    def column(self, name: str) -> np.ndarray:
        """One column of every case by its name (``'xB'``, ``'xB.v'``, ``'P.x'``): cases × rows."""
        return self._stack(lambda c: c.column(name))

    __getitem__ = column

    @property
    def t(self) -> np.ndarray:
        """The times of every case's rows: cases × rows."""
        return self.column("t")

    def sensitivity(self, parameter: str, order: int = 0) -> np.ndarray:
        """SweepResult.sensitivity of every case: cases × rows × the columns of ``q`` (``qd``, ``qdd``)."""
        return self._stack(lambda c: c.sensitivity(parameter, order))

    def to_pandas(self) -> Any:
        """The rows of the cases swept to their end in one pandas.DataFrame, a ``case`` column first and then the
        columns of ``phiq run``, as the one file of ``phiq batch`` (python3-pandas must be installed)."""
        import pandas  # imported here: pandas is optional

        frames = []
        for k, c in self._swept():
            if c.ok:
                frame = pandas.DataFrame(c.table, columns=c.columns)
                frame.insert(0, "case", k)
                frames.append(frame)
        if not frames:
            return pandas.DataFrame(columns=["case"] + self._swept()[0][1].columns)
        return pandas.concat(frames, ignore_index=True)

    def __repr__(self) -> str:
        failed = self.failed
        return (f"<phiq.BatchResult: {len(self)} cases of {', '.join(self.parameters) or 'no parameter'}, "
                f"{len(failed)} failed, {self.threads} threads, {self.seconds:.3g} s>")


def run_batch_tables(scene: Any, cases: Any, sensitivities: Optional[Sequence[Any]], fields: Dict[str, Any],
                     identifier_names: bool, threads: int) -> BatchResult:
    """The batch itself (run_batch checks its keyword arguments first)."""
    names, values = case_table(cases)
    raw = _phiq._batch_scene(scene, names, values, None if sensitivities is None else list(sensitivities), fields,
                             identifier_names, threads)
    return BatchResult(names, np.ascontiguousarray(values), raw)
