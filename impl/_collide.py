"""The free/blocked decision between convex polygons (docs/model.md §4), vectorised over many polygons.

Free means Euclidean distance > eps; everything else is blocked, including a NaN anywhere in
the arithmetic (every test is written "free iff gap > eps", so an undefined gap never frees a
cell). The decision is monotone under containment because distance is: shrinking either polygon
can only increase it. Cheap tests settle most pairs
(bounding boxes, then separating axes, both lower bounds on the distance); only pairs whose
best separating gap lies in (0, eps] get the exact vertex-edge distance.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np
import numpy.typing as npt

__all__ = ["PolygonSet", "pad_polygons", "blocked_against", "polygon_distance_batch"]

Polygon = npt.NDArray[np.float64]      # (V, 2)
Polygons = npt.NDArray[np.float64]     # (C, V, 2), padded by repeating the last vertex
BoolArray = npt.NDArray[np.bool_]


def pad_polygons(polys: Sequence[Polygon], size: int | None = None) -> Polygons:
    """Stack polygons of different vertex counts into (C, V, 2), repeating each last vertex."""
    v = max(len(p) for p in polys) if size is None else size
    out = np.empty((len(polys), v, 2))
    for c, p in enumerate(polys):
        out[c, : len(p)] = p
        out[c, len(p):] = p[-1]
    return out


@dataclass(frozen=True)
class PolygonSet:
    """Convex CCW polygons (C, V, 2) with what the decision reuses across layers: outward unit
    edge normals, each edge's offset (normal . vertex), which edges have a length, bounding boxes."""

    verts: Polygons
    normals: Polygons
    offsets: npt.NDArray[np.float64]
    ok: BoolArray
    lo: npt.NDArray[np.float64]
    hi: npt.NDArray[np.float64]

    @classmethod
    def of(cls, verts: npt.ArrayLike) -> PolygonSet:
        v = np.asarray(verts, dtype=float)
        edges = np.roll(v, -1, axis=-2) - v
        length = np.hypot(edges[..., 0], edges[..., 1])
        ok = length > 0
        safe = np.where(ok, length, 1.0)
        normals = np.stack([edges[..., 1] / safe, -edges[..., 0] / safe], axis=-1)  # outward (CCW)
        offsets = (normals * v).sum(-1)
        return cls(v, normals, offsets, ok, v.min(-2), v.max(-2))

    def __len__(self) -> int:
        return len(self.verts)

    def take(self, idx: npt.NDArray[np.int64]) -> PolygonSet:
        return PolygonSet(self.verts[idx], self.normals[idx], self.offsets[idx], self.ok[idx],
                          self.lo[idx], self.hi[idx])


def _separation(a: PolygonSet, b: PolygonSet) -> npt.NDArray[np.float64]:
    """Largest gap along an outward edge normal of either polygon, a single one against many.

    By the separating-axis theorem this is > 0 iff the convex polygons are disjoint, and it is
    a lower bound on their distance. ``a`` holds one polygon, ``b`` many.
    """
    av, an, ao, aok = a.verts[0], a.normals[0], a.offsets[0], a.ok[0]
    # Along a's normals: b's nearest vertex beyond a's edge line.
    gap_a = (b.verts @ an.T).min(axis=1) - ao                          # (C, Va)
    gap_a = np.where(aok, gap_a, -np.inf).max(-1)
    # Along b's normals: a's nearest vertex beyond b's edge line.
    gap_b = (b.normals @ av.T).min(axis=2) - b.offsets                 # (C, Vb)
    gap_b = np.where(b.ok, gap_b, -np.inf).max(-1)
    return np.maximum(gap_a, gap_b)


def _point_segment(p: Polygons, s0: Polygons, s1: Polygons) -> npt.NDArray[np.float64]:
    d = s1 - s0
    dd = (d * d).sum(-1)
    t = np.where(dd > 0, ((p - s0) * d).sum(-1) / np.where(dd > 0, dd, 1.0), 0.0)
    t = np.clip(t, 0.0, 1.0)
    q = s0 + t[..., None] * d
    return np.sqrt(((p - q) ** 2).sum(-1))


def polygon_distance_batch(a: Polygons, b: Polygons) -> npt.NDArray[np.float64]:
    """Exact distance between pairs of convex polygons known NOT to intersect: (C, Va, 2), (C, Vb, 2)."""
    def one_way(p: Polygons, q: Polygons) -> npt.NDArray[np.float64]:
        s0 = q[:, None, :, :]
        s1 = np.roll(q, -1, axis=1)[:, None, :, :]
        return _point_segment(p[:, :, None, :], s0, s1).min(axis=(1, 2))
    return np.minimum(one_way(a, b), one_way(b, a))


def blocked_against(a: Polygon, b: PolygonSet, eps: float) -> BoolArray:
    """For one polygon ``a`` (V, 2) and many ``b``: not distance(a, b[c]) > eps, per c.

    Every comparison frees only on ``> eps`` (or ``> 0``), so NaN coordinates give "blocked".
    """
    blocked = np.zeros(len(b), dtype=bool)
    aset = PolygonSet.of(a[None])
    box_gap = np.maximum(b.lo - aset.hi, aset.lo - b.hi).max(-1)
    idx = np.flatnonzero(~(box_gap > eps))      # a box gap > eps already proves distance > eps
    if len(idx) == 0:
        return blocked
    near = b.take(idx)
    gap = _separation(aset, near)
    hit = ~(gap > 0.0)                           # no separating axis: they intersect
    unsure = (gap > 0.0) & ~(gap > eps)          # apart, but maybe not by more than eps
    if unsure.any():
        u = np.flatnonzero(unsure)
        dist = polygon_distance_batch(np.broadcast_to(a, (len(u),) + a.shape), near.verts[u])
        hit[u] = ~(dist > eps)
    blocked[idx] = hit
    return blocked
