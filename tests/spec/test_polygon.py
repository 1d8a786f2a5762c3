"""The spec's convex-polygon distance agrees with shapely and with hand-computed cases."""

from __future__ import annotations

import math

import numpy as np
import pytest
import shapely
from hypothesis import assume, given, settings
from hypothesis import strategies as st

from cfmpa.errors import InputError
from cfmpa.spec import polygon_distance
from cfmpa.spec._polygon import polygon_distances

UNIT = [(0.0, 0.0), (1.0, 0.0), (1.0, 1.0), (0.0, 1.0)]


def square(x: float, y: float, side: float = 1.0) -> list[tuple[float, float]]:
    return [(x, y), (x + side, y), (x + side, y + side), (x, y + side)]


def shapely_geom(points: list[tuple[float, float]]) -> shapely.Geometry:
    if len(points) == 1:
        return shapely.Point(points[0])
    if len(points) == 2:
        return shapely.LineString(points)
    return shapely.Polygon(points)


def hull(points: list[tuple[float, float]]) -> list[tuple[float, float]]:
    """Vertices of the convex hull (shapely's), counter-clockwise, closing vertex dropped."""
    geom = shapely.MultiPoint(points).convex_hull
    if isinstance(geom, shapely.Point):
        return [(geom.x, geom.y)]
    if isinstance(geom, shapely.LineString):
        return list(geom.coords)
    return list(geom.exterior.coords)[:-1]


coord = st.floats(min_value=-5.0, max_value=5.0, allow_nan=False, allow_infinity=False)
point_sets = st.lists(st.tuples(coord, coord), min_size=1, max_size=8)


def test_a_point_on_a_vanishing_segment_is_at_distance_zero():
    # Hypothesis found it: shapely says inf here; the segment from the origin to (0, 1.46e-243)
    # holds the origin.
    assert polygon_distance([(0.0, 0.0)], [(0.0, 0.0), (0.0, 1.4604556074455173e-243)]) == 0.0
    assert polygon_distance([(0.0, 1e-300)], [(0.0, 0.0), (0.0, 1e-243)]) == 0.0


@settings(max_examples=300, deadline=None)
@given(point_sets, point_sets, st.tuples(coord, coord))
def test_matches_shapely_on_random_convex_polygons(pa, pb, shift):
    a = hull(pa)
    b = [(x + shift[0], y + shift[1]) for x, y in hull(pb)]
    expected = shapely_geom(a).distance(shapely_geom(b))
    # GEOS has no distance for a segment shorter than about 1e-200 (it answers inf): no oracle.
    assume(math.isfinite(expected))
    got = polygon_distance(a, b)
    assert got == pytest.approx(expected, abs=1e-9)
    # Orientation and argument order do not matter.
    assert polygon_distance(b[::-1], a) == pytest.approx(got, abs=1e-12)


def test_touching_along_an_edge_is_zero():
    assert polygon_distance(UNIT, square(1.0, 0.0)) == 0.0


def test_touching_at_a_corner_is_zero():
    assert polygon_distance(UNIT, square(1.0, 1.0)) == 0.0


def test_vertex_touching_an_edge_is_zero():
    diamond = [(2.0, 0.5), (1.5, 1.0), (1.0, 0.5), (1.5, 0.0)]
    assert polygon_distance(UNIT, diamond) == 0.0


def test_contained_is_zero_both_ways():
    inner = square(0.25, 0.25, 0.5)
    assert polygon_distance(UNIT, inner) == 0.0
    assert polygon_distance(inner, UNIT) == 0.0


def test_crossing_without_contained_vertices_is_zero():
    # A plus sign: no vertex of either lies inside the other, only the edges cross.
    wide = [(-2.0, -0.1), (2.0, -0.1), (2.0, 0.1), (-2.0, 0.1)]
    tall = [(-0.1, -2.0), (0.1, -2.0), (0.1, 2.0), (-0.1, 2.0)]
    assert polygon_distance(wide, tall) == 0.0


def test_separated_along_a_diagonal_is_vertex_to_vertex():
    assert polygon_distance(UNIT, square(2.0, 2.0)) == pytest.approx(math.sqrt(2.0), abs=1e-15)


def test_separated_side_by_side_is_the_gap():
    assert polygon_distance(UNIT, square(3.5, 0.5)) == pytest.approx(2.5, abs=1e-15)


def test_degenerate_polygons_point_and_segment():
    assert polygon_distance([(3.0, 4.0)], [(0.0, 0.0)]) == pytest.approx(5.0)
    # Collinear segments that do not overlap are apart (an edge normal alone would not show it).
    assert polygon_distance([(0.0, 0.0), (1.0, 0.0)], [(2.0, 0.0), (3.0, 0.0)]) == pytest.approx(1.0)
    assert polygon_distance([(0.0, 0.0), (2.0, 0.0)], [(1.0, 0.0), (3.0, 0.0)]) == 0.0
    assert polygon_distance(UNIT, [(0.5, 0.5)]) == 0.0
    assert polygon_distance(UNIT, [(0.5, 3.0)]) == pytest.approx(2.0)


def test_batch_broadcasts_and_matches_scalar():
    rng = np.random.default_rng(7)
    centres = rng.uniform(-3, 3, size=(50, 2))
    a = np.asarray(UNIT)[None, :, :] + centres[:, None, :]
    b = np.asarray(square(0.0, 0.0, 0.5))
    got = polygon_distances(a, b)
    assert got.shape == (50,)
    for k in range(50):
        assert got[k] == polygon_distance(a[k], b)
    assert np.any(got == 0.0) and np.any(got > 0.0)


def test_refuses_malformed_input():
    with pytest.raises(InputError):
        polygon_distance([(0.0, 0.0, 1.0)], UNIT)
    with pytest.raises(InputError):
        polygon_distance([], UNIT)
    with pytest.raises(InputError):
        polygon_distance(UNIT, [(0.0, float("nan"))])
    with pytest.raises(InputError):
        polygon_distance([UNIT, UNIT], UNIT)
