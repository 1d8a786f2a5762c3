"""The searches with compact back-pointers (``BackPointers``: the box of s moves per step) and
one layer of D_R's free mask at a time return exactly what the search before that change
returned (tests/legacy_search.py): status, reason, (J1, J2), the path with its tie-break,
and with ``with_witness`` the same witness arrays."""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

import legacy_search
from cfmpa.impl._fast_search import search_opt_path_fast
from cfmpa.impl._search import BackPointers, search_opt_path
from dr_strategies import random_dr


def random_drs() -> st.SearchStrategy:
    # Long N against small grids too, so that the box of s moves covers the grid and stops
    # growing; density 0 gives the most ties.
    return random_dr(max_n=12, max_side=9, density=st.sampled_from([0.0, 0.1, 0.25, 0.4, 0.6]),
                     free_ends=None)


def same_witness(a, b):
    if a is None or b is None:
        return a is b
    if a.kind != b.kind:
        return False
    return all(np.array_equal(np.asarray(a.arrays[k]), np.asarray(b.arrays[k]))
               and np.asarray(a.arrays[k]).dtype == np.asarray(b.arrays[k]).dtype
               for k in b.arrays)


@settings(max_examples=250, deadline=None)
@given(case=random_drs(), with_witness=st.booleans())
def test_new_searches_return_the_old_result(case, with_witness):
    dr, start, goal = case
    old = legacy_search.search_opt_path(dr, start, goal, with_witness=with_witness)
    for new in (search_opt_path(dr, start, goal, with_witness=with_witness),
                search_opt_path_fast(dr, start, goal, progress=False, with_witness=with_witness)):
        assert (new.status, new.reason, new.path) == (old.status, old.reason, old.path)
        assert (new.J1, new.J2) == (old.J1, old.J2)
        assert same_witness(new.witness, old.witness)


def test_a_long_free_run_takes_the_same_path():
    # Many ties, N beyond the grid's radius from the start, goal far from the start.
    dr = np.zeros((15, 7, 11), dtype=np.uint8)
    dr[3:9, 2:5, 4] = 1
    old = legacy_search.search_opt_path(dr, (6, 0), (0, 10))
    assert old.path
    assert search_opt_path(dr, (6, 0), (0, 10)) == old
    assert search_opt_path_fast(dr, (6, 0), (0, 10), progress=False) == old


def test_back_pointers_hold_the_box_of_s_moves_only():
    bp = BackPointers((1, 5), 4, 30)
    for s in (1, 2, 3):
        assert bp.new(s).shape == (9, min(4, 1 + s + 1) - max(0, 1 - s), 2 * s + 1)
    assert bp.box(3) == (0, 4, 2, 9)
    bp.layers[2][4, 3, 6] = 7
    assert bp.at(3, 4, 3, 8) == 7
    with pytest.raises(AssertionError):
        bp.at(3, 4, 3, 9)          # 4 moves from the start: no state there at step 3
    with pytest.raises(AssertionError):
        bp.new(5)                   # steps are made in order


def test_the_unwind_catches_a_wrong_back_pointer(monkeypatch):
    # Seeded fault: every back-pointer read says "arrived by (-1, -1)"; the walk back must notice
    # (it leaves the box of s moves, or ends at another cell than the start).
    dr = np.zeros((6, 6, 6), dtype=np.uint8)
    assert search_opt_path(dr, (0, 0), (5, 5)).path
    monkeypatch.setattr(BackPointers, "at", lambda self, s, d, i, j: 0)
    for search in (search_opt_path, search_opt_path_fast):
        with pytest.raises(AssertionError):
            search(dr, (0, 0), (5, 5))
