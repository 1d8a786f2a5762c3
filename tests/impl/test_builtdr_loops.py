"""The loop-form BuiltDR (Algorithm 1 as written, the source the proofs extract) gives build_dr's
and build_dr_fast's D_R bit for bit: random small workcells and the bundled scenarios at dt 0.4."""

from __future__ import annotations

import tomllib
from pathlib import Path

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from cfmpa.impl import build_dr, build_dr_fast, build_dr_loops, builtdr_loop_nest, right_regions
from cfmpa.spec import Variant, make_grid, parse_scenario
from dr_strategies import random_workcells

SCENARIOS = sorted(Path(__file__).resolve().parents[2].joinpath("scenarios").glob("*.toml"))


def assert_same(s, variant):
    g = make_grid(s)
    loops = build_dr_loops(s, variant, g)
    assert loops.dtype == np.uint8 and loops.shape == g.shape
    assert set(np.unique(loops)) <= {0, 1}          # every cell stored (2 marks "never stored")
    rr = right_regions(s, g)
    for other in (build_dr(s, variant, g, right=rr), build_dr_fast(s, variant, g, right=rr)):
        diff = np.argwhere(loops != other)
        assert diff.size == 0, f"{len(diff)} cells differ, first (k, i, j) = {diff[:5].tolist()}"
    return loops


def coarse(path: Path, dt: float = 0.4):
    """A bundled scenario at a coarser time step (its cells re-picked inside the smaller grid)."""
    doc = tomllib.loads(path.read_text())
    doc["dt"] = dt
    doc["right"]["start_cell"], doc["right"]["goal_cell"] = [0, 0], [1, 1]
    return parse_scenario(doc, check_budget=False)


@pytest.mark.parametrize("variant", list(Variant), ids=str)
@pytest.mark.parametrize("path", SCENARIOS, ids=lambda p: p.stem)
def test_bit_identical_on_bundled_scenarios_at_a_coarse_dt(path, variant):
    dr = assert_same(coarse(path), variant)
    assert 0 < dr.mean() < 1                          # both decisions occur


def random_scenarios():
    """Small random workcells (dt 0.25 .. 0.5), so that the Python loop nest stays quick."""
    return random_workcells(dts=(0.25, 0.3, 0.4, 0.5))


@settings(max_examples=25, deadline=None)
@given(s=random_scenarios(), variant=st.sampled_from(list(Variant)))
def test_bit_identical_on_random_scenarios(s, variant):
    assert_same(s, variant)


def test_an_edited_nest_is_what_runs():
    # The rest layer left unstored: the marker 2 shows through, so the comparison has teeth.
    calls = []

    def nest(N, m, n, P, SL, SR, rule, region_left, region_right, region_rest, inter):
        calls.append(rule)
        builtdr_loop_nest(N - 1, m, n, P, SL, SR, rule, region_left, region_right,
                          region_rest, inter)
    s = coarse(SCENARIOS[0])
    dr = build_dr_loops(s, "modified", nest=nest)
    assert calls == [Variant.MODIFIED.rule] and (dr == 2).any()
