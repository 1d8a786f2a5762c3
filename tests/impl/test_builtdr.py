"""BuiltDR meets Theorem 1/3's postcondition, and the variants nest (Property 8, corrected)."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest
from hypothesis import assume, given, settings
from hypothesis import strategies as st

import factory
from cfmpa.impl import build_dr, check_containment, right_regions
from cfmpa.impl._fast_builtdr import build_dr_fast
from cfmpa.spec import EPS, Variant, load_scenario, make_grid, parse_scenario
from cfmpa.spec._builtdr_post import BAND, dr_postcondition, expected_cells

SCENARIOS = sorted(Path(__file__).resolve().parents[2].joinpath("scenarios").glob("*.toml"))
VARIANTS = list(Variant)


@pytest.fixture(scope="module")
def tiny():
    s = factory.scenario()
    g = make_grid(s)
    return s, g, {v: build_dr(s, v, g) for v in VARIANTS}


def test_shape_and_dtype_follow_the_grid_formulas(tiny):
    s, g, drs = tiny
    for dr in drs.values():
        assert dr.dtype == np.uint8
        assert dr.shape == (g.N + 1, g.m, g.n) == (7, 27, 27)
        assert set(np.unique(dr)) <= {0, 1}


@pytest.mark.parametrize("variant", VARIANTS, ids=str)
def test_build_dr_meets_the_postcondition_at_every_cell(tiny, variant):
    s, g, drs = tiny
    report = dr_postcondition(s, variant, g, drs[variant])
    assert report.ok, report.mismatches
    assert report.checked == drs[variant].size
    assert 0 < drs[variant].mean() < 1  # both decisions occur, so the check has teeth


@pytest.mark.parametrize("variant", VARIANTS, ids=str)
def test_postcondition_rejects_a_flipped_cell(tiny, variant):
    s, g, drs = tiny
    dr = drs[variant]
    for value in (0, 1):
        k, i, j = (int(x[0]) for x in np.nonzero(dr == value))
        bad = dr.copy()
        bad[k, i, j] = 1 - value
        report = dr_postcondition(s, variant, g, bad)
        assert not report.ok
        assert [(m.layer, m.cell, m.got) for m in report.mismatches] == [(k, (i, j), 1 - value)]


def test_rest_layer_repeats_the_last_layer_except_for_tight(tiny):
    s, g, drs = tiny
    assert np.array_equal(drs[Variant.ORIGINAL][g.N], drs[Variant.ORIGINAL][g.N - 1])
    assert np.array_equal(drs[Variant.MODIFIED][g.N], drs[Variant.MODIFIED][g.N - 1])
    # At rest the principal occupies less than while moving through its last layer.
    assert drs[Variant.TIGHT][g.N].sum() < drs[Variant.TIGHT][g.N - 1].sum()


def test_variants_nest_cell_by_cell(tiny):
    _, _, drs = tiny
    assert (drs[Variant.TIGHT] <= drs[Variant.MODIFIED]).all()
    assert (drs[Variant.MODIFIED] <= drs[Variant.ORIGINAL]).all()
    assert (drs[Variant.MODIFIED] < drs[Variant.ORIGINAL]).any()


@pytest.mark.parametrize("path", SCENARIOS, ids=lambda p: p.stem)
def test_containment_chain_on_bundled_scenarios(path):
    report = check_containment(load_scenario(path))
    assert report.ok, report.detail


coords = st.floats(-0.8, 0.8)
small_angles = st.floats(-3.2, 3.2)


@settings(max_examples=25, deadline=None)
@given(base=st.tuples(coords, coords), start=st.tuples(small_angles, small_angles),
       goal=st.tuples(small_angles, small_angles),
       omega=st.tuples(st.floats(0.3, 2.0), st.floats(0.3, 2.0)), dt=st.floats(0.1, 0.5))
def test_containment_and_nesting_on_random_scenarios(base, start, goal, omega, dt):
    s = factory.scenario(dt=dt, right__base=list(base), left__start=list(start),
                         left__goal=list(goal), left__omega=list(omega),
                         right__start_cell=[0, 0], right__goal_cell=[1, 1])
    report = check_containment(s)
    assert report.ok, report.detail
    g = make_grid(s)
    if g.N * g.m * g.n > 20000:
        return
    drs = [build_dr(s, v, g) for v in (Variant.TIGHT, Variant.MODIFIED, Variant.ORIGINAL)]
    assert (drs[0] <= drs[1]).all() and (drs[1] <= drs[2]).all()


@pytest.mark.filterwarnings("ignore::RuntimeWarning")
def test_decision_frees_only_pairs_proved_apart_nan_blocks():
    from cfmpa.impl._collide import PolygonSet, blocked_against

    sq = np.array([[0.0, 0.0], [1.0, 0.0], [1.0, 1.0], [0.0, 1.0]])
    far, near, apart, undefined = sq + [5.0, 0.0], sq + [1.0 + 5e-10, 0.0], sq + [1.0 + 2e-9, 0.0], \
        sq + [5.0, 0.0]
    undefined[2, 1] = np.nan
    got = blocked_against(sq, PolygonSet.of(np.stack([far, near, apart, undefined])), 1e-9)
    assert got.tolist() == [False, True, False, True]
    nan_a = sq.copy()
    nan_a[0, 0] = np.nan
    assert blocked_against(nan_a, PolygonSet.of(far[None]), 1e-9).tolist() == [True]


# ---- Theorem 1/3's postcondition on random small scenarios, and a random flipped cell ----

@st.composite
def small_scenarios(draw, max_cells=4000):
    """Coarse random workcells (a few hundred to a few thousand cells): goal below start in
    either joint (modified's s = -1) and narrow, off-centre right limits included."""
    f = st.floats
    dt = draw(st.sampled_from([0.15, 0.2, 0.25, 0.3]))
    start = [draw(f(-3.0, 3.0)), draw(f(-3.0, 3.0))]
    goal = [start[q] + draw(st.one_of(f(-1.5, -0.2), f(0.2, 1.5))) for q in range(2)]
    limits = []
    for _ in range(2):
        lo = draw(f(-3.0, 1.0))
        limits.append([lo, lo + draw(st.one_of(f(0.6, 2.0), st.just(2 * math.pi)))])
    omega_r = [draw(f(1.0, 3.0)), draw(f(1.0, 3.0))]
    doc = factory.doc(dt=dt, left__start=start, left__goal=goal,
                      left__omega=[draw(f(0.5, 2.0)), draw(f(0.5, 2.0))],
                      right__base=[draw(f(0.2, 0.8)), draw(f(-0.3, 0.3))],
                      right__omega=omega_r, right__limits=limits,
                      right__start_cell=[0, 0], right__goal_cell=[0, 0])
    s = parse_scenario(doc, check_budget=False)
    assume(200 <= s.cells <= max_cells)
    return s


def _check_postcondition_and_flip(s, variant, data):
    g = make_grid(s)
    dr = build_dr(s, variant, g)
    report = dr_postcondition(s, variant, g, dr)
    assert report.ok, report.mismatches
    assert report.checked == dr.size
    # Flip one random cell, in the direction the array allows: the spec must see it.
    value = data.draw(st.sampled_from(sorted({int(x) for x in np.unique(dr)})))
    cells = np.argwhere(dr == value)
    k, i, j = (int(x) for x in cells[data.draw(st.integers(0, len(cells) - 1))])
    dist = float(expected_cells(s, variant, g, [k], [i], [j])[0])
    assume(abs(dist - EPS) > BAND)          # a cell in the indeterminate band is accepted either way
    bad = dr.copy()
    bad[k, i, j] = 1 - value
    flipped = dr_postcondition(s, variant, g, bad)
    assert not flipped.ok
    assert [(m.layer, m.cell, m.got) for m in flipped.mismatches] == [(k, (i, j), 1 - value)]


@settings(max_examples=12, deadline=None)
@given(s=small_scenarios(), variant=st.sampled_from(VARIANTS), data=st.data())
def test_postcondition_holds_on_random_scenarios_and_sees_a_random_flip(s, variant, data):
    _check_postcondition_and_flip(s, variant, data)


@pytest.mark.slow
@settings(max_examples=300, deadline=None)
@given(s=small_scenarios(max_cells=20000), variant=st.sampled_from(VARIANTS), data=st.data())
def test_postcondition_holds_on_many_random_scenarios_slow(s, variant, data):
    _check_postcondition_and_flip(s, variant, data)


@pytest.mark.parametrize("variant", VARIANTS, ids=str)
def test_postcondition_with_goal_below_start_and_narrow_limits(variant):
    # A fixed case of what the random test covers: both joints run backwards (s = -1), the right
    # arm's limits are far from [0, 2 pi].
    s = factory.scenario(left__start=[1.6, 2.2], left__goal=[0.3, 0.8],
                         right__limits=[[1.0, 3.0], [-1.2, 0.9]], right__omega=[1.5, 1.5],
                         right__start_cell=[0, 0], right__goal_cell=[1, 1])
    assert all(s.left.goal[q] < s.left.start[q] for q in range(2))
    g = make_grid(s)
    dr = build_dr(s, variant, g)
    assert 0 < dr.mean() < 1
    report = dr_postcondition(s, variant, g, dr)
    assert report.ok, report.mismatches


# ---- D_R nesting on every bundled scenario, with the fast kernel ----

@pytest.mark.parametrize("path", SCENARIOS, ids=lambda p: p.stem)
def test_dr_nests_cell_by_cell_on_bundled_scenarios(path):
    s = load_scenario(path)
    g = make_grid(s)
    rr = right_regions(s, g)
    tight, modified, original = (build_dr_fast(s, v, g, right=rr, progress=False)
                                 for v in (Variant.TIGHT, Variant.MODIFIED, Variant.ORIGINAL))
    assert (tight <= modified).all()
    assert (modified <= original).all()
    assert (modified < original).any()   # the chain is not trivially equal
