"""Theorem 1 / Theorem 3's postcondition, decided cell by cell with the spec's own geometry.

For all k <= N, i < m, j < n: P[k, i, j] = (dist(S_LArm[k], S_RArm[i][j]) > eps -> 0 | 1). The
regions come from ``_regions`` and distances from shapely (GEOS), sharing no code with impl/.
Two float computations of the same polygons can differ by rounding, so a cell whose spec
distance lies within ``band`` of eps is counted as indeterminate and accepted either way.

``expected_cells`` is the definition, cell by cell (the sampled contracts use it);
``full_verdicts`` decides every cell the same way, vectorised with rigorous bounds on the same
regions, leaving to ``expected_cells`` the cells no bound decides (tests check the two agree).
"""

from __future__ import annotations

from collections.abc import Callable, Iterator, Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np
import numpy.typing as npt
import shapely

from ._grid import EPS, Grid, Variant
from ._kinematics import TOOL, pairs_to_test, part_points, parts
from ._layers import take_cells
from ._regions import left_region_polygons, margin, right_region_polygons
from ._scenario import Scenario

__all__ = ["BAND", "BLOCK_CELLS", "SLACK", "CellMismatch", "PostReport", "dr_postcondition",
           "expected_cells", "full_verdicts"]

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
    """The spec's distance between S_LArm[k] and S_RArm[i][j] for each (k, i, j) given: the
    least over the pairs of parts whose heights overlap (``pairs_to_test``; inf if none)."""
    layers = np.asarray(layers)
    i = np.asarray(i)
    j = np.asarray(j)
    left = left_region_polygons(s, variant, grid)
    right = right_region_polygons(s, grid, i, j)
    dist = np.full(layers.shape, np.inf)
    for k in np.unique(layers):
        sel = layers == k
        for a, b in pairs_to_test(s.left, s.right):
            dist[sel] = np.minimum(dist[sel], shapely.distance(left[int(k)][a], right[b][sel]))
    return dist


def dr_postcondition(s: Scenario, variant: Variant | str, grid: Grid, dr: npt.NDArray[np.uint8],
                     *, cells: npt.NDArray[np.int64] | None = None, eps: float = EPS,
                     band: float = BAND, limit: int = 20) -> PostReport:
    """Check dr against the triple at ``cells`` ((C, 3) array of k, i, j), or at every cell.

    At given cells the distances are ``expected_cells``'s (the definition); at every cell the
    verdicts are ``full_verdicts``'s, the same decisions vectorised. Returns at most ``limit``
    mismatches, each with the definition's distance (the count of checked cells is exact).
    """
    if cells is None:
        return _all_cells(s, variant, grid, dr, eps, band, limit)
    k, i, j = cells[:, 0], cells[:, 1], cells[:, 2]
    dist = expected_cells(s, variant, grid, k, i, j)
    expected = (dist <= eps).astype(np.int8)
    near = np.abs(dist - eps) <= band
    got = take_cells(dr, k, i, j).astype(np.int8)
    bad = np.flatnonzero((got != expected) & ~near)
    shown = bad[:limit]
    return _report(s, variant, grid, len(bad) == 0, len(k), int(((got != expected) & near).sum()),
                   (k[shown], i[shown], j[shown]), got[shown], expected[shown])


def _all_cells(s: Scenario, variant: Variant | str, grid: Grid, dr: npt.NDArray[np.uint8],
               eps: float, band: float, limit: int) -> PostReport:
    """dr_postcondition at every cell, a block of rows of a layer at a time: the bounds'
    verdicts there (``_block_bounds``) against dr[k, i0:i1], so that no D_R-sized temporary is
    made, nor one the size of a layer's link-2 regions. The cells no
    bound decides are gathered and decided by the definition at the end, in one call, as
    ``full_verdicts`` does; the mismatches shown are the first ``limit`` in (k, i, j) order,
    the same as over the whole array."""
    N, m, n = grid.N, grid.m, grid.n
    bad_count = 0
    shown: list[tuple[int, int]] = []       # (flat index, expected): the first bad cells
    open_k, open_c = [], []
    for k, i0, i1, meets, undecided in _block_bounds(s, variant, grid, eps, band):
        got = np.asarray(dr[k, i0:i1]).reshape(-1).astype(np.int8)
        wrong = np.flatnonzero((got != meets) & ~undecided)
        bad_count += wrong.size
        c = wrong[:limit]                    # the least `limit` of this block and layer
        shown.extend(zip((k * m * n + i0 * n + c).tolist(), meets[c].astype(int).tolist()))
        if len(shown) > 4 * limit:
            shown = sorted(shown)[:limit]
        c = np.flatnonzero(undecided)
        open_k.append(np.full(c.size, k, dtype=np.int64))
        open_c.append(i0 * n + c)
    kk, cc = np.concatenate(open_k), np.concatenate(open_c)
    indeterminate = 0
    if kk.size:
        dist = expected_cells(s, variant, grid, kk, cc // n, cc % n)
        want = (dist <= eps).astype(np.int8)
        near = np.abs(dist - eps) <= band
        got = take_cells(dr, kk, cc // n, cc % n).astype(np.int8)
        wrong = (got != want) & ~near
        bad_count += int(wrong.sum())
        indeterminate = int(((got != want) & near).sum())
        shown.extend(zip((kk * m * n + cc)[wrong].tolist(), want[wrong].astype(int).tolist()))
    shown = sorted(shown)[:limit]
    flat = np.asarray([f for f, _ in shown], dtype=np.int64)
    at = np.unravel_index(flat, (N + 1, m, n))
    got = take_cells(dr, *at).astype(np.int8)
    expected = np.asarray([e for _, e in shown], dtype=np.int8)
    return _report(s, variant, grid, bad_count == 0, (N + 1) * m * n, indeterminate, at, got,
                   expected)


def _report(s: Scenario, variant: Variant | str, grid: Grid, ok: bool, checked: int,
            indeterminate: int, at: tuple[npt.NDArray[np.int64], ...],
            got: npt.NDArray[np.int8], expected: npt.NDArray[np.int8]) -> PostReport:
    """The report, its mismatches at the cells ``at`` (k, i, j) with the definition's distance."""
    # (No cell shown, no regions made: the definition builds every layer's left regions.)
    dist_shown = expected_cells(s, variant, grid, *at) if len(got) else np.zeros(0)
    mismatches = tuple(
        CellMismatch(layer=int(kk), cell=(int(ii), int(jj)),
                     angles=grid.angles((int(ii), int(jj))), got=int(g), expected=int(e),
                     distance_m=float(d))
        for kk, ii, jj, g, e, d in zip(*at, got, expected, dist_shown))
    return PostReport(ok=ok, checked=checked, indeterminate=indeterminate,
                      mismatches=mismatches)


# --- every cell, vectorised ------------------------------------------------------------------
#
# A cell's distance is the least over four pairs: a left region (link 1 or 2 of layer k) and a
# right region (link 1, which depends on the row i alone, or link 2). Link 1's pairs are few
# (2 (N + 1) m) and get the definition's shapely distance where their boxes are close. Link 2's
# (2 (N + 1) m n) are decided by bounds that are rigorous for convex sets, in numpy over whole
# layers:
#   1. bounding boxes: a gap above the limit below means free;
#   2. the axis of link 2's rectangle at the cell's own angles (inside its region) crossing the
#      left region (clipped by its edges' half-planes), or a corner of the left region inside
#      that rectangle, means they meet: blocked;
#   3. the gap of the two projections on link 2's direction or its normal: free above the limit;
#   4. the separating-axis test on the edges of both convex polygons (one-sided: the other
#      polygon beyond an edge's line): no separating edge means they meet (blocked), a gap
#      above the limit means free (a gap on any unit axis is at most the distance).
# ``decide`` runs them in the order 1 (rows' boxes, then cells'), 3, 2 at the cells 3 leaves
# open, 4 where the hull's extents along link 2's axes leave it open: each skips only cells
# the next would decide as it does (docs/model.md §7.5, tests/spec/test_check_shortcuts.py).
# A free verdict needs every gap above eps + band + SLACK, SLACK covering the rounding of two
# float computations of one polygon; a cell no bound decides (a distance within about eps of
# eps: none on the bundled scenarios) is decided by ``expected_cells`` itself. The right link-2
# region of a cell is the hull of its 36 lattice corners; its hull corners are found on the
# first row, and every other row is that row turned about the base by t_i - t_0 (changing t1
# moves link 2 rigidly), rounding far inside SLACK.

#: Metres a bound may be off by float rounding (of order 1e-16 m here); far below BAND.
SLACK = 1e-12


def full_verdicts(s: Scenario, variant: Variant | str, grid: Grid, *, eps: float = EPS,
                  band: float = BAND) -> tuple[npt.NDArray[np.int8], npt.NDArray[np.bool_]]:
    """For every cell (N + 1, m, n): the expected D_R value (dist <= eps -> 1 | 0) and whether it
    is indeterminate (|dist - eps| <= band), as ``expected_cells`` decides them."""
    N, m, n = grid.N, grid.m, grid.n
    expected = np.zeros((N + 1, m * n), dtype=np.int8)
    undecided = np.zeros((N + 1, m * n), dtype=bool)
    for k, i0, i1, meets, unsure in _block_bounds(s, variant, grid, eps, band):
        expected[k, i0 * n:i1 * n] = meets
        undecided[k, i0 * n:i1 * n] = unsure
    near = np.zeros((N + 1, m * n), dtype=bool)
    kk, cc = np.nonzero(undecided)
    if kk.size:
        dist = expected_cells(s, variant, grid, kk, cc // n, cc % n)
        expected[kk, cc] = dist <= eps
        near[kk, cc] = np.abs(dist - eps) <= band
    return expected.reshape(N + 1, m, n), near.reshape(N + 1, m, n)


#: Cells (whole rows of n, at least one row) whose link-2 regions are prepared at once
#: (``_Link2``: its hull corners, edge normals and offsets, float64, about 2 KB a cell with the
#: bounds' temporaries): the full check's memory is that block's, not the grid's (about 70 MB
#: at 2**15 cells, measured on the default workcell at dt = 0.01, against 480 MB for the whole
#: grid at once, with no loss of speed there).
BLOCK_CELLS = 1 << 15


def _block_bounds(s: Scenario, variant: Variant | str, grid: Grid, eps: float, band: float
                  ) -> Iterator[tuple[int, int, int, npt.NDArray[np.bool_],
                                      npt.NDArray[np.bool_]]]:
    """(k, i0, i1, blocked by the bounds, left undecided by them), each ((i1 - i0) n,), for
    every layer k and block of rows i0:i1 (blocks outer, layers inner); a cell undecided is not
    blocked. The decisions of ``full_verdicts``, cell by cell the same (every bound is computed
    per cell), on one block of rows at a time."""
    m, n = grid.m, grid.n
    left = left_region_polygons(s, variant, grid)
    rows = np.arange(m)
    r1 = right_region_polygons(s, grid, rows, np.zeros_like(rows))[0]
    b1 = shapely.bounds(r1)
    free_at = eps + band + SLACK
    pairs = pairs_to_test(s.left, s.right)
    link1 = []                          # per layer: link 1's distance per row (m,)
    for links in left:
        d1 = np.full(m, np.inf)        # inf: more than free_at (the boxes' gap shows it)
        for a in (links[p] for p, q in pairs if q == 0):
            close = np.flatnonzero(_box_gap(shapely.bounds(a), b1.T) <= free_at)
            d1[close] = np.minimum(d1[close], shapely.distance(a, r1[close]))   # exact
        link1.append(d1)
    # The link-2 and tool pairs, the principal's outer parts first: the cells they block are
    # skipped for the others (``decide``'s skip; a cell's verdict is the same in any order:
    # blocked by any pair, undecided by one and blocked by none).
    link2_pairs = sorted(((p, q) for p, q in pairs if q != 0), key=lambda pq: -pq[0])
    step = max(1, BLOCK_CELLS // n)
    row0 = {q: _row0(s, grid, q) for q in parts(s.right) if q > 0}     # once, not per block
    left_edges: dict[int, _LeftEdges] = {}     # each left region's corners and edges, once
    for i0 in range(0, m, step):
        i1 = min(m, i0 + step)
        per_cell = {q: _Link2(s, grid, i0, i1, part=q, row0=row0[q], left=left_edges)
                    for q in row0}
        for k, links in enumerate(left):
            d1 = link1[k][i0:i1]
            meets = np.repeat(d1 <= eps - band, n)
            unsure = np.repeat(np.abs(d1 - eps) <= band, n)
            for p, q in link2_pairs:
                hit, open_ = per_cell[q].decide(links[p], free_at, meets)
                meets |= hit
                unsure |= open_
            yield k, i0, i1, meets, unsure & ~meets


def _box_gap(a: Sequence[Any] | npt.NDArray[np.float64],
             b: Sequence[npt.NDArray[np.float64]] | npt.NDArray[np.float64]
             ) -> npt.NDArray[np.float64]:
    """The larger per-axis gap between box a (xmin, ymin, xmax, ymax) and boxes b (their xmin,
    ymin, xmax, ymax, (K,) each): at most the distance between anything inside them."""
    bx0, by0, bx1, by1 = b
    return np.maximum(np.maximum(a[0] - bx1, bx0 - a[2]), np.maximum(a[1] - by1, by0 - a[3]))


class _Link2:
    """The right link-2 (or tool) regions of every cell, prepared for the bounds: boxes, the
    axis of the rectangle at the cell's own angles (link 2 only), the extents along the
    forearm's direction and its normal, the hull (counter-clockwise) and its edges. Arrays hold
    cells last, (corners, cells), so that the bounds reduce over the first axis."""

    def __init__(self, s: Scenario, grid: Grid, i0: int = 0, i1: int | None = None, *,
                 part: int = 1, row0: _Row0 | None = None,
                 left: dict[int, _LeftEdges] | None = None) -> None:
        """Rows i0:i1 (all by default) of part ``part`` (1 link 2, TOOL the tool); cells are
        numbered (i - i0) n + j. ``row0``: ``_row0(s, grid, part)`` if already computed (the
        blocks of one check share it); ``left``: where ``decide`` keeps the left regions'
        corners and edges (``_left_edges``) for the blocks of one check."""
        self.left = {} if left is None else left
        n, h = grid.n, grid.h
        i1 = grid.m if i1 is None else i1
        m = i1 - i0
        ti = grid.lo[0] + np.arange(grid.m) * h[0]
        tj = grid.lo[1] + np.arange(n) * h[1]
        grow, pts, order, self.flat = _row0(s, grid, part) if row0 is None else row0
        hull = np.take_along_axis(pts, order[:, :, None], axis=1)       # (n, L, 2)
        # Row i is row 0 turned about the base by t_i - t_0, and so are its hull corners, axis
        # and edge normals.
        turn = ti[i0:i1] - ti[0]
        cos, sin = np.cos(turn)[None, :, None], np.sin(turn)[None, :, None]   # (1, m, 1)
        bx, by = s.right.base

        def rotate(x: npt.NDArray[np.float64], y: npt.NDArray[np.float64], about: bool
                   ) -> tuple[npt.NDArray[np.float64], npt.NDArray[np.float64]]:
            """Points (about the base) or directions (not), (K, n), of row 0 -> (K, m n)."""
            ox, oy = (bx, by) if about else (0.0, 0.0)
            x, y = (x - ox)[:, None, :], (y - oy)[:, None, :]
            k = x.shape[0]
            return ((ox + cos * x - sin * y).reshape(k, m * n),
                    (oy + sin * x + cos * y).reshape(k, m * n))

        self.hx, self.hy = rotate(hull[..., 0].T, hull[..., 1].T, True)       # (L, cells)
        nx0, ny0, _ = _edges(hull[..., 0].T, hull[..., 1].T)
        self.nx, self.ny = rotate(nx0, ny0, False)
        self.offset = self.nx * self.hx + self.ny * self.hy
        self.box = (self.hx.min(axis=0), self.hy.min(axis=0), self.hx.max(axis=0),
                    self.hy.max(axis=0))
        # Each row's box, around its cells' boxes: a gap to it is at most the gap to any of them.
        self.n = n
        self.row_box = tuple(f(b.reshape(m, n), axis=1) for f, b in
                             zip((np.min, np.min, np.max, np.max), self.box))
        # The rectangle at the cell's own angles (lattice point 4 of 9) lies in the region; its
        # axis runs between the midpoints of its short sides. A tool has no such core (bound 2
        # is left out for it); its projections use the forearm's axis at the cell's angles.
        if part == TOOL:
            phi = ti[0] + tj
            ends = np.stack([np.broadcast_to(np.array([bx, by]), (n, 2)),
                             np.stack([bx + np.cos(phi), by + np.sin(phi)], -1)])   # (2, n, 2)
        else:
            ends = np.stack([(pts[:, 16] + pts[:, 19]) / 2, (pts[:, 17] + pts[:, 18]) / 2])
        ex, ey = rotate(ends[..., 0], ends[..., 1], True)                    # (2, cells)
        self.q0, self.d = (ex[0], ey[0]), (ex[1] - ex[0], ey[1] - ey[0])
        length = np.hypot(*self.d)
        self.u = (self.d[0] / length, self.d[1] / length)
        self.v = (-self.u[1], self.u[0])
        pu = self.hx * self.u[0] + self.hy * self.u[1]
        pv = self.hx * self.v[0] + self.hy * self.v[1]
        self.ext = (pu.min(axis=0), pu.max(axis=0), pv.min(axis=0), pv.max(axis=0))
        # The rectangle itself in its frame: u from q0 to q1, v within +-(half its width).
        self.core = (ex[0] * self.u[0] + ey[0] * self.u[1], ex[1] * self.u[0] + ey[1] * self.u[1],
                     ex[0] * self.v[0] + ey[0] * self.v[1], s.right.width / 2 + grow)
        self.has_core = part != TOOL

    def decide(self, a: shapely.Geometry, free_at: float, skip: npt.NDArray[np.bool_]
               ) -> tuple[npt.NDArray[np.bool_], npt.NDArray[np.bool_]]:
        """(meets, undecided) per cell for the left region ``a``: meets where the two regions
        certainly meet, undecided where no bound shows a gap above ``free_at`` either; cells
        in ``skip`` (already known to be blocked) are left out."""
        C = skip.shape[0]
        meets = np.zeros(C, dtype=bool)
        undecided = np.zeros(C, dtype=bool)
        if self.flat or shapely.get_type_id(a) != 3:
            # A region that is not a polygon (of zero width: not with links of width > 0) is
            # left to the definition, cell by cell.
            return meets, ~skip
        held = self.left.get(id(a))
        if held is None or held[0] is not a:
            held = self.left[id(a)] = _left_edges(a)
        _, ax, ay, (anx, any_, aoff) = held                               # (V, 1) each
        # 1. boxes: first the rows' (``row_box``), then the cells' of the rows from the first
        # to the last row within reach (a cell of a row apart is apart: its gap is at least
        # the row's).
        rows = np.flatnonzero(_box_gap_of(ax, ay, self.row_box) <= free_at)
        if rows.size == 0:
            return meets, undecided
        lo, hi = int(rows[0]) * self.n, (int(rows[-1]) + 1) * self.n
        gap = _box_gap_of(ax, ay, tuple(b[lo:hi] for b in self.box))
        c = lo + np.flatnonzero((gap <= free_at) & ~skip[lo:hi])
        if c.size == 0:
            return meets, undecided
        # 3. A's corners on the axis and its normal: a corner inside the rectangle at the
        # cell's angles means they meet; a gap of the projections above the limit, free.
        pu = ax * self.u[0][c] + ay * self.u[1][c]                       # (V, S)
        pv = ax * self.v[0][c] + ay * self.v[1][c]
        u0, u1, v0, half = self.core[0][c], self.core[1][c], self.core[2][c], self.core[3]
        inside = ((pu >= u0) & (pu <= u1) & (np.abs(pv - v0) <= half)).any(axis=0)
        hit = inside if self.has_core else np.zeros(c.size, dtype=bool)
        e = [x[c] for x in self.ext]
        gap = np.maximum(np.maximum(e[0] - pu.max(axis=0), pu.min(axis=0) - e[1]),
                         np.maximum(e[2] - pv.max(axis=0), pv.min(axis=0) - e[3]))
        if self.has_core:
            # 2. the axis crossing A, at the cells 3 leaves open (regions that meet have no
            # gap above the limit of 3 on any axis: a cell 3 frees is not one it would block).
            at = np.flatnonzero(~hit & (gap <= free_at))
            hit[at] = _crosses(self.q0[0][c[at]], self.q0[1][c[at]], self.d[0][c[at]],
                               self.d[1][c[at]], anx, any_, aoff)
        meets[c[hit]] = True
        c = c[~hit & (gap <= free_at)]
        if c.size == 0:
            return meets, undecided
        # 4. separating axes, one-sided: every corner of one polygon beyond an edge's line of
        # the other. Edges of A against the hull's corners, then the hull's edges against A's.
        # First a bound below each edge's sum: the hull lies in its extents along u and v
        # (``ext``), so n . h is at least min(nu e0, nu e1) + min(nv e2, nv e3), nu = n . u,
        # nv = n . v; a cell it shows separated by more than the limit and SLACK (the two
        # computations' rounding) is one the sums below would drop.
        nu = anx * self.u[0][c] + any_ * self.u[1][c]                    # (V, S)
        nv = anx * self.v[0][c] + any_ * self.v[1][c]
        c = c[_extent_sep(nu, nv, [x[c] for x in self.ext], aoff) <= free_at + SLACK]
        if c.size == 0:
            return meets, undecided
        sep = _chunked(lambda at: _a_edges_sep(self.hx[:, at], self.hy[:, at], anx, any_, aoff),
                       c)
        c, sep = c[sep <= free_at], sep[sep <= free_at]      # the rest: an edge of A separates
        np.maximum(sep, _chunked(lambda at: _hull_edges_sep(self.nx[:, at], self.ny[:, at],
                                                            self.offset[:, at], ax, ay), c),
                   out=sep)
        meets[c[sep <= 0]] = True
        undecided[c[(sep > 0) & (sep <= free_at)]] = True
        return meets, undecided


def _box_gap_of(ax: npt.NDArray[np.float64], ay: npt.NDArray[np.float64],
                box: tuple[npt.NDArray[np.float64], ...]) -> npt.NDArray[np.float64]:
    """``_box_gap`` from the box of corners (ax, ay) to boxes (xmin, ymin, xmax, ymax), each
    (K,)."""
    return _box_gap((ax.min(), ay.min(), ax.max(), ay.max()), box)


def _extent_sep(nu: npt.NDArray[np.float64], nv: npt.NDArray[np.float64],
                ext: list[npt.NDArray[np.float64]], aoff: npt.NDArray[np.float64]
                ) -> npt.NDArray[np.float64]:
    """Per cell, at most (up to rounding) ``_a_edges_sep``: the greatest over A's edges of the
    least n . h - offset over the rectangle of the hull's extents along u and v (``ext``: e0..e1
    along u, e2..e3 along v), n = nu u + nv v ((V, S) each)."""
    e0, e1, e2, e3 = ext
    low = np.minimum(nu * e0, nu * e1) + np.minimum(nv * e2, nv * e3) - aoff
    return low.max(axis=0)


#: Cells whose (V, L) projections bound 4 holds at once (``_chunked``): a few MB.
SEP_CHUNK = 2048


def _chunked(f: Callable[[npt.NDArray[np.int64]], npt.NDArray[np.float64]],
             c: npt.NDArray[np.int64]) -> npt.NDArray[np.float64]:
    """``f(c)`` computed SEP_CHUNK cells at a time (f is elementwise over the cells)."""
    if c.size <= SEP_CHUNK:
        return f(c)
    return np.concatenate([f(c[k:k + SEP_CHUNK]) for k in range(0, c.size, SEP_CHUNK)])


def _a_edges_sep(hx: npt.NDArray[np.float64], hy: npt.NDArray[np.float64],
                 anx: npt.NDArray[np.float64], any_: npt.NDArray[np.float64],
                 aoff: npt.NDArray[np.float64]) -> npt.NDArray[np.float64]:
    """Per cell (hull corners (L, S)): the greatest over A's edges k ((V, 1) normals and
    offsets) of min over the corners of n_k . h - offset_k, every edge at once (V, L, S): each
    value the same float operations as one edge at a time."""
    proj = hx[None] * anx[:, :, None] + hy[None] * any_[:, :, None]
    return (proj.min(axis=1) - aoff).max(axis=0)


def _hull_edges_sep(nx: npt.NDArray[np.float64], ny: npt.NDArray[np.float64],
                    offset: npt.NDArray[np.float64], ax: npt.NDArray[np.float64],
                    ay: npt.NDArray[np.float64]) -> npt.NDArray[np.float64]:
    """Per cell (hull edges' normals and offsets (L, S)): the greatest over the hull's edges of
    min over A's corners ((V, 1)) of n . a - offset, every corner at once (V, L, S)."""
    least = (nx[None] * ax[:, :, None] + ny[None] * ay[:, :, None]).min(axis=0)
    return (least - offset).max(axis=0)


#: A left region (kept, so that its id is not reused), its corners' x and y (V, 1), counter-
#: clockwise, and its edges' outward normals and offsets (``_edges``).
_LeftEdges = tuple[shapely.Geometry, npt.NDArray[np.float64], npt.NDArray[np.float64],
                   tuple[npt.NDArray[np.float64], npt.NDArray[np.float64],
                         npt.NDArray[np.float64]]]


def _left_edges(a: shapely.Geometry) -> _LeftEdges:
    """``a``'s corners and edges as ``_Link2.decide`` reads them."""
    A = _ccw(shapely.get_coordinates(a)[:-1])
    ax, ay = A[:, 0:1], A[:, 1:2]
    return a, ax, ay, _edges(ax, ay)


#: The first row's lattice points of a part (grow, points (n, P, 2), hull order, flat): ``_row0``.
_Row0 = tuple[float, npt.NDArray[np.float64], npt.NDArray[np.int64], bool]


def _row0(s: Scenario, grid: Grid, part: int) -> _Row0:
    """The first row's lattices of right part ``part`` (n cells of 3 x 3 lattice points, each
    grown by the part's margin) and their hulls' corners (``_hull_order``): every other row is
    this one turned about the base (``_Link2``)."""
    n, h = grid.n, grid.h
    steps = np.array([-1.0, 0.0, 1.0])
    t1 = grid.lo[0] + steps[:, None] * h[0]
    t2 = (grid.lo[1] + np.arange(n) * h[1])[:, None, None] + steps[None, :] * h[1]
    t1, t2 = np.broadcast_arrays(t1, t2)                # (n, 3, 3): the first row's lattices
    grow = margin(s.right, part, h, (3, 3))
    pts = part_points(s.right, t1, t2, part, grow).reshape(n, -1, 2)
    order, flat = _hull_order(pts)                      # (n, L): the first row's hull corners
    return grow, pts, order, flat


def _ccw(p: npt.NDArray[np.float64]) -> npt.NDArray[np.float64]:
    """Vertices (V, 2) in counter-clockwise order."""
    x, y = p[:, 0], p[:, 1]
    return p if np.sum(x * np.roll(y, -1) - np.roll(x, -1) * y) >= 0 else p[::-1]


def _edges(x: npt.NDArray[np.float64], y: npt.NDArray[np.float64]
           ) -> tuple[npt.NDArray[np.float64], npt.NDArray[np.float64], npt.NDArray[np.float64]]:
    """Outward unit normals (nx, ny) and offsets of counter-clockwise polygons, corners (V, C)
    in x and y: the polygon is {p: n . p <= offset for every edge}. A zero-length edge (a
    repeated corner) gets the normal 0 and offset 0, a half-plane that holds everywhere."""
    ex, ey = np.roll(x, -1, axis=0) - x, np.roll(y, -1, axis=0) - y
    length = np.hypot(ex, ey)
    ok = length > 0
    safe = np.where(ok, length, 1.0)
    nx, ny = np.where(ok, ey / safe, 0.0), np.where(ok, -ex / safe, 0.0)
    return nx, ny, nx * x + ny * y


def _crosses(x0: npt.NDArray[np.float64], y0: npt.NDArray[np.float64],
             dx: npt.NDArray[np.float64], dy: npt.NDArray[np.float64],
             nx: npt.NDArray[np.float64], ny: npt.NDArray[np.float64],
             offset: npt.NDArray[np.float64]) -> npt.NDArray[np.bool_]:
    """Whether each segment (x0, y0) + t (dx, dy), 0 <= t <= 1 (S of them), meets the convex
    polygon {n . p <= offset} ((V, 1) edges): [0, 1] clipped by every edge's half-plane is not
    empty."""
    num = offset - (x0 * nx + y0 * ny)                              # (V, S)
    den = dx * nx + dy * ny
    ratio = num / np.where(den != 0, den, 1.0)
    hi = np.minimum(1.0, np.where(den > 0, ratio, np.inf).min(axis=0))
    lo = np.maximum(0.0, np.where(den < 0, ratio, -np.inf).max(axis=0))
    parallel_out = ((den == 0) & (num < 0)).any(axis=0)
    return (lo <= hi) & ~parallel_out


def _hull_order(pts: npt.NDArray[np.float64]) -> tuple[npt.NDArray[np.int64], bool]:
    """For point sets (n, P, 2): the indices of each hull's corners, counter-clockwise, padded
    to one length by repeating the last (a zero-length edge); and whether some hull is not a
    polygon (then the indices mean nothing). Every hull at once: its ring's corners (shapely's
    coordinates, the closing one left out), turned counter-clockwise where the shoelace sum is
    negative (``_ccw``'s test), each matched to the point it is."""
    hulls = shapely.convex_hull(shapely.linestrings(pts))
    if np.any(shapely.get_type_id(hulls) != 3):
        return np.zeros((len(pts), 1), dtype=np.int64), True
    coords, owner = shapely.get_coordinates(hulls, return_index=True)
    size = np.bincount(owner, minlength=len(pts)) - 1          # corners, the closing one out
    first = np.cumsum(size + 1) - (size + 1)                    # each ring's first coordinate
    ring_of = np.repeat(np.arange(len(pts)), size)
    pos = np.arange(size.sum()) - np.repeat(np.cumsum(size) - size, size)   # index in its ring
    at = first[ring_of] + pos                                   # the corner's coordinate row
    after = first[ring_of] + (pos + 1) % size[ring_of]          # the next corner's (np.roll)
    x, y = coords[:, 0], coords[:, 1]
    area = np.zeros(len(pts))
    np.add.at(area, ring_of, x[at] * y[after] - x[after] * y[at])
    turned = first[ring_of] + np.where(area[ring_of] >= 0, pos, size[ring_of] - 1 - pos)
    corner = coords[turned]                                     # counter-clockwise (C, 2)
    index = np.argmax((corner[:, None] == pts[ring_of]).all(axis=2), axis=1)
    width = int(size.max())
    take = np.minimum(np.arange(width)[None, :], size[:, None] - 1)
    return index[(np.cumsum(size) - size)[:, None] + take].astype(np.int64), False
