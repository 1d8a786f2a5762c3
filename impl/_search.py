"""searchoptpath (the paper's step 4; docs/model.md §5): the exact least-(J1, J2) path over D_R.

The search is a shortest path over states (s, c, p): step s capped at N, cell c, previous move p.
Steps 0..N-1 form a DAG and are solved layer by layer over whole (3, 3, m, n) arrays; the
static graph at the capped step N is solved by a bucket (Dial) queue over J1 whose buckets are
expanded as vectorised frontiers.
"""

from __future__ import annotations

import os
import tempfile
from collections.abc import Callable, Iterator
from dataclasses import replace
from typing import IO, Any

import numpy as np
import numpy.typing as npt

from ..errors import InputError
from ..spec import (
    MOVES,
    REASON_GOAL_BLOCKED,
    REASON_START_BLOCKED,
    REASON_UNREACHABLE,
    SPILL_BYTES,
    Cell,
    LayerSpill,
    SearchResult,
    Witness,
    check_search_inputs,
    spill_wanted,
)

__all__ = ["BackPointers", "WitnessLabels", "hold_waits", "search_opt_path"]

IntArray = npt.NDArray[np.int64]
BoolArray = npt.NDArray[np.bool_]

#: Costs are one int64 key J1 * 2**SHIFT + J2. The key orders like the pair (J1, J2) as long as
#: 0 <= J2 < 2**SHIFT, and every path has J2 <= 2 * J1 (each move's |d|_1 enters J2 at most
#: twice, as |d_k - d_{k-1}| <= |d_k| + |d_{k-1}|), with J1 <= 2 per step; see _check_size.
SHIFT = 31
J2_MASK = (1 << SHIFT) - 1
INF = np.int64(1) << np.int64(61)
WAIT = MOVES.index((0, 0))
_MOVE = np.asarray(MOVES, dtype=np.int64)
#: |d|_1 per move d (MOVES order): what stopping after d adds to J2.
_MOVE_NORM = np.abs(_MOVE).sum(axis=1)
#: |d - p|_1 per pair of moves [p, d]: what turning from p to d adds to J2.
_MOVE_GAP = np.abs(_MOVE[:, None, :] - _MOVE[None, :, :]).sum(axis=2)
#: |d|_1 of the move with index (di + 1, dj + 1) (MOVES runs over di, then dj, from -1 to 1).
_STEP_J1 = _MOVE_NORM.reshape(3, 3)


def _prepare(dr: npt.NDArray[np.integer], start: Cell, goal: Cell, with_witness: bool
             ) -> tuple[tuple[Any, ...], SearchResult | None]:
    """What both searches do first: the checked inputs, the free mask (C-contiguous), the
    blocked-end reason and the witness labels; or the early answer when an end is blocked (the
    goal's only without a witness: with one, the search still settles the reachable states)."""
    N, m, n, start, goal = check_search_inputs(dr, start, goal)
    free = FreeLayers(dr)
    reason = (REASON_START_BLOCKED if not free[0, start[0], start[1]] else
              REASON_GOAL_BLOCKED if not free[N, goal[0], goal[1]] else None)
    if reason is not None and not with_witness:
        return (), SearchResult.no_path(reason)
    _check_size(N, m, n)
    labels = WitnessLabels(N, m, n) if with_witness else None
    if reason == REASON_START_BLOCKED:
        assert labels is not None       # a blocked start returns early above without a witness
        return (), replace(SearchResult.no_path(reason), witness=labels.witness(found=False))
    return (N, m, n, start, goal, free, reason, labels), None


def search_opt_path(dr: npt.NDArray[np.integer], start: Cell, goal: Cell, *,
                    with_witness: bool = False) -> SearchResult:
    """The least (J1, J2), lexicographically, over all valid paths of any length (exact), or why none.

    Exactness: this is a shortest path over states (step s capped at N, cell, previous move) with
    edge cost (|d|_1, |d - p|_1) for move d after move p. Capping loses no path because every
    layer at steps >= N is R, so two states at steps >= N with equal (cell, previous move) allow
    the same continuations at the same costs. A path ends at the goal; holding the goal up to
    step N costs nothing (the J2 term |0 - d_last| is paid either way), so the finished paths are
    the states (N, goal, d) plus a final J2 term |d|_1. The returned list drops trailing waits.
    At the capped step waits are dropped too: wait-then-move costs |p| + |d| >= |d - p| in J2.

    Ties (deterministic), on the returned list L: it never waits at a step >= N before its end,
    L_{k+1} != L_k for N <= k < len - 1 (dropping such a wait keeps a path valid and costs no
    more), and among the optimal lists that do not, it is the least by this order. Pad L with
    the goal to N + 1 cells if shorter (the arm
    holds it until the principal stops): cells L_0 .. L_T, T = max(len - 1, N), moves
    d_k = L_{k+1} - L_k. Rank the last move d_{T-1} by its index in MOVES; rank each earlier
    d_k by its index if it arrives before step N (k + 1 < N), by 9 + its index if it arrives at
    step N or later. The ranks read backwards, d_{T-1} first, are lexicographically least.
    (Internally: the least last move over the goal states; then, for each state, its optimal
    predecessor with the state at step N itself before one at a later step, then the one with
    the least previous move.)
    Reasons, checked in this order: start blocked in layer 0, goal blocked in the rest layer,
    unreachable.

    ``with_witness``: the result also carries its certificate (``SearchResult.witness``,
    docs/model.md §11): the exact (J1, J2) label of every state when a path is found, else the
    set of states reachable from the start. The labels of steps < N are the DAG's; the capped
    step's Dial search then runs until every reachable state is settled (it stops at the goal
    otherwise), and a wait at step N gets the label of the state it holds plus |p|_1 (waits
    are left out of the search, being never better). The path and costs are the same either way.
    """
    return search_by_phases(dr, start, goal, with_witness, _dag_phase, _static_phase)


def search_by_phases(dr: npt.NDArray[np.integer], start: Cell, goal: Cell, with_witness: bool,
                     dag_phase: Callable[[FreeLayers, Cell, WitnessLabels | None],
                                         tuple[IntArray, BackPointers]],
                     static_phase: Callable[..., Any]) -> SearchResult:
    """searchoptpath's driver: the early exits (``_prepare``), ``dag_phase`` (steps 0..N, its
    keys and back-pointers), ``static_phase`` (the capped step), the walk back and the witness.
    The reference passes its own phases; the numpy kernel (``_numpy_search``) passes faster
    ones with the same results, and so shares everything else."""
    setup, early = _prepare(dr, start, goal, with_witness)
    if early is not None:
        return early
    N, m, n, start, goal, free, reason, labels = setup
    keys, dag_pred = dag_phase(free, start, labels)
    with dag_pred:                  # its temporary file closed once the path is walked back
        found = static_phase(free[N], keys, goal, labels)
        if found is None:
            result = SearchResult.no_path(reason or REASON_UNREACHABLE)
        else:
            key, last, static_pred, static_from = found
            path = _unwind(goal, last, start, static_pred, static_from, dag_pred)
            result = SearchResult.found(path, key >> SHIFT, key & J2_MASK)
    if labels is None:
        return result
    return replace(result, witness=labels.witness(found=found is not None))


class FreeLayers:
    """D_R's free masks, one layer at a time: ``free[s]`` is ``dr[s] == 0`` (C-contiguous bool),
    made when asked for, so that the search holds no second D_R-sized array."""

    def __init__(self, dr: npt.NDArray[np.integer]) -> None:
        self.dr = dr
        self.shape = tuple(dr.shape)

    def __getitem__(self, key: Any) -> Any:
        return np.ascontiguousarray(np.asarray(self.dr[key]) == 0)


#: Back-pointers held in memory past this many bytes go to a temporary file (BackPointers).
BACK_POINTER_BYTES = SPILL_BYTES


class BackPointers:
    """The DAG steps' back-pointers, compact: for step s = 1..N, the previous move (index into
    MOVES, int8) of each state's optimal predecessor, kept only on the box of cells within s
    moves of the start, rows r0:r1 and columns c0:c1 of ``box(s)``. A state at step s outside
    that box has no label (a move changes each coordinate by at most 1), so nothing is lost: the
    pointers take 9 (2 s + 1)^2 bytes at step s at most, instead of 9 m n.

    Once the finished steps' pointers held pass ``spill_bytes`` (default
    ``BACK_POINTER_BYTES``, 64 MiB), they are moved to an unnamed temporary file (``TMPDIR``),
    as every later step's is when the next one is made; ``at`` then reads its one byte there.
    So the search's memory does not grow with N beyond that (the walk back reads N bytes)."""

    def __init__(self, start: Cell, m: int, n: int, spill_bytes: int | None = None) -> None:
        self.start, self.m, self.n = start, m, n
        #: Step s's pointers at index s - 1; None once moved to the file.
        self.layers: list[npt.NDArray[np.int8] | None] = []
        self.spill_bytes = BACK_POINTER_BYTES if spill_bytes is None else spill_bytes
        self._held = 0
        self._file: IO[bytes] | None = None
        self._offsets: dict[int, int] = {}             # step index -> its offset in the file
        self._end = 0

    @property
    def spilled(self) -> int:
        """The steps whose pointers are in the temporary file."""
        return len(self._offsets)

    def close(self) -> None:
        """Close (and so remove) the temporary file, once the path is walked back; idempotent."""
        if self._file is not None:
            self._file.close()

    def __enter__(self) -> BackPointers:
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()

    def _settle(self) -> None:
        """Every step made so far is finished: past ``spill_bytes`` held, to the file."""
        if self._held <= self.spill_bytes:
            return
        if self._file is None:
            self._file = tempfile.TemporaryFile(prefix="cfmpa-backpointers-")
        for k, a in enumerate(self.layers):
            if a is None:
                continue
            self._file.write(np.ascontiguousarray(a).data)
            self._offsets[k] = self._end
            self._end += a.nbytes
            self._held -= a.nbytes
            self.layers[k] = None
        self._file.flush()

    @property
    def N(self) -> int:
        return len(self.layers)

    def box(self, s: int) -> tuple[int, int, int, int]:
        """(r0, r1, c0, c1): the rows and columns within s moves of the start."""
        i, j = self.start
        return max(0, i - s), min(self.m, i + s + 1), max(0, j - s), min(self.n, j + s + 1)

    def new(self, s: int) -> npt.NDArray[np.int8]:
        """Step s's pointers (9, r1 - r0, c1 - c0), -1 (no predecessor) until written; steps are
        made in order 1, 2, ..."""
        if s != self.N + 1:
            raise AssertionError(f"BackPointers.new({s}) after step {self.N}")
        self._settle()
        r0, r1, c0, c1 = self.box(s)
        a = np.full((9, r1 - r0, c1 - c0), -1, dtype=np.int8)
        self.layers.append(a)
        self._held += a.nbytes
        return a

    def at(self, s: int, d: int, i: int, j: int) -> int:
        """The previous move of state (s, (i, j), d)'s optimal predecessor."""
        r0, r1, c0, c1 = self.box(s)
        if not (r0 <= i < r1 and c0 <= j < c1):
            raise AssertionError(f"BackPointers.at: cell {(i, j)} is not within {s} moves of "
                                 f"the start {self.start}")
        a = self.layers[s - 1]
        if a is not None:
            return int(a[d, i - r0, j - c0])
        assert self._file is not None
        at = self._offsets[s - 1] + (d * (r1 - r0) + i - r0) * (c1 - c0) + j - c0
        return int.from_bytes(os.pread(self._file.fileno(), 1, at), "little", signed=True)


class WitnessLabels:
    """A search's labels, step by step, as the witness's arrays j1, j2 (N + 1, 9, m, n).

    The type is uint16 when every label of the DAG steps fits (J1 <= 2 s, J2 <= 4 s at step s,
    so when 4 N + 4 < 65535), else uint32; the capped step's labels widen it when they do not
    fit. The type's largest value marks a state without a label.

    Arrays larger than ``spec.SPILL_BYTES`` together (or with ``spill=True``) are not held: each
    step's labels are appended to a ``spec.LayerSpill`` (a temporary file) as they are made, in
    step order, and the witness reads them back one layer at a time (``spec.Layers``).
    """

    def __init__(self, N: int, m: int, n: int, spill: bool | None = None) -> None:
        dtype = np.uint16 if 4 * N + 4 < np.iinfo(np.uint16).max else np.uint32
        self.N = N
        self.shape = (N + 1, 9, m, n)
        if spill is None:
            spill = spill_wanted(2 * (N + 1) * 9 * m * n * np.dtype(dtype).itemsize)
        self.spills: tuple[LayerSpill, LayerSpill] | None = None
        if spill:
            self.spills = (LayerSpill(self.shape, dtype), LayerSpill(self.shape, dtype))
        else:
            self.j1 = np.full(self.shape, np.iinfo(dtype).max, dtype=dtype)
            self.j2 = np.full(self.shape, np.iinfo(dtype).max, dtype=dtype)

    @property
    def dtype(self) -> np.dtype[Any]:
        return self.spills[0].dtype if self.spills is not None else self.j1.dtype

    def put(self, s: int, keys: IntArray, box: tuple[int, int, int, int] | None = None) -> None:
        """Step s's keys (9, m, n), INF for no label; only rows r0:r1, columns c0:c1 of
        ``box`` = (r0, r1, c0, c1) when given (no label elsewhere). Spilled, steps are put in
        order 0, 1, ..., N."""
        r0, r1, c0, c1 = box or (0, keys.shape[1], 0, keys.shape[2])
        k = keys[:, r0:r1, c0:c1]
        reached = k < INF
        none = np.iinfo(self.dtype).max
        finite = k[reached]
        if finite.size and max(int(finite.max() >> SHIFT), int((finite & J2_MASK).max())) >= none:
            # Widened, "no label" stays "no label" in the steps already put (the old type's
            # largest value is a label value in uint32).
            if self.spills is not None:
                old = self.spills
                self.spills = (old[0].widened(np.uint32), old[1].widened(np.uint32))
                for spill in old:
                    spill.close()
            else:
                self.j1, self.j2 = (np.where(a == none, np.iinfo(np.uint32).max,
                                             a.astype(np.uint32)) for a in (self.j1, self.j2))
            none = np.iinfo(np.uint32).max
        if self.spills is None:
            self.j1[s, :, r0:r1, c0:c1] = np.where(reached, k >> SHIFT, none)
            self.j2[s, :, r0:r1, c0:c1] = np.where(reached, k & J2_MASK, none)
            return
        if s != self.spills[0].written:
            raise AssertionError(f"WitnessLabels.put: step {s} after {self.spills[0].written}")
        for spill, part in zip(self.spills, (k >> SHIFT, k & J2_MASK)):
            spill.append(np.where(reached, part, none).astype(self.dtype), (r0, r1, c0, c1))

    def witness(self, *, found: bool) -> Witness:
        """The labels, or (no path) the set of labelled states: those reachable from the start."""
        none = np.iinfo(self.dtype).max
        if self.spills is not None:
            while self.spills[0].written < self.shape[0]:    # steps never reached: no labels
                for spill in self.spills:
                    spill.append(np.zeros((9, 0, 0), dtype=self.dtype), (0, 0, 0, 0))
            j1, j2 = self.spills[0].layers(), self.spills[1].layers()
            if found:
                return Witness.of_labels(j1, j2)
            j2.close()                      # the set reads j1 only: closed here, not by the GC
            return Witness.of_reachable(j1.map(lambda a: a != none, np.bool_))
        if found:
            return Witness.of_labels(self.j1, self.j2)
        return Witness.of_reachable(self.j1 != none)


def hold_waits(keys: IntArray) -> IntArray:
    """The capped step's keys (9, m, n) with each wait's key lowered to the least key of a
    state at the same cell plus |p|_1 (a wait at step N after move p costs (0, |p|_1))."""
    norm = _STEP_J1.reshape(9, 1, 1)
    via = np.min(np.where(keys < INF, keys + norm, INF), axis=0)
    keys[WAIT] = np.minimum(keys[WAIT], via)
    return keys


def _check_size(N: int, m: int, n: int) -> None:
    # A label is the cost of a chain of distinct states (at most N + 9 m n moves, J1 <= 2 each)
    # or one move more, so J1 <= 2 (N + 9 m n + 1) and J2 <= 2 J1. Exact keys below INF need
    # J1 < 2**30 (then J2 < 2**31 = 2**SHIFT).
    if 2 * (N + 9 * m * n + 1) >= 1 << 30:
        raise InputError("dr", (N + 1, m, n), "is too large for the search's int64 cost keys")


def _dag_phase(free: FreeLayers, start: Cell, labels: WitnessLabels | None = None
               ) -> tuple[IntArray, BackPointers]:
    """Keys of the states at step N (shape (3, 3, m, n), move index (di+1, dj+1)), and per step
    s = 1..N the previous move (index into MOVES) of each state's optimal predecessor, on the
    box of s moves (``BackPointers``). Only one step's keys are held at a time; the keys of steps
    0..N-1 go to ``labels`` when given."""
    N = free.shape[0] - 1
    m, n = free.shape[1:]
    keys = np.full((3, 3, m, n), INF, dtype=np.int64)
    keys[1, 1, start[0], start[1]] = 0  # step 0: at start, "arrived" by the rest move (0, 0)
    preds = BackPointers(start, m, n)
    for s in range(1, N + 1):
        if labels is not None:
            labels.put(s - 1, keys.reshape(9, m, n))
        keys, pred = _step(keys, np.where(free[s], np.int64(0), INF))
        r0, r1, c0, c1 = preds.box(s)
        preds.new(s)[:] = pred.reshape(9, m, n)[:, r0:r1, c0:c1]
    return keys, preds


def _static_phase(free_rest: BoolArray, initial: IntArray, goal: Cell,
                  labels: WitnessLabels | None = None
                  ) -> tuple[int, int, npt.NDArray[np.int8], BoolArray] | None:
    """Dial's algorithm over the states (cell, previous move) at the capped step N.

    Returns (key of the best finished path, its last move, predecessor moves, and whether each
    state's predecessor is itself at step N) or None when the goal is unreachable. Buckets hold
    J1. Waits are left out: at steps >= N a wait after move p then a move d costs |p| + |d| in J2,
    never less than turning at once, |d - p|; every other move costs J1 >= 1, so a bucket's
    states are final once the buckets before it are expanded. With ``labels`` it goes on past
    the goal until every reachable state is settled (settled states keep their key and
    predecessor, so the answer is the same) and gives the final keys, waits held, to step N.
    """
    m, n = free_rest.shape
    M = m * n
    keys = initial.reshape(9 * M).copy()  # state u = move * M + cell
    pred = np.full(9 * M, -1, dtype=np.int8)
    from_static = np.zeros(9 * M, dtype=bool)
    done = np.zeros(9 * M, dtype=bool)
    norm, gap = _MOVE_NORM, _MOVE_GAP                # gap[p, d] = |d - p|_1
    targets = _targets(free_rest)
    goal_states = np.arange(9) * M + goal[0] * n + goal[1]

    buckets: dict[int, list[IntArray]] = {}
    _push(buckets, np.flatnonzero(keys < INF), keys)
    answer = None
    for _, u in settled_buckets(buckets, keys, done, unique=True):
        if answer is None and (finished := goal_finish(keys, done, goal_states)) is not None:
            answer = *finished, pred, from_static
            if labels is None:
                return answer
        # Expand every move but the wait from the settled frontier.
        cells = u % M
        prev = u // M
        cand_u, cand_k, cand_p = [], [], []
        for d in range(9):
            if d == WAIT:
                continue
            to = targets[d][cells]
            ok = to >= 0
            cand_u.append(d * M + to[ok])
            cand_k.append(keys[u[ok]] + (norm[d] << SHIFT) + gap[prev[ok], d])
            cand_p.append(prev[ok])
        improved = _improve(keys, pred, from_static, done, np.concatenate(cand_u),
                            np.concatenate(cand_k), np.concatenate(cand_p))
        _push(buckets, improved, keys)
    if labels is not None:
        labels.put(labels.N, hold_waits(keys.reshape(9, m, n)))
    return answer


def settled_buckets(buckets: dict[int, list[IntArray]], keys: IntArray, done: BoolArray, *,
                    unique: bool) -> Iterator[tuple[int, IntArray]]:
    """Dial's order over ``buckets`` (J1 -> lists of states; later ones may be added between
    yields): (J1, its states not yet done whose key still has that J1), each marked done as it
    is yielded; with ``unique`` each state once and in ascending order."""
    b = 0
    while buckets:
        chunk = buckets.pop(b, None)
        b += 1
        if chunk is None:
            continue
        u = chunk[0] if len(chunk) == 1 else np.concatenate(chunk)
        if unique:
            u = np.unique(u)
        u = u[~done[u] & ((keys[u] >> SHIFT) == b - 1)]
        if u.size == 0:
            continue
        done[u] = True
        yield b - 1, u


def goal_finish(keys: IntArray, done: BoolArray, goal_states: IntArray) -> tuple[int, int] | None:
    """(key of the best path stopping at the goal, its last move) once a goal state is done, else
    None. Stopping after move d adds |d|_1 to J2 (the low bits of the key); ties go to the
    smallest move."""
    if not done[goal_states].any():
        return None
    finish = np.where(done[goal_states], keys[goal_states] + _MOVE_NORM, INF)
    last = int(np.argmin(finish))
    return int(finish[last]), last


def _improve(keys: IntArray, pred: npt.NDArray[np.int8], from_static: BoolArray,
             done: BoolArray, to: IntArray, key: IntArray, prev: IntArray) -> IntArray:
    """Lower keys[to] to key where strictly better (first the least key, then the least prev move
    among candidates for one state); returns the states improved."""
    live = ~done[to]
    to, key, prev = to[live], key[live], prev[live]
    if to.size == 0:
        return to
    order = np.lexsort((prev, key, to))
    to, key, prev = to[order], key[order], prev[order]
    first = np.ones(to.size, dtype=bool)
    first[1:] = to[1:] != to[:-1]
    to, key, prev = to[first], key[first], prev[first]
    # Strict: on equal keys the existing label stays, so a DAG predecessor (earlier step) wins.
    better = key < keys[to]
    to = to[better]
    keys[to] = key[better]
    pred[to] = prev[better]
    from_static[to] = True
    return to


def _push(buckets: dict[int, list[IntArray]], states: IntArray, keys: IntArray) -> None:
    if states.size == 0:
        return
    j1 = keys[states] >> SHIFT
    for value in np.unique(j1):
        buckets.setdefault(int(value), []).append(states[j1 == value])


def _unwind(goal: Cell, last: int, start: Cell, static_pred: npt.NDArray[np.int8],
            from_static: BoolArray, dag_pred: BackPointers) -> list[Cell]:
    """The cells of the optimal path, from the predecessor moves, without trailing waits."""
    n = dag_pred.n
    M = dag_pred.m * n
    N = dag_pred.N
    cells = [goal]
    i, j, d = goal[0], goal[1], last
    while from_static[d * M + i * n + j]:  # back through the capped step N
        p = int(static_pred[d * M + i * n + j])
        i, j = i - MOVES[d][0], j - MOVES[d][1]
        d = p
        cells.append((i, j))
    for s in range(N, 0, -1):  # back through the DAG steps N .. 1
        p = dag_pred.at(s, d, i, j)
        i, j = i - MOVES[d][0], j - MOVES[d][1]
        d = p
        cells.append((i, j))
    if cells[-1] != start:
        raise AssertionError(f"search_opt_path: back-tracking reached {cells[-1]}, not {start}")
    cells.reverse()
    while len(cells) > 1 and cells[-2] == goal:
        cells.pop()
    return cells


def _step(keys: IntArray, block_next: IntArray) -> tuple[IntArray, npt.NDArray[np.int8]]:
    """One DAG step: new[d, c + d] = min_p keys[p, c] + (|d|_1 << SHIFT) + |d - p|_1.

    |d - p|_1 splits by coordinate, so the min over the 9 previous moves is two mins over 3.
    """
    m, n = keys.shape[2:]
    best, pred_here = _best_moves(keys)
    new = np.full((3, 3, m, n), INF, dtype=np.int64)
    pred = np.full((3, 3, m, n), -1, dtype=np.int8)  # read only where new < INF
    for d1 in range(3):
        for d2 in range(3):
            dst, src = _shift_slices(d1 - 1, d2 - 1, m, n)
            new[d1, d2][dst] = best[d1, d2][src]
            pred[d1, d2][dst] = pred_here[d1, d2][src]
    # Blocked cells hold no state (block_next is INF there, else 0); sums that reach INF are
    # "unreachable" and are clamped back to INF (INF = 2**61, so two INFs still fit in int64).
    np.add(new, block_next, out=new)
    np.minimum(new, INF, out=new)
    return new, pred


def _best_moves(keys: IntArray) -> tuple[IntArray, npt.NDArray[np.int8]]:
    """Per move d and cell c of ``keys`` (3, 3, ...): min_p keys[p, c] + (|d|_1 << SHIFT) +
    |d - p|_1 and the least minimising previous move p (as an index 0..8), before the move."""
    # Over p2 (moved to the front): t[d2, p1] = min_p2 keys[p1, p2] + |d2 - p2|.
    t, arg2 = _min_plus_gap(keys.transpose(1, 0, 2, 3))
    # Over p1: best[d1, d2] = min_p1 t[d2, p1] + |d1 - p1|. Both keep the smallest index on
    # ties, so the chosen (p1, p2) is the lexicographically smallest optimal previous move.
    best, arg1 = _min_plus_gap(t.transpose(1, 0, 2, 3))
    # arg2[d2, arg1[d1, d2]], gathered by packing the three 2-bit p2 choices of each d2 in a byte
    a = arg2.astype(np.uint8)
    packed = a[:, 0] | (a[:, 1] << 2) | (a[:, 2] << 4)
    arg2_chosen = (packed[None] >> (2 * arg1).astype(np.uint8)) & 3
    pred_here = (arg1 * 3 + arg2_chosen).astype(np.int8)
    best += (_STEP_J1 << SHIFT)[:, :, None, None]
    return best, pred_here


def _min_plus_gap(x: IntArray) -> tuple[IntArray, npt.NDArray[np.int8]]:
    """out[d] = min over p of x[p] + |d - p| for d, p in 0..2, and the least minimising p."""
    out = np.empty_like(x)
    arg = np.zeros(x.shape, dtype=np.int8)
    for d in range(3):
        best = out[d]
        np.add(x[0], d, out=best)
        for p in (1, 2):
            v = x[p] + abs(d - p)
            better = v < best  # strict: the smaller p stays on ties
            np.copyto(best, v, where=better)
            np.copyto(arg[d], p, where=better)
    return out, arg


def _targets(free_rest: BoolArray) -> list[IntArray]:
    """For each move d, the flat index of c + d for every flat cell c, or -1 if outside or blocked."""
    m, n = free_rest.shape
    index = np.arange(m * n, dtype=np.int64).reshape(m, n)
    out = []
    for di, dj in MOVES:
        to = np.full((m, n), -1, dtype=np.int64)
        dst, src = _shift_slices(di, dj, m, n)
        to[src] = np.where(free_rest[dst], index[dst], -1)
        out.append(to.reshape(m * n))
    return out


def _shift_slices(di: int, dj: int, m: int, n: int) -> tuple[Any, Any]:
    """(dst, src) slices with dst = src shifted by (di, dj), both inside an m x n grid."""
    def one(d: int, size: int) -> tuple[slice, slice]:
        return (slice(d, size), slice(0, size - d)) if d >= 0 else (slice(0, size + d),
                                                                    slice(-d, size))
    (a, b), (c, e) = one(di, m), one(dj, n)
    return (a, c), (b, e)
