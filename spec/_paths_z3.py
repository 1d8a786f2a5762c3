"""docs/model.md §5 as Z3 terms: is_path (fixed semantics), J1 and J2 over a path of bounded length.

``z3_opt_path`` minimises (J1, J2) lexicographically with Z3's Optimize: Definition 5 made
executable by a solver, for tiny grids. Lengths up to ``length_bound`` lose no optimum.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass

import numpy as np
import numpy.typing as npt
import z3

from ._paths import Cell, SearchStatus, check_search_inputs, layer_of_step

__all__ = [
    "FreeFn",
    "Z3OptResult",
    "Z3Path",
    "dr_free",
    "length_bound",
    "path_vars",
    "z3_J1",
    "z3_J2",
    "z3_is_path",
    "z3_opt_path",
]

#: free(layer, x, y): cell (x, y) is free in D_R's layer (0..N-1, or N for the rest layer R).
FreeFn = Callable[[int, z3.ArithRef, z3.ArithRef], z3.BoolRef]


@dataclass(frozen=True)
class Z3Path:
    """A path of symbolic length ``length`` (1..bound), given as the cell (xs[k], ys[k]) held at
    each step k < bound: the list's cells for k < length, then the goal, where the arm waits.

    Move k is (px[k] - nx[k], py[k] - ny[k]) with parts in {0, 1} and px + nx <= 1, so that
    |d_k|_1 = px + nx + py + ny is linear (is_path ties the parts to the cells).
    """

    length: z3.ArithRef
    xs: tuple[z3.ArithRef, ...]
    ys: tuple[z3.ArithRef, ...]
    px: tuple[z3.ArithRef, ...]
    nx: tuple[z3.ArithRef, ...]
    py: tuple[z3.ArithRef, ...]
    ny: tuple[z3.ArithRef, ...]

    @property
    def bound(self) -> int:
        return len(self.xs)

    def moves(self) -> list[tuple[z3.ArithRef, z3.ArithRef]]:
        """d_k for k < bound - 1 (zero once the goal is held)."""
        return [(self.px[k] - self.nx[k], self.py[k] - self.ny[k]) for k in range(self.bound - 1)]


@dataclass(frozen=True)
class Z3OptResult:
    """Z3's optimum: status found / no_path with (J1, J2) and a path, or unknown and why."""

    status: SearchStatus | None      # None when Z3 answered unknown
    J1: int | None
    J2: int | None
    path: tuple[Cell, ...]
    reason_unknown: str | None


def length_bound(dr: npt.NDArray[np.integer]) -> int:
    """B = N + (cells free in R): if a valid path exists, some optimal one has at most B cells.

    Cutting a valid path between two visits of one cell at steps k1 < k2, both >= N, keeps it
    valid (the later cells move to steps still >= N, all in R) and never raises J1 (moves are
    removed) nor J2 (the removed terms sum_{k1..k2} |d_k - d_{k-1}| are >= |d_{k2} - d_{k1-1}|,
    the one new term, by the triangle inequality). Each cut shortens the path, so cutting until
    no cell repeats from step N on ends, at a path whose cells there are distinct and free in R.
    """
    N = dr.shape[0] - 1
    return N + int(np.count_nonzero(np.asarray(dr)[N] == 0))


def path_vars(bound: int, prefix: str = "L") -> Z3Path:
    """Fresh Z3 integer variables for a path of at most ``bound`` cells."""
    def ints(name: str, count: int) -> tuple[z3.ArithRef, ...]:
        return tuple(z3.Int(f"{prefix}_{name}{k}") for k in range(count))
    return Z3Path(z3.Int(f"{prefix}_len"), ints("x", bound), ints("y", bound),
                  ints("px", bound - 1), ints("nx", bound - 1), ints("py", bound - 1),
                  ints("ny", bound - 1))


def z3_is_path(p: Z3Path, free: FreeFn, N: int, m: int, n: int, start: Cell,
               goal: Cell) -> z3.BoolRef:
    """docs/model.md §5's is_path over p: in the grid, one move per step, start to goal, and the cell
    held at every step k < max(len, N) (the goal once the list ends) free, and the goal free in R."""
    B = p.bound
    L, xs, ys = p.length, p.xs, p.ys
    gx, gy = z3.IntVal(goal[0]), z3.IntVal(goal[1])
    parts = [L >= 1, L <= B, xs[0] == start[0], ys[0] == start[1]]
    for k in range(B):
        # L_{len-1} = goal, and the arm holds it at every later step.
        parts.append(z3.Implies(k >= L - 1, z3.And(xs[k] == gx, ys[k] == gy)))
        parts.append(z3.And(0 <= xs[k], xs[k] < m, 0 <= ys[k], ys[k] < n))
        parts.append(free(layer_of_step(k, N), xs[k], ys[k]))
    for k in range(B - 1):
        # Consecutive cells differ by -1, 0 or +1 per coordinate: the move's parts say which.
        bits = (p.px[k], p.nx[k], p.py[k], p.ny[k])
        parts += [z3.And(0 <= b, b <= 1) for b in bits]
        parts += [p.px[k] + p.nx[k] <= 1, p.py[k] + p.ny[k] <= 1,
                  xs[k + 1] == xs[k] + p.px[k] - p.nx[k], ys[k + 1] == ys[k] + p.py[k] - p.ny[k]]
    for k in range(B, N):  # steps past the bound but before the principal stops: the goal
        parts.append(free(k, gx, gy))
    parts.append(free(N, gx, gy))
    return z3.And(parts)


def z3_J1(p: Z3Path) -> z3.ArithRef:
    """J1 = sum over moves of |d_k|_1 (exact under z3_is_path; holding the goal adds zeros)."""
    return z3.Sum([z3.IntVal(0), *p.px, *p.nx, *p.py, *p.ny])


def z3_J2(p: Z3Path) -> z3.ArithRef:
    """J2 = sum_k |d_k - d_{k-1}|_1 with d_{-1} = d_{len-1} = 0, as an exact Z3 term.

    Holding the goal adds zero moves, whose terms |0 - 0| vanish, so no guard on len is needed.
    """
    return z3.Sum([_abs(e) for e in _turns(p)])


def dr_free(dr: npt.NDArray[np.integer]) -> FreeFn:
    """``free`` for a concrete D_R: (x, y) is one of the layer's free cells, and none of its
    blocked ones.

    Inside the grid either half alone says "free"; both are given because Z3 proves "no path"
    far faster with the first (a 4 x 4 wall: under a second, against no answer in 60 s with the
    second alone) and finds optima faster with the second.
    """
    layers = np.asarray(dr)
    free_cells = [list(zip(*np.nonzero(layers[k] == 0))) for k in range(layers.shape[0])]
    blocked = [list(zip(*np.nonzero(layers[k]))) for k in range(layers.shape[0])]

    def free(layer: int, x: z3.ArithRef, y: z3.ArithRef) -> z3.BoolRef:
        one_of = z3.Or([z3.And(x == int(i), y == int(j)) for i, j in free_cells[layer]]
                       or [z3.BoolVal(False)])
        none_of = [z3.Not(z3.And(x == int(i), y == int(j))) for i, j in blocked[layer]]
        return z3.And(one_of, *none_of)
    return free


def z3_opt_path(dr: npt.NDArray[np.integer], start: Cell, goal: Cell, *,
                timeout_ms: int = 20_000) -> Z3OptResult:
    """The least (J1, J2) over valid paths of at most length_bound(dr) cells, by Z3 Optimize with
    lexicographic priority; unknown (e.g. a timeout) is reported, never taken as an answer."""
    N, m, n, start, goal = check_search_inputs(dr, start, goal)
    p = path_vars(length_bound(dr))
    opt = z3.Optimize()
    opt.set(timeout=timeout_ms, priority="lex")
    opt.add(z3_is_path(p, dr_free(dr), N, m, n, start, goal))
    # J2 is minimised through the epigraph a_t >= |e_t| (a_t >= e_t, a_t >= -e_t): linear, so
    # Optimize's simplex sees it, where the If of |.| would make it case-split. At a lex optimum
    # every a_t = |e_t| (else lowering one would lower the objective at the same J1), so the two
    # minima agree; the exact z3_J2 is evaluated on the model and must equal it.
    turns = _turns(p)
    epi = [z3.Int(f"J2_epi{t}") for t in range(len(turns))]
    opt.add([z3.And(a >= e, a >= -e) for a, e in zip(epi, turns)])
    j1, j2 = z3_J1(p), z3_J2(p)
    opt.minimize(j1)
    opt.minimize(z3.Sum(epi))
    verdict = opt.check()
    if verdict == z3.unsat:
        return Z3OptResult(SearchStatus.NO_PATH, None, None, (), None)
    if verdict != z3.sat:
        return Z3OptResult(None, None, None, (), opt.reason_unknown())
    model = opt.model()

    def value(term: z3.ArithRef) -> int:
        return model.eval(term, model_completion=True).as_long()
    if value(z3.Sum(epi)) != value(j2):
        raise AssertionError("z3_opt_path: J2 epigraph above |.| at the optimum")
    path = tuple((value(p.xs[k]), value(p.ys[k])) for k in range(value(p.length)))
    return Z3OptResult(SearchStatus.FOUND, value(j1), value(j2), path, None)


def _turns(p: Z3Path) -> list[z3.ArithRef]:
    """The per-coordinate changes of move, d_k - d_{k-1} for k = 0..bound-1 (d_{-1} = 0 and the
    move after the last step is 0)."""
    zero = (z3.IntVal(0), z3.IntVal(0))
    ds = [zero, *p.moves(), zero]
    return [e for a, b in zip(ds, ds[1:]) for e in (b[0] - a[0], b[1] - a[1])]


def _abs(e: z3.ArithRef) -> z3.ArithRef:
    return z3.If(e >= 0, e, -e)
