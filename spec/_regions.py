"""The swept regions S_LArm[k] and S_RArm[i][j] as docs/model.md §4 defines them (the spec's own code).

A region is the convex hull of a part (link rectangle or tool polygon), grown by the margin
delta, at the lattice points of the joint box (lattice anchored at the box's anchor, spacing g
per joint, the box rounded outward). delta = sum over joints with more than one lattice point
of g_q^2/8 * R_q, plus SNAP * g_q * R_q for rounding box ends onto the lattice (R_1 = R_base,
R_2 = R_elbow; a tool's from its farthest vertex).
"""

from __future__ import annotations

import math
from typing import cast

import numpy as np
import numpy.typing as npt
import shapely

from ._grid import Grid, Variant, left_angles, left_box, rest_box
from ._kinematics import part_points, parts, reach
from ._scenario import Arm, Scenario

__all__ = ["SNAP", "margin", "lattice", "left_region_polygons", "right_region_polygons"]

SNAP = 1e-9


def lattice(lo: float, hi: float, anchor: float, g: float) -> npt.NDArray[np.float64]:
    """Angles anchor + i g for the lattice indices covering [lo, hi] (ends snapped within SNAP g)."""
    a = math.floor((lo - anchor) / g + SNAP)
    b = math.ceil((hi - anchor) / g - SNAP)
    a, b = min(a, b), max(a, b)
    # cast: numpy's stubs type an int array times a float as floating[Any]
    return cast(npt.NDArray[np.float64], anchor + np.arange(a, b + 1) * g)


def margin(arm: Arm, link: int, g: tuple[float, float], sizes: tuple[int, int]) -> float:
    """delta for a lattice of ``sizes`` points per joint with spacing ``g``."""
    R = reach(arm, link)
    return sum((g[q] ** 2 / 8 * R[q] if sizes[q] > 1 else 0.0) + SNAP * g[q] * R[q]
               for q in range(2))


def _hulls(points: npt.NDArray[np.float64]) -> npt.NDArray[np.object_]:
    """Convex hulls of point clouds (..., P, 2) as shapely geometries."""
    flat = points.reshape(-1, points.shape[-2], 2)
    return shapely.convex_hull(shapely.multipoints(flat))


def _region(arm: Arm, link: int, box: tuple[tuple[float, float], tuple[float, float]],
            anchor: tuple[float, float], g: tuple[float, float]) -> shapely.Geometry:
    axes = [lattice(box[q][0], box[q][1], anchor[q], g[q]) for q in range(2)]
    grow = margin(arm, link, g, (len(axes[0]), len(axes[1])))
    t1, t2 = np.meshgrid(*axes, indexing="ij")
    pts = part_points(arm, t1, t2, link, grow).reshape(-1, 2)
    return _hulls(pts[None])[0]


def left_region_polygons(s: Scenario, variant: Variant | str, grid: Grid
                         ) -> list[tuple[shapely.Geometry, ...]]:
    """S_LArm for layers 0..N-1 and the rest layer R (index N), per variant: a region per part
    of the principal (``parts``: link 1, link 2, then the tool if any)."""
    v = Variant(variant)
    g = (s.left.omega[0] * s.dt, s.left.omega[1] * s.dt)
    out = []
    for k in range(grid.N):
        a = left_angles(s, k * s.dt)
        anchor = (float(a[0]), float(a[1]))
        box = left_box(s, v, k)
        out.append(tuple(_region(s.left, p, box, anchor, g) for p in parts(s.left)))
    if v.rest_at_goal:
        goal = (float(s.left.goal[0]), float(s.left.goal[1]))
        box = rest_box(s, v, grid.N)
        out.append(tuple(_region(s.left, p, box, goal, g) for p in parts(s.left)))
    else:
        out.append(out[-1])
    return out


def right_region_polygons(s: Scenario, grid: Grid, i: npt.ArrayLike, j: npt.ArrayLike
                          ) -> tuple[npt.NDArray[np.object_], ...]:
    """S_RArm at cells (i, j) (arrays of equal shape): a geometry array per part of the
    subordinate (``parts``: link 1, link 2, then the tool if any)."""
    i = np.asarray(i)
    j = np.asarray(j)
    h = grid.h
    ti = grid.lo[0] + i * h[0]
    tj = grid.lo[1] + j * h[1]
    steps = np.array([-1.0, 0.0, 1.0])
    # The 3 x 3 lattice of the box [t_i -+ h1] x [t_j -+ h2], anchored at the cell's own angles.
    t1 = ti[..., None, None] + steps[:, None] * h[0]
    t2 = tj[..., None, None] + steps[None, :] * h[1]
    t1, t2 = np.broadcast_arrays(t1, t2)
    out = []
    for link in parts(s.right):
        grow = margin(s.right, link, h, (3, 3))
        pts = part_points(s.right, t1, t2, link, grow)
        out.append(_hulls(pts.reshape(*i.shape, 9 * pts.shape[-2], 2)).reshape(i.shape))
    return tuple(out)
