"""Rigorous re-decision of the cells a path occupies (docs/model.md §4.3, §7).

The planner and the spec decide "free" in floating point: distance between two regions > eps.
Here each (layer, cell) that a found path uses is decided again in ball arithmetic (python-flint's
``arb``): the corner points that define both regions (the spec's construction: link rectangles of
half-width w/2 + delta at the lattice angles, delta = g^2/8 R + SNAP g R per joint) are enclosed
with rigorous sin and cos, and a separating direction n taken from the float geometry is checked:

    min over B of n.b  -  max over A of n.a  >  eps |n|

The regions are the convex hulls of those points, so this bounds their distance from below: a
cell that passes is free whatever the float rounding of the polygons. A cell that fails is
"undecided" (its float decision then rests on rounding alone), never silently free.
"""

from __future__ import annotations

import functools
import math
from collections.abc import Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np
import numpy.typing as npt
import shapely
from flint import arb, ctx

from ._arith import max_of, min_of, sqrt_of
from ._grid import EPS, Grid, Variant, left_angles, left_box, rest_box
from ._kinematics import TOOL, pairs_to_test, parts
from ._regions import SNAP, lattice
from ._scenario import Arm, Scenario

__all__ = ["EXACT_PREC_BITS", "ExactCell", "ExactGaps", "exact_path_gaps", "gap_over_norm",
           "path_layer_cells", "projection_bounds"]

#: Working precision of the balls (bits); doubles carry 53, so rounding is far below any gap.
EXACT_PREC_BITS = 128

Cell = tuple[int, int]
Points = list[tuple[arb, arb]]
#: A region: its corner points in balls, the convex hull of their midpoints (shapely), the
#: midpoints as doubles (P, 2) and the slack of their float projections (``_slack``), all made
#: once per region, not once per pair of regions compared (``_gap``).
Region = tuple[Points, shapely.Geometry, npt.NDArray[np.float64], float]

#: A bound on the relative error of a double midpoint and of its float projection n.x (a
#: rounding of the midpoint and two of the dot product: about 3 * 2**-53 = 3.3e-16), with room.
FLOAT_REL = 1e-12


@dataclass(frozen=True)
class ExactCell:
    """One (layer, cell) pair of a path: the proved lower bound on its least region gap (m),
    and whether that bound exceeds eps (``free``)."""

    layer: int
    cell: Cell
    gap_lower_m: float
    free: bool


@dataclass(frozen=True)
class ExactGaps:
    """The path's cells re-decided in ball arithmetic; ``ok`` iff every one is proved free."""

    cells: tuple[ExactCell, ...]
    least_gap_m: float
    least_at: tuple[int, Cell] | None

    @property
    def ok(self) -> bool:
        return all(c.free for c in self.cells)

    @property
    def undecided(self) -> tuple[ExactCell, ...]:
        return tuple(c for c in self.cells if not c.free)

    def as_json(self) -> dict[str, object]:
        return {"method": f"arb ball arithmetic ({EXACT_PREC_BITS} bits), separating direction",
                "cells": len(self.cells), "ok": self.ok, "least_gap_m": self.least_gap_m,
                "least_at": None if self.least_at is None
                else {"layer": self.least_at[0], "cell": list(self.least_at[1])},
                "undecided": [{"layer": c.layer, "cell": list(c.cell),
                               "gap_lower_m": c.gap_lower_m} for c in self.undecided]}


def path_layer_cells(path: Sequence[Sequence[int]], N: int) -> list[tuple[int, Cell]]:
    """The (layer, cell) pairs the fixed is_path reads: step k holds cell L_min(k, len-1) in layer
    min(k, N), for k = 0 .. max(len - 1, N), so the goal is checked in the rest layer too."""
    cells = [(int(c[0]), int(c[1])) for c in path]
    out: dict[tuple[int, Cell], None] = {}
    for k in range(max(len(cells) - 1, N) + 1):
        out[(min(k, N), cells[min(k, len(cells) - 1)])] = None
    return list(out)


@functools.lru_cache(maxsize=1 << 12)
def _cos_sin(t1: float, t2: float | None, prec: int) -> tuple[arb, arb]:
    """(cos phi, sin phi) in balls at ``prec`` bits, phi = arb(t1) (t2 None) or arb(t1) +
    arb(t2): the same balls each time, computed once for the lattice angles that neighbouring
    cells and both links share."""
    phi = arb(t1) if t2 is None else arb(t1) + arb(t2)
    return phi.cos(), phi.sin()


def _corners(arm: Arm, t1: float, t2: float, link: int, r: arb) -> Points:
    """The four corners of the link's rectangle of half-width ``r`` at the float angles
    (t1, t2), enclosed in balls (the spec's ``corners`` formula, term for term)."""
    c1, s1 = _cos_sin(t1, None, ctx.prec)
    bx, by = arb(arm.base[0]), arb(arm.base[1])
    ex, ey = bx + arb(arm.links[0]) * c1, by + arb(arm.links[0]) * s1
    if link == 0:
        c, s = c1, s1
        px, py, qx, qy = bx, by, ex, ey
    else:
        c, s = _cos_sin(t1, t2, ctx.prec)
        px, py = ex, ey
        qx, qy = ex + arb(arm.links[1]) * c, ey + arb(arm.links[1]) * s
    ux, uy = r * c, r * s
    return [(px - ux + uy, py - uy - ux), (qx + ux + uy, qy + uy - ux),
            (qx + ux - uy, qy + uy + ux), (px - ux - uy, py - uy + ux)]


def _tool_points(arm: Arm, t1: float, t2: float, grow: arb) -> Points:
    """The tool's vertices each moved by +-grow along the forearm and its normal, at the float
    angles (t1, t2), enclosed in balls (the spec's ``part_points`` for the tool, term for term)."""
    assert arm.tool is not None
    a1, phi = arb(t1), arb(t1) + arb(t2)
    c, s = phi.cos(), phi.sin()
    wx = arb(arm.base[0]) + arb(arm.links[0]) * a1.cos() + arb(arm.links[1]) * c
    wy = arb(arm.base[1]) + arb(arm.links[0]) * a1.sin() + arb(arm.links[1]) * s
    steps = [(-grow, -grow), (grow, -grow), (grow, grow), (-grow, grow)]
    return [(wx + (arb(x) + dx) * c - (arb(y) + dy) * s, wy + (arb(x) + dx) * s + (arb(y) + dy) * c)
            for x, y in arm.tool.polygon for dx, dy in steps]


def _margin(arm: Arm, link: int, g: tuple[float, float], sizes: tuple[int, int]) -> arb:
    """delta of the spec's regions (``_regions.margin``) in balls, with R as the exact hypot."""
    r = arb(arm.width) / 2
    if link == TOOL:
        assert arm.tool is not None
        # arb.max: a ball holding the max of any points of the balls (the exact farthest vertex).
        far = functools.reduce(arb.max, (((arb(arm.links[1]) + arb(x)) ** 2 + arb(y) ** 2).sqrt()
                                         for x, y in arm.tool.polygon))
        R = arb(arm.links[0]) + far, far
    elif link == 0:
        R = ((arb(arm.links[0]) + r) ** 2 + r ** 2).sqrt(), arb(0)
    else:
        far = ((arb(arm.links[1]) + r) ** 2 + r ** 2).sqrt()
        R = arb(arm.links[0]) + far, far
    out = arb(0)
    for q in range(2):
        gq = arb(g[q])
        if sizes[q] > 1:
            out += gq ** 2 / 8 * R[q]
        out += arb(SNAP) * gq * R[q]
    return out


def _region_points(arm: Arm, link: int, axes: tuple[np.ndarray, np.ndarray],
                   g: tuple[float, float]) -> Region:
    """(ball corner points, the float hull of their midpoints) of a region over the lattice
    ``axes``."""
    grow = _margin(arm, link, g, (len(axes[0]), len(axes[1])))
    r = arb(arm.width) / 2 + grow
    balls: Points = []
    for t1 in axes[0]:
        for t2 in axes[1]:
            balls += (_tool_points(arm, float(t1), float(t2), grow) if link == TOOL
                      else _corners(arm, float(t1), float(t2), link, r))
    floats = np.array([[float(x.mid()), float(y.mid())] for x, y in balls])
    return balls, shapely.convex_hull(shapely.multipoints(floats)), floats, _slack(balls, floats)


def _slack(balls: Points, floats: npt.NDArray[np.float64]) -> float:
    """s such that |float(n . m) - n . x| <= (|nx| + |ny|) s / 4 for every ball's double
    midpoint m and every point x of the ball, doubles n: the midpoint's and the dot product's
    rounding (``FLOAT_REL`` of the largest coordinate, which also covers the ball arithmetic's
    own rounding of n . x) and the balls' radius (twice the largest, covering its rounding to a
    double), with a factor 4 (``_extreme`` needs 2). The largest radius is bounded by the radius
    of the balls' sum: a ball holding every sum of points of balls of radii r_1, r_2, ... has a
    radius of at least r_1 + r_2 + ... (one sum, not a radius read per coordinate)."""
    total = arb(0)
    for x, y in balls:
        total += x
        total += y
    rad = float(total.rad())
    return 4.0 * (float(np.abs(floats).max(initial=0.0)) * FLOAT_REL + 2.0 * rad)


def _extreme(r: Region, dx: float, dy: float, sign: float) -> Points:
    """The balls of ``r`` that may hold the greatest sign * n . x, n = (dx, dy): all but those
    whose float projection lies more than (|dx| + |dy|) s below the float greatest (s =
    ``_slack``). A ball left out has every point's projection, and so its end, below the end of
    the ball of the float greatest: max (sign 1) of the upper ends, or min (sign -1) of the
    lower ends, over the balls kept is that over all of them, the same value
    (tests/spec/test_check_shortcuts.py; a slack without the balls' radii, the seeded fault,
    drops a wide ball that holds the end)."""
    # Python floats, not numpy: a region has tens of points, fewer than numpy's overhead.
    sx, sy = sign * dx, sign * dy
    f = [x * sx + y * sy for x, y in r[2].tolist()]
    least = max(f) - (abs(dx) + abs(dy)) * r[3]
    return [b for b, v in zip(r[0], f) if v >= least]


def _gap(a: Region, b: Region) -> arb:
    """A ball containing a lower bound on dist(hull A, hull B), by the float nearest direction;
    arb(0) when the float hulls already meet (no direction separates them). The projections'
    ends are taken over the balls that may hold them (``_extreme``): the same ends as over
    every ball, without the ball arithmetic of the others."""
    (x0, y0), (x1, y1) = shapely.get_coordinates(shapely.shortest_line(a[1], b[1])).tolist()
    dx, dy = x1 - x0, y1 - y0
    if dx == 0.0 and dy == 0.0:
        return arb(0)
    nx, ny = arb(dx), arb(dy)
    hi_a, lo_b = projection_bounds(nx, ny, _extreme(a, dx, dy, 1.0), _extreme(b, dx, dy, -1.0))
    return gap_over_norm(hi_a, lo_b, nx, ny)


def _upper(x: Any) -> Any:
    """A value at or above every point of ``x``: the upper end of a ball; a Z3 term itself."""
    return x.upper() if type(x) is arb else x        # (is_term's test costs more, per point)


def _lower(x: Any) -> Any:
    """A value at or below every point of ``x``: the lower end of a ball; a Z3 term itself."""
    return x.lower() if type(x) is arb else x


def projection_bounds(nx: Any, ny: Any, a: Sequence[tuple[Any, Any]],
                      b: Sequence[tuple[Any, Any]]) -> tuple[Any, Any]:
    """(hi_a, lo_b): hi_a at or above n.x for every point x of ``a``, lo_b at or below n.y for
    every point y of ``b`` (the ends of the balls; exact on Z3 terms, max_of and min_of an If
    there, Python's max and min on balls)."""
    hi_a = functools.reduce(max_of, (_upper(nx * x + ny * y) for x, y in a))
    lo_b = functools.reduce(min_of, (_lower(nx * x + ny * y) for x, y in b))
    return hi_a, lo_b


def gap_over_norm(hi_a: Any, lo_b: Any, nx: Any, ny: Any) -> Any:
    """The separating-axis gap (lo_b - hi_a) / |n|: a lower bound on the distance between the
    hulls when n.x <= hi_a on the one and n.y >= lo_b on the other, n != 0 (proved in
    proofs/_obl_constants.py). On balls (``arb.sqrt``) and on Z3 terms (``Sqrt``)."""
    return (lo_b - hi_a) / sqrt_of(nx * nx + ny * ny)


def _lower_float(x: arb) -> float:
    """A float at or below every point of the ball ``x``."""
    lo = x.lower()
    f = float(lo.mid())
    return f if arb(f) <= lo else math.nextafter(f, -math.inf)


def exact_path_gaps(s: Scenario, variant: Variant | str, grid: Grid,
                    path: Sequence[Sequence[int]]) -> ExactGaps:
    """Every (layer, cell) of ``path`` re-decided in ball arithmetic against eps, over the part
    pairs whose heights overlap (``pairs_to_test``); a cell with no such pair is free."""
    v = Variant(variant)
    gl = (s.left.omega[0] * s.dt, s.left.omega[1] * s.dt)
    pairs = pairs_to_test(s.left, s.right)
    old = ctx.prec
    ctx.prec = EXACT_PREC_BITS
    try:
        left: dict[int, list[Region]] = {}
        right: dict[Cell, list[Region]] = {}
        out = []
        for layer, cell in path_layer_cells(path, grid.N):
            if layer not in left:
                left[layer] = _left_points(s, v, grid, layer, gl)
            if cell not in right:
                right[cell] = _right_points(s, grid, cell)
            gaps = [_gap(left[layer][a], right[cell][b]) for a, b in pairs]
            if not gaps:
                out.append(ExactCell(layer, cell, math.inf, True))
                continue
            gap = min(gaps, key=lambda x: _lower_float(x))
            out.append(ExactCell(layer, cell, _lower_float(gap), bool(gap > arb(EPS))))
    finally:
        ctx.prec = old
    least = min(out, key=lambda c: c.gap_lower_m, default=None)
    return ExactGaps(cells=tuple(out), least_gap_m=least.gap_lower_m if least else math.inf,
                     least_at=(least.layer, least.cell) if least else None)


def _left_points(s: Scenario, v: Variant, grid: Grid, layer: int, g: tuple[float, float]
                 ) -> list[Region]:
    """The principal's regions (one per part) of ``layer`` (the rest layer is N), as the spec builds them."""
    if layer == grid.N:
        if v.rest_at_goal:
            goal = (float(s.left.goal[0]), float(s.left.goal[1]))
            box, anchor = rest_box(s, v, grid.N), goal
        else:
            return _left_points(s, v, grid, grid.N - 1, g)
    else:
        a = left_angles(s, layer * s.dt)
        anchor = (float(a[0]), float(a[1]))
        box = left_box(s, v, layer)
    axes = (lattice(box[0][0], box[0][1], anchor[0], g[0]),
            lattice(box[1][0], box[1][1], anchor[1], g[1]))
    return [_region_points(s.left, link, axes, g) for link in parts(s.left)]


def _right_points(s: Scenario, grid: Grid, cell: Cell) -> list[Region]:
    """The subordinate's regions (one per part) at ``cell``: the 3 x 3 lattice of its box."""
    h = grid.h
    ti = grid.lo[0] + cell[0] * h[0]
    tj = grid.lo[1] + cell[1] * h[1]
    steps = np.array([-1.0, 0.0, 1.0])
    axes = (ti + steps * h[0], tj + steps * h[1])
    return [_region_points(s.right, link, axes, h) for link in parts(s.right)]
