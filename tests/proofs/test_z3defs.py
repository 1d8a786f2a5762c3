"""The Z3 terms of Definition 4 agree with the spec's executable is_path on concrete data."""

from __future__ import annotations

import numpy as np
import pytest
import z3
from hypothesis import given, settings
from hypothesis import strategies as st

from cfmpa.spec.z3defs import Z3Dims, Z3PathVar, is_path_fixed, is_path_paper

paths = pytest.importorskip("cfmpa.spec._paths")


def _array3(dr: np.ndarray) -> z3.ExprRef:
    k, i, j = z3.Ints("c!k c!i c!j")
    body = z3.IntVal(0)
    for (a, b, c), v in np.ndenumerate(dr):
        if v:
            body = z3.If(z3.And(k == a, i == b, j == c), z3.IntVal(int(v)), body)
    return z3.Lambda([k, i, j], body)


def _list(values: list[int]) -> z3.ExprRef:
    # Past the end: -1, outside the grid, so the printed definition's L_{k+1} is never a cell.
    arr = z3.K(z3.IntSort(), z3.IntVal(-1))
    for idx, v in enumerate(values):
        arr = z3.Store(arr, idx, v)
    return arr


def _holds(f: z3.BoolRef) -> bool:
    s = z3.Solver()
    s.set("timeout", 10_000)
    s.add(z3.Not(f))
    r = s.check()
    assert r != z3.unknown, s.reason_unknown()
    return r == z3.unsat


@st.composite
def cases(draw):
    N, m, n = draw(st.integers(1, 3)), draw(st.integers(1, 3)), draw(st.integers(1, 3))
    # Mostly free cells, so that valid paths come up as often as invalid ones.
    dr = np.array(draw(st.lists(st.sampled_from([0, 0, 0, 1]), min_size=(N + 1) * m * n,
                                max_size=(N + 1) * m * n)), dtype=np.uint8).reshape(N + 1, m, n)
    length = draw(st.integers(1, 5))
    cell = st.tuples(st.integers(-1, m), st.integers(-1, n))
    path = [draw(cell)]
    for _ in range(length - 1):
        di, dj = draw(st.integers(-1, 1)), draw(st.integers(-1, 1))
        path.append(draw(st.sampled_from([(path[-1][0] + di, path[-1][1] + dj), draw(cell)])))
    start = path[0] if draw(st.booleans()) else draw(cell)
    goal = path[-1] if draw(st.booleans()) else draw(cell)
    return dr, path, start, goal


def _check(dr, path, start, goal) -> tuple[bool, bool]:
    N, m, n = dr.shape[0] - 1, dr.shape[1], dr.shape[2]
    d = Z3Dims(z3.IntVal(N), z3.IntVal(m), z3.IntVal(n))
    L = Z3PathVar(_list([c[0] for c in path]), _list([c[1] for c in path]), z3.IntVal(len(path)))
    s = (z3.IntVal(start[0]), z3.IntVal(start[1]))
    g = (z3.IntVal(goal[0]), z3.IntVal(goal[1]))
    P = _array3(dr)
    inside = all(0 <= a < m and 0 <= b < n for a, b in [start, goal])
    fixed = paths.is_path(path, dr, start, goal)
    printed = paths.is_path_paper(path, dr, start, goal)
    if inside:   # the executable version is meant for start/goal inside the grid
        assert _holds(is_path_fixed(P, d, s, g, L)) == fixed
    assert _holds(is_path_paper(P, d, s, g, L)) == printed
    return fixed, printed


@settings(max_examples=80, deadline=None)
@given(cases())
def test_z3_is_path_matches_the_executable_one(case):
    _check(*case)


def test_known_cases_both_ways():
    free = np.zeros((3, 2, 2), dtype=np.uint8)
    assert _check(free, [(0, 0), (1, 1)], (0, 0), (1, 1)) == (True, True)
    last = free.copy()
    last[1, 1, 1] = 1               # the last cell, at its own step: the printed text skips it
    assert _check(last, [(0, 0), (1, 1)], (0, 0), (1, 1)) == (False, True)
    after = free.copy()
    after[2, 1, 1] = 1              # the goal swept at step 2, after the 2-cell list has ended
    assert _check(after, [(0, 0), (1, 1)], (0, 0), (1, 1)) == (False, True)
    early = free.copy()
    early[0, 0, 0] = 1              # the start is blocked at step 0
    assert _check(early, [(0, 0), (1, 1)], (0, 0), (1, 1)) == (False, False)
