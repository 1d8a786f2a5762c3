"""Witnesses of searchoptpath's answer and their checker (docs/model.md §11).

A certifying search (McConnell, Mehlhorn, Näher, Schweitzer, "Certifying algorithms", 2011)
returns, with its answer, a witness that this small checker verifies without trusting the search.

**States.** ``(s, c, p)``: step ``s`` capped at N, cell ``c``, previous move ``p`` (an index
into ``MOVES``; the start is ``(0, start, WAIT)``, the arm at rest). A state is free when ``c`` is
free in layer ``s`` (``D_R[s][c] == 0``; from N on the layer is the rest layer R). A **free edge**
is a move ``d`` from a free state ``(s, c, p)`` to the free state ``(min(s + 1, N), c + d, d)``,
``c + d`` in the grid; it costs ``(|d|_1, |d - p|_1)``, what ``J1`` and ``J2`` add for that step.
The **admissible goal states** are ``(N, goal, p)`` for every ``p`` when the goal is free in R:
there the arm can hold the goal for ever, and stopping costs ``(0, |p|_1)`` more (J2's last term).

A valid path (the fixed ``is_path``), padded with the goal to ``T + 1 = max(len, N + 1)`` cells, is
a walk along free edges from the start to an admissible goal state, and its (J1, J2) is the walk's
cost plus the stop term (padding with the goal changes neither cost).

**Labels** (a path was found): arrays ``j1``, ``j2`` of shape ``(N + 1, 9, m, n)`` (step, previous
move, cell), of one unsigned integer type; its largest value marks a state without a label. The
checker's conditions, in order:

- ``witness.form``: the shape, the type, a label in both arrays or in neither, and
  ``j1 < 2**30``, ``j2 < 2**31`` (so that the checker's sums are exact in int64);
- ``witness.start``: the start state's label is ``(0, 0)``;
- ``witness.edge``: every free edge from a labelled state ends at a labelled state, and
  ``label[s'] <= label[s] + cost(s, s')``, lexicographically on (J1, J2);
- ``witness.path``: the returned path is valid (``is_path``);
- ``witness.goal``: its (J1, J2) equals the least ``label + (0, |p|_1)`` over the labelled
  admissible goal states.

By induction over the prefixes of any valid path, every state on its walk is labelled at most the
prefix's cost; so its (J1, J2) is at least the least goal label, which is the returned path's: the
returned path is optimal (obligation ``Witness.labels_sound``).

**Reachable set** (no path): a boolean array ``reachable`` of shape ``(N + 1, 9, m, n)``:

- ``witness.form``: the shape and the type;
- ``witness.start``: the start state is in the set when the start is free in layer 0;
- ``witness.closure``: every free edge from a state of the set ends in the set;
- ``witness.exclusion``: no admissible goal state is in the set.

A valid path's walk would stay in the set and end at an admissible goal state: no valid path
exists (obligation ``Witness.reachable_sound``).

The checker shares no code with impl/; it reads each layer once, on the bounding box of the
labelled (or reached) states, and names the first failing condition with its state, edge and
labels.

**The conditions, written once.** Each test the checker makes at a state or an edge is one of the
functions below (``label_key`` .. ``exclusion_breaks``). They use only ``+ - * == <= < & | ~``
and ``abs``, so they run on numpy integer or Boolean arrays (as the checker calls them) and on
Z3 terms (as ``proofs/_obl_witness.py`` calls them): the soundness proof is about these very
conditions, and an edit of one changes the proved statement (a loosened one fails the proof).
Labels are compared as keys ``J1 * 2**32 + J2`` (``label_key``), lexicographic as long as J2 and
the sums below stay under 2**32, which ``witness.form``'s ``label_in_range`` ensures (proved in
the VC ``labels.edge``).
"""

from __future__ import annotations

import io
import zipfile
from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np
import numpy.typing as npt

from ..errors import MISSING, InputError
from ..files import LIMITS, check_file_size
from ._layers import Layers, layered, npz_member
from ._paths import J1, J2, MOVES, SearchResult, SearchStatus, path_violations
from ._triples import Failure

__all__ = ["KEY_BASE", "LABEL_LIMITS", "WITNESS_FORMAT", "Witness", "check_witness",
           "closure_breaks", "edge_bound", "edge_holds", "exclusion_breaks", "goal_holds",
           "label_in_range", "label_key", "load_witness", "start_breaks", "start_label_breaks",
           "step_cost", "stop_key"]

#: The tag a witness file carries (npz member ``format``).
WITNESS_FORMAT = "cfmpa-witness-1"
#: Labels must lie below these (J1, J2): then keys J1 * 2**32 + J2 and their sums are exact.
LABEL_LIMITS = (1 << 30, 1 << 31)

#: The weight of J1 in a label's key J1 * KEY_BASE + J2.
KEY_BASE = 1 << 32

Array = npt.NDArray[Any]


# --- the checker's conditions: on numpy arrays and on Z3 terms ----------------------------------
# Nothing here may use Python's `and`, `or`, `not`, `if` or a call numpy and Z3 do not share.


def label_key(j1: Any, j2: Any) -> Any:
    """The key J1 * KEY_BASE + J2 by which labels are compared."""
    return j1 * KEY_BASE + j2


def label_in_range(j1: Any, j2: Any) -> Any:
    """witness.form's range: J1 < 2**30 and J2 < 2**31 (unsigned: both >= 0)."""
    return (j1 < LABEL_LIMITS[0]) & (j2 < LABEL_LIMITS[1])


def step_cost(d: tuple[Any, Any], p: tuple[Any, Any]) -> tuple[Any, Any]:
    """(|d|_1, |d - p|_1): what J1 and J2 add for the move d after the move p."""
    return abs(d[0]) + abs(d[1]), abs(d[0] - p[0]) + abs(d[1] - p[1])


def edge_bound(source_key: Any, cost: tuple[Any, Any]) -> Any:
    """The key of label[s] + cost(s, s'): cost's J1 part weighs KEY_BASE, its J2 part 1."""
    return source_key + cost[0] * KEY_BASE + cost[1]


def edge_holds(target_key: Any, bound: Any) -> Any:
    """witness.edge at one free edge from a labelled state: label[s'] <= label[s] + cost."""
    return target_key <= bound


def stop_key(key: Any, p: tuple[Any, Any]) -> Any:
    """A goal state's key plus the stop term (0, |p|_1), p the move that arrived."""
    return key + abs(p[0]) + abs(p[1])


def goal_holds(cost: tuple[Any, Any], least: tuple[Any, Any]) -> Any:
    """witness.goal: the path's (J1, J2) equals the least goal label plus its stop term."""
    return (cost[0] == least[0]) & (cost[1] == least[1])


def start_label_breaks(j1: Any, j2: Any) -> Any:
    """witness.start (found path) fails: the start state's label is not (0, 0) (no label, the
    type's largest value, is not (0, 0) either)."""
    return (j1 != 0) | (j2 != 0)


def start_breaks(start_free: Any, in_set: Any) -> Any:
    """witness.start (no path) fails: the start is free in layer 0, its state not in the set."""
    return start_free & ~in_set


def closure_breaks(source_in: Any, target_free: Any, target_in: Any) -> Any:
    """witness.closure fails at an edge from a free state: its source in the set, its target
    free and not in the set."""
    return source_in & target_free & ~target_in


def exclusion_breaks(goal_free: Any, in_set: Any) -> Any:
    """witness.exclusion fails: the goal is free in R and a goal state (N, goal, p) in the set."""
    return goal_free & in_set


_WAIT = MOVES.index((0, 0))
_DI = np.array([d[0] for d in MOVES], dtype=np.int64)
_DJ = np.array([d[1] for d in MOVES], dtype=np.int64)
_NORM = step_cost((_DI, _DJ), (0, 0))[0]                                          # |d|_1
_TURN = step_cost((_DI[None, :], _DJ[None, :]), (_DI[:, None], _DJ[:, None]))[1]  # [p, d]
_SHIFT = 32
#: Above every finite key plus an edge cost, and far from overflowing int64.
_NONE = np.int64((1 << 62) + (1 << 40))


@dataclass(frozen=True, eq=False)
class Witness:
    """A search's certificate: labels ``j1``, ``j2`` (found) or a ``reachable`` set (no path),
    each of shape ``(N + 1, 9, m, n)`` indexed (step, previous move, i, j); see the module."""

    kind: str                       # "labels" | "reachable"
    j1: Array | Layers | None = None
    j2: Array | Layers | None = None
    reachable: Array | Layers | None = None

    @classmethod
    def of_labels(cls, j1: Array | Layers, j2: Array | Layers) -> Witness:
        return cls("labels", j1=j1, j2=j2)

    @classmethod
    def of_reachable(cls, reachable: Array | Layers) -> Witness:
        return cls("reachable", reachable=reachable)

    @property
    def arrays(self) -> dict[str, Any]:
        if self.kind == "labels":
            return {"j1": self.j1, "j2": self.j2}
        return {"reachable": self.reachable}

    def close(self) -> None:
        """Release the arrays read a layer at a time (their temporary files, spec.LayerSpill);
        the witness cannot be read after that. Idempotent; nothing to do for ndarrays."""
        for a in (self.j1, self.j2, self.reachable):
            if isinstance(a, Layers):
                a.close()

    def __enter__(self) -> Witness:
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()

    def npz_members(self) -> dict[str, Any]:
        """The witness file's members: ``format``, ``kind`` and the arrays (``npz_bytes`` writes
        them whole, ``spec.save_npz`` layer by layer)."""
        return {"format": np.array(WITNESS_FORMAT), "kind": np.array(self.kind), **self.arrays}

    def npz_bytes(self) -> bytes:
        """The witness file: an uncompressed npz with ``format``, ``kind`` and the arrays."""
        buf = io.BytesIO()
        np.savez(buf, **self.npz_members())
        return buf.getvalue()


def load_witness(path: str | Path) -> Witness:
    """A witness file written by ``Witness.npz_bytes``; InputError names what is wrong."""
    source = str(path)

    def bad(field: str, value: Any, message: str) -> InputError:
        return InputError(field, value, message, source=source)

    # Bounded (docs/model.md §11): the file and its arrays unpacked within LIMITS["witness"].
    limit = LIMITS["witness"]
    check_file_size(path, limit, source, field="witness")
    try:
        with zipfile.ZipFile(path) as zf:
            unpacked = sum(info.file_size for info in zf.infolist())
    except (OSError, zipfile.BadZipFile):
        unpacked = 0                                   # np.load below says what is wrong
    if unpacked > limit.value():
        raise bad("witness", MISSING, f"unpacks to {unpacked:,} bytes, more than "
                  f"{limit.words(limit.value())}")
    try:
        z = np.load(path, allow_pickle=False)
        if not isinstance(z, np.lib.npyio.NpzFile):
            raise bad("witness", MISSING, "is not an .npz witness file (a single array)")
        with z:
            # Large members are read in place, a layer at a time (spec._layers).
            members = {k: npz_member(path, z, k) for k in z.files}
    except OSError as exc:
        raise bad("witness", MISSING, f"cannot be read ({exc.strerror or exc})") from None
    except (ValueError, zipfile.BadZipFile, EOFError) as exc:
        raise bad("witness", MISSING, f"is not an .npz witness file ({exc})") from None
    tag = members.get("format")
    if tag is None or tag.shape != () or str(tag) != WITNESS_FORMAT:
        raise bad("format", None if tag is None else str(tag), f"must be {WITNESS_FORMAT!r}")
    tag_kind = members.get("kind")
    kind = None if tag_kind is None or tag_kind.shape != () else str(tag_kind)
    if kind == "labels" and {"j1", "j2"} <= set(members):
        return Witness.of_labels(members["j1"], members["j2"])
    if kind == "reachable" and "reachable" in members:
        return Witness.of_reachable(members["reachable"])
    raise bad("kind", kind, "must be 'labels' (with j1, j2) or 'reachable' (with reachable)")


def check_witness(dr: npt.ArrayLike, start: Sequence[int], goal: Sequence[int],
                  result: SearchResult, witness: Witness | None) -> list[Failure]:
    """The first failing condition of the module docstring, or [] when the witness proves the
    answer: a found path optimal, or no path valid. ``dr`` is a 0/1 array (N + 1, m, n)."""
    dr = layered(dr)                     # a Layers (a store) is read a layer at a time too
    free = Layers(dr.shape, np.bool_, lambda s: dr[s] == 0)   # one layer at a time (§11)
    N, m, n = free.shape[0] - 1, free.shape[1], free.shape[2]
    start, goal = (int(start[0]), int(start[1])), (int(goal[0]), int(goal[1]))
    found = result.status is SearchStatus.FOUND
    want = "labels" if found else "reachable"
    if witness is None or witness.kind != want:
        return [_fail("form", f"a {'found path' if found else 'no-path answer'} needs a "
                      f"'{want}' witness", ("witness", None if witness is None else witness.kind))]
    shape = (N + 1, 9, m, n)
    bad = [(k, a) for k, a in witness.arrays.items()
           if not isinstance(a, (np.ndarray, Layers)) or a.shape != shape
           or (a.dtype != np.bool_ if k == "reachable" else a.dtype.kind != "u")
           or (k == "j2" and a.dtype != witness.j1.dtype)]
    if bad:
        k, a = bad[0]
        return [_fail("form", f"the witness array {k} has the wrong shape or type",
                      ("array", k), ("shape", list(getattr(a, "shape", ()))),
                      ("dtype", str(getattr(a, "dtype", type(a).__name__))),
                      ("expected shape", list(shape)),
                      ("expected dtype", "bool" if k == "reachable" else "unsigned, as j1"))]
    if found:
        return _check_labels(free, start, goal, result, witness.j1, witness.j2)
    return _check_reachable(free, start, goal, witness.reachable)


# --- labels -------------------------------------------------------------------------------------


def _check_labels(free: Layers, start: tuple[int, int], goal: tuple[int, int],
                  result: SearchResult, j1: Array, j2: Array) -> list[Failure]:
    # One pass over the layers: witness.form at each layer as witness.edge reads it (the
    # labels are read once, not once per condition); the form's failure, the first layer's,
    # is still reported before the start's and the edges'.
    N = free.shape[0] - 1
    form: list[Failure] = []
    edge = _check_edges(free, j1, j2, form)
    if form:
        return form
    at = (0, _WAIT, *start)
    if start_label_breaks(j1[at], j2[at]):
        return [_fail("start", "the start state's label is not (0, 0)",
                      ("state", _state(0, start, _WAIT)), ("label", _label(j1, j2, at)))]
    if edge:
        return edge
    path = list(result.path)
    blocked = free.map(lambda a: (~a).astype(np.uint8), np.uint8)
    bad = path_violations(path, blocked, start, goal)
    if bad:
        return [_fail("path", f"the returned path is not valid: {bad[0].message}",
                      ("clause", bad[0].clause), ("failed clauses", len(bad)))]
    cost = (J1(path), J2(path))
    keys = stop_key(_keys(j1[N, :, goal[0], goal[1]], j2[N, :, goal[0], goal[1]]), (_DI, _DJ))
    p = int(np.argmin(keys))
    least = None if keys[p] >= _NONE else (int(keys[p] >> _SHIFT), int(keys[p] & 0xFFFFFFFF))
    if least is None or not goal_holds(cost, least):
        return [_fail("goal", "the path's (J1, J2) is not the least label over the goal's "
                      "admissible states (plus the stop term |p|_1)",
                      ("path's J1, J2 (recomputed)", list(cost)),
                      ("least goal label + stop", None if least is None else list(least)),
                      ("at state", _state(N, goal, p)))]
    return []


def _keys(j1: Array, j2: Array) -> Array:
    """Lexicographic keys J1 * 2**32 + J2 (int64), _NONE where there is no label."""
    none = np.iinfo(j1.dtype).max
    with np.errstate(over="ignore"):        # the unlabelled overflow; replaced by _NONE below
        k = label_key(j1.astype(np.int64), j2.astype(np.int64))
    return np.where(j1 == none, _NONE, k)


def _form_failures(s: int, j1: Array, j2: Array, a: Array) -> list[Failure]:
    """witness.form at layer s (``a``: its states without a label in j1): a label in both
    arrays or in neither, and every label in range (``label_in_range``), judged on the box of
    the cells that hold a label (outside it there is none to judge); its first failure."""
    none = np.iinfo(j1.dtype).max
    b = j2[s] == none
    if not np.array_equal(a, b):
        p, i, j = _first(a != b)
        return [_fail("form", "a state has a label in one array only",
                      ("state", _state(s, (i, j), p)), ("j1", int(j1[s, p, i, j])),
                      ("j2", int(j2[s, p, i, j])), ("no label", int(none)))]
    box = _box(~a.all(axis=0))
    if box is None:
        return []
    r0, r1, c0, c1 = box
    big = ~a[:, r0:r1, c0:c1] & ~label_in_range(j1[s, :, r0:r1, c0:c1], j2[s, :, r0:r1, c0:c1])
    if big.any():
        p, i, j = _first(big)          # the first in (p, i, j) order: the box holds them all
        i, j = i + r0, j + c0
        return [_fail("form", "a label is out of range (J1 < 2**30, J2 < 2**31)",
                      ("state", _state(s, (i, j), p)),
                      ("label", [int(j1[s, p, i, j]), int(j2[s, p, i, j])]))]
    return []


def _check_edges(free: Array, j1: Array, j2: Array, form: list[Failure]) -> list[Failure]:
    """witness.edge, layer by layer on the box of the labelled free states (plus one cell), and
    witness.form, each layer as it is read (``_form_failures``): its first failure is put in
    ``form`` and the edges' check stops there (the form's is reported)."""
    N, m, n = free.shape[0] - 1, free.shape[1], free.shape[2]
    none = np.iinfo(j1.dtype).max
    first, count = None, 0
    for s in range(N + 1):
        t = min(s + 1, N)
        unlabelled = j1[s] == none
        form += _form_failures(s, j1, j2, unlabelled)
        if form:
            return []
        src = ~unlabelled & free[s]                          # labelled free states (9, m, n)
        box = _box(src.any(axis=0))
        if box is None:
            continue
        r0, r1, c0, c1 = box
        key = np.where(src[:, r0:r1, c0:c1], _keys(j1[s, :, r0:r1, c0:c1], j2[s, :, r0:r1, c0:c1]),
                       _NONE)
        for d in range(9):
            # Sources in the box whose target c + d lies in the grid.
            a0, a1 = max(r0, -_DI[d]), min(r1, m - _DI[d])
            b0, b1 = max(c0, -_DJ[d]), min(c1, n - _DJ[d])
            if a0 >= a1 or b0 >= b1:
                continue
            sub = key[:, a0 - r0:a1 - r0, b0 - c0:b1 - c0]
            # The least label[s] + cost over p: the edge holds for every p iff for the least.
            bound = np.min(edge_bound(sub, (_NORM[d], _TURN[:, d, None, None])), axis=0)
            ti, tj = slice(a0 + _DI[d], a1 + _DI[d]), slice(b0 + _DJ[d], b1 + _DJ[d])
            target = _keys(j1[t, d, ti, tj], j2[t, d, ti, tj])
            bad = (bound < _NONE) & free[t, ti, tj] & ~edge_holds(target, bound)
            if bad.any():
                count += int(bad.sum())
                if first is None:
                    i, j = (int(x) for x in np.argwhere(bad)[0])
                    first = (s, t, d, a0 + i, b0 + j)
    if first is None:
        return []
    s, t, d, i, j = first
    p = int(np.argmin(_keys(j1[s, :, i, j], j2[s, :, i, j]) + _TURN[:, d]))
    to = (i + int(_DI[d]), j + int(_DJ[d]))
    cost = [int(_NORM[d]), int(_TURN[p, d])]
    have = _label(j1, j2, (s, p, i, j))
    assert have is not None         # the edge's source holds a label: it broke the bound
    return [_fail("edge", "a free edge breaks label[s'] <= label[s] + cost(s, s')",
                  ("state", _state(s, (i, j), p)), ("label", have), ("move", list(MOVES[d])),
                  ("edge cost", cost), ("to state", _state(t, to, d)),
                  ("its label", _label(j1, j2, (t, d, *to))),
                  ("bound", [have[0] + cost[0], have[1] + cost[1]]), count=count)]


# --- reachable set ------------------------------------------------------------------------------


def _check_reachable(free: Array, start: tuple[int, int], goal: tuple[int, int],
                     reach: Array) -> list[Failure]:
    N, m, n = free.shape[0] - 1, free.shape[1], free.shape[2]
    if start_breaks(free[0][start], reach[0, _WAIT, start[0], start[1]]):
        return [_fail("start", "the start state is free but not in the set",
                      ("state", _state(0, start, _WAIT)))]
    first, count = None, 0
    for s in range(N + 1):
        t = min(s + 1, N)
        src = reach[s].any(axis=0) & free[s]    # the moves from a cell do not depend on p
        box = _box(src)
        if box is None:
            continue
        r0, r1, c0, c1 = box
        for d in range(9):
            a0, a1 = max(r0, -_DI[d]), min(r1, m - _DI[d])
            b0, b1 = max(c0, -_DJ[d]), min(c1, n - _DJ[d])
            if a0 >= a1 or b0 >= b1:
                continue
            ti, tj = slice(a0 + _DI[d], a1 + _DI[d]), slice(b0 + _DJ[d], b1 + _DJ[d])
            bad = closure_breaks(src[a0:a1, b0:b1], free[t, ti, tj], reach[t, d, ti, tj])
            if bad.any():
                count += int(bad.sum())
                if first is None:
                    i, j = (int(x) for x in np.argwhere(bad)[0])
                    first = (s, t, d, a0 + i, b0 + j)
    if first is not None:
        s, t, d, i, j = first
        p = int(np.flatnonzero(reach[s, :, i, j])[0])
        to = (i + int(_DI[d]), j + int(_DJ[d]))
        return [_fail("closure", "a free edge leaves the set",
                      ("state", _state(s, (i, j), p)), ("move", list(MOVES[d])),
                      ("to state", _state(t, to, d)), count=count)]
    if exclusion_breaks(free[N][goal], reach[N, :, goal[0], goal[1]]).any():
        p = int(np.flatnonzero(reach[N, :, goal[0], goal[1]])[0])
        return [_fail("exclusion", "an admissible goal state is in the set (the goal can be "
                      "held from it)", ("state", _state(N, goal, p)))]
    return []


# --- helpers ------------------------------------------------------------------------------------


def _box(mask: Array) -> tuple[int, int, int, int] | None:
    """Rows [r0, r1) and columns [c0, c1) holding every True of a 2-d mask; None if none."""
    rows, cols = np.flatnonzero(mask.any(axis=1)), np.flatnonzero(mask.any(axis=0))
    if rows.size == 0:
        return None
    return int(rows[0]), int(rows[-1]) + 1, int(cols[0]), int(cols[-1]) + 1


def _first(mask: Array) -> tuple[int, ...]:
    return tuple(int(x) for x in np.argwhere(mask)[0])


def _state(s: int, cell: tuple[int, int], p: int) -> dict[str, Any]:
    return {"step": int(s), "cell": [int(cell[0]), int(cell[1])], "previous move": list(MOVES[p])}


def _label(j1: Array, j2: Array, at: tuple[int, ...]) -> list[int] | None:
    none = np.iinfo(j1.dtype).max
    return None if j1[at] == none else [int(j1[at]), int(j2[at])]


def _fail(name: str, message: str, *values: tuple[str, Any], count: int = 1) -> Failure:
    return Failure(f"witness.{name}", message, tuple(values), count)
