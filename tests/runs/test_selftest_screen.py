"""The self-check's shortcuts give the faults the self-check made before them.

``_worse_path`` screens each blocked cell with the fast kernel's costs and runs the spec's search
only where the screen finds the optimum worse: its path is the one the spec's search on every
cell in turn finds. ``_opt_path_of`` (the early-arrival and rest-layer faults, full and sampled
mode) searches each table once: its answer is the spec's opt_path of that very table.
"""

from __future__ import annotations

from typing import Any

import numpy as np
import pytest

import cfmpa.runs._selftest as st
from cfmpa.impl import build_dr, search_opt_path
from cfmpa.spec import J1, J2, SearchResult, SearchStatus, make_grid, opt_path


def _fault(name: str) -> st.Fault:
    return next(f for f in st.FAULTS if f.name == name)


def _unscreened(dr: Any, start: st.Cell, goal: st.Cell) -> SearchResult:
    """_worse_path as it reads without the screen: the spec's search on every cell in turn."""
    best = search_opt_path(dr, start, goal)
    N = dr.shape[0] - 1
    for k in range(1, len(best.path) - 1):
        more = dr.copy()
        more[min(k, N), best.path[k][0], best.path[k][1]] = 1
        alt = opt_path(more, start, goal)
        if alt.status is SearchStatus.FOUND and (alt.J1, alt.J2) > (best.J1, best.J2):
            return SearchResult.found(alt.path, J1(alt.path), J2(alt.path))
    raise st.FaultNotMade("no single blocked cell makes the optimum worse")


def _tables() -> list[tuple[Any, st.Cell, st.Cell]]:
    """D_R of the non-optimal fault's workcell, and a harder one: the first cells the optimum
    crosses blocked in their layers, so the first worse cell lies farther along."""
    f = _fault("non-optimal path")
    s = st.workcell(f.workcell)
    dr = build_dr(s, f.variant, make_grid(s))
    a, b = s.right.start_cell, s.right.goal_cell
    out = [(dr, a, b)]
    best = search_opt_path(dr, a, b)
    harder = dr.copy()
    for k in (2, 3):
        i, j = best.path[k]
        harder[min(k, dr.shape[0] - 1), i, j] = 1
    if search_opt_path(harder, a, b).status is SearchStatus.FOUND:
        out.append((harder, a, b))
    return out


@pytest.mark.parametrize("n", [0, 1])
def test_the_screened_worse_path_is_the_unscreened_one(n: int) -> None:
    tables = _tables()
    if n >= len(tables):
        pytest.skip("no second table with a path")
    dr, a, b = tables[n]
    st._worse_path.cache_clear()
    got = st._worse_path(dr.shape, dr.tobytes(), tuple(a), tuple(b))
    want = _unscreened(dr, a, b)
    assert (got.path, got.J1, got.J2) == (want.path, want.J1, want.J2)


def test_a_screen_that_misses_a_worse_cell_is_caught(monkeypatch: pytest.MonkeyPatch) -> None:
    # Seeded fault: a screen that weighs J1 only (J2 read as 0) passes over the first worse
    # cell, which is worse in J2 alone here, so a later cell's path (or none) is returned.
    real = st.search_opt_path_fast

    def short(dr: Any, start: st.Cell, goal: st.Cell, **kw: Any) -> SearchResult:
        r = real(dr, start, goal, **kw)
        return r if r.status is not SearchStatus.FOUND else SearchResult.found(r.path, r.J1, 0)

    dr, a, b = _tables()[0]
    want = _unscreened(dr, a, b)
    monkeypatch.setattr(st, "search_opt_path_fast", short)
    st._worse_path.cache_clear()
    try:
        got = st._worse_path(dr.shape, dr.tobytes(), tuple(a), tuple(b))
    except st.FaultNotMade:
        got = None
    finally:
        st._worse_path.cache_clear()
    assert got is None or (got.path, got.J1, got.J2) != (want.path, want.J1, want.J2)


def test_the_cached_opt_path_is_the_spec_s_of_that_table() -> None:
    dr, a, b = _tables()[0]
    st._opt_path_cached.cache_clear()
    first = st._opt_path_of(dr, a, b)
    assert first == opt_path(dr, a, b)
    assert st._opt_path_of(dr.copy(), a, b) is first            # equal table: searched once
    assert st._opt_path_cached.cache_info().hits == 1
    # Another table (the optimum's second cell blocked in its layer) is searched anew.
    more = dr.copy()
    i, j = first.path[1]
    more[1, i, j] = 1
    assert st._opt_path_of(more, a, b) == opt_path(more, a, b) != first
    # A D_R of another type is searched directly, never looked up by its bytes.
    wide = dr.astype(np.int64)
    assert st._opt_path_of(wide, a, b) == opt_path(dr, a, b)


def test_a_cache_keyed_without_the_cells_is_caught(monkeypatch: pytest.MonkeyPatch) -> None:
    # Seeded fault: the cache keyed by the shape only serves the first table's path for the
    # second; the comparison with the spec's search on that table sees it.
    dr, a, b = _tables()[0]
    seen: dict[Any, SearchResult] = {}

    def by_shape(shape: Any, cells: bytes, start: st.Cell, goal: st.Cell) -> SearchResult:
        if shape not in seen:
            seen[shape] = opt_path(np.frombuffer(cells, dtype=np.uint8).reshape(shape), start,
                                   goal)
        return seen[shape]

    monkeypatch.setattr(st, "_opt_path_cached", by_shape)
    first = st._opt_path_of(dr, a, b)
    more = dr.copy()
    i, j = first.path[1]
    more[1, i, j] = 1
    assert st._opt_path_of(more, a, b) != opt_path(more, a, b)


def test_the_early_arrival_and_rest_layer_faults_search_once_for_both_modes() -> None:
    st._opt_path_cached.cache_clear()
    for name in ("path through a blocked cell in the rest layer",):
        f = _fault(name)
        s = st.workcell(f.workcell)
        g = make_grid(s)
        dr = build_dr(s, f.variant, g)
        search = f.make(s, f.variant, g).search
        assert search is not None
        a, b = s.right.start_cell, s.right.goal_cell
        one, two = search(dr, a, b), search(dr.copy(), a, b)
        assert one == two
        assert st._opt_path_cached.cache_info().misses == 1
