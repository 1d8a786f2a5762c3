"""Swept regions are sound (contain the link at every configuration in the box) and monotone."""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

import factory
from cfmpa.impl import containment_slack as _slack
from cfmpa.impl import link_rectangles, naive_hull, swept_region

TOL = 1e-12
ARM = factory.scenario().left

angles = st.floats(-7.0, 7.0, allow_nan=False)
widths = st.floats(0.0, 0.8, allow_nan=False)
fractions = st.floats(0.0, 1.0)
spacings = st.floats(0.005, 0.3)


def inside(poly: np.ndarray, rect: np.ndarray) -> float:
    """How far inside poly the rectangle's corners are (negative: sticks out)."""
    return _slack(rect, poly)


@st.composite
def box_and_point(draw):
    lo = (draw(angles), draw(angles))
    w = (draw(widths), draw(widths))
    box = ((lo[0], lo[0] + w[0]), (lo[1], lo[1] + w[1]))
    # Corners, edges and interior: snap some fractions to 0 or 1.
    f = [draw(st.one_of(st.just(0.0), st.just(1.0), fractions)) for _ in range(2)]
    theta = (lo[0] + f[0] * w[0], lo[1] + f[1] * w[1])
    anchor = (lo[0] + draw(fractions) * w[0], lo[1] + draw(fractions) * w[1])
    g = (draw(spacings), draw(spacings))
    return box, theta, anchor, g


@settings(max_examples=300, deadline=None)
@given(box_and_point(), st.sampled_from([0, 1]))
def test_region_contains_link_at_every_configuration_in_box(case, link):
    box, theta, anchor, g = case
    region = swept_region(ARM, link, box, anchor, g)
    rect = link_rectangles(ARM, theta[0], theta[1], link)
    assert inside(region, rect) >= -TOL


@settings(max_examples=200, deadline=None)
@given(box_and_point(), fractions, fractions, fractions, fractions, st.sampled_from([0, 1]))
def test_region_of_sub_box_lies_in_region_of_box(case, a, b, c, d, link):
    box, _, anchor, g = case
    sub = tuple((lo + min(x, y) * (hi - lo), lo + max(x, y) * (hi - lo))
                for (lo, hi), x, y in zip(box, (a, c), (b, d)))
    big = swept_region(ARM, link, box, anchor, g)
    small = swept_region(ARM, link, sub, anchor, g)
    assert inside(big, small) >= -TOL


# Found by the search below and kept as a regression example: the default left arm's link 2
# over the original box of width 2 omega dt = 0.04 rad.
NAIVE_BOX = ((0.3, 0.34), (0.8, 0.84))
NAIVE_THETA = (0.32, 0.80)
NAIVE_PROTRUSION_M = 1.2779e-4


def test_naive_hull_of_end_configurations_is_unsound():
    arm = factory.scenario().left
    hull = naive_hull(arm, 1, NAIVE_BOX)
    rect = link_rectangles(arm, *NAIVE_THETA, 1)
    protrusion = -inside(hull, rect)
    assert protrusion == pytest.approx(NAIVE_PROTRUSION_M, rel=1e-3)
    # The sound region, on the same box, contains it.
    region = swept_region(arm, 1, NAIVE_BOX, (0.3, 0.8), (0.02, 0.02))
    assert inside(region, rect) > 0


def test_naive_hull_search_finds_a_protrusion_that_grows_with_the_box():
    arm = factory.scenario().left
    worst = []
    for w in (0.04, 0.3, 0.6):
        box = ((0.3, 0.3 + w), (0.8, 0.8 + w))
        hull = naive_hull(arm, 1, box)
        ts = np.linspace(0.0, 1.0, 21)
        worst.append(max(-inside(hull, link_rectangles(arm, 0.3 + a * w, 0.8 + b * w, 1))
                         for a in ts for b in ts))
    assert 0 < worst[0] < worst[1] < worst[2]
    assert worst[1] > 5e-3  # millimetres at a 0.3 rad sweep


# docs/model.md §4.2's second figure, kept as a regression example: at a 0.6 rad sweep of both joints
# the naive hull misses link 2 of the default left arm by ~28.5 mm (at theta1 mid-sweep).
WIDE_BOX = ((0.3, 0.9), (0.8, 1.4))
WIDE_THETA = (0.6, 0.8)
WIDE_PROTRUSION_M = 0.028539


def test_naive_hull_misses_the_link_by_28_mm_at_a_wide_sweep():
    arm = factory.scenario().left
    rect = link_rectangles(arm, *WIDE_THETA, 1)
    protrusion = -inside(naive_hull(arm, 1, WIDE_BOX), rect)
    assert protrusion > 25e-3
    assert protrusion == pytest.approx(WIDE_PROTRUSION_M, rel=1e-3)
    region = swept_region(arm, 1, WIDE_BOX, (0.3, 0.8), (0.02, 0.02))
    assert inside(region, rect) > 0


@pytest.mark.parametrize("scale", [1.0, 1e160, 1e300])
def test_convex_hull_stays_convex_at_huge_coordinates(scale):
    # Orientation products of 1e160 coordinates overflow; the hull scales them exactly first.
    from cfmpa.impl import convex_hull

    pts = np.array([[0.0, 0.0], [1.0, 0.2], [0.5, 0.5], [1.2, 1.0], [-0.1, 0.9], [0.4, 0.1]])
    hull = convex_hull(pts * scale)
    assert (hull / scale).tolist() == [[-0.1, 0.9], [0.0, 0.0], [1.0, 0.2], [1.2, 1.0]]
