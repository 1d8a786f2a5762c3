"""Hypothesis strategies for random D_R arrays, shared by the search and path tests."""

from __future__ import annotations

import numpy as np
from hypothesis import strategies as st

Cell = tuple[int, int]


@st.composite
def random_dr(draw: st.DrawFn, *, max_n: int, max_side: int, density: st.SearchStrategy[float],
              free_ends: bool | None) -> tuple[np.ndarray, Cell, Cell]:
    """A random D_R of shape (N + 1, m, n) with N <= max_n and m, n <= max_side, each cell blocked
    with a drawn probability, and a start and goal cell. ``free_ends``: True frees the start in
    layer 0 and the goal in the rest layer, so that most cases reach the search proper; None
    draws whether to; False leaves them as drawn."""
    N = draw(st.integers(1, max_n))
    m, n = draw(st.integers(1, max_side)), draw(st.integers(1, max_side))
    p = draw(density)
    seed = draw(st.integers(0, 2**32 - 1))
    dr = (np.random.default_rng(seed).random((N + 1, m, n)) < p).astype(np.uint8)
    start = (draw(st.integers(0, m - 1)), draw(st.integers(0, n - 1)))
    goal = (draw(st.integers(0, m - 1)), draw(st.integers(0, n - 1)))
    if free_ends or (free_ends is None and draw(st.booleans())):
        dr[0][start] = 0
        dr[N][goal] = 0
    return dr, start, goal
