"""Ledger A12: the float distances BuiltDR compares with eps are within spec.DISTANCE_ERROR_M of
the exact distance, checked against exact rational arithmetic (docs/model.md §4.3).

Polygons are random convex hulls of doubles at coordinates up to spec.MAX_COORD_M, placed near
touching (gaps from 0 to a few microns, overlaps too): where cancellation is worst. A double is
a rational, so the exact distance of the same polygons is decided in Fractions: 0 if they meet
(an exact separating-axis test), else the least vertex-edge distance, whose square is rational.
What Safety.separation needs of each float quantity q compared with eps (the box gap, the
separating-axis gap, the vertex-edge distance): exact distance >= q - DISTANCE_ERROR_M.
"""

from __future__ import annotations

from fractions import Fraction

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from cfmpa.impl._collide import PolygonSet, _separation, polygon_distance_batch
from cfmpa.spec import DISTANCE_ERROR_M, EPS, MAX_COORD_M, polygon_distance

F = Fraction


def _cross(o, a, b):
    return (a[0] - o[0]) * (b[1] - o[1]) - (a[1] - o[1]) * (b[0] - o[0])


def _hull(points: np.ndarray) -> np.ndarray:
    """Counter-clockwise convex hull (monotone chain), orientation decided exactly."""
    pts = sorted({(float(x), float(y)) for x, y in points})
    q = [(F(x), F(y)) for x, y in pts]

    def half(seq):
        out: list = []
        for p in seq:
            while len(out) >= 2 and _cross(out[-2], out[-1], p) <= 0:
                out.pop()
            out.append(p)
        return out
    lower, upper = half(q), half(q[::-1])
    hull = lower[:-1] + upper[:-1]
    return np.array([[float(x), float(y)] for x, y in hull])


def _seg_sq(p, a, b) -> Fraction:
    dx, dy = b[0] - a[0], b[1] - a[1]
    dd = dx * dx + dy * dy
    t = F(0) if dd == 0 else min(F(1), max(F(0), ((p[0] - a[0]) * dx + (p[1] - a[1]) * dy) / dd))
    gx, gy = p[0] - a[0] - t * dx, p[1] - a[1] - t * dy
    return gx * gx + gy * gy


def _separated(a, b) -> bool:
    """Some edge line of a or b has the other polygon strictly outside (exact)."""
    for p, q in ((a, b), (b, a)):
        for i in range(len(p)):
            e0, e1 = p[i], p[(i + 1) % len(p)]
            if e0 == e1:
                continue
            if all(_cross(e0, e1, v) < 0 for v in q):     # CCW: outside is to the right
                return True
    return False


def exact_distance_sq(a: np.ndarray, b: np.ndarray) -> Fraction:
    qa = [(F(float(x)), F(float(y))) for x, y in a]
    qb = [(F(float(x)), F(float(y))) for x, y in b]
    if not _separated(qa, qb):
        return F(0)
    return min(min(_seg_sq(p, q[i], q[(i + 1) % len(q)]) for p in pp for i in range(len(q)))
               for pp, q in ((qa, qb), (qb, qa)))


def _quantities(a: np.ndarray, b: np.ndarray) -> dict[str, float]:
    sa, sb = PolygonSet.of(a[None]), PolygonSet.of(b[None])
    box = float(np.maximum(sb.lo - sa.hi, sa.lo - sb.hi).max())
    return {"box gap": box, "separating-axis gap": float(_separation(sa, sb)[0]),
            "vertex-edge distance": float(polygon_distance_batch(a[None], b[None])[0]),
            "spec.polygon_distance": polygon_distance(a, b)}


def violations(a: np.ndarray, b: np.ndarray, bound: float) -> list[str]:
    """The float quantities q with q - bound > the exact distance (what A12 rules out)."""
    d2 = exact_distance_sq(a, b)
    out = []
    for name, q in _quantities(a, b).items():
        low = F(q) - F(bound)
        if low > 0 and low * low > d2:
            out.append(f"{name} {q!r} exceeds the exact distance {float(d2) ** 0.5!r} "
                       f"by more than {bound!r}")
    return out


def _pair(rng: np.random.Generator, scale: float) -> tuple[np.ndarray, np.ndarray]:
    """Two convex polygons of size ``scale`` near touching, far from the origin."""
    centre = rng.uniform(-1, 1, 2) * (MAX_COORD_M - 4 * scale)
    a = _hull(centre + rng.normal(size=(rng.integers(3, 12), 2)) * scale)
    # b: a copy of another random hull pushed along a random direction until nearly touching.
    b0 = _hull(rng.normal(size=(rng.integers(3, 12), 2)) * scale)
    u = rng.normal(size=2)
    u /= np.hypot(*u)
    reach_a = (a - centre) @ u
    reach_b = b0 @ u
    gap = float(rng.choice([0.0, 1e-12, 1e-10, 1e-9, 3e-9, 1e-6, -1e-9]))
    shift = reach_a.max() - reach_b.min() + gap
    return a, _hull(b0 + centre + shift * u)


@pytest.mark.parametrize("seed", range(4))
def test_float_distances_are_within_the_bound_of_the_exact_one(seed):
    rng = np.random.default_rng(seed)
    for _ in range(60):
        a, b = _pair(rng, float(rng.choice([0.01, 1.0, 100.0])))
        assert violations(a, b, DISTANCE_ERROR_M) == [], (a.tolist(), b.tolist())


@settings(max_examples=60, deadline=None)
@given(st.integers(0, 2**32 - 1), st.sampled_from([0.01, 0.3, 10.0, 300.0]))
def test_float_distances_within_the_bound_hypothesis(seed, scale):
    a, b = _pair(np.random.default_rng(seed), scale)
    assert violations(a, b, DISTANCE_ERROR_M) == []


def test_the_check_can_fail_with_a_bound_far_too_small():
    # Seeded fault: a bound of 1e-4 rounding units per metre (the error is of order u M); the
    # same comparison must find float quantities past the exact distance.
    rng = np.random.default_rng(0)
    tiny = 1e-4 * 2.0 ** -53 * MAX_COORD_M
    found = sum(bool(violations(*_pair(rng, 100.0), tiny)) for _ in range(200))
    assert found > 0


def test_the_exact_distance_is_exact_on_a_known_pair():
    a = np.array([[0.0, 0.0], [1.0, 0.0], [1.0, 1.0], [0.0, 1.0]])
    b = a + [3.0, 4.0]          # nearest corners (1, 1) and (3, 4): distance sqrt(13)
    assert exact_distance_sq(a, b) == 13
    assert exact_distance_sq(a, a + [0.5, 0.5]) == 0
    assert exact_distance_sq(a, a + [1.0, 0.0]) == 0       # touching along an edge


def test_eps_is_above_the_bound():
    assert 0 < DISTANCE_ERROR_M < EPS
