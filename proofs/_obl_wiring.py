"""The wiring of the certificate and the monitor: which segment's speed feeds which time piece,
and which trajectory pieces a gap's speed is taken over (docs/model.md §7.2, §12).

``Certificate.lipschitz`` proves the speed formulas and ``Monitor.between_samples`` the bound
for whatever speed it is given; what joins them to a verdict is index arithmetic in numpy code.
These obligations run that code itself on Z3 terms (``_symexec``: the function objects with the
module's ``np`` replaced by a stand-in on terms, every path of their branches), with the sizes,
indices, times and angles symbols, so a changed index or slice changes what is proved:

- ``Certificate.wiring``. For one time piece [t0, t1] of the executed motion, with its path
  segment ``seg`` and the principal's ``moving`` flag as the pieces are made, and any two
  instants t, t' of it: the subordinate's angles that the certificate samples the distances at
  (``right_angles``; a trajectory's ``angles``) are the executed motion of docs/model.md §7.2
  (§12 for a trajectory) on that piece; each joint moves by at most the joint speed the
  certificate hands ``link_speeds`` for that piece (``lipschitz``) times |t' - t|, the
  principal's likewise (its motion ``spec.ptp_angles`` at the Tf the motion holds); the
  piece's constant is ``pair_lipschitz`` of the two arms' link speeds, left part by right part;
  and no index is out of range. With ``Certificate.lipschitz`` (a joint speed bounds a link
  point's speed, hence the distance's rate) the bound the certificate proves on the piece is
  the executed motion's.
- ``Monitor.reference_speeds``. For a gap (a, b) between two samples of a trajectory of R
  rows (any R >= 1) and any piece j of it (0 before the first row, R after the last) whose
  time meets the gap, the speed ``ReferenceSpeeds.over`` gives each joint (with ``of``'s
  speeds per piece) is at least the trajectory's speed on piece j: the w_r that
  ``Monitor.between_samples`` needs.

Named, not proved (docs/model.md §7.2, §12): the pieces' own arithmetic (``pieces()``: each
piece lies in its segment's step, cut at Tf; checked on data by ``Certificate.pieces``); one
piece (one gap) stands for all, the code being elementwise in them; floats read as reals (A2).
"""

from __future__ import annotations

import types
from collections.abc import Sequence
from typing import Any

import numpy as np
import z3

from .. import spec
from ._obl_constants import GROUP_CERTIFICATE
from ._obligation import (
    VC,
    CheckOutcome,
    CheckQuery,
    Method,
    Obligation,
    Verdict,
    Z3Query,
    check_source,
)
from ._symexec import Explorer, ExtractionError, Path, SymArray, SymNumpy, obj, rebind

__all__ = ["GROUP_MONITOR", "KEY_GAP", "KEY_ROW", "KEY_SEGMENT", "PIECE_CASES", "exact_cells",
           "exact_coverage_failures", "grid_motion_vcs", "is_path_reads", "pieces_failures",
           "reference_speed_vcs", "trajectory_motion_vcs", "wiring_obligations"]

GROUP_MONITOR = "Trajectories (docs/model.md §12)"

#: Parts per arm in the recorded link speeds (any number would do: the combination is checked
#: part by part).
_PARTS = 2
#: The key premise of the certificate's VCs: the piece's segment is a segment of the path (or
#: the rest after it). Without it the index runs out of the path and the motion is another.
KEY_SEGMENT = "pieces(): seg = -1 (at rest after the path) or a segment 0 <= seg <= n - 2"
KEY_STEP = ("dt > 0, and pieces(): a segment's piece lies in its step, seg dt <= t0, "
            "t1 <= (seg + 1) dt")
KEY_MOVING = "pieces(): moving = (t0 < Tf)"
KEY_ROW = "pieces(): seg = -1 (one row) or a row of the part, offset <= seg <= offset + R - 2"
#: The key premise of the monitor's VCs: piece j meets the gap.
KEY_GAP = "piece j meets the gap (a, b)"

Hyp = tuple[str, z3.BoolRef]


def _abs(x: Any) -> Any:
    return z3.If(x >= 0, x, -x)


class _LinkSpeeds:
    """Stands for ``link_speeds`` in the code under proof: records the joint speeds handed to
    it for each arm (by the arm's name) and returns a symbol per part, ``v_<arm>[part]``."""

    def __init__(self) -> None:
        self.calls: dict[str, Any] = {}

    def __call__(self, arm: Any, w: Any) -> Any:
        if arm.name in self.calls:
            raise ExtractionError(f"link_speeds called twice for the {arm.name} arm")
        self.calls[arm.name] = w
        rows = np.shape(w)[0]
        return obj([[self.speed(arm.name, p) for p in range(_PARTS)] for _ in range(rows)])

    @staticmethod
    def speed(arm: str, part: int) -> z3.ArithRef:
        return z3.Real(f"v_{arm}[{part}]")

    def joint_speeds(self, arm: str) -> Any:
        if arm not in self.calls:
            raise ExtractionError(f"lipschitz did not hand the {arm} arm's joint speeds to "
                                  "link_speeds")
        return self.calls[arm]


def _arms(start: Sequence[z3.ArithRef], goal: Sequence[z3.ArithRef]) -> Any:
    left = types.SimpleNamespace(name="left", start=tuple(start), goal=tuple(goal))
    return types.SimpleNamespace(left=left, right=types.SimpleNamespace(name="right"))


def _combine(lip: Any) -> z3.BoolRef:
    """The piece's constant, left part a by right part b, is pair_lipschitz(v_left[a],
    v_right[b])."""
    return z3.And(*[lip[0][a][b] == spec.pair_lipschitz(_LinkSpeeds.speed("left", a),
                                                       _LinkSpeeds.speed("right", b))
                    for a in range(_PARTS) for b in range(_PARTS)])


def _rate(x: Any, xp: Any, w: Any, t: Any, tp: Any) -> z3.BoolRef:
    return _abs(xp - x) <= w * _abs(tp - t)


def _path_hyps(p: Path, base: Sequence[Hyp]) -> tuple[Hyp, ...]:
    return tuple(base) + tuple((f"path: {c}", f) for c, f in p.conds) + tuple(p.defs)


def _path_vc(name: str, p: Path, base: Sequence[Hyp], goal: z3.BoolRef, key: str | None,
             extra: Sequence[Hyp] = ()) -> VC:
    return VC(name, _path_hyps(p, base) + tuple(extra), z3.And(goal, *[c for _, c in p.checks]),
              key_premise=key)


def _rows_named(T: z3.FuncDeclRef, terms: Sequence[z3.ExprRef]) -> list[z3.ArithRef]:
    """The distinct arguments of T's applications in ``terms``: the rows a statement names."""
    seen: dict[int, z3.ArithRef] = {}
    done: set[int] = set()
    todo = list(terms)
    while todo:
        e = todo.pop()
        if e.get_id() in done:
            continue
        done.add(e.get_id())
        if z3.is_app(e) and e.decl().eq(T) and e.num_args() == 1:
            arg = z3.simplify(e.arg(0))
            seen.setdefault(arg.get_id(), arg)
        todo.extend(e.children())
    return sorted(seen.values(), key=lambda x: x.sexpr())


def _increasing(T: z3.FuncDeclRef, R: z3.ArithRef, terms: Sequence[z3.ExprRef]) -> Hyp:
    """Times strictly increase (validate refuses any other trajectory), stated at every pair of
    the rows the statement names (ledger A8): for rows x < y of [0, R), T(x) < T(y)."""
    rows = _rows_named(T, terms)
    return ("times strictly increase (validate), at each pair of rows the statement names",
            z3.And(*[z3.Implies(z3.And(0 <= x, x < y, y < R), T(x) < T(y))
                     for x in rows for y in rows if not x.eq(y)]))


# --- the grid path's motion (spec._certificate._Motion) -------------------------------------


def grid_motion_vcs(motion_class: Any = None) -> tuple[VC, ...]:
    """One VC per path of ``lipschitz`` and ``right_angles`` (of ``motion_class``, default the
    spec's motion of a grid path) run on one symbolic piece."""
    cls = spec.GridMotion if motion_class is None else motion_class
    n, seg = z3.Int("n"), z3.Int("seg")
    dt, tf, t0, t1, t, tp = z3.Reals("dt Tf t0 t1 t t'")
    moving = z3.Bool("moving")
    P = [z3.Function(f"L{q + 1}", z3.IntSort(), z3.RealSort()) for q in range(2)]
    start, goal = z3.Reals("start1 start2"), z3.Reals("goal1 goal2")
    motion = types.SimpleNamespace(
        scenario=_arms(start, goal), dt=dt, tf=tf,
        path_angles=SymArray(n, lambda i: obj([P[0](i), P[1](i)]), 1))
    base: list[Hyp] = [
        ("the path has n >= 1 cells, L_q(i) the angle of joint q at its cell i", n >= 1),
        ("Tf >= 0", tf >= 0),
        ("pieces(): 0 <= t0 <= t1", z3.And(0 <= t0, t0 <= t1)),
        (KEY_SEGMENT, z3.Or(seg == -1, z3.And(0 <= seg, seg <= n - 2))),
        (KEY_STEP, z3.And(dt > 0, z3.Implies(seg >= 0, z3.And(seg * dt <= t0,
                                                                 t1 <= (seg + 1) * dt)))),
        (KEY_MOVING, moving == (t0 < tf)),
        ("pieces(): no piece straddles Tf (the motion is cut there)",
         z3.Not(z3.And(t0 < tf, tf < t1))),
        ("t and t' are instants of the piece", z3.And(t0 <= t, t <= t1, t0 <= tp, tp <= t1)),
    ]
    sym = SymNumpy()
    speeds = _LinkSpeeds()
    lipschitz = rebind(cls.lipschitz, np=sym, link_speeds=speeds)
    right_angles = rebind(cls.right_angles, np=sym)

    def run() -> Any:
        speeds.calls.clear()
        lip = lipschitz(motion, obj([seg]), obj([moving]))
        return (lip, speeds.joint_speeds("left"), speeds.joint_speeds("right"),
                right_angles(motion, obj([t]), obj([seg])),
                right_angles(motion, obj([tp]), obj([seg])))

    # The principal's motion, spec.left_angles: spec.ptp_angles at the Tf the motion holds.
    left_t, left_tp = spec.ptp_angles(start, goal, tf, t), spec.ptp_angles(start, goal, tf, tp)
    out = []
    for p in Explorer(base).paths(run):
        lip, wl, wr, r_t, r_tp = p.result

        def executed(x: Any, q: int) -> Any:
            # docs/model.md §7.2: on [seg dt, (seg + 1) dt] from L_seg to L_seg+1, linearly;
            # after the path's end at rest at its last cell.
            k = seg
            return z3.If(seg >= 0, P[q](k) + (x - k * dt) / dt * (P[q](k + 1) - P[q](k)),
                         P[q](n - 1))
        moved = [*[z3.And(r_t[0][q] == executed(t, q), r_tp[0][q] == executed(tp, q))
                   for q in range(2)], _combine(lip)]
        right = z3.And(*[_rate(r_t[0][q], r_tp[0][q], wr[0][q], t, tp) for q in range(2)])
        left = z3.And(*[_rate(left_t[q], left_tp[q], wl[0][q], t, tp) for q in range(2)])
        name = f"grid_path{p.index + 1}"
        texts = {c for c, _ in p.conds}
        one_cell, left_moves = "n == 1" in texts, "Tf > 0" in texts
        # An arm that cannot move on this path (a one-cell path; Tf <= 0) has its rate in the
        # motion's VC: 0 <= 0, true whatever the premises. Each other rate is a VC of its own:
        # Z3 decides each in a fraction of a second, their conjunction in seconds or not at all.
        out.append(_path_vc(f"{name}.motion", p, base, z3.And(
            *moved, *([right] if one_cell else []), *([] if left_moves else [left])),
            KEY_SEGMENT))
        if not one_cell:
            out.append(VC(f"{name}.right_rate", _path_hyps(p, base), right, key_premise=KEY_STEP))
        if left_moves:
            out.append(VC(f"{name}.left_rate", _path_hyps(p, base), left,
                          key_premise=KEY_MOVING))
    return tuple(out)


# --- a trajectory's motion (spec._trajectory._TrajectoryMotion) -----------------------------


def trajectory_motion_vcs(motion_class: Any = None, trajectory_class: Any = None
                          ) -> tuple[VC, ...]:
    """One VC per path of a trajectory motion's ``lipschitz`` and ``angles`` (with the
    trajectory's ``_interp``) run on one symbolic piece of a part starting at row ``offset``."""
    cls = spec.TrajectoryMotion if motion_class is None else motion_class
    tcls = spec.Trajectory if trajectory_class is None else trajectory_class
    R, off, seg = z3.Ints("R offset seg")
    t0, t1, t, tp = z3.Reals("t0 t1 t t'")
    T = z3.Function("T", z3.IntSort(), z3.RealSort())
    A = [z3.Function(f"A{q + 1}", z3.IntSort(), z3.RealSort()) for q in range(4)]
    sym = SymNumpy()
    interp = rebind(tcls._interp, np=sym)
    traj = types.SimpleNamespace(t=SymArray(R, T), rows=R,
                                 angles=SymArray(R, lambda i: obj([a(i) for a in A]), 1))
    traj._interp = lambda tt, kk: interp(traj, tt, kk)
    motion = types.SimpleNamespace(scenario=_arms((), ()), traj=traj, offset=off)
    k = seg - off
    base: list[Hyp] = [
        ("the part has R >= 1 rows, row i at time T(i) with angles A_q(i), from row offset "
         ">= 0 of the trajectory", z3.And(R >= 1, off >= 0)),
        (KEY_ROW, z3.Or(z3.And(seg == -1, R == 1), z3.And(off <= seg, seg <= off + R - 2))),
        ("pieces(): the piece of row seg is [T(seg - offset), T(seg - offset + 1)]; of one row "
         "the instant T(0)",
         z3.If(seg >= 0, z3.And(t0 == T(k), t1 == T(k + 1)), z3.And(t0 == T(0), t1 == T(0)))),
        ("t and t' are instants of the piece", z3.And(t0 <= t, t <= t1, t0 <= tp, tp <= t1)),
    ]
    speeds = _LinkSpeeds()
    lipschitz = rebind(cls.lipschitz, np=sym, link_speeds=speeds)
    angles = rebind(cls.angles, np=sym)

    def run() -> Any:
        speeds.calls.clear()
        lip = lipschitz(motion, obj([seg]), obj([True]))
        w = (speeds.joint_speeds("left"), speeds.joint_speeds("right"))
        return lip, w, angles(motion, obj([t]), obj([seg])), angles(motion, obj([tp]), obj([seg]))

    out = []
    for p in Explorer(base).paths(run):
        lip, (wl, wr), a_t, a_tp = p.result

        def executed(x: Any, q: int) -> Any:
            # docs/model.md §12: linear in joint space between rows k and k + 1.
            return z3.If(seg >= 0, A[q](k) + (x - T(k)) / (T(k + 1) - T(k))
                         * (A[q](k + 1) - A[q](k)), A[q](0))
        w = [wl[0][0], wl[0][1], wr[0][0], wr[0][1]]
        goal_p = z3.And(
            *[z3.And(a_t[0][q] == executed(t, q), a_tp[0][q] == executed(tp, q))
              for q in range(4)],
            *[_rate(a_t[0][q], a_tp[0][q], w[q], t, tp) for q in range(4)],
            _combine(lip))
        rows = _increasing(T, R, [goal_p] + [f for _, f in _path_hyps(p, base)]
                           + [c for _, c in p.checks])
        out.append(_path_vc(f"trajectory_path{p.index + 1}", p, base, goal_p, KEY_ROW, [rows]))
    return tuple(out)


# --- the monitor's speed over a gap (spec.ReferenceSpeeds) ----------------------------------


def reference_speed_vcs(speeds_class: Any = None) -> tuple[VC, ...]:
    """One VC per path of ``ReferenceSpeeds.of`` then ``.over`` on one gap of a symbolic
    trajectory of R rows."""
    cls = spec.ReferenceSpeeds if speeds_class is None else speeds_class
    R, j = z3.Ints("R j")
    a, b = z3.Reals("a b")
    T = z3.Function("T", z3.IntSort(), z3.RealSort())
    A = [z3.Function(f"A{q + 1}", z3.IntSort(), z3.RealSort()) for q in range(4)]
    traj = types.SimpleNamespace(t=SymArray(R, T), rows=R,
                                 angles=SymArray(R, lambda i: obj([x(i) for x in A]), 1))
    meets = z3.And(0 <= j, j <= R, z3.Or(j == 0, T(j - 1) < b), z3.Or(j == R, a < T(j)))
    base: list[Hyp] = [
        ("the trajectory has R >= 1 rows, row i at time T(i) with angles A_q(i)", R >= 1),
        ("a < b: a gap between two samples", a < b),
        (KEY_GAP, meets),
    ]
    sym = SymNumpy()
    of = rebind(cls.of, np=sym)
    over = rebind(cls.over, np=sym)

    def run() -> Any:
        return over(of(traj), obj([a]), obj([b]))

    def speed(q: int) -> Any:
        # docs/model.md §12: at rest before the first row (j = 0) and after the last (j = R);
        # between rows j - 1 and j, |A(j) - A(j - 1)| / (T(j) - T(j - 1)).
        return z3.If(z3.Or(j == 0, j == R), z3.RealVal(0),
                     _abs(A[q](j) - A[q](j - 1)) / (T(j) - T(j - 1)))

    out = []
    for p in Explorer(base, instances=[j]).paths(run):
        goal_p = z3.And(*[speed(q) <= p.result[0][q] for q in range(4)])
        rows = _increasing(T, R, [goal_p] + [f for _, f in _path_hyps(p, base)]
                           + [c for _, c in p.checks])
        out.append(_path_vc(f"gap_path{p.index + 1}", p, base, goal_p, KEY_GAP, [rows]))
    return tuple(out)


# --- the pieces, on data --------------------------------------------------------------------


#: Motions whose pieces are checked: (path length, dt, Tf), every kind of end (the path ending
#: before, at and after Tf; Tf a multiple of dt or not; a one-cell path; Tf = 0).
PIECE_CASES: tuple[tuple[int, float, float], ...] = tuple(
    (n, dt, tf) for n in (1, 2, 3, 7) for dt in (0.02, 0.1, 0.25)
    for tf in (0.0, 0.05, 0.1, 0.2, 0.3, 0.37, 1.0))


def pieces_failures(motion_class: Any = None,
                    cases: Sequence[tuple[int, float, float]] = PIECE_CASES) -> list[str]:
    """What ``Certificate.wiring`` assumes of ``pieces()``, checked on each case: every piece
    has 0 <= t0 <= t1; a segment piece (seg >= 0) has seg <= n - 2 and lies in its step,
    seg dt <= t0, t1 <= (seg + 1) dt (the same float products); a piece at rest (seg = -1)
    starts at or after (n - 1) dt; moving = (t0 < Tf); none straddles Tf; sorted by t0, the
    pieces tile [0, max((n - 1) dt, Tf)] end to end (an all-static motion: the instant 0)."""
    cls: Any = spec.GridMotion if motion_class is None else motion_class   # built on no scenario
    bad: list[str] = []
    for n, dt, tf in cases:
        m = cls(None, dt, tf, np.zeros((n, 2)), np.zeros((n, 2), dtype=np.int64))
        t0, t1, seg, moving = m.pieces()
        where = f"n={n}, dt={dt}, Tf={tf}"
        last = n - 1
        for a, b, s, mv in zip(t0.tolist(), t1.tolist(), seg.tolist(), moving.tolist()):
            if not 0 <= a <= b:
                bad.append(f"{where}: piece [{a}, {b}] not 0 <= t0 <= t1")
            if s >= 0 and not (s <= last - 1 and s * dt <= a and b <= (s + 1) * dt):
                bad.append(f"{where}: piece [{a}, {b}] of segment {s} outside its step")
            if s < -1 or (s == -1 and a < last * dt):
                bad.append(f"{where}: piece [{a}, {b}] at rest (seg {s}) before the path ends")
            if bool(mv) != (a < tf):
                bad.append(f"{where}: piece [{a}, {b}] moving={mv}, t0 < Tf is {a < tf}")
            if a < tf < b:
                bad.append(f"{where}: piece [{a}, {b}] straddles Tf")
        end = max(last * dt, tf)
        order = np.argsort(t0, kind="stable")
        a_s, b_s = t0[order].tolist(), t1[order].tolist()
        if a_s[0] != 0.0 or b_s[-1] != end or any(
                b_s[i] != a_s[i + 1] for i in range(len(a_s) - 1)):
            bad.append(f"{where}: the pieces {list(zip(a_s, b_s))} do not tile [0, {end}]")
    return bad


def _pieces_check() -> CheckOutcome:
    bad = pieces_failures()
    if bad:
        return CheckOutcome(False, f"{len(bad)} failure(s); first: {bad[0]}", "; ".join(bad[:5]))
    return CheckOutcome(True, f"the pieces of {len(PIECE_CASES)} motions meet every assumption")


def _pieces_query() -> CheckQuery:
    content = (check_source(spec.GridMotion.pieces, pieces_failures)
               + f"\ncases: {PIECE_CASES!r}")
    return CheckQuery(_pieces_check, content)


# --- the exact re-decision's cells (spec.exact_path_gaps) ----------------------------------


class _RecordingDR:
    """Stands for D_R in ``spec.path_violations``: every entry reads 0 (free) and is recorded
    as (layer, cell), so the fixed is_path's own loops say which entries a path rests on."""

    def __init__(self, N: int, m: int, n: int) -> None:
        self.shape = (N + 1, m, n)
        self.reads: dict[tuple[int, tuple[int, int]], None] = {}

    def __getitem__(self, key: tuple[int, int, int]) -> int:
        layer, i, j = (int(x) for x in key)
        self.reads[(layer, (i, j))] = None
        return 0


def is_path_reads(path: Sequence[Sequence[int]], N: int) -> list[tuple[int, tuple[int, int]]]:
    """The (layer, cell) entries of D_R that the fixed is_path (``spec.path_violations``, run
    on a recording D_R) reads for ``path`` with N motion layers: the entries a found path's
    safety rests on, the rest layer N included."""
    cells = [(int(c[0]), int(c[1])) for c in path]
    rec = _RecordingDR(N, max(i for i, _ in cells) + 1, max(j for _, j in cells) + 1)
    spec.path_violations(cells, rec, cells[0], cells[-1])    # type: ignore[arg-type]
    return list(rec.reads)


def exact_cells(s: Any, variant: Any, grid: Any, path: Sequence[Sequence[int]],
                exact: Any = None) -> list[tuple[int, tuple[int, int]]]:
    """The (layer, cell) pairs ``exact_path_gaps`` (default ``spec.exact_path_gaps``) decides
    for ``path``: its own code run with the geometry replaced (each pair's regions by
    placeholders, one part pair, a gap of 1 m), so its loop, its layer and cell choice and its
    records are what runs, in milliseconds rather than the seconds of ball arithmetic."""
    f = spec.exact_path_gaps if exact is None else exact
    arb = f.__globals__["arb"]
    cheap = rebind(f, _left_points=lambda *a: [None], _right_points=lambda *a: [None],
                   pairs_to_test=lambda *a: [(0, 0)], _gap=lambda a, b: arb(1))
    return [(c.layer, c.cell) for c in cheap(s, variant, grid, path).cells]


def exact_coverage_failures(s: Any, variant: Any, grid: Any, path: Sequence[Sequence[int]],
                            exact: Any = None) -> list[str]:
    """Where the exact re-decision of ``path`` (``exact_cells``) differs from what the fixed
    is_path reads (``is_path_reads``): a pair it leaves out (a cell of the path never
    re-decided; the rest layer's, typically) or one it adds. Empty: it visits every one."""
    got, want = exact_cells(s, variant, grid, path, exact), is_path_reads(path, grid.N)
    bad = [f"the exact re-decision leaves out layer {layer}, cell {list(c)}"
           + (" (the rest layer)" if layer == grid.N else "")
           for layer, c in want if (layer, c) not in set(got)]
    bad += [f"the exact re-decision decides layer {layer}, cell {list(c)}, which is_path does "
            "not read" for layer, c in got if (layer, c) not in set(want)]
    return bad


# --- the obligations ------------------------------------------------------------------------


def wiring_obligations() -> list[Obligation]:
    """Certificate.wiring, Certificate.pieces and Monitor.reference_speeds."""
    return [
        Obligation(
            "Certificate.wiring", GROUP_CERTIFICATE, "docs/model.md §7.2, §12 (the pieces)",
            "For one time piece [t0, t1] of the executed motion and any instants t, t' of it, "
            "the certificate's own code run on Z3 terms (the motion's lipschitz and "
            "right_angles for a grid path of n cells, a trajectory motion's lipschitz and "
            "angles for a part of R rows from row offset; numpy replaced by a stand-in on "
            "terms, every path of their branches): the subordinate's angles it samples are the "
            "executed motion on that piece (docs/model.md §7.2: from L_seg to L_seg+1 over "
            "[seg dt, (seg + 1) dt], at rest after; §12: linear between rows); each joint of "
            "either arm moves by at most the joint speed lipschitz hands link_speeds for that "
            "piece times |t' - t| (the principal's motion spec.ptp_angles); the piece's constant "
            "is pair_lipschitz of the two arms' link speeds, part by part; no index leaves its "
            "array. Assumed of the pieces (checked on data, Certificate.pieces): each lies in "
            "its segment's step, cut at Tf, moving = (t0 < Tf).",
            Method.Z3, Verdict.PROVED,
            lambda: Z3Query(grid_motion_vcs() + trajectory_motion_vcs()),
            label="pieces checked on data",
            summary=("For each time piece of a motion the certificate checks, the speed it charges "
                     "each arm is the speed that arm really has on that piece, and the angles it "
                     "samples are the motion's own.")),
        Obligation(
            "Certificate.pieces", GROUP_CERTIFICATE, "docs/model.md §7.2 (the pieces)",
            "The grid motion's pieces() meets what Certificate.wiring assumes, on "
            f"{len(PIECE_CASES)} motions (path lengths 1-7, three dt, Tf from 0 to past the "
            "path's end, multiples of dt or not): 0 <= t0 <= t1; a segment's piece in its step "
            "(the same float products); a piece at rest after (n - 1) dt; moving = (t0 < Tf); "
            "none straddles Tf; together they tile [0, max((n - 1) dt, Tf)].",
            Method.DATA, Verdict.PROVED, _pieces_query, label="checked on data",
            summary=("The certificate cuts the motion into pieces that each lie within one path "
                     "step, stop where the principal arm stops, and together cover the whole "
                     "motion without gaps.")),
        Obligation(
            "Monitor.reference_speeds", GROUP_MONITOR, "docs/model.md §12 (monitor between "
            "samples)",
            "For a trajectory of any R >= 1 rows (times strictly increasing) and a gap (a, b) "
            "between two samples, each joint's speed spec.ReferenceSpeeds gives the gap (of, "
            "then over, run on Z3 terms: numpy's searchsorted as its documented insertion "
            "index, a slice's max at least its element at the piece named, every path of the "
            "branches) is at least the trajectory's speed on every piece j that meets the gap "
            "(0 before the first row and after the last, |A(j) - A(j - 1)| / (T(j) - T(j - 1)) "
            "between rows j - 1 and j), and no index leaves its array: the w_r "
            "Monitor.between_samples assumes.",
            Method.Z3, Verdict.PROVED, lambda: Z3Query(reference_speed_vcs()),
            label="any number of pieces",
            summary=("For a gap between two measured samples, the plan's speed the monitor uses is "
                     "at least its speed on every part of the plan the gap overlaps, however many "
                     "parts that is.")),
    ]

