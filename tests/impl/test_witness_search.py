"""The searches' witnesses (``with_witness=True``): the reference's and the fast search's are the
same arrays, they agree with the spec's opt_path, and asking for one changes neither the path
nor the costs."""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from cfmpa.impl import search_opt_path, search_opt_path_fast
from cfmpa.impl._search import WitnessLabels
from cfmpa.spec import MOVES, SearchStatus, check_witness, opt_path
from dr_strategies import random_dr

WAIT = MOVES.index((0, 0))
STOP = np.abs(np.asarray(MOVES)).sum(axis=1)


def drs(max_n=6, max_side=8):
    return random_dr(max_n=max_n, max_side=max_side,
                     density=st.sampled_from([0.0, 0.1, 0.25, 0.4, 0.6]), free_ends=None)


def assert_agree(dr, start, goal):
    ref = search_opt_path(dr, start, goal, with_witness=True)
    fast = search_opt_path_fast(dr, start, goal, with_witness=True)
    plain = search_opt_path_fast(dr, start, goal)
    # The answer is the same with a witness and without, path and costs alike.
    assert ref == fast == plain == search_opt_path(dr, start, goal)
    assert ref.path == fast.path == plain.path
    assert ref.witness.kind == fast.witness.kind
    for name, a in ref.witness.arrays.items():
        b = fast.witness.arrays[name]
        assert a.dtype == b.dtype and a.shape == (dr.shape[0], 9, *dr.shape[1:])
        assert np.array_equal(a, b), name
    spec = opt_path(dr, start, goal)
    assert spec.status is ref.status
    w = fast.witness
    N = dr.shape[0] - 1
    if ref.status is SearchStatus.FOUND:
        none = np.iinfo(w.j1.dtype).max
        at = (N, slice(None), goal[0], goal[1])
        ok = w.j1[at] != none
        least = min((int(a), int(b) + int(c)) for a, b, c, k in
                    zip(w.j1[at], w.j2[at], STOP, ok) if k)
        assert least == (spec.J1, spec.J2) == (ref.J1, ref.J2)
        assert (w.j1[0, WAIT, start[0], start[1]], w.j2[0, WAIT, start[0], start[1]]) == (0, 0)
    else:
        assert not w.reachable[N, :, goal[0], goal[1]].any() or dr[N][goal]
    assert check_witness(dr, start, goal, fast, w) == []
    return ref


@settings(max_examples=300, deadline=None)
@given(case=drs())
def test_reference_and_fast_witnesses_agree_with_opt_path(case):
    assert_agree(*case)


@pytest.mark.slow
@settings(max_examples=2000, deadline=None)
@given(case=drs(max_n=10, max_side=14))
def test_reference_and_fast_witnesses_agree_with_opt_path_many(case):
    assert_agree(*case)


def test_each_outcome_has_its_witness():
    free = np.zeros((4, 6, 6), dtype=np.uint8)
    assert assert_agree(free, (0, 0), (5, 3)).witness.kind == "labels"
    start_blocked = free.copy()
    start_blocked[0, 0, 0] = 1
    r = assert_agree(start_blocked, (0, 0), (5, 3))
    assert r.witness.kind == "reachable" and not r.witness.reachable.any()
    goal_blocked = free.copy()
    goal_blocked[3, 5, 3] = 1
    r = assert_agree(goal_blocked, (0, 0), (5, 3))
    assert r.witness.kind == "reachable" and r.witness.reachable.sum() > 100
    wall = free.copy()
    wall[:, 2, :] = 1
    assert assert_agree(wall, (0, 0), (5, 3)).witness.kind == "reachable"


def test_labels_at_the_capped_step_cover_the_whole_reachable_grid():
    # The capped step's buckets run on past the goal: a state far behind the start is labelled.
    dr = np.zeros((3, 10, 10), dtype=np.uint8)
    r = search_opt_path_fast(dr, (5, 5), (6, 6), with_witness=True)
    assert r.J1 == 2
    assert r.witness.j1[2, MOVES.index((-1, -1)), 0, 0] == 10      # (5,5) to (0,0): 5 diagonals
    assert (r.witness.j1[2, WAIT] != np.iinfo(r.witness.j1.dtype).max).all()


def test_labels_widen_to_uint32_when_uint16_is_too_small():
    w = WitnessLabels(2, 1, 2)
    assert w.j1.dtype == np.uint16
    keys = np.full((9, 1, 2), np.int64(1) << np.int64(61))
    keys[WAIT, 0, 0] = (np.int64(70000) << np.int64(31)) | 5
    w.put(2, keys)
    assert w.j1.dtype == w.j2.dtype == np.uint32
    assert (w.j1[2, WAIT, 0, 0], w.j2[2, WAIT, 0, 0]) == (70000, 5)
    assert w.j1[2, WAIT, 0, 1] == np.iinfo(np.uint32).max
