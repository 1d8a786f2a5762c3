"""The swept regions of the reference, the same arrays, with their convex hulls in compiled code.

``convex_hulls`` gives, for each point set, exactly ``convex_hull``'s polygon: the same sort (x,
then y), the same duplicates dropped, the same monotone chain with the same orientation test in
the same double operations (no fused multiply-add: numba compiles without fast-math), so the
same vertices in the same order. Where ``convex_hull`` could choose otherwise, the set is handed
to it instead: two points equal as numbers but not as bits (0.0 and -0.0, which np.unique may
keep either of), a coordinate not finite or above HULL_SCALE_ABOVE (its scaled path), or fewer
than three distinct points. Tests compare both on random and bundled workcells.
"""

from __future__ import annotations

import math

import numpy as np
import numpy.typing as npt
from numba import njit, prange

from ..spec import Grid, Scenario, Variant, make_grid
from ._builtdr import LeftRegions, RightRegions, left_regions_by, right_row
from ._regions import HULL_SCALE_ABOVE, Polygon, convex_hull
from ._threads import parallel

__all__ = ["convex_hulls", "left_regions_fast", "right_regions_fast"]

Points = npt.NDArray[np.float64]  # (P, 2)


def convex_hulls(point_sets: list[Points]) -> list[Polygon]:
    """``[convex_hull(p) for p in point_sets]``, the same arrays, most of them compiled."""
    if not point_sets:
        return []
    sets = [np.asarray(p, dtype=float).reshape(-1, 2) for p in point_sets]
    flat = np.ascontiguousarray(np.concatenate(sets))
    starts = np.zeros(len(sets) + 1, dtype=np.int64)
    starts[1:] = np.cumsum([len(p) for p in sets])
    order, counts = _hulls(flat, starts, HULL_SCALE_ABOVE)
    return [convex_hull(p) if k < 0 else flat[order[a:a + k]]
            for p, k, a in zip(sets, counts, starts)]


def left_regions_fast(s: Scenario, variant: Variant | str, grid: Grid | None = None
                      ) -> LeftRegions:
    """``left_regions(s, variant, grid)``, the same polygons."""
    return left_regions_by(lambda pts: convex_hulls([pts])[0], s, variant, grid)


def right_regions_fast(s: Scenario, grid: Grid | None = None) -> RightRegions:
    """``right_regions(s, grid)``, the same arrays."""
    g = grid or make_grid(s)
    link1, link2, tool = right_row(s, g, convex_hulls)
    t_i = np.asarray(g.angle(0, np.arange(g.m)), dtype=float)
    # _rotate's cosines and sines, of the same array; then its products and sums, compiled.
    c, sn = np.cos(t_i), np.sin(t_i)
    bx, by = (float(v) for v in s.right.base)
    one = parallel(_turn, np.ascontiguousarray(link1[None]), c, sn, bx, by)[:, 0]
    return RightRegions(
        link1=one, link2=parallel(_turn, np.ascontiguousarray(link2), c, sn, bx, by),
        tool=None if tool is None else parallel(_turn, np.ascontiguousarray(tool), c, sn, bx, by))


# ---------------------------------------------------------------- compiled kernel (numba) ----

@njit(cache=True)
def _hulls(flat, starts, big):  # pragma: no cover - compiled; tested against convex_hull
    """Per point set c (rows starts[c]:starts[c+1] of flat): the flat row indices of its hull's
    vertices, counter-clockwise from the least (x, y), in order[starts[c]:], and their count
    (-1: left to convex_hull, see the module docstring)."""
    order = np.empty(flat.shape[0], dtype=np.int64)
    counts = np.empty(starts.shape[0] - 1, dtype=np.int64)
    for c in range(starts.shape[0] - 1):
        counts[c] = _hull(flat, starts[c], starts[c + 1], big, order)
    return order, counts


@njit(cache=True)
def _hull(flat, lo, hi, big, order):  # pragma: no cover - compiled
    n = hi - lo
    idx = np.empty(n, dtype=np.int64)
    for k in range(n):
        x, y = flat[lo + k, 0], flat[lo + k, 1]
        if not (abs(x) <= big and abs(y) <= big):   # NaN, infinite or huge: convex_hull's case
            return -1
        # Insertion sort by (x, y): a handful of points, and ties between equal numbers are
        # settled below, so the order of equal points does not matter.
        j = k
        while j > 0 and (flat[idx[j - 1], 0] > x
                         or (flat[idx[j - 1], 0] == x and flat[idx[j - 1], 1] > y)):
            idx[j] = idx[j - 1]
            j -= 1
        idx[j] = lo + k
    u = 0                                          # np.unique: keep one of each equal run
    for k in range(n):
        if u > 0:
            p, q = idx[u - 1], idx[k]
            if flat[p, 0] == flat[q, 0] and flat[p, 1] == flat[q, 1]:
                if not (_same_bits(flat[p, 0], flat[q, 0]) and _same_bits(flat[p, 1], flat[q, 1])):
                    return -1                      # 0.0 and -0.0: np.unique may keep either
                continue
        idx[u] = idx[k]
        u += 1
    if u <= 2:
        return -1
    chain = np.empty(2 * u, dtype=np.int64)        # lower hull, then upper, as _hull_indices
    top = 0
    for k in range(u):
        while top >= 2 and _cross(flat, chain[top - 2], chain[top - 1], idx[k]) <= 0:
            top -= 1
        chain[top] = idx[k]
        top += 1
    lower = top
    for k in range(u - 1, -1, -1):
        while top - lower >= 2 and _cross(flat, chain[top - 2], chain[top - 1], idx[k]) <= 0:
            top -= 1
        chain[top] = idx[k]
        top += 1
    # lower[:-1] + upper[:-1]
    count = 0
    for k in range(lower - 1):
        order[lo + count] = chain[k]
        count += 1
    for k in range(lower, top - 1):
        order[lo + count] = chain[k]
        count += 1
    return count


@njit(cache=True, inline="always")
def _cross(flat, o, a, b):  # pragma: no cover - compiled; _hull_indices' cross, same operations
    return ((flat[a, 0] - flat[o, 0]) * (flat[b, 1] - flat[o, 1])
            - (flat[a, 1] - flat[o, 1]) * (flat[b, 0] - flat[o, 0]))


@njit(cache=True, inline="always")
def _same_bits(x, y):  # pragma: no cover - compiled; equal numbers, also in the sign of zero
    return x == y and math.copysign(1.0, x) == math.copysign(1.0, y)


@njit(cache=True, parallel=True)
def _turn(row, c, s, bx, by):  # pragma: no cover - compiled; tested against _rotate
    """(m, n, V, 2): polygons row (n, V, 2) turned by each angle (cosines c, sines s) about the
    origin, then moved to (bx, by), in _rotate's operations: (c x + (-s) y) + bx, (s x + c y) + by."""
    m, n, V = c.shape[0], row.shape[0], row.shape[1]
    out = np.empty((m, n, V, 2))
    for i in prange(m):
        ci, si, nsi = c[i], s[i], -s[i]
        for j in range(n):
            for v in range(V):
                x, y = row[j, v, 0], row[j, v, 1]
                out[i, j, v, 0] = (ci * x + nsi * y) + bx
                out[i, j, v, 1] = (si * x + ci * y) + by
    return out
