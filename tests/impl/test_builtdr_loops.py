"""The loop-form BuiltDR (Algorithm 1 as written, the source the proofs extract) gives build_dr's
and build_dr_fast's D_R bit for bit: random small workcells and the bundled scenarios at dt 0.4."""

from __future__ import annotations

import math
import tomllib
from pathlib import Path

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from cfmpa.impl import build_dr, build_dr_fast, build_dr_loops, builtdr_loop_nest, right_regions
from cfmpa.spec import Variant, joint_points, make_grid, parse_scenario

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


@st.composite
def random_scenarios(draw):
    """Random workcells with small grids (dt 0.25 .. 0.5): bases, links, widths, speeds, start
    and goal vary; the right base is near enough for the arms to meet."""
    dt = draw(st.sampled_from([0.25, 0.3, 0.4, 0.5]))
    f = st.floats

    def arm(base):
        return {"base": base, "links": [draw(f(0.05, 0.5)), draw(f(0.05, 0.5))],
                "width": draw(f(0.005, 0.15)), "omega": [draw(f(1.2, 3.0)), draw(f(1.2, 3.0))]}

    left = arm([draw(f(-0.2, 0.2)), draw(f(-0.2, 0.2))])
    start = [draw(f(-3.2, 3.2)), draw(f(-3.2, 3.2))]
    left["start"] = start
    left["goal"] = [start[q] + draw(f(-1.5, 1.5)) for q in range(2)]
    right = arm([draw(f(0.0, 0.9)), draw(f(-0.4, 0.4))])
    limits = []
    for q in range(2):
        lo = draw(f(-math.pi, 0.0))
        limits.append([lo, lo + draw(f(0.5, 2 * math.pi))])
    right["limits"] = limits
    size = [joint_points(limits[q][0], limits[q][1], right["omega"][q], dt) for q in range(2)]
    right["start_cell"] = [draw(st.integers(0, size[q] - 1)) for q in range(2)]
    right["goal_cell"] = [draw(st.integers(0, size[q] - 1)) for q in range(2)]
    return parse_scenario({"name": "random", "purpose": "hypothesis", "dt": dt, "left": left,
                           "right": right}, check_budget=False)


@settings(max_examples=25, deadline=None)
@given(s=random_scenarios(), variant=st.sampled_from(list(Variant)))
def test_bit_identical_on_random_scenarios(s, variant):
    assert_same(s, variant)


def test_an_edited_nest_is_what_runs():
    # The rest layer left unstored: the marker 2 shows through, so the comparison has teeth.
    calls = []

    def nest(N, m, n, P, SL, SR, variant, region_left, region_right, region_rest, inter):
        calls.append(variant)
        builtdr_loop_nest(N - 1, m, n, P, SL, SR, variant, region_left, region_right,
                          region_rest, inter)
    s = coarse(SCENARIOS[0])
    dr = build_dr_loops(s, "modified", nest=nest)
    assert calls == ["modified"] and (dr == 2).any()
