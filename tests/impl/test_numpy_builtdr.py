"""build_dr_numpy (the kernel a run uses while the fast ones compile, docs/model.md §7.5) gives
the reference's D_R bit for bit: bundled scenarios, random ones, polygons it cannot decide, and
the pairs it leaves to the reference (thresholds widened so that many do)."""

from __future__ import annotations

import contextlib
import dataclasses
import math
import sys
from pathlib import Path

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

import factory
import mutant_module
from cfmpa.impl import _numpy_builtdr, build_dr, right_regions
from cfmpa.impl._builtdr import RightRegions
from cfmpa.impl._numpy_builtdr import build_dr_numpy
from cfmpa.spec import Variant, load_scenario, make_grid
from dr_strategies import random_workcells

SCENARIOS = sorted(Path(__file__).resolve().parents[2].joinpath("scenarios").glob("*.toml"))
SMALL = [p for p in SCENARIOS if p.stem != "default"]


def differing(s, variant, grid=None, right=None, **kw):
    g = grid or make_grid(s)
    rr = right or right_regions(s, g)
    ref = build_dr(s, variant, g, right=rr, **kw)
    fast = build_dr_numpy(s, variant, g, right=rr, **kw)
    assert fast.dtype == ref.dtype == np.uint8
    assert fast.shape == ref.shape == g.shape
    return ref, np.argwhere(fast != ref)


def assert_same(s, variant, **kw):
    ref, diff = differing(s, variant, **kw)
    assert diff.size == 0, f"{len(diff)} cells differ, first (k, i, j) = {diff[:5].tolist()}"
    return ref


@pytest.mark.parametrize("path", SMALL, ids=lambda p: p.stem)
def test_bit_identical_on_bundled_scenarios_coarser(path):
    # Each bundled workcell at 3x its time step (a grid 9x smaller): the fast stand-in for the
    # slow test below, which runs them as they are.
    s = load_scenario(path)
    ref = assert_same(dataclasses.replace(s, dt=3 * s.dt), Variant.MODIFIED)
    assert 0 < ref.mean() < 1   # both decisions occur, so equality has teeth


@pytest.mark.slow
@pytest.mark.parametrize("variant", list(Variant), ids=str)
@pytest.mark.parametrize("path", SCENARIOS, ids=lambda p: p.stem)
def test_bit_identical_on_every_bundled_scenario(path, variant):
    ref = assert_same(load_scenario(path), variant)
    assert 0 < ref.mean() < 1


@pytest.mark.parametrize("variant", list(Variant), ids=str)
def test_bit_identical_on_a_coarse_default(variant):
    s = factory.scenario(dt=0.08, right__start_cell=[10, 25], right__goal_cell=[38, 15])
    assert_same(s, variant)


@pytest.mark.parametrize("variant", list(Variant), ids=str)
def test_pairs_left_to_the_reference_are_decided_as_it_does(monkeypatch, variant):
    # A margin of 5 cm sends every pair near contact to blocked_against; eps = 1 cm makes the
    # reference's exact-distance band (0, eps] matter. The output must still be identical.
    monkeypatch.setattr(_numpy_builtdr, "MARGIN_REL", 0.05)
    calls = []
    real = _numpy_builtdr.blocked_against
    monkeypatch.setattr(_numpy_builtdr, "blocked_against",
                        lambda a, b, eps: calls.append(len(b)) or real(a, b, eps))
    assert_same(factory.scenario(), variant, eps=0.01)
    assert sum(calls) > 50   # the fallback really ran, on many pairs


def test_the_kernel_decides_most_pairs_itself(monkeypatch):
    # With the real margin the per-cell pairs never reach the reference routine on the coarse
    # default (only link 1's rows, which are always its).
    calls = []
    real = _numpy_builtdr.blocked_against
    monkeypatch.setattr(_numpy_builtdr, "blocked_against",
                        lambda a, b, eps: calls.append(len(b)) or real(a, b, eps))
    s = factory.scenario(dt=0.08, right__start_cell=[10, 25], right__goal_cell=[38, 15])
    g = make_grid(s)
    build_dr_numpy(s, Variant.ORIGINAL, g)
    assert calls and all(c == g.m for c in calls)


@pytest.mark.parametrize("margin", [-0.05, 0.0])
def test_seeded_fault_a_margin_too_small_is_caught(monkeypatch, margin):
    # The margin is what makes the kernel's own verdicts safe: without it (or negative), gaps
    # within the rounding of 0 or eps are decided here, and with eps = 1 cm and a negative
    # margin of 5 cm the comparison above sees cells differ.
    monkeypatch.setattr(_numpy_builtdr, "MARGIN_REL", margin)
    s = factory.scenario()
    _, diff = differing(s, Variant.ORIGINAL, eps=0.01)
    if margin < 0:
        assert diff.size > 0


def random_scenarios():
    """Coarse random workcells (m, n <= ~40, N <= ~15), tools and heights too."""
    return random_workcells(dts=(0.1, 0.125, 0.2, 0.25), tools=True)


@settings(max_examples=40, deadline=None)
@given(s=random_scenarios(), variant=st.sampled_from(list(Variant)))
def test_bit_identical_on_random_scenarios(s, variant):
    assert_same(s, variant)


@pytest.mark.parametrize("poison", ["nan", "inf", "huge"])
def test_polygons_the_kernel_cannot_decide_go_to_the_reference(poison):
    s = factory.scenario()
    g = make_grid(s)
    rr = right_regions(s, g)
    link1, link2 = rr.link1.copy(), rr.link2.copy()
    if poison == "huge":
        link2[3, 5] *= 1e150
        link1[7] *= 1e150
    else:
        bad = math.nan if poison == "nan" else math.inf
        link2[3, 5, 0, 0] = bad
        link1[7, 2, 1] = bad
    poisoned = RightRegions(link1=link1, link2=link2)
    # An infinite vertex makes its polygon's edge normals inf / inf (impl/_collide.py,
    # PolygonSet.of): numpy says "invalid value", expected here and only here; the kernel sends
    # a coordinate not finite to the reference (docs/model.md §7.5), whose answer is compared.
    with (pytest.warns(RuntimeWarning, match="invalid value") if poison == "inf"
          else contextlib.nullcontext()):
        for variant in Variant:
            ref = assert_same(s, variant, grid=g, right=poisoned)
            if poison == "nan":
                assert ref[:, 3, 5].all() and ref[:, 7, :].all()
                assert not ref.all()


@pytest.mark.filterwarnings("ignore::RuntimeWarning")
@pytest.mark.parametrize("field, value", [("width", 1e160), ("width", 1e308),
                                          ("links", (1e200, 0.3))])
def test_absurd_magnitudes_past_the_loader_block_every_cell(field, value):
    s0 = factory.scenario()
    s = dataclasses.replace(s0, left=dataclasses.replace(s0.left, **{field: value}))
    for variant in (Variant.ORIGINAL, Variant.TIGHT):
        assert assert_same(s, variant).all()


#: One-line faults planted in a copy of the kernel: each must make the coarse default differ.
MUTANTS = {
    # the gap along a's normals skips b's second vertex
    "a-normals-vertex-off-by-one": [("for v in range(1, len(x)):", "for v in range(2, len(x)):")],
    # the gap along b's normals skips a's second vertex
    "b-normals-vertex-off-by-one": [("for v in range(1, len(av)):",
                                     "for v in range(2, len(av)):")],
    # the boxes' upper x bound taken as the lower one
    "box-wrong-bound": [("self.x.max(1), self.y.max(1))", "self.x.min(1), self.y.max(1))")],
}


@pytest.mark.parametrize("name", sorted(MUTANTS))
def test_seeded_fault_in_a_copy_is_caught(monkeypatch, name):
    mod = mutant_module.mutated_module(name, "impl/_numpy_builtdr.py", MUTANTS[name],
                                       lambda k, v: monkeypatch.setitem(sys.modules, k, v))
    s = factory.scenario(dt=0.08, right__start_cell=[10, 25], right__goal_cell=[38, 15])
    g = make_grid(s)
    rr = right_regions(s, g)
    diff = 0
    for variant in (Variant.ORIGINAL, Variant.MODIFIED):
        ref = build_dr(s, variant, g, right=rr)
        assert np.array_equal(build_dr_numpy(s, variant, g, right=rr), ref)   # the original
        diff += int((mod.build_dr_numpy(s, variant, g, right=rr) != ref).sum())
    assert diff > 0, f"mutant {name} not caught"
