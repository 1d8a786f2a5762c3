"""Theorem 1/3's postcondition at every cell: the vectorised ``full_verdicts`` decides every cell
as the readable per-cell definition ``expected_cells`` does (random workcells, every variant),
also when its bounds are made to leave cells to the definition; and the full check reports a
wrong cell as the per-cell check does."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

import factory
from cfmpa.impl import build_dr_fast
from cfmpa.spec import (
    EPS,
    Variant,
    _builtdr_post,
    joint_points,
    load_scenario,
    make_grid,
    parse_scenario,
)
from cfmpa.spec._builtdr_post import BAND, dr_postcondition, expected_cells, full_verdicts

SCENARIOS = sorted(Path(__file__).resolve().parents[2].joinpath("scenarios").glob("*.toml"))


def definition(s, variant, g):
    """(expected, near) at every cell by the per-cell definition."""
    k, i, j = (a.ravel() for a in np.meshgrid(np.arange(g.N + 1), np.arange(g.m),
                                              np.arange(g.n), indexing="ij"))
    dist = expected_cells(s, variant, g, k, i, j).reshape(g.shape)
    return (dist <= EPS), np.abs(dist - EPS) <= BAND


def assert_agree(s, variant):
    g = make_grid(s)
    expected, near = full_verdicts(s, variant, g)
    want, want_near = definition(s, variant, g)
    assert np.array_equal(near, want_near)
    assert np.array_equal(expected.astype(bool)[~near], want[~near])


@st.composite
def workcells(draw):
    """Small random workcells (grids up to about 25 x 25, N up to about 10) whose arms meet."""
    dt = draw(st.sampled_from([0.2, 0.25, 0.3]))
    f = st.floats

    def arm(base):
        return {"base": base, "links": [draw(f(0.05, 0.5)), draw(f(0.05, 0.5))],
                "width": draw(f(0.005, 0.15)), "omega": [draw(f(1.2, 3.0)), draw(f(1.2, 3.0))]}

    left = arm([draw(f(-0.2, 0.2)), draw(f(-0.2, 0.2))])
    left["start"] = [draw(f(-3.2, 3.2)), draw(f(-3.2, 3.2))]
    left["goal"] = [left["start"][q] + draw(f(-1.5, 1.5)) for q in range(2)]
    right = arm([draw(f(0.0, 0.9)), draw(f(-0.4, 0.4))])
    right["limits"] = []
    for _ in range(2):
        lo = draw(f(-math.pi, 0.0))
        right["limits"].append([lo, lo + draw(f(0.5, 2 * math.pi))])
    size = [joint_points(*right["limits"][q], right["omega"][q], dt) for q in range(2)]
    right["start_cell"] = [0, 0]
    right["goal_cell"] = [size[0] - 1, size[1] - 1]
    return parse_scenario({"name": "random", "purpose": "hypothesis", "dt": dt, "left": left,
                           "right": right}, check_budget=False)


@settings(max_examples=25, deadline=None)
@given(s=workcells(), variant=st.sampled_from(list(Variant)))
def test_every_cell_is_decided_as_the_definition_decides_it(s, variant):
    assert_agree(s, variant)


@pytest.mark.slow
@settings(max_examples=200, deadline=None)
@given(s=workcells(), variant=st.sampled_from(list(Variant)))
def test_every_cell_is_decided_as_the_definition_decides_it_many(s, variant):
    assert_agree(s, variant)


@pytest.mark.parametrize("variant", list(Variant), ids=str)
def test_cells_no_bound_decides_go_to_the_definition(monkeypatch, variant):
    # With a slack of 5 cm most touching pairs are left undecided by the bounds, so the
    # definition decides them: the verdicts must not change.
    s = factory.scenario()
    g = make_grid(s)
    exact = full_verdicts(s, variant, g)
    calls = []
    real = _builtdr_post.expected_cells

    def counting(*args):
        calls.append(len(args[3]))
        return real(*args)

    monkeypatch.setattr(_builtdr_post, "SLACK", 0.05)
    monkeypatch.setattr(_builtdr_post, "expected_cells", counting)
    loose = full_verdicts(s, variant, g)
    assert calls and calls[0] > 20                       # the fallback really ran
    assert all(np.array_equal(a, b) for a, b in zip(exact, loose))
    assert_agree(s, variant)


def test_a_wrong_cell_is_reported_as_the_per_cell_check_reports_it():
    s = factory.scenario()
    g = make_grid(s)
    dr = build_dr_fast(s, Variant.MODIFIED, g)
    assert dr_postcondition(s, "modified", g, dr).ok
    k, i, j = (int(x) for x in np.argwhere(dr == 1)[3])
    bad = dr.copy()
    bad[k, i, j] = 0
    cells = np.argwhere(np.ones(g.shape, dtype=bool))
    full = dr_postcondition(s, "modified", g, bad)
    each = dr_postcondition(s, "modified", g, bad, cells=cells)
    assert not full.ok and full == each
    assert (full.mismatches[0].layer, full.mismatches[0].cell) == (k, (i, j))


@pytest.mark.parametrize("variant", list(Variant), ids=str)
@pytest.mark.parametrize("path", [p for p in SCENARIOS if p.stem != "default"],
                         ids=lambda p: p.stem)
def test_the_planners_dr_meets_the_postcondition_on_bundled_scenarios(path, variant):
    s = load_scenario(path)
    assert dr_postcondition(s, variant, make_grid(s), build_dr_fast(s, variant)).ok


@pytest.mark.slow
@pytest.mark.parametrize("variant", list(Variant), ids=str)
def test_the_planners_dr_meets_the_postcondition_on_the_default_scenario(variant):
    s = load_scenario(next(p for p in SCENARIOS if p.stem == "default"))
    report = dr_postcondition(s, variant, make_grid(s), build_dr_fast(s, variant))
    assert report.ok and report.checked == math.prod(make_grid(s).shape)
