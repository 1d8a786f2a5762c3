"""Negative controls of ``cfmpa prove``: wrong inputs every checker must reject, and the safety
compositions without each of their premises, which must not be proved (docs/model.md §10.3).

A checker that accepts everything, or a composition whose conclusion follows without a premise
it names, would pass every obligation: the controls are what show that the checks can fail.
Each is a result in results.json (``controls``) and in the report; the run is not OK unless
every control ends as expected. Expectations are written here, never pinned by ``--repin``.

Checker controls run the spec's checkers (the ones ``cfmpa check`` and the contracts use) on a
wrong input built from a correct one on the built-in workcell ``small`` (cfmpa.scenarios):
- witness.forged: the optimal path with its genuine witness, one goal label lowered;
- witness.worse_path: a valid path one wait longer than the optimum, with the optimum's genuine
  witness;
- dr.unsound_free_cell: D_R with one blocked cell, on the border of free space, set free;
- path.through_blocked: the optimal path with one cell replaced by a blocked neighbour;
- certificate.contact: the subordinate held, from the start, at a cell where the arms touch at
  a layer's instant;
and the wiring's controls of ``_controls_wiring`` (a moving near-contact, a gap over three
pieces, a raised start label). Each construction asserts that the wrong input is what it says,
and each names the condition its fault must be rejected at: a control that cannot build its
input, or whose input is rejected at another condition (so it is not the fault the control
plants), ends ``error``, which no control expects, never ``rejected``.

Positive controls (``Control.accept.*``) give each checker a right input it must accept (the
optimal path with its genuine witness, the D_R as built, the optimal path, its certificate, a
gap the monitor covers): a checker that rejects everything fails them. ``Control.harness``
checks the harness itself: a control that cannot build its input, or is rejected at another
condition, must end ``error``.

Premise controls: for each ``Safety.<variant>.composition`` and each of its hypotheses that is
not an instance of a proved lemma, the composition without it. Expected: not proved, i.e. Z3
finds a counter-model (``refuted``; with the premise's own pins where
``PREMISE_COUNTER_WITNESSES`` has some, then with the composition's one-cell pins, then without
pins) or does not decide it within the control's budget (``unknown``: weaker evidence, said
so). The budget is Z3's resource count (``PREMISE_OWN_RLIMIT``, ``PREMISE_PINNED_RLIMIT``,
``PREMISE_FREE_RLIMIT``), not the
wall clock (kept only as a safety net), so which controls end ``unknown`` does not depend on
the machine's load. An
instance of a proved lemma ("by time_step at t", "by motion at the step k") is a valid fact:
dropping it cannot give a counter-model, and Z3 re-derives some of them within a second on one
machine and not on another, so the composition without it measures how hard the lemma is for
Z3, not whether the composition needs it; those are not controls (the lemma's own obligation
proves it, and a wrong rule fails there).
"""

from __future__ import annotations

import functools
import time
from collections.abc import Sequence
from dataclasses import dataclass, replace
from typing import Any

import numpy as np
import z3

from ..spec import (
    J1,
    J2,
    MOVES,
    Witness,
    certify,
    check_witness,
    dr_cell_failures,
    is_path,
    left_angles,
    path_violations,
    pose_distance,
)
from ._control_base import Control, ControlNotMade, _case, _rejected, _require
from ._controls_wiring import wiring_controls, wiring_positive_controls
from ._z3vec import constants

__all__ = ["Control", "ControlNotMade", "ControlResult", "PREMISE_COUNTER_WITNESSES",
           "PREMISE_FREE_MS", "PREMISE_FREE_RLIMIT", "PREMISE_OWN_MS", "PREMISE_OWN_RLIMIT",
           "PREMISE_PINNED_MS", "PREMISE_PINNED_RLIMIT", "checker_controls", "collect_controls",
           "harness_controls", "positive_controls", "premise_controls", "premise_pins",
           "run_control"]

#: Z3's budget per premise control: with the composition's pins, then without them. The
#: resource limits decide (deterministic: the same answer however loaded the machine); the
#: wall-clock limits are a safety net only. With the pins, every counter-model of the bundled
#: compositions is found within 1 250 000 (and every pinned check shown unsat within 550 000);
#: without them, none of the six left was decided within 6 000 000 (four of them now refuted
#: by their own pins, below; the two of tight have no counter-model).
PREMISE_PINNED_RLIMIT = 2_500_000
PREMISE_FREE_RLIMIT = 1_000_000
PREMISE_PINNED_MS = 10_000
PREMISE_FREE_MS = 10_000
#: Z3's budget for a premise's own pins (``PREMISE_COUNTER_WITNESSES``), tried first: each
#: bundled one gives its counter-model within 110 000; one that no longer does (a statement
#: changed) costs at most this before the one-cell pins are tried, as without it.
PREMISE_OWN_RLIMIT = 500_000
PREMISE_OWN_MS = 10_000

#: A value as the pins write it: an integer, or a rational as text ("1/2").
PinValue = int | str

#: The principal's first joint from 0 to 3 at unit speed, unit steps (so Tf = 3), N = 3, at
#: t = 0 (layer 0). The rest layer's box, layer N-1's (original [1, 3], modified [2, 3]), does not
#: hold theta_L(0) = (0, 0): without the premise that places the principal's links (or tool) in
#: layer k's regions, no hypothesis places them in a region BuiltDR tested, and a point of both
#: arms is a counter-model. With one layer (the one-cell pins) the rest box is layer 0's and
#: holds theta_L(t), and with two the original rest box [0, 2] does: no counter-model there.
_THREE_LAYERS: tuple[tuple[str, PinValue], ...] = (
    ("N", 3), ("dt", 1), ("L.omega.x", 1), ("L.omega.y", 1), ("L.start.x", 0),
    ("L.start.y", 0), ("L.goal.x", 3), ("L.goal.y", 0), ("t", 0), ("kk", 0))
_LINKS_IN_LAYER = ("(c) Safety.region_soundness: links 1 and 2 of the principal at theta_L(t) in "
                   "layer k's regions (its box, k < N; at p)")
_TOOL_IN_LAYER = ("(c) Safety.tool_region: the principal's tool at theta_L(t) in layer k's region "
                  "(its box, k < N; at p)")

#: Per-premise counter-model pins (docs/model.md §10.3): (variant, the hypothesis's name) ->
#: (constant's name, value) pairs, which replace the one-cell pins of the same constants and
#: join the others. Keyed by name, so a reordered composition cannot pin the wrong premise; a
#: name no composition has is an error (``premise_pins``). Found by reasoning about what the
#: dropped premise constrains, each checked by Z3 (tests/proofs/test_premise_pins.py). The
#: tight composition needs neither ``omega_q > 0`` nor Tf's definition (its box is theta_L's
#: own hull and its rest box the goal, whatever Tf is): no counter-model exists there.
PREMISE_COUNTER_WITNESSES: dict[tuple[str, str], tuple[tuple[str, PinValue], ...]] = {
    ("original", _LINKS_IN_LAYER): _THREE_LAYERS,
    ("original", _TOOL_IN_LAYER): _THREE_LAYERS,
    ("modified", _LINKS_IN_LAYER): _THREE_LAYERS,
    ("modified", _TOOL_IN_LAYER): _THREE_LAYERS,
}


@dataclass(frozen=True)
class ControlResult:
    """How a control ended: ``ok`` iff its outcome is one it expects."""

    id: str
    checker: str
    what: str
    expected: tuple[str, ...]
    outcome: str
    detail: str
    seconds: float

    @property
    def ok(self) -> bool:
        return self.outcome in self.expected

    def as_json(self) -> dict[str, Any]:
        return {"id": self.id, "checker": self.checker, "what": self.what,
                "expected": list(self.expected), "outcome": self.outcome, "ok": self.ok,
                "detail": self.detail, "seconds": round(self.seconds, 3)}


def run_control(c: Control) -> ControlResult:
    """Run one control; an exception (a control that could not be built) ends ``error``, which no
    control expects, saying why."""
    t0 = time.perf_counter()
    try:
        outcome, detail = c.run()
    except Exception as exc:  # noqa: BLE001 - a control must end in a result, not a crash
        outcome, detail = "error", f"{type(exc).__name__}: {exc}"
    return ControlResult(c.id, c.checker, c.what, c.expected, outcome, detail,
                         time.perf_counter() - t0)


# --- the checkers' controls --------------------------------------------------------------------


def _forged_witness() -> tuple[str, str]:
    c = _case()
    w = c.best.witness
    if w is None or not isinstance(w.j1, np.ndarray) or not isinstance(w.j2, np.ndarray):
        raise ControlNotMade("the small workcell's search gave no labels in memory")
    j1, j2 = w.j1.copy(), w.j2.copy()
    N, (gi, gj) = c.dr.shape[0] - 1, c.goal
    # Claim a better optimum: the goal's settled labels one below the path's cost.
    settled = j1[N, :, gi, gj] == c.best.J1
    _require(bool(settled.any()) and (c.best.J1 or 0) > 0, "no goal label carries the path's J1")
    j1[N, settled, gi, gj] -= 1
    forged = Witness.of_labels(j1, j2)
    _require(not np.array_equal(j1, w.j1), "the forgery changed nothing")
    # A lowered goal label breaks the edge into that goal state (or, reached otherwise, the goal).
    return _rejected(check_witness(c.dr, c.start, c.goal, c.best, forged),
                     ("witness.edge", "witness.goal"))


def _worse_path() -> tuple[str, str]:
    c = _case()
    path = list(c.best.path)
    best = (c.best.J1, c.best.J2)
    for at in range(len(path)):
        longer = path[:at + 1] + path[at:]          # one wait at position at
        # A wait while moving costs smoothness (J2); one at the start costs nothing.
        if (J1(longer), J2(longer)) > best and is_path(longer, c.dr, c.start, c.goal):
            break
    else:
        raise ControlNotMade("no single wait gives a valid path worse than the optimum")
    worse = replace(c.best, path=tuple(longer), J1=J1(longer), J2=J2(longer))
    out, detail = _rejected(check_witness(c.dr, c.start, c.goal, worse, c.best.witness),
                            ("witness.goal",))
    return out, f"a wait at step {at}, (J1, J2) = ({J1(longer)}, {J2(longer)}); {detail}"


def _unsound_free_cell() -> tuple[str, str]:
    c = _case()
    free = c.dr == 0
    near = np.zeros_like(free)
    near[:, 1:] |= free[:, :-1]
    near[:, :-1] |= free[:, 1:]
    border = np.argwhere((c.dr == 1) & near)
    _require(len(border) > 0, "D_R has no blocked cell next to a free one")
    k, i, j = (int(x) for x in border[len(border) // 2])
    bad = c.dr.copy()
    bad[k, i, j] = 0
    _, failures = dr_cell_failures(c.scenario, "modified", c.grid, bad)
    out, detail = _rejected(failures, ("post.cells",))
    return out, f"layer {k}, cell ({i}, {j}) set free; {detail}"


def _through_blocked() -> tuple[str, str]:
    c = _case()
    path = list(c.best.path)
    m, n = c.dr.shape[1], c.dr.shape[2]
    for k in range(1, len(path) - 1):
        for di, dj in MOVES:
            i, j = path[k][0] + di, path[k][1] + dj
            if (di, dj) != (0, 0) and 0 <= i < m and 0 <= j < n and c.dr[min(k, len(c.dr) - 1), i, j]:
                bad = path[:k] + [(i, j)] + path[k + 1:]
                if all(abs(a[0] - b[0]) <= 1 and abs(a[1] - b[1]) <= 1
                       for a, b in zip(bad, bad[1:])):
                    out, detail = _rejected(path_violations(bad, c.dr, c.start, c.goal),
                                            ("blocked",))
                    return out, f"step {k} moved to the blocked cell ({i}, {j}); {detail}"
    raise ControlNotMade("no blocked neighbour keeps the moves adjacent")


def _contact() -> tuple[str, str]:
    c = _case()
    s, g = c.scenario, c.grid
    m, n = c.dr.shape[1], c.dr.shape[2]
    for k in range(c.dr.shape[0] - 1):
        left = tuple(left_angles(s, k * s.dt))
        for i in range(m):
            for j in range(n):
                if pose_distance(s, left, g.angles((i, j))) == 0.0:
                    path = [(i, j)] * (k + 1)
                    cert = certify(s, g, path)
                    if cert.clear:
                        return "accepted", f"held at ({i}, {j}) through layer {k}: certified clear"
                    if cert.contact is None:    # not the contact the control plants
                        return "error", (f"held at ({i}, {j}) through layer {k}: not clear, but "
                                         "undecided rather than a contact")
                    return "rejected", f"held at ({i}, {j}) through layer {k}: not clear (a contact)"
    raise ControlNotMade("no cell of the grid touches the principal at a layer's instant")


# --- right inputs each checker must accept ------------------------------------------------------


def _accept_witness() -> tuple[str, str]:
    c = _case()
    return _rejected(check_witness(c.dr, c.start, c.goal, c.best, c.best.witness))


def _accept_dr() -> tuple[str, str]:
    c = _case()
    _, failures = dr_cell_failures(c.scenario, "modified", c.grid, c.dr)
    return _rejected(failures)


def _accept_path() -> tuple[str, str]:
    c = _case()
    return _rejected(path_violations(list(c.best.path), c.dr, c.start, c.goal))


def _accept_certificate() -> tuple[str, str]:
    c = _case()
    cert = certify(c.scenario, c.grid, list(c.best.path))
    if cert.clear:
        return "accepted", f"the optimal path certified clear by {cert.lower_bound_m:.4f} m"
    return "rejected", "the optimal path not certified clear (" + (
        "a contact" if cert.contact is not None else "undecided intervals") + ")"


def positive_controls() -> list[Control]:
    """One right input per checker: each must accept it."""
    A = ("accepted",)
    return [
        Control("Control.accept.witness", "witness (spec.check_witness)",
                "the optimal path with its genuine witness", A, _accept_witness),
        Control("Control.accept.dr", "D_R postcondition (spec.dr_cell_failures)",
                "the D_R BuiltDR builds", A, _accept_dr),
        Control("Control.accept.path", "path (spec.path_violations, fixed is_path)",
                "the optimal path", A, _accept_path),
        Control("Control.accept.certificate", "certificate (spec.certify)",
                "the optimal path's motion", A, _accept_certificate),
    ] + wiring_positive_controls()


# --- the harness itself -----------------------------------------------------------------------


def _harness() -> tuple[str, str]:
    """Two controls that must end ``error``: one whose input cannot be built, one rejected at a
    condition other than its own. ``rejected`` when both do, ``accepted`` (a harness that
    counts them as passes) otherwise."""
    def unbuildable() -> tuple[str, str]:
        raise ControlNotMade("a wrong input that cannot be built")

    elsewhere = [type("Planted", (), {"condition": "witness.form", "message": "planted"})()]
    inner = [run_control(Control("Control.harness.inner.unbuildable", "none",
                                 "an input that cannot be built", ("rejected",), unbuildable)),
             run_control(Control("Control.harness.inner.elsewhere", "none",
                                 "rejected at another condition", ("rejected",),
                                 lambda: _rejected(elsewhere, ("witness.goal",))))]
    bad = [r for r in inner if r.outcome != "error" or r.ok]
    if bad:
        return "accepted", "; ".join(f"{r.id} ended {r.outcome}: {r.detail}" for r in bad)
    return "rejected", "both ended error: " + "; ".join(r.detail for r in inner)


def harness_controls() -> list[Control]:
    return [Control("Control.harness.error_is_not_a_pass", "the controls' harness (run_control)",
                    "a control that cannot build its input, and one rejected at another "
                    "condition: both must end error", ("rejected",), _harness)]


def checker_controls() -> list[Control]:
    """One wrong input per checker the safety argument reads at run time, and the wiring's (a
    moving near-contact, a gap over three pieces, a raised start label)."""
    R = ("rejected",)
    return [
        Control("Control.witness.forged", "witness (spec.check_witness)",
                "the optimal path with its witness, the goal's labels lowered by one", R,
                _forged_witness),
        Control("Control.witness.worse_path", "witness (spec.check_witness)",
                "a valid path one wait longer than the optimum, with the optimum's genuine "
                "witness", R, _worse_path),
        Control("Control.dr.unsound_free_cell", "D_R postcondition (spec.dr_cell_failures)",
                "D_R with one blocked cell on the border of free space set free", R,
                _unsound_free_cell),
        Control("Control.path.through_blocked", "path (spec.path_violations, fixed is_path)",
                "the optimal path with one cell moved to a blocked neighbour", R,
                _through_blocked),
        Control("Control.certificate.contact", "certificate (spec.certify)",
                "the subordinate held where the arms touch at a layer's instant", R, _contact),
    ] + wiring_controls()


# --- the compositions without a premise --------------------------------------------------------


@functools.cache
def _composition(variant: str) -> Any:
    """The composition VC of ``variant``, built once a process: its controls read the same
    hypotheses (built in the parent before the workers fork, so each inherits it)."""
    from ._obl_safety import composition_vc

    return composition_vc(variant)


Pins = tuple[tuple[z3.ExprRef, z3.ExprRef], ...]


def _constants(vc: Any) -> dict[str, z3.ExprRef]:
    """The constants the composition's hypotheses and goal name, by name (a walk of its terms:
    about 0.05 s, so only for a name its own pins do not give)."""
    return {c.decl().name(): c for c in constants(*(h for _, h in vc.hypotheses), vc.goal)}


def premise_pins(vc: Any, variant: str,
                 table: dict[tuple[str, str], tuple[tuple[str, PinValue], ...]] | None = None
                 ) -> dict[int, Pins]:
    """The own pins of ``vc``'s premises (``table``, by default ``PREMISE_COUNTER_WITNESSES``,
    its entries for ``variant``), by the premise's index now: each hypothesis found by its name,
    each constant by its name, the one-cell pins of other constants kept (in their order, then
    the own ones). A name ``vc`` lacks, a lemma's instance (not a control) or a value of no
    number raises KeyError or ValueError naming it."""
    entries = {name: pins for (v, name), pins in (
        PREMISE_COUNTER_WITNESSES if table is None else table).items() if v == variant}
    if not entries:
        return {}
    names = [n for n, _ in vc.hypotheses]
    consts = {c.decl().name(): c for c, _ in (*vc.witness, *vc.counter_witness)}
    out: dict[int, Pins] = {}
    for name, pins in entries.items():
        where = [i for i, n in enumerate(names) if n == name]
        if len(where) != 1:
            raise KeyError(f"PREMISE_COUNTER_WITNESSES: {vc.name} has {len(where)} hypotheses "
                           f"named {name!r} (one expected)")
        if name.startswith(LEMMA_INSTANCE):
            raise KeyError(f"PREMISE_COUNTER_WITNESSES: {vc.name}'s {name!r} is a lemma's "
                           "instance, not a premise control")
        own: list[tuple[z3.ExprRef, z3.ExprRef]] = []
        for cname, value in pins:
            if cname not in consts:
                consts = _constants(vc) | consts
            if cname not in consts:
                raise KeyError(f"PREMISE_COUNTER_WITNESSES: {vc.name} has no constant "
                               f"{cname!r} (pins of {name!r})")
            c = consts[cname]
            try:
                v = z3.IntVal(value) if c.sort() == z3.IntSort() else z3.RealVal(value)
            except Exception as exc:  # noqa: BLE001 - z3 raises several kinds on a bad number
                raise ValueError(f"PREMISE_COUNTER_WITNESSES: {cname} = {value!r} (pins of "
                                 f"{name!r}) is not a number of its sort") from exc
            own.append((c, v))
        mine = {c.decl().name() for c, _ in own}
        out[where[0]] = tuple((c, v) for c, v in vc.counter_witness
                              if c.decl().name() not in mine) + tuple(own)
    return out


@functools.cache
def _own_pins(variant: str) -> dict[int, Pins]:
    return premise_pins(_composition(variant), variant)


@functools.cache
def _composition_text(variant: str) -> Any:
    """Z3's text of the composition's hypotheses, its negated goal, its one-cell pins and its
    premises' own pins (each equation once), printed once a process (``_z3text.Printed``): each
    control's checks are cut from it."""
    from ._z3text import Printed

    vc = _composition(variant)
    formulas = [h for _, h in vc.hypotheses] + [z3.Not(vc.goal)]
    formulas += [c == v for c, v in vc.counter_witness]
    ids = {f.get_id() for f in formulas}           # hash-consed: an equal formula, an equal id
    for pins in _own_pins(variant).values():
        for c, v in pins:
            if (c == v).get_id() not in ids:
                formulas.append(c == v)
                ids.add(formulas[-1].get_id())
    return Printed(formulas)


def _without(variant: str, index: int, own: Sequence[tuple[str, PinValue]] | None = None
             ) -> tuple[str, str]:
    """The composition of ``variant`` without hypothesis ``index``: Z3 with the premise's own
    pins (``own``, a test's, else ``PREMISE_COUNTER_WITNESSES``'s), then the one-cell pins,
    then none; ``refuted`` at the first sat, ``proved`` if unsat without pins, else
    ``unknown``."""
    from ._limits import wall_net_ms
    from ._obligation import _solver, _why_unknown

    vc = _composition(variant)
    printed = _composition_text(variant)
    n = len(vc.hypotheses)
    rest = [h for i, (_, h) in enumerate(vc.hypotheses) if i != index]
    kept = [i for i in range(n) if i != index] + [n]        # the other hypotheses, the goal
    if own is None:
        mine = _own_pins(variant).get(index)
    else:
        mine = premise_pins(vc, variant, {(variant, vc.hypotheses[index][0]): tuple(own)})[index]
    tries: list[tuple[str, Pins, int, int]] = []
    if mine is not None:
        tries.append(("with the premise's own pins", mine, PREMISE_OWN_MS, PREMISE_OWN_RLIMIT))
    tries += [("with the one-cell pins", tuple(vc.counter_witness), PREMISE_PINNED_MS,
               PREMISE_PINNED_RLIMIT), ("without pins", (), PREMISE_FREE_MS, PREMISE_FREE_RLIMIT)]
    answers = []
    for label, pins, ms, rlimit in tries:
        eqs = [c == v for c, v in pins]
        # The same text as printing these formulas, byte for byte (Z3's search depends on it);
        # a test's own pins are printed for the check.
        at = [next((k for k in range(n + 1, len(printed.formulas))
                    if z3.eq(printed.formulas[k], e)), -1) for e in eqs]
        text = printed.text(kept + at) if -1 not in at and at == sorted(at) else None
        # The resource limit decides; the wall clock, as for the obligations' checks, is only a
        # net, made as much longer (a loaded machine once stopped without[35] at 10 s).
        s = _solver(wall_net_ms(ms, rlimit), formulas=rest + [z3.Not(vc.goal)] + eqs,
                    text=text, rlimit=rlimit)
        r = s.check()
        if r == z3.sat:
            return "refuted", f"a counter-model {label}"
        answers.append(f"{r} {label}" + (f" ({_why_unknown(s, rlimit)})" if r == z3.unknown
                                         else ""))
    if "unsat without pins" in answers:
        return "proved", "the conclusion follows without it: " + "; ".join(answers)
    return "unknown", "; ".join(answers)


#: How a hypothesis that instantiates a proved lemma is named (``_obl_safety.Lemma.use``).
LEMMA_INSTANCE = "by "


def premise_controls() -> list[Control]:
    """For each composition, one control per hypothesis that is not a proved lemma's instance:
    the composition without it."""
    from ._obl_safety import VARIANTS

    out = []
    for v in VARIANTS:
        _own_pins(v)        # a pin keyed to a name the composition lacks fails here
        for i, (name, _) in enumerate(_composition(v).hypotheses):
            if name.startswith(LEMMA_INSTANCE):
                continue
            out.append(Control(f"Control.Safety.{v}.composition.without[{i}]",
                               f"Safety.{v}.composition", f"without: {name}",
                               ("refuted", "unknown"),
                               functools.partial(_without, v, i)))
    return out


def collect_controls(only: Sequence[str] | None = None) -> list[Control]:
    """The controls of ``cfmpa prove``, checkers' wrong inputs first, then their right inputs,
    the harness's, the compositions': all, or (``only``, as ``--only``) those whose id or whose
    composition is selected."""
    from ._select import selected

    return [c for c in checker_controls() + positive_controls() + harness_controls()
            + premise_controls() if selected(c.id, only) or selected(c.checker, only)]
