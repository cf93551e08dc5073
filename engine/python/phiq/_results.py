"""The result of a sweep: numpy views of one table of doubles (no copy per row), the names of its columns, the
summary as a dict and the warnings as objects."""

from __future__ import annotations

import functools

from typing import Any, Dict, List, Optional

import numpy as np

from . import _phiq


class SolveError(RuntimeError):
    """A numerical failure turned into an exception by ``raise_for_status()``: phiq's one-line message, with the
    status (a ``SolveStatus``) and the summary (a dict) attached."""

    def __init__(self, message: str, status: "_phiq.SolveStatus", summary: Dict[str, Any]):
        super().__init__(message)
        self.status = status
        self.summary = summary


class SweepResult:
    """Rows of a sweep, as the CSV of ``phiq run`` holds them (the same columns and the same doubles).

    Arrays (rows × columns, views of one table, valid as long as any of them is referenced):
      ``t``: times; ``q``: positions of the coordinate columns; ``qd``, ``qdd``: velocities and accelerations, or
      None when not asked for; ``outputs``: the other columns (points, drivers, residuals, rcond); ``table``: all of
      them, ``columns`` naming each.
    A failed sweep holds the rows delivered before the failure; ``ok`` is False, ``status`` and ``message`` say
    why, and ``raise_for_status()`` raises ``SolveError``.
    """

    def __init__(self, table: Any):
        self._table = table
        self.table: np.ndarray = np.asarray(table)
        self.table.flags.writeable = False
        nq, nv, na = table.q_columns, table.v_columns, table.a_columns
        self._bounds = (1, 1 + nq, 1 + nq + nv, 1 + nq + nv + na)
        self.t: np.ndarray = self.table[:, 0]
        self.q: np.ndarray = self.table[:, 1:1 + nq]
        self.qd: Optional[np.ndarray] = self.table[:, 1 + nq:1 + nq + nv] if nv else None
        self.qdd: Optional[np.ndarray] = self.table[:, 1 + nq + nv:1 + nq + nv + na] if na else None
        self.outputs: np.ndarray = self.table[:, 1 + nq + nv + na:]
        s = table.summary
        self.status: _phiq.SolveStatus = s.status
        self.message: str = s.message
        self.warnings: List[_phiq.SweepWarning] = list(s.warnings)
        self.summary: Dict[str, Any] = s.to_dict()

    # The names are made on first use: a 10⁴-loop chain has 6·10⁴ columns, whose Python strings cost more than
    # returning the arrays does.
    @functools.cached_property
    def columns(self) -> List[str]:
        """Every column's name, "t" first, as the CSV's header names them."""
        return list(self._table.columns)

    @property
    def coordinate_names(self) -> List[str]:
        """Names of the columns of ``q``."""
        return self.columns[self._bounds[0]:self._bounds[1]]

    @property
    def velocity_names(self) -> List[str]:
        """Names of the columns of ``qd`` (``theta2.v``)."""
        return self.columns[self._bounds[1]:self._bounds[2]]

    @property
    def acceleration_names(self) -> List[str]:
        """Names of the columns of ``qdd`` (``theta2.a``)."""
        return self.columns[self._bounds[2]:self._bounds[3]]

    @property
    def output_names(self) -> List[str]:
        """Names of the columns of ``outputs`` (points, drivers, residuals, rcond, sensitivities)."""
        return self.columns[self._bounds[3]:]

    @functools.cached_property
    def _index(self) -> Dict[str, int]:
        return {name: k for k, name in enumerate(self.columns)}

    @property
    def ok(self) -> bool:
        """True when every time point was solved and delivered."""
        return self.status == _phiq.SolveStatus.SUCCESS

    def raise_for_status(self) -> "SweepResult":
        """Raise SolveError with phiq's one-line message unless the sweep succeeded; return self otherwise."""
        if not self.ok:
            raise SolveError(self.message, self.status, self.summary)
        return self

    def column(self, name: str) -> np.ndarray:
        """One column by its name (``'xB'``, ``'xB.v'``, ``'P.x'``, ``'motor.f'``); KeyError lists the names."""
        try:
            return self.table[:, self._index[name]]
        except KeyError:
            raise KeyError(f"no column '{name}' in this result (its columns: {', '.join(self.columns)})") from None

    __getitem__ = column

    def point(self, name: str) -> np.ndarray:
        """Positions of output point ``name``: rows × 2 (planar) or rows × 3 (spatial)."""
        for dot in (".", "__"):  # dotted or identifier column names
            axes = [f"{name}{dot}{a}" for a in ("x", "y", "z") if f"{name}{dot}{a}" in self._index]
            if axes:
                return np.stack([self.column(a) for a in axes], axis=1)
        raise KeyError(f"no output point '{name}' in this result (its columns: {', '.join(self.columns)})")

    def sensitivity(self, parameter: str, order: int = 0) -> np.ndarray:
        """Sensitivities to a parameter of the scene's ``output.sensitivities`` (or of run_sweep's
        ``sensitivities``): ∂q/∂p (order 0), ∂q̇/∂p (1) or
        ∂q̈/∂p (2), rows × the columns of ``q`` (``qd``, ``qdd``) in their order; NaN on a singular position."""
        if order not in (0, 1, 2):
            raise ValueError(f"order must be 0, 1 or 2, not {order}")
        base = (self.coordinate_names, self.velocity_names, self.acceleration_names)[order]
        for suffix in (f".d_{parameter}", f"__d_{parameter}"):  # dotted or identifier column names
            names = [n + suffix for n in base]
            if names and all(n in self._index for n in names):
                return self.table[:, [self._index[n] for n in names]]
        raise KeyError(f"no sensitivities of order {order} to '{parameter}' in this result (list the parameter in "
                       f"the scene's output.sensitivities or pass it in run_sweep's sensitivities; its columns: "
                       f"{', '.join(self.columns)})")

    def __len__(self) -> int:
        return self.table.shape[0]

    def to_pandas(self) -> Any:
        """A pandas.DataFrame of the table, indexed by t (pandas must be installed: python3-pandas)."""
        import pandas  # imported here: pandas is optional

        return pandas.DataFrame(self.table[:, 1:], index=pandas.Index(self.t, name="t"), columns=self.columns[1:])

    def __repr__(self) -> str:
        return (f"<phiq.SweepResult: {len(self)} rows × {len(self.columns)} columns, {self.status}"
                f"{': ' + self.message if self.message else ''}>")
