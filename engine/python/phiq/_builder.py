"""Models built in code: a SceneBuilder writes the sections of a scene file (models/README.md) from keyword
arguments named as the scene format names them, and phiq's scene reader builds the model. Every constraint kind of
the registry is available without binding code of its own, with the reader's checks and messages; a message points
at the Python line that added the entry."""

from __future__ import annotations

import inspect
import json
import re
from typing import Any, Dict, List, Optional, Sequence, Tuple, Union

from . import _phiq

Value = Union[float, int, str]


class SceneBuilder:
    """Builds a scene in code, entry by entry, in the scene format's own words::

        b = phiq.SceneBuilder("crank-slider")
        b.parameters(L2=0.3, L3=1.0)
        b.coordinates(theta2=0.0, xA=0.28, yA=0.03, xB=1.25)
        b.point("O", [0, 0]); b.point("A", ["xA", "yA"]); b.point("B", ["xB", 0])
        b.constraint("crank", type="polar", point="A", origin="O", length="L2", angle="theta2")
        b.constraint("rod", type="distance", points=["A", "B"], length="L3")
        b.driver("motor", coordinate="theta2", law={"type": "linear", "initial": 0, "rate": 2})
        b.time(start=0, end=math.pi, steps=180)
        scene = b.build()

    Names and expressions are strings, numbers are numbers; ``phiq.constraint_kinds()`` lists every type with an
    example entry. build() raises SceneError naming the Python line of the entry at fault.
    """

    def __init__(self, name: str = "", dimension: int = 2, description: Optional[str] = None):
        self._top: Dict[str, Any] = {"phiq": 1, "name": name, "dimension": dimension}
        if description is not None:
            self._top["description"] = description
        # section -> list of (entry text key or None, value, where it was added)
        self._maps: Dict[str, List[Tuple[str, Any, str]]] = {s: [] for s in ("parameters", "coordinates", "points",
                                                                           "bodies", "vectors")}
        self._lists: Dict[str, List[Tuple[Dict[str, Any], str]]] = {"constraints": [], "drivers": []}
        self._blocks: Dict[str, Tuple[Dict[str, Any], str]] = {}

    @staticmethod
    def _caller() -> str:
        frame = inspect.currentframe()
        here = frame.f_code.co_filename if frame else ""
        while frame is not None and frame.f_code.co_filename == here:
            frame = frame.f_back
        return f"{frame.f_code.co_filename}:{frame.f_lineno}" if frame else "<unknown>"

    def _map_entry(self, section: str, name: str, value: Any) -> str:
        self._maps[section].append((name, value, self._caller()))
        return name

    def parameter(self, name: str, value: Value) -> str:
        """A named constant (a number or an expression of the parameters before it)."""
        return self._map_entry("parameters", name, value)

    def parameters(self, **values: Value) -> None:
        """Several parameters, in order."""
        for k, v in values.items():
            self._map_entry("parameters", k, v)

    def coordinate(self, name: str, initial: Value) -> str:
        """A generalized coordinate and its initial guess (a rough placement is enough). Returns its name."""
        return self._map_entry("coordinates", name, initial)

    def coordinates(self, **initial: Value) -> None:
        """Several coordinates, in the order of q."""
        for k, v in initial.items():
            self._map_entry("coordinates", k, v)

    def point(self, name: str, components: Sequence[Value]) -> str:
        """A point of natural coordinates: [x, y] (or [x, y, z]), each a coordinate name or a constant."""
        return self._map_entry("points", name, list(components))

    def body(self, name: str, components: Sequence[Value]) -> str:
        """A body in reference-point coordinates: [x, y, psi], or [x, y, z, e0, e1, e2, e3] in 3D."""
        return self._map_entry("bodies", name, list(components))

    def vector(self, name: str, components: Sequence[Value]) -> str:
        """A natural unit vector [ux, uy, uz] (dimension 3)."""
        return self._map_entry("vectors", name, list(components))

    def constraint(self, name: str, type: str, **fields: Any) -> str:
        """A constraint of any kind in the registry: ``type`` and the fields as in models/README.md."""
        self._lists["constraints"].append(({"name": name, "type": type, **fields}, self._caller()))
        return name

    def driver(self, name: str, **fields: Any) -> str:
        """A driver (motor), fields as in the scene's ``drivers`` section (coordinate or joint, law, …)."""
        self._lists["drivers"].append(({"name": name, **fields}, self._caller()))
        return name

    def time(self, start: float, end: float, steps: int) -> None:
        """The sweep: steps + 1 time points from start to end."""
        self._blocks["time"] = ({"start": start, "end": end, "steps": steps}, self._caller())

    def output(self, **fields: Any) -> None:
        """What to compute and write: velocities, accelerations, coordinates, points, drivers, … (the scene's
        ``output`` section)."""
        self._blocks["output"] = (dict(fields), self._caller())

    def solver(self, **fields: Any) -> None:
        """Numerical settings (the scene's ``solver`` section)."""
        self._blocks["solver"] = (dict(fields), self._caller())

    def text(self) -> Tuple[str, List[str]]:
        """The scene as JSON text (a YAML document), one entry per line, and for each line where it was added."""
        def dump(v: Any) -> str:
            return json.dumps(v, ensure_ascii=False, allow_nan=True)

        lines: List[str] = ["{"]
        where: List[str] = ["", ""]  # 1-based: where[k] is line k's origin
        out: List[Tuple[str, str]] = []  # (text, origin) of every line; commas between members added below
        for key, value in self._top.items():
            out.append((f"{dump(key)}: {dump(value)}", ""))
        for section, entries in self._maps.items():
            if entries:
                out.append((f"{dump(section)}: {{", ""))
                for k, (n, v, origin) in enumerate(entries):
                    out.append((f"  {dump(n)}: {dump(v)}" + ("," if k + 1 < len(entries) else ""), origin))
                out.append(("}", ""))
        for section, entries2 in self._lists.items():
            if entries2:
                out.append((f"{dump(section)}: [", ""))
                for k, (e, origin) in enumerate(entries2):
                    out.append((f"  {dump(e)}" + ("," if k + 1 < len(entries2) else ""), origin))
                out.append(("]", ""))
        for section, (block, origin) in self._blocks.items():
            out.append((f"{dump(section)}: {dump(block)}", origin))
        # commas between top-level members: after every line that ends one (a scalar member or a closing bracket)
        for k, (t, origin) in enumerate(out):
            closes = not t.endswith(("{", "[")) and not t.startswith("  ")
            lines.append(t + ("," if closes and k + 1 < len(out) else ""))
            where.append(origin)
        lines.append("}")
        return "\n".join(lines) + "\n", where

    def build(self, parameters: Optional[Dict[str, float]] = None) -> "_phiq.Scene":
        """The scene (model, time grid, outputs). Raises SceneError naming the Python line of a bad entry."""
        text, where = self.text()
        label = "<SceneBuilder" + (f" '{self._top['name']}'" if self._top.get("name") else "") + ">"
        try:
            return _phiq.parse_scene(text, label, parameters)
        except _phiq.SceneError as e:
            message = str(e)
            m = re.match(re.escape(label) + r":(\d+):\d+: (.*)", message)
            if m and 0 < int(m.group(1)) < len(where) and where[int(m.group(1))]:
                message = f"{where[int(m.group(1))]}: {m.group(2)}"
            raise _phiq.SceneError(message) from None
