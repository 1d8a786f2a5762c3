"""BuiltDR in numpy alone: the reference's D_R bit for bit, with no compile (docs/model.md §7.5).

The kernel a run uses while the fast kernels' machine code is being compiled in the background
(``_kernel_cache``): it starts at once, and is several times faster than the reference.

Same regions: the reference's own ``right_regions`` and ``left_regions`` arrays, and the same
``PolygonSet`` (normals, offsets, boxes) for them. Same decision, as in ``_fast_builtdr``:

- the bounding-box gap is the reference's, in its own float operations, so it agrees exactly;
- the separating-axis gap g (max over the edge normals of both polygons of the least
  vertex term) is computed here with elementwise products written out, contiguous in memory,
  where the reference uses a matrix product: the two differ by a few ulps of the coordinates
  at most, which MARGIN (``MARGIN_REL`` of the largest coordinate, at least 1 m) exceeds by
  orders of magnitude. So g > eps + MARGIN here means the reference's g > eps (free), and
  g < -MARGIN means the reference's g < 0 (blocked);
- every other pair (g within MARGIN of 0 or eps, a coordinate not finite or beyond MAX_COORD,
  hence a NaN gap) is handed to the reference's own ``blocked_against`` on the same polygons,
  whose per-pair arithmetic does not depend on which other pairs share the batch.

Structure used (the decision is an OR over the pairs of parts): a row whose link 1 is blocked
is blocked whole; a cell already blocked is not tested again; the rest layer of
original/modified is layer N-1 itself (copied).
"""

from __future__ import annotations

import numpy as np
import numpy.typing as npt

from ..spec import EPS, Grid, Scenario, Variant, make_grid, pairs_to_test
from ._builtdr import DR, RightRegions, left_regions, right_regions
from ._collide import PolygonSet, blocked_against

__all__ = ["MARGIN_REL", "MAX_COORD", "build_dr_numpy"]

#: Margin around the thresholds 0 and eps, relative to the largest coordinate (at least 1 m).
MARGIN_REL = 1e-12

#: Polygons with a coordinate beyond this (metres), or not finite, are left to the reference.
MAX_COORD = 1e100


class _Packed:
    """One per-cell part's polygons (C, V, 2) laid out for the gap: x, y (C, V), contiguous
    (``_columns`` gathers a subset as (V, C'), over which a reduction over the vertices is
    elementwise over polygons); the boxes' lo x, lo y,
    hi x, hi y (C,), PolygonSet's values; ``row_box`` (rows, 4) the union of each row's n boxes
    (NaN where one is); ``sane`` (C,) every coordinate finite and within MAX_COORD; ``scale``
    the largest |coordinate| of the sane polygons. The normals and offsets (C, V), PolygonSet's
    own values, are made for a polygon when it first reaches the gap (most never do):
    PolygonSet.of is elementwise per polygon, so a subset's are the whole set's."""

    def __init__(self, verts: npt.NDArray[np.float64], n: int) -> None:
        self.verts = verts
        self.x = np.ascontiguousarray(verts[..., 0])
        self.y = np.ascontiguousarray(verts[..., 1])
        # The boxes as PolygonSet's min and max over the vertices (the same values: a min or
        # max rounds nothing; a NaN coordinate gives NaN either way).
        self.box = (self.x.min(1), self.y.min(1), self.x.max(1), self.y.max(1))
        # Every coordinate within MAX_COORD (so finite) iff every box bound is (a NaN is not).
        bound = np.abs(np.stack(self.box))
        self.sane = (bound <= MAX_COORD).all(axis=0)
        self.scale = float(bound[:, self.sane].max()) if self.sane.any() else 0.0
        rows = len(verts) // n
        b = self.box
        self.row_box = np.stack([b[0].reshape(rows, n).min(1), b[1].reshape(rows, n).min(1),
                                 b[2].reshape(rows, n).max(1), b[3].reshape(rows, n).max(1)], -1)
        shape = verts.shape[:2]
        self.nx, self.ny, self.off = np.empty(shape), np.empty(shape), np.empty(shape)
        self.packed = np.zeros(len(verts), dtype=bool)

    def pack(self, cells: npt.NDArray[np.int64]) -> None:
        """Make the normals and offsets of ``cells`` (those not made before)."""
        new = cells[~self.packed[cells]]
        if new.size == 0:
            return
        ps = PolygonSet.of(self.verts[new])
        self.nx[new] = ps.normals[..., 0]
        self.ny[new] = ps.normals[..., 1]
        self.off[new] = np.where(ps.ok, ps.offsets, np.inf)  # no length: never separates
        self.packed[new] = True

    def polygons(self, cells: npt.NDArray[np.int64]) -> PolygonSet:
        """The reference's PolygonSet of ``cells``."""
        return PolygonSet.of(self.verts[cells])


def build_dr_numpy(s: Scenario, variant: Variant | str, grid: Grid | None = None, *,
                   eps: float = EPS, right: RightRegions | None = None,
                   progress: bool | None = None) -> DR:
    """D_R for ``variant``, identical to ``build_dr`` (uint8 (N + 1, m, n), 1 = blocked).

    ``progress`` is accepted for the fast kernel's signature and ignored (no bar)."""
    del progress
    g = grid or make_grid(s)
    rr = right or right_regions(s, g)
    left = left_regions(s, variant, g)
    m, n = g.m, g.n
    link1 = PolygonSet.of(rr.link1)
    packed = [None] + [_Packed(np.ascontiguousarray(r.reshape(m * n, *r.shape[2:])), n)
                       for r in rr.per_cell()]
    # Link 1 first: a row it blocks is blocked whole, and its cells are not tested again.
    pairs = sorted(pairs_to_test(s.left, s.right), key=lambda ab: ab[1] != 0)
    P = np.zeros(g.shape, dtype=np.uint8)
    for k, regions in enumerate(left.links):
        if k > 0 and regions is left.links[k - 1]:
            P[k] = P[k - 1]                       # the rest layer is layer N-1 itself
            continue
        blocked = np.zeros((m, n), dtype=bool)
        for a, b in pairs:
            if b == 0:
                blocked |= blocked_against(regions[a], link1, eps)[:, None]
                continue
            pk = packed[b]
            assert pk is not None
            cells = _open_cells(regions[a], pk, blocked, eps)
            hit = _blocked_among(regions[a], pk, cells, eps)
            blocked.reshape(-1)[cells[hit]] = True
        P[k] = blocked
    return P


def _open_cells(a: npt.NDArray[np.float64], b: _Packed, blocked: npt.NDArray[np.bool_],
                eps: float) -> npt.NDArray[np.int64]:
    """The cells (flat indices) not yet blocked whose box gap to polygon ``a`` is not > eps (the
    reference's box test, in its float operations: the rest it frees). A row whose union box
    is apart by more than eps has every cell's box apart by at least as much."""
    lo, hi = a.min(0), a.max(0)
    rb = b.row_box
    row_gap = np.maximum(np.maximum(rb[:, 0] - hi[0], lo[0] - rb[:, 2]),
                         np.maximum(rb[:, 1] - hi[1], lo[1] - rb[:, 3]))
    m, n = blocked.shape
    rows = np.flatnonzero(~(row_gap > eps) & ~blocked.all(1))
    if rows.size == 0:
        return rows
    cells = (rows[:, None] * n + np.arange(n)[None, :]).reshape(-1)
    cells = cells[~blocked.reshape(-1)[cells]]
    lx, ly, hx, hy = (c[cells] for c in b.box)
    gap = np.maximum(np.maximum(lx - hi[0], lo[0] - hx), np.maximum(ly - hi[1], lo[1] - hy))
    return cells[~(gap > eps)]


def _blocked_among(a: npt.NDArray[np.float64], b: _Packed, near: npt.NDArray[np.int64],
                   eps: float) -> npt.NDArray[np.bool_]:
    """blocked_against(a, b.polygons(near), eps) for cells whose box gap is not > eps: the same
    booleans (see the module docstring)."""
    out = np.zeros(len(near), dtype=bool)
    if near.size == 0:
        return out
    aset = PolygonSet.of(a[None])
    a_sane = bool((np.abs(a) <= MAX_COORD).all())
    scale = max(1.0, b.scale, float(np.abs(a).max()) if a_sane else 0.0)
    margin = MARGIN_REL * scale
    gap = _gap(aset, b, near, eps, margin) if a_sane else np.full(len(near), np.nan)
    sane = b.sane[near]
    sure_hit = (gap < -margin) & sane
    unsure = ~((gap > eps + margin) & sane) & ~sure_hit
    out[sure_hit] = True
    u = np.flatnonzero(unsure)
    if u.size:
        out[u] = blocked_against(a, b.polygons(near[u]), eps)
    return out


def _gap(aset: PolygonSet, b: _Packed, near: npt.NDArray[np.int64], eps: float,
         margin: float) -> npt.NDArray[np.float64]:
    """The separating-axis gap of polygon ``aset`` against b's polygons ``near`` (see
    ``_collide._separation``), elementwise: within a few ulps of the reference's; where a's
    normals alone give more than eps + margin (free), b's are not tried (a lower bound)."""
    x, y = _columns(b.x, near), _columns(b.y, near)         # (V, C) C-contiguous
    av, an, ao, aok = aset.verts[0], aset.normals[0], aset.offsets[0], aset.ok[0]
    an, ao = an[aok], ao[aok]                     # an edge without length never separates
    if len(an):                                   # along a's normals: b's nearest vertex
        # least[e, c] over b's vertices v, one vertex at a time: the products and the sum
        # are the reference's own per element (x an_x + y an_y), only their order of work
        # differs (so the same floats as one normal at a time).
        least = np.empty((len(an), len(near)))
        term = np.empty_like(least)
        other = np.empty_like(least)
        np.multiply.outer(an[:, 0], x[0], out=least)
        least += np.multiply.outer(an[:, 1], y[0], out=other)
        for v in range(1, len(x)):
            np.multiply.outer(an[:, 0], x[v], out=term)
            term += np.multiply.outer(an[:, 1], y[v], out=other)
            np.minimum(least, term, out=least)
        least -= ao[:, None]
        gap = least.max(axis=0)
    else:
        gap = np.full(len(near), -np.inf)
    rest = np.flatnonzero(~(gap > eps + margin))  # not yet free on a's normals alone
    if rest.size == 0:
        return gap
    sub = near[rest]
    b.pack(sub)
    nx, ny = _columns(b.nx, sub), _columns(b.ny, sub)
    least = nx * av[0, 0]
    term_b, other_b = np.empty_like(least), np.empty_like(least)
    least += np.multiply(ny, av[0, 1], out=term_b)
    for v in range(1, len(av)):                   # along b's normals: a's nearest vertex
        np.multiply(nx, av[v, 0], out=term_b)
        term_b += np.multiply(ny, av[v, 1], out=other_b)
        np.minimum(least, term_b, out=least)
    least -= _columns(b.off, sub)             # an edge without length: offset +inf, term -inf
    gap[rest] = np.maximum(gap[rest], least.max(axis=0))
    return gap


def _columns(a: npt.NDArray[np.float64], cells: npt.NDArray[np.int64]) -> npt.NDArray[np.float64]:
    """Rows ``cells`` of ``a`` (C, V) as a C-contiguous (V, len(cells)): a reduction over the
    vertices is then elementwise over polygons (rows gathered, then transposed: faster than
    gathering columns)."""
    return np.ascontiguousarray(a.take(cells, axis=0).T)
