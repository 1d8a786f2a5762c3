"""Proof obligations as values, and discharging one into a verdict.

An obligation names a statement of the paper (or of docs/model.md) and how it is checked. Discharging
it gives a ``Proof``: the verdict, the time, the solver's own statistics, and for a ``sat``
answer a readable counterexample. A Z3 ``unknown`` is reported as UNKNOWN, never as proved, and
every Z3 proof first shows its hypotheses satisfiable (else it FAILS as vacuous). Every solver
call has a timeout; sympy and data checks, which have none of their own, run under a wall-clock
limit (SIGALRM in the main thread, a watcher thread elsewhere) and end UNKNOWN past it.

Beyond the verdict, a Z3 obligation's proof records for each VC: its depth (``_depth``: the
weakest reasoning that proves it, propositional, ground or full; the obligation is as deep as its
deepest VC), the hash of its statement in standard SMT-LIB 2.6 (``_smtlib``, what
proofs/obligations.lock pins), and which solvers confirm it: Z3, cvc5 replaying the standard
text (``_cvc5``; a cvc5 answer contradicting Z3's makes the obligation FAILED), or a
sum-of-squares certificate checked exactly by sympy (``_sos``) where cvc5 does not decide. The
while-programs' smoke tests (``Z3Query.smoke``, from ``_while.smoke_tests``) must not be shown
unsatisfiable: an Assume, a branch or a loop that no state reaches makes the obligation FAILED.
"""

from __future__ import annotations

import dataclasses
import functools
import hashlib
import inspect
import signal
import threading
import time
import traceback
from collections.abc import Callable, Sequence
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
    "Smoke",
    "SmokeResult",
    "VC",
    "VCResult",
    "Verdict",
    "Z3Query",
    "check_source",
    "discharge",
    "discharge_pending",
    "render_query",
    "standard_smtlib",
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
    #: A sum-of-squares certificate of the goal from the hypotheses (``_sos.Certificate``),
    #: checked by sympy where cvc5 does not decide the VC.
    certificate: Any = None
    #: The Z3 tactic whose solver runs the proof check, where Z3's default solver was measured
    #: slow on this VC (docs/model.md §6.1), with its parameters (``z3_tactic_params``: name,
    #: bool or int); None: Z3's default solver. How the check is run, not what it states: the
    #: statement and its hash are the same; the saved query shows it (``(check-sat-using)``).
    z3_tactic: str | None = None
    z3_tactic_params: tuple[tuple[str, bool | int], ...] = ()

    def without(self, premise: str) -> VC:
        """This VC with one hypothesis removed (for negative tests)."""
        names = [n for n, _ in self.hypotheses]
        if premise not in names:
            raise KeyError(f"{self.name} has no hypothesis {premise!r}; it has {names}")
        return VC(self.name, tuple(h for h in self.hypotheses if h[0] != premise), self.goal,
                  None, self.witness, self.kind, self.counter_witness)


@dataclass(frozen=True)
class Smoke:
    """A smoke test of a while-program (``_while.smoke_tests``): a point of the program that
    some state must reach, i.e. ``hypotheses ∧ ¬goal`` satisfiable (the goal says the point is
    never reached). ``witness`` pins constants to help Z3 find the model."""

    name: str
    hypotheses: tuple[tuple[str, z3.BoolRef], ...]
    goal: z3.BoolRef
    witness: tuple[tuple[z3.ExprRef, z3.ExprRef], ...] = ()
    #: Closed facts about a model fixed by ``lemma_witness`` (a substitution of concrete
    #: values), e.g. "no path exists" of a small D_R: each is proved valid once substituted,
    #: then replaced by true in the substituted test, whose model Z3 can then find. (name, fact)
    lemmas: tuple[tuple[str, z3.BoolRef], ...] = ()
    lemma_witness: tuple[tuple[z3.ExprRef, z3.ExprRef], ...] = ()


@dataclass(frozen=True)
class Z3Query:
    """What a Z3 obligation hands the solver: its VCs, how to print a counterexample, and the
    smoke tests of the programs the VCs come from."""

    vcs: tuple[VC, ...]
    render: Callable[[z3.ModelRef], str] | None = None
    note: str = ""
    smoke: tuple[Smoke, ...] = ()


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
    return "\n".join(source_of(o) for o in objs)


def spec_closure_source(*objs: Callable[..., Any]) -> str:
    """A line per ``cfmpa.spec`` module the objects' modules import, directly or through one
    another (``spec_closure``), with the sha256 of its whole source: what a check that judges
    data by these functions rests on, down to the helpers they call, so that editing any of
    them changes the check's text, a change to review that names the module (docs/model.md
    §6.4); the hashes, not the sources, keep the saved text small."""
    return "\n".join(f"# module {name} sha256 {_module_facts(name)[0]}"
                     for name in spec_closure(*objs))


def spec_closure(*objs: Callable[..., Any]) -> tuple[str, ...]:
    """The names of the ``cfmpa.spec`` modules ``objs`` are defined in and those they import
    within the package (its relative imports, at any depth of their code), sorted."""
    package = _spec_package()
    todo = [o.__module__ for o in objs if o.__module__.startswith(package + ".")]
    seen: set[str] = set()
    while todo:
        name = todo.pop()
        if name not in seen:
            seen.add(name)
            todo += _module_facts(name)[1]
    return tuple(sorted(seen))


def _spec_package() -> str:
    import importlib

    return importlib.import_module("..spec", __package__).__name__


@functools.lru_cache(maxsize=64)
def _module_facts(name: str) -> tuple[str, tuple[str, ...]]:
    """(the sha256 of module ``name``'s whole source, the spec modules it imports: its relative
    imports at any depth of its code), read and parsed once a process: each of the 21
    translation checks asks for the same twelve modules (0.1 s a time, parsed again)."""
    import ast
    import hashlib
    import importlib

    source = inspect.getsource(importlib.import_module(name)).rstrip()
    package = _spec_package()
    imports: list[str] = []
    for node in ast.walk(ast.parse(source)):
        if isinstance(node, ast.ImportFrom) and node.level == 1:
            # from ._x import f  |  from . import _x
            imports += ([f"{package}.{node.module}"] if node.module else
                        [f"{package}.{a.name}" for a in node.names])
    return hashlib.sha256(source.encode()).hexdigest(), tuple(imports)


@functools.lru_cache(maxsize=1024)
def source_of(obj: Callable[..., Any]) -> str:
    """``inspect.getsource(obj)``, trailing space stripped, read once a process: the seven checks
    of each workcell hash the same functions' source, and reading one re-tokenises its file
    (``inspect.getblock``), a second of CPU over a prove. A run reads the files as they are
    when first asked, as inspect's own line cache already does."""
    return inspect.getsource(obj).rstrip()


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
    #: What the proof does not cover, in a few words (e.g. "wrapper proved, search assumed"),
    #: shown next to the verdict.
    label: str = ""
    #: Why the proof is definitional (docs/model.md §10: true by a definition's own clauses, a
    #: termination measure or a named choice instance); empty for a theorem. The one place an
    #: obligation's kind is declared (``_registry.DEFINITIONAL`` is a view of it).
    definitional: str = ""
    #: What the obligation establishes, in one plain sentence for a reader who does not read the
    #: statement (docs/model.md §8; ``_summaries.summary_problems`` checks it).
    summary: str = ""

    @property
    def kind(self) -> str:
        """``definitional`` when ``definitional`` gives a reason, else ``theorem``."""
        return "definitional" if self.definitional else "theorem"


@dataclass(frozen=True)
class VCResult:
    """One VC's answers: vacuity (want sat) and the proof (want unsat; sat for a refutation),
    its depth when proved, its statement's hash (standard SMT-LIB 2.6, or Z3's text when it
    has no standard rendering), cvc5's answer on the standard text and the confirming solvers."""

    name: str
    vacuity: str
    answer: str
    depth: str | None = None
    sha256: str = ""
    cvc5: str = ""                 # unsat | sat | unknown | "" (not replayed)
    cvc5_reason: str = ""
    solvers: tuple[str, ...] = ()
    note: str = ""                 # why a second solver does not confirm it, if it does not
    nonlinear: bool = False        # nonlinear real or integer arithmetic (_depth.is_nonlinear)
    #: cvc5's answer taken from proofs/obligations.lock (undecided when pinned), not re-run.
    cvc5_from_pin: bool = False
    #: Z3's resource count on the vacuity check and on the proof check (each in a context of
    #: its own, so a function of the statement alone): what ``_limits`` calibrates from.
    rlimit_count: tuple[int, ...] = ()
    #: The cvc5 strategy the replay ran under (``_cvc5.STRATEGIES``); "" when not replayed.
    cvc5_strategy: str = ""


@dataclass(frozen=True)
class SmokeResult:
    """A smoke test's answer: sat (the point is reached), unsat (vacuous) or unknown, with how
    it was decided."""

    name: str
    answer: str
    how: str = ""


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
    depth: str | None = None            # the deepest VC's level (proved Z3 obligations)
    label: str = ""
    smoke: tuple[SmokeResult, ...] = ()
    pins: dict[str, str] = field(default_factory=dict)   # what obligations.lock pins
    standard: str = ""                  # every VC in standard SMT-LIB 2.6 (Z3 obligations)
    cvc5_seconds: float = 0.0
    #: Z3's resource limit per check that ran (``_limits.z3_rlimit``); None: wall clock only.
    rlimit: int | None = None

    @property
    def as_expected(self) -> bool:
        return self.verdict is self.expected

    @property
    def solvers(self) -> tuple[str, ...]:
        """The solvers that confirm every VC (Z3 obligations; empty for the others)."""
        if not self.vcs:
            return ()
        common = set(self.vcs[0].solvers)
        for v in self.vcs[1:]:
            common &= set(v.solvers)
        return tuple(s for s in self.vcs[0].solvers if s in common)


# --- discharging --------------------------------------------------------------------------------

def discharge(ob: Obligation) -> Proof:
    """Run one obligation to a verdict (cvc5's replay included, waited for); any exception is
    a FAILED verdict that says why."""
    from ._cvc5 import Cvc5Pool

    with Cvc5Pool() as pool:
        return discharge_pending(ob, pool).settle()


#: Per smoke-test check (with the pins, the ground abstraction, without the pins): a resource
#: limit (every bundled smoke check is decided in under 40 000) and a wall-clock safety net.
SMOKE_TIMEOUT_MS = 1_500
SMOKE_RLIMIT = 1_000_000


@dataclass
class _Pending:
    """An obligation discharged by Z3, its cvc5 replays still running (``settle`` waits)."""

    ob: Obligation
    text: str
    seconds: float
    fields: dict[str, Any]
    futures: list[Any]            # per VC: a Future of a Cvc5Answer, or None
    certificates: list[Any]       # per VC: the VC if it carries a certificate, else None

    def settle(self) -> Proof:
        """Wait for cvc5; record per VC the solvers that confirm it (Z3, cvc5, or an SOS
        certificate where cvc5 did not); a cvc5 answer contradicting Z3's FAILS it."""
        from ._sos import check_certificate

        f = dict(self.fields)
        results = list(f.get("vcs", ()))
        disagree = []
        cvc5_s = 0.0
        own = 0.0      # time spent here (certificates), not waiting for cvc5
        for n, (r, fut) in enumerate(zip(results, self.futures)):
            solvers = list(r.solvers)
            note = r.note
            cvc5, reason = r.cvc5, r.cvc5_reason
            if fut is not None:
                a = fut.result()
                cvc5, reason, cvc5_s = a.answer, a.reason, cvc5_s + a.seconds
                if r.answer in ("unsat", "sat") and cvc5 in ("unsat", "sat"):
                    if cvc5 == r.answer:
                        solvers.append("cvc5")
                    else:
                        disagree.append(f"{r.name} (Z3 {r.answer}, cvc5 {cvc5})")
                if cvc5 == "unknown":
                    note = (f"{note}: still unknown ({reason})" if "when pinned" in note
                            else f"cvc5 unknown ({reason})")
            vc = self.certificates[n]
            if "cvc5" not in solvers and r.answer == "unsat" and vc is not None:
                t0 = time.perf_counter()
                ok, detail = check_certificate(vc)
                own += time.perf_counter() - t0
                if ok:
                    solvers.append("sympy-sos")
                    note = (note + "; " if note else "") + f"confirmed by {detail}"
                else:
                    note = (note + "; " if note else "") + f"not confirmed: {detail}"
            results[n] = dataclasses.replace(r, cvc5=cvc5, cvc5_reason=reason,
                                             solvers=tuple(solvers), note=note)
        if disagree and f["verdict"] is not Verdict.FAILED:
            f["verdict"] = Verdict.FAILED
            f["reason"] = "the solvers disagree: " + ", ".join(disagree)
        f["vcs"] = tuple(results)
        return Proof(id=self.ob.id, group=self.ob.group, method=self.ob.method,
                     expected=self.ob.expected, seconds=self.seconds + own, smtlib=self.text,
                     sha256=hashlib.sha256(self.text.encode()).hexdigest(),
                     label=self.ob.label, cvc5_seconds=round(cvc5_s, 3), **f)


def discharge_pending(ob: Obligation, pool: Any, skip: dict[str, str] | None = None,
                      recheck: bool = False, strategies: dict[str, str] | None = None
                      ) -> _Pending:
    """Run one obligation with Z3 (or sympy, or the data check), handing each VC's standard
    SMT-LIB to ``pool`` (a ``_cvc5.Cvc5Pool``) for the replay; the statements in ``skip`` (hash
    -> why: cvc5 did not decide them when they were pinned) are not replayed: their answer is
    the pinned one (``VCResult.cvc5_from_pin``), unless ``recheck`` (``--recheck-undecided``)
    replays them too (docs/model.md §6); ``strategies`` (hash -> name, ``_pins.cvc5_strategies``)
    the cvc5 strategy of a statement, else ``_cvc5.DEFAULT_STRATEGY``. Z3 decides every VC
    either way. ``settle()`` gives the Proof. Any exception is a FAILED verdict that says why."""
    t0 = time.perf_counter()
    text = ""
    futures: list[Any] = []
    certs: list[Any] = []
    try:
        query = ob.build()
        # Each check's Z3 text, printed once: the saved query holds it and each check's
        # solver is rebuilt from it (``_solver``), the same text either way.
        texts = _check_texts(query) if isinstance(query, Z3Query) else []
        text = render_query(ob, query, texts)
        if isinstance(query, Z3Query):
            fields, futures, certs = _run_z3(ob, query, pool, skip or {}, recheck, texts,
                                             strategies or {})
        else:
            outcome = _guarded(query.run, ob.timeout_ms)
            fields = _check_fields(ob, outcome)
            fields["pins"] = {"source": _source_hash(ob, query)}
            # The result is part of the hashed text: new data or a changed computation that
            # gives another N, h or slack is reported "changed", not "same".
            text += _outcome_text(outcome)
    except Exception as exc:  # noqa: BLE001 - an obligation must end in a verdict, not a crash
        tb = traceback.format_exception_only(type(exc), exc)[-1].strip()
        fields, futures, certs = _failed_fields(f"exception: {tb}"), [], []
    return _Pending(ob, text, time.perf_counter() - t0, fields, futures, certs)


def failed_proof(ob: Obligation, reason: str) -> Proof:
    """The FAILED Proof of an obligation that could not be run to an answer, saying why."""
    return _Pending(ob, "", 0.0, _failed_fields(reason), [], []).settle()


def _failed_fields(reason: str) -> dict[str, Any]:
    return dict(verdict=Verdict.FAILED, statistics={}, counterexample=None, reason_unknown=None,
                reason=reason, vcs=())


def _source_hash(ob: Obligation, q: CheckQuery) -> str:
    """What the lock pins of a sympy or data check: its canonical text, which holds the
    check's source. A per-scenario check's first line names the scenario file and its hash
    (data, not statement): left out, so the pin is the check's, whatever the workcell."""
    content = q.content
    if ob.id.startswith("Scenario.") and content.startswith("scenario "):
        content = content.split("\n", 1)[1] if "\n" in content else ""
    return hashlib.sha256(content.encode()).hexdigest()


def standard_smtlib(vc: VC) -> tuple[str | None, str, str]:
    """(text, sha256, note) of the VC's proof check in standard SMT-LIB 2.6 (``_smtlib``); with
    no standard rendering, (None, the hash of Z3's own text, why)."""
    from ._smtlib import NotStandard, smtlib_query

    hyps = [h for _, h in vc.hypotheses]
    try:
        q = smtlib_query(hyps, vc.goal)
        return q.text, q.sha256, ""
    except NotStandard as exc:
        s = z3.Solver()
        s.add(hyps)
        s.add(z3.Not(vc.goal))
        z3text = "z3 dialect\n" + s.sexpr()
        return (None, hashlib.sha256(z3text.encode()).hexdigest(),
                f"no standard SMT-LIB rendering ({exc})")


def _solver(timeout_ms: int, ctx: z3.Context | None = None,
            formulas: Sequence[z3.BoolRef] = (), text: str | None = None,
            rlimit: int | None = None, tactic: str | None = None,
            tactic_params: Sequence[tuple[str, bool | int]] = ()) -> z3.Solver:
    """A solver with a timeout; given ``formulas``, in a context of its own holding them, rebuilt
    from their SMT-LIB text (``text``, when the caller has printed it already: ``_text_of`` of
    the same formulas, which it must be). ``tactic``: the solver of that Z3 tactic, given
    ``tactic_params`` (``VC.z3_tactic``), instead of Z3's default solver; the same limits.

    Z3's search on quantified VCs depends on the order of the terms it holds: a VC proved in
    0.1 s ran out of its 20 s once a vacuity check had run in the same context, or after other
    proofs in the process. Rebuilt from text in a new context, a check's answer depends on its
    statement alone, wherever and whenever it runs.
    """
    if formulas or text is not None:
        # (No formulas: an empty check, in a context of its own too, so that its resource
        # count is its own.)
        ctx = z3.Context()
        if text is None:
            text = _text_of(formulas)
        parsed = list(z3.parse_smt2_string(text, ctx=ctx))
        if len(parsed) != len(formulas):
            raise AssertionError(f"re-read {len(parsed)} assertions of {len(formulas)}")
    if tactic is None:
        s = z3.Solver(ctx=ctx)
    else:
        t = z3.Tactic(tactic, ctx=ctx)
        s = (z3.With(t, **dict(tactic_params)) if tactic_params else t).solver()
    s.set("timeout", timeout_ms)
    if rlimit is not None:
        # Z3's resource limit, counted from where the check starts: deterministic, so the
        # answer does not depend on the machine's load (``_limits``); ``timeout_ms`` is then
        # only a safety net.
        s.set("rlimit", rlimit)
    if formulas:
        s.add(parsed)
    return s


def _why_unknown(s: z3.Solver, rlimit: int | None) -> str:
    """Z3's reason for an unknown, saying when the check ran into its resource limit (some
    tactics report that as "canceled")."""
    why = str(s.reason_unknown())
    if rlimit is not None and rlimit_count(s) >= rlimit:
        why = (why if "resource limit" in why else f"{why}: resource limit") + f" {rlimit} reached"
    return why


def rlimit_count(s: z3.Solver) -> int:
    """Z3's resource count of the solver's context so far (``rlimit count``; 0 before any
    check): for a check in a context of its own, what the check used."""
    for key, value in s.statistics():
        if key == "rlimit count":
            return int(value)
    return 0


def _text_of(formulas: Sequence[z3.BoolRef]) -> str:
    """Z3's SMT-LIB text of ``formulas`` (declarations, then one assert each, in order)."""
    from ._z3text import text_of

    return text_of(formulas)


def _stats(s: z3.Solver, into: dict[str, float]) -> None:
    for key, value in s.statistics():   # z3.Statistics yields (key, value) pairs
        if key in _VOLATILE_STATS:
            continue
        into[key] = into.get(key, 0) + value


def _smoke(sm: Smoke, stats: dict[str, float], ctx: z3.Context | None = None) -> SmokeResult:
    """Decide a smoke test: sat (a state reaches the point: a model, with the pins or
    without), unsat (none does: shown on the test itself, or on its ground abstraction, which
    over-approximates it, so its unsat is the test's), or unknown (neither shown)."""
    from ._depth import _unsat
    from ._limits import wall_net_ms
    from ._smtlib import Mode, NotStandard, smtlib_query

    net = wall_net_ms(SMOKE_TIMEOUT_MS, SMOKE_RLIMIT)
    ctx = ctx or z3.Context()
    s = _solver(net, ctx, rlimit=SMOKE_RLIMIT)
    s.add([h.translate(ctx) for _, h in sm.hypotheses])
    s.add(z3.Not(sm.goal.translate(ctx)))
    if sm.lemmas and sm.lemma_witness:
        found = _smoke_by_lemmas(sm, stats, ctx)
        if found is not None:
            return found
    pins = [c.translate(ctx) == v.translate(ctx) for c, v in sm.witness]
    pinned = None
    if pins:
        pinned = s.check(*pins)
        _stats(s, stats)
        if pinned == z3.sat:
            return SmokeResult(sm.name, "sat", "a model, with the pinned constants")
    # The pins only help find a model: unsat with them says nothing.
    try:
        text = smtlib_query([h for _, h in sm.hypotheses], sm.goal, Mode.GROUND).text
        if _unsat(text, net, ctx, SMOKE_RLIMIT):
            return SmokeResult(sm.name, "unsat", "its ground abstraction is unsat")
    except NotStandard:
        pass
    if pinned == z3.unknown:
        # Z3 gave up on the pinned test already; without the pins it would not do better.
        return SmokeResult(sm.name, "unknown", "undecided (unknown with the pinned constants); "
                           "its ground abstraction has a model")
    r = s.check()
    _stats(s, stats)
    if r == z3.sat:
        return SmokeResult(sm.name, "sat", "a model")
    if r == z3.unsat:
        return SmokeResult(sm.name, "unsat", "unsat")
    return SmokeResult(sm.name, "unknown", f"undecided ({s.reason_unknown()}); its ground "
                       "abstraction has a model")


def _smoke_by_lemmas(sm: Smoke, stats: dict[str, float], ctx: z3.Context) -> SmokeResult | None:
    """A model of the smoke test with ``lemma_witness`` substituted, its lemmas proved valid
    there and replaced by true (a closed fact proved valid is true in every model, so the test
    and the test with it replaced by true have the same models); None if that does not work."""
    from ._limits import wall_net_ms

    net = wall_net_ms(SMOKE_TIMEOUT_MS, SMOKE_RLIMIT)
    sig = [(c, v) for c, v in sm.lemma_witness]
    f = z3.substitute(z3.And(*[h for _, h in sm.hypotheses], z3.Not(sm.goal)), *sig)
    used = []
    for lname, lemma in sm.lemmas:
        closed = z3.substitute(lemma, *sig)
        if z3.eq(z3.substitute(f, (closed, z3.BoolVal(True))), f):
            continue                    # not in this test
        s = _solver(net, ctx, rlimit=SMOKE_RLIMIT)
        s.add(z3.Not(closed.translate(ctx)))
        r = s.check()
        _stats(s, stats)
        if r != z3.unsat:
            return None
        f = z3.substitute(f, (closed, z3.BoolVal(True)))
        used.append(lname)
    s = _solver(net, ctx, rlimit=SMOKE_RLIMIT)
    s.add(f.translate(ctx))
    r = s.check()
    _stats(s, stats)
    if r != z3.sat:
        return None
    return SmokeResult(sm.name, "sat", "a model of the pinned test"
                       + (f", with {'; '.join(used)} proved of it" if used else ""))


def _short_text(f: z3.ExprRef, width: int = 50) -> str:
    text = " ".join(str(f).split())
    return text if len(text) <= width else text[: width - 3] + "..."


def proof_answer(ob: Obligation) -> str:
    """What a proof check of ``ob`` must answer: sat for a refutation, else unsat."""
    return "sat" if ob.expected is Verdict.REFUTED_AS_EXPECTED else "unsat"


def vc_keys(vcs: Sequence[VC]) -> list[str]:
    """Each VC's key in the lock and in results.json: its name, or, for a name an earlier VC of
    the obligation has, the name and its position (``name#3``)."""
    keys: list[str] = []
    for vc in vcs:
        keys.append(vc.name if vc.name not in keys else f"{vc.name}#{len(keys) + 1}")
    return keys


def _run_z3(ob: Obligation, q: Z3Query, pool: Any, skip: dict[str, str], recheck: bool = False,
            texts: Sequence[tuple[str, str]] | None = None,
            strategies: dict[str, str] | None = None
            ) -> tuple[dict[str, Any], list[Any], list[Any]]:
    """Z3's answers on each VC's vacuity and proof checks (``texts``: their Z3 text,
    ``_check_texts``, printed by the caller; printed here if not given), its depth, statement
    hash and cvc5 replay; the Proof's fields, cvc5's futures and the VCs to certify."""
    from ._cvc5 import CVC5_TIMEOUT_MS, DEFAULT_STRATEGY, strategy_flags
    from ._depth import NonlinearMemo, deepest, is_nonlinear, vc_depth
    from ._limits import wall_net_ms, z3_rlimit

    if not q.vcs:
        return (dict(verdict=Verdict.FAILED, statistics={}, counterexample=None,
                     reason_unknown=None, reason="no verification conditions", vcs=()), [], [])
    stats: dict[str, float] = {}
    results: list[VCResult] = []
    futures: list[Any] = []
    certs: list[Any] = []
    pins: dict[str, str] = {}
    standard: list[str] = []
    vacuous: list[str] = []
    unknowns: list[str] = []
    refuted: list[tuple[str, str]] = []
    want = proof_answer(ob)
    if texts is None:
        texts = _check_texts(q)
    limit = z3_rlimit(ob.id)
    net = wall_net_ms(ob.timeout_ms, limit)
    # The VCs of one obligation share most hypotheses: each is scanned once (docs/model.md §6.4).
    scanned = NonlinearMemo()
    for vc, key, (vac_text, proof_text) in zip(q.vcs, vc_keys(q.vcs), texts, strict=True):
        hyps = [h for _, h in vc.hypotheses]
        # Vacuity: the hypotheses (with the optional witness pinned) must have a model.
        s = _solver(net, formulas=hyps + [c == v for c, v in vc.witness], text=vac_text,
                    rlimit=limit)
        vac = s.check()
        _stats(s, stats)
        vac_count = rlimit_count(s)
        if vac == z3.unsat:
            vacuous.append(vc.name)
        elif vac == z3.unknown:
            unknowns.append(f"{vc.name} (vacuity check): {_why_unknown(s, limit)}")
        # The proof: hypotheses and the negated goal must have no model.
        s = _solver(net, formulas=hyps + [z3.Not(vc.goal)], text=proof_text, rlimit=limit,
                    tactic=vc.z3_tactic, tactic_params=vc.z3_tactic_params)
        ans = s.check()
        _stats(s, stats)
        counts = (vac_count, rlimit_count(s))
        if ans == z3.sat:
            model = s.model().translate(z3.main_ctx())
            text = q.render(model) if q.render is not None else _default_render(model)
            refuted.append((vc.name, text))
        elif ans == z3.unknown:
            unknowns.append(f"{vc.name}: {_why_unknown(s, limit)}")
        # The statement in standard SMT-LIB: pinned by its hash, replayed by cvc5.
        std, sha, note = standard_smtlib(vc)
        pins[key] = sha
        chosen = (strategies or {}).get(sha, DEFAULT_STRATEGY)
        if std is not None:
            # The replay's options in the comment: `cvc5 <flags> <file>` re-runs it as it ran.
            standard += [f"; VC {vc.name}: proof check (expect {want}); cvc5 "
                         + strategy_flags(chosen),
                         std.replace("(exit)\n", "(reset)\n")]
        depth = None
        if ans == z3.unsat and ob.expected is Verdict.PROVED:
            depth = vc_depth(hyps, vc.goal)
        replay = std is not None and ans != z3.unknown
        # A statement cvc5 did not decide when pinned: its pinned answer (the same text gets
        # the same answer), re-run only when asked; a decided one is re-run every time.
        pinned = replay and sha in skip and not recheck
        strategy = chosen if replay else ""
        futures.append(pool.submit(std, strategy=strategy) if replay and not pinned else None)
        certs.append(vc if vc.certificate is not None else None)
        cvc5 = why = ""
        if pinned:
            cvc5, why = "unknown", skip[sha]
            note = (f"cvc5 undecided when pinned ({skip[sha]}); taken from the lock, not re-run "
                    "(cfmpa prove --recheck-undecided re-runs it)")
        elif replay and sha in skip:
            note = f"cvc5 undecided when pinned ({skip[sha]}); re-run for {CVC5_TIMEOUT_MS} ms"
        results.append(VCResult(vc.name, str(vac), str(ans), depth=depth, sha256=sha,
                                cvc5=cvc5, cvc5_reason=why,
                                solvers=("z3",) if str(ans) == want else (), note=note,
                                nonlinear=is_nonlinear(hyps + [vc.goal], scanned),
                                cvc5_from_pin=pinned,
                                rlimit_count=counts, cvc5_strategy=strategy))
    smoke = [_smoke(sm, stats) for sm in q.smoke]      # each in a context of its own
    dead = [r.name for r in smoke if r.answer == "unsat"]
    undecided = [r.name for r in smoke if r.answer == "unknown"]
    cex = "\n".join(f"[{name}]\n{text}" if len(q.vcs) > 1 else text for name, text in refuted)
    cex_or_none = cex or None
    unknown_text = "; ".join(unknowns) or None
    if vacuous:
        verdict, reason = Verdict.FAILED, "vacuous: hypotheses unsatisfiable in " + ", ".join(vacuous)
    elif dead:
        verdict = Verdict.FAILED
        reason = ("vacuous program: no state reaches " + "; ".join(dead)
                  + " (smoke tests unsat)")
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
    if q.smoke and not dead:
        reason += (f"; {len(smoke) - len(undecided)} of {len(smoke)} smoke tests reached"
                   + (f", {len(undecided)} undecided ({'; '.join(undecided)})"
                      if undecided else ""))
    depth_all = (deepest([r.depth for r in results if r.depth is not None])
                 if verdict is Verdict.PROVED else None)
    return (dict(verdict=verdict, statistics=dict(sorted(stats.items())),
                 counterexample=cex_or_none, reason_unknown=unknown_text, reason=reason,
                 vcs=tuple(results), depth=depth_all, smoke=tuple(smoke), pins=pins,
                 standard="\n".join(standard) + ("\n(exit)\n" if standard else ""),
                 rlimit=limit),
            futures, certs)


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


def _check_texts(query: Z3Query) -> list[tuple[str, str]]:
    """Per VC, Z3's text of its vacuity check (the hypotheses, the witness pinned) and of its
    proof check (the hypotheses, the goal negated): ``_text_of`` of those formulas, in order,
    byte for byte, both cut from one print of the hypotheses, the pins and the negated goal
    (``_z3text``: printing is most of the cost, and the hypotheses would be printed twice)."""
    from ._z3text import Printed

    out = []
    for vc in query.vcs:
        hyps = [h for _, h in vc.hypotheses]
        pins = [c == v for c, v in vc.witness]
        printed = Printed(hyps + pins + [z3.Not(vc.goal)])
        n, m = len(hyps), len(pins)
        out.append((printed.text(range(n + m)), printed.text([*range(n), n + m])))
    return out


def check_command(vc: VC) -> str:
    """The SMT-LIB command that runs ``vc``'s proof check as ``_run_z3`` does: ``(check-sat)``
    on Z3's default solver, or ``(check-sat-using T)`` with its tactic and parameters."""
    if vc.z3_tactic is None:
        return "(check-sat)"
    if not vc.z3_tactic_params:
        return f"(check-sat-using {vc.z3_tactic})"
    opts = " ".join(f":{k} {str(v).lower() if isinstance(v, bool) else v}"
                    for k, v in vc.z3_tactic_params)
    return f"(check-sat-using (using-params {vc.z3_tactic} {opts}))"


def render_query(ob: Obligation, query: Query,
                 texts: Sequence[tuple[str, str]] | None = None) -> str:
    """The replayable text of an obligation: SMT-LIB for Z3 (one block per check, then (reset)),
    the canonical inputs for sympy and data checks. Its sha256 identifies the obligation.
    ``texts``: the checks' Z3 text (``_check_texts``) if printed already."""
    head = [f"; obligation {ob.id} ({ob.paper_ref})", f"; method {ob.method}, expected {ob.expected}"]
    head += [f"; {line}" for line in ob.statement.splitlines()]
    if isinstance(query, CheckQuery):
        return "\n".join(head + ["", query.content.rstrip(), ""])
    out = head
    second = ("refutation (expect sat: the counterexample)"
              if ob.expected is Verdict.REFUTED_AS_EXPECTED else "proof (expect unsat)")
    if texts is None:
        texts = _check_texts(query)
    from ._limits import wall_net_ms, z3_rlimit

    limit = z3_rlimit(ob.id)
    # The limits each check runs under: the resource limit, and the wall clock as a net.
    options = [f"(set-option :timeout {wall_net_ms(ob.timeout_ms, limit)})"]
    if limit is not None:
        options.append(f"(set-option :rlimit {limit})")
    for vc, pair in zip(query.vcs, texts, strict=True):
        # The vacuity check runs on Z3's default solver, the proof check on the VC's tactic.
        for label, body, check in zip(("vacuity (expect sat)", second), pair,
                                      ("(check-sat)", check_command(vc))):
            names = ", ".join(n for n, _ in vc.hypotheses) or "none"
            # (reset) rather than push/pop: incremental mode would change Z3's tactics.
            out += ["", f"; VC {vc.name}: {label}; hypotheses: {names}",
                    *options, body.rstrip(), check, "(reset)"]
    return "\n".join(out) + "\n"
