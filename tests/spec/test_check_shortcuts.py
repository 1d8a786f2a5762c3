"""The full contracts' shortcuts decide what the checks without them decide (docs/model.md §7.5):
the postcondition's row boxes skip only rows whose cells' boxes are apart, the exact
first-row hulls' corners are found all at once, the exact re-decision's ends are taken over
the balls that may hold them, and the witness's form is checked in the edges' pass over the
layers, on the box of the labelled cells, still reported first. Seeded faults: a row box that
does not hold its cells' boxes misses a planted cell, hulls left in shapely's orientation
differ, a slack without the balls' radii drops the ball that holds the end, and a label out of
range at a state no free labelled state is near, or a form failure behind an edge failure, is
still found.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
import shapely
from flint import arb, ctx

import factory
from cfmpa.impl import build_dr, search_opt_path
from cfmpa.spec import EPS, MOVES, Variant, Witness, check_witness, load_scenario, make_grid
from cfmpa.spec import _builtdr_post as post
from cfmpa.spec import _exact as exact
from cfmpa.spec._builtdr_post import (
    BAND,
    TOOL,
    _ccw,
    _hull_order,
    _row0,
    dr_postcondition,
    full_verdicts,
)
from cfmpa.spec._exact import _extreme, _slack, projection_bounds
from cfmpa.spec._kinematics import parts
from cfmpa.spec._regions import left_region_polygons

WAIT = MOVES.index((0, 0))
ROOT = Path(__file__).resolve().parents[2]


@pytest.fixture(scope="module")
def built():
    s = factory.scenario(right__start_cell=[0, 8], right__goal_cell=[15, 5])
    v = Variant("modified")
    g = make_grid(s)
    return s, v, g, build_dr(s, v, g)


def _decide_all(s, v, g, row_box=None):
    """Every layer's and left part's (meets, undecided) of link 2 on the whole grid, with the
    row boxes replaced by ``row_box(link)`` when given."""
    link = post._Link2(s, g, part=1)
    if row_box is not None:
        link.row_box = row_box(link)
    skip = np.zeros(g.m * g.n, dtype=bool)
    return [link.decide(a, EPS + BAND + post.SLACK, skip)
            for layer in left_region_polygons(s, v, g) for a in layer]


def _everything(link):
    """Row boxes holding everything: no row is skipped (the check without the shortcut)."""
    return tuple(np.full(g.shape[0], x) for g, x in zip(link.row_box, (-np.inf, -np.inf,
                                                                         np.inf, np.inf)))


def _middle_cell(link):
    """Seeded fault: each row's box is its middle cell's, which does not hold the others."""
    m = link.row_box[0].shape[0]
    return tuple(b.reshape(m, link.n)[:, link.n // 2] for b in link.box)


def test_row_boxes_skip_only_rows_whose_cells_are_apart(built):
    s, v, g, _ = built
    for (m1, u1), (m2, u2) in zip(_decide_all(s, v, g), _decide_all(s, v, g, _everything)):
        assert np.array_equal(m1, m2) and np.array_equal(u1, u2)
    assert any(m.any() for m, _ in _decide_all(s, v, g))          # not vacuous: cells meet


def test_the_extents_bound_drops_only_cells_the_sums_drop(built, monkeypatch):
    s, v, g, _ = built
    faithful = _decide_all(s, v, g)
    # Without the shortcut: the bound never drops a cell.
    monkeypatch.setattr(post, "_extent_sep", lambda nu, nv, ext, aoff: np.full(nu.shape[1],
                                                                                -np.inf))
    for (m1, u1), (m2, u2) in zip(faithful, _decide_all(s, v, g)):
        assert np.array_equal(m1, m2) and np.array_equal(u1, u2)
    # Seeded fault: the rectangle's greatest corner, not its least, drops cells that meet.
    def greatest(nu, nv, ext, aoff):
        e0, e1, e2, e3 = ext
        return (np.maximum(nu * e0, nu * e1) + np.maximum(nv * e2, nv * e3) - aoff).max(axis=0)

    monkeypatch.setattr(post, "_extent_sep", greatest)
    assert any(not np.array_equal(m1, m2) for (m1, _), (m2, _) in zip(faithful,
                                                                      _decide_all(s, v, g)))


def _shown(s, v, g, dr):
    """Every mismatch the postcondition reports, as (layer, cell)."""
    rep = dr_postcondition(s, v, g, dr, limit=10**6)
    return {(c.layer, c.cell) for c in rep.mismatches}


def test_a_cell_a_wrong_row_box_would_skip_is_caught(built, monkeypatch):
    s, v, g, dr = built
    assert dr_postcondition(s, v, g, dr).ok
    right, _ = full_verdicts(s, v, g)
    init = post._Link2.__init__

    def faulty(self, *args, **kwargs):
        init(self, *args, **kwargs)
        self.row_box = _middle_cell(self)

    with monkeypatch.context() as mp:
        mp.setattr(post._Link2, "__init__", faulty)
        wrong, _ = full_verdicts(s, v, g)
        missed = np.argwhere((right == 1) & (wrong == 0))
        assert len(missed), "the seeded fault changes some verdict"
        k, i, j = (int(x) for x in missed[0])
        planted = dr.copy()
        planted[k, i, j] = 0                                    # a blocked cell made free
        # The faulty bound misses it (and reports cells that are right elsewhere).
        assert (k, (i, j)) not in _shown(s, v, g, planted)
    rep = dr_postcondition(s, v, g, planted)                    # the real one does not
    assert not rep.ok and (rep.mismatches[0].layer, rep.mismatches[0].cell) == (k, (i, j))


def _hull_order_one_by_one(pts, turn=True):
    """The hulls' corner indices a hull at a time (what ``_hull_order`` did before it took
    every hull at once); ``turn=False``, the seeded fault, keeps shapely's orientation."""
    hulls = shapely.convex_hull(shapely.linestrings(pts))
    if np.any(shapely.get_type_id(hulls) != 3):
        return np.zeros((len(pts), 1), dtype=np.int64), True
    out = []
    for q, hull in zip(pts, hulls):
        ring = shapely.get_coordinates(hull)[:-1]
        ring = _ccw(ring) if turn else ring
        out.append(np.argmax((ring[:, None] == q[None]).all(axis=2), axis=1).tolist())
    width = max(len(o) for o in out)
    return np.array([o + [o[-1]] * (width - len(o)) for o in out], dtype=np.int64), False


def _same_order(a, b):
    return a[1] == b[1] and (a[1] or np.array_equal(a[0], b[0]))


def test_hulls_at_once_are_the_hulls_one_by_one():
    s = load_scenario(ROOT / "scenarios" / "gripper.toml")
    g = make_grid(s)
    sets = [_row0(s, g, part)[1] for part in (1, TOOL)]
    rng = np.random.default_rng(3)
    sets += [rng.normal(size=(6, int(rng.integers(3, 12)), 2)) for _ in range(40)]
    sets += [np.round(rng.normal(size=(6, 9, 2)), 1) for _ in range(20)]   # repeated points
    sets += [np.zeros((2, 4, 2))]                                          # not polygons
    for pts in sets:
        assert _same_order(_hull_order(pts), _hull_order_one_by_one(pts))
        mirrored = pts * np.array([1.0, -1.0])
        assert _same_order(_hull_order(mirrored), _hull_order_one_by_one(mirrored))
    # Seeded fault: shapely's own orientation, not turned counter-clockwise, differs.
    assert not all(_same_order(_hull_order(p), _hull_order_one_by_one(p, turn=False))
                   for p in sets[:2])


def _same(x, y):
    """The same ball: midpoint and radius equal, exactly."""
    return bool(x.mid() == y.mid()) and bool(x.rad() == y.rad())


def test_the_ends_over_the_balls_kept_are_the_ends_over_all(built):
    s, v, g, dr = built
    path = search_opt_path(dr, s.right.start_cell, s.right.goal_cell).path
    assert path
    old = ctx.prec
    ctx.prec = exact.EXACT_PREC_BITS
    try:
        gl = (s.left.omega[0] * s.dt, s.left.omega[1] * s.dt)
        left = exact._left_points(s, v, g, 2, gl)
        right = exact._right_points(s, g, tuple(path[len(path) // 2]))
        rng = np.random.default_rng(7)
        dropped = 0
        for a in left:
            for b in right:
                for nx, ny in rng.normal(size=(8, 2)):
                    ka, kb = _extreme(a, nx, ny, 1.0), _extreme(b, nx, ny, -1.0)
                    dropped += len(a[0]) - len(ka) + len(b[0]) - len(kb)
                    hi, lo = projection_bounds(arb(nx), arb(ny), ka, kb)
                    hi_all, lo_all = projection_bounds(arb(nx), arb(ny), a[0], b[0])
                    assert _same(hi, hi_all) and _same(lo, lo_all)
        assert dropped > 0                                       # the shortcut does skip balls
        assert len(parts(s.left)) == len(left)
    finally:
        ctx.prec = old


def test_a_wide_ball_that_holds_the_end_is_kept():
    # The second ball's midpoint projects below the first's, its upper end above it.
    balls = [(arb(0), arb(0)), (arb(-1e-12, 1e-9), arb(0))]
    floats = np.array([[0.0, 0.0], [-1e-12, 0.0]])
    region = (balls, None, floats, _slack(balls, floats))
    hi_all, _ = projection_bounds(arb(1), arb(0), balls, balls)
    hi, _ = projection_bounds(arb(1), arb(0), _extreme(region, 1.0, 0.0, 1.0), balls)
    assert _same(hi, hi_all) and hi > 0
    # Seeded fault: a slack of the midpoints' rounding alone drops that ball.
    thin = (balls, None, floats, 4.0 * float(np.abs(floats).max()) * exact.FLOAT_REL)
    hi_bad, _ = projection_bounds(arb(1), arb(0), _extreme(thin, 1.0, 0.0, 1.0), balls)
    assert not _same(hi_bad, hi_all) and hi_bad < hi_all


def _certified(dr, start, goal):
    from cfmpa.impl import search_opt_path_fast

    r = search_opt_path_fast(dr, start, goal, with_witness=True)
    assert check_witness(dr, start, goal, r, r.witness) == []
    return r


def _wide(j):
    """Labels as uint32, "no label" still the type's largest value."""
    out = j.astype(np.uint32)
    out[j == np.iinfo(j.dtype).max] = np.iinfo(np.uint32).max
    return out


def test_a_form_failure_behind_an_edge_failure_is_the_one_reported():
    dr = np.zeros((4, 3, 3), dtype=np.uint8)
    r = _certified(dr, (0, 0), (2, 2))
    j1, j2 = _wide(r.witness.j1), _wide(r.witness.j2)
    j1[1, MOVES.index((1, 1)), 1, 1] += 5                    # an edge failure at step 0
    (f,) = check_witness(dr, (0, 0), (2, 2), r, Witness.of_labels(j1, j2))
    assert f.condition == "witness.edge"
    j1[3, WAIT, 2, 2] = 1 << 30                               # out of range, at the last layer
    (f,) = check_witness(dr, (0, 0), (2, 2), r, Witness.of_labels(j1, j2))
    assert f.condition == "witness.form" and "out of range" in f.message
    assert dict(f.values)["state"] == {"step": 3, "cell": [2, 2], "previous move": [0, 0]}


def test_a_label_out_of_range_where_no_free_state_is_labelled_is_found():
    # A blocked column: the labelled free states of step 1 lie within a move of the start; a
    # label out of range at a blocked cell apart from them (which no edge reads) is judged.
    dr = np.zeros((3, 5, 5), dtype=np.uint8)
    dr[:, :, 2] = 1
    dr[:, 4, 2] = 0
    r = _certified(dr, (0, 0), (0, 1))
    j1, j2 = _wide(r.witness.j1), _wide(r.witness.j2)
    none = np.iinfo(np.uint32).max
    assert j1[1, :, 2:, 2:].min() == none                     # nothing labelled there
    j1[1, WAIT, 3, 2], j2[1, WAIT, 3, 2] = 1 << 30, 0
    (f,) = check_witness(dr, (0, 0), (0, 1), r, Witness.of_labels(j1, j2))
    assert f.condition == "witness.form" and "out of range" in f.message
    assert dict(f.values)["state"] == {"step": 1, "cell": [3, 2], "previous move": [0, 0]}
    j1[1, WAIT, 3, 2] = 3                                     # in range: in j2 only is next
    j2[1, WAIT, 2, 2] = 3
    (f,) = check_witness(dr, (0, 0), (0, 1), r, Witness.of_labels(j1, j2))
    assert f.condition == "witness.form" and "one array only" in f.message
