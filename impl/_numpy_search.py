"""searchoptpath without a compile: the reference's states, costs and tie-break in faster numpy,
with the fast search's signature (docs/model.md §7.5).

The "numpy" kernel's search (``_kernels``): a run uses it while the fast kernels are compiled
in the background. Same answer as ``search_opt_path`` (status, reason, J1, J2, the path with
its tie-break) and, with ``with_witness`` (the default here: a run under full contracts then
verifies that witness instead of asking the fast search for one, which would compile it in the
foreground), the same witness arrays. The driver (``search_by_phases``: the input and size
checks, the walk back, the witness), the back-pointers and the labels (``BackPointers``,
``WitnessLabels``, ``hold_waits``) are the reference's own; this module gives the driver its two
phases. What differs is how the labels are computed:

- DAG steps 1..N: the reference's ``_step`` arithmetic (the same ``_best_moves``, the same
  int64 sums clamped to INF) on the box of cells within s - 1 moves of the start only, shifted
  into the box of s moves: outside it every key is INF in the reference too (a move changes each
  coordinate by at most 1), and the labels are put on that box (``WitnessLabels.put``).
- The capped step N: Dial's buckets over J1 as in the reference, with waits left out, but each
  bucket's frontier expanded over its 8 moves at once, and the per-state choice (least key, then
  least previous move) made with one ``np.minimum.at`` instead of a sort. Every candidate for a
  state (c, d) made from one bucket has the same J1 (bucket + |d|_1), so comparing
  (J2, previous move) among them is the reference's (key, previous move) order; a label is
  lowered only by a strictly smaller key, as in the reference, so a DAG label keeps an equal
  static one out. A bucket's states are found without ``np.unique``: a state held twice is
  expanded twice, giving the same candidates twice, which changes no minimum.
"""

from __future__ import annotations

import numpy as np
import numpy.typing as npt

from ..spec import Cell, SearchResult
from ._search import (
    _MOVE_GAP,
    _MOVE_NORM,
    INF,
    J2_MASK,
    SHIFT,
    WAIT,
    BackPointers,
    FreeLayers,
    WitnessLabels,
    _best_moves,
    _targets,
    goal_finish,
    hold_waits,
    search_by_phases,
    settled_buckets,
)

__all__ = ["search_opt_path_numpy"]

IntArray = npt.NDArray[np.int64]

_NORM, _GAP = _MOVE_NORM, _MOVE_GAP                                   # |d|_1, |d - p|_1
#: The moves expanded at the capped step (every one but the wait), and per move its J1 part.
_EXPAND = np.asarray([d for d in range(9) if d != WAIT], dtype=np.int64)
_EXPAND_J1 = _NORM[_EXPAND] << SHIFT
#: A state's (J2, previous move) as one int64: J2 < 2**SHIFT, the move < 2**_PREV_BITS.
_PREV_BITS = 4
_NO_CANDIDATE = np.iinfo(np.int64).max


def search_opt_path_numpy(dr: npt.NDArray[np.integer], start: Cell, goal: Cell, *,
                          progress: bool | None = None, with_witness: bool = True
                          ) -> SearchResult:
    """The same result as ``search_opt_path(dr, start, goal, with_witness=with_witness)``
    (least (J1, J2), its path, or why none; the same witness); ``progress`` is accepted for the
    fast search's signature and ignored."""
    del progress
    return search_by_phases(dr, start, goal, with_witness, _dag_phase, _static_phase)


def _dag_phase(free: FreeLayers, start: Cell, labels: WitnessLabels | None = None
               ) -> tuple[IntArray, BackPointers]:
    """The reference's ``_dag_phase`` (keys at step N (3, 3, m, n), back-pointers, the labels of
    steps 0..N-1 put), computed on the box of s moves at step s."""
    N = free.shape[0] - 1
    m, n = free.shape[1:]
    preds = BackPointers(start, m, n)
    # ``canvas`` is every step's keys on the whole grid, INF outside the current box: the boxes
    # grow with s, so writing each step's box into it keeps the rest INF.
    canvas = np.full((3, 3, m, n), INF, dtype=np.int64)
    box = preds.box(0)
    keys = np.full((3, 3, 1, 1), INF, dtype=np.int64)
    keys[1, 1, 0, 0] = 0            # step 0: at start, "arrived" by the rest move (0, 0)
    for s in range(1, N + 1):
        r0, r1, c0, c1 = box
        if labels is not None:
            canvas[:, :, r0:r1, c0:c1] = keys
            labels.put(s - 1, canvas.reshape(9, m, n), box)
        nbox = preds.box(s)
        keys, pred = _step(keys, box, nbox, free[s, nbox[0]:nbox[1], nbox[2]:nbox[3]])
        preds.new(s)[:] = pred.reshape(9, *pred.shape[2:])
        box = nbox
    r0, r1, c0, c1 = box
    canvas[:, :, r0:r1, c0:c1] = keys
    return canvas, preds


def _step(keys: IntArray, box: tuple[int, int, int, int], nbox: tuple[int, int, int, int],
          free_next: npt.NDArray[np.bool_]) -> tuple[IntArray, npt.NDArray[np.int8]]:
    """The reference's ``_step`` from the keys on ``box`` (3, 3, rows, cols) to those on
    ``nbox``, a box one cell larger on every side (clipped to the grid), holding every cell a
    move reaches from ``box``: the same sums, the same least previous move on ties."""
    best, pred_here = _best_moves(keys)
    r0, r1, c0, c1 = box
    R0, R1, C0, C1 = nbox
    h, w = R1 - R0, C1 - C0
    new = np.full((3, 3, h, w), INF, dtype=np.int64)
    pred = np.full((3, 3, h, w), -1, dtype=np.int8)   # read only where new < INF
    for d1 in range(3):
        for d2 in range(3):
            # rows of ``box`` whose target row r + d1 - 1 lies in nbox: nbox holds every row
            # of box moved by one, except where the grid ends (nbox clipped there).
            di, dj = d1 - 1, d2 - 1
            i0, i1 = max(r0, R0 - di), min(r1, R1 - di)
            j0, j1 = max(c0, C0 - dj), min(c1, C1 - dj)
            src = (slice(i0 - r0, i1 - r0), slice(j0 - c0, j1 - c0))
            dst = (slice(i0 + di - R0, i1 + di - R0), slice(j0 + dj - C0, j1 + dj - C0))
            new[d1, d2][dst] = best[d1, d2][src]
            pred[d1, d2][dst] = pred_here[d1, d2][src]
    np.add(new, np.where(free_next, np.int64(0), INF), out=new)
    np.minimum(new, INF, out=new)
    return new, pred


def _static_phase(free_rest: npt.NDArray[np.bool_], initial: IntArray, goal: Cell,
                  labels: WitnessLabels | None = None
                  ) -> tuple[int, int, npt.NDArray[np.int8], npt.NDArray[np.bool_]] | None:
    """The reference's ``_static_phase`` (the same return, the same labels put at step N), each
    bucket's frontier expanded in one batch (see the module docstring)."""
    m, n = free_rest.shape
    M = m * n
    keys = initial.reshape(9 * M).copy()  # state u = move * M + cell
    pred = np.full(9 * M, -1, dtype=np.int8)
    from_static = np.zeros(9 * M, dtype=bool)
    done = np.zeros(9 * M, dtype=bool)
    every = _targets(free_rest)
    targets = np.stack([every[d] for d in _EXPAND])                      # (8, M): c + d or -1
    base = (_EXPAND * M)[:, None]
    gap_t = np.ascontiguousarray(_GAP[:, _EXPAND].T)                     # (8, 9): |d - p|_1
    goal_states = np.arange(9) * M + goal[0] * n + goal[1]
    scratch = np.full(9 * M, _NO_CANDIDATE, dtype=np.int64)

    buckets: dict[int, list[IntArray]] = {}
    reached = np.flatnonzero(keys < INF)
    j1 = keys[reached] >> SHIFT
    order = np.argsort(j1, kind="stable")
    reached, j1 = reached[order], j1[order]
    cuts = np.flatnonzero(j1[1:] != j1[:-1]) + 1
    for part in np.split(reached, cuts) if reached.size else ():
        buckets[int(keys[part[0]] >> SHIFT)] = [part]
    answer = None
    for bucket, u in settled_buckets(buckets, keys, done, unique=False):
        if answer is None and (finished := goal_finish(keys, done, goal_states)) is not None:
            answer = *finished, pred, from_static
            if labels is None:
                return answer
        cells = u % M
        prev = u // M
        to = targets.take(cells, axis=1)                         # (8, F)
        ok = to >= 0
        to = (to + base)[ok]
        key = (keys[u][None, :] + _EXPAND_J1[:, None] + gap_t.take(prev, axis=1))[ok]
        prev = np.broadcast_to(prev, ok.shape)[ok]
        live = ~done[to]
        to, key, prev = to[live], key[live], prev[live]
        if to.size == 0:
            continue
        # Per state, the least (J2, previous move); its J1 is the same for all (see above).
        rank = ((key & J2_MASK) << _PREV_BITS) | prev
        np.minimum.at(scratch, to, rank)
        win = scratch[to] == rank
        scratch[to] = _NO_CANDIDATE
        to, key, prev = to[win], key[win], prev[win]
        better = key < keys[to]            # strict: an equal existing label stays
        to, key, prev = to[better], key[better], prev[better]
        if to.size == 0:
            continue
        keys[to] = key
        pred[to] = prev
        from_static[to] = True
        diagonal = (key >> SHIFT) != bucket + 1
        for later, states in ((bucket + 1, to[~diagonal]), (bucket + 2, to[diagonal])):
            if states.size:
                buckets.setdefault(later, []).append(states)
    if labels is not None:
        labels.put(labels.N, hold_waits(keys.reshape(9, m, n)))
    return answer
