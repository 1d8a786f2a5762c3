"""Theorem 1 / Theorem 3's postcondition, decided cell by cell with the spec's own geometry.

For all k <= N, i < m, j < n: P[k, i, j] = (dist(S_LArm[k], S_RArm[i][j]) > eps -> 0 | 1). The
regions come from ``_regions`` and distances from shapely (GEOS), sharing no code with impl/.
Two float computations of the same polygons can differ by rounding, so a cell whose spec
distance lies within ``band`` of eps is counted as indeterminate and accepted either way.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import numpy.typing as npt
import shapely

from ._grid import EPS, Grid, Variant
from ._regions import left_region_polygons, right_region_polygons
from ._scenario import Scenario

__all__ = ["BAND", "CellMismatch", "PostReport", "dr_postcondition", "expected_cells"]

#: Distances within this of eps (metres) may be decided either way by two float computations.
BAND = 1e-10


@dataclass(frozen=True)
class CellMismatch:
    """One cell where D_R disagrees with the triple: what it holds, what it should, and why."""

    layer: int
    cell: tuple[int, int]
    angles: tuple[float, float]
    got: int
    expected: int
    distance_m: float


@dataclass(frozen=True)
class PostReport:
    """The postcondition's verdict over the cells checked."""

    ok: bool
    checked: int
    indeterminate: int
    mismatches: tuple[CellMismatch, ...]


def expected_cells(s: Scenario, variant: Variant | str, grid: Grid, layers: npt.ArrayLike,
                   i: npt.ArrayLike, j: npt.ArrayLike) -> npt.NDArray[np.float64]:
    """The spec's distance between S_LArm[k] and S_RArm[i][j] for each (k, i, j) given."""
    layers = np.asarray(layers)
    i = np.asarray(i)
    j = np.asarray(j)
    left = left_region_polygons(s, variant, grid)
    r1, r2 = right_region_polygons(s, grid, i, j)
    dist = np.full(layers.shape, np.inf)
    for k in np.unique(layers):
        sel = layers == k
        for a in left[int(k)]:
            for rb in (r1[sel], r2[sel]):
                dist[sel] = np.minimum(dist[sel], shapely.distance(a, rb))
    return dist


def dr_postcondition(s: Scenario, variant: Variant | str, grid: Grid, dr: npt.NDArray[np.uint8],
                     *, cells: npt.NDArray[np.int64] | None = None, eps: float = EPS,
                     band: float = BAND, limit: int = 20) -> PostReport:
    """Check dr against the triple at ``cells`` ((C, 3) array of k, i, j), or at every cell.

    Returns at most ``limit`` mismatches (the count of checked cells is exact).
    """
    if cells is None:
        k, i, j = np.meshgrid(np.arange(grid.N + 1), np.arange(grid.m), np.arange(grid.n),
                              indexing="ij")
        k, i, j = k.ravel(), i.ravel(), j.ravel()
        # One layer's right regions serve all layers: compute them once, reuse per layer.
        dist = _all_layers(s, variant, grid)
    else:
        k, i, j = cells[:, 0], cells[:, 1], cells[:, 2]
        dist = expected_cells(s, variant, grid, k, i, j)
    got = dr[k, i, j].astype(int)
    expected = (dist <= eps).astype(int)
    near = np.abs(dist - eps) <= band
    bad = np.flatnonzero((got != expected) & ~near)
    mismatches = tuple(
        CellMismatch(layer=int(k[c]), cell=(int(i[c]), int(j[c])),
                     angles=grid.angles((int(i[c]), int(j[c]))), got=int(got[c]),
                     expected=int(expected[c]), distance_m=float(dist[c]))
        for c in bad[:limit])
    return PostReport(ok=len(bad) == 0, checked=len(k),
                      indeterminate=int(((got != expected) & near).sum()), mismatches=mismatches)


def _all_layers(s: Scenario, variant: Variant | str, grid: Grid) -> npt.NDArray[np.float64]:
    ii, jj = np.meshgrid(np.arange(grid.m), np.arange(grid.n), indexing="ij")
    r1, r2 = right_region_polygons(s, grid, ii.ravel(), jj.ravel())
    shapely.prepare(r1)
    shapely.prepare(r2)
    left = left_region_polygons(s, variant, grid)
    out = np.empty((grid.N + 1, grid.m * grid.n))
    for k, links in enumerate(left):
        d = np.full(grid.m * grid.n, np.inf)
        for a in links:
            d = np.minimum(d, shapely.distance(a, r1))
            d = np.minimum(d, shapely.distance(a, r2))
        out[k] = d
    return out.ravel()
