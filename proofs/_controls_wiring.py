"""Controls of the wiring (docs/model.md §10): wrong inputs whose verdict depends on which segment,
which pieces or which label the checker reads, run by every ``cfmpa prove``.

- certificate.moving_contact: on the built-in workcell ``small``, a path that waits, then jumps
  several cells in one step (a fast linear move) through the principal and out: the arms are at
  least ``MARGIN_M`` apart at both of the step's grid instants and touch in between. The step
  before is a wait, so a certificate that took the previous segment's speed for the piece (0)
  would prove it clear from its two end samples; the certificate must find the contact.
- monitor.gap_last_piece: a trajectory and a gap between two samples on it that spans three of
  its pieces, the last the fastest; the tube is chosen between the bound with that piece's speed
  and the bound without it, so the monitor's coverage of the gap (``between_samples_bound`` with
  ``ReferenceSpeeds.over``, as ``cfmpa monitor`` computes it) depends on the last piece: it must
  leave the gap uncovered (unobserved).
- witness.raised_start: the optimal path with its genuine witness, the start state's label raised
  from (0, 0) to (0, 1); ``check_witness`` must reject it at witness.start.

- exact.rest_layer_contact: on ``small`` (the modified variant), a path that waits N steps at a
  cell free in every motion layer, then moves to a neighbour blocked in the rest layer only
  visited there (its regions meet the principal's at rest at its goal): the exact re-decision
  (``spec.exact_path_gaps``, in ball arithmetic) must leave that rest-layer cell undecided, and
  no other. One that stops a layer short never sees it.

- kinds.theorem_moved: the kinds with ``Safety.separation`` moved into the definitional list; the
  kinds' audit (``definitional_failures``: no obligation a verdict or a run-time checker rests
  on, ``THEOREM_PREFIXES``, may be definitional) must reject it. Its right input,
  ``Control.accept.kinds``, is the code's own ``kind_of``: a theorem moved into DEFINITIONAL in
  the code fails it (the lock's pinned kind fails the run too, but a pin is not what catches).

- loader.spacing_above_bound: the workcell ``small`` with the principal's first joint fast enough
  that omega dt is the double 3.14, just above the lattice spacing the safety proofs assume
  (their G_MAX, 157/50, read from proofs/_z3vec.py); the loader must refuse it, naming
  that joint's omega. A loader admitting it would build regions outside the proved lemma.

And their right inputs: ``Control.accept.monitor.gap`` (a gap inside one piece, within the tube:
covered), ``Control.accept.exact`` (the optimal path of ``small``: every cell proved free) and
``Control.accept.loader.spacing_at_bound`` (omega dt the largest double <= 157/50: loaded)
beside the checkers' own positive controls in ``_controls``.
"""

from __future__ import annotations

import copy
import math
from collections.abc import Callable
from fractions import Fraction
from typing import Any

import numpy as np

from .. import spec
from ..errors import InputError
from ..scenarios import SELFCHECK_WORKCELLS
from ..spec import (
    MOVES,
    ReferenceSpeeds,
    Trajectory,
    Witness,
    between_samples_bound,
    certify,
    check_witness,
    left_angles,
    parse_scenario,
    trajectory_distances,
)
from ._control_base import Control, ControlNotMade, _case, _rejected, _require
from ._registry import FIXED_IDS, kind_of

__all__ = ["MARGIN_M", "THEOREM_PREFIXES", "definitional_failures", "wiring_controls",
           "wiring_positive_controls"]

#: How far apart the arms are at both grid instants of the moving near-contact (m).
MARGIN_M = 0.1
#: Sub-instants of a step at which the near-contact's motion is sampled to find the touch.
_SUB = 16


def _moving_near_contact() -> tuple[int, tuple[int, int], tuple[int, int], float, float, float]:
    """(k, cell, target, distance at k dt, at (k + 1) dt, an instant of contact): the first, in
    a fixed order (k from 1, jumps of 5, 3, 2 cells along each move, cells in order), of the
    steps from a wait at ``cell`` to ``target`` over [k dt, (k + 1) dt] whose motion is at least
    MARGIN_M clear at both grid instants and touches the principal at a sub-instant."""
    c = _case()
    s, g = c.scenario, c.grid
    ii, jj = np.meshgrid(np.arange(g.m), np.arange(g.n), indexing="ij")
    cells = np.stack([ii.ravel(), jj.ravel()], axis=1)
    u = np.linspace(0.0, 1.0, _SUB + 1)
    for k in range(1, g.N):
        for mult in (5, 3, 2):
            for d in MOVES:
                if d == (0, 0):
                    continue
                step = np.array(d) * mult
                ok = np.all((cells + step >= 0) & (cells + step < (g.m, g.n)), axis=1)
                a0 = np.stack([g.lo[0] + cells[ok, 0] * g.h[0],
                               g.lo[1] + cells[ok, 1] * g.h[1]], axis=1)
                a1 = a0 + step * np.array(g.h)
                dist = np.stack([trajectory_distances(s, np.concatenate(
                    [np.broadcast_to(left_angles(s, (k + x) * g.dt), a0.shape),
                     a0 + x * (a1 - a0)], axis=1)).min(axis=(1, 2)) for x in u], axis=1)
                hit = np.flatnonzero((dist[:, 0] > MARGIN_M) & (dist[:, -1] > MARGIN_M)
                                     & np.any(dist[:, 1:-1] == 0.0, axis=1))
                if len(hit):
                    h = int(hit[0])
                    cell = (int(cells[ok][h, 0]), int(cells[ok][h, 1]))
                    touch = (k + u[1 + int(np.argmax(dist[h, 1:-1] == 0.0))]) * g.dt
                    return (k, cell, (cell[0] + int(step[0]), cell[1] + int(step[1])),
                            float(dist[h, 0]), float(dist[h, -1]), float(touch))
    raise ControlNotMade("no step from a wait touches the principal between two grid instants "
                         f"at which the arms are {MARGIN_M} m apart")


def _moving_contact() -> tuple[str, str]:
    c = _case()
    k, cell, target, d0, d1, touch = _moving_near_contact()
    path = [cell] * (k + 1) + [target]
    _require(k >= 1 and path[k - 1] == path[k], "the step before the jump is not a wait")
    cert = certify(c.scenario, c.grid, path)
    what = (f"a wait at {cell}, then a jump to {target} over [{k * c.grid.dt:g}, "
            f"{(k + 1) * c.grid.dt:g}] s: {d0:.3f} m and {d1:.3f} m apart at its ends, touching "
            f"at {touch:.4f} s")
    if cert.clear:
        return "accepted", f"{what}: certified clear by {cert.lower_bound_m:.4f} m"
    if cert.contact is None:
        return "error", f"{what}: not clear, but undecided rather than a contact"
    return "rejected", f"{what}: a contact at {cert.contact[0]:.4f} s"


# --- the monitor's gap ------------------------------------------------------------------------

#: One joint (right1) of a trajectory: slow on rows 1-3, fast from row 3 to 4 (rad, s).
_ROWS_T = np.array([0.0, 0.1, 0.104, 0.108, 0.2])
_ROWS_Q = np.array([0.0, 0.0, 0.0002, 0.0004, 0.0924])
#: The robot's speed bound per joint (rad/s): the small workcell's omega.
_W_ROBOT = 1.0


def _gap_verdict(a: float, b: float, tol: float) -> tuple[bool, np.ndarray]:
    """Whether the monitor covers the gap (a, b) between two samples on the trajectory (their
    deviations 0): ``between_samples_bound`` with ``ReferenceSpeeds.over``'s speeds, within tol
    for every joint, as ``cfmpa monitor`` decides a gap."""
    traj = _trajectory()
    ref = ReferenceSpeeds.of(traj)
    x = traj.at(np.array([a, b]))
    dev = np.abs(x - traj.at(np.array([a, b])))
    bound = between_samples_bound(dev[0], dev[1], b - a, np.full(4, _W_ROBOT),
                                  ref.over(np.array([a]), np.array([b]))[0])
    return bool(np.all(bound <= tol)), bound


def _trajectory() -> Trajectory:
    angles = np.zeros((len(_ROWS_T), 4))
    angles[:, 2] = _ROWS_Q
    return Trajectory(_ROWS_T.copy(), angles)


def _pieces_met(a: float, b: float) -> list[tuple[int, float]]:
    """(piece, right1's speed on it) for every piece whose time meets (a, b), from the rows
    directly (piece j between rows j - 1 and j)."""
    t, q = _ROWS_T, _ROWS_Q
    out = []
    for j in range(1, len(t)):
        if t[j - 1] < b and t[j] > a:
            out.append((j, abs(q[j] - q[j - 1]) / (t[j] - t[j - 1])))
    return out


def _gap_last_piece() -> tuple[str, str]:
    a, b = 0.102, 0.109
    met = _pieces_met(a, b)
    _require(len(met) == 3, f"the gap meets {len(met)} pieces, not three")
    speeds = [w for _, w in met]
    _require(speeds[-1] > max(speeds[:-1]), "the gap's last piece is not the fastest")
    with_last = (_W_ROBOT + speeds[-1]) * (b - a) / 2
    without = (_W_ROBOT + max(speeds[:-1])) * (b - a) / 2
    tol = (with_last + without) / 2             # the verdict depends on the last piece
    covered, bound = _gap_verdict(a, b, tol)
    what = (f"a gap [{a}, {b}] s over pieces {[j for j, _ in met]} (speeds "
            f"{', '.join(f'{w:.3g}' for w in speeds)} rad/s), tube {tol:.3g} rad: bound "
            f"{bound.max():.3g} rad")
    return ("accepted", f"{what}, covered") if covered else ("rejected", f"{what}, unobserved")


def _accept_gap() -> tuple[str, str]:
    a, b = 0.15, 0.16
    met = _pieces_met(a, b)
    _require(len(met) == 1, "the gap is not inside one piece")
    tol = 2 * (_W_ROBOT + met[0][1]) * (b - a) / 2
    covered, bound = _gap_verdict(a, b, tol)
    what = f"a gap [{a}, {b}] s inside piece {met[0][0]}, tube {tol:.3g} rad: bound {bound.max():.3g}"
    return ("accepted", f"{what}, covered") if covered else ("rejected", f"{what}, unobserved")


# --- the witness's start label ----------------------------------------------------------------


def _raised_start() -> tuple[str, str]:
    c = _case()
    wait = MOVES.index((0, 0))
    at = (0, wait, c.start[0], c.start[1])
    w = c.best.witness
    if w is None or not isinstance(w.j1, np.ndarray) or not isinstance(w.j2, np.ndarray):
        raise ControlNotMade("the small workcell's search gave no labels in memory")
    j1, j2 = w.j1.copy(), w.j2.copy()
    _require(int(j1[at]) == 0 and int(j2[at]) == 0, "the genuine start label is not (0, 0)")
    j2[at] = 1
    out, detail = _rejected(check_witness(c.dr, c.start, c.goal, c.best,
                                          Witness.of_labels(j1, j2)), ("witness.start",))
    return out, f"the start state labelled (0, 1); {detail}"


# --- the exact re-decision's rest layer -------------------------------------------------------


def _rest_layer_path() -> tuple[list[tuple[int, int]], tuple[int, int]]:
    """(path, its last cell): N steps at a cell free in every motion layer of the small
    workcell's D_R, then one move to a neighbour blocked in the rest layer (the first such pair
    in row-major order); the neighbour is occupied in the rest layer only."""
    c = _case()
    dr, N = c.dr, c.grid.N
    free = ~np.any(dr[:N] != 0, axis=0)
    for i, j in np.argwhere(dr[N] != 0):
        for d in MOVES:
            b = (int(i) + d[0], int(j) + d[1])
            if d != (0, 0) and 0 <= b[0] < dr.shape[1] and 0 <= b[1] < dr.shape[2] and free[b]:
                return [b] * N + [(int(i), int(j))], (int(i), int(j))
    raise ControlNotMade("no cell blocked in the rest layer has a neighbour free in every "
                         "motion layer")


def _exact_verdict(path: list[tuple[int, int]]) -> Any:
    c = _case()
    return spec.exact_path_gaps(c.scenario, "modified", c.grid, path)


def _rest_layer_contact() -> tuple[str, str]:
    c = _case()
    N = c.grid.N
    path, last = _rest_layer_path()
    _require(len(path) == N + 1 and path[-2] != last, "the blocked cell is not reached at step N")
    e = _exact_verdict(path)
    what = (f"{N} steps at {list(path[0])}, then {list(last)} (blocked in the rest layer {N} "
            "only there)")
    if e.ok:
        return "accepted", f"{what}: every cell proved free ({len(e.cells)} re-decided)"
    where = [(x.layer, x.cell) for x in e.undecided]
    if where != [(N, last)]:
        return "error", f"{what}: undecided at {where}, not only at ({N}, {list(last)})"
    return "rejected", (f"{what}: layer {N}, cell {list(last)} undecided (gap at least "
                        f"{e.undecided[0].gap_lower_m:.3g} m)")


def _accept_exact() -> tuple[str, str]:
    c = _case()
    path = [tuple(x) for x in c.best.path]
    e = _exact_verdict(path)   # type: ignore[arg-type]
    what = f"the optimal path of {len(path)} cells, {len(e.cells)} (layer, cell) pairs"
    return ("accepted", f"{what}, each proved free") if e.ok else (
        "rejected", f"{what}: {len(e.undecided)} undecided")


# --- the kinds -------------------------------------------------------------------------------

#: The obligations a found plan's verdict rests on (the report's rows: Safety., Certificate.,
#: Tolerance.) and those of the run-time checkers' bounds (Exact., Monitor., Witness.): theorems
#: about the robot and the code, never definitional (docs/model.md §6.4, §10).
THEOREM_PREFIXES = ("Safety.", "Certificate.", "Tolerance.", "Exact.", "Monitor.", "Witness.")


def definitional_failures(kind_of: Callable[[str], str]) -> list[str]:
    """The obligations of THEOREM_PREFIXES that ``kind_of`` calls anything but a theorem."""
    return [i for i in FIXED_IDS if i.startswith(THEOREM_PREFIXES) and kind_of(i) != "theorem"]


def _kinds_verdict(kind_of: Callable[[str], str]) -> tuple[str, str]:
    n = sum(1 for i in FIXED_IDS if i.startswith(THEOREM_PREFIXES))
    bad = definitional_failures(kind_of)
    if bad:
        return "rejected", (f"{len(bad)} of the {n} obligations a verdict rests on called "
                            f"definitional: {', '.join(bad[:3])}")
    return "accepted", f"the {n} obligations a verdict rests on are theorems"


def _theorem_moved() -> tuple[str, str]:
    moved = "Safety.separation"
    _require(moved in FIXED_IDS and kind_of(moved) == "theorem",
             f"{moved} is not a theorem of the run")
    return _kinds_verdict(lambda i: "definitional" if i == moved else kind_of(i))


def _accept_kinds() -> tuple[str, str]:
    return _kinds_verdict(kind_of)


# --- the loader's spacing bound --------------------------------------------------------------


def _proofs_bound() -> Fraction:
    """The lattice spacing bound the safety proofs assume (Safety.region_statement's g_q)."""
    from ._z3vec import G_MAX

    return Fraction(G_MAX.numerator_as_long(), G_MAX.denominator_as_long())


def _load_with_step(step: float) -> tuple[str, str]:
    """The workcell ``small`` with the principal's first omega making omega dt = ``step`` (the
    same double: dt is a power of 2), through the loader: ``rejected`` when it refuses that
    omega, ``accepted`` when it loads, ``error`` when it refuses something else."""
    doc = copy.deepcopy(SELFCHECK_WORKCELLS["small"])
    dt = doc["dt"]
    _require(math.log2(dt).is_integer(), "dt is not a power of 2")
    doc["left"]["omega"] = [step / dt, doc["left"]["omega"][1]]
    _require(doc["left"]["omega"][0] * dt == step, "omega dt is not the step meant")
    try:
        parse_scenario(doc, check_budget=False)
    except InputError as exc:
        if exc.field != "left.omega[0]":
            return "error", f"refused at {exc.field}, not at left.omega[0]: {exc}"
        return "rejected", str(exc)
    return "accepted", f"omega dt = {step!r} loaded"


def _spacing_above_bound() -> tuple[str, str]:
    bound = _proofs_bound()
    step = 3.14
    _require(Fraction(step) > bound and Fraction(math.nextafter(step, 0.0)) <= bound,
             "3.14 is not the least double above the proofs' spacing bound")
    return _load_with_step(step)


def _spacing_at_bound() -> tuple[str, str]:
    step = math.nextafter(3.14, 0.0)
    _require(Fraction(step) <= _proofs_bound(), "the step is above the proofs' spacing bound")
    return _load_with_step(step)


def wiring_controls() -> list[Control]:
    """The wiring's wrong inputs."""
    R = ("rejected",)
    return [
        Control("Control.certificate.moving_contact", "certificate (spec.certify)",
                "a wait, then a jump of several cells through the principal between two grid "
                f"instants at which the arms are over {MARGIN_M} m apart", R, _moving_contact),
        Control("Control.monitor.gap_last_piece",
                "monitor (spec.between_samples_bound, spec.ReferenceSpeeds.over)",
                "a gap over three pieces of the trajectory whose last is the fastest, the tube "
                "between the bound with it and without it", R, _gap_last_piece),
        Control("Control.witness.raised_start", "witness (spec.check_witness)",
                "the optimal path with its witness, the start state's label raised to (0, 1)",
                R, _raised_start),
        Control("Control.exact.rest_layer_contact", "exact re-decision (spec.exact_path_gaps)",
                "a path waiting N steps, then moving to a cell blocked in the rest layer, "
                "visited only there", R, _rest_layer_contact),
        Control("Control.kinds.theorem_moved", "the kinds (proofs._registry.kind_of)",
                "Safety.separation moved into the definitional list", R, _theorem_moved),
        Control("Control.loader.spacing_above_bound", "scenario loader (spec.parse_scenario)",
                "the principal's omega dt the double 3.14, just above the spacing bound the "
                "safety proofs assume (157/50)", R, _spacing_above_bound),
    ]


def wiring_positive_controls() -> list[Control]:
    """The monitor's, the exact re-decision's and the loader's right inputs (the others' are
    ``_controls.positive_controls``)."""
    return [Control("Control.accept.monitor.gap",
                    "monitor (spec.between_samples_bound, spec.ReferenceSpeeds.over)",
                    "a gap inside one piece, within the tube", ("accepted",), _accept_gap),
            Control("Control.accept.exact", "exact re-decision (spec.exact_path_gaps)",
                    "the optimal path of the small workcell", ("accepted",), _accept_exact),
            Control("Control.accept.kinds", "the kinds (proofs._registry.kind_of)",
                    "the kinds as the code gives them", ("accepted",), _accept_kinds),
            Control("Control.accept.loader.spacing_at_bound",
                    "scenario loader (spec.parse_scenario)",
                    "the principal's omega dt the largest double <= 157/50", ("accepted",),
                    _spacing_at_bound)]
