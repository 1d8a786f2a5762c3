"""Scenario files (docs/model.md §3): a frozen value object, validated before any work starts.

Every refusal is an InputError naming the field and the value, e.g.
``right.omega[1] must be > 0, got -1.0``. Beyond finiteness and sign, values must lie in a
physical range (so that no float in the geometry overflows): base coordinates within
MAX_BASE_M = 1000 m, link lengths and widths in (0, MAX_LENGTH_M = 100 m], angles (start, goal,
limits) within MAX_ANGLE_RAD = 1000 rad, and omega_q * dt <= 157/50 = 3.14 rad for every
joint of both arms, exactly, both as the exact product of the doubles and as the float product
the code uses (the margin lemma, ``Lemma.sweep_margin``, is proved for lattice spacings
g <= 3.14; the left spacing is the float omega dt, the right the float h_q, which
``joint_grid`` holds to 157/50 itself). Numbers are read as written: tomllib's ``parse_float``
keeps each TOML float's text as an exact decimal (``spec._counts.Written``), and integers keep
their digits, so the grid is counted on the decimals in the file (docs/model.md §2, §3). The
grid's size is computed in exact integers and held to the memory budget before any float grid
step exists; each joint's grid then comes from ``joint_grid`` (spec/_counts.py), the same
function ``make_grid`` uses, and a joint it cannot confirm is refused naming right.limits[q].
"""

from __future__ import annotations

import hashlib
import math
import os
import re
import tomllib
from dataclasses import dataclass
from fractions import Fraction
from typing import Any

from ..errors import MISSING, InputError
from ..files import LIMITS, echo, env_positive_int, read_bounded
from ._counts import (
    MAX_SPACING,
    GridRefused,
    Written,
    joint_grid,
    min_points,
    spacing_conditions,
    time_steps,
    written,
)

__all__ = [
    "Arm",
    "Tool",
    "LeftArm",
    "RightArm",
    "Scenario",
    "load_scenario",
    "parse_scenario",
    "max_cells",
    "whole_max_cells",
    "DEFAULT_MAX_CELLS",
    "ANGLE_TOLERANCE",
    "MAX_BASE_M",
    "MAX_LENGTH_M",
    "MAX_ANGLE_RAD",
    "MAX_STEP_RAD",
    "MAX_TOOL_VERTICES",
]

#: Cells of D_R, (N + 1) * m * n, allowed before any work starts: what fits in 6 GiB at the
#: peak of a fully checked `cfmpa plan` with D_R in its store (dr.zarr, the default above 100 M
#: cells: built a block of layers at a time, searched and checked a layer at a time), measured
#: on the default workcell at dt = 0.0035: 2.1 bytes a cell (2,329 MiB for 1.11 G cells; 3.7 at
#: dt = 0.005, the per-(m, n) arrays' share falling as N grows); 6 GiB / 3 bytes (the larger
#: figure rounded up) = 2.1 G, rounded down. Raise with CFMPA_MAX_CELLS. docs/model.md §3.
DEFAULT_MAX_CELLS = 2_000_000_000
#: Cells allowed when D_R is held whole in memory (`--store npy`, or a kernel other than the
#: fast one, which build the whole array): 15.6 bytes a cell measured for a fully checked plan
#: at dt = 0.01, 6 GiB / 15.6 = 413 M, rounded down. Raise with CFMPA_MAX_WHOLE_CELLS.
WHOLE_MAX_CELLS = 400_000_000
#: An angle given for the right arm's start or goal must be this close to a grid point (rad).
ANGLE_TOLERANCE = 1e-9
#: Physical range: |base coordinate| <= MAX_BASE_M (m); 0 < link length, width <= MAX_LENGTH_M (m).
MAX_BASE_M = 1000.0
MAX_LENGTH_M = 100.0
#: |angle| <= MAX_ANGLE_RAD for start, goal and limits: the grid's angles keep ~1e-13 rad ulps.
MAX_ANGLE_RAD = 1000.0
#: omega_q * dt <= MAX_STEP_RAD per joint: the margin lemma holds for spacings g <= 3.14 rad.
MAX_STEP_RAD = 3.14
#: A tool polygon has 3 to MAX_TOOL_VERTICES vertices (docs/model.md §2, "Tools and heights").
MAX_TOOL_VERTICES = 16
#: Cells beyond this are refused even with check_budget=False: no machine holds them, and
#: counts this large no longer convert to floats.
_HARD_MAX_CELLS = 2**53
#: Numbers in messages are printed in full up to this many digits, else in scientific notation.
_MAX_DIGITS = 15

Pair = tuple[float, float]


@dataclass(frozen=True)
class Tool:
    """A rigid convex part fixed to link 2 (docs/model.md §2, "Tools and heights"): its vertices,
    counter-clockwise, in the forearm's frame (origin at the end of link 2, x along the forearm,
    y to its left), and its closed height interval (m), or None for every height."""

    polygon: tuple[Pair, ...]
    z: Pair | None = None


@dataclass(frozen=True)
class Arm:
    """A planar two-link arm: base position, link lengths, link width, joint speed limits; the
    closed height intervals of link 1 and link 2 (None: every height) and a tool (or None)."""

    base: Pair
    links: Pair
    width: float
    omega: Pair
    z: tuple[Pair, Pair] | None = None
    tool: Tool | None = None


@dataclass(frozen=True, kw_only=True)
class LeftArm(Arm):
    """The principal arm, moving point-to-point from ``start`` to ``goal`` (radians)."""

    start: Pair
    goal: Pair


@dataclass(frozen=True, kw_only=True)
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
        R, L = self.right, self.left
        m, n = (joint_grid(R.limits[q][0], R.limits[q][1], R.omega[q], self.dt)[0]
                for q in range(2))
        return (time_steps(L.start, L.goal, L.omega, self.dt) + 1) * m * n


_TOP_KEYS = {"name", "purpose", "dt", "left", "right"}
_ARM_KEYS = {"base", "links", "width", "omega"}
_ARM_OPTIONAL = {"z", "tool"}
_TOOL_KEYS = {"polygon", "z"}
_LEFT_KEYS = _ARM_KEYS | _ARM_OPTIONAL | {"start", "goal"}
_RIGHT_KEYS = _ARM_KEYS | _ARM_OPTIONAL | {"limits", "start_cell", "goal_cell", "start", "goal"}


def max_cells() -> int:
    """The memory budget in cells: CFMPA_MAX_CELLS if set (a positive integer), else the default."""
    return env_positive_int("CFMPA_MAX_CELLS", DEFAULT_MAX_CELLS, "cells")


def whole_max_cells() -> int:
    """The budget in cells of a D_R held whole in memory (WHOLE_MAX_CELLS): CFMPA_MAX_WHOLE_CELLS
    if set (a positive integer), else the default."""
    return env_positive_int("CFMPA_MAX_WHOLE_CELLS", WHOLE_MAX_CELLS, "cells")


class _Reader:
    """Validates fields of one TOML document, keeping the source for line numbers."""

    def __init__(self, text: str | None, source: str | None) -> None:
        self.text = text
        self.source = source

    def line_of(self, field: str) -> int | None:
        if self.text is None:
            return None
        # "right.tool.polygon[2][0]": key polygon in table [right.tool].
        path = [part.split("[")[0] for part in field.split(".")]
        key = path[-1]
        table = ".".join(path[:-1]) if len(path) > 1 else None
        whole = ".".join(path)
        in_table = table is None
        for n, line in enumerate(self.text.splitlines(), start=1):
            stripped = line.strip()
            if stripped.startswith("["):
                # A header may carry a comment: `[left]   # principal`.
                header = stripped.split("#", 1)[0].strip()
                if header.strip("[] ") == whole:
                    return n                    # the field is a table: `[left.gadget]`
                in_table = table is not None and header.strip("[] ") == table
                if table is None:
                    in_table = False
                continue
            if in_table and re.match(rf"{re.escape(key)}\s*=", stripped):
                return n
        return None

    def fail(self, field: str, value: Any, message: str) -> InputError:
        return InputError(field, echo(value), message, source=self.source,
                          line=self.line_of(field))

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

    def number(self, value: Any, field: str, *, positive: bool = False,
               bound: float | None = None, unit: str = "") -> float:
        """A finite float; > 0 if ``positive``; |x| <= ``bound`` if given (stated in the message)."""
        if isinstance(value, bool) or not isinstance(value, (int, float)):
            raise self.fail(field, value, "must be a number")
        try:
            x = float(value)
        except OverflowError:  # an integer beyond the float range
            raise self.fail(field, _short(value), "must be finite") from None
        if not math.isfinite(x):
            raise self.fail(field, value, "must be finite")
        if positive and not x > 0:
            raise self.fail(field, value, "must be > 0")
        if bound is not None and not abs(x) <= bound:
            within = f"<= {bound:g}{unit}" if positive else f"within [-{bound:g}, {bound:g}]{unit}"
            raise self.fail(field, value, f"must be {within} (the physical range)")
        # Keep the decimal as written (a file's float text, an integer's digits): the grid is
        # counted on it (spec._counts.decimal). A plain float from a Python document stays one.
        return written(value) if isinstance(value, (int, Written)) else x

    def pair(self, value: Any, field: str, *, positive: bool = False,
             bound: float | None = None, unit: str = "") -> Pair:
        if not isinstance(value, list) or len(value) != 2:
            raise self.fail(field, value, "must be a list of 2 numbers")
        return (self.number(value[0], f"{field}[0]", positive=positive, bound=bound, unit=unit),
                self.number(value[1], f"{field}[1]", positive=positive, bound=bound, unit=unit))

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


def _short(x: Any) -> Any:
    """An integer too long to print usefully, as a string in scientific notation."""
    if isinstance(x, int) and not isinstance(x, bool) and len(str(abs(x))) > _MAX_DIGITS:
        digits = str(abs(x))
        return f"{'-' if x < 0 else ''}{digits[0]}.{digits[1:4]}e+{len(digits) - 1}"
    return x


def _arm_common(r: _Reader, doc: dict[str, Any], side: str, dt: float) -> dict[str, Any]:
    out: dict[str, Any] = {
        "base": r.pair(doc["base"], f"{side}.base", bound=MAX_BASE_M, unit=" m"),
        "links": r.pair(doc["links"], f"{side}.links", positive=True, bound=MAX_LENGTH_M,
                        unit=" m"),
        "width": r.number(doc["width"], f"{side}.width", positive=True, bound=MAX_LENGTH_M,
                          unit=" m"),
        "omega": r.pair(doc["omega"], f"{side}.omega", positive=True),
    }
    for q in range(2):
        w = out["omega"][q]
        step = w * dt
        # Exactly, as margin_side checks it: the float product (the left spacing) and the
        # exact product of the doubles (which bounds the right spacing h) both <= 157/50.
        if not (step <= MAX_STEP_RAD and Fraction(step) <= _G_MAX
                and Fraction(w) * Fraction(dt) <= _G_MAX):
            raise r.fail(f"{side}.omega[{q}]", w,
                         f"times dt = {dt!r} is {step!r} rad per step, must be <= {MAX_STEP_RAD} "
                         "exactly (157/50; the double 3.14 is slightly above it) (the margin "
                         "lemma holds for lattice spacings up to 3.14 rad)")
    return out


#: The margin lemma's bound on a lattice spacing, exactly (MAX_STEP_RAD as written).
_G_MAX = MAX_SPACING


def _joint_grids(r: _Reader, limits: tuple[Pair, Pair], omega: Pair, dt: float
                 ) -> tuple[tuple[int, float], tuple[int, float]]:
    """Each joint's (m, h) from joint_grid; a joint that cannot be confirmed safe is refused."""
    out = []
    for q in range(2):
        try:
            out.append(joint_grid(limits[q][0], limits[q][1], omega[q], dt))
        except GridRefused as exc:
            raise r.fail(f"right.limits[{q}]", list(limits[q]),
                         f"cannot be gridded safely with right.omega[{q}] = {omega[q]!r} and "
                         f"dt = {dt!r}: {exc}; widen or narrow the limits slightly") from None
    return (out[0], out[1])


def _check_budget(r: _Reader, N: int, m: int, n: int, budget: int | None) -> None:
    """Refuse (N + 1) * m * n over ``budget`` (None: only the hard limit), in exact integers."""
    cells = (N + 1) * m * n
    if cells <= min(budget or _HARD_MAX_CELLS, _HARD_MAX_CELLS):
        return
    # Blame the largest factor's inputs: N comes from dt and the left arm's motion, m and n
    # from the right arm's limits, omega and dt.
    factors = {"N + 1": (N + 1, "dt, left.omega, left.start, left.goal"),
               "m": (m, "right.limits[0], right.omega[0], dt"),
               "n": (n, "right.limits[1], right.omega[1], dt")}
    name, (_, inputs) = max(factors.items(), key=lambda kv: kv[1][0])
    if budget is not None and cells > budget:
        over = f"the memory budget of {_short(budget)} cells (raise it with CFMPA_MAX_CELLS)"
    else:
        over = f"the hard limit of 2**53 = {_short(_HARD_MAX_CELLS)} cells"
    if budget is not None and cells > _HARD_MAX_CELLS and budget < _HARD_MAX_CELLS:
        over += f"; no budget may exceed 2**53 = {_short(_HARD_MAX_CELLS)} cells"
    raise r.fail("grid", f"N={_short(N)}, m={_short(m)}, n={_short(n)}",
                 f"has (N + 1) * m * n = {_short(cells)} cells, over {over}; the largest factor "
                 f"is {name} (from {inputs}): coarsen it")


def _grid_point(r: _Reader, doc: dict[str, Any], which: str, limits: tuple[Pair, Pair],
                grids: tuple[tuple[int, float], tuple[int, float]], omega: Pair, dt: float
                ) -> tuple[int, int]:
    """Reads ``which``_cell, or ``which`` as angles snapped to the grid (within ANGLE_TOLERANCE)."""
    sizes = (grids[0][0], grids[1][0])
    cell_key, angle_key = f"{which}_cell", which
    if (cell_key in doc) == (angle_key in doc):
        raise r.fail(f"right.{cell_key}", doc.get(cell_key, doc.get(angle_key, MISSING)),
                     f"exactly one of right.{cell_key} or right.{angle_key} must be given")
    if cell_key in doc:
        cell = r.cell(doc[cell_key], f"right.{cell_key}")
        for q in range(2):
            if not 0 <= cell[q] < sizes[q]:
                raise r.fail(f"right.{cell_key}[{q}]", cell[q],
                             f"must be a grid index in [0, {sizes[q] - 1}]")
        return cell
    angles = r.pair(doc[angle_key], f"right.{angle_key}", bound=MAX_ANGLE_RAD, unit=" rad")
    out = []
    for q in range(2):
        lo, hi = limits[q]
        m, h = grids[q]
        field = f"right.{angle_key}[{q}]"
        if not lo - ANGLE_TOLERANCE <= angles[q] <= hi + ANGLE_TOLERANCE:
            raise r.fail(field, angles[q], f"must lie within the limits [{lo!r}, {hi!r}]")
        x = (angles[q] - lo) / h
        i = min(max(round(x), 0), m - 1)
        if abs(lo + i * h - angles[q]) > ANGLE_TOLERANCE:
            below = min(max(math.floor(x), 0), m - 1)
            above = min(below + 1, m - 1)
            base = min_points(lo, hi, omega[q], dt)
            why = ""
            if m > base:
                failed = [c.words() for c in spacing_conditions(
                    lo, hi, omega[q], dt, base, (hi - lo) / (base - 1)) if not c.holds]
                reason = "; ".join(failed) or "its last point would miss the upper limit"
                why = (f"; joint {q + 1}'s grid has {m} points, not {base}: with {base} the float "
                       f"spacing {(hi - lo) / (base - 1)!r} would fail ({reason}), so a point was "
                       f"added and the spacing is {h!r}")
            raise r.fail(field, angles[q],
                         f"must be a grid point (within {ANGLE_TOLERANCE} rad); nearest are index "
                         f"{below} = {lo + below * h!r} and index {above} = {lo + above * h!r}"
                         + why)
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

    ld = r.table(doc, "left", _LEFT_KEYS, _LEFT_KEYS - _ARM_OPTIONAL)
    angle: dict[str, Any] = {"bound": MAX_ANGLE_RAD, "unit": " rad"}
    left = LeftArm(**_arm_common(r, ld, "left", dt), **_arm_parts(r, ld, "left"),
                   start=r.pair(ld["start"], "left.start", **angle),
                   goal=r.pair(ld["goal"], "left.goal", **angle))

    rd = r.table(doc, "right", _RIGHT_KEYS, _ARM_KEYS | {"limits"})
    common = _arm_common(r, rd, "right", dt)
    lim = rd["limits"]
    if not isinstance(lim, list) or len(lim) != 2:
        raise r.fail("right.limits", lim, "must be a list of 2 [lo, hi] pairs")
    limits = (r.pair(lim[0], "right.limits[0]"), r.pair(lim[1], "right.limits[1]"))
    for q in range(2):
        lo, hi = limits[q]
        if not lo < hi:
            raise r.fail(f"right.limits[{q}]", list(limits[q]), "must have lo < hi")
        if not math.isfinite(hi - lo):
            raise r.fail(f"right.limits[{q}]", list(limits[q]),
                         "must have a finite span hi - lo (as a float)")
        for e in range(2):
            r.number(limits[q][e], f"right.limits[{q}][{e}]", **angle)
    omega = common["omega"]
    # The grid's size in exact integers, before any float grid step is formed.
    sizes = tuple(min_points(limits[q][0], limits[q][1], omega[q], dt) for q in range(2))
    N = time_steps(left.start, left.goal, left.omega, dt)
    _check_budget(r, N, sizes[0], sizes[1], max_cells() if check_budget else None)
    # Then each joint's grid as make_grid builds it (possibly a point more), held again.
    grids = _joint_grids(r, limits, omega, dt)
    _check_budget(r, N, grids[0][0], grids[1][0], max_cells() if check_budget else None)
    start_cell = _grid_point(r, rd, "start", limits, grids, omega, dt)
    goal_cell = _grid_point(r, rd, "goal", limits, grids, omega, dt)
    right = RightArm(**common, **_arm_parts(r, rd, "right"), limits=limits, start_cell=start_cell,
                     goal_cell=goal_cell)
    return Scenario(name=name, purpose=purpose, dt=dt, left=left, right=right,
                    source=source or "<memory>", sha256=sha256)


def _interval(r: _Reader, value: Any, field: str) -> Pair:
    """A closed height interval [lo, hi] (m), lo <= hi (a single height is allowed), within the
    physical range."""
    lo, hi = r.pair(value, field, bound=MAX_BASE_M, unit=" m")
    if not lo <= hi:
        raise r.fail(field, value, "must have lo <= hi (a closed height interval [lo, hi] in "
                     "metres)")
    return (float(lo), float(hi))


def _arm_parts(r: _Reader, doc: dict[str, Any], side: str) -> dict[str, Any]:
    """The optional heights of the links (``z``) and the tool (``[side.tool]``)."""
    out: dict[str, Any] = {}
    if "z" in doc:
        z = doc["z"]
        if not isinstance(z, list) or len(z) != 2:
            raise r.fail(f"{side}.z", z, "must be a list of 2 [lo, hi] height intervals (m): "
                         "link 1's and link 2's")
        out["z"] = (_interval(r, z[0], f"{side}.z[0]"), _interval(r, z[1], f"{side}.z[1]"))
    if "tool" in doc:
        td = r.table(doc, "tool", _TOOL_KEYS, {"polygon"}, prefix=f"{side}.")
        out["tool"] = Tool(polygon=_tool_polygon(r, td["polygon"], f"{side}.tool.polygon"),
                           z=_interval(r, td["z"], f"{side}.tool.z") if "z" in td else None)
    return out


def _tool_polygon(r: _Reader, value: Any, field: str) -> tuple[Pair, ...]:
    """A strictly convex polygon of 3 to MAX_TOOL_VERTICES vertices, decided exactly on the
    doubles (every other vertex strictly to the left of every edge, after orienting it
    counter-clockwise), returned counter-clockwise."""
    if not isinstance(value, list) or not 3 <= len(value) <= MAX_TOOL_VERTICES:
        raise r.fail(field, value,
                     f"must be a list of 3 to {MAX_TOOL_VERTICES} [x, y] vertices (m)")
    pts = [r.pair(v, f"{field}[{k}]", bound=MAX_LENGTH_M, unit=" m") for k, v in enumerate(value)]
    pts = [(float(x), float(y)) for x, y in pts]
    q = [(Fraction(x), Fraction(y)) for x, y in pts]
    V = len(q)
    area = sum(q[k][0] * q[(k + 1) % V][1] - q[(k + 1) % V][0] * q[k][1] for k in range(V))
    (ax, ay), (bx, by) = q[0], q[1]
    if all((bx - ax) * (cy - ay) - (by - ay) * (cx - ax) == 0 for cx, cy in q):
        raise r.fail(field, value, "must enclose an area (this polygon is degenerate: its "
                     "vertices lie on one line)")
    if area < 0:
        pts, q = pts[::-1], q[::-1]
    for k in range(V):
        (ax, ay), (bx, by) = q[k], q[(k + 1) % V]
        for c in range(V):
            if c in (k, (k + 1) % V):
                continue
            cx, cy = q[c]
            if not (bx - ax) * (cy - ay) - (by - ay) * (cx - ax) > 0:
                raise r.fail(field, value,
                             "must be a strictly convex polygon (vertices in order, either "
                             "orientation, no three on a line, no repeated vertex)")
    return tuple(pts)


def load_scenario(path: str | os.PathLike[str]) -> Scenario:
    """Read and validate a scenario TOML file; InputError (exit 2) names what is wrong."""
    source = str(path)
    # Bounded (docs/model.md §3): /dev/zero or a huge file ends at the limit, not in memory.
    data = read_bounded(path, LIMITS["scenario"], source, field="scenario")
    try:
        text = data.decode("utf-8")
    except UnicodeDecodeError:
        raise InputError("scenario", MISSING, "is not UTF-8 text", source=source) from None
    try:
        doc = tomllib.loads(text, parse_float=written)
    except tomllib.TOMLDecodeError as exc:
        m = re.search(r"line (\d+)", str(exc))
        raise InputError("toml", echo(str(exc)), "is not valid TOML", source=source,
                         line=int(m.group(1)) if m else None) from None
    return parse_scenario(doc, source=source, text=text, sha256=hashlib.sha256(data).hexdigest())


def exact(x: float) -> Fraction:
    """The float's exact rational value (floats are dyadic rationals)."""
    return Fraction(x)
