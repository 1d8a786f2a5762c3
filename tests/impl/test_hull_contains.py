"""impl.convex_hull is what Safety.region_statement's hull definition reads it as (ledger A11):
a convex polygon whose vertices are input points and which contains every input point. A hull
with a vertex dropped (seeded fault) is caught."""

from __future__ import annotations

import numpy as np
from hypothesis import given, settings
from hypothesis import strategies as st

from cfmpa.impl import convex_hull

coords = st.floats(-10, 10, allow_nan=False, allow_infinity=False)
point_sets = st.lists(st.tuples(coords, coords), min_size=3, max_size=40)


def _contains_all(hull: np.ndarray, pts: np.ndarray, tol: float = 1e-9) -> bool:
    """Every point on the inner side of (or on) every edge of the counter-clockwise hull."""
    if len(hull) < 3:
        return True
    a, b = hull, np.roll(hull, -1, axis=0)
    e = b - a
    rel = pts[:, None, :] - a[None, :, :]
    cross = e[None, :, 0] * rel[..., 1] - e[None, :, 1] * rel[..., 0]
    scale = np.linalg.norm(e, axis=1)[None, :]
    return bool((cross >= -tol * np.maximum(scale, 1.0)).all())


@settings(max_examples=200, deadline=None)
@given(point_sets)
def test_the_hull_contains_every_point_and_is_made_of_them(pts):
    p = np.array(pts, dtype=float)
    hull = convex_hull(p)
    assert _contains_all(hull, p)
    for v in hull:
        assert (np.abs(p - v).max(axis=1) == 0).any()


def test_a_hull_with_a_vertex_dropped_is_caught():
    p = np.array([(0, 0), (2, 0), (2, 2), (0, 2), (1, 1)], dtype=float)
    hull = convex_hull(p)
    assert len(hull) == 4 and _contains_all(hull, p)
    assert not _contains_all(hull[1:], p)
