"""search_opt_path_fast returns exactly what search_opt_path returns: (J1, J2), status, reason
and the path itself (tie-break included), on random D_R arrays and on the bundled scenarios."""

from __future__ import annotations

import io
import sys
from pathlib import Path

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from cfmpa.errors import InputError
from cfmpa.impl import _progress
from cfmpa.impl._fast_builtdr import build_dr_fast
from cfmpa.impl._fast_search import search_opt_path_fast
from cfmpa.impl._search import search_opt_path
from cfmpa.spec import Variant, load_scenario
from cfmpa.spec._paths import (
    REASON_GOAL_BLOCKED,
    REASON_START_BLOCKED,
    REASON_UNREACHABLE,
    SearchStatus,
    is_path,
)
from dr_strategies import random_dr

SCENARIOS = sorted(Path(__file__).resolve().parents[2].joinpath("scenarios").glob("*.toml"))
SMALL = [p for p in SCENARIOS if p.stem != "default"]
DEFAULT = [p for p in SCENARIOS if p.stem == "default"]


def assert_same(dr, start, goal):
    ref = search_opt_path(dr, start, goal)
    fast = search_opt_path_fast(dr, start, goal)
    assert fast == ref
    if fast.status is SearchStatus.FOUND:
        assert is_path(fast.path, dr, start, goal)
    return ref


def random_drs() -> st.SearchStrategy:
    """D_R arrays with few to many blocked cells (none at all gives the most ties)."""
    return random_dr(max_n=7, max_side=9, density=st.sampled_from([0.0, 0.1, 0.25, 0.4, 0.6]),
                     free_ends=False)


@settings(max_examples=300, deadline=None)
@given(case=random_drs())
def test_same_result_on_random_drs(case):
    assert_same(*case)


def test_every_reason_and_ties_occur_and_agree():
    # Fixed cases for each outcome, so the random test's coverage is not left to chance.
    free = np.zeros((4, 6, 6), dtype=np.uint8)
    assert assert_same(free, (0, 0), (5, 3)).J1 == 8          # many optimal paths: tie-break
    start_blocked = free.copy()
    start_blocked[0, 0, 0] = 1
    assert assert_same(start_blocked, (0, 0), (5, 3)).reason == REASON_START_BLOCKED
    goal_blocked = free.copy()
    goal_blocked[3, 5, 3] = 1
    assert assert_same(goal_blocked, (0, 0), (5, 3)).reason == REASON_GOAL_BLOCKED
    wall = free.copy()
    wall[:, 2, :] = 1
    assert assert_same(wall, (0, 0), (5, 3)).reason == REASON_UNREACHABLE
    sweep = free.copy()
    sweep[1:3, 5, 3] = 1          # the goal is swept by the principal: arrive late, or detour
    assert assert_same(sweep, (5, 0), (5, 3)).status is SearchStatus.FOUND


def test_bad_inputs_are_refused_as_the_reference_refuses_them():
    dr = np.zeros((3, 4, 4), dtype=np.uint8)
    for args in ((dr, (0, 0), (4, 0)), (dr[0], (0, 0), (1, 1)), (dr, (-1, 0), (1, 1))):
        with pytest.raises(InputError) as fast:
            search_opt_path_fast(*args)
        with pytest.raises(InputError) as ref:
            search_opt_path(*args)
        assert str(fast.value) == str(ref.value)


@pytest.mark.parametrize("variant", list(Variant), ids=str)
@pytest.mark.parametrize("path", SMALL, ids=lambda p: p.stem)
def test_same_result_on_bundled_scenarios(path, variant):
    s = load_scenario(path)
    assert_same(build_dr_fast(s, variant), s.right.start_cell, s.right.goal_cell)


@pytest.mark.slow
@pytest.mark.parametrize("variant", list(Variant), ids=str)
@pytest.mark.parametrize("path", DEFAULT, ids=lambda p: p.stem)
def test_same_result_on_the_default_scenario(path, variant):
    s = load_scenario(path)
    ref = assert_same(build_dr_fast(s, variant), s.right.start_cell, s.right.goal_cell)
    assert ref.status is SearchStatus.FOUND


class FakeTerminal(io.StringIO):
    def isatty(self) -> bool:
        return True


def test_search_progress_only_on_a_terminal(monkeypatch, capsys):
    monkeypatch.setattr(_progress, "PROGRESS_MIN_CELLS", 0)
    dr = np.zeros((5, 6, 6), dtype=np.uint8)
    search_opt_path_fast(dr, (0, 0), (5, 5))
    assert capsys.readouterr().err == ""                    # pytest's stderr is no terminal
    term = FakeTerminal()
    monkeypatch.setattr(sys, "stderr", term)
    search_opt_path_fast(dr, (0, 0), (5, 5))
    assert term.getvalue().startswith("\rsearch ") and " 5/5 [" in term.getvalue()
    assert term.getvalue().endswith("\n")
