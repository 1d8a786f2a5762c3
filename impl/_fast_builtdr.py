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
line, where a common point is looked for. The per-cell polygons' boxes and spines are made for
every cell first; a cell's geo when it first reaches the polygon test (most never do), by the
thread that owns its row.

Parts: a left polygon per part (link 1, link 2, the tool); the right link 1 per row, and the
per-cell parts (link 2, the tool) stacked; only pairs whose heights overlap are tested
(``spec.pairs_to_test``), as in the reference.

Structure used: the rest layer of original/modified is layer N-1 (copied); a row i whose right
link 1 is blocked (and tested) is blocked whole; a row whose union box is apart is free whole; a
cell already blocked by one left link is not tested again (the decision is an OR). The kernel
takes a row through every layer before the next (its polygons stay in the cache); rows are
shared out among Python threads running the nogil kernel, each thread owning its rows, so the
bits do not depend on the number of threads. docs/model.md §4.3.
"""

from __future__ import annotations

import math
import time

import numpy as np
import numpy.typing as npt
from numba import njit

from ..spec import EPS, Arm, Grid, Scenario, Variant, left_angles, make_grid, pairs_to_test
from ._builtdr import DR, LeftRegions, RightRegions
from ._collide import PolygonSet, blocked_against, pad_polygons
from ._fast_regions import left_regions_fast, right_regions_fast
from ._kernel_cache import ensure_compiled
from ._progress import progress_bar
from ._threads import shared

__all__ = ["MARGIN_REL", "MAX_COORD", "STAGES", "build_dr_fast", "build_from_regions",
           "decision_margin"]

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
    ensure_compiled()
    clock = _Clock(stages)
    g = grid or make_grid(s)
    rr = right or right_regions_fast(s, g)
    clock.lap("right_regions")
    left = left_regions_fast(s, variant, g)
    clock.lap("left_regions")
    return build_from_regions(s, g, rr, left, eps=eps, progress=progress, clock=clock)


#: Rows decided per kernel call (in every layer): about this many cells (the progress bar
#: advances per call).
CHUNK_CELLS = 2_000_000


def build_from_regions(s: Scenario, g: Grid, rr: RightRegions, left: LeftRegions, *,
                       eps: float = EPS, progress: bool | None = None,
                       clock: _Clock | None = None) -> DR:
    """build_dr_fast given both arms' regions (the reference's arrays or their compiled twins')."""
    clock = clock or _Clock(None)
    m, n = g.m, g.n
    r1 = np.ascontiguousarray(rr.link1)
    # The per-cell parts (link 2, the tool) stacked part by part, padded to one vertex count
    # (a repeated vertex: a zero-length edge, which no test uses): cell c of part p is polygon
    # p m n + c. The reference settles a pair on its own part's array (``per_cell``).
    per_cell = [np.ascontiguousarray(r.reshape(m * n, *r.shape[2:])) for r in rr.per_cell()]
    size = max(x.shape[1] for x in per_cell)
    r2 = (per_cell[0] if len(per_cell) == 1
          else np.concatenate([_pad_to(r, size) for r in per_cell]))
    parts2 = len(per_cell)
    spine1, lines = _right_spines(s, g, parts2)
    g1, box1 = _pack(r1)
    # Every cell's box and centre line now; a cell's geometry when it first reaches the polygon
    # test (most never do), in the kernel, by the thread that owns its row.
    box2 = np.empty((r2.shape[0], 4))
    spine2 = np.empty((r2.shape[0], 4))
    row_box = np.empty((parts2 * m, 4))
    row_scale = np.empty(parts2 * m)
    shared(_boxes, r2, n, box2, row_box, row_scale, *lines, spine2)
    g2 = np.empty((r2.shape[0], size, 6))
    packed = np.zeros(r2.shape[0], dtype=np.bool_)
    A = len(left.links[0])
    tested1 = np.zeros(A, dtype=np.bool_)
    tested2 = np.zeros((A, parts2), dtype=np.bool_)
    for a, b in pairs_to_test(s.left, s.right):
        if b == 0:
            tested1[a] = True
        else:
            tested2[a, b - 1] = True
    clock.lap("pack_right")
    # The layers to compute: the rest layer of original/modified is layer N-1 itself (copied).
    ks = [k for k, pair in enumerate(left.links) if k == 0 or pair is not left.links[k - 1]]
    ga, boxa = _pack(pad_polygons([p for k in ks for p in left.links[k]]))
    spa = _left_spines(s, ks, g.N)
    margin = decision_margin(box1, row_scale, boxa)
    P = np.zeros(g.shape, dtype=np.uint8)
    out = P.reshape(g.shape[0], m * n)
    layers = np.array(ks, dtype=np.int64)
    unc1 = np.zeros((len(ks), A, m), dtype=np.bool_)
    assert A * parts2 <= 8                              # unc2's bits: at most 3 x 2 parts
    unc2 = np.zeros((len(ks), m * n), dtype=np.uint8)   # bit a * parts2 + p
    rowu = np.zeros((len(ks), m), dtype=np.bool_)
    chunk = max(1, CHUNK_CELLS // (n * len(ks)))
    clock.lap("pack_left")
    with progress_bar(f"BuiltDR {left.variant}", m, int(np.prod(g.shape)), progress) as bar:
        for i0 in range(0, m, chunk):
            i1 = min(m, i0 + chunk)
            shared(_layers, i0, i1, layers, out, ga, boxa, spa, A, g1, box1, spine1, r2, g2,
                   box2, spine2, packed, row_box, m, n, tested1, tested2, eps, margin, unc1,
                   unc2, rowu)
            bar.advance(i1 - i0)
        clock.lap("layer_kernel")
        for c, k in enumerate(ks):
            if unc1[c].any() or rowu[c].any():
                clock.count("unsure_pairs", _settle_unsure(
                    left.links[k], r1, per_cell, unc1[c], unc2[c], rowu[c], out[k].reshape(m, n),
                    eps))
        clock.lap("settle_unsure")
    for k in range(1, len(left.links)):
        if left.links[k] is left.links[k - 1]:
            P[k] = P[k - 1]                       # the rest layer is layer N-1 itself
    clock.lap("other")
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


def _left_spines(s: Scenario, ks: list[int], N: int) -> npt.NDArray[np.float64]:
    """Centre lines (len(ks) A, 4) of the principal's parts at each layer's anchor (the goal
    at rest), layer by layer: the links' axes, and a diagonal of the tool if any.

    Only a hint where to look for a common point: every point is checked before it counts.
    """
    arm = s.left
    at = np.asarray(ks)
    theta = left_angles(s, np.minimum(at, N) * s.dt)
    theta[at >= N] = np.asarray(arm.goal, dtype=float)
    t1, t12 = theta[:, 0], theta[:, 0] + theta[:, 1]
    base = np.broadcast_to(np.asarray(arm.base, dtype=float), (len(ks), 2))
    elbow = base + arm.links[0] * np.stack([np.cos(t1), np.sin(t1)], -1)
    tip = elbow + arm.links[1] * np.stack([np.cos(t12), np.sin(t12)], -1)
    lines = [np.concatenate([base, elbow], -1), np.concatenate([elbow, tip], -1)]
    if arm.tool is not None:
        lines.append(_tool_spine(arm, t1, t12))
    return np.ascontiguousarray(np.stack(lines, axis=1).reshape(-1, 4))


def _right_spines(s: Scenario, g: Grid, parts2: int
                  ) -> tuple[npt.NDArray[np.float64], tuple[npt.NDArray[np.float64], ...]]:
    """The centre lines of the subordinate's link 1 per row (m, 4), and what _boxes draws the
    per-cell parts' lines from (elbow per row (m, 2), t_i, t_j, and each part's two ends in the
    forearm's frame with the elbow as origin (parts2, 2, 2): link 2's axis, the tool's diagonal
    from its vertex 0 to vertex V // 2, inside the convex polygon)."""
    arm = s.right
    t_i = np.asarray(g.angle(0, np.arange(g.m)), dtype=float)
    t_j = np.asarray(g.angle(1, np.arange(g.n)), dtype=float)
    base = np.broadcast_to(np.asarray(arm.base, dtype=float), (g.m, 2))
    elbow = np.ascontiguousarray(base + arm.links[0] * np.stack([np.cos(t_i), np.sin(t_i)], -1))
    l2 = float(arm.links[1])
    ends = [[(0.0, 0.0), (l2, 0.0)]]
    if arm.tool is not None:
        poly = arm.tool.polygon
        ends.append([(l2 + poly[0][0], poly[0][1]),
                     (l2 + poly[len(poly) // 2][0], poly[len(poly) // 2][1])])
    assert len(ends) == parts2
    spine1 = np.ascontiguousarray(np.concatenate([base, elbow], axis=1))
    return spine1, (elbow, t_i, t_j, np.array(ends, dtype=float))


def _settle_unsure(pair: tuple[npt.NDArray[np.float64], ...],
                   r1: npt.NDArray[np.float64], per_cell: list[npt.NDArray[np.float64]],
                   unc1: npt.NDArray[np.bool_], unc2: npt.NDArray[np.uint8],
                   rowu: npt.NDArray[np.bool_], out: npt.NDArray[np.uint8], eps: float) -> int:
    """Decide the pairs the kernel left open in one layer with the reference's routine, on the
    same arrays (PolygonSet.of: the reference's own normals for those polygons; each per-cell
    part's own array, as the reference has it, not the kernel's padded stack). ``unc1[a, i]``:
    left part a against row i's link 1; bit a * parts + p of ``unc2[c]``: left part a against
    part p of cell c, in the rows ``rowu`` flags. Returns the number of pairs settled."""
    m, n = out.shape
    flat = out.reshape(-1)
    rows = np.flatnonzero(rowu)
    cells_open = (rows[:, None] * n + np.arange(n)[None, :]).reshape(-1)
    bits = unc2[cells_open]
    settled = 0
    for a, poly in enumerate(pair):
        hit_rows = np.flatnonzero(unc1[a])
        settled += hit_rows.size
        if hit_rows.size:
            out[hit_rows[blocked_against(poly, PolygonSet.of(r1[hit_rows]), eps)]] = 1
        for p, r2 in enumerate(per_cell):
            cells = cells_open[((bits >> (a * len(per_cell) + p)) & 1) == 1]
            settled += cells.size
            cells = cells[flat[cells] == 0]   # a cell already blocked stays blocked
            if cells.size:
                flat[cells[blocked_against(poly, PolygonSet.of(r2[cells]), eps)]] = 1
    return settled


# ---------------------------------------------------------------- compiled kernel (numba) ----
# Arrays are indexed in place, never sliced: a view costs reference counting in compiled code.

def _pack(verts: npt.NDArray[np.float64]
          ) -> tuple[npt.NDArray[np.float64], npt.NDArray[np.float64]]:
    """geo (C, V, 6) and box (C, 4) of CCW polygons (C, V, 2), see the module docstring.

    A polygon with a coordinate that is NaN, infinite or beyond MAX_COORD gets a NaN box: the
    kernel then leaves every pair with it to the reference. The arrays are made here, not in
    the kernel: a kernel that allocates makes numba's cache load import numba's array
    implementation (0.04 s CPU of `cfmpa dr`'s start-up, docs/model.md §7.5)."""
    C, V = verts.shape[0], verts.shape[1]
    geo = np.zeros((C, V, 6))
    box = np.empty((C, 4))
    _pack_into(verts, geo, box)
    return geo, box


@njit(cache=True)
def _pack_into(verts, geo, box):  # pragma: no cover - compiled; PolygonSet.of's formulas
    """_pack's geo and box, per polygon, into the zeroed geo and the box given."""
    for c in range(verts.shape[0]):
        _box_one(verts, c, box)
        if box[c, 0] == box[c, 0]:
            _geo_one(verts, c, geo)


@njit(cache=True, nogil=True)
def _boxes(t, K, verts, n, box, row_box, row_scale, elbow, t_i, t_j, ends, spine
           ):  # pragma: no cover - compiled
    """Thread t of K: for its rows of n polygons (r = t, t + K, ...; part r // m, row r % m),
    each polygon's box, the row's union box (NaN if a box is) and largest |coordinate| (0.0 if
    none), and each cell's centre line: the part's two ends (``ends``, forearm frame, elbow at
    the origin) at the cell's configuration (only a hint, see _left_spines)."""
    m = elbow.shape[0]
    for r in range(t, verts.shape[0] // n, K):
        p, i = r // m, r % m
        lo_x, lo_y, hi_x, hi_y = np.inf, np.inf, -np.inf, -np.inf
        scale, sane = 0.0, True
        for c in range(r * n, (r + 1) * n):
            t12 = t_i[i] + t_j[c - r * n]
            ca, sa = math.cos(t12), math.sin(t12)
            for e in range(2):
                x, y = ends[p, e, 0], ends[p, e, 1]
                spine[c, 2 * e] = elbow[i, 0] + x * ca - y * sa
                spine[c, 2 * e + 1] = elbow[i, 1] + x * sa + y * ca
            _box_one(verts, c, box)
            if box[c, 0] != box[c, 0]:
                sane = False
                continue
            lo_x, lo_y = min(lo_x, box[c, 0]), min(lo_y, box[c, 1])
            hi_x, hi_y = max(hi_x, box[c, 2]), max(hi_y, box[c, 3])
            for e in range(4):
                scale = max(scale, abs(box[c, e]))
        if sane:
            row_box[r, 0], row_box[r, 1], row_box[r, 2], row_box[r, 3] = lo_x, lo_y, hi_x, hi_y
        else:
            for e in range(4):
                row_box[r, e] = np.nan
        row_scale[r] = scale


@njit(cache=True, inline="always")
def _box_one(verts, c, box):  # pragma: no cover - compiled
    V = verts.shape[1]
    for v in range(V):
        if not (abs(verts[c, v, 0]) <= MAX_COORD and abs(verts[c, v, 1]) <= MAX_COORD):
            for e in range(4):
                box[c, e] = np.nan
            return
    box[c, 0], box[c, 1] = verts[c, 0, 0], verts[c, 0, 1]
    box[c, 2], box[c, 3] = verts[c, 0, 0], verts[c, 0, 1]
    for v in range(V):
        x, y = verts[c, v, 0], verts[c, v, 1]
        box[c, 0], box[c, 1] = min(box[c, 0], x), min(box[c, 1], y)
        box[c, 2], box[c, 3] = max(box[c, 2], x), max(box[c, 3], y)


@njit(cache=True, inline="always")
def _geo_one(verts, c, geo):  # pragma: no cover - compiled
    V = verts.shape[1]
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
        else:
            geo[c, v, 2], geo[c, v, 3], geo[c, v, 4], geo[c, v, 5] = 0.0, 0.0, 0.0, 0.0


@njit(cache=True, nogil=True)
def _layers(t, K, i0, i1, layers, out, ga, boxa, spa, A, g1, box1, sp1, r2, g2, box2, sp2,
            packed, row_box, m, n, tested1, tested2, eps, margin, unc1, unc2, rowu
            ):  # pragma: no cover - compiled; tested against build_dr
    """Thread t of K: rows i = i0 + t, i0 + t + K, ... below i1, each in every computed layer c
    (layer layers[c], left polygons c A .. c A + A - 1 of ga): out[k, i n + j] = 1 where
    certainly blocked; unc1/unc2/rowu flag the unsure pairs (see _settle_unsure).

    Rows are independent (each writes its own cells, flags and packed cells), so the threads
    share nothing they write. A row in every layer before the next row: its m-th of the right
    polygons stays in the cache across the layers. Alternate rows: neighbouring rows cost alike
    (contiguous halves did not balance)."""
    for i in range(i0 + t, i1, K):
        for c in range(layers.shape[0]):
            _row(c, layers[c], i, A, ga, boxa, spa, g1, box1, sp1, r2, g2, box2, sp2, packed,
                 row_box, m, n, tested1, tested2, eps, margin, out, unc1, unc2, rowu)


@njit(cache=True)
def _row(c, k, i, A, ga, boxa, spa, g1, box1, sp1, r2, g2, box2, sp2, packed, row_box, m, n,
         tested1, tested2, eps, margin, out, unc1, unc2, rowu):  # pragma: no cover - compiled
    """Row i of layer k (computed layer c, whose flags these are). Only the pairs of parts whose
    heights overlap are tested: ``tested1[a]`` left part a against the right link 1,
    ``tested2[a, p]`` against the right per-cell part p (link 2, the tool), whose polygons are
    g2[p m n + cell], packed here on first use."""
    P2 = tested2.shape[1]
    none = i < 0            # False, and 0 below, as values: one compiled _pair for both calls
    zero = i - i
    for a in range(A):
        if not tested1[a]:
            continue
        st, _, _ = _pair(ga, boxa, spa, c * A + a, g1, box1, sp1, i, eps, margin, zero, none,
                         0.0, 0.0)
        if st == BLOCKED or st == _BLOCKED_AT:
            for j in range(n):
                out[k, i * n + j] = 1
            return
        if st == UNSURE:
            unc1[c, a, i] = True
    for a in range(A):
        ca = c * A + a
        for p in range(P2):
            if not tested2[a, p]:
                continue
            if _box_gap(boxa, ca, row_box, p * m + i) > eps:
                continue  # every cell's own box gap is at least the row's
            # Neighbours in j are alike: the axis that last separated, or the point that last
            # lay deep in both, is tried first.
            hint, have, px, py = zero, none, 0.0, 0.0
            for j in range(n):
                cell = i * n + j
                if out[k, cell] == 1:
                    continue
                b = p * m * n + cell
                if _box_gap(boxa, ca, box2, b) > eps:
                    continue  # free (_pair's first test)
                if not packed[b]:
                    _geo_one(r2, b, g2)
                    packed[b] = True
                st, qx, qy = _pair(ga, boxa, spa, ca, g2, box2, sp2, b, eps, margin, hint, have,
                                   px, py)
                if st == _BLOCKED_AT:
                    out[k, cell] = 1
                    have, px, py = True, qx, qy
                elif st == BLOCKED:
                    out[k, cell] = 1
                elif st == UNSURE:
                    unc2[c, cell] |= np.uint8(1 << (a * P2 + p))
                    rowu[c, i] = True
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
    # The previous cell was blocked (``have``): look for a common point after the hinted axis;
    # else after every axis. Either order finds the same proofs; only the work differs.
    search_at = 0 if have else va + vb - 1
    for step in range(va + vb):                # a separating axis, the hinted one first
        e = hint + step
        if e >= va + vb:
            e -= va + vb
        if e < va:
            if ga[a, e, 5] != 0.0 and _separates(gb, b, ga, a, e, free_at):
                return _SEPARATED + e, 0.0, 0.0
        elif gb[b, e - va, 5] != 0.0 and _separates(ga, a, gb, b, e - va, free_at):
            return _SEPARATED + e, 0.0, 0.0
        if step == search_at:
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
