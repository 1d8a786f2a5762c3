"""The compiled region builders give the reference's arrays, byte for byte: the hull twin against
convex_hull on random point sets (ties, signed zeros, collinear runs, huge and non-finite
coordinates), the right and left regions against right_regions and left_regions, and the
reference's one-call-per-shape rectangles against its definition (one swept_region per j)."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from cfmpa.impl import build_dr, convex_hull, left_regions, right_regions, swept_region
from cfmpa.impl._collide import pad_polygons
from cfmpa.impl._fast_builtdr import build_dr_fast
from cfmpa.impl._fast_regions import (
    _hull_order,
    convex_hulls,
    left_regions_fast,
    right_regions_fast,
)
from cfmpa.spec import Variant, load_scenario, make_grid
from dr_strategies import random_workcells

SCENARIOS = sorted(Path(__file__).resolve().parents[2].joinpath("scenarios").glob("*.toml"))


def same_bytes(a: np.ndarray, b: np.ndarray) -> bool:
    return a.shape == b.shape and a.dtype == b.dtype and a.tobytes() == b.tobytes()


# Coordinates on a coarse lattice make ties, duplicates and collinear runs common; a few special
# values reach the cases the twin hands back to convex_hull.
coord = st.one_of(st.integers(-4, 4).map(float), st.sampled_from([0.0, -0.0, 0.5, -0.5]),
                  st.floats(-10, 10, allow_nan=False),
                  st.sampled_from([1e101, -1e150, float("inf"), float("nan")]))
point_sets = st.lists(st.lists(st.tuples(coord, coord), min_size=1, max_size=40), min_size=1,
                      max_size=6)


@settings(max_examples=300, deadline=None)
@given(point_sets)
def test_hull_twin_gives_convex_hulls_arrays(sets):
    pts = [np.array(p, dtype=float) for p in sets]
    for got, p in zip(convex_hulls(pts), pts):
        assert same_bytes(got, convex_hull(p)), (p.tolist(), got.tolist())


def test_hull_twin_on_the_cases_it_hands_back():
    cases = [np.array([[0.0, 0.0], [-0.0, 0.0], [1.0, 0.0], [0.0, 1.0]]),   # 0.0 and -0.0
             np.array([[0.0, 0.0], [1e120, 0.0], [0.0, 1e120]]),              # scaled path
             np.array([[0.0, 0.0], [np.nan, 1.0], [1.0, 1.0], [1.0, 0.0]]),  # NaN
             np.array([[0.0, 0.0], [1.0, 1.0], [1.0, 1.0]])]                  # two distinct
    for p, got in zip(cases, convex_hulls(cases)):
        assert same_bytes(got, convex_hull(p))
        # ...by handing each back: the twin itself answers -1 (equality alone would also hold
        # if the twin happened to choose as np.unique did).
        _, counts = _hull_order(np.ascontiguousarray(p), np.array([0, len(p)]))
        assert counts[0] == -1, p.tolist()
    line = np.array([[0.0, 0.0], [1.0, 1.0], [2.0, 2.0], [3.0, 3.0]])      # the twin's own case
    assert same_bytes(convex_hulls([line])[0], convex_hull(line))
    assert convex_hulls([line])[0].tolist() == [[0.0, 0.0], [3.0, 3.0]]
    square = np.array([[0.0, 0.0], [1.0, 0.0], [1.0, 1.0], [0.0, 1.0], [0.5, 0.5], [0.5, 0.0]])
    assert convex_hulls([square])[0].tolist() == [[0.0, 0.0], [1.0, 0.0], [1.0, 1.0], [0.0, 1.0]]


def right_by_definition(s, g):
    """right_regions as docs/model.md §4 builds it: one swept_region per j, turned by each t_i."""
    from cfmpa.impl._builtdr import _rotate
    arm = s.right
    origin = type(arm)(**{**arm.__dict__, "base": (0.0, 0.0)})
    h1, h2 = g.h
    t_i = np.asarray(g.angle(0, np.arange(g.m)), dtype=float)
    t_j = np.asarray(g.angle(1, np.arange(g.n)), dtype=float)
    l1 = swept_region(origin, 0, ((-h1, h1), (0.0, 0.0)), (0.0, 0.0), (h1, h2))
    l2 = pad_polygons([swept_region(origin, 1, ((-h1, h1), (tj - h2, tj + h2)), (0.0, tj),
                                    (h1, h2)) for tj in t_j])
    return _rotate(l1, t_i, arm.base), _rotate(l2, t_i, arm.base)


def assert_regions_equal(s):
    g = make_grid(s)
    ref = right_regions(s, g)
    fast = right_regions_fast(s, g)
    assert same_bytes(fast.link1, ref.link1) and same_bytes(fast.link2, ref.link2)
    link1, link2 = right_by_definition(s, g)
    assert same_bytes(ref.link1, link1) and same_bytes(ref.link2, link2)
    for v in Variant:
        a, b = left_regions(s, v, g), left_regions_fast(s, v, g)
        assert len(a.links) == len(b.links)
        for k, (pa, pb) in enumerate(zip(a.links, b.links)):
            assert all(same_bytes(x, y) for x, y in zip(pa, pb)), (v, k)
        # build_dr_fast copies the rest layer when it is layer N-1's very pair (not a copy).
        assert (b.links[-1] is b.links[-2]) == (a.links[-1] is a.links[-2])


@pytest.mark.parametrize("path", SCENARIOS, ids=lambda p: p.stem)
def test_regions_equal_on_bundled_scenarios(path):
    assert_regions_equal(load_scenario(path))


@settings(max_examples=25, deadline=None)
@given(random_workcells(dts=(0.1, 0.2)))
def test_regions_equal_on_random_workcells(s):
    assert_regions_equal(s)


@settings(max_examples=10, deadline=None)
@given(random_workcells(dts=(0.2,)))
def test_build_dr_fast_with_its_own_regions_is_build_dr(s):
    assert np.array_equal(build_dr_fast(s, Variant.TIGHT, progress=False),
                          build_dr(s, Variant.TIGHT))
