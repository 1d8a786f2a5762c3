"""BuiltDR, the reference (the paper's Algorithm 1, step 3), for the three variants of docs/model.md §4.

Read next to the paper: for every layer k, cell (i, j): P[k, i, j] = 0 iff the principal's region
S_LArm[k] and the subordinate's region S_RArm[i][j] are apart (distance > eps), else 1. The loops
over i and j are vectorised; the loop over k and the links is written out. A region is one per
part (link 1, link 2, the tool if any); only pairs of parts whose heights overlap are tested
(``spec.pairs_to_test``, docs/model.md §2 "Tools and heights").
"""

from __future__ import annotations

import hashlib
from collections.abc import Callable, Sequence
from dataclasses import dataclass
from fractions import Fraction
from typing import Any

import numpy as np
import numpy.typing as npt

from ..spec import (
    EPS,
    Grid,
    Scenario,
    Variant,
    left_angles,
    left_box,
    make_grid,
    pairs_to_test,
    parts,
    rest_box,
)
from ._collide import PolygonSet, blocked_against, pad_polygons
from ._kinematics import link_rectangles
from ._regions import Angles, Box, Polygon, convex_hull, swept_lattice, swept_points

__all__ = [
    "LeftRegions",
    "RightRegions",
    "left_regions",
    "left_regions_by",
    "right_regions",
    "right_row",
    "rotate_row",
    "build_dr",
    "ContainmentReport",
    "check_containment",
    "contained_exactly",
    "containment_slack",
    "left_spacing",
]

DR = npt.NDArray[np.uint8]  # (N + 1, m, n)


@dataclass(frozen=True)
class LeftRegions:
    """The principal's region per layer: ``links[k] = (link 1, link 2[, tool])``, k = 0..N (N:
    rest), a polygon per part (``spec.parts``)."""

    variant: Variant
    links: tuple[tuple[Polygon, ...], ...]


@dataclass(frozen=True)
class RightRegions:
    """The subordinate's regions: link 1 per i (m, V, 2); link 2 per (i, j) (m, n, V, 2); the
    tool's per (i, j) (m, n, V, 2), or None without a tool."""

    link1: npt.NDArray[np.float64]
    link2: npt.NDArray[np.float64]
    tool: npt.NDArray[np.float64] | None = None

    def per_cell(self) -> list[npt.NDArray[np.float64]]:
        """The regions that depend on the cell, in part order: link 2, then the tool if any."""
        return [self.link2] if self.tool is None else [self.link2, self.tool]


def left_spacing(s: Scenario) -> tuple[float, float]:
    """The lattice spacing of the principal's regions, omega_q dt per joint, in every variant."""
    # One lattice for all variants (anchored at theta_L(k dt), spacing omega dt) makes the
    # variants' lattices nest, so tight within modified within original holds point for point.
    return (s.left.omega[0] * s.dt, s.left.omega[1] * s.dt)


def left_regions(s: Scenario, variant: Variant | str, grid: Grid | None = None, *,
                 margin_scale: float = 1.0) -> LeftRegions:
    """S_LArm[k] for k = 0..N-1 and the rest layer (index N), per docs/model.md §4."""
    return left_regions_by(convex_hull, s, variant, grid, margin_scale=margin_scale)


def left_regions_by(hull: Callable[[npt.NDArray[np.float64]], Polygon], s: Scenario,
                    variant: Variant | str, grid: Grid | None = None, *,
                    margin_scale: float = 1.0) -> LeftRegions:
    """left_regions with ``hull`` taking the points' convex hull (impl's compiled twin of
    convex_hull gives the same arrays faster)."""
    v = Variant(variant)
    g = grid or make_grid(s)
    spacing = left_spacing(s)

    def region(link: int, box: Box, anchor: Angles) -> Polygon:
        return hull(swept_points(s.left, link, box, anchor, spacing, margin_scale=margin_scale))
    out = []
    for k in range(g.N):
        box = left_box(s, v, k)
        anchor = left_angles(s, k * s.dt)
        out.append(tuple(region(link, box, anchor) for link in parts(s.left)))
    if v.rest_at_goal:
        goal = tuple(s.left.goal)
        out.append(tuple(region(link, rest_box(s, v, g.N), goal) for link in parts(s.left)))
    else:
        out.append(out[-1])
    return LeftRegions(variant=v, links=tuple(out))


def _rotate(poly: npt.NDArray[np.float64], angles: npt.NDArray[np.float64],
            base: tuple[float, float]) -> npt.NDArray[np.float64]:
    """Rotate polygons (…, V, 2) about the origin by each angle, then translate to base."""
    # Written out rather than as an einsum: the same two products and one sum per coordinate
    # (so the same doubles), several times faster on the right arm's m x n polygons.
    shape = (len(angles),) + (1,) * (poly.ndim - 1)
    c, s = np.cos(angles).reshape(shape), np.sin(angles).reshape(shape)
    x, y = poly[..., 0][None], poly[..., 1][None]
    return np.stack([c * x + (-s) * y, s * x + c * y], axis=-1) + np.asarray(base)


def right_regions(s: Scenario, grid: Grid | None = None, *, margin_scale: float = 1.0
                  ) -> RightRegions:
    """S_RArm[i][j] for every cell: the box [t_i -+ h1] x [t_j -+ h2] swept by each link.

    Computed at t_i = 0 with the base at the origin, then rotated by t_i about the base: turning
    theta1 rotates every configuration's rectangle rigidly, so this is the same construction.
    """
    g = grid or make_grid(s)
    return rotate_row(s, g, *right_row(s, g, lambda pts: [convex_hull(p) for p in pts],
                                       margin_scale=margin_scale))


def rotate_row(s: Scenario, g: Grid, link1: Polygon, link2: npt.NDArray[np.float64],
               tool: npt.NDArray[np.float64] | None = None) -> RightRegions:
    """right_row's regions turned by every t_i about the subordinate's base."""
    t_i = np.asarray(g.angle(0, np.arange(g.m)), dtype=float)
    return RightRegions(link1=_rotate(link1, t_i, s.right.base),
                        link2=_rotate(link2, t_i, s.right.base),
                        tool=None if tool is None else _rotate(tool, t_i, s.right.base))


def right_row(s: Scenario, g: Grid,
              hulls: Callable[[list[npt.NDArray[np.float64]]], Sequence[Polygon]], *,
              margin_scale: float = 1.0, row_points: Callable[..., Any] | None = None
              ) -> tuple[Polygon, npt.NDArray[np.float64], npt.NDArray[np.float64] | None]:
    """The subordinate's regions at t_i = 0, base at the origin: link 1 (V, 2), link 2 per j
    (n, V, 2), padded, and the tool's per j likewise (None without a tool); ``hulls`` takes the
    convex hull of each point set (as convex_hull), ``row_points`` (by default _row_points)
    gives a part's point sets per j (the fast kernels' twin gives the same arrays)."""
    arm = s.right
    origin = type(arm)(**{**arm.__dict__, "base": (0.0, 0.0)})
    h1, h2 = g.h
    t_j = np.asarray(g.angle(1, np.arange(g.n)), dtype=float)
    points = [swept_points(origin, 0, ((-h1, h1), (0.0, 0.0)), (0.0, 0.0), (h1, h2),
                           margin_scale=margin_scale)]
    per_cell = [p for p in parts(arm) if p > 0]
    for part in per_cell:
        points += (row_points or _row_points)(origin, part, t_j, (h1, h2), margin_scale)
    polys = hulls(points)
    n = len(t_j)
    out = [pad_polygons(list(polys[1 + c * n:1 + (c + 1) * n])) for c in range(len(per_cell))]
    return polys[0], out[0], out[1] if len(out) > 1 else None


def _row_points(origin: Any, part: int, t_j: npt.NDArray[np.float64], h: tuple[float, float],
                margin_scale: float) -> list[npt.NDArray[np.float64]]:
    """The points of the part's region per j at t_i = 0 (link 2's or the tool's), in one call
    per lattice shape and margin (elementwise the same operations as one call per j, so the
    same doubles)."""
    h1, h2 = h
    lattices = [swept_lattice(origin, part, ((-h1, h1), (tj - h2, tj + h2)), (0.0, tj), (h1, h2),
                              margin_scale=margin_scale) for tj in t_j]
    groups: dict[tuple[tuple[int, ...], float], list[int]] = {}
    for j, (t1, _, grow) in enumerate(lattices):
        groups.setdefault((t1.shape, grow), []).append(j)
    out: list[npt.NDArray[np.float64]] = [np.empty(0)] * len(lattices)
    for (_, grow), js in groups.items():
        corners = link_rectangles(origin, np.stack([lattices[j][0] for j in js]),
                                  np.stack([lattices[j][1] for j in js]), part, grow=grow)
        for j, c in zip(js, corners):
            out[j] = c.reshape(-1, 2)
    return out


def build_dr(s: Scenario, variant: Variant | str, grid: Grid | None = None, *,
             eps: float = EPS, right: RightRegions | None = None, margin_scale: float = 1.0) -> DR:
    """D_R for ``variant``: uint8 (N + 1, m, n), layers 0..N-1 then the rest layer; 1 = blocked."""
    g = grid or make_grid(s)
    rr = right or right_regions(s, g, margin_scale=margin_scale)
    left = left_regions(s, variant, g, margin_scale=margin_scale)
    m, n = g.m, g.n
    sets = [PolygonSet.of(rr.link1)] + [PolygonSet.of(r.reshape(m * n, *r.shape[2:]))
                                        for r in rr.per_cell()]
    pairs = pairs_to_test(s.left, s.right)               # the parts whose heights overlap
    P = np.zeros(g.shape, dtype=np.uint8)
    for k, regions in enumerate(left.links):             # For all k = 0 to N (N: rest layer)
        blocked = np.zeros((m, n), dtype=bool)
        for a, b in pairs:                                # S_LArm[k] = the union of its parts
            if b == 0:
                blocked |= blocked_against(regions[a], sets[0], eps)[:, None]
            else:
                blocked |= blocked_against(regions[a], sets[b], eps).reshape(m, n)
        P[k] = blocked                                    # if S_LArm ∩ S_RArm = Φ then 0 else 1
    return P


@dataclass(frozen=True)
class ContainmentReport:
    """tight within modified within original, per layer and rest layer, on computed polygons:
    ``ok`` is the exact verdict; ``worst_slack_m`` the least float slack, for information."""

    ok: bool
    layers: int
    worst_slack_m: float
    detail: str
    regions_sha256: str = ""   # of every polygon checked, so a replay can tell changed regions


def contained_exactly(inner: Polygon, outer: Polygon) -> bool:
    """Whether every vertex of ``inner`` lies in the convex CCW polygon ``outer`` (boundary
    included), decided exactly on the doubles: each edge-side sign comes from the float cross
    product when it exceeds a bound on that product's rounding error, else from Fractions."""
    o = outer.astype(np.float64)
    e = np.roll(o, -1, axis=0) - o
    d = inner[:, None, :] - o[None, :, :]                          # vertex minus edge start
    a, b = e[None, :, 0] * d[..., 1], e[None, :, 1] * d[..., 0]
    cross = a - b
    # |fl(cross) - cross| <= 8u (|e||d| terms) covers the two differences, two products and one
    # subtraction (u = 2^-53); doubled for the rounding of the bound itself.
    bound = 16 * 2.0 ** -53 * (np.abs(a) + np.abs(b)) + 1e-300
    if np.any(cross < -bound):
        return False
    for vi, ei in np.argwhere(np.abs(cross) <= bound):
        ox, oy = Fraction(o[ei, 0]), Fraction(o[ei, 1])
        nx, ny = o[(ei + 1) % len(o)]
        vx, vy = Fraction(inner[vi, 0]), Fraction(inner[vi, 1])
        if (Fraction(nx) - ox) * (vy - oy) - (Fraction(ny) - oy) * (vx - ox) < 0:
            return False
    return True


def containment_slack(inner: Polygon, outer: Polygon) -> float:
    """Least distance by which inner's vertices lie inside outer's edge lines (< 0: outside)."""
    edges = np.roll(outer, -1, axis=0) - outer
    normals = np.stack([edges[:, 1], -edges[:, 0]], -1)           # outward for CCW
    normals /= np.hypot(normals[:, 0], normals[:, 1])[:, None]
    out = np.einsum("ed,ved->ve", normals, inner[:, None, :] - outer[None, :, :])
    return float(-out.max())


_PART = {0: "link 1", 1: "link 2", 2: "tool"}


def check_containment(s: Scenario, grid: Grid | None = None) -> ContainmentReport:
    """Check each variant's region within its rule's ``within`` (``Variant.nesting``: tight
    within modified within original) at every layer and R."""
    g = grid or make_grid(s)
    regs = {v: left_regions(s, v, g) for v in Variant}
    pairs = Variant.nesting()
    worst = np.inf
    where = ""
    outside = []
    for k in range(g.N + 1):
        for link in parts(s.left):
            for inner, outer in pairs:
                a, b = regs[inner].links[k][link], regs[outer].links[k][link]
                sl = containment_slack(a, b)
                if sl < worst:
                    worst, where = sl, f"layer {k} {_PART[link]}: {inner} within {outer}"
                if not contained_exactly(a, b):
                    outside.append(f"layer {k} {_PART[link]}: {inner} not within {outer}")
    ok = not outside
    digest = hashlib.sha256()
    for v in Variant:
        for pair in regs[v].links:
            for poly in pair:
                digest.update(poly.tobytes())
    layer_word = "rest layer" if where.startswith(f"layer {g.N} ") else "layer"
    detail = (f"{g.N} layers and the rest layer, every part, decided exactly on the doubles; "
              + (f"{len(outside)} not contained, first {outside[0]}; " if outside else "")
              + f"least slack {worst:.3e} m at {where} ({layer_word})")
    return ContainmentReport(ok=ok, layers=g.N + 1, worst_slack_m=float(worst), detail=detail,
                             regions_sha256=digest.hexdigest())
