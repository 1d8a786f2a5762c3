"""BuiltDR, fast: the reference's regions and decision, bit for bit, in a compiled kernel.

Same regions: the arrays of the reference's ``left_regions`` and ``right_regions``, built by
their compiled twins (``_fast_regions``, equal element for element, tested so).
Same decision: the reference declares a pair blocked iff its bounding-box gap is <= eps and its
computed separating-axis gap g (max over the edge normals of both polygons) is <= 0, or lies in
(0, eps] and the exact distance is <= eps. The kernel decides a pair only where that outcome is
certain despite rounding, and hands every other pair to the reference's own ``blocked_against``:

- the bounding-box test is the reference's, in the same float operations, so it agrees exactly;
- "free" when one axis's gap, computed here, exceeds eps + MARGIN: the reference's gap on that
  axis differs from ours by at most a few ulps of the coordinates (same vertices, normals and
  offsets; only the order of the two products may differ), which MARGIN exceeds by orders of
  magnitude, so the reference's g > eps too and it says free;
- "blocked" when every axis's gap is below -MARGIN (so the reference's g < 0), or when a point
  of one polygon lies inside the other by more than MARGIN: a point of B at depth d inside A
  makes every gap <= -d (along A's normals B reaches the point; along B's normals A covers the
  disc of radius d around it), and symmetrically. The points tried: one that proved the
  previous cell of the row (it lies in A: a vertex of A, or deeper than MARGIN in A), points
  of the links' centre lines checked deeper than MARGIN in both, and the vertices of each;
- a polygon with a coordinate that is not finite or beyond MAX_COORD (where the kernel's
  unguarded sqrt and the reference's hypot could differ) has its box packed as NaN, and every
  pair with it is "unsure"; every comparison that frees or blocks is written so that NaN does
  neither (free iff gap > eps + MARGIN, blocked iff depth > MARGIN);
- everything else (gaps within MARGIN of 0 or eps) is "unsure" and goes to ``blocked_against`` on
  the same polygon arrays, whose per-pair arithmetic does not depend on which other pairs share
  the batch (the reference itself runs it on the box-filtered subset).

Layout: each polygon set is packed as geo (C, V, 6) = x, y, outward normal x, y, offset, edge
has a length (1.0/0.0); box (C, 4) = lo x, lo y, hi x, hi y; spine (C, 4), the link's centre
line, where a common point is looked for. Few arrays per call keep the compiled calls cheap.

Parts: a left polygon per part (link 1, link 2, the tool); the right link 1 per row, and the
per-cell parts (link 2, the tool) stacked; only pairs whose heights overlap are tested
(``spec.pairs_to_test``), as in the reference.

Structure used: the rest layer of original/modified is layer N-1 (copied); a row i whose right
link 1 is blocked (and tested) is blocked whole; a row whose union box is apart is free whole; a cell already
blocked by one left link is not tested again (the decision is an OR).
"""

from __future__ import annotations

import math
import time

import numpy as np
import numpy.typing as npt
from numba import njit, prange

from ..spec import (EPS, Arm, Grid, Scenario, Variant, joints, left_angles, make_grid,
                    pairs_to_test)
from ._builtdr import DR, RightRegions
from ._fast_regions import left_regions_fast, right_regions_fast
from ._collide import PolygonSet, blocked_against, pad_polygons
from ._progress import progress_bar
from ._threads import parallel

__all__ = ["MARGIN_REL", "MAX_COORD", "STAGES", "build_dr_fast", "decision_margin"]

#: Safety margin around the thresholds 0 and eps, relative to the largest coordinate (at least
#: 1 m). Rounding differences between two evaluations of one gap are ~1e-15 of the coordinates.
MARGIN_REL = 1e-12

#: Polygons with a coordinate beyond this (metres) are left to the reference: the loader's
#: physical range keeps every coordinate far below it, so this never costs time in practice.
MAX_COORD = 1e100

FREE, BLOCKED, UNSURE = 0, 1, 2
_BLOCKED_AT = 3  # BLOCKED, proved by a common point, returned with it (the next cell tries it)
_SEPARATED = 4   # FREE, found on axis (code - _SEPARATED): the next cell tries that axis first


def decision_margin(*coords: npt.NDArray[np.float64]) -> float:
    """MARGIN: pairs whose computed gaps are this close to 0 or eps go to the reference routine.

    Scaled by the largest coordinate the kernel decides on (finite, at most MAX_COORD)."""
    scale = 1.0
    for c in coords:
        a = np.abs(c)
        a = a[a <= MAX_COORD]                  # NaN and the rest go to the reference anyway
        if a.size:
            scale = max(scale, float(a.max()))
    return MARGIN_REL * scale


#: build_dr_fast's stages, in its order, as ``stages`` records them.
STAGES = ("right_regions", "left_regions", "pack_right", "pack_left", "layer_kernel",
          "settle_unsure", "other")


def build_dr_fast(s: Scenario, variant: Variant | str, grid: Grid | None = None, *,
                  eps: float = EPS, right: RightRegions | None = None,
                  progress: bool | None = None, stages: dict[str, float] | None = None) -> DR:
    """D_R for ``variant``, identical to ``build_dr`` (uint8 (N + 1, m, n), 1 = blocked).

    ``stages``, if given, gains the seconds spent in each of STAGES (and "unsure_pairs")."""
    clock = _Clock(stages)
    g = grid or make_grid(s)
    rr = right or right_regions_fast(s, g)
    clock.lap("right_regions")
    left = left_regions_fast(s, variant, g)
    clock.lap("left_regions")
    m, n = g.m, g.n
    spine1, spine2 = _right_spines(s, g)
    r1 = np.ascontiguousarray(rr.link1)
    # The per-cell parts (link 2, the tool) stacked part by part, padded to one vertex count
    # (a repeated vertex: a zero-length edge, which no test uses): cell c of part p is polygon
    # p m n + c. The reference settles a pair on its own part's array (``per_cell``).
    per_cell = [np.ascontiguousarray(r.reshape(m * n, *r.shape[2:])) for r in rr.per_cell()]
    r2 = np.ascontiguousarray(np.concatenate([_pad_to(r, max(x.shape[1] for x in per_cell))
                                              for r in per_cell]))
    g1, box1 = parallel(_pack_all, r1)
    g2, box2 = parallel(_pack_all, r2)
    rows = box2.reshape(len(per_cell) * m, n, 4)
    row_box = np.concatenate([rows[..., :2].min(axis=1), rows[..., 2:].max(axis=1)], axis=1)
    margin = decision_margin(box1, box2, *(p for pair in left.links for p in pair))
    P = np.zeros(g.shape, dtype=np.uint8)
    A = len(left.links[0])
    tested1 = np.zeros(A, dtype=np.bool_)
    tested2 = np.zeros((A, len(per_cell)), dtype=np.bool_)
    for a, b in pairs_to_test(s.left, s.right):
        if b == 0:
            tested1[a] = True
        else:
            tested2[a, b - 1] = True
    unc1 = np.zeros((A, m), dtype=np.bool_)
    unc2 = np.zeros((A, len(per_cell) * m * n), dtype=np.bool_)
    rows_dealt = np.concatenate([np.arange(0, m, 2), np.arange(1, m, 2)])
    clock.lap("pack_right")
    with progress_bar(f"BuiltDR {Variant(variant)}", len(left.links), int(np.prod(g.shape)),
                      progress) as bar:
        for k, pair in enumerate(left.links):
            if k > 0 and pair is left.links[k - 1]:
                P[k] = P[k - 1]                   # the rest layer is layer N-1 itself
                bar.advance()
                clock.lap("other")
                continue
            ga, boxa = _pack(pad_polygons(list(pair)))
            out = P[k].reshape(m * n)
            unc1[:] = False
            unc2[:] = False
            spa = _left_spines(s, k, g.N)
            clock.lap("pack_left")
            parallel(_layer, rows_dealt, ga, boxa, spa, g1, box1, spine1, g2, box2, spine2,
                       row_box, m, n, tested1, tested2, eps, margin, out, unc1, unc2)
            clock.lap("layer_kernel")
            if unc1.any() or unc2.any():
                clock.count("unsure_pairs", int(unc1.sum() + unc2.sum()))
                _settle_unsure(pair, r1, per_cell, unc1, unc2, out.reshape(m, n), eps)
            bar.advance()
            clock.lap("settle_unsure")
    return P


class _Clock:
    """Adds the seconds since the last lap to a stage of ``stages`` (nothing if it is None)."""

    def __init__(self, stages: dict[str, float] | None) -> None:
        self.stages = stages
        self.t = time.perf_counter()

    def lap(self, stage: str) -> None:
        if self.stages is not None:
            now = time.perf_counter()
            self.stages[stage] = self.stages.get(stage, 0.0) + now - self.t
            self.t = now

    def count(self, what: str, k: int) -> None:
        if self.stages is not None:
            self.stages[what] = self.stages.get(what, 0) + k


def _pad_to(polys: npt.NDArray[np.float64], size: int) -> npt.NDArray[np.float64]:
    """Polygons (C, V, 2) padded to (C, size, 2) by repeating each last vertex."""
    if polys.shape[1] == size:
        return polys
    extra = np.repeat(polys[:, -1:], size - polys.shape[1], axis=1)
    return np.concatenate([polys, extra], axis=1)


def _tool_spine(arm: Arm, t1: npt.NDArray[np.float64], t12: npt.NDArray[np.float64]
                ) -> npt.NDArray[np.float64]:
    """A diagonal of the tool (its vertex 0 to vertex V // 2, inside the convex polygon) at
    each configuration, (..., 4): where a common point is looked for first."""
    assert arm.tool is not None
    along = np.stack([np.cos(t12), np.sin(t12)], -1)
    normal = np.stack([-along[..., 1], along[..., 0]], -1)
    wrist = (np.asarray(arm.base, dtype=float)
             + arm.links[0] * np.stack([np.cos(t1), np.sin(t1)], -1) + arm.links[1] * along)
    poly = arm.tool.polygon
    ends = [wrist + x * along + y * normal for x, y in (poly[0], poly[len(poly) // 2])]
    return np.concatenate(ends, axis=-1)


def _left_spines(s: Scenario, k: int, N: int) -> npt.NDArray[np.float64]:
    """Centre lines (A, 4) of the principal's parts at the layer's anchor (the goal at rest):
    the links' axes, and a diagonal of the tool if any.

    Only a hint where to look for a common point: every point is checked before it counts.
    """
    theta = s.left.goal if k >= N else tuple(left_angles(s, k * s.dt))
    t1, t2 = float(theta[0]), float(theta[1])
    base, elbow, tip = joints(s.left, (t1, t2))
    lines = [[*base, *elbow], [*elbow, *tip]]
    if s.left.tool is not None:
        lines.append(list(_tool_spine(s.left, np.array(t1), np.array(t1 + t2))))
    return np.array(lines, dtype=float)


def _right_spines(s: Scenario, g: Grid) -> tuple[npt.NDArray[np.float64], npt.NDArray[np.float64]]:
    """Centre lines of the subordinate's link 1 per row (m, 4) and of the per-cell parts per
    cell, part by part ((parts - 1) m n, 4): link 2's axis, the tool's diagonal."""
    arm = s.right
    t_i = np.asarray(g.angle(0, np.arange(g.m)), dtype=float)
    t_j = np.asarray(g.angle(1, np.arange(g.n)), dtype=float)
    base = np.broadcast_to(np.asarray(arm.base, dtype=float), (g.m, 2))
    elbow = base + arm.links[0] * np.stack([np.cos(t_i), np.sin(t_i)], -1)
    t12 = t_i[:, None] + t_j[None, :]
    tip = elbow[:, None, :] + arm.links[1] * np.stack([np.cos(t12), np.sin(t12)], -1)
    spine1 = np.concatenate([base, elbow], axis=1)
    spine2 = [np.concatenate([np.broadcast_to(elbow[:, None, :], tip.shape), tip],
                             axis=2).reshape(g.m * g.n, 4)]
    if arm.tool is not None:
        t1 = np.broadcast_to(t_i[:, None], t12.shape)
        spine2.append(_tool_spine(arm, t1, t12).reshape(g.m * g.n, 4))
    return np.ascontiguousarray(spine1), np.ascontiguousarray(np.concatenate(spine2))


def _settle_unsure(pair: tuple[npt.NDArray[np.float64], ...],
                   r1: npt.NDArray[np.float64], per_cell: list[npt.NDArray[np.float64]],
                   unc1: npt.NDArray[np.bool_], unc2: npt.NDArray[np.bool_],
                   out: npt.NDArray[np.uint8], eps: float) -> None:
    """Decide the pairs the kernel left open with the reference's routine, on the same arrays
    (PolygonSet.of: the reference's own normals for those polygons; each per-cell part's own
    array, as the reference has it, not the kernel's padded stack)."""
    m, n = out.shape
    for a, poly in enumerate(pair):
        rows = np.flatnonzero(unc1[a])
        if rows.size:
            out[rows[blocked_against(poly, PolygonSet.of(r1[rows]), eps)]] = 1
        for p, r2 in enumerate(per_cell):
            cells = np.flatnonzero(unc2[a, p * m * n:(p + 1) * m * n])
            cells = cells[out.reshape(-1)[cells] == 0]   # a cell already blocked stays blocked
            if cells.size:
                hit = cells[blocked_against(poly, PolygonSet.of(r2[cells]), eps)]
                out[hit // n, hit % n] = 1


# ---------------------------------------------------------------- compiled kernel (numba) ----
# Arrays are indexed in place, never sliced: a view costs reference counting in compiled code.

@njit(cache=True)
def _pack(verts):  # pragma: no cover - compiled; PolygonSet.of's formulas, per polygon
    """geo (C, V, 6) and box (C, 4) of CCW polygons (C, V, 2), see the module docstring.

    A polygon with a coordinate that is NaN, infinite or beyond MAX_COORD gets a NaN box: the
    kernel then leaves every pair with it to the reference."""
    C, V = verts.shape[0], verts.shape[1]
    geo = np.zeros((C, V, 6))
    box = np.empty((C, 4))
    for c in range(C):
        _pack_one(verts, c, geo, box)
    return geo, box


@njit(cache=True, parallel=True)
def _pack_all(verts):  # pragma: no cover - compiled; _pack over threads (each polygon alone)
    """_pack for many polygons, the polygons shared out among the threads."""
    C, V = verts.shape[0], verts.shape[1]
    geo = np.zeros((C, V, 6))
    box = np.empty((C, 4))
    for c in prange(C):
        _pack_one(verts, c, geo, box)
    return geo, box


@njit(cache=True, inline="always")
def _pack_one(verts, c, geo, box):  # pragma: no cover - compiled
    V = verts.shape[1]
    sane = True
    for v in range(V):
        if not (abs(verts[c, v, 0]) <= MAX_COORD and abs(verts[c, v, 1]) <= MAX_COORD):
            sane = False
    if not sane:
        for e in range(4):
            box[c, e] = np.nan
        return
    box[c, 0], box[c, 1] = verts[c, 0, 0], verts[c, 0, 1]
    box[c, 2], box[c, 3] = verts[c, 0, 0], verts[c, 0, 1]
    for v in range(V):
        x, y = verts[c, v, 0], verts[c, v, 1]
        w = v + 1 if v + 1 < V else 0
        ex, ey = verts[c, w, 0] - x, verts[c, w, 1] - y
        length = math.sqrt(ex * ex + ey * ey)  # hypot's care for overflow costs 3x here
        geo[c, v, 0], geo[c, v, 1] = x, y
        if length > 0:
            nx, ny = ey / length, -ex / length
            geo[c, v, 2], geo[c, v, 3] = nx, ny
            geo[c, v, 4] = nx * x + ny * y
            geo[c, v, 5] = 1.0
        box[c, 0], box[c, 1] = min(box[c, 0], x), min(box[c, 1], y)
        box[c, 2], box[c, 3] = max(box[c, 2], x), max(box[c, 3], y)


@njit(cache=True, parallel=True)
def _layer(rows, ga, boxa, spa, g1, box1, sp1, g2, box2, sp2, row_box, m, n, tested1, tested2,
           eps, margin, out, unc1, unc2):  # pragma: no cover - compiled; tested against build_dr
    """One layer: out[i*n + j] = 1 where certainly blocked; unc1/unc2 flag the unsure pairs.

    Rows are independent (each writes its own cells and flags), so the order ``rows`` deals them
    out in changes nothing but the threads' shares: prange gives each thread a contiguous block
    of it. parallel=True also for one thread: numba compiles the outlined loop body of a prange
    to code 1.7x faster than the same plain loop (measured here, numba 0.68).
    """
    for r in prange(rows.shape[0]):
        _row(rows[r], ga, boxa, spa, g1, box1, sp1, g2, box2, sp2, row_box, m, n, tested1,
             tested2, eps, margin, out, unc1, unc2)


@njit(cache=True)
def _row(i, ga, boxa, spa, g1, box1, sp1, g2, box2, sp2, row_box, m, n, tested1, tested2, eps,
         margin, out, unc1, unc2):  # pragma: no cover - compiled
    """Row i of one layer (see _layer). Only the pairs of parts whose heights overlap are
    tested: ``tested1[a]`` left part a against the right link 1, ``tested2[a, p]`` against the
    right per-cell part p (link 2, the tool), whose polygons are g2[p m n + c]."""
    for a in range(ga.shape[0]):
        if not tested1[a]:
            continue
        st, _, _ = _pair(ga, boxa, spa, a, g1, box1, sp1, i, eps, margin, 0, False, 0.0, 0.0)
        if st == BLOCKED or st == _BLOCKED_AT:
            for j in range(n):
                out[i * n + j] = 1
            return
        if st == UNSURE:
            unc1[a, i] = True
    for a in range(ga.shape[0]):
        for p in range(tested2.shape[1]):
            if not tested2[a, p]:
                continue
            if _box_gap(boxa, a, row_box, p * m + i) > eps:
                continue  # every cell's own box gap is at least the row's
            # Neighbours in j are alike: the axis that last separated, or the point that last
            # lay deep in both, is tried first.
            hint, have, px, py = 0, False, 0.0, 0.0
            for j in range(n):
                c = i * n + j
                if out[c] == 1:
                    continue
                b = p * m * n + c
                st, qx, qy = _pair(ga, boxa, spa, a, g2, box2, sp2, b, eps, margin, hint, have,
                                   px, py)
                if st == _BLOCKED_AT:
                    out[c] = 1
                    have, px, py = True, qx, qy
                elif st == BLOCKED:
                    out[c] = 1
                elif st == UNSURE:
                    unc2[a, b] = True
                elif st >= _SEPARATED:
                    hint = st - _SEPARATED


@njit(cache=True, forceinline=True)
def _box_gap(boxa, a, boxb, b):  # pragma: no cover - compiled
    """The reference's bounding-box gap, in its own float operations (so exactly equal); NaN
    when either box is NaN (a polygon left to the reference, see _pack)."""
    if boxa[a, 0] != boxa[a, 0] or boxb[b, 0] != boxb[b, 0]:
        return np.nan
    return max(max(boxb[b, 0] - boxa[a, 2], boxa[a, 0] - boxb[b, 2]),
               max(boxb[b, 1] - boxa[a, 3], boxa[a, 1] - boxb[b, 3]))


@njit(cache=True, forceinline=True)
def _separates(gp, p, gq, q, e, above):  # pragma: no cover - compiled
    """Whether every vertex of polygon p lies beyond edge line e of polygon q by > ``above``."""
    nx, ny, off = gq[q, e, 2], gq[q, e, 3], gq[q, e, 4]
    for v in range(gp.shape[1]):
        if not gp[p, v, 0] * nx + gp[p, v, 1] * ny - off > above:  # NaN: not separated
            return False
    return True


@njit(cache=True, forceinline=True)
def _overlaps(gp, p, gq, q, e, below):  # pragma: no cover - compiled
    """Whether some vertex of polygon p lies inside edge line e of polygon q by > ``below``."""
    nx, ny, off = gq[q, e, 2], gq[q, e, 3], gq[q, e, 4]
    for v in range(gp.shape[1]):
        if gp[p, v, 0] * nx + gp[p, v, 1] * ny - off < -below:
            return True
    return False


@njit(cache=True, forceinline=True)
def _deep(x, y, gq, q, d):  # pragma: no cover - compiled
    """Whether (x, y) lies inside every edge line of polygon q by more than d."""
    for e in range(gq.shape[1]):
        if gq[q, e, 5] != 0.0 and not gq[q, e, 2] * x + gq[q, e, 3] * y - gq[q, e, 4] < -d:
            return False  # NaN: not deep
    return True


@njit(cache=True, forceinline=True)
def _vertex_inside(gp, p, gq, q, d):  # pragma: no cover - compiled
    """The first vertex of polygon p lying inside polygon q by more than d, or -1."""
    for v in range(gp.shape[1]):
        if _deep(gp[p, v, 0], gp[p, v, 1], gq, q, d):
            return v
    return -1


@njit(cache=True, forceinline=True)
def _clip(x0, y0, dx, dy, gq, q, d, lo, hi):  # pragma: no cover - compiled
    """Narrow [lo, hi] to the t with p0 + t d inside every edge line of polygon q by >= d."""
    for e in range(gq.shape[1]):
        if gq[q, e, 5] == 0.0:
            continue
        nx, ny = gq[q, e, 2], gq[q, e, 3]
        num = gq[q, e, 4] - d - (nx * x0 + ny * y0)
        den = nx * dx + ny * dy
        if den > 0.0:
            hi = min(hi, num / den)
        elif den < 0.0:
            lo = max(lo, num / den)
        elif num < 0.0:
            return 1.0, 0.0
        if lo > hi:
            break
    return lo, hi


@njit(cache=True, forceinline=True)
def _common_point(sp, s, ga, a, gb, b, margin):  # pragma: no cover - compiled
    """(found, x, y): a point of segment s of sp certified deeper than margin in polygon a of ga
    and polygon b of gb. The clip aims at depth 2 margin; the verdict is the point's own check."""
    x0, y0 = sp[s, 0], sp[s, 1]
    dx, dy = sp[s, 2] - x0, sp[s, 3] - y0
    lo, hi = _clip(x0, y0, dx, dy, ga, a, 2 * margin, 0.0, 1.0)
    if lo > hi:
        return False, 0.0, 0.0
    lo, hi = _clip(x0, y0, dx, dy, gb, b, 2 * margin, lo, hi)
    if lo > hi:
        return False, 0.0, 0.0
    t = 0.5 * (lo + hi)
    x, y = x0 + t * dx, y0 + t * dy
    return _deep(x, y, ga, a, margin) and _deep(x, y, gb, b, margin), x, y


@njit(cache=True, forceinline=True)
def _pair(ga, boxa, spa, a, gb, boxb, spb, b, eps, margin, hint, have, px, py
          ):  # pragma: no cover - compiled
    """(code, x, y) for polygon a of A and polygon b of B: FREE or _SEPARATED + the axis found;
    _BLOCKED_AT with the common point (x, y) that proves it, or BLOCKED; or UNSURE.

    ``hint`` is an axis to try first; (px, py), if ``have``, a point known to lie in polygon a (a
    vertex of it, or deeper than margin), tried first for b. Axis e is an edge normal of A
    (e < V_A) or of B (e - V_A). Its gap is the min over the other polygon's vertices of
    (n.v - offset); rounding is monotone, so "every vertex's term > t" is exactly "gap > t", and
    the scans may stop early.
    """
    box_gap = _box_gap(boxa, a, boxb, b)
    if box_gap > eps:
        return FREE, 0.0, 0.0
    if box_gap != box_gap:
        return UNSURE, 0.0, 0.0               # a polygon _pack left to the reference
    if have and _deep(px, py, gb, b, margin):
        return _BLOCKED_AT, px, py
    free_at = eps + margin
    va, vb = ga.shape[1], gb.shape[1]
    for step in range(va + vb):                # a separating axis, the hinted one first
        e = hint + step
        if e >= va + vb:
            e -= va + vb
        if e < va:
            if ga[a, e, 5] != 0.0 and _separates(gb, b, ga, a, e, free_at):
                return _SEPARATED + e, 0.0, 0.0
        elif gb[b, e - va, 5] != 0.0 and _separates(ga, a, gb, b, e - va, free_at):
            return _SEPARATED + e, 0.0, 0.0
        if step == 0:
            # A point deep in both: each link's centre line usually crosses the other region.
            found, x, y = _common_point(spb, b, ga, a, gb, b, margin)
            if not found:
                found, x, y = _common_point(spa, a, ga, a, gb, b, margin)
            if found:
                return _BLOCKED_AT, x, y
            # A vertex of one inside the other: a vertex of A lies in A, one of B inside A is
            # deep in A, so either may serve the next cell as the common point.
            v = _vertex_inside(ga, a, gb, b, margin)
            if v >= 0:
                return _BLOCKED_AT, ga[a, v, 0], ga[a, v, 1]
            v = _vertex_inside(gb, b, ga, a, margin)
            if v >= 0:
                return _BLOCKED_AT, gb[b, v, 0], gb[b, v, 1]
    for e in range(va):                        # no axis separates: overlapping on every one?
        if ga[a, e, 5] != 0.0 and not _overlaps(gb, b, ga, a, e, margin):
            return UNSURE, 0.0, 0.0
    for f in range(vb):
        if gb[b, f, 5] != 0.0 and not _overlaps(ga, a, gb, b, f, margin):
            return UNSURE, 0.0, 0.0
    return BLOCKED, 0.0, 0.0
