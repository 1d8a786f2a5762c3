"""Hypothesis strategies shared by the tests: random D_R arrays (search and path tests) and random
workcells with coarse grids (the BuiltDR kernels' agreement tests)."""

from __future__ import annotations

import math

import numpy as np
from hypothesis import strategies as st

from cfmpa.spec import Scenario, joint_points, parse_scenario

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


@st.composite
def convex_tools(draw: st.DrawFn) -> list[list[float]]:
    """A strictly convex polygon of 3 to 8 vertices in a forearm's frame (m): points of an
    ellipse at sorted, well-separated angles, in either orientation."""
    f = st.floats
    n = draw(st.integers(3, 8))
    cuts = sorted(draw(st.lists(f(0.0, 1.0), min_size=n, max_size=n)))
    # Spread the angles so that no two vertices nearly coincide (the reader refuses those).
    angles = [2 * math.pi * (k + 0.6 * c) / n for k, c in enumerate(cuts)]
    cx, cy = draw(f(-0.05, 0.15)), draw(f(-0.05, 0.05))
    ax, ay = draw(f(0.01, 0.12)), draw(f(0.01, 0.08))
    pts = [[cx + ax * math.cos(a), cy + ay * math.sin(a)] for a in angles]
    return pts[::-1] if draw(st.booleans()) else pts


@st.composite
def heights(draw: st.DrawFn) -> list[float] | None:
    """A closed height interval (m) on a coarse scale, so that touching ends occur, or None."""
    if draw(st.booleans()):
        return None
    lo = draw(st.integers(0, 4))
    return [lo / 10, (lo + draw(st.integers(1, 3))) / 10]


@st.composite
def random_workcells(draw: st.DrawFn, *, dts: tuple[float, ...], tools: bool = False) -> Scenario:
    """Random workcells with coarse grids (a time step drawn from ``dts``): bases, links, widths,
    speeds, start and goal all vary; the right base is near enough for the arms to meet. With
    ``tools``: each arm may carry a random convex tool, and its parts random heights."""
    dt = draw(st.sampled_from(dts))
    f = st.floats

    def arm(base):
        return {"base": base,
                "links": [draw(f(0.05, 0.5)), draw(f(0.05, 0.5))],
                "width": draw(f(0.005, 0.15)),
                "omega": [draw(f(1.2, 3.0)), draw(f(1.2, 3.0))]}

    left = arm([draw(f(-0.2, 0.2)), draw(f(-0.2, 0.2))])
    start = [draw(f(-3.2, 3.2)), draw(f(-3.2, 3.2))]
    left["start"] = start
    left["goal"] = [start[q] + draw(f(-1.5, 1.5)) for q in range(2)]
    right = arm([draw(f(0.0, 0.9)), draw(f(-0.4, 0.4))])
    limits = []
    for _q in range(2):
        lo = draw(f(-math.pi, 0.0))
        limits.append([lo, lo + draw(f(0.5, 2 * math.pi))])
    right["limits"] = limits
    size = [joint_points(limits[q][0], limits[q][1], right["omega"][q], dt) for q in range(2)]
    right["start_cell"] = [draw(st.integers(0, size[q] - 1)) for q in range(2)]
    right["goal_cell"] = [draw(st.integers(0, size[q] - 1)) for q in range(2)]
    for a in (left, right) if tools else ():
        z = [draw(heights()), draw(heights())]
        if z[0] is not None and z[1] is not None:
            a["z"] = z
        if draw(st.booleans()):
            a["tool"] = {"polygon": draw(convex_tools())}
            if (tz := draw(heights())) is not None:
                a["tool"]["z"] = tz
    return parse_scenario({"name": "random", "purpose": "hypothesis", "dt": dt, "left": left,
                           "right": right}, check_budget=False)
