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
from typing import Any

import numpy as np
import numpy.typing as npt
from numba import njit

from ..spec import Grid, Scenario, Variant, exact_tf, left_angles, make_grid, parts, rest_box
from ._builtdr import LeftRegions, RightRegions, left_spacing, right_row
from ._kernel_cache import ensure_compiled
from ._kinematics import link_rectangles
from ._regions import HULL_SCALE_ABOVE, SNAP, Polygon, convex_hull, sweep_margin, swept_points
from ._threads import shared

__all__ = ["convex_hulls", "left_regions_fast", "right_regions_fast"]

Points = npt.NDArray[np.float64]  # (P, 2)


def convex_hulls(point_sets: list[Points]) -> list[Polygon]:
    """``[convex_hull(p) for p in point_sets]``, the same arrays, most of them compiled."""
    ensure_compiled()
    if not point_sets:
        return []
    sets = [np.asarray(p, dtype=float).reshape(-1, 2) for p in point_sets]
    flat = np.ascontiguousarray(np.concatenate(sets))
    starts = np.zeros(len(sets) + 1, dtype=np.int64)
    starts[1:] = np.cumsum([len(p) for p in sets])
    order, counts = _hull_order(flat, starts)
    return [convex_hull(p) if k < 0 else flat[order[a:a + k]]
            for p, k, a in zip(sets, counts, starts)]


def _hull_order(flat: Points, starts: npt.NDArray[np.int64]
                ) -> tuple[npt.NDArray[np.int64], npt.NDArray[np.int64]]:
    """(order, counts) of ``_hulls`` on the point sets flat[starts[c]:starts[c + 1]]. Every
    array the kernel writes is made here: a kernel that allocates makes numba's cache load
    import numba's array implementation (0.04 s CPU of `cfmpa dr`'s start-up, docs/model.md
    §7.5)."""
    most = int(np.diff(starts).max(initial=0))
    order = np.empty(flat.shape[0], dtype=np.int64)
    counts = np.empty(starts.shape[0] - 1, dtype=np.int64)
    _hulls(flat, starts, HULL_SCALE_ABOVE, order, counts, np.empty(most, dtype=np.int64),
           np.empty(2 * most, dtype=np.int64))
    return order, counts


def left_regions_fast(s: Scenario, variant: Variant | str, grid: Grid | None = None
                      ) -> LeftRegions:
    """``left_regions(s, variant, grid)``, the same polygons: left_regions_by's boxes, anchors
    and points (the rule's layer box with Tf computed once, the PTP angles of every layer in one
    call: the same float operations elementwise), and every hull in one compiled call."""
    v = Variant(variant)
    g = grid or make_grid(s)
    L = s.left
    tf = float(exact_tf(s))
    spacing = left_spacing(s)
    links = parts(L)
    anchors = left_angles(s, np.asarray(np.arange(g.N) * s.dt, dtype=np.float64))   # (N, 2)
    boxes = np.array([v.layer_box(L.start, L.goal, L.omega, s.dt, tf, k) for k in range(g.N)],
                     dtype=float)                                      # (N, 2 joints, lo/hi)
    if v.rest_at_goal:
        anchors = np.concatenate([anchors, np.asarray(L.goal, dtype=float)[None]])
        boxes = np.concatenate([boxes, np.array(rest_box(s, v, g.N), dtype=float)[None]])
    per_link = [_lattice_points(L, link, boxes[..., 0], boxes[..., 1], anchors, spacing, 1.0)
                for link in links]
    hulls = convex_hulls([pts for layer in zip(*per_link) for pts in layer])
    A = len(links)
    out = [tuple(hulls[k * A:(k + 1) * A]) for k in range(g.N)]
    out.append(tuple(hulls[g.N * A:]) if v.rest_at_goal else out[-1])
    return LeftRegions(variant=v, links=tuple(out))


def right_regions_fast(s: Scenario, grid: Grid | None = None) -> RightRegions:
    """``right_regions(s, grid)``, the same arrays."""
    ensure_compiled()
    g = grid or make_grid(s)
    link1, link2, tool = right_row(s, g, convex_hulls, row_points=_row_points_fast)
    t_i = np.asarray(g.angle(0, np.arange(g.m)), dtype=float)
    # _rotate's cosines and sines, of the same array; then its products and sums, compiled.
    c, sn = np.cos(t_i), np.sin(t_i)
    bx, by = (float(v) for v in s.right.base)
    return RightRegions(link1=_turned(link1[None], c, sn, bx, by)[:, 0],
                        link2=_turned(link2, c, sn, bx, by),
                        tool=None if tool is None else _turned(tool, c, sn, bx, by))


def _turned(row: npt.NDArray[np.float64], c: npt.NDArray[np.float64],
            sn: npt.NDArray[np.float64], bx: float, by: float) -> npt.NDArray[np.float64]:
    """(m, n, V, 2): the polygons row (n, V, 2) turned by each angle, on the kernel threads."""
    out = np.empty((c.shape[0], *row.shape))
    shared(_turn, np.ascontiguousarray(row), c, sn, bx, by, out)
    return out



def _row_points_fast(origin: Any, part: int, t_j: Points, h: tuple[float, float],
                     margin_scale: float) -> list[Points]:
    """``_row_points``' point sets, the same arrays (its boxes and anchors per j to
    _lattice_points; its groups are _lattice_points' too, so link_rectangles gets the same
    arrays)."""
    h1, h2 = h
    lo = np.stack([np.full_like(t_j, -h1), t_j - h2], axis=-1)
    hi = np.stack([np.full_like(t_j, h1), t_j + h2], axis=-1)
    anchor = np.stack([np.zeros_like(t_j), t_j], axis=-1)
    return _lattice_points(origin, part, lo, hi, anchor, h, margin_scale)


def _lattice_points(arm: Any, link: int, lo: Points, hi: Points, anchor: Points,
                    g: tuple[float, float], margin_scale: float) -> list[Points]:
    """``[swept_points(arm, link, box_c, anchor_c, g) for each c]`` (box_c = ((lo[c, 0],
    hi[c, 0]), (lo[c, 1], hi[c, 1]))), the same arrays, the lattices computed at once:
    lattice_range's float operations elementwise (floor((lo - anchor) / g + SNAP), ceil((hi -
    anchor) / g - SNAP), their min and max), then anchor + index g, as swept_lattice does; then
    link_rectangles once per group of equal lattice shape and margin, on contiguous stacked
    arrays (as _row_points stacks them: elementwise the same doubles). A spacing <= 0 or a value
    not finite goes to swept_points."""
    if not (g[0] > 0 and g[1] > 0 and np.isfinite(lo).all() and np.isfinite(hi).all()
            and np.isfinite(anchor).all()):
        return [swept_points(arm, link, ((lo[c, 0], hi[c, 0]), (lo[c, 1], hi[c, 1])),
                             anchor[c], g, margin_scale=margin_scale) for c in range(len(lo))]
    first = np.empty((len(lo), 2))
    count = np.empty((len(lo), 2), dtype=np.int64)
    for q in range(2):
        if link == 0 and q == 1:           # link 1 does not depend on theta2: one sample
            first[:, q], count[:, q] = 0.0, 1
            continue
        a = np.floor((lo[:, q] - anchor[:, q]) / g[q] + SNAP)
        b = np.ceil((hi[:, q] - anchor[:, q]) / g[q] - SNAP)
        first[:, q] = np.minimum(a, b)
        count[:, q] = (np.maximum(a, b) - first[:, q]).astype(np.int64) + 1
    grows: dict[tuple[bool, bool], float] = {}
    groups: dict[tuple[tuple[int, int], float], list[int]] = {}
    for c in range(len(lo)):
        n0, n1 = int(count[c, 0]), int(count[c, 1])
        moving = (n0 > 1, n1 > 1)
        if moving not in grows:
            grows[moving] = margin_scale * sweep_margin(arm, link, g, moving)
        groups.setdefault(((n0, n1), grows[moving]), []).append(c)
    out: list[Points] = [np.empty(0)] * len(lo)
    for ((n0, n1), grow), cs in groups.items():
        idx = np.asarray(cs)
        axes = [anchor[idx, q, None] + (first[idx, q, None] + np.arange(n)[None, :]) * g[q]
                if not (link == 0 and q == 1) else anchor[idx, 1, None]
                for q, n in ((0, n0), (1, n1))]
        # Contiguous, as the stacked meshgrids: numpy's cos and sin may take another loop (and
        # round otherwise) on strided input.
        t1 = np.ascontiguousarray(np.broadcast_to(axes[0][:, :, None], (len(cs), n0, n1)))
        t2 = np.ascontiguousarray(np.broadcast_to(axes[1][:, None, :], (len(cs), n0, n1)))
        corners = link_rectangles(arm, t1, t2, link, grow=grow)
        for c, pts in zip(cs, corners):
            out[c] = pts.reshape(-1, 2)
    return out

# ---------------------------------------------------------------- compiled kernel (numba) ----

@njit(cache=True)
def _hulls(flat, starts, big, order, counts, idx, chain
           ):  # pragma: no cover - compiled; tested against convex_hull
    """Per point set c (rows starts[c]:starts[c+1] of flat): the flat row indices of its hull's
    vertices, counter-clockwise from the least (x, y), in order[starts[c]:], and their count in
    counts[c] (-1: left to convex_hull, see the module docstring). idx and chain: scratch of at
    least the largest set's size and twice it (nothing here allocates)."""
    for c in range(starts.shape[0] - 1):
        counts[c] = _hull(flat, starts[c], starts[c + 1], big, order, idx, chain)


@njit(cache=True)
def _hull(flat, lo, hi, big, order, idx, chain):  # pragma: no cover - compiled
    n = hi - lo
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
    # chain[:2 u]: the lower hull, then the upper, as _hull_indices
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


@njit(cache=True, nogil=True)
def _turn(t, K, row, c, s, bx, by, out):  # pragma: no cover - compiled; tested against _rotate
    """Thread t of K: out[i] (n, V, 2) for its block of angles i, the polygons row (n, V, 2)
    turned by angle i (cosine c[i], sine s[i]) about the origin, then moved to (bx, by), in
    _rotate's operations: (c x + (-s) y) + bx, (s x + c y) + by."""
    m, n, V = c.shape[0], row.shape[0], row.shape[1]
    for i in range(t * m // K, (t + 1) * m // K):
        ci, si, nsi = c[i], s[i], -s[i]
        for j in range(n):
            for v in range(V):
                x, y = row[j, v, 0], row[j, v, 1]
                out[i, j, v, 0] = (ci * x + nsi * y) + bx
                out[i, j, v, 1] = (si * x + ci * y) + by
