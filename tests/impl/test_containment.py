"""Containment of the variants' regions decided exactly on the doubles, not up to a slack."""

from __future__ import annotations

from fractions import Fraction

import numpy as np
from hypothesis import given, settings
from hypothesis import strategies as st

import factory
from cfmpa.impl import check_containment, contained_exactly, containment_slack

SQUARE = np.array([[0.0, 0.0], [1.0, 0.0], [1.0, 1.0], [0.0, 1.0]])   # CCW


def _inside_fractions(inner: np.ndarray, outer: np.ndarray) -> bool:
    """The definition, all in Fractions."""
    o = [(Fraction(x), Fraction(y)) for x, y in outer]
    for vx, vy in ((Fraction(x), Fraction(y)) for x, y in inner):
        for k, (ax, ay) in enumerate(o):
            bx, by = o[(k + 1) % len(o)]
            if (bx - ax) * (vy - ay) - (by - ay) * (vx - ax) < 0:
                return False
    return True


def test_a_vertex_on_the_boundary_is_inside_and_one_a_hair_outside_is_not():
    on_edge = np.array([[0.5, 0.0], [1.0, 0.3]])
    assert contained_exactly(on_edge, SQUARE)
    hair = np.array([[0.5, -1e-300]])
    assert not contained_exactly(hair, SQUARE)
    # The former rule (slack >= -1e-12 m) accepted a vertex 1e-13 m outside; the exact one does not.
    out = np.array([[0.5, -1e-13]])
    assert containment_slack(out, SQUARE) >= -1e-12
    assert not contained_exactly(out, SQUARE)


def test_a_tilted_edge_where_floats_cannot_tell_is_decided_by_fractions():
    # A long thin triangle: the cross products for points near its long edge are tiny against
    # their terms, so the filter hands them to Fractions.
    tri = np.array([[0.0, 0.0], [1.0, 1e-3], [0.5, 1.0]])
    on_line = np.array([[0.1, 1e-4]])
    assert contained_exactly(on_line, tri) == _inside_fractions(on_line, tri)
    below = np.array([[0.3, np.nextafter(3e-4, 0.0)]])
    assert contained_exactly(below, tri) == _inside_fractions(below, tri)


coord = st.floats(-2.0, 2.0, allow_nan=False, allow_infinity=False)


@settings(max_examples=200, deadline=None)
@given(pts=st.lists(st.tuples(coord, coord), min_size=1, max_size=6),
       cx=coord, cy=coord, r=st.floats(0.01, 3.0), n=st.integers(3, 9), phase=st.floats(0, 6.3))
def test_the_filtered_decision_equals_the_fraction_definition(pts, cx, cy, r, n, phase):
    ang = phase + 2 * np.pi * np.arange(n) / n
    outer = np.stack([cx + r * np.cos(ang), cy + r * np.sin(ang)], -1)   # convex, CCW
    inner = np.array(pts)
    assert contained_exactly(inner, outer) == _inside_fractions(inner, outer)


def test_the_bundled_style_workcell_nests_exactly_and_says_so():
    rep = check_containment(factory.scenario())
    assert rep.ok, rep.detail
    assert "decided exactly" in rep.detail
