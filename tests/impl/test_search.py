"""search_opt_path is exact: checked against two Dijkstras and against Z3's Optimize (docs/model.md §5)."""

from __future__ import annotations

import heapq

import numpy as np
import pytest
from hypothesis import event, given, settings
from hypothesis import strategies as st

from cfmpa.errors import InputError
from cfmpa.impl._search import _check_size, search_opt_path
from cfmpa.spec._paths import (
    J1,
    J2,
    MOVES,
    REASON_GOAL_BLOCKED,
    REASON_START_BLOCKED,
    REASON_UNREACHABLE,
    SearchResult,
    SearchStatus,
    is_path,
    opt_path,
)
from cfmpa.spec._paths_z3 import length_bound, z3_opt_path
from dr_strategies import random_dr
from path_enumeration import optimal_lists

Cell = tuple[int, int]


def plain_dijkstra(dr: np.ndarray, start: Cell, goal: Cell) -> tuple[str, object]:
    """("found", (J1, J2)) or ("no_path", reason), by a Dijkstra written for this test alone.

    States (cell, previous move, step capped at N); a path may stop at (goal, p, N), paying the
    last J2 term |p|_1 (holding the goal from an earlier step is the same as waiting to step N).
    """
    N, m, n = dr.shape[0] - 1, dr.shape[1], dr.shape[2]
    if dr[0][start]:
        return "no_path", REASON_START_BLOCKED
    if dr[N][goal]:
        return "no_path", REASON_GOAL_BLOCKED
    first = (start, (0, 0), 0)
    dist = {first: (0, 0)}
    heap = [((0, 0), first)]
    answer = None
    while heap:
        cost, state = heapq.heappop(heap)
        if answer is not None and cost >= answer:
            break
        if dist[state] < cost:
            continue
        (i, j), (pi, pj), s = state
        if s == N and (i, j) == goal:
            stop = (cost[0], cost[1] + abs(pi) + abs(pj))
            answer = stop if answer is None else min(answer, stop)
        nxt = min(s + 1, N)
        for di in (-1, 0, 1):
            for dj in (-1, 0, 1):
                c = (i + di, j + dj)
                if not (0 <= c[0] < m and 0 <= c[1] < n) or dr[nxt][c]:
                    continue
                new = (cost[0] + abs(di) + abs(dj), cost[1] + abs(di - pi) + abs(dj - pj))
                key = (c, (di, dj), nxt)
                if key not in dist or new < dist[key]:
                    dist[key] = new
                    heapq.heappush(heap, (new, key))
    return ("found", answer) if answer is not None else ("no_path", REASON_UNREACHABLE)


def dr_cases(max_n: int = 6, max_side: int = 8) -> st.SearchStrategy:
    """A random D_R (random sizes and obstacle density), start and goal; mostly free ends."""
    return random_dr(max_n=max_n, max_side=max_side, density=st.floats(0.0, 0.6),
                     free_ends=None)


def check_against_oracles(dr: np.ndarray, start: Cell, goal: Cell) -> SearchResult:
    got = search_opt_path(dr, start, goal)
    spec = opt_path(dr, start, goal)
    status, value = plain_dijkstra(dr, start, goal)
    assert (got.status, got.reason, got.J1, got.J2) == (spec.status, spec.reason, spec.J1, spec.J2)
    if status == "found":
        assert got.status == SearchStatus.FOUND and (got.J1, got.J2) == value
        assert is_path(got.path, dr, start, goal)
        assert (J1(got.path), J2(got.path)) == (got.J1, got.J2)
        assert len(got.path) == 1 or got.path[-2] != goal    # trailing waits are dropped
    else:
        assert (got.status, got.reason, got.path) == (SearchStatus.NO_PATH, value, ())
    return got


@settings(max_examples=200, deadline=None)
@given(dr_cases())
def test_search_matches_both_dijkstras(case: tuple[np.ndarray, Cell, Cell]) -> None:
    got = check_against_oracles(*case)
    event(f"{got.status}: {got.reason}")


@pytest.mark.slow
@settings(max_examples=2000, deadline=None)
@given(dr_cases(max_n=10, max_side=14))
def test_search_matches_both_dijkstras_many(case: tuple[np.ndarray, Cell, Cell]) -> None:
    check_against_oracles(*case)


@pytest.mark.parametrize("seed", range(4))
def test_search_matches_on_larger_grids(seed: int) -> None:
    # Many buckets and long detours after step N, in a few cases.
    rng = np.random.default_rng(seed)
    dr = (rng.random((9, 40, 40)) < 0.35).astype(np.uint8)
    dr[:, 0, 0] = 0
    dr[8, 39, 39] = 0
    check_against_oracles(dr, (0, 0), (39, 39))


# --- Z3's Optimize over the spec's encoding (Definition 5 by a solver) -------------------------

Z3_TIMEOUT_MS = 60_000


def check_against_z3(dr: np.ndarray, start: Cell, goal: Cell) -> SearchResult:
    """Z3's optimum over the spec's encoding equals the search's: (J1, J2), or both no path."""
    z = z3_opt_path(dr, start, goal, timeout_ms=Z3_TIMEOUT_MS)
    assert z.status is not None, f"Z3 answered unknown: {z.reason_unknown}"
    got = search_opt_path(dr, start, goal)
    assert (got.status, got.J1, got.J2) == (z.status, z.J1, z.J2)
    if z.status == SearchStatus.FOUND:
        assert is_path(z.path, dr, start, goal)
        assert (J1(z.path), J2(z.path)) == (z.J1, z.J2)
    return got


def z3_cases() -> st.SearchStrategy:
    """A tiny random D_R for Z3 (N <= 4, m, n <= 4), any start and goal, with densities up to
    0.8 so that a good share of cases have no path (unreachable, or an end blocked)."""
    return random_dr(max_n=4, max_side=4, density=st.sampled_from([0.0, 0.2, 0.4, 0.6, 0.8]),
                     free_ends=None)


@settings(max_examples=50, deadline=None)
@given(z3_cases())
def test_search_matches_z3_on_random_tiny_drs(case: tuple[np.ndarray, Cell, Cell]) -> None:
    got = check_against_z3(*case)
    event(f"{got.status}: {got.reason}")


def test_search_matches_z3_on_the_largest_free_grid() -> None:
    # N = 4, 5 x 5, nothing blocked: the largest length bound here, B = 4 + 25 cells.
    dr = np.zeros((5, 5, 5), dtype=np.uint8)
    assert check_against_z3(dr, (0, 0), (4, 4)).status is SearchStatus.FOUND


def test_search_and_z3_agree_on_an_unreachable_goal() -> None:
    # A wall across the grid from step 1 on: both ends are free, yet no path reaches the goal.
    dr = np.zeros((4, 4, 4), dtype=np.uint8)
    dr[1:, 2, :] = 1
    got = check_against_z3(dr, (0, 1), (3, 2))
    assert (got.status, got.reason) == (SearchStatus.NO_PATH, REASON_UNREACHABLE)


def test_search_and_z3_agree_when_the_start_is_blocked() -> None:
    dr = np.zeros((3, 3, 3), dtype=np.uint8)
    dr[0, 1, 1] = 1
    got = check_against_z3(dr, (1, 1), (2, 2))
    assert (got.status, got.reason) == (SearchStatus.NO_PATH, REASON_START_BLOCKED)


def test_search_matches_z3_on_the_early_arrival_case() -> None:
    # 1 x 3, N = 4: the start is swept at step 1 and the goal (0, 2) at step 3. Arriving at
    # step 2 (J1, J2) = (2, 2) and holding the goal is invalid; the optimum waits mid-way at
    # (0, 1) and arrives at step 4, (2, 4).
    dr = np.zeros((5, 1, 3), dtype=np.uint8)
    dr[1, 0, 0] = 1
    dr[3, 0, 2] = 1
    check_against_z3(dr, (0, 0), (0, 2))
    result = search_opt_path(dr, (0, 0), (0, 2))
    assert (result.path, result.J1, result.J2) == (((0, 0), (0, 1), (0, 1), (0, 1), (0, 2)), 2, 4)


@pytest.mark.slow
@settings(max_examples=150, deadline=None)
@given(dr_cases(max_n=4, max_side=5))
def test_search_matches_z3_many(case: tuple[np.ndarray, Cell, Cell]) -> None:
    check_against_z3(*case)


# --- behaviour on hand-built cases ---------------------------------------------------------------

def test_reasons_are_checked_in_order() -> None:
    dr = np.zeros((3, 2, 2), dtype=np.uint8)
    dr[0, 0, 0] = 1
    dr[2, 1, 1] = 1
    assert search_opt_path(dr, (0, 0), (1, 1)).reason == REASON_START_BLOCKED
    dr[0, 0, 0] = 0
    assert search_opt_path(dr, (0, 0), (1, 1)).reason == REASON_GOAL_BLOCKED
    dr[2, 1, 1] = 0
    dr[1] = 1   # every cell blocked at step 1
    assert search_opt_path(dr, (0, 0), (1, 1)).reason == REASON_UNREACHABLE


def test_start_equal_to_goal_is_a_one_cell_path() -> None:
    dr = np.zeros((4, 3, 3), dtype=np.uint8)
    result = search_opt_path(dr, (1, 1), (1, 1))
    assert (result.status, result.path, result.J1, result.J2) == ("found", ((1, 1),), 0, 0)


def test_dodges_the_principal_and_comes_back_after_it_stops() -> None:
    # The start is swept at step 2 and the arm must step aside, though the goal is the start.
    dr = np.zeros((4, 1, 3), dtype=np.uint8)
    dr[2, 0, 0] = 1
    result = search_opt_path(dr, (0, 0), (0, 0))
    assert (result.J1, result.J2) == (2, 4)
    assert len(result.path) == 4 and result.path[2] == (0, 1)
    assert is_path(result.path, dr, (0, 0), (0, 0))


def test_ties_follow_the_documented_rule() -> None:
    # Three optimal paths with (J1, J2) = (2, 4) end with moves (1, 1), (0, 1) and (1, 0); the
    # rule keeps the smallest last move in MOVES order, (0, 1), so the path comes from (1, 0).
    result = search_opt_path(np.zeros((2, 2, 2), dtype=np.uint8), (0, 0), (1, 1))
    assert (result.path, result.J1, result.J2) == (((0, 0), (1, 0), (1, 1)), 2, 4)


def test_ties_are_broken_the_same_way_every_time() -> None:
    dr = np.zeros((3, 6, 6), dtype=np.uint8)   # many optimal paths
    first = search_opt_path(dr, (0, 0), (5, 5))
    assert all(search_opt_path(dr.copy(), (0, 0), (5, 5)) == first for _ in range(3))


def test_accepts_any_integer_cells_and_returns_python_ints() -> None:
    dr = np.zeros((2, 3, 3), dtype=np.uint8)
    result = search_opt_path(dr, np.array([0, 0]), (np.int64(2), 2))
    assert all(type(v) is int for cell in result.path for v in cell)
    assert type(result.J1) is int and type(result.J2) is int


def test_rejects_bad_inputs() -> None:
    dr = np.zeros((2, 3, 3), dtype=np.uint8)
    with pytest.raises(InputError, match="goal"):
        search_opt_path(dr, (0, 0), (0, 3))
    with pytest.raises(InputError, match="dr"):
        search_opt_path(np.zeros((3, 3), dtype=np.uint8), (0, 0), (0, 0))


def test_refuses_grids_too_large_for_exact_cost_keys() -> None:
    _check_size(71, 316, 316)   # a default-sized grid is far inside the limit
    with pytest.raises(InputError, match="too large"):
        _check_size(1 << 29, 1, 1)


# --- the tie-break rule of search_opt_path's docstring, by enumeration ---------------------------

def tie_rank(path: tuple[Cell, ...], N: int) -> tuple[int, ...]:
    """The docstring's order: pad to N + 1 cells, read the moves backwards, the last one ranked
    by its MOVES index, each earlier d_k by its index, plus 9 if it arrives at step N or later."""
    padded = list(path) + [path[-1]] * (N + 1 - len(path))
    d = [(b[0] - a[0], b[1] - a[1]) for a, b in zip(padded, padded[1:])]
    T = len(d)
    return (MOVES.index(d[T - 1]),
            *(MOVES.index(d[k]) + (9 if k + 1 >= N else 0) for k in range(T - 2, -1, -1)))


def waits_after_N(path: tuple[Cell, ...], N: int) -> bool:
    return any(path[k + 1] == path[k] for k in range(N, len(path) - 1))


def tiny_cases(max_n: int = 3, max_side: int = 3) -> st.SearchStrategy:
    """Grids small enough to enumerate every list up to length_bound: often free (many ties)."""
    return random_dr(max_n=max_n, max_side=max_side,
                     density=st.sampled_from([0.0, 0.0, 0.15, 0.3]), free_ends=True)


def check_tie_rule(dr: np.ndarray, start: Cell, goal: Cell) -> int:
    """The search returns the optimal list the documented rule picks; the number of optima."""
    N = dr.shape[0] - 1
    cost, optimal = optimal_lists(dr, start, goal, length_bound(dr))
    got = search_opt_path(dr, start, goal)
    if cost is None:
        assert got.status is SearchStatus.NO_PATH
        return 0
    assert (got.J1, got.J2) == cost and got.path in optimal
    # Every list the rule ranks has at most length_bound cells (its cells from step N on are
    # distinct: a loop there holds a non-wait move and cutting it lowers J1), so none is missed.
    eligible = [p for p in optimal if not waits_after_N(p, N)]
    assert got.path == min(eligible, key=lambda p: tie_rank(p, N))
    return len(optimal)


@settings(max_examples=80, deadline=None)
@given(tiny_cases())
def test_ties_follow_the_documented_rule_on_every_optimum(case: tuple[np.ndarray, Cell, Cell]
                                                           ) -> None:
    ties = check_tie_rule(*case)
    event("no path" if ties == 0 else "one optimum" if ties == 1 else "ties")


@pytest.mark.slow
@settings(max_examples=600, deadline=None)
@given(tiny_cases(max_n=4))
def test_ties_follow_the_documented_rule_many(case: tuple[np.ndarray, Cell, Cell]) -> None:
    check_tie_rule(*case)


def test_tie_rule_ranks_the_last_move_before_the_arrival_step() -> None:
    # N = 1, 2 x 2 free, (1, 0) to (0, 1): three optima with (J1, J2) = (2, 4) that never wait.
    # The diagonal arrives at step 1 = N with last move (-1, 1) (index 2); via (1, 1) the last
    # move is (-1, 0) (index 1); via (0, 0) it is (0, 1) (index 5). The least last move wins,
    # though that path arrives after step N.
    dr = np.zeros((2, 2, 2), dtype=np.uint8)
    cost, optimal = optimal_lists(dr, (1, 0), (0, 1), length_bound(dr))
    never_wait = {p for p in optimal if all(a != b for a, b in zip(p, p[1:]))}
    assert cost == (2, 4) and never_wait == {((1, 0), (0, 1)), ((1, 0), (1, 1), (0, 1)),
                                             ((1, 0), (0, 0), (0, 1))}
    assert search_opt_path(dr, (1, 0), (0, 1)).path == ((1, 0), (1, 1), (0, 1))


def test_tie_rule_prefers_reaching_a_state_at_step_N() -> None:
    # N = 2, 2 x 2 free, (1, 0) to (0, 1): both ((1, 0), (1, 1), (0, 1)) and the same with a
    # wait at (1, 1) end with (-1, 0); the first reaches (1, 1) by step N, ranks (1, 5) against
    # (1, 13, 5), and is returned.
    dr = np.zeros((3, 2, 2), dtype=np.uint8)
    cost, optimal = optimal_lists(dr, (1, 0), (0, 1), length_bound(dr))
    assert cost == (2, 4) and ((1, 0), (1, 1), (1, 1), (0, 1)) in optimal
    assert tie_rank(((1, 0), (1, 1), (0, 1)), 2) == (1, 5)
    assert tie_rank(((1, 0), (1, 1), (1, 1), (0, 1)), 2) == (1, 13, 5)
    assert search_opt_path(dr, (1, 0), (0, 1)).path == ((1, 0), (1, 1), (0, 1))
