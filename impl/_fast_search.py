"""searchoptpath, fast: the reference's states, costs and tie-break, in compiled loops.

Same answer as ``search_opt_path``: the same (J1, J2), status, reason and path. The states
(step capped at N, cell, previous move), the int64 keys J1 * 2**SHIFT + J2, the input checks, the
size check and the walk back (``_unwind``) are the reference's own. What differs is how labels
are computed, and the tie-break is a property of the labels, not of the order of work:

- DAG steps 1..N: the same min over the 9 previous moves with the least move index kept on ties
  (the reference's two-stage min keeps the lexicographically least (p1, p2), which is the least
  index 3 p1 + p2); only the cells within s moves of the start are visited at step s.
- The capped step N: Dial's buckets over J1, as in the reference, with waits left out. Every
  static predecessor of a state (c, d) has J1 = J1(c, d) - |d|_1, so all of them are expanded
  together, before (c, d) is; keeping the least key and, on equal keys, the least previous move
  among them, and a DAG label against an equal static one, is exactly the reference's rule.
- It stops at the first bucket holding a goal state, and finishes with the least key + |d|_1
  over the goal states of that bucket, the least move on ties, as the reference does.

So the tie-break is the one ``search_opt_path``'s docstring states on the returned path.
``with_witness`` gives the reference's witness too (the same arrays): the DAG steps' labels are
written as they are computed, and the capped step's buckets run on until every reachable state
is settled.
"""

from __future__ import annotations

from dataclasses import replace

import numpy as np
import numpy.typing as npt
from numba import njit

from ..spec import MOVES, REASON_UNREACHABLE, Cell, SearchResult
from ._kernel_cache import ensure_compiled
from ._progress import progress_bar
from ._search import INF, J2_MASK, SHIFT, WAIT, BackPointers, _prepare, _unwind, hold_waits

__all__ = ["search_opt_path_fast"]

_DI = np.array([d[0] for d in MOVES], dtype=np.int64)
_DJ = np.array([d[1] for d in MOVES], dtype=np.int64)
_NORM = np.abs(_DI) + np.abs(_DJ)                                            # |d|_1
_GAP = np.abs(_DI[:, None] - _DI[None, :]) + np.abs(_DJ[:, None] - _DJ[None, :])  # |d - p|_1


def search_opt_path_fast(dr: npt.NDArray[np.integer], start: Cell, goal: Cell, *,
                         progress: bool | None = None, with_witness: bool = False
                         ) -> SearchResult:
    """The same result as ``search_opt_path`` (least (J1, J2), its path, or why none), and with
    ``with_witness`` the same witness."""
    ensure_compiled()
    setup, early = _prepare(dr, start, goal, with_witness)
    if early is not None:
        return early
    N, m, n, start, goal, free, reason, labels = setup
    dag_pred = BackPointers(start, m, n)               # on the box of s moves, per step
    keys = np.full((9, m, n), INF, dtype=np.int64)
    spare = np.full((9, m, n), INF, dtype=np.int64)
    keys[WAIT, start[0], start[1]] = 0                 # step 0: at start, "arrived" by waiting
    with progress_bar("search", N + 1, (N + 1) * m * n, progress) as bar:
        for s in range(1, N + 1):
            if labels is not None:                     # labels only within s - 1 moves
                labels.put(s - 1, keys, (max(0, start[0] - s + 1), min(m, start[0] + s),
                                         max(0, start[1] - s + 1), min(n, start[1] + s)))
            _dag_step(free[s], keys, spare, dag_pred.new(s), start[0], start[1], s,
                      _DI, _DJ, _NORM, _GAP, SHIFT, INF)
            keys, spare = spare, keys
            bar.advance()
        M = m * n
        pred = np.full(9 * M, -1, dtype=np.int8)
        from_static = np.zeros(9 * M, dtype=np.bool_)
        goal_flat = goal[0] * n + goal[1]
        key, last = _static_phase(free[N].reshape(M), n, keys.reshape(9 * M), pred, from_static,
                                  goal_flat, _DI, _DJ, _NORM, _GAP, SHIFT, INF, WAIT,
                                  labels is not None)
        bar.advance()
    with dag_pred:                  # its temporary file closed once the path is walked back
        if key < 0:
            result = SearchResult.no_path(reason or REASON_UNREACHABLE)
        else:
            path = _unwind(goal, int(last), start, pred, from_static, dag_pred)
            result = SearchResult.found(path, key >> SHIFT, key & J2_MASK)
    if labels is None:
        return result
    labels.put(N, hold_waits(keys))
    return replace(result, witness=labels.witness(found=key >= 0))


# ---------------------------------------------------------------- compiled kernels (numba) ----

@njit(cache=True)
def _dag_step(free, keys, out, pred, si, sj, s, DI, DJ, NORM, GAP, shift, inf
              ):  # pragma: no cover - compiled; its results are tested against search_opt_path
    """Step s: out[d, c] = min over p of keys[p, c - d] + |d - p|_1 + (|d|_1 << shift), the least
    p on ties into pred[d, c - (i0, j0)] (pred holds the box of s moves only, BackPointers);
    inf where c is blocked or no finite label reaches it."""
    m, n = free.shape
    i0, i1 = max(0, si - s), min(m - 1, si + s)   # cells within s moves of the start
    j0, j1 = max(0, sj - s), min(n - 1, sj + s)
    for i in range(i0, i1 + 1):
        for j in range(j0, j1 + 1):
            if not free[i, j]:
                for d in range(9):
                    out[d, i, j] = inf
                continue
            for d in range(9):
                pi, pj = i - DI[d], j - DJ[d]
                best, arg = inf, -1
                if 0 <= pi < m and 0 <= pj < n:
                    for p in range(9):
                        k = keys[p, pi, pj]
                        if k < inf:
                            v = k + GAP[p, d]
                            if v < best:
                                best, arg = v, p
                if arg >= 0:
                    out[d, i, j] = best + (NORM[d] << shift)
                    pred[d, i - i0, j - j0] = arg
                else:
                    out[d, i, j] = inf


@njit(cache=True)
def _grow(buf, count):  # pragma: no cover - compiled
    """buf with room for one more after its first ``count`` entries (doubled when full; a plain
    loop: slice assignment costs seconds of compile)."""
    if count < buf.shape[0]:
        return buf
    bigger = np.empty(2 * buf.shape[0], dtype=np.int64)
    for k in range(count):
        bigger[k] = buf[k]
    return bigger


@njit(cache=True)
def _by_j1(keys, shift, inf):  # pragma: no cover - compiled
    """The states with a finite key, stably sorted by J1 (a counting sort: the order of a stable
    argsort of J1 over them, taken in index order), and their J1s."""
    count, lo, hi = 0, inf, -1
    for u in range(keys.shape[0]):
        if keys[u] < inf:
            count += 1
            b = keys[u] >> shift
            lo = min(lo, b)
            hi = max(hi, b)
    initial = np.empty(count, dtype=np.int64)
    j1 = np.empty(count, dtype=np.int64)
    if count == 0:
        return initial, j1
    at = np.zeros(hi - lo + 2, dtype=np.int64)
    for u in range(keys.shape[0]):
        if keys[u] < inf:
            at[(keys[u] >> shift) - lo + 1] += 1
    for w in range(hi - lo):
        at[w + 1] += at[w]
    for u in range(keys.shape[0]):
        if keys[u] < inf:
            b = (keys[u] >> shift) - lo
            initial[at[b]] = u
            j1[at[b]] = b + lo
            at[b] += 1
    return initial, j1


@njit(cache=True)
def _static_phase(free, n, keys, pred, from_static, goal, DI, DJ, NORM, GAP, shift, inf, wait,
                  complete):  # pragma: no cover - compiled; tested against search_opt_path
    """Dial's buckets over J1 at the capped step N; returns (finish key, last move), or (-1, -1)
    when the goal is unreachable. State u = move * M + cell; keys start as the DAG's labels.
    ``complete``: go on past the goal's bucket until every reachable state is settled (settled
    states are never changed, so the answer is the same)."""
    M = free.shape[0]
    m = M // n
    done = np.zeros(keys.shape[0], dtype=np.bool_)
    initial, init_j1 = _by_j1(keys, shift, inf)   # as sorted; a key may drop later
    nxt = 0                                            # next unread state of ``initial``
    # Moves cost J1 1 or 2, so the open buckets are b, b + 1, b + 2: a ring of three.
    ring0 = np.empty(1024, dtype=np.int64)
    ring1 = np.empty(1024, dtype=np.int64)
    ring2 = np.empty(1024, dtype=np.int64)
    size = np.zeros(3, dtype=np.int64)
    frontier = np.empty(1024, dtype=np.int64)
    b = 0 if initial.shape[0] == 0 else init_j1[0]
    found_key, found_last = inf, -1
    while nxt < initial.shape[0] or size[0] + size[1] + size[2] > 0:
        if size[0] + size[1] + size[2] == 0 and init_j1[nxt] > b:
            b = init_j1[nxt]                           # skip empty buckets
        slot = b % 3
        count = 0
        while nxt < initial.shape[0] and init_j1[nxt] == b:
            u = initial[nxt]
            nxt += 1
            if not done[u] and keys[u] >> shift == b:
                done[u] = True
                frontier = _grow(frontier, count)
                frontier[count] = u
                count += 1
        ring = ring0 if slot == 0 else (ring1 if slot == 1 else ring2)
        for r in range(size[slot]):
            u = ring[r]
            if not done[u] and keys[u] >> shift == b:
                done[u] = True
                frontier = _grow(frontier, count)
                frontier[count] = u
                count += 1
        size[slot] = 0
        if found_last < 0:
            best, last = inf, -1
            for d in range(9):                         # the least move on equal finishes
                u = d * M + goal
                if done[u] and keys[u] + NORM[d] < best:
                    best, last = keys[u] + NORM[d], d
            if last >= 0:
                found_key, found_last = best, last
                if not complete:
                    return found_key, found_last
        for f in range(count):
            u = frontier[f]
            p, c = u // M, u % M
            i, j = c // n, c % n
            for d in range(9):
                if d == wait:
                    continue
                ti, tj = i + DI[d], j + DJ[d]
                if ti < 0 or ti >= m or tj < 0 or tj >= n or not free[ti * n + tj]:
                    continue
                v = d * M + ti * n + tj
                if done[v]:
                    continue
                cand = keys[u] + (NORM[d] << shift) + GAP[p, d]
                if cand < keys[v]:
                    keys[v] = cand
                    pred[v] = p
                    from_static[v] = True
                    target = (b + NORM[d]) % 3
                    if target == 0:
                        ring0 = _grow(ring0, size[0])
                        ring0[size[0]] = v
                    elif target == 1:
                        ring1 = _grow(ring1, size[1])
                        ring1[size[1]] = v
                    else:
                        ring2 = _grow(ring2, size[2])
                        ring2[size[2]] = v
                    size[target] += 1
                elif cand == keys[v] and from_static[v] and p < pred[v]:
                    pred[v] = p                         # equal keys: the least previous move
        b += 1
    if found_last >= 0:
        return found_key, found_last
    return -1, -1
