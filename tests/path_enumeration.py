"""Definition 5 by brute force, for tests: every list of cells up to a length, kept if is_path
accepts it and no other list has a smaller (J1, J2). Shares no code with the searches."""

from __future__ import annotations

import numpy as np

from cfmpa.spec._paths import J1, J2, MOVES, is_path, layer_of_step

Cell = tuple[int, int]


def optimal_lists(dr: np.ndarray, start: Cell, goal: Cell, max_len: int
                  ) -> tuple[tuple[int, int] | None, set[tuple[Cell, ...]]]:
    """The least (J1, J2) over lists of at most ``max_len`` cells that is_path accepts, and every
    such list reaching it with its trailing waits dropped; (None, set()) if none is valid.

    Depth first over in-grid move sequences. A prefix is cut only when no extension within
    ``max_len`` can be an optimal path: a cell of the list blocked at its own step (is_path
    checks every step k < len), the goal more moves away than cells are left, or partial costs
    already above the best found (J1 and the J2 terms so far only grow, so an extension costs at
    least as much, lexicographically). Nothing is searched when is_path's own clauses rule out
    every list: the start blocked in layer 0 or the goal blocked in the rest layer.
    """
    N, m, n = dr.shape[0] - 1, dr.shape[1], dr.shape[2]
    free = (np.asarray(dr) == 0).tolist()
    best: list[tuple[int, int] | None] = [None]
    found: set[tuple[Cell, ...]] = set()

    def visit(path: list[Cell], j1: int, j2: int, last: Cell) -> None:
        if best[0] is not None and (j1, j2) > best[0]:
            return
        if path[-1] == goal and is_path(path, dr, start, goal):
            cost = (J1(path), J2(path))
            if best[0] is None or cost < best[0]:
                best[0] = cost
                found.clear()
            if cost == best[0]:
                found.add(_drop_trailing_waits(path))
        i, j = path[-1]
        if len(path) == max_len or max(abs(goal[0] - i), abs(goal[1] - j)) > max_len - len(path):
            return
        layer = free[layer_of_step(len(path), N)]
        for di, dj in MOVES:
            c = (i + di, j + dj)
            if 0 <= c[0] < m and 0 <= c[1] < n and layer[c[0]][c[1]]:
                path.append(c)
                visit(path, j1 + abs(di) + abs(dj), j2 + abs(di - last[0]) + abs(dj - last[1]),
                      (di, dj))
                path.pop()

    if free[0][start[0]][start[1]] and free[N][goal[0]][goal[1]]:
        visit([start], 0, 0, (0, 0))
    return best[0], found


def _drop_trailing_waits(path: list[Cell]) -> tuple[Cell, ...]:
    cells = list(path)
    while len(cells) > 1 and cells[-2] == cells[-1]:
        cells.pop()
    return tuple(cells)
