"""BuiltDR meets Theorem 1/3's postcondition, and the variants nest (Property 8, corrected)."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

import factory
from cfmpa.impl import build_dr, check_containment
from cfmpa.spec import Variant, load_scenario, make_grid
from cfmpa.spec._builtdr_post import dr_postcondition

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
