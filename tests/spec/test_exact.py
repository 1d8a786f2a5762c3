"""The path's cells re-decided in ball arithmetic: free cells are proved free, a blocked or
borderline cell is never."""

from __future__ import annotations

import numpy as np
import pytest

import factory
from cfmpa.impl import build_dr, search_opt_path
from cfmpa.spec import EPS, Variant, make_grid, polygon_distance
from cfmpa.spec import _exact as exact_mod
from cfmpa.spec._exact import exact_path_gaps, path_layer_cells
from cfmpa.spec._regions import left_region_polygons, right_region_polygons


@pytest.fixture(scope="module", params=list(Variant))
def planned(request):
    # Cells between which a path exists under every variant.
    s = factory.scenario(right__start_cell=[0, 8], right__goal_cell=[15, 5])
    v = request.param
    g = make_grid(s)
    dr = build_dr(s, v, g)
    r = search_opt_path(dr, s.right.start_cell, s.right.goal_cell)
    assert r.path, "the factory workcell has a path in every variant"
    return s, v, g, dr, r.path


def _float_gap(s, v, g, layer, cell) -> float:
    left = left_region_polygons(s, v, g)[layer]
    r1, r2 = right_region_polygons(s, g, np.array([cell[0]]), np.array([cell[1]]))
    return min(polygon_distance(np.asarray(a.exterior.coords), np.asarray(b[0].exterior.coords))
               for a in left for b in (r1, r2))


def test_the_pairs_read_are_the_fixed_is_paths_steps():
    # A 2-cell path with N = 3: steps 0..3, the goal held from step 1, layer 3 is the rest layer.
    assert path_layer_cells([(0, 0), (0, 1)], 3) == [(0, (0, 0)), (1, (0, 1)), (2, (0, 1)),
                                                    (3, (0, 1))]
    # A path longer than N: its tail is in the rest layer.
    assert path_layer_cells([(0, 0), (1, 0), (2, 0)], 1) == [(0, (0, 0)), (1, (1, 0)),
                                                            (1, (2, 0))]


def test_every_cell_of_a_found_path_is_proved_free_and_the_bound_is_below_the_float_gap(planned):
    s, v, g, dr, path = planned
    e = exact_path_gaps(s, v, g, path)
    assert e.ok and not e.undecided
    assert len(e.cells) == len(path_layer_cells(path, g.N))
    assert e.least_gap_m > EPS
    layer, cell = e.least_at
    # A lower bound on the exact gap: never above the float distance by more than rounding.
    assert e.least_gap_m <= _float_gap(s, v, g, layer, cell) + 1e-12
    assert e.least_gap_m >= _float_gap(s, v, g, layer, cell) - 1e-9


def test_a_blocked_cell_planted_in_the_path_is_not_proved_free(planned):
    s, v, g, dr, path = planned
    k, i, j = map(int, np.argwhere(dr[: g.N] == 1)[0])
    bad = [tuple(c) for c in path]
    bad[min(k, len(bad) - 1)] = (i, j)      # so that step k holds (i, j) in layer k
    e = exact_path_gaps(s, v, g, bad)
    assert not e.ok
    assert any(c.cell == (i, j) and c.gap_lower_m <= EPS for c in e.undecided)


def test_a_gap_below_eps_is_undecided_not_free(planned, monkeypatch):
    # Raise eps 1 um above the path's least proved gap (the balls are far tighter than that):
    # that cell, and only cells within 1 um of it, are then reported undecided.
    s, v, g, dr, path = planned
    before = exact_path_gaps(s, v, g, path)
    monkeypatch.setattr(exact_mod, "EPS", before.least_gap_m + 1e-6)
    e = exact_path_gaps(s, v, g, path)
    assert not e.ok
    assert (before.least_at[0], before.least_at[1]) in {(c.layer, c.cell) for c in e.undecided}
    assert all(c.gap_lower_m <= before.least_gap_m + 1e-6 for c in e.undecided)
