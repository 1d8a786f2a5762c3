"""search_opt_path_numpy (the search a run uses while the fast kernels compile, docs/model.md
§7.5) returns exactly what search_opt_path returns: status, reason, (J1, J2), the path (tie-break
included) and, with a witness, the same witness arrays, which the spec's checker accepts; a
planted off-by-one in a copy of it is caught by these comparisons."""

from __future__ import annotations

import dataclasses
import sys
from pathlib import Path

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

import mutant_module
from cfmpa.errors import InputError
from cfmpa.impl import _search
from cfmpa.impl._numpy_builtdr import build_dr_numpy
from cfmpa.impl._numpy_search import search_opt_path_numpy
from cfmpa.impl._search import search_opt_path
from cfmpa.spec import SearchStatus, Variant, check_witness, load_scenario, make_grid
from cfmpa.spec._paths import (
    REASON_GOAL_BLOCKED,
    REASON_START_BLOCKED,
    REASON_UNREACHABLE,
    is_path,
)
from dr_strategies import random_dr

SCENARIOS = sorted(Path(__file__).resolve().parents[2].joinpath("scenarios").glob("*.toml"))


def differences(dr, start, goal, search=search_opt_path_numpy):
    """What differs between ``search`` and the reference, with and without a witness (empty:
    nothing); the witness is also checked by the spec's checker."""
    out = []
    for with_witness in (True, False):
        ref = search_opt_path(dr, start, goal, with_witness=with_witness)
        got = search(dr, start, goal, with_witness=with_witness)
        for field in ("status", "reason", "J1", "J2", "path"):
            if getattr(ref, field) != getattr(got, field):
                out.append(f"{field}: {getattr(got, field)!r} != {getattr(ref, field)!r}")
        if not with_witness:
            assert got.witness is None
            continue
        assert ref.witness.kind == got.witness.kind
        for name, a in ref.witness.npz_members().items():
            b = np.asarray(got.witness.npz_members()[name])
            a = np.asarray(a)
            if a.dtype != b.dtype or not np.array_equal(a, b):
                out.append(f"witness {name}")
        out += [f"check_witness: {f}" for f in check_witness(dr, start, goal, got, got.witness)]
        ref.witness.close()
        got.witness.close()
    return out


def assert_same(dr, start, goal):
    assert differences(dr, start, goal) == []
    res = search_opt_path_numpy(dr, start, goal, with_witness=False)
    if res.status is SearchStatus.FOUND:
        assert is_path(res.path, dr, start, goal)
    return res


def drs(max_n=7, max_side=9):
    return random_dr(max_n=max_n, max_side=max_side,
                     density=st.sampled_from([0.0, 0.1, 0.25, 0.4, 0.6]), free_ends=None)


@settings(max_examples=150, deadline=None)
@given(case=drs())
def test_same_result_and_witness_on_random_drs(case):
    assert_same(*case)


@settings(max_examples=40, deadline=None)
@given(case=random_dr(max_n=25, max_side=30, density=st.sampled_from([0.0, 0.2, 0.45]),
                      free_ends=True))
def test_same_result_and_witness_on_larger_random_drs(case):
    # N well past the grid's size and well below it: the box of s moves clipped or not.
    assert_same(*case)


def test_every_reason_and_ties_occur_and_agree():
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
    one = np.zeros((2, 1, 1), dtype=np.uint8)                 # one cell: the box clipped at once
    assert tuple(assert_same(one, (0, 0), (0, 0)).path) == ((0, 0),)


def test_spilled_labels_and_pointers_give_the_same_answer_and_witness(monkeypatch):
    # Past spec.SPILL_BYTES the labels go to temporary files and the pointers to another: what
    # a full-size grid does (the default scenario's witness is spilled).
    monkeypatch.setattr(_search, "spill_wanted", lambda nbytes: True)
    monkeypatch.setattr(_search, "BACK_POINTER_BYTES", 0)
    rng = np.random.default_rng(7)
    for _ in range(4):
        dr = (rng.random((9, 12, 14)) < 0.25).astype(np.uint8)
        dr[0, 1, 2] = dr[-1, 10, 11] = 0
        assert differences(dr, (1, 2), (10, 11)) == []


def test_bad_inputs_are_refused_as_the_reference_refuses_them():
    dr = np.zeros((3, 4, 4), dtype=np.uint8)
    for args in ((dr, (0, 0), (4, 0)), (dr[0], (0, 0), (1, 1)), (dr, (-1, 0), (1, 1))):
        with pytest.raises(InputError) as got:
            search_opt_path_numpy(*args)
        with pytest.raises(InputError) as ref:
            search_opt_path(*args)
        assert str(got.value) == str(ref.value)


@pytest.mark.parametrize("path", SCENARIOS, ids=lambda p: p.stem)
def test_same_result_on_bundled_scenarios(path):
    # The full-size grids (316 x 316) at twice their time step, their ends moved to the same
    # fraction of the grid (the slow test below runs them as they are).
    s = load_scenario(path)
    start, goal = s.right.start_cell, s.right.goal_cell
    big = make_grid(s).m > 200
    if big:
        s = dataclasses.replace(s, dt=2 * s.dt)
    dr = build_dr_numpy(s, Variant.MODIFIED)
    if big:
        m, n = dr.shape[1:]
        start, goal = ((c[0] * m // 316, c[1] * n // 316) for c in (start, goal))
        dr[0][start] = dr[-1][goal] = 0
    res = assert_same(dr, start, goal)
    assert res.status is SearchStatus.FOUND


@pytest.mark.slow
@pytest.mark.parametrize("variant", list(Variant), ids=str)
@pytest.mark.parametrize("path", SCENARIOS, ids=lambda p: p.stem)
def test_same_result_on_every_bundled_scenario(path, variant):
    s = load_scenario(path)
    assert_same(build_dr_numpy(s, variant), s.right.start_cell, s.right.goal_cell)


# ------------------------------------------------------------------------ seeded faults ----

#: One-line faults planted in a copy of the module: each must make some case below differ.
MUTANTS = {
    # the source rows of a DAG step one short at the box's far edge (a shape error)
    "box-row-off-by-one": [("i0, i1 = max(r0, R0 - di), min(r1, R1 - di)",
                            "i0, i1 = max(r0, R0 - di), min(r1 - 1, R1 - di)")],
    # the free mask of the box of s moves read one column off (no shape error: found by value)
    "free-mask-column-off-by-one": [("free[s, nbox[0]:nbox[1], nbox[2]:nbox[3]]",
                                     "np.roll(free[s], 1, axis=1)[nbox[0]:nbox[1], "
                                     "nbox[2]:nbox[3]]")],
    # ties among a state's candidates go to the largest previous move
    "tie-largest-move": [("rank = ((key & J2_MASK) << _PREV_BITS) | prev",
                          "rank = ((key & J2_MASK) << _PREV_BITS) | (8 - prev)")],
    # an equal static key replaces the DAG's label
    "not-strict": [("better = key < keys[to]", "better = key <= keys[to]")],
    # a diagonal move's successor put one bucket early
    "bucket-off-by-one": [("(bucket + 2, to[diagonal])", "(bucket + 1, to[diagonal])")],
}


def _fixed_cases():
    free = np.zeros((4, 6, 6), dtype=np.uint8)
    sweep = free.copy()
    sweep[1:3, 5, 3] = 1
    cases = [(free, (0, 0), (5, 3)), (sweep, (5, 0), (5, 3)), (free, (3, 3), (0, 5))]
    rng = np.random.default_rng(3)
    for _ in range(12):
        dr = (rng.random((6, 9, 8)) < 0.3).astype(np.uint8)
        start, goal = (int(rng.integers(9)), int(rng.integers(8))), (int(rng.integers(9)),
                                                                     int(rng.integers(8)))
        dr[0][start] = dr[-1][goal] = 0
        cases.append((dr, start, goal))
    return cases


def test_the_unmutated_copy_passes(monkeypatch):
    mod = mutant_module.mutated_module("none", "impl/_numpy_search.py", [],
                                       lambda k, v: monkeypatch.setitem(sys.modules, k, v))
    assert all(differences(*c, search=mod.search_opt_path_numpy) == [] for c in _fixed_cases())


@pytest.mark.parametrize("name", sorted(MUTANTS))
def test_seeded_fault_in_a_copy_is_caught(monkeypatch, name):
    mod = mutant_module.mutated_module(name, "impl/_numpy_search.py", MUTANTS[name],
                                       lambda k, v: monkeypatch.setitem(sys.modules, k, v))
    caught = []
    for case in _fixed_cases():
        try:
            caught += differences(*case, search=mod.search_opt_path_numpy)
        except (AssertionError, ValueError, IndexError):
            caught.append("raised")
        if caught:
            break
    assert caught, f"mutant {name} not caught"
