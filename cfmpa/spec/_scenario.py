"""Scenario files (DESIGN §3): a frozen value object, validated before any work starts.

Every refusal is an InputError naming the field and the value, e.g.
``right.omega[1] must be > 0, got -1.0``.
"""

from __future__ import annotations

import hashlib
import math
import os
import re
import tomllib
from dataclasses import dataclass
from fractions import Fraction
from pathlib import Path
from typing import Any

from ..errors import MISSING, InputError

__all__ = [
    "Arm",
    "LeftArm",
    "RightArm",
    "Scenario",
    "load_scenario",
    "parse_scenario",
    "max_cells",
    "DEFAULT_MAX_CELLS",
    "ANGLE_TOLERANCE",
]

#: Cells of D_R, (N + 1) * m * n, allowed before any work starts. About 1 byte per cell for
#: dr.npy and ~20 bytes per cell at the search's peak; raise with CFMPA_MAX_CELLS.
DEFAULT_MAX_CELLS = 60_000_000
#: An angle given for the right arm's start or goal must be this close to a grid point (rad).
ANGLE_TOLERANCE = 1e-9

Pair = tuple[float, float]


@dataclass(frozen=True)
class Arm:
    """A planar two-link arm: base position, link lengths, link width, joint speed limits."""

    base: Pair
    links: Pair
    width: float
    omega: Pair


@dataclass(frozen=True)
class LeftArm(Arm):
    """The principal arm, moving point-to-point from ``start`` to ``goal`` (radians)."""

    start: Pair
    goal: Pair


@dataclass(frozen=True)
class RightArm(Arm):
    """The subordinate arm: joint limits, and start/goal as grid cells (i, j)."""

    limits: tuple[Pair, Pair]
    start_cell: tuple[int, int]
    goal_cell: tuple[int, int]


@dataclass(frozen=True)
class Scenario:
    """A validated workcell; ``sha256`` hashes the file's bytes (empty for in-memory data)."""

    name: str
    purpose: str
    dt: float
    left: LeftArm
    right: RightArm
    source: str = "<memory>"
    sha256: str = ""

    @property
    def cells(self) -> int:
        """(N + 1) * m * n: the size of D_R for this scenario."""
        from ._grid import make_grid  # local: _grid imports this module

        g = make_grid(self)
        return (g.N + 1) * g.m * g.n


_TOP_KEYS = {"name", "purpose", "dt", "left", "right"}
_ARM_KEYS = {"base", "links", "width", "omega"}
_LEFT_KEYS = _ARM_KEYS | {"start", "goal"}
_RIGHT_KEYS = _ARM_KEYS | {"limits", "start_cell", "goal_cell", "start", "goal"}


def max_cells() -> int:
    """The memory budget in cells: CFMPA_MAX_CELLS if set (a positive integer), else the default."""
    raw = os.environ.get("CFMPA_MAX_CELLS")
    if raw is None:
        return DEFAULT_MAX_CELLS
    try:
        value = int(raw)
    except ValueError:
        value = -1
    if value <= 0:
        raise InputError("CFMPA_MAX_CELLS", raw, "must be a positive integer")
    return value


class _Reader:
    """Validates fields of one TOML document, keeping the source for line numbers."""

    def __init__(self, text: str | None, source: str | None) -> None:
        self.text = text
        self.source = source

    def line_of(self, field: str) -> int | None:
        if self.text is None:
            return None
        key = field.split(".")[-1].split("[")[0]
        table = field.split(".")[0] if "." in field else None
        in_table = table is None
        for n, line in enumerate(self.text.splitlines(), start=1):
            stripped = line.strip()
            if stripped.startswith("["):
                in_table = table is not None and stripped.strip("[] ") == table
                if table is None:
                    in_table = False
                continue
            if in_table and re.match(rf"{re.escape(key)}\s*=", stripped):
                return n
        return None

    def fail(self, field: str, value: Any, message: str) -> InputError:
        return InputError(field, value, message, source=self.source, line=self.line_of(field))

    def table(self, doc: dict[str, Any], key: str, allowed: set[str], required: set[str],
              prefix: str = "") -> dict[str, Any]:
        field = f"{prefix}{key}"
        if key not in doc:
            raise self.fail(field, MISSING, "is required")
        value = doc[key]
        if not isinstance(value, dict):
            raise self.fail(field, value, "must be a table")
        self.keys(value, allowed, required, f"{field}.")
        return value

    def keys(self, doc: dict[str, Any], allowed: set[str], required: set[str], prefix: str) -> None:
        for key in sorted(doc):
            if key not in allowed:
                raise self.fail(f"{prefix}{key}", doc[key],
                                f"is not a known key (known: {', '.join(sorted(allowed))})")
        for key in sorted(required):
            if key not in doc:
                raise self.fail(f"{prefix}{key}", MISSING, "is required")

    def number(self, value: Any, field: str, *, positive: bool = False) -> float:
        if isinstance(value, bool) or not isinstance(value, (int, float)):
            raise self.fail(field, value, "must be a number")
        x = float(value)
        if not math.isfinite(x):
            raise self.fail(field, value, "must be finite")
        if positive and not x > 0:
            raise self.fail(field, value, "must be > 0")
        return x

    def pair(self, value: Any, field: str, *, positive: bool = False) -> Pair:
        if not isinstance(value, list) or len(value) != 2:
            raise self.fail(field, value, "must be a list of 2 numbers")
        return (self.number(value[0], f"{field}[0]", positive=positive),
                self.number(value[1], f"{field}[1]", positive=positive))

    def cell(self, value: Any, field: str) -> tuple[int, int]:
        if not isinstance(value, list) or len(value) != 2:
            raise self.fail(field, value, "must be a list of 2 integers")
        out = []
        for q, x in enumerate(value):
            if isinstance(x, bool) or not isinstance(x, int):
                raise self.fail(f"{field}[{q}]", x, "must be an integer")
            out.append(x)
        return (out[0], out[1])

    def string(self, value: Any, field: str) -> str:
        if not isinstance(value, str) or not value.strip():
            raise self.fail(field, value, "must be a non-empty string")
        return value


def _arm_common(r: _Reader, doc: dict[str, Any], side: str) -> dict[str, Any]:
    return {
        "base": r.pair(doc["base"], f"{side}.base"),
        "links": r.pair(doc["links"], f"{side}.links", positive=True),
        "width": r.number(doc["width"], f"{side}.width", positive=True),
        "omega": r.pair(doc["omega"], f"{side}.omega", positive=True),
    }


def _grid_point(r: _Reader, doc: dict[str, Any], which: str, limits: tuple[Pair, Pair],
                omega: Pair, dt: float) -> tuple[int, int]:
    """Reads ``which``_cell, or ``which`` as angles snapped to the grid (within ANGLE_TOLERANCE)."""
    from ._grid import joint_points  # local: _grid imports this module

    cell_key, angle_key = f"{which}_cell", which
    if (cell_key in doc) == (angle_key in doc):
        raise r.fail(f"right.{cell_key}", doc.get(cell_key, doc.get(angle_key)),
                     f"exactly one of right.{cell_key} or right.{angle_key} must be given")
    sizes = [joint_points(limits[q][0], limits[q][1], omega[q], dt) for q in range(2)]
    if cell_key in doc:
        cell = r.cell(doc[cell_key], f"right.{cell_key}")
        for q in range(2):
            if not 0 <= cell[q] < sizes[q]:
                raise r.fail(f"right.{cell_key}[{q}]", cell[q],
                             f"must be a grid index in [0, {sizes[q] - 1}]")
        return cell
    angles = r.pair(doc[angle_key], f"right.{angle_key}")
    out = []
    for q in range(2):
        lo, hi = limits[q]
        m = sizes[q]
        field = f"right.{angle_key}[{q}]"
        if not lo - ANGLE_TOLERANCE <= angles[q] <= hi + ANGLE_TOLERANCE:
            raise r.fail(field, angles[q], f"must lie within the limits [{lo!r}, {hi!r}]")
        h = (hi - lo) / (m - 1)
        x = (angles[q] - lo) / h
        i = min(max(round(x), 0), m - 1)
        if abs(lo + i * h - angles[q]) > ANGLE_TOLERANCE:
            below = min(max(math.floor(x), 0), m - 1)
            above = min(below + 1, m - 1)
            raise r.fail(field, angles[q],
                         f"must be a grid point (within {ANGLE_TOLERANCE} rad); nearest are index "
                         f"{below} = {lo + below * h!r} and index {above} = {lo + above * h!r}")
        out.append(i)
    return (out[0], out[1])


def parse_scenario(doc: dict[str, Any], *, source: str | None = None, text: str | None = None,
                   sha256: str = "", check_budget: bool = True) -> Scenario:
    """Validate a parsed TOML document; the result satisfies every precondition of BuiltDR."""
    r = _Reader(text, source)
    if not isinstance(doc, dict):
        raise r.fail("<document>", doc, "must be a table")
    r.keys(doc, _TOP_KEYS, _TOP_KEYS, "")
    name = r.string(doc["name"], "name")
    purpose = r.string(doc["purpose"], "purpose")
    dt = r.number(doc["dt"], "dt", positive=True)

    ld = r.table(doc, "left", _LEFT_KEYS, _LEFT_KEYS)
    left = LeftArm(**_arm_common(r, ld, "left"), start=r.pair(ld["start"], "left.start"),
                   goal=r.pair(ld["goal"], "left.goal"))

    rd = r.table(doc, "right", _RIGHT_KEYS, _ARM_KEYS | {"limits"})
    common = _arm_common(r, rd, "right")
    lim = rd["limits"]
    if not isinstance(lim, list) or len(lim) != 2:
        raise r.fail("right.limits", lim, "must be a list of 2 [lo, hi] pairs")
    limits = (r.pair(lim[0], "right.limits[0]"), r.pair(lim[1], "right.limits[1]"))
    for q in range(2):
        if not limits[q][0] < limits[q][1]:
            raise r.fail(f"right.limits[{q}]", list(limits[q]), "must have lo < hi")
    omega = common["omega"]
    start_cell = _grid_point(r, rd, "start", limits, omega, dt)
    goal_cell = _grid_point(r, rd, "goal", limits, omega, dt)
    right = RightArm(**common, limits=limits, start_cell=start_cell, goal_cell=goal_cell)
    scenario = Scenario(name=name, purpose=purpose, dt=dt, left=left, right=right,
                        source=source or "<memory>", sha256=sha256)
    if check_budget:
        budget = max_cells()
        cells = scenario.cells
        if cells > budget:
            raise r.fail("dt", dt, f"gives a grid of {cells} cells ((N + 1) * m * n), over the "
                         f"memory budget of {budget} cells; raise CFMPA_MAX_CELLS to allow it")
    return scenario


def load_scenario(path: str | os.PathLike[str]) -> Scenario:
    """Read and validate a scenario TOML file; InputError (exit 2) names what is wrong."""
    p = Path(path)
    source = str(path)
    try:
        data = p.read_bytes()
    except OSError as exc:
        raise InputError("scenario", MISSING, f"cannot be read ({exc.strerror or exc})",
                         source=source) from None
    try:
        text = data.decode("utf-8")
    except UnicodeDecodeError:
        raise InputError("scenario", MISSING, "is not UTF-8 text", source=source) from None
    try:
        doc = tomllib.loads(text)
    except tomllib.TOMLDecodeError as exc:
        m = re.search(r"line (\d+)", str(exc))
        raise InputError("toml", str(exc), "is not valid TOML", source=source,
                         line=int(m.group(1)) if m else None) from None
    return parse_scenario(doc, source=source, text=text, sha256=hashlib.sha256(data).hexdigest())


def exact(x: float) -> Fraction:
    """The float's exact rational value (floats are dyadic rationals)."""
    return Fraction(x)
