"""Euclidean distance between convex polygons: the spec's own routine, shared with no impl.

A polygon is a closed convex set given by its vertices in boundary order (either orientation;
repeated and collinear vertices allowed; 1 vertex is a point, 2 a segment). The distance is 0.0
exactly when the closed sets meet (touching counts), else the true distance up to float rounding.

Method (no iteration, no tolerance): two convex polygons meet iff an edge of one crosses an edge
of the other or a vertex of one lies in the other; when they do not meet, the closest pair of
points has a vertex at one end, so the distance is the least vertex-to-edge distance.
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np
import numpy.typing as npt

from ..errors import InputError

__all__ = ["polygon_distance", "polygon_distances"]

FloatArray = npt.NDArray[np.float64]


def polygon_distance(a: Sequence[Sequence[float]] | FloatArray,
                     b: Sequence[Sequence[float]] | FloatArray) -> float:
    """Distance between convex polygons ``a`` and ``b`` (sequences of (x, y)); 0.0 iff they meet."""
    pa = _as_polygons(a, "a")
    pb = _as_polygons(b, "b")
    if pa.ndim != 2 or pb.ndim != 2:
        raise InputError("a" if pa.ndim != 2 else "b", (pa if pa.ndim != 2 else pb).shape,
                         "must be one polygon, a sequence of (x, y) points")
    return float(_distances(pa, pb))


def polygon_distances(a: npt.ArrayLike, b: npt.ArrayLike) -> FloatArray:
    """Distances between batches of convex polygons, shapes (..., na, 2) and (..., nb, 2).

    Leading dimensions broadcast against each other. Polygons of different vertex counts share
    one batch by repeating a vertex (a repeated vertex is a zero-length edge, which is harmless).
    """
    return _distances(_as_polygons(a, "a"), _as_polygons(b, "b"))


def _as_polygons(p: npt.ArrayLike, field: str) -> FloatArray:
    arr = np.asarray(p, dtype=float)
    if arr.ndim < 2 or arr.shape[-1] != 2 or arr.shape[-2] < 1:
        raise InputError(field, arr.shape, "must have shape (..., vertices >= 1, 2)")
    if not np.all(np.isfinite(arr)):
        raise InputError(field, arr.tolist() if arr.size <= 16 else "<array>",
                         "must have finite coordinates")
    return arr


# --- pure numpy -------------------------------------------------------------------------------


def _cross(ux: FloatArray, uy: FloatArray, vx: FloatArray, vy: FloatArray) -> FloatArray:
    return ux * vy - uy * vx


def _orientation(p: FloatArray) -> FloatArray:
    """Sign of the signed area (+1 counter-clockwise, -1 clockwise, 0 degenerate), shape (...)."""
    x, y = p[..., 0], p[..., 1]
    xn, yn = np.roll(x, -1, axis=-1), np.roll(y, -1, axis=-1)
    # Shift to the first vertex so the shoelace sum does not lose digits far from the origin.
    x0, y0 = x[..., :1], y[..., :1]
    area2 = np.sum(_cross(x - x0, y - y0, xn - x0, yn - y0), axis=-1)
    return np.sign(area2)


def _side(p: FloatArray, q: FloatArray) -> FloatArray:
    """side[..., i, j] = cross(edge i of p, q_j - p_i): where q's vertex j lies w.r.t. p's edge i."""
    e = np.roll(p, -1, axis=-2) - p                       # (..., np, 2)
    rel = q[..., None, :, :] - p[..., :, None, :]          # (..., np, nq, 2)
    return _cross(e[..., :, None, 0], e[..., :, None, 1], rel[..., 0], rel[..., 1])


def _inside(side: FloatArray, orient: FloatArray) -> npt.NDArray[np.bool_]:
    """Whether any vertex of q lies in the closed polygon p, given _side(p, q) and p's orientation.

    A degenerate p (zero area) contains nothing here: a vertex on a segment is found by the
    vertex-to-edge distance instead, which is then 0.
    """
    on_inner_side = orient[..., None, None] * side >= 0
    return (orient != 0) & np.any(np.all(on_inner_side, axis=-2), axis=-1)


def _crossing(side_pq: FloatArray, side_qp: FloatArray) -> npt.NDArray[np.bool_]:
    """Whether some edge of p properly crosses some edge of q (endpoints strictly on both sides).

    Touching and collinear overlaps are not crossings; they put a vertex on an edge, where the
    vertex-to-edge distance is 0.
    """
    s1 = np.sign(side_pq)                                  # (..., np, nq): q_j vs edge p_i
    s2 = np.sign(side_qp)                                  # (..., nq, np): p_i vs edge q_j
    q_straddles = s1 * np.roll(s1, -1, axis=-1) < 0        # q_j, q_{j+1} on opposite sides of p_i
    p_straddles = s2 * np.roll(s2, -1, axis=-1) < 0        # p_i, p_{i+1} on opposite sides of q_j
    return np.any(q_straddles & np.swapaxes(p_straddles, -1, -2), axis=(-2, -1))


def _vertex_edge_sq(p: FloatArray, q: FloatArray) -> FloatArray:
    """Least squared distance from a vertex of q to an edge of p, shape (...)."""
    e = np.roll(p, -1, axis=-2) - p                        # (..., np, 2)
    rel = q[..., None, :, :] - p[..., :, None, :]           # (..., np, nq, 2)
    ee = np.sum(e * e, axis=-1)[..., :, None]               # (..., np, 1)
    dot = np.sum(rel * e[..., :, None, :], axis=-1)         # (..., np, nq)
    # A zero-length edge is its start point: t = 0.
    t = np.where(ee > 0, np.clip(dot / np.where(ee > 0, ee, 1.0), 0.0, 1.0), 0.0)
    gap = rel - t[..., None] * e[..., :, None, :]
    return np.min(np.sum(gap * gap, axis=-1), axis=(-2, -1))


def _distances_reference(a: FloatArray, b: FloatArray) -> FloatArray:
    """The method of the module docstring on arrays (..., vertices, 2) as they come: the
    statement ``_distances`` computes, number for number, batch last (tests/spec/test_polygon.py
    checks the two agree bit for bit)."""
    lead = np.broadcast_shapes(a.shape[:-2], b.shape[:-2])
    a = np.broadcast_to(a, lead + a.shape[-2:])
    b = np.broadcast_to(b, lead + b.shape[-2:])
    side_ab = _side(a, b)
    side_ba = _side(b, a)
    meet = (_crossing(side_ab, side_ba) | _inside(side_ab, _orientation(a))
            | _inside(side_ba, _orientation(b)))
    gap_sq = np.minimum(_vertex_edge_sq(a, b), _vertex_edge_sq(b, a))
    return np.where(meet, 0.0, np.sqrt(gap_sq))


# --- the same, batch last ---------------------------------------------------------------------
# ``_distances`` lays each coordinate out as (vertices, N), the N pairs of the batch last and
# contiguous, so every step is one elementwise operation over whole rows and every reduction over
# vertices is elementwise across rows, where ``_distances_reference`` reduces tiny trailing axes
# (2 coordinates, a few vertices) pair by pair. Each value is the same IEEE operation on the same
# operands in the same order (a sum of two terms is x0 + x1 in both; orientations are computed
# by ``_orientation`` itself), so the distances are bit-identical.


def _soa(p: FloatArray, lead: tuple[int, ...]) -> tuple[FloatArray, FloatArray]:
    """(x, y) of polygons (..., V, 2) broadcast to ``lead``: each (V, N), contiguous."""
    flat = np.broadcast_to(p, lead + p.shape[-2:]).reshape(-1, p.shape[-2], 2)
    return np.ascontiguousarray(flat[:, :, 0].T), np.ascontiguousarray(flat[:, :, 1].T)


def _next_minus(x: FloatArray) -> FloatArray:
    """x[i + 1] - x[i] along the first axis, cyclically: ``np.roll(x, -1, axis=0) - x``."""
    out = np.empty_like(x)
    np.subtract(x[1:], x[:-1], out=out[:-1])
    np.subtract(x[0], x[-1], out=out[-1])
    return out


def _half(px: FloatArray, py: FloatArray, qx: FloatArray, qy: FloatArray
          ) -> tuple[FloatArray, FloatArray]:
    """(side, least squared vertex-to-edge distance) of q's vertices against p's edges: side
    (np, nq, N) is ``_side``'s, the distance (N,) ``_vertex_edge_sq``'s (in place where a
    temporary is done with: the same operations on the same operands)."""
    ex, ey = _next_minus(px), _next_minus(py)            # (np, N): p_{i+1} - p_i
    relx = qx[None, :, :] - px[:, None, :]               # (np, nq, N)
    rely = qy[None, :, :] - py[:, None, :]
    exb, eyb = ex[:, None, :], ey[:, None, :]
    side = exb * rely
    side -= eyb * relx                                   # cross(e, rel)
    ee = (ex * ex + ey * ey)[:, None, :]                 # (np, 1, N)
    t = relx * exb
    t += rely * eyb                                      # dot(rel, e)
    pos = ee > 0
    if np.all(pos):                                      # no zero-length edge: t = 0 nowhere
        t /= ee
        np.clip(t, 0.0, 1.0, out=t)
    else:
        t = np.where(pos, np.clip(t / np.where(pos, ee, 1.0), 0.0, 1.0), 0.0)
    gx = t * exb
    np.subtract(relx, gx, out=gx)
    gy = t * eyb
    np.subtract(rely, gy, out=gy)
    gx *= gx
    gy *= gy
    gx += gy
    return side, np.min(gx.reshape(gx.shape[0] * gx.shape[1], gx.shape[2]), axis=0)


def _straddles(side: FloatArray) -> npt.NDArray[np.bool_]:
    """side[i, j] and side[i, j + 1] (cyclically) strictly of opposite signs: ``_crossing``'s
    sign(x) * sign(y) < 0."""
    neg, pos = side < 0, side > 0
    out = np.empty_like(neg)
    out[:, :-1] = (neg[:, :-1] & pos[:, 1:]) | (pos[:, :-1] & neg[:, 1:])
    out[:, -1] = (neg[:, -1] & pos[:, 0]) | (pos[:, -1] & neg[:, 0])
    return out


def _contains(side: FloatArray, orient: FloatArray) -> npt.NDArray[np.bool_]:
    """``_inside`` of (np, nq, N) sides and (N,) orientations."""
    inner = orient * side >= 0
    return (orient != 0) & np.any(np.all(inner, axis=0), axis=0)


def _distances(a: FloatArray, b: FloatArray) -> FloatArray:
    lead = np.broadcast_shapes(a.shape[:-2], b.shape[:-2])
    ax, ay = _soa(a, lead)
    bx, by = _soa(b, lead)
    orient_a = np.broadcast_to(_orientation(a), lead).reshape(-1)
    orient_b = np.broadcast_to(_orientation(b), lead).reshape(-1)
    side_ab, gap_ab = _half(ax, ay, bx, by)
    side_ba, gap_ba = _half(bx, by, ax, ay)
    meet = (np.any(_straddles(side_ab) & np.swapaxes(_straddles(side_ba), 0, 1), axis=(0, 1))
            | _contains(side_ab, orient_a) | _contains(side_ba, orient_b))
    out = np.where(meet, 0.0, np.sqrt(np.minimum(gap_ab, gap_ba)))
    return out.reshape(lead)
