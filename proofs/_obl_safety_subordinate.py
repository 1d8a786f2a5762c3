"""Part (b) of the end-to-end safety theorem (docs/model.md §10),
``Safety.subordinate_in_cell_box``: the linear move from cell L_k to a neighbour stays in L_k's
box over the whole step; on a valid path every step is such a move, a wait once the list has
ended.
"""

from __future__ import annotations

from dataclasses import dataclass

import z3

from ..spec import (
    cell_box,
)
from ..spec.z3defs import (
    Z3Dims,
    abs_int,
    adjacent,
    in_grid,
    is_path_fixed,
    position,
    z3_path,
)
from ._lemmas import Lemma, lemma
from ._obl_safety_principal import in_box, step_window
from ._z3vec import (
    Vec,
)
from ._z3vec import vec as _v

_R = z3.RealSort()

# --- (b) the subordinate in its cell's box -----------------------------------------------------

@dataclass(frozen=True)
class Subordinate:
    lo: Vec
    h: Vec

    @classmethod
    def named(cls) -> Subordinate:
        return cls(_v("R.lo"), _v("R.h"))

    def angle(self, c: tuple[z3.ArithRef, z3.ArithRef]) -> Vec:
        return (self.lo[0] + z3.ToReal(c[0]) * self.h[0], self.lo[1] + z3.ToReal(c[1]) * self.h[1])

    def box(self, c: tuple[z3.ArithRef, z3.ArithRef]) -> tuple[Vec, Vec]:
        """spec.cell_box (spec.right_box's rule) run on the symbols."""
        return cell_box(self.lo, self.h, (z3.ToReal(c[0]), z3.ToReal(c[1])))

    def theta(self, c: tuple[z3.ArithRef, z3.ArithRef], c2: tuple[z3.ArithRef, z3.ArithRef],
              k: z3.ArithRef, t: z3.ArithRef, dt: z3.ArithRef) -> Vec:
        """The linear move in joint space from c (at k dt) to c2 (at (k+1) dt)."""
        f = (t - z3.ToReal(k) * dt) / dt
        a, b = self.angle(c), self.angle(c2)
        return (a[0] + f * (b[0] - a[0]), a[1] + f * (b[1] - a[1]))


def subordinate_lemmas(*, reach: int = 1) -> tuple[Lemma, Lemma]:
    """(b): a move to a neighbour stays in the cell's box; on a valid path every step is one
    (a wait once the list has ended). ``reach`` is the tests' mutant (2: a jump of two cells)."""
    S = Subordinate.named()
    dt, t = z3.Real("dt"), z3.Real("t")
    k = z3.Int("k")
    c, c2 = (z3.Int("c.i"), z3.Int("c.j")), (z3.Int("c'.i"), z3.Int("c'.j"))
    key = "c' a neighbour of c: |c'_q - c_q| <= 1"
    hyps = (("dt > 0", dt > 0), ("h_q > 0", z3.And(S.h[0] > 0, S.h[1] > 0)), ("k >= 0", k >= 0),
            ("k dt <= t <= (k+1) dt", step_window(k, t, dt)),
            (key, z3.And(abs_int(c2[0] - c[0]) <= reach, abs_int(c2[1] - c[1]) <= reach)))
    move = lemma("neighbour_move", hyps, in_box(S.theta(c, c2, k, t, dt), S.box(c)), key,
                 names=dict(c=c, c2=c2, k=k, t=t))
    d = Z3Dims.named()
    ints = z3.IntSort()
    P = z3.Array("P", ints, ints, ints, ints)
    start, goal = (z3.Int("start.i"), z3.Int("start.j")), (z3.Int("goal.i"), z3.Int("goal.j"))
    L = z3_path("L")
    key2 = "is_path L (fixed, docs/model.md §5)"
    here, nxt = position(L, k), position(L, k + 1)
    hyps2 = (("N >= 1, m, n >= 1", d.sane()),
             ("start, goal in the grid", z3.And(in_grid(d, start), in_grid(d, goal))),
             (key2, is_path_fixed(P, d, start, goal, L)), ("k >= 0", k >= 0))
    goal2 = z3.And(in_grid(d, here), adjacent(here, nxt),
                   z3.Implies(k + 1 >= L.length, z3.And(here[0] == goal[0], here[1] == goal[1],
                                                        nxt[0] == goal[0], nxt[1] == goal[1])))
    on_path = lemma("on_path", hyps2, goal2, key2, names=dict(k=k))
    return move, on_path
