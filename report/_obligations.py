"""The report's proof data: obligations, the assumptions ledger and the mutation self-check.

Where the obligations come from (decided here, printed in the report):
- ``proofs_json`` given (what ``make prove`` passes: ``build/proofs/results.json``, just written):
  read from that file, so the report shows exactly the run that ``make prove`` printed;
- otherwise a fresh run of the prove machinery (``cfmpa.proofs.collect_obligations``,
  discharged by ``cfmpa.proofs.run_obligations`` with its workers side by side, into a temporary
  folder; nothing is written under build/proofs).
Either way the ids are checked here against ``cfmpa.proofs.expected_ids`` (or the list the caller
gives): none missing, none extra, none twice; what a results.json says of its own ids is not taken
on trust.

When the report is about given workcell files (``files``), the per-scenario obligations are
exactly those files' (``audited_ids``: the scenario-independent ids, then four per file): a
fresh run discharges them, and a results.json must cover them; its rows for other workcells are
left out of the report and named in the note.
"""

from __future__ import annotations

import dataclasses
import json
from collections.abc import Iterable, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any, TextIO

from ..errors import InputError

__all__ = [
    "ControlRow",
    "ObligationRow",
    "ProofData",
    "VCRow",
    "SUMMARY_COLUMNS",
    "CARD_GROUPS",
    "BADGES",
    "badge_of",
    "audited_ids",
    "card_groups",
    "control_summary",
    "kind_counts",
    "check_ids",
    "load_proofs",
    "read_results",
    "summary_table",
    "load_selftest",
]

#: The summary's columns (gnatprove.out style), key -> heading.
SUMMARY_COLUMNS: tuple[tuple[str, str], ...] = (
    ("total", "total"),
    ("proved_z3", "proved by Z3"),
    ("proved_sympy", "proved by sympy"),
    ("checked_data", "checked on data"),
    ("tested_only", "tested only"),
    ("refuted_as_expected", "refuted as expected"),
    ("unproved", "unproved"),
)

_VERDICTS = ("proved", "refuted as expected", "unknown", "failed")
_KINDS = ("theorem", "definitional")

#: What a card's badge says was done, by the obligation's method, for a *proved* verdict: only a
#: solver's proof is "proved" (Z3's unsat, sympy's exact computation); a check on the run's
#: concrete data (the per-workcell Scenario.* checks) is "checked on data"; a method that only
#: tests, "tested only". Other verdicts are shown as they are (refuted as expected, unknown,
#: failed). The ledger's entries are "assumed" (docs/model.md §6.3, §8).
PROVED_BADGES: dict[str, str] = {"z3": "proved", "sympy": "proved", "data": "checked on data",
                                 "test": "tested only"}
#: Every badge a card or a ledger entry can carry.
BADGES = ("proved", "checked on data", "tested only", "refuted as expected", "unknown", "failed",
          "assumed")


def badge_of(method: str, verdict: str) -> str:
    """The badge of an obligation's card: what was done (PROVED_BADGES), never "proved" for a
    check on data; a proved verdict under a method this report does not know is "unknown"
    (nothing is called proved that is not known to be a proof)."""
    if verdict == "proved":
        return PROVED_BADGES.get(method, "unknown")
    return verdict


@dataclass(frozen=True)
class VCRow:
    """One verification condition of an obligation, as its folded details list it."""

    name: str
    depth: str | None             # propositional | ground | full (None: not measured)
    solvers: tuple[str, ...]      # the solvers that confirm it
    nonlinear: bool               # it holds nonlinear real arithmetic

    def as_json(self) -> dict[str, Any]:
        return {"name": self.name, "depth": self.depth, "solvers": list(self.solvers),
                "nonlinear": self.nonlinear}


@dataclass(frozen=True)
class ObligationRow:
    """One obligation's outcome as the report prints it."""

    id: str
    group: str
    paper_ref: str
    statement: str
    method: str
    verdict: str
    expected: str
    seconds: float | None
    counterexample: str | None
    reason: str
    sha256: str
    change: str | None = None      # new | changed | same | not run, against the previous prove run
    depth: str | None = None       # propositional | ground | full (proved Z3 obligations)
    solvers: tuple[str, ...] = ()  # the solvers confirming every VC (Z3 obligations)
    label: str = ""                # what the proof does not cover, in a few words
    z3_only: tuple[str, ...] = ()  # "VC: why" for each VC only Z3 confirms
    summary: str | None = None     # one plain sentence (cfmpa.proofs.obligation_summary)
    kind: str = "theorem"          # theorem | definitional (cfmpa.proofs.kind_of)
    kind_why: str = ""             # why a definitional one is (results.json's kind_why)
    vcs: tuple[VCRow, ...] = ()
    #: What cvc5 did with its VCs, undecided ones taken from the lock said (proofs.cvc5_tally).
    cvc5: str = ""

    @property
    def as_expected(self) -> bool:
        return self.verdict == self.expected

    @property
    def badge(self) -> str:
        """What its card's badge says was done (``badge_of``)."""
        return badge_of(self.method, self.verdict)

    def as_json(self) -> dict[str, Any]:
        return {"id": self.id, "group": self.group, "paper_ref": self.paper_ref,
                "statement": self.statement, "method": self.method, "verdict": self.verdict,
                "badge": self.badge,
                "expected": self.expected, "as_expected": self.as_expected,
                "seconds": self.seconds, "counterexample": self.counterexample,
                "reason": self.reason, "sha256": self.sha256, "change": self.change,
                "depth": self.depth, "solvers": list(self.solvers), "label": self.label,
                "z3_only": list(self.z3_only), "summary": self.summary, "kind": self.kind,
                "kind_why": self.kind_why, "vcs": [v.as_json() for v in self.vcs],
                "cvc5": self.cvc5}


@dataclass(frozen=True)
class ControlRow:
    """A negative control of ``cfmpa prove`` (docs/model.md §10.3) as results.json recorded it.

    ``ok`` is the report's own reading: the outcome is one the control expects, and the file
    does not say otherwise; a recorded ``ok`` is not taken on trust."""

    id: str
    checker: str
    what: str
    expected: tuple[str, ...]
    outcome: str
    detail: str
    seconds: float | None
    recorded_ok: bool | None

    @property
    def ok(self) -> bool:
        return self.outcome in self.expected and self.recorded_ok is not False

    def as_json(self) -> dict[str, Any]:
        """The record's fields as report.json holds them, with the report's ``ok`` in place of
        the recorded one (derived from the fields: a field added is shown, not forgotten)."""
        doc = dataclasses.asdict(self)
        del doc["recorded_ok"]
        return {**doc, "expected": list(self.expected), "ok": self.ok}


@dataclass(frozen=True)
class ProofData:
    """Obligations and ledger, with where they came from; ``available`` False: none this run."""

    available: bool
    source: str
    note: str
    rows: tuple[ObligationRow, ...]
    ledger: tuple[dict[str, str], ...]
    ledger_available: bool
    missing_ids: tuple[str, ...] = ()      # expected by the prove machinery, not in the data
    unexpected_ids: tuple[str, ...] = ()   # in the data, not expected
    run: dict[str, Any] | None = None      # results.json's "run" record (None: fresh, or absent)
    not_run: tuple[str, ...] = ()          # ids results.json carried over from an earlier run
    #: The negative controls; None: none in this data (a fresh run, or a results.json without
    #: them), said in ``controls_note``.
    controls: tuple[ControlRow, ...] | None = None
    controls_note: str = ""
    missing_controls: tuple[str, ...] = ()  # expected of a whole prove run, not in the data
    depth_measures: str = ""                # what results.json says ``depth`` measures


def load_proofs(proofs_json: str | None, scenarios_dir: str | Path,
                expected: Sequence[str] | None = None,
                files: Sequence[str | Path] | None = None,
                progress: TextIO | None = None) -> ProofData:
    """Obligations and ledger from ``proofs_json``, else from a fresh run (module docstring).

    ``expected``: the ids the data must hold (None: ``audited_ids(files)`` when ``files`` is
    given, else ``expected_ids(scenarios_dir)``, every obligation; a prove run restricted with
    ``--only`` is then reported with ids missing). ``files``: the workcells the report is about,
    whose per-scenario obligations are then the ones shown (a given ``expected`` overrides).
    ``progress``: a fresh run's line per group of obligations as it ends (``run_obligations``).
    """
    from ..proofs import FIXED_IDS, collect_obligations, expected_ids, scenario_obligations

    if files is None or expected is not None:   # the caller's ids, or the folder's
        want = tuple(expected) if expected is not None else expected_ids(Path(scenarios_dir))
        if proofs_json is not None:
            return _from_file(Path(proofs_json), want)
        return _fresh(list(collect_obligations(scenarios_dir)), want, progress)
    paths = [Path(f) for f in files]
    want = audited_ids(paths)
    if proofs_json is not None:
        return _from_file(Path(proofs_json), want, keep={p.stem for p in paths})
    fixed = [o for o in collect_obligations(scenarios_dir) if o.id in FIXED_IDS]
    return _fresh(fixed + scenario_obligations(paths), want, progress)


def audited_ids(files: Sequence[str | Path]) -> tuple[str, ...]:
    """The ids a report on ``files`` must show: the scenario-independent ones, then the four
    per-scenario checks of each file (by its stem), in the order given."""
    from ..proofs import FIXED_IDS, SCENARIO_CHECKS, scenario_check_id

    return FIXED_IDS + tuple(scenario_check_id(Path(f).stem, c) for f in files
                             for c in SCENARIO_CHECKS)


def _scenario_stem(ident: str) -> str | None:
    """The workcell stem of a per-scenario id (Scenario.<stem>.<check>), else None."""
    from ..proofs import SCENARIO_CHECKS

    parts = ident.split(".")
    if len(parts) >= 3 and parts[0] == "Scenario" and parts[-1] in SCENARIO_CHECKS:
        return ".".join(parts[1:-1])
    return None


def check_ids(ids: Sequence[str], expected: Sequence[str]) -> tuple[tuple[str, ...],
                                                                     tuple[str, ...]]:
    """(missing, unexpected): by the prove run's own rule (``proofs.compare_ids``), with each
    repeated id listed among the unexpected as ``"<id> (twice)"``, or its count."""
    from ..proofs import compare_ids

    missing, unexpected, repeated = compare_ids(ids, expected)
    return missing, unexpected + tuple(f"{i} ({'twice' if n == 2 else f'{n} times'})"
                                       for i, n in repeated.items())


def summary_table(rows: Iterable[ObligationRow]) -> dict[str, Any]:
    """Counts per group (in first-seen order) and in total, by the columns of SUMMARY_COLUMNS.

    "proved by Z3 / sympy", "checked on data" and "tested only" count proved verdicts by their
    method (data: an exhaustive check on concrete data; test: method 'test', if any obligation
    declares it); "unproved" counts unknown and failed verdicts.
    """
    groups: dict[str, dict[str, int]] = {}
    total = {k: 0 for k, _ in SUMMARY_COLUMNS}
    for r in rows:
        g = groups.setdefault(r.group, {k: 0 for k, _ in SUMMARY_COLUMNS})
        key = _column(r)
        for bucket in (g, total):
            bucket["total"] += 1
            bucket[key] += 1
    return {"columns": [{"key": k, "heading": h} for k, h in SUMMARY_COLUMNS],
            "rows": [{"group": name, **counts} for name, counts in groups.items()],
            "total": total, "kinds": kind_counts(rows)}


def kind_counts(rows: Iterable[ObligationRow]) -> dict[str, int]:
    """How many obligations are theorems and how many definitional (the headline's counts):
    a definitional one is true by a definition's own clauses, a termination measure or a named
    choice instance (docs/model.md §10), and is not counted among the theorems."""
    out = dict.fromkeys(_KINDS, 0)
    for r in rows:
        out[r.kind] += 1
    return out


def control_summary(rows: Iterable[ControlRow]) -> dict[str, int]:
    """How the negative controls ended, by the report's reading: in all, as expected, and per
    outcome (rejected, refuted, unknown, accepted, proved, error)."""
    rows = list(rows)
    out = {"total": len(rows), "as_expected": sum(r.ok for r in rows)}
    for r in rows:
        out[r.outcome] = out.get(r.outcome, 0) + 1
    return out


@dataclass(frozen=True)
class CardGroup:
    """A group of obligation cards: what its obligations establish, in a reviewer's words."""

    key: str
    title: str
    prefixes: tuple[str, ...]      # id prefixes (up to a dot); () with ``findings``: see below
    findings: bool = False         # the paper's statements shown false (expected refuted)


#: The cards' groups in the order shown, the safety theorem first. An obligation goes to the
#: first group that takes it: the findings group takes every obligation expected to be refuted,
#: then the prefixes decide; one no group takes is shown under "other".
CARD_GROUPS: tuple[CardGroup, ...] = (
    CardGroup("safety", "The safety theorem: no contact at any instant of the executed motion",
              ("Safety",)),
    CardGroup("tolerance", "How far the robot may deviate from its plan", ("Tolerance",)),
    CardGroup("workcells", "Each workcell meets the theorems' premises, and the code's output "
              "for it is checked", ("Scenario",)),
    CardGroup("planner", "The planner computes what the paper claims (Theorems 1-4, "
              "Properties 1-8, the search's witnesses)", ("Thm1", "Thm2", "Thm3", "Thm4",
                                                           "Prop1", "Prop2", "Prop3", "Prop4",
                                                           "Prop5", "Prop6", "Prop7", "Prop8",
                                                           "Def4", "Witness")),
    CardGroup("geometry", "The swept regions cover the motion between grid points (geometry)",
              ("Def1", "Def2", "Def3", "Lemma1", "Lemma2", "Sep", "Margin", "Lemma")),
    CardGroup("findings", "Statements of the paper shown false, as intended (the findings)",
              (), findings=True),
)
_OTHER = CardGroup("other", "Other obligations", ())


def card_groups(rows: Iterable[ObligationRow]) -> list[dict[str, Any]]:
    """The cards by CARD_GROUPS (only groups with a card), each with its ids in the rows' order
    and how many are not as expected (a group with one is shown open)."""
    found: dict[str, list[ObligationRow]] = {}
    for r in rows:
        refuted = r.expected == "refuted as expected"
        group = next((g for g in CARD_GROUPS if g.findings and refuted), None) or next(
            (g for g in CARD_GROUPS if any(r.id.startswith(p + ".") for p in g.prefixes)),
            _OTHER)
        found.setdefault(group.key, []).append(r)
    return [{"key": g.key, "title": g.title, "ids": [r.id for r in found[g.key]],
             "not_as_expected": sum(not r.as_expected for r in found[g.key])}
            for g in (*CARD_GROUPS, _OTHER) if g.key in found]


def _column(r: ObligationRow) -> str:
    if r.verdict == "proved":
        return {"z3": "proved_z3", "sympy": "proved_sympy", "data": "checked_data",
                "test": "tested_only"}.get(r.method, "unproved")
    if r.verdict == "refuted as expected":
        return "refuted_as_expected"
    return "unproved"


# --- from results.json ------------------------------------------------------------------------

def read_results(path: str | Path) -> dict[str, Any]:
    """The results.json of a prove run, parsed; InputError (naming it) if it cannot be read, is
    not JSON or has no obligations list. The audit calls it first, before any work."""
    p = Path(path)
    try:
        doc = json.loads(p.read_text(encoding="utf-8"))
    except OSError as exc:
        raise InputError("proofs_json", str(p),
                         f"cannot be read ({exc.strerror or exc})") from None
    except json.JSONDecodeError as exc:
        raise InputError("proofs_json", str(p), f"is not valid JSON ({exc.msg}, line "
                         f"{exc.lineno})") from None
    if not isinstance(doc, dict) or not isinstance(doc.get("obligations"), list):
        raise InputError("proofs_json", str(p), "has no 'obligations' list")
    return doc


def _from_file(path: Path, expected: Sequence[str], keep: set[str] | None = None) -> ProofData:
    doc = read_results(path)
    items = doc["obligations"]
    rows = tuple(_row_from_json(item, k, path) for k, item in enumerate(items))
    left_out: list[str] = []
    if keep is not None:   # other workcells' checks are not this report's
        left_out = sorted({stem for r in rows if (stem := _scenario_stem(r.id)) is not None
                           and stem not in keep})
        rows = tuple(r for r in rows if _scenario_stem(r.id) in keep or _scenario_stem(r.id)
                     is None)
    ledger_doc = doc.get("assumptions")
    ledger = _ledger_entries(ledger_doc) if isinstance(ledger_doc, list) else ()
    missing, unexpected = check_ids([r.id for r in rows], expected)
    run = doc.get("run") if isinstance(doc.get("run"), dict) else None
    controls, controls_note, missing_controls = _controls_from_json(doc, path, expected)
    depth = doc.get("depth")
    if not isinstance(depth, dict):
        depth = {}
    return ProofData(available=True, source=f"read from {path}",
                     note="the results the prove run recorded, not re-run for this report"
                     + (f"; left out, as not the workcells reported on: the checks of "
                        f"{', '.join(left_out)}" if left_out else ""),
                     rows=rows, ledger=ledger, ledger_available=isinstance(ledger_doc, list),
                     missing_ids=missing, unexpected_ids=unexpected, run=run,
                     not_run=tuple(r.id for r in rows if r.change == "not run"),
                     controls=controls, controls_note=controls_note,
                     missing_controls=missing_controls,
                     depth_measures=str(depth.get("measures") or ""))


def _controls_from_json(doc: dict[str, Any], path: Path, expected: Sequence[str]
                        ) -> tuple[tuple[ControlRow, ...] | None, str, tuple[str, ...]]:
    """(controls, note, missing control ids) of a results.json. When the report expects every
    scenario-independent obligation (a whole prove run), it expects every control of
    ``cfmpa.proofs.collect_controls()`` too: a results.json with controls left out (or none)
    does not pass for a complete one."""
    from ..proofs import FIXED_IDS, collect_controls

    items = doc.get("controls")
    if items is not None and not isinstance(items, list):
        raise InputError("controls", items, f"in {path} must be a list")
    rows = None if items is None else tuple(_control_from_json(c, k, path)
                                            for k, c in enumerate(items))
    missing: tuple[str, ...] = ()
    if set(FIXED_IDS) <= set(expected):
        have = {r.id for r in rows or ()}
        missing = tuple(c.id for c in collect_controls() if c.id not in have)
    if rows is None:
        return None, (f"{path} records no negative controls (a results.json of an older "
                      "cfmpa prove)"), missing
    if not rows:
        return rows, "the prove run selected no negative control (cfmpa prove --only)", missing
    return rows, f"read from {path}, as the prove run recorded them", missing


def _control_from_json(item: Any, k: int, path: Path) -> ControlRow:
    field = f"controls[{k}]"
    if not isinstance(item, dict) or not isinstance(item.get("id"), str):
        raise InputError(field, item, f"in {path} must be an object with an 'id'")
    expected = item.get("expected")
    if not isinstance(expected, list) or not all(isinstance(e, str) for e in expected):
        raise InputError(f"{field}.expected", expected, f"in {path} must be a list of outcomes")
    seconds = item.get("seconds")
    ok = item.get("ok")
    return ControlRow(id=item["id"], checker=str(item.get("checker") or ""),
                      what=str(item.get("what") or ""), expected=tuple(expected),
                      outcome=str(item.get("outcome") or ""), detail=str(item.get("detail") or ""),
                      seconds=float(seconds) if isinstance(seconds, (int, float)) else None,
                      recorded_ok=ok if isinstance(ok, bool) else None)


def _row_from_json(item: Any, k: int, path: Path) -> ObligationRow:
    from ..proofs import obligation_summary

    if not isinstance(item, dict) or not isinstance(item.get("id"), str):
        raise InputError(f"obligations[{k}]", item, f"in {path} must be an object with an 'id'")
    verdict = str(item.get("verdict", ""))
    if verdict not in _VERDICTS:
        raise InputError(f"obligations[{k}].verdict", verdict,
                         f"in {path} must be one of {', '.join(_VERDICTS)}")
    seconds = item.get("seconds")
    return ObligationRow(
        id=item["id"], group=str(item.get("group") or "ungrouped"),
        paper_ref=str(item.get("paper_ref") or ""), statement=str(item.get("statement") or ""),
        method=str(item.get("method", "")), verdict=verdict,
        expected=str(item.get("expected", "proved")),
        seconds=float(seconds) if isinstance(seconds, (int, float)) else None,
        counterexample=item.get("counterexample"), reason=str(item.get("reason", "")),
        sha256=str(item.get("sha256", "")), change=item.get("change"),
        depth=item.get("depth") if isinstance(item.get("depth"), str) else None,
        solvers=tuple(str(s) for s in item.get("solvers") or ()),
        label=str(item.get("label") or ""), z3_only=_z3_only(item.get("vcs")),
        summary=obligation_summary(item["id"]), kind=_kind(item, k, path),
        kind_why=str(item.get("kind_why") or ""), vcs=_vc_rows(item.get("vcs")),
        cvc5=str(item.get("cvc5_tally") or ""))


def _kind(item: dict[str, Any], k: int, path: Path) -> str:
    """results.json's kind; an older file without one: the prove machinery's (kind_of)."""
    from ..proofs import kind_of

    kind = item.get("kind", kind_of(item["id"]))
    if kind not in _KINDS:
        raise InputError(f"obligations[{k}].kind", kind,
                         f"in {path} must be one of {', '.join(_KINDS)}")
    return str(kind)


def _vc_rows(vcs: Any) -> tuple[VCRow, ...]:
    return tuple(VCRow(name=str(v.get("name")), depth=v.get("depth") if isinstance(
                     v.get("depth"), str) else None,
                     solvers=tuple(str(x) for x in v.get("solvers") or ()),
                     nonlinear=v.get("nonlinear") is True)
                 for v in (vcs if isinstance(vcs, list) else ()) if isinstance(v, dict))


def _z3_only(vcs: Any) -> tuple[str, ...]:
    """'VC: why' for each VC of a results.json entry that Z3 alone confirms."""
    out = []
    for v in vcs if isinstance(vcs, list) else ():
        if isinstance(v, dict) and list(v.get("solvers") or ()) == ["z3"]:
            out.append(f"{v.get('name')}: {v.get('note') or 'no second solver confirmed it'}")
    return tuple(out)


# --- a fresh run --------------------------------------------------------------------------------

def _fresh(obligations: Sequence[Any], expected: Sequence[str],
           progress: TextIO | None = None) -> ProofData:
    import tempfile

    from ..proofs import (
        ASSUMPTIONS,
        DEFINITIONAL,
        FIXED_IDS,
        collect_controls,
        cvc5_tally,
        default_workers,
        kind_of,
        obligation_summary,
        run_obligations,
    )

    # The prove runner itself: its worker processes side by side, each with its cvc5 replay in
    # the background, and the lock's record of what cvc5 did not decide (one obligation at a
    # time with a fresh cvc5 each, as before, took 157 s of a 173 s audit on two cores).
    workers = default_workers()
    # A run of every scenario-independent obligation runs the negative controls too, as
    # `cfmpa prove` does: the verdict rows rest on them (docs/model.md §8); a narrower run
    # (a test's stand-in) has none to run and says so.
    whole = set(FIXED_IDS) <= {o.id for o in obligations}
    controls = collect_controls() if whole else ()
    with tempfile.TemporaryDirectory(prefix="cfmpa-audit-proofs-") as tmp:
        run = run_obligations(obligations, tmp, [o.id for o in obligations], workers=workers,
                              controls=controls, progress=progress)
    by_id = {p.id: p for p in run.proofs}
    rows = []
    for ob in obligations:
        p = by_id[ob.id]
        rows.append(ObligationRow(
            id=ob.id, group=ob.group, paper_ref=ob.paper_ref, statement=ob.statement,
            method=p.method.value, verdict=p.verdict.value, expected=p.expected.value,
            seconds=float(p.seconds), counterexample=p.counterexample, reason=p.reason,
            sha256=p.sha256, depth=p.depth, solvers=p.solvers, label=p.label,
            z3_only=tuple(f"{v.name}: {v.note or 'no second solver confirmed it'}"
                          for v in p.vcs if v.solvers == ("z3",)),
            summary=obligation_summary(ob.id), kind=kind_of(ob.id),
            kind_why=DEFINITIONAL.get(ob.id, ""),
            vcs=tuple(VCRow(v.name, v.depth, tuple(v.solvers), bool(v.nonlinear))
                      for v in p.vcs), cvc5=cvc5_tally(p)))
    missing, unexpected = check_ids([r.id for r in rows], expected)
    checked = tuple(ControlRow(id=c.id, checker=c.checker, what=c.what, expected=c.expected,
                               outcome=c.outcome, detail=c.detail, seconds=float(c.seconds),
                               recorded_ok=None) for c in run.controls)
    missing_controls: tuple[str, ...] = ()
    if set(FIXED_IDS) <= set(expected):
        have = {c.id for c in checked}
        missing_controls = tuple(c.id for c in collect_controls() if c.id not in have)
    return ProofData(available=True, source="a fresh run of the prove machinery for this report",
                     note=f"{len(rows)} obligations discharged by {workers} process(es) side "
                     "by side, "
                     f"{sum(r.seconds or 0.0 for r in rows):.1f} s in all"
                     + (f", then {len(checked)} negative controls" if checked else "")
                     + "; nothing written under build/proofs",
                     rows=tuple(rows), ledger=_ledger_entries(ASSUMPTIONS), ledger_available=True,
                     missing_ids=missing, unexpected_ids=unexpected,
                     controls=checked or None, missing_controls=missing_controls,
                     controls_note="run for this report, as cfmpa prove runs them" if checked
                     else "not run for this report: this run did not discharge every "
                     "scenario-independent obligation, with which cfmpa prove runs the negative "
                     "controls")


def _ledger_entries(entries: Iterable[Any]) -> tuple[dict[str, str], ...]:
    """Ledger entries {id, what, why, used_by, badge} from Assumption values or their JSON; the
    badge of each is "assumed" (taken on trust, not proved here)."""
    out = []
    for e in entries:
        get = e.get if isinstance(e, dict) else (lambda k, _e=e: getattr(_e, k, None))
        out.append({**{k: str(get(k) or "") for k in ("id", "what", "why", "used_by")},
                    "badge": "assumed"})
    return tuple(out)


# --- mutation self-check ------------------------------------------------------------------------

def load_selftest() -> dict[str, Any]:
    """The mutation self-check, run now: ``cfmpa.runs.selftest_rows()``."""
    from .. import runs as _selftest

    rows = [dataclasses.asdict(r) for r in _selftest.selftest_rows()]
    return {"available": True, "source": "cfmpa.runs.selftest_rows(), run for this "
            "report", "note": f"sampled mode: {_selftest.SAMPLE} random cells (seed 0) plus the "
            "cells the path occupies; full mode: every cell, and optimality by the independent "
            "search opt_path", "rows": rows}
