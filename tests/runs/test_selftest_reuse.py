"""The self-check makes each fault once for both modes, and the non-optimal path (asked for by
two faults in two modes) is searched once per D_R: the same rows as made afresh."""

from __future__ import annotations

import cfmpa.runs._selftest as st
from cfmpa.impl import build_dr
from cfmpa.runs._contracts import Mode
from cfmpa.spec import make_grid


def _fault(name: str) -> st.Fault:
    return next(f for f in st.FAULTS if f.name == name)


def test_the_non_optimal_path_is_searched_once_per_table_and_is_the_fresh_one():
    f = _fault("non-optimal path")
    s = st.workcell(f.workcell)
    g = make_grid(s)
    dr = build_dr(s, f.variant, g)
    search = f.make(s, f.variant, g).search
    st._worse_path.cache_clear()
    first = search(dr, s.right.start_cell, s.right.goal_cell)
    again = search(dr.copy(), s.right.start_cell, s.right.goal_cell)     # equal table: no search
    assert again is first and st._worse_path.cache_info().hits == 1
    st._worse_path.cache_clear()
    assert search(dr, s.right.start_cell, s.right.goal_cell) == first
    # Seeded fault: another table (one more blocked cell on the path) is not served the old one.
    more = dr.copy()
    i, j = first.path[1]
    more[1, i, j] = 1
    assert search(more, s.right.start_cell, s.right.goal_cell) != first


def test_a_fault_made_once_gives_the_outcome_of_one_made_per_run():
    f = _fault("path with a jump")
    s = st.workcell(f.workcell)
    m = f.make(s, f.variant, make_grid(s))
    assert (st.run_fault(f, Mode.SAMPLED, scenario=s, mutant=m)
            == st.run_fault(f, Mode.SAMPLED, scenario=s))
