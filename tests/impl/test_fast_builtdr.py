"""build_dr_fast gives the reference's D_R bit for bit: bundled scenarios, random ones, and the
pairs its kernel leaves to the reference (thresholds widened so that many do)."""

from __future__ import annotations

import io
import math
import sys
from pathlib import Path

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

import factory
from cfmpa.impl import (
    _fast_builtdr,
    _progress,
    build_dr,
    kernel_threads,
    right_regions,
    set_kernel_threads,
)
from cfmpa.impl._fast_builtdr import build_dr_fast
from cfmpa.spec import Variant, load_scenario, make_grid, parse_scenario
from dr_strategies import random_workcells

SCENARIOS = sorted(Path(__file__).resolve().parents[2].joinpath("scenarios").glob("*.toml"))
SMALL = [p for p in SCENARIOS if p.stem != "default"]
DEFAULT = [p for p in SCENARIOS if p.stem == "default"]


def assert_same(s, variant, grid=None, **kw):
    g = grid or make_grid(s)
    rr = right_regions(s, g)
    ref = build_dr(s, variant, g, right=rr, **kw)
    fast = build_dr_fast(s, variant, g, right=rr, **kw)
    assert fast.dtype == ref.dtype == np.uint8
    assert fast.shape == ref.shape == g.shape
    diff = np.argwhere(fast != ref)
    assert diff.size == 0, f"{len(diff)} cells differ, first (k, i, j) = {diff[:5].tolist()}"
    return ref


@pytest.mark.parametrize("variant", list(Variant), ids=str)
@pytest.mark.parametrize("path", SMALL, ids=lambda p: p.stem)
def test_bit_identical_on_bundled_scenarios(path, variant):
    ref = assert_same(load_scenario(path), variant)
    assert 0 < ref.mean() < 1   # both decisions occur, so equality has teeth


@pytest.mark.slow
@pytest.mark.parametrize("variant", list(Variant), ids=str)
@pytest.mark.parametrize("path", DEFAULT, ids=lambda p: p.stem)
def test_bit_identical_on_the_default_scenario(path, variant):
    assert_same(load_scenario(path), variant)


@pytest.mark.parametrize("variant", list(Variant), ids=str)
def test_bit_identical_on_a_coarse_default(variant):
    # The default workcell at 4x the time step: the default run's stand-in for the slow test.
    s = parse_scenario(factory.doc(dt=0.08, right__start_cell=[10, 25], right__goal_cell=[38, 15]),
                       check_budget=False)
    assert_same(s, variant)


@pytest.mark.parametrize("variant", list(Variant), ids=str)
def test_pairs_left_to_the_reference_are_decided_as_it_does(monkeypatch, variant):
    # A margin of 5 cm sends every pair near contact to blocked_against; eps = 1 cm makes the
    # reference's exact-distance band (0, eps] matter. The output must still be identical.
    monkeypatch.setattr(_fast_builtdr, "MARGIN_REL", 0.05)
    s = factory.scenario()
    calls = []
    real = _fast_builtdr.blocked_against
    monkeypatch.setattr(_fast_builtdr, "blocked_against",
                        lambda *a: calls.append(len(a[1])) or real(*a))
    assert_same(s, variant, eps=0.01)
    assert sum(calls) > 50   # the fallback really ran, on many pairs


def test_kernel_decides_default_pairs_itself(monkeypatch):
    # With the real margin no pair of the coarse default needs the reference routine.
    calls = []
    monkeypatch.setattr(_fast_builtdr, "blocked_against", lambda *a: calls.append(a) or None)
    s = factory.scenario(dt=0.08, right__start_cell=[10, 25], right__goal_cell=[38, 15])
    build_dr_fast(s, Variant.ORIGINAL)
    assert calls == []


def random_scenarios():
    """Coarse random workcells (m, n <= ~40, N <= ~15)."""
    return random_workcells(dts=(0.1, 0.125, 0.2, 0.25))


@settings(max_examples=40, deadline=None)
@given(s=random_scenarios(), variant=st.sampled_from(list(Variant)))
def test_bit_identical_on_random_scenarios(s, variant):
    assert_same(s, variant)


class FakeTerminal(io.StringIO):
    def isatty(self) -> bool:
        return True


def test_progress_is_silent_when_stderr_is_not_a_terminal(monkeypatch, capsys):
    monkeypatch.setattr(_progress, "PROGRESS_MIN_CELLS", 0)   # even a tiny grid counts as large
    build_dr_fast(factory.scenario(), Variant.TIGHT)
    assert capsys.readouterr().err == ""


def test_progress_is_silent_for_small_grids_on_a_terminal(monkeypatch):
    term = FakeTerminal()
    monkeypatch.setattr(sys, "stderr", term)
    build_dr_fast(factory.scenario(), Variant.TIGHT)
    assert term.getvalue() == ""


def test_progress_draws_a_bar_on_a_terminal_for_large_grids(monkeypatch):
    term = FakeTerminal()
    monkeypatch.setattr(sys, "stderr", term)
    monkeypatch.setattr(_progress, "PROGRESS_MIN_CELLS", 0)
    s = factory.scenario()
    build_dr_fast(s, Variant.TIGHT)
    rows = make_grid(s).m                  # the bar counts rows, each decided in every layer
    out = term.getvalue()
    assert out.startswith("\rBuiltDR tight ") and f" {rows}/{rows} [" in out
    assert out.endswith("\n") and "ETA" in out


def test_progress_false_silences_even_a_terminal(monkeypatch):
    term = FakeTerminal()
    monkeypatch.setattr(sys, "stderr", term)
    monkeypatch.setattr(_progress, "PROGRESS_MIN_CELLS", 0)
    build_dr_fast(factory.scenario(), Variant.TIGHT, progress=False)
    assert term.getvalue() == ""


@pytest.mark.filterwarnings("ignore::RuntimeWarning")   # inf - inf in the reference's normals
@pytest.mark.parametrize("poison", ["nan", "inf", "huge"])
def test_polygons_the_kernel_cannot_decide_go_to_the_reference(poison):
    # A NaN or infinite vertex, or a polygon far beyond MAX_COORD, is left to blocked_against:
    # identical output, and a NaN vertex blocks its cell in every layer (an infinite one need
    # not: its bounding box can still prove the pair apart).
    from cfmpa.impl._builtdr import RightRegions

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
    for variant in Variant:
        ref = build_dr(s, variant, g, right=poisoned)
        fast = build_dr_fast(s, variant, g, right=poisoned)
        assert np.array_equal(ref, fast)
        if poison == "nan":
            assert ref[:, 3, 5].all() and ref[:, 7, :].all()
            assert not ref.all()


@pytest.mark.filterwarnings("ignore::RuntimeWarning")
@pytest.mark.parametrize("field, value", [("width", 1e160), ("width", 1e308),
                                          ("links", (1e200, 0.3))])
def test_absurd_magnitudes_past_the_loader_block_every_cell_in_both_kernels(field, value):
    # The loader refuses these; built anyway, the arm covers the workcell: all blocked.
    import dataclasses

    s0 = factory.scenario()
    s = dataclasses.replace(s0, left=dataclasses.replace(s0.left, **{field: value}))
    g = make_grid(s)
    for variant in (Variant.ORIGINAL, Variant.TIGHT):
        ref = build_dr(s, variant, g)
        assert ref.all()
        assert np.array_equal(build_dr_fast(s, variant, g), ref)


def test_one_thread_and_two_give_the_same_bits():
    # The rows (and the polygons packed, the rows turned) are shared out among the threads;
    # any split must give the same D_R.
    s = factory.scenario(dt=0.08, right__start_cell=[10, 25], right__goal_cell=[38, 15])
    before = kernel_threads()
    out = {}
    try:
        for k in (1, 2):
            set_kernel_threads(k)
            out[k] = build_dr_fast(s, Variant.MODIFIED, progress=False)
    finally:
        set_kernel_threads(before)
    assert np.array_equal(out[1], out[2]) and 0 < out[1].mean() < 1
    for bad in (0, True, 1.5):
        with pytest.raises(ValueError, match="k="):
            set_kernel_threads(bad)
