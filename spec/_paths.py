"""Paths over D_R, their costs and the optimal path (docs/model.md §5; the paper's Definitions 4-5).

``is_path`` is the fixed definition: the subordinate holds the goal after its list ends, so every
step up to ``max(len, N)`` and the rest layer are checked. ``is_path_paper`` is the paper's
Definition 4 word for word, kept only to show its flaw. ``opt_path`` computes Definition 5's
optimum by a plain Dijkstra over capped states (not by ranging over every list); it is the
spec's independent oracle for searchoptpath. ``is_opt_path`` is Definition 5's condition on
one list, decided with that optimum.
"""

from __future__ import annotations

import heapq
from collections.abc import Sequence
from dataclasses import dataclass, field
from enum import Enum
from typing import TYPE_CHECKING, Any

import numpy as np
import numpy.typing as npt

from ..errors import InputError

if TYPE_CHECKING:
    from ._witness import Witness

__all__ = [
    "Cell",
    "MOVES",
    "PathViolation",
    "REASON_GOAL_BLOCKED",
    "REASON_START_BLOCKED",
    "REASON_UNREACHABLE",
    "SearchResult",
    "SearchStatus",
    "J1",
    "J2",
    "check_search_inputs",
    "is_opt_path",
    "is_path",
    "is_path_paper",
    "layer_of_step",
    "opt_path",
    "path_violations",
]

Cell = tuple[int, int]
State = tuple[int, int, int, int, int]

#: The nine moves of one step, (di, dj) in lexicographic order; (0, 0) (waiting) is a move.
MOVES: tuple[Cell, ...] = tuple((di, dj) for di in (-1, 0, 1) for dj in (-1, 0, 1))

REASON_START_BLOCKED = "start blocked in layer 0"
REASON_GOAL_BLOCKED = "goal blocked in the rest layer"
REASON_UNREACHABLE = "unreachable"


class SearchStatus(str, Enum):
    """Whether a search found a path."""

    FOUND = "found"
    NO_PATH = "no_path"

    def __str__(self) -> str:
        return self.value


@dataclass(frozen=True)
class SearchResult:
    """The outcome of an optimal-path search: the path and its (J1, J2), or no path and why.

    ``witness`` is the search's certificate when it was asked for one (``spec.check_witness``
    verifies it, docs/model.md §11); it takes no part in comparisons."""

    status: SearchStatus
    reason: str | None
    path: tuple[Cell, ...]
    J1: int | None
    J2: int | None
    witness: Witness | None = field(default=None, compare=False, repr=False)

    def __post_init__(self) -> None:
        object.__setattr__(self, "status", SearchStatus(self.status))  # accept "found" too

    @classmethod
    def no_path(cls, reason: str) -> SearchResult:
        return cls(SearchStatus.NO_PATH, reason, (), None, None)

    @classmethod
    def found(cls, path: Sequence[Cell], j1: int, j2: int) -> SearchResult:
        return cls(SearchStatus.FOUND, None, tuple((int(i), int(j)) for i, j in path),
                   int(j1), int(j2))

    def as_json(self) -> dict[str, Any]:
        """The plan.json keys of docs/model.md §9 that a search decides."""
        return {"status": self.status.value, "reason": self.reason,
                "path": [[i, j] for i, j in self.path], "J1": self.J1, "J2": self.J2}


@dataclass(frozen=True)
class PathViolation:
    """One failed clause of ``is_path``: which clause, and the step, cell and layer involved."""

    clause: str            # empty | outside_grid | not_adjacent | wrong_start | wrong_goal | blocked
    step: int | None
    cell: Cell | None
    layer: int | None
    message: str

    def __str__(self) -> str:
        return self.message


def layer_of_step(k: int, N: int) -> int:
    """The index into D_R of the layer in force at step k: k for k < N, the rest layer N after."""
    return k if k < N else N


def check_search_inputs(dr: Any, start: Any, goal: Any) -> tuple[int, int, int, Cell, Cell]:
    """(N, m, n, start, goal) for a D_R array of shape (N + 1, m, n) and two cells inside it.

    Raises InputError naming the bad argument otherwise.
    """
    shape = getattr(dr, "shape", None)
    if shape is None or len(shape) != 3 or shape[0] < 2 or shape[1] < 1 or shape[2] < 1:
        raise InputError("dr", shape, "must be an array of shape (N + 1, m, n) with N, m, n >= 1")
    N, m, n = shape[0] - 1, shape[1], shape[2]
    return N, m, n, _cell_arg("start", start, m, n), _cell_arg("goal", goal, m, n)


def is_path(path: Sequence[Cell], dr: npt.NDArray[np.integer], start: Cell, goal: Cell) -> bool:
    """True iff ``path`` is valid under the fixed semantics of docs/model.md §5 (waiting at goal checked)."""
    return not path_violations(path, dr, start, goal)


def path_violations(path: Sequence[Cell], dr: npt.NDArray[np.integer], start: Cell,
                    goal: Cell) -> list[PathViolation]:
    """Every failed clause of the fixed ``is_path``, clause by clause in the order of docs/model.md §5.

    Empty means valid. Steps k >= len are the subordinate holding its last cell (the goal).
    """
    N, m, n = dr.shape[0] - 1, dr.shape[1], dr.shape[2]
    cells = [(int(c[0]), int(c[1])) for c in path]
    if not cells:
        return [PathViolation("empty", None, None, None, "path is empty")]
    out: list[PathViolation] = []
    inside = [0 <= i < m and 0 <= j < n for i, j in cells]
    for k, (c, ok) in enumerate(zip(cells, inside)):
        if not ok:
            out.append(PathViolation("outside_grid", k, c, None,
                                     f"step {k}: cell {c} is outside the {m} x {n} grid"))
    for k in range(len(cells) - 1):
        a, b = cells[k], cells[k + 1]
        if abs(b[0] - a[0]) > 1 or abs(b[1] - a[1]) > 1:
            out.append(PathViolation("not_adjacent", k, b,
                                     None, f"step {k}->{k + 1}: {a} to {b} is not one move"))
    if cells[0] != tuple(start):
        out.append(PathViolation("wrong_start", 0, cells[0], None,
                                 f"step 0: path starts at {cells[0]}, not at start {tuple(start)}"))
    last = len(cells) - 1
    if cells[last] != tuple(goal):
        out.append(PathViolation("wrong_goal", last, cells[last], None,
                                 f"step {last}: path ends at {cells[last]}, not at goal {tuple(goal)}"))
    # The arm occupies cells[k] for k < len, then holds its last cell for ever: through the
    # remaining motion layers and in the rest layer R.
    for k in range(max(len(cells), N)):
        c, ok = (cells[k], inside[k]) if k < len(cells) else (cells[last], inside[last])
        layer = layer_of_step(k, N)
        if ok and dr[layer, c[0], c[1]] != 0:
            out.append(PathViolation("blocked", k, c, layer,
                                     f"step {k}: cell {c} is blocked in layer {layer}"))
    if len(cells) <= N and inside[last] and dr[N, cells[last][0], cells[last][1]] != 0:
        # When len > N the loop above already checked the last cell in R.
        out.append(PathViolation("blocked", None, cells[last], N,
                                 f"after the motion: final cell {cells[last]} is blocked in the "
                                 f"rest layer {N}"))
    return out


def is_path_paper(path: Sequence[Cell], dr: npt.NDArray[np.integer], start: Cell,
                  goal: Cell) -> bool:
    """The paper's Definition 4 (is_path_def) read literally; NOT the definition the project uses.

    Its flaw: only steps k < LENGTH(L) are checked, so a path that arrives early and waits at a
    goal the principal later sweeps passes. Read literally it also never checks any pair with a
    cell outside the grid, nor the last cell: the clause for k = LENGTH(L) - 1 needs
    L_{k+1} = L_{LENGTH(L)}, and this function takes that element to be no grid cell.

    That is a chosen reading. In HOL4 an element past the end is not absent but unspecified:
    with L_k = EL k L, L_{LENGTH(L)} = HD [], one fixed unknown pair, the same for every list.
    Were it a grid cell, the clause would also ask the goal to be one move from it and free at
    step LENGTH(L) - 1 (layer N - 1 from N on), and no list at all would reach a goal not next
    to it. The flaw holds under every reading that lets some list reach the goal: the early-arrival
    path's goal is free at its own last step, and steps LENGTH(L) .. N - 1, where it is swept,
    are checked under none.
    """
    N, m, n = dr.shape[0] - 1, dr.shape[1], dr.shape[2]
    cells = [(int(c[0]), int(c[1])) for c in path]
    # L_0 of an empty list is unspecified in HOL; no empty list is taken to be a path.
    if not cells or cells[0] != tuple(start) or cells[-1] != tuple(goal):
        return False
    # forall i j k i' j'. i < m /\ i' < m /\ j < n /\ j' < n /\ k < LENGTH L ==>
    #   L_k = (i, j) /\ L_{k+1} = (i', j') ==> adjacent /\ (k < N ==> P_{k,i,j} = 0)
    #                                          /\ (k >= N ==> P_{N-1,i,j} = 0)
    # At k = LENGTH L - 1, L_{k+1} is taken to be no grid cell (see above): antecedent never met.
    for k in range(len(cells) - 1):
        (i, j), (i2, j2) = cells[k], cells[k + 1]
        if not (0 <= i < m and 0 <= i2 < m and 0 <= j < n and 0 <= j2 < n):
            continue
        if not (abs(i2 - i) <= 1 and abs(j2 - j) <= 1):
            return False
        if dr[k if k < N else N - 1, i, j] != 0:
            return False
    return True


def J1(path: Sequence[Cell]) -> int:
    """The paper's shortest movement: sum over moves d_k = L_{k+1} - L_k of |d_k|_1."""
    return sum(abs(dx) + abs(dy) for dx, dy in _moves(path))


def J2(path: Sequence[Cell]) -> int:
    """Smoothness: sum over k = 0..len-1 of |d_k - d_{k-1}|_1, with d_{-1} = d_{len-1} = (0, 0).

    The arm starts and ends at rest, so waiting at the goal after arriving changes neither cost.
    """
    if not path:
        return 0
    ds = [(0, 0), *_moves(path), (0, 0)]
    return sum(abs(b[0] - a[0]) + abs(b[1] - a[1]) for a, b in zip(ds, ds[1:]))


def opt_path(dr: npt.NDArray[np.integer], start: Cell, goal: Cell) -> SearchResult:
    """The least (J1, J2), lexicographically, over all valid paths (Definition 5's optimum), and
    one path reaching it; or no path, and why.

    Not Definition 5 read literally (an epsilon-choice over every list that is_path accepts):
    a plain Dijkstra with tuple costs over states (step capped at N, cell, previous move). The
    two agree because layers at steps >= N are all R, so states there with equal (cell,
    previous move) have the same futures at the same costs; the tests check the agreement
    against every list up to length_bound cells (grids up to 3 x 3, N <= 3) and against Z3's
    Optimize. Only (status, reason, J1, J2) are specified; which optimal path it returns is not.
    """
    N, m, n, start, goal = check_search_inputs(dr, start, goal)
    free = (np.asarray(dr) == 0).tolist()
    if not free[0][start[0]][start[1]]:
        return SearchResult.no_path(REASON_START_BLOCKED)
    if not free[N][goal[0]][goal[1]]:
        return SearchResult.no_path(REASON_GOAL_BLOCKED)
    # State (s, i, j, di, dj): at cell (i, j) at step s (capped at N), arrived by move (di, dj).
    # A path ends at its goal; waiting there to step N costs nothing more (see J2), so the
    # finished paths are exactly the states (N, goal, d), plus a last J2 term |d|_1 to stop.
    done = (N + 1, 0, 0, 0, 0)  # the sink; a tuple of ints so heap entries stay comparable
    first = (0, start[0], start[1], 0, 0)
    best: dict[State, tuple[int, int]] = {first: (0, 0)}
    parent: dict[State, State | None] = {first: None}
    heap: list[tuple[int, int, State]] = [(0, 0, first)]
    while heap:
        c1, c2, state = heapq.heappop(heap)
        if best[state] != (c1, c2):
            continue  # a stale entry; the state was settled at a lower cost
        if state == done:
            return SearchResult.found(_unwind(parent, done, goal), c1, c2)
        s, i, j, pi, pj = state
        if s == N and (i, j) == goal:
            _relax(best, parent, heap, done, (c1, c2 + abs(pi) + abs(pj)), state)
        s2 = min(s + 1, N)
        layer = free[s2]
        for di, dj in MOVES:
            i2, j2 = i + di, j + dj
            if 0 <= i2 < m and 0 <= j2 < n and layer[i2][j2]:
                cost = (c1 + abs(di) + abs(dj), c2 + abs(di - pi) + abs(dj - pj))
                _relax(best, parent, heap, (s2, i2, j2, di, dj), cost, state)
    return SearchResult.no_path(REASON_UNREACHABLE)


def is_opt_path(path: Sequence[Cell], dr: npt.NDArray[np.integer], start: Cell,
                goal: Cell) -> bool:
    """Definition 5's condition on one list: valid, and no valid list has a smaller (J1, J2).

    Decided as is_path(path) and (J1, J2)(path) = opt_path's optimum, so it is exact as far as
    opt_path is (see there); any of the optimal lists passes, not only the one opt_path returns.
    """
    if not is_path(path, dr, start, goal):
        return False
    best = opt_path(dr, start, goal)
    return best.status is SearchStatus.FOUND and (J1(path), J2(path)) == (best.J1, best.J2)


def _relax(best: dict[State, tuple[int, int]], parent: dict[State, State | None],
           heap: list[tuple[int, int, State]], state: State, cost: tuple[int, int],
           via: State) -> None:
    old = best.get(state)
    if old is None or cost < old:
        best[state] = cost
        parent[state] = via
        heapq.heappush(heap, (cost[0], cost[1], state))


def _unwind(parent: dict[State, State | None], done: State, goal: Cell) -> list[Cell]:
    cells: list[Cell] = []
    state = parent[done]
    while state is not None:
        cells.append((state[1], state[2]))
        state = parent[state]
    cells.reverse()
    # Trailing waits at the goal are the arm holding it; the shortest list drops them.
    while len(cells) > 1 and cells[-2] == goal:
        cells.pop()
    return cells


def _cell_arg(name: str, value: Any, m: int, n: int) -> Cell:
    try:
        i, j = (int(v) for v in value)
        exact = all(int(v) == v for v in value)
    except (TypeError, ValueError):
        raise InputError(name, value, "must be a cell (i, j) of two integers") from None
    if not exact:
        raise InputError(name, value, "must be a cell (i, j) of two integers")
    if not (0 <= i < m and 0 <= j < n):
        raise InputError(name, value, f"must be a cell inside the {m} x {n} grid")
    return (i, j)


def _moves(path: Sequence[Cell]) -> list[Cell]:
    return [(int(b[0]) - int(a[0]), int(b[1]) - int(a[1])) for a, b in zip(path, path[1:])]
