"""BuiltDR in the paper's loop form (Algorithm 1, step 3), one cell at a time.

``builtdr_loop_nest`` is the algorithm as written: the principal's region of every layer, the
subordinate's region of every cell, then for every layer k and cell (i, j) the decision
"S_LArm[k] ∩ S_RArm[i][j] = Φ -> 0 | 1", then the rest layer. It is written in the restricted
subset that ``cfmpa.proofs`` extracts into the while-language of Theorems 1 and 3 (docs/model.md
§4.3): counted ``for`` loops over ``range(lo, hi)``, ``if``/``else``, stores ``A[idx] = e``, calls
of the helpers passed in. Edit it and the extracted program, hence the proof, changes with it.

``build_dr_loops`` runs that nest with impl's own regions (the padded polygons ``build_dr``
uses) and decision (``blocked_against``); the tests check it bit-identical to ``build_dr`` and
``build_dr_fast``. It is slow (a Python call per cell): a reference for small grids.
"""

from __future__ import annotations

from collections.abc import Callable
from typing import Any

import numpy as np

from ..spec import EPS, Grid, Scenario, Variant, make_grid, pairs_to_test
from ._builtdr import DR, left_regions, right_regions
from ._collide import PolygonSet, blocked_against

__all__ = ["build_dr_loops", "builtdr_loop_nest"]


def builtdr_loop_nest(N: int, m: int, n: int, P: Any, SL: Any, SR: Any, rule: Any,
                      region_left: Callable[[int], Any], region_right: Callable[[int, int], Any],
                      region_rest: Callable[[], Any], inter: Callable[[Any, Any], bool]) -> None:
    """Algorithm 1, step 3: fill P[0..N, 0..m-1, 0..n-1] (1 = blocked), layer N the rest layer:
    the principal at rest (``region_rest()``) when the variant's rule (``Variant.rule``) says
    its rest layer is the goal, else layer N - 1's region, as in the paper (docs/model.md §4)."""
    for k in range(0, N):
        SL[k] = region_left(k)
    for i in range(0, m):
        for j in range(0, n):
            SR[i, j] = region_right(i, j)
    for k in range(0, N):
        for i in range(0, m):
            for j in range(0, n):
                if inter(SL[k], SR[i, j]):
                    P[k, i, j] = 1
                else:
                    P[k, i, j] = 0
    for i in range(0, m):
        for j in range(0, n):
            if inter(region_rest() if rule.rest_at_goal else SL[N - 1], SR[i, j]):
                P[N, i, j] = 1
            else:
                P[N, i, j] = 0


def build_dr_loops(s: Scenario, variant: Variant | str, grid: Grid | None = None, *,
                   eps: float = EPS, nest: Callable[..., None] | None = None) -> DR:
    """D_R for ``variant`` by the loop form: uint8 (N + 1, m, n), as ``build_dr`` gives it.

    ``nest`` replaces ``builtdr_loop_nest`` (the tests run edited copies)."""
    v = Variant(variant)
    g = grid or make_grid(s)
    left = left_regions(s, v, g)
    rr = right_regions(s, g)
    m, n = g.m, g.n
    set1 = PolygonSet.of(rr.link1)
    per_cell = [PolygonSet.of(r.reshape(m * n, *r.shape[2:])) for r in rr.per_cell()]
    pairs = pairs_to_test(s.left, s.right)

    def region_left(k: int) -> tuple[Any, ...]:
        return left.links[k]

    def region_rest() -> tuple[Any, ...]:
        return left.links[g.N]

    def region_right(i: int, j: int) -> tuple[PolygonSet, ...]:
        return (set1.take(np.array([i])), *(r.take(np.array([i * n + j])) for r in per_cell))

    def inter(a: tuple[Any, ...], b: tuple[PolygonSet, ...]) -> bool:
        # Blocked iff some left part is within eps of some right part whose heights overlap
        # it (not "distance > eps").
        return any(bool(blocked_against(a[p], b[q], eps)[0]) for p, q in pairs)

    P = np.full(g.shape, 2, dtype=np.uint8)        # 2: never stored (the tests look for it)
    SL: dict[int, Any] = {}
    SR: dict[tuple[int, int], Any] = {}
    (nest or builtdr_loop_nest)(g.N, m, n, P, SL, SR, v.rule, region_left, region_right,
                                region_rest, inter)
    return P
