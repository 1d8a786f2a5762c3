"""Paths, costs and Definition 5's oracle (docs/model.md §5) on hand-built D_R arrays."""

from __future__ import annotations

import numpy as np
import pytest
import z3
from hypothesis import event, given, settings
from hypothesis import strategies as st

from cfmpa.errors import InputError
from cfmpa.spec._paths import (
    J1,
    J2,
    REASON_GOAL_BLOCKED,
    REASON_START_BLOCKED,
    REASON_UNREACHABLE,
    SearchResult,
    SearchStatus,
    is_opt_path,
    is_path,
    is_path_paper,
    opt_path,
    path_violations,
)
from cfmpa.spec._paths_z3 import dr_free, length_bound, path_vars, z3_is_path, z3_J1, z3_J2
from dr_strategies import random_dr
from path_enumeration import optimal_lists

Cell = tuple[int, int]


def free_dr(N: int, m: int, n: int) -> np.ndarray:
    return np.zeros((N + 1, m, n), dtype=np.uint8)


# --- J1 and J2 -------------------------------------------------------------------------------

@pytest.mark.parametrize("path, j1, j2", [
    ([(0, 0)], 0, 0),
    ([(0, 0), (1, 0), (2, 0)], 2, 2),            # start 1, straight 0, stop 1
    ([(0, 0), (1, 0), (1, 1)], 2, 4),            # start 1, turn |(-1, 1)| = 2, stop 1
    ([(0, 0), (1, 1)], 2, 4),                    # a diagonal: start 2, stop 2
    ([(0, 0), (1, 0), (0, 0)], 2, 4),            # reversal: 1 + 2 + 1
    ([(0, 0), (1, 0), (1, 0), (2, 0)], 2, 4),    # a wait mid-way stops and restarts: 1+1+1+1
    ([(3, 3), (2, 4), (1, 5), (1, 6)], 5, 4),    # (-1,1),(-1,1),(0,1): 2 + 0 + 1, stop 1
])
def test_costs_on_hand_examples(path: list[tuple[int, int]], j1: int, j2: int) -> None:
    assert (J1(path), J2(path)) == (j1, j2)


def test_waiting_at_either_end_changes_neither_cost() -> None:
    base = [(0, 0), (1, 0), (1, 1), (2, 2)]
    for extra in range(1, 4):
        at_goal = base + [base[-1]] * extra
        at_start = [base[0]] * extra + base
        assert (J1(at_goal), J2(at_goal)) == (J1(base), J2(base))
        assert (J1(at_start), J2(at_start)) == (J1(base), J2(base))


# --- is_path (fixed) and is_path_paper (Definition 4, literal) ---------------------------------

def test_is_path_accepts_a_valid_path() -> None:
    dr = free_dr(3, 3, 3)
    dr[1, 1, 1] = 1
    path = [(0, 0), (1, 0), (2, 1), (2, 2)]
    assert is_path(path, dr, (0, 0), (2, 2))
    assert path_violations(path, dr, (0, 0), (2, 2)) == []
    assert is_path_paper(path, dr, (0, 0), (2, 2))


@pytest.mark.parametrize("path, start, goal, clause, step", [
    ([(0, 0), (2, 0), (2, 1)], (0, 0), (2, 1), "not_adjacent", 0),   # a jump of 2 rows
    ([(0, 0), (0, -1), (0, 0), (1, 0)], (0, 0), (1, 0), "outside_grid", 1),
    ([(0, 0), (0, 3), (0, 2)], (0, 0), (0, 2), "outside_grid", 1),
    ([(1, 1), (1, 2)], (0, 0), (1, 2), "wrong_start", 0),
    ([(0, 0), (1, 1)], (0, 0), (2, 2), "wrong_goal", 1),
    ([], (0, 0), (0, 0), "empty", None),
])
def test_is_path_rejects(path: list[tuple[int, int]], start: tuple[int, int],
                         goal: tuple[int, int], clause: str, step: int | None) -> None:
    dr = free_dr(2, 3, 3)
    found = path_violations(path, dr, start, goal)
    assert not is_path(path, dr, start, goal)
    assert (found[0].clause, found[0].step) == (clause, step)


def test_is_path_rejects_a_blocked_cell_and_says_where() -> None:
    dr = free_dr(3, 3, 3)
    dr[2, 1, 1] = 1
    path = [(0, 0), (0, 1), (1, 1), (2, 2)]   # at (1, 1) at step 2
    found = path_violations(path, dr, (0, 0), (2, 2))
    assert [(v.clause, v.step, v.cell, v.layer) for v in found] == [("blocked", 2, (1, 1), 2)]
    assert "step 2" in str(found[0]) and "(1, 1)" in str(found[0]) and "layer 2" in str(found[0])
    assert not is_path(path, dr, (0, 0), (2, 2))
    assert not is_path_paper(path, dr, (0, 0), (2, 2))


def test_steps_from_N_on_use_the_rest_layer() -> None:
    dr = free_dr(2, 1, 4)
    dr[2, 0, 2] = 1   # blocked only in R (index N = 2)
    path = [(0, 0), (0, 1), (0, 2), (0, 3)]   # at (0, 2) at step 2 = N
    found = path_violations(path, dr, (0, 0), (0, 3))
    assert [(v.step, v.layer) for v in found] == [(2, 2)]
    wait_first = [(0, 0), (0, 1), (0, 1), (0, 2), (0, 3)]   # step 3: still R
    assert not is_path(wait_first, dr, (0, 0), (0, 3))


def test_early_arrival_is_the_paper_definitions_flaw() -> None:
    # The path reaches its goal at step 2 and waits there; the principal sweeps the goal in
    # layer 3 < N. Definition 4 checks only k < LENGTH(L), so it accepts; the fixed one does not.
    N = 5
    dr = free_dr(N, 3, 3)
    dr[3, 2, 0] = 1
    path = [(0, 0), (1, 0), (2, 0)]
    assert is_path_paper(path, dr, (0, 0), (2, 0))
    assert not is_path(path, dr, (0, 0), (2, 0))
    found = path_violations(path, dr, (0, 0), (2, 0))
    assert [(v.clause, v.step, v.cell, v.layer) for v in found] == [("blocked", 3, (2, 0), 3)]
    # Arriving after the sweep is valid under both.
    late = [(0, 0), (0, 0), (0, 0), (0, 0), (1, 0), (2, 0)]
    assert is_path(late, dr, (0, 0), (2, 0)) and is_path_paper(late, dr, (0, 0), (2, 0))


def test_goal_blocked_only_in_the_rest_layer() -> None:
    dr = free_dr(3, 1, 2)
    dr[3, 0, 1] = 1
    path = [(0, 0), (0, 1)]
    found = path_violations(path, dr, (0, 0), (0, 1))
    assert [(v.clause, v.step, v.cell, v.layer) for v in found] == [("blocked", None, (0, 1), 3)]
    assert is_path_paper(path, dr, (0, 0), (0, 1))   # the paper never looks at R here


def test_paper_definition_read_literally_skips_the_last_cell_and_outside_pairs() -> None:
    dr = free_dr(3, 2, 2)
    dr[1, 1, 1] = 1
    # The last cell, at step 1, is blocked in layer 1: L_1 has no L_2, so nothing checks it.
    assert is_path_paper([(0, 0), (1, 1)], dr, (0, 0), (1, 1))
    assert not is_path([(0, 0), (1, 1)], dr, (0, 0), (1, 1))
    # A pair with a cell outside the grid does not meet the antecedent i < m /\ ...
    out = [(0, 0), (0, -5), (0, 1)]
    assert is_path_paper(out, dr, (0, 0), (0, 1))
    assert not is_path(out, dr, (0, 0), (0, 1))


def test_paper_definition_uses_layer_N_minus_1_from_step_N_on() -> None:
    dr = free_dr(1, 1, 3)
    dr[0, 0, 1] = 1   # blocked in layer N - 1 = 0 only; free in the rest layer R = dr[1]
    path = [(0, 0), (0, 1), (0, 2)]   # at (0, 1) at step 1 = N
    assert not is_path_paper(path, dr, (0, 0), (0, 2))
    assert is_path(path, dr, (0, 0), (0, 2))


# --- opt_path: Definition 5 by Dijkstra ----------------------------------------------------------

def test_opt_path_reasons_in_order() -> None:
    dr = free_dr(2, 2, 2)
    dr[0, 0, 0] = 1
    dr[2, 1, 1] = 1
    assert opt_path(dr, (0, 0), (1, 1)).reason == REASON_START_BLOCKED
    dr[0, 0, 0] = 0
    assert opt_path(dr, (0, 0), (1, 1)).reason == REASON_GOAL_BLOCKED
    dr[2, 1, 1] = 0
    dr[1] = 1   # every cell blocked at step 1
    result = opt_path(dr, (0, 0), (1, 1))
    assert (result.status, result.reason, result.path) == (SearchStatus.NO_PATH,
                                                          REASON_UNREACHABLE, ())


def test_opt_path_waits_out_an_early_sweep_of_the_goal() -> None:
    N = 5
    dr = free_dr(N, 1, 3)
    dr[3, 0, 2] = 1       # the goal is swept at step 3
    result = opt_path(dr, (0, 0), (0, 2))
    assert (result.status, result.J1, result.J2) == ("found", 2, 2)
    assert is_path(result.path, dr, (0, 0), (0, 2))
    assert len(result.path) >= 5 and result.path[-2] != (0, 2)   # arrives at step >= 4


def test_search_result_as_json_and_status_from_text() -> None:
    found = SearchResult("found", None, ((0, 0), (0, 1)), 1, 2)
    assert found.status is SearchStatus.FOUND
    assert found.as_json() == {"status": "found", "reason": None, "path": [[0, 0], [0, 1]],
                               "J1": 1, "J2": 2}
    assert SearchResult.no_path(REASON_UNREACHABLE).as_json()["status"] == "no_path"
    with pytest.raises(ValueError, match="'lost' is not a valid SearchStatus"):
        SearchResult("lost", None, (), None, None)


def test_opt_path_rejects_bad_inputs() -> None:
    dr = free_dr(2, 3, 3)
    with pytest.raises(InputError, match="start"):
        opt_path(dr, (3, 0), (0, 0))
    with pytest.raises(InputError, match="goal"):
        opt_path(dr, (0, 0), (0, 1.5))
    with pytest.raises(InputError, match="dr"):
        opt_path(np.zeros((1, 3, 3), dtype=np.uint8), (0, 0), (0, 0))


def enumerable_cases(max_n: int = 3) -> st.SearchStrategy:
    """Grids up to 3 x 3 (N <= max_n), small enough to enumerate every list up to the bound."""
    return random_dr(max_n=max_n, max_side=3, density=st.sampled_from([0.0, 0.15, 0.3, 0.5]),
                     free_ends=None)


def check_opt_path_by_enumeration(dr: np.ndarray, start: Cell, goal: Cell, extra: int) -> str:
    """opt_path's optimum is the least (J1, J2) over every list of at most length_bound + extra
    cells that is_path accepts (the extra cells check, here, that longer lists never beat the
    bound), and is_opt_path accepts exactly the lists reaching it."""
    want, optimal = optimal_lists(dr, start, goal, length_bound(dr) + extra)
    got = opt_path(dr, start, goal)
    if want is None:
        assert got.status == SearchStatus.NO_PATH
        N = dr.shape[0] - 1
        assert got.reason == (REASON_START_BLOCKED if dr[0][start] else
                              REASON_GOAL_BLOCKED if dr[N][goal] else REASON_UNREACHABLE)
        return f"no path: {got.reason}"
    assert got.status == SearchStatus.FOUND and (got.J1, got.J2) == want
    assert is_path(got.path, dr, start, goal) and (J1(got.path), J2(got.path)) == want
    assert is_opt_path(got.path, dr, start, goal)
    assert all(is_opt_path(p, dr, start, goal) for p in optimal)
    # Valid lists that cost more: the optimum, then a step off the goal and back (J1 + 2).
    m, n = dr.shape[1:]
    rejected = 0
    for di, dj in ((0, 1), (1, 0), (0, -1), (-1, 0)):
        off = (goal[0] + di, goal[1] + dj)
        detour = [*got.path, off, goal]
        if 0 <= off[0] < m and 0 <= off[1] < n and is_path(detour, dr, start, goal):
            assert J1(detour) == want[0] + 2 and not is_opt_path(detour, dr, start, goal)
            rejected += 1
    return "found, a costlier list rejected" if rejected else "found"


@settings(max_examples=100, deadline=None)
@given(enumerable_cases())
def test_opt_path_is_the_minimum_over_all_short_paths(
        case: tuple[np.ndarray, Cell, Cell]) -> None:
    event(check_opt_path_by_enumeration(*case, extra=1))


@pytest.mark.slow
@settings(max_examples=400, deadline=None)
@given(enumerable_cases(max_n=4))
def test_opt_path_is_the_minimum_over_all_short_paths_many(
        case: tuple[np.ndarray, Cell, Cell]) -> None:
    check_opt_path_by_enumeration(*case, extra=2)


def test_is_opt_path_on_hand_lists() -> None:
    dr = free_dr(2, 1, 3)
    dr[1, 0, 1] = 1          # (0, 1) is swept at step 1
    best = opt_path(dr, (0, 0), (0, 2))
    assert (best.J1, best.J2) == (2, 2)
    assert is_opt_path([(0, 0), (0, 0), (0, 1), (0, 2)], dr, (0, 0), (0, 2))   # waits it out
    assert not is_opt_path([(0, 0), (0, 1), (0, 2)], dr, (0, 0), (0, 2))      # blocked: invalid
    stop_start = [(0, 0), (0, 0), (0, 1), (0, 1), (0, 2)]                      # valid, (2, 4)
    assert is_path(stop_start, dr, (0, 0), (0, 2))
    assert not is_opt_path(stop_start, dr, (0, 0), (0, 2))
    walled = free_dr(2, 1, 3)
    walled[:, 0, 1] = 1
    assert not is_opt_path([(0, 0), (0, 1), (0, 2)], walled, (0, 0), (0, 2))  # no path at all


# --- the Z3 encoding that Optimize minimises, against the executable definitions ----------------

@st.composite
def pinned_cases(draw: st.DrawFn) -> tuple[np.ndarray, list[tuple[int, int]], tuple[int, int],
                                           tuple[int, int], int]:
    """A tiny D_R, a list of cells (a walk with some jumps and cells just outside the grid, so
    valid and invalid lists both come up), start, goal, and a Z3 bound of at least its length."""
    N, m, n = draw(st.integers(1, 3)), draw(st.integers(1, 3)), draw(st.integers(1, 3))
    dr = np.array(draw(st.lists(st.sampled_from([0, 0, 0, 1]), min_size=(N + 1) * m * n,
                                max_size=(N + 1) * m * n)), dtype=np.uint8).reshape(N + 1, m, n)
    cell = st.tuples(st.integers(-1, m), st.integers(-1, n))
    inside = st.tuples(st.integers(0, m - 1), st.integers(0, n - 1))
    length = draw(st.integers(1, length_bound(dr)))
    path = [draw(inside)]
    for _ in range(length - 1):
        di, dj = draw(st.integers(-1, 1)), draw(st.integers(-1, 1))
        step = (path[-1][0] + di, path[-1][1] + dj)
        path.append(step if draw(st.integers(0, 5)) else draw(cell))
    start = path[0] if draw(st.integers(0, 5)) else draw(inside)
    goal = path[-1] if draw(st.integers(0, 5)) else draw(inside)
    # Bounds below N too, where z3_is_path checks the goal at the steps past the bound.
    bound = draw(st.integers(length, length + N + 1))
    return dr, path, start, goal, bound


def _z3_verdict(dr: np.ndarray, path: list[tuple[int, int]], start: tuple[int, int],
                goal: tuple[int, int], bound: int) -> tuple[int, int] | None:
    """(J1, J2) that z3_is_path, z3_J1 and z3_J2 force on the pinned list, or None if
    z3_is_path rejects it; fails if the terms leave either cost undetermined."""
    N, m, n = dr.shape[0] - 1, dr.shape[1], dr.shape[2]
    p = path_vars(bound)
    pinned = [p.length == len(path)]
    pinned += [z3.And(p.xs[k] == i, p.ys[k] == j) for k, (i, j) in enumerate(path)]
    solver = z3.Solver()
    solver.set(timeout=10_000)
    solver.add(z3_is_path(p, dr_free(dr), N, m, n, start, goal), *pinned)
    verdict = solver.check()
    assert verdict != z3.unknown, solver.reason_unknown()
    if verdict == z3.unsat:
        return None
    model = solver.model()
    j1, j2 = (model.eval(t, model_completion=True).as_long() for t in (z3_J1(p), z3_J2(p)))
    # The costs are functions of the list: no other model of the same list gives other values.
    solver.add(z3.Or(z3_J1(p) != j1, z3_J2(p) != j2))
    assert solver.check() == z3.unsat
    return j1, j2


@settings(max_examples=120, deadline=None)
@given(pinned_cases())
def test_z3_encoding_agrees_with_is_path_J1_J2_on_pinned_lists(
        case: tuple[np.ndarray, list[tuple[int, int]], tuple[int, int], tuple[int, int], int]
) -> None:
    dr, path, start, goal, _ = case
    got = _z3_verdict(*case)
    valid = is_path(path, dr, start, goal)
    event("valid" if valid else f"invalid: {path_violations(path, dr, start, goal)[0].clause}")
    assert got == ((J1(path), J2(path)) if valid else None)


def test_z3_encoding_on_hand_lists() -> None:
    dr = free_dr(3, 2, 3)
    dr[2, 1, 2] = 1        # the goal (1, 2) is swept at step 2
    late = [(0, 0), (0, 1), (0, 1), (1, 2)]
    early = [(0, 0), (1, 1), (1, 2)]
    assert _z3_verdict(dr, late, (0, 0), (1, 2), 6) == (J1(late), J2(late)) == (3, 6)
    assert _z3_verdict(dr, early, (0, 0), (1, 2), 3) is None     # held at the goal at step 2
    assert _z3_verdict(dr, [(0, 0), (1, 2)], (0, 0), (1, 2), 4) is None    # not one move
