"""Proof obligations as values, and discharging one into a verdict.

An obligation names a statement of the paper (or of docs/model.md) and how it is checked. Discharging
it gives a ``Proof``: the verdict, the time, the solver's own statistics, and for a ``sat``
answer a readable counterexample. A Z3 ``unknown`` is reported as UNKNOWN, never as proved, and
every Z3 proof first shows its hypotheses satisfiable (else it FAILS as vacuous). Every solver
call has a timeout; sympy and data checks, which have none of their own, run under a wall-clock
limit (SIGALRM in the main thread, a watcher thread elsewhere) and end UNKNOWN past it.
"""

from __future__ import annotations

import functools
import hashlib
import inspect
import signal
import threading
import time
import traceback
from collections.abc import Callable
from dataclasses import dataclass, field
from enum import Enum
from typing import Any

import z3

__all__ = [
    "CheckOutcome",
    "CheckQuery",
    "DEFAULT_TIMEOUT_MS",
    "Method",
    "Obligation",
    "Proof",
    "VC",
    "VCResult",
    "Verdict",
    "Z3Query",
    "check_source",
    "discharge",
    "render_query",
]

#: Per solver call. Every Solver gets it; no obligation here needs more than a few seconds.
DEFAULT_TIMEOUT_MS = 20_000

#: Solver statistics that depend on the process (memory, allocation, time, the context's shared
#: resource counter) rather than on the query; left out so results.json is reproducible.
_VOLATILE_STATS = frozenset({"memory", "max memory", "num allocs", "time", "rlimit count"})


@functools.total_ordering
class Verdict(Enum):
    """How an obligation ended, ordered best first: PROVED < REFUTED_AS_EXPECTED < UNKNOWN < FAILED."""

    PROVED = "proved"
    REFUTED_AS_EXPECTED = "refuted as expected"
    UNKNOWN = "unknown"
    FAILED = "failed"

    @property
    def rank(self) -> int:
        return _RANK[self]

    def __lt__(self, other: object) -> bool:
        if not isinstance(other, Verdict):
            return NotImplemented
        return self.rank < other.rank

    def __str__(self) -> str:
        return self.value


_RANK = {Verdict.PROVED: 0, Verdict.REFUTED_AS_EXPECTED: 1, Verdict.UNKNOWN: 2, Verdict.FAILED: 3}


class Method(str, Enum):
    """How an obligation is discharged."""

    Z3 = "z3"          # an SMT query; unsat of hypotheses ∧ ¬goal proves it
    SYMPY = "sympy"    # exact symbolic computation
    DATA = "data"      # an exhaustive check on concrete data (a scenario, computed polygons)

    def __str__(self) -> str:
        return self.value


@dataclass(frozen=True)
class VC:
    """One verification condition: the named hypotheses imply the goal.

    ``key_premise`` names the hypothesis whose removal must make the VC fail (negative tests).
    ``witness`` pins some constants for the vacuity check only: a model that extends it shows
    the hypotheses satisfiable, which is all the check needs. ``counter_witness`` does the same
    for the negative test's search for a counter-model once the key premise is dropped.
    """

    name: str
    hypotheses: tuple[tuple[str, z3.BoolRef], ...]
    goal: z3.BoolRef
    key_premise: str | None = None
    witness: tuple[tuple[z3.ExprRef, z3.ExprRef], ...] = ()
    kind: str = "correctness"
    counter_witness: tuple[tuple[z3.ExprRef, z3.ExprRef], ...] = ()

    def without(self, premise: str) -> VC:
        """This VC with one hypothesis removed (for negative tests)."""
        names = [n for n, _ in self.hypotheses]
        if premise not in names:
            raise KeyError(f"{self.name} has no hypothesis {premise!r}; it has {names}")
        return VC(self.name, tuple(h for h in self.hypotheses if h[0] != premise), self.goal,
                  None, self.witness, self.kind, self.counter_witness)


@dataclass(frozen=True)
class Z3Query:
    """What a Z3 obligation hands the solver: its VCs, and how to print a counterexample."""

    vcs: tuple[VC, ...]
    render: Callable[[z3.ModelRef], str] | None = None
    note: str = ""


@dataclass(frozen=True)
class CheckOutcome:
    """The answer of a sympy or data check: holds True/False, or None when it could not decide."""

    holds: bool | None
    detail: str
    counterexample: str | None = None


@dataclass(frozen=True)
class CheckQuery:
    """A sympy or data check: ``content`` is the canonical text hashed for replay (the check's
    source and its inputs); the outcome it computes is appended to the hashed text when run."""

    run: Callable[[], CheckOutcome]
    content: str


def check_source(*objs: Callable[..., Any]) -> str:
    """The source text of the functions a check runs: hashed, so editing the check is a change."""
    return "\n".join(inspect.getsource(o).rstrip() for o in objs)


Query = Z3Query | CheckQuery


@dataclass(frozen=True)
class Obligation:
    """A statement to discharge: id (paper numbering), reference, words, method, expectation.

    ``build`` produces the query lazily, so collecting obligations is cheap and cannot fail.
    """

    id: str
    group: str
    paper_ref: str
    statement: str
    method: Method
    expected: Verdict
    build: Callable[[], Query] = field(repr=False, compare=False)
    timeout_ms: int = DEFAULT_TIMEOUT_MS


@dataclass(frozen=True)
class VCResult:
    """The solver's two answers for one VC: vacuity (want sat) and the proof (want unsat)."""

    name: str
    vacuity: str
    answer: str


@dataclass(frozen=True)
class Proof:
    """The result of discharging one obligation."""

    id: str
    group: str
    method: Method
    verdict: Verdict
    expected: Verdict
    seconds: float
    statistics: dict[str, float]
    counterexample: str | None
    reason_unknown: str | None
    reason: str
    smtlib: str
    sha256: str
    vcs: tuple[VCResult, ...] = ()

    @property
    def as_expected(self) -> bool:
        return self.verdict is self.expected


# --- discharging --------------------------------------------------------------------------------

def discharge(ob: Obligation) -> Proof:
    """Run one obligation to a verdict; any exception is a FAILED verdict that says why."""
    t0 = time.perf_counter()
    text = ""
    try:
        query = ob.build()
        text = render_query(ob, query)
        if isinstance(query, Z3Query):
            fields = _run_z3(ob, query)
        else:
            outcome = _guarded(query.run, ob.timeout_ms)
            fields = _check_fields(ob, outcome)
            # The result is part of the hashed text: new data or a changed computation that
            # gives another N, h or slack is reported "changed", not "same".
            text += _outcome_text(outcome)
    except Exception as exc:  # noqa: BLE001 - an obligation must end in a verdict, not a crash
        tb = traceback.format_exception_only(type(exc), exc)[-1].strip()
        fields = dict(verdict=Verdict.FAILED, statistics={}, counterexample=None,
                      reason_unknown=None, reason=f"exception: {tb}", vcs=())
    seconds = time.perf_counter() - t0
    return Proof(id=ob.id, group=ob.group, method=ob.method, expected=ob.expected,
                 seconds=seconds, smtlib=text, sha256=hashlib.sha256(text.encode()).hexdigest(),
                 **fields)


def _solver(timeout_ms: int, ctx: z3.Context | None = None) -> z3.Solver:
    s = z3.Solver(ctx=ctx)
    s.set("timeout", timeout_ms)
    return s


def _stats(s: z3.Solver, into: dict[str, float]) -> None:
    st = s.statistics()
    for key in st.keys():
        if key in _VOLATILE_STATS:
            continue
        into[key] = into.get(key, 0) + st.get_key_value(key)


def _run_z3(ob: Obligation, q: Z3Query) -> dict[str, Any]:
    if not q.vcs:
        return dict(verdict=Verdict.FAILED, statistics={}, counterexample=None,
                    reason_unknown=None, reason="no verification conditions", vcs=())
    stats: dict[str, float] = {}
    results: list[VCResult] = []
    vacuous: list[str] = []
    unknowns: list[str] = []
    refuted: list[tuple[str, str]] = []
    for vc in q.vcs:
        # Each check runs in a fresh Z3 context, so its answer does not depend on what ran
        # before it in this process (the run order, or a selection with ``only``).
        ctx = z3.Context()
        hyps = [h.translate(ctx) for _, h in vc.hypotheses]
        # Vacuity: the hypotheses (with the optional witness pinned) must have a model.
        s = _solver(ob.timeout_ms, ctx)
        s.add(hyps)
        s.add([c.translate(ctx) == v.translate(ctx) for c, v in vc.witness])
        vac = s.check()
        _stats(s, stats)
        if vac == z3.unsat:
            vacuous.append(vc.name)
        elif vac == z3.unknown:
            unknowns.append(f"{vc.name} (vacuity check): {s.reason_unknown()}")
        # The proof: hypotheses and the negated goal must have no model.
        s = _solver(ob.timeout_ms, ctx)
        s.add(hyps)
        s.add(z3.Not(vc.goal.translate(ctx)))
        ans = s.check()
        _stats(s, stats)
        if ans == z3.sat:
            model = s.model().translate(z3.main_ctx())
            text = q.render(model) if q.render is not None else _default_render(model)
            refuted.append((vc.name, text))
        elif ans == z3.unknown:
            unknowns.append(f"{vc.name}: {s.reason_unknown()}")
        results.append(VCResult(vc.name, str(vac), str(ans)))
    cex = "\n".join(f"[{name}]\n{text}" if len(q.vcs) > 1 else text for name, text in refuted)
    cex_or_none = cex or None
    unknown_text = "; ".join(unknowns) or None
    if vacuous:
        verdict, reason = Verdict.FAILED, "vacuous: hypotheses unsatisfiable in " + ", ".join(vacuous)
    elif refuted:
        if ob.expected is Verdict.REFUTED_AS_EXPECTED:
            verdict, reason = Verdict.REFUTED_AS_EXPECTED, "counterexample found (sat)"
        else:
            verdict = Verdict.FAILED
            reason = "refuted: counterexample to " + ", ".join(n for n, _ in refuted)
    elif unknowns:
        verdict, reason = Verdict.UNKNOWN, "solver answered unknown"
    else:
        verdict, reason = Verdict.PROVED, f"{len(q.vcs)} VC(s) unsat, hypotheses satisfiable"
    return dict(verdict=verdict, statistics=dict(sorted(stats.items())),
                counterexample=cex_or_none, reason_unknown=unknown_text, reason=reason,
                vcs=tuple(results))


class _CheckTimeout(Exception):
    pass


def _guarded(run: Callable[[], CheckOutcome], timeout_ms: int) -> CheckOutcome:
    """Run a sympy or data check under a wall-clock limit (sympy has none of its own): SIGALRM
    interrupts it in the main thread; elsewhere a watcher thread stops waiting (the check runs
    on, but its answer is dropped). A timeout is UNKNOWN, never proved."""
    limit = timeout_ms / 1000
    what = f"timed out after {limit:g} s (wall clock)"
    if hasattr(signal, "SIGALRM") and threading.current_thread() is threading.main_thread():
        def on_alarm(signum: int, frame: object) -> None:
            raise _CheckTimeout
        old = signal.signal(signal.SIGALRM, on_alarm)
        signal.setitimer(signal.ITIMER_REAL, limit)
        try:
            return run()
        except _CheckTimeout:
            return CheckOutcome(None, what)
        finally:
            signal.setitimer(signal.ITIMER_REAL, 0)
            signal.signal(signal.SIGALRM, old)
    box: list[CheckOutcome | BaseException] = []

    def target() -> None:
        try:
            box.append(run())
        except BaseException as exc:  # noqa: BLE001 - handed back to the caller below
            box.append(exc)
    t = threading.Thread(target=target, daemon=True)
    t.start()
    t.join(limit)
    if not box:
        return CheckOutcome(None, what + "; the check was left running in its thread")
    if isinstance(box[0], BaseException):
        raise box[0]
    return box[0]


def _outcome_text(out: CheckOutcome) -> str:
    lines = ["", "; outcome (part of the hash)", f"holds: {out.holds}", f"detail: {out.detail}"]
    if out.counterexample:
        lines.append(f"counterexample: {out.counterexample}")
    return "\n".join(lines) + "\n"


def _check_fields(ob: Obligation, out: CheckOutcome) -> dict[str, Any]:
    if out.holds is None:
        verdict = Verdict.UNKNOWN
    elif out.holds:
        verdict = Verdict.PROVED
    elif ob.expected is Verdict.REFUTED_AS_EXPECTED:
        verdict = Verdict.REFUTED_AS_EXPECTED
    else:
        verdict = Verdict.FAILED
    return dict(verdict=verdict, statistics={}, counterexample=out.counterexample,
                reason_unknown=out.detail if out.holds is None else None, reason=out.detail,
                vcs=())


def _default_render(model: z3.ModelRef) -> str:
    """Every constant of the model, by name; functions and arrays as Z3 prints them."""
    lines = []
    for d in sorted(model.decls(), key=lambda d: d.name()):
        if d.arity() == 0:
            lines.append(f"{d.name()} = {model[d]}")
    return "\n".join(lines)


def render_query(ob: Obligation, query: Query) -> str:
    """The replayable text of an obligation: SMT-LIB for Z3 (one block per check, then (reset)),
    the canonical inputs for sympy and data checks. Its sha256 identifies the obligation."""
    head = [f"; obligation {ob.id} ({ob.paper_ref})", f"; method {ob.method}, expected {ob.expected}"]
    head += [f"; {line}" for line in ob.statement.splitlines()]
    if isinstance(query, CheckQuery):
        return "\n".join(head + ["", query.content.rstrip(), ""])
    out = head
    second = ("refutation (expect sat: the counterexample)"
              if ob.expected is Verdict.REFUTED_AS_EXPECTED else "proof (expect unsat)")
    for vc in query.vcs:
        for label, negate in (("vacuity (expect sat)", False), (second, True)):
            s = z3.Solver()
            s.add([h for _, h in vc.hypotheses])
            if negate:
                s.add(z3.Not(vc.goal))
            else:
                s.add([c == v for c, v in vc.witness])
            names = ", ".join(n for n, _ in vc.hypotheses) or "none"
            # (reset) rather than push/pop: incremental mode would change Z3's tactics.
            out += ["", f"; VC {vc.name}: {label}; hypotheses: {names}",
                    f"(set-option :timeout {ob.timeout_ms})", s.sexpr().rstrip(), "(check-sat)",
                    "(reset)"]
    return "\n".join(out) + "\n"
