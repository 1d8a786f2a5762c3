"""`make prove`: collect the obligations, discharge them, compare with the last run, report.

Each obligation is declared once, by an ``Obligation(...)`` in a collector of COLLECTORS;
EXPECTED_VERDICTS, DEFINITIONAL and FIXED_IDS are views of the declarations (all four kept in
the registry, proofs/_registry.py, and re-exported here), and
proofs/obligations.lock the independent pin (its ids are expected, its verdicts and kinds
compared). The run passes only if every verdict is the declared one, the statements and kinds
are the pinned ones, and the set of obligation ids equals the expected list, without
repeats: the fixed ids (FIXED_IDS) plus one per check (CHECKS) and scenario, by name for the bundled
folder's scenarios (so a deleted file is a missing id) and per file found for any other folder
(said in the report). Nothing can be dropped silently. Every obligation's query is saved under
the output directory with its sha256, and results.json says which obligations are new, changed or
the same since last time.
"""

from __future__ import annotations

import datetime as _dt
import hashlib
import json
import os
import time
from collections.abc import Iterable, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, TextIO

import sympy
import z3

from .. import __version__
from ..files import dumps_json, write_bytes_atomic
from ..gitstate import package_state
from ..scenarios import BUNDLED_DIR
from ._controls import Control, ControlResult, run_control
from ._ledger import ASSUMPTIONS, Assumption
from ._obl_scenario import CHECKS, scenario_check_id, scenario_files, scenario_obligations
from ._obligation import Method, Obligation, Proof, Verdict, discharge_pending, failed_proof
from ._pins import LOCK, Mismatch, check_kinds, check_pins, cvc5_skips, cvc5_strategies, load_lock
from ._pins import repin as repin_lock
from ._registry import (
    COLLECTORS,
    DEFINITIONAL,
    EXPECTED_VERDICTS,
    FIXED_IDS,
    declared,
    fixed_ids,
    kind_and_why,
    kind_of,
)
from ._select import selected

__all__ = [
    "BUNDLED_DIR",
    "BUNDLED_SCENARIOS",
    "COLLECTORS",
    "DEFINITIONAL",
    "EXPECTED_VERDICTS",
    "FIXED_IDS",
    "ProveRun",
    "collect_obligations",
    "declared",
    "default_workers",
    "expected_ids",
    "fixed_ids",
    "is_bundled",
    "kind_and_why",
    "kind_of",
    "pinned_verdict",
    "render_report",
    "run_obligations",
    "scenarios_note",
    "selected",
]

#: The bundled scenario files (stems) of ``BUNDLED_DIR``: their checks are expected by name, so
#: a deleted file is a missing id, not a quietly shorter run. Every scenario check must prove.
BUNDLED_SCENARIOS: tuple[str, ...] = ("default", "early-arrival", "gripper", "levels",
                                      "limited-joints", "narrow-gap", "original-fails")


def is_bundled(scenarios_dir: str | Path) -> bool:
    """Whether ``scenarios_dir`` is the repository's own scenarios folder."""
    try:
        return Path(scenarios_dir).resolve() == BUNDLED_DIR.resolve()
    except OSError:
        return False


def pinned_verdict(ident: str) -> Verdict | None:
    """The verdict ``ident`` must get: from EXPECTED_VERDICTS, PROVED for a scenario check, None
    for an id this module does not know (it is then an unexpected id)."""
    if ident in EXPECTED_VERDICTS:
        return EXPECTED_VERDICTS[ident]
    parts = ident.split(".")
    if len(parts) >= 3 and parts[0] == "Scenario" and parts[-1] in CHECKS:
        return Verdict.PROVED
    return None


_COLUMNS = ("total", "proved (Z3)", "proved (sympy)", "checked on data", "refuted as expected",
            "unknown", "failed")


def collect_obligations(scenarios_dir: str | Path = BUNDLED_DIR,
                        only: Iterable[str] | None = None) -> tuple[Obligation, ...]:
    """Every obligation (cheap: queries are built when discharged), optionally filtered."""
    obs = [o for collect in COLLECTORS for o in collect()]
    obs += scenario_obligations(scenarios_dir)
    return tuple(o for o in obs if selected(o.id, only))


def expected_ids(scenarios_dir: str | Path = BUNDLED_DIR) -> tuple[str, ...]:
    """The ids a full run must produce: FIXED_IDS, then len(CHECKS) per workcell: for the bundled
    folder the pinned BUNDLED_SCENARIOS (whatever files are there), for a user's folder one set
    per file in it, its workcells being the ones to prove (``scenarios_note`` says so)."""
    if is_bundled(scenarios_dir):
        stems = list(BUNDLED_SCENARIOS)
    else:
        stems = [f.stem for f in scenario_files(scenarios_dir)]
    return FIXED_IDS + tuple(scenario_check_id(s, c) for s in stems for c in CHECKS)


def scenarios_note(scenarios_dir: str | Path) -> str:
    """What the run proves of the scenario folder, in one plain line (printed at the top): the
    workcells and the ids expected of them (the bundled set is the default)."""
    def ids(stems: Sequence[str]) -> str:
        return ", ".join(scenario_check_id(s, "{" + ",".join(CHECKS) + "}")
                         for s in stems) or "(none)"

    if is_bundled(scenarios_dir):
        return (f"scenarios: the {len(BUNDLED_SCENARIOS)} bundled workcells, expecting "
                + ids(BUNDLED_SCENARIOS))
    stems = [f.stem for f in scenario_files(scenarios_dir)]
    return f"scenarios: the {len(stems)} workcell(s) in {scenarios_dir}, expecting {ids(stems)}"


@dataclass(frozen=True)
class ProveRun:
    """One run: the proofs, how each compares with the previous run, and the id check."""

    proofs: tuple[Proof, ...]
    obligations: tuple[Obligation, ...]
    changes: dict[str, str]            # id -> new | changed | same
    removed: tuple[str, ...]           # in the previous results, expected no longer
    missing_ids: tuple[str, ...]       # expected but not produced
    unexpected_ids: tuple[str, ...]    # produced but not expected
    seconds: float
    assumptions: tuple[Assumption, ...] = field(default=ASSUMPTIONS)
    verdict_mismatch: tuple[str, ...] = ()   # verdict or Obligation.expected != the pinned one
    duplicate_ids: tuple[str, ...] = ()      # produced more than once
    scenarios_note: str = ""
    record: dict[str, Any] = field(default_factory=dict)   # results.json's "run" (run_record)
    pin_mismatch: tuple[Mismatch, ...] = ()  # statement not the one obligations.lock pins
    repinned: tuple[str, ...] | None = None  # --repin: what it changed in the lock
    controls: tuple[ControlResult, ...] = ()  # the negative controls (proofs/_controls.py)
    kind_mismatch: tuple[Mismatch, ...] = ()  # kind not the one obligations.lock pins

    @property
    def ok(self) -> bool:
        return (all(p.as_expected for p in self.proofs) and not self.missing_ids
                and not self.unexpected_ids and not self.verdict_mismatch
                and not self.duplicate_ids and not self.pin_mismatch
                and not self.kind_mismatch and all(c.ok for c in self.controls))


def compare_ids(ids: Sequence[str], expected: Sequence[str]
                ) -> tuple[tuple[str, ...], tuple[str, ...], dict[str, int]]:
    """(missing, unexpected, repeated): expected ids absent from ``ids`` (in expected order),
    ids not expected (first-seen order, once each), and each id produced more than once with
    its count. The prove run and the audit report judge a set of results by this one rule."""
    want = set(expected)
    seen: dict[str, int] = {}
    for i in ids:
        seen[i] = seen.get(i, 0) + 1
    return (tuple(i for i in expected if i not in seen), tuple(i for i in seen if i not in want),
            {i: n for i, n in seen.items() if n > 1})


def run_record(scenarios_dir: str | Path) -> dict[str, Any]:
    """What these results are of: the date, the checkout's commit and cleanliness (an installed
    wheel's: as recorded when it was built), and the sha256 of every scenario file read, so a
    report can tell results of another tree."""
    git = package_state()
    return {"date_utc": _dt.datetime.now(_dt.UTC).isoformat(timespec="seconds"),
            "git": {"commit": git["commit"], "clean": git["clean"]},
            "scenarios": {f.name: hashlib.sha256(f.read_bytes()).hexdigest()
                          for f in scenario_files(scenarios_dir)}}


def run_obligations(obligations: Sequence[Obligation], out_dir: str | Path,
                    expected: Sequence[str], *, note: str = "",
                    record: dict[str, Any] | None = None, lock: str | Path | None = None,
                    repin: bool = False, workers: int = 1,
                    controls: Sequence[Control] = (),
                    progress: TextIO | None = None,
                    recheck_undecided: bool = False) -> ProveRun:
    """Discharge each obligation (in ``workers`` forked processes side by side; the results do
    not depend on how many), save its query and the results, compare with the last run;
    every verdict is checked against ``pinned_verdict`` as well as ``Obligation.expected``,
    and every statement against the lock (``lock``, default proofs/obligations.lock), which
    ``repin`` rewrites first (for the obligations run; after a whole run, dropping the rest).
    cvc5 replays each VC in the background while Z3 goes on (``_cvc5.Cvc5Pool``), except a
    statement it did not decide when pinned, whose answer is the lock's (said per VC and per
    obligation, ``cvc5_tally``) unless ``recheck_undecided`` or ``repin``. The negative
    ``controls`` run too (in the same processes, from the same queue, longest first); the run
    is OK only if each ends as it expects. ``repin`` never touches what a control expects.
    ``progress``: a line per group of obligations as its last one ends, and one for the
    controls (``GroupProgress``); the results do not depend on it."""
    out = Path(out_dir)
    out.mkdir(parents=True, exist_ok=True)
    previous = _load_previous(out / "results.json")
    lock_path = Path(lock) if lock is not None else LOCK
    # cvc5 replays the statements it decided when they were pinned; the undecided ones' answer
    # is the pinned one (--repin: every one replayed; --recheck-undecided: those too).
    pinned = load_lock(lock_path)
    skip = {} if repin else cvc5_skips(pinned)
    # The strategy each statement's replay runs under (the lock's choice, also with --repin,
    # which then writes it back: a choice is changed by measuring, bench/tune_cvc5.py).
    strategies = cvc5_strategies(pinned, lock_path)
    t0 = time.perf_counter()
    told = GroupProgress(obligations, progress)
    if workers > 1 and len(obligations) + len(controls) > 1:
        # One pool for the obligations and the controls, the longest first (by the last run's
        # seconds), so that no process idles at a barrier between the two. With no last run
        # (the audit's fresh one), an obligation's time limit stands in: the per-scenario D_R
        # checks (600 s) first, the controls (short, unknown) last.
        cost = {o.id: o.timeout_ms / 1000 for o in obligations}
        cost.update((i, float(o.get("seconds") or 0.0)) for i, o in previous.items())
        cost.update(_previous_control_seconds(out / "results.json"))
        proofs, checked = _discharge_side_by_side(obligations, skip, workers, cost, told,
                                                  recheck=recheck_undecided, controls=controls,
                                                  strategies=strategies)
    else:
        proofs = _discharge_in_turn(obligations, skip, told, recheck=recheck_undecided,
                                    strategies=strategies)
        checked = tuple(run_control(c) for c in controls)
        if controls:
            told.line("negative controls", len(checked), sum(c.seconds for c in checked))
    seconds = time.perf_counter() - t0
    repinned = None
    if repin:
        ran = {p.id for p in proofs}
        complete = set(FIXED_IDS) <= set(expected) <= ran
        repinned = tuple(repin_lock(proofs, lock_path, complete=complete, kind_of=kind_and_why))
    pinned = load_lock(lock_path) if repin else pinned       # as --repin above rewrote it
    pins = tuple(check_pins(proofs, pinned))
    # A kind is pinned like an expected verdict: --repin above kept every pinned one.
    kinds = tuple(check_kinds(proofs, pinned, kind_and_why))
    changes = {}
    for p in proofs:
        old = previous.get(p.id)
        changes[p.id] = "new" if old is None else ("same" if old.get("sha256") == p.sha256
                                                  else "changed")
        _write_atomic(out / _query_file(p), p.smtlib)
        if p.standard:
            _write_atomic(out / f"{p.id}.std.smt2", p.standard)
    ids = [p.id for p in proofs]
    exp = list(expected)
    mismatch = []
    for p in proofs:
        pin = pinned_verdict(p.id)
        if pin is not None and (p.verdict is not pin or p.expected is not pin):
            mismatch.append(p.id)
    missing, unexpected, repeated = compare_ids(ids, exp)
    run = ProveRun(proofs=proofs, obligations=tuple(obligations), changes=changes,
                   removed=tuple(sorted(set(previous) - set(exp) - set(ids))),
                   missing_ids=missing, unexpected_ids=unexpected,
                   seconds=seconds, verdict_mismatch=tuple(mismatch),
                   duplicate_ids=tuple(sorted(repeated)),
                   scenarios_note=note, record=dict(record or {}), pin_mismatch=pins,
                   repinned=repinned, controls=checked, kind_mismatch=kinds)
    _write_atomic(out / "results.json", _results_json(run, previous))
    return run


def default_workers() -> int:
    """Processes that discharge obligations side by side: two where the machine has two cores
    or more (each is one Z3 at a time, with its own cvc5 replay beside it)."""
    return 2 if (os.cpu_count() or 1) >= 2 else 1


class GroupProgress:
    """A line per group of obligations on ``stream`` as the last of the group ends: the group,
    how many, their own time (summed: side by side it exceeds the wall clock) and the time since
    the run began; in the order the groups end, which the results do not depend on. None:
    silent."""

    def __init__(self, obligations: Sequence[Obligation], stream: TextIO | None) -> None:
        self.stream = stream
        self.start = time.perf_counter()
        self.left: dict[str, int] = {}
        for o in obligations:
            self.left[o.group] = self.left.get(o.group, 0) + 1
        self.count = dict(self.left)
        self.work = dict.fromkeys(self.left, 0.0)

    def done(self, ob: Obligation, p: Proof) -> None:
        """``ob`` has ended with ``p``: the line of its group if it was the group's last."""
        self.work[ob.group] += p.seconds
        self.left[ob.group] -= 1
        if self.left[ob.group] == 0:
            self.line(ob.group, self.count[ob.group], self.work[ob.group])

    def line(self, what: str, n: int, work: float) -> None:
        if self.stream is not None:
            self.stream.write(f"prove: {what}: {n} done, {work:.1f} s of work, at "
                              f"{time.perf_counter() - self.start:.1f} s\n")
            self.stream.flush()


def _discharge_in_turn(obligations: Sequence[Obligation], skip: dict[str, str],
                       told: GroupProgress, recheck: bool = False,
                       strategies: dict[str, str] | None = None) -> tuple[Proof, ...]:
    """Each obligation discharged in this process, one after another, cvc5 replaying behind Z3;
    each settled (``_Pending.settle``, the same Proof whenever it is called) as soon as its
    replays are done, so that a group's line comes when the group is, not at the end."""
    from ._cvc5 import Cvc5Pool

    out: list[Proof | None] = [None] * len(obligations)
    pending: dict[int, Any] = {}

    def settle(i: int) -> None:
        p = pending.pop(i).settle()
        out[i] = p
        told.done(obligations[i], p)

    with Cvc5Pool() as pool:
        for i, o in enumerate(obligations):
            pending[i] = discharge_pending(o, pool, skip, recheck, strategies)
            for j in [j for j, p in pending.items()
                      if all(f is None or f.done() for f in p.futures)]:
                settle(j)
        for j in sorted(pending):
            settle(j)
    assert all(p is not None for p in out)
    return tuple(out)  # type: ignore[arg-type]


# What a worker process of _discharge_side_by_side works on: set before the pool forks, so the
# obligations (closures) are inherited, never pickled; only an index goes out, a Proof back.
_SHARED: dict[str, Any] = {}


def _worker_start() -> None:
    from multiprocessing.util import Finalize

    from ..impl import set_kernel_threads
    from ._cvc5 import Cvc5Pool

    set_kernel_threads(1)              # the workers share the cores already
    pool = Cvc5Pool()
    _SHARED["pool"] = pool
    Finalize(pool, pool.close, exitpriority=10)   # the worker's cvc5 ends with the worker


def _worker_discharge(index: int) -> Proof:
    ob = _SHARED["obligations"][index]
    return discharge_pending(ob, _SHARED["pool"], _SHARED["skip"], _SHARED["recheck"],
                             _SHARED["strategies"]).settle()


def _discharge_side_by_side(obligations: Sequence[Obligation], skip: dict[str, str], jobs: int,
                            cost: dict[str, float], told: GroupProgress | None = None,
                            recheck: bool = False, controls: Sequence[Control] = (),
                            strategies: dict[str, str] | None = None
                            ) -> tuple[tuple[Proof, ...], tuple[ControlResult, ...]]:
    """Each obligation discharged, and each control run, in one of ``jobs`` forked processes,
    the longest (by the last run's seconds, ``cost`` by id) first so that they finish
    together; returned in the given orders. An obligation whose process dies is FAILED with
    that reason, a control ``error`` (which no control expects), never lost or waited for.
    Each obligation is told to ``told`` as it ends, the controls once all have."""
    import multiprocessing
    from concurrent.futures import ProcessPoolExecutor, as_completed

    tasks = [("ob", i, obligations[i].id) for i in range(len(obligations))]
    tasks += [("control", j, controls[j].id) for j in range(len(controls))]
    tasks.sort(key=lambda t: -cost.get(t[2], 0.0))        # stable: the given order on ties
    _SHARED.update(obligations=obligations, skip=skip, recheck=recheck, controls=controls,
                   strategies=strategies)
    out: list[Proof | None] = [None] * len(obligations)
    checked: list[ControlResult | None] = [None] * len(controls)
    try:
        with ProcessPoolExecutor(max_workers=min(jobs, len(tasks)),
                                 mp_context=multiprocessing.get_context("fork"),
                                 initializer=_worker_start) as ex:
            futures = {ex.submit(_worker_discharge if kind == "ob" else _control_worker, i):
                       (kind, i) for kind, i, _ in tasks}
            for fut in as_completed(futures):
                kind, i = futures[fut]
                got: Any                # a ControlResult or a Proof, by kind
                try:
                    got = fut.result()
                except Exception as exc:  # noqa: BLE001 - a dead worker is a verdict, not a crash
                    why = f"{type(exc).__name__}: {exc}" if str(exc) else type(exc).__name__
                    if kind == "control":
                        c = controls[i]
                        got = ControlResult(c.id, c.checker, c.what, c.expected, "error",
                                            f"its worker process ended ({why})", 0.0)
                    else:
                        got = failed_proof(obligations[i], f"its worker process ended ({why})")
                if kind == "control":
                    checked[i] = got
                    if told is not None and all(c is not None for c in checked):
                        told.line("negative controls", len(checked),
                                  sum(c.seconds for c in checked if c is not None))
                    continue
                out[i] = got
                if told is not None:
                    told.done(obligations[i], got)
    finally:
        _SHARED.clear()
    assert all(p is not None for p in out)      # every future ended in a Proof, above
    assert all(c is not None for c in checked)
    return tuple(out), tuple(checked)  # type: ignore[arg-type]


def _control_worker(index: int) -> ControlResult:
    return run_control(_SHARED["controls"][index])


def _previous_control_seconds(path: Path) -> dict[str, float]:
    """Each control's seconds in the last run's results.json (the order of the next run)."""
    try:
        doc = json.loads(path.read_text())
        return {str(c["id"]): float(c.get("seconds") or 0.0) for c in doc.get("controls", [])
                if isinstance(c, dict) and "id" in c}
    except (OSError, ValueError, KeyError, TypeError, AttributeError):
        return {}


def _query_file(p: Proof) -> str:
    return f"{p.id}.smt2" if p.method is Method.Z3 else f"{p.id}.txt"


def _load_previous(path: Path) -> dict[str, dict[str, Any]]:
    try:
        doc = json.loads(path.read_text())
        return {o["id"]: o for o in doc.get("obligations", []) if isinstance(o, dict) and "id" in o}
    except (OSError, ValueError, KeyError, TypeError, AttributeError):
        return {}


def _write_atomic(path: Path, text: str) -> None:
    """``text`` (UTF-8) written atomically by the one writer, cfmpa.files.write_bytes_atomic."""
    write_bytes_atomic(path, text.encode("utf-8"))


def _counts(proofs: Iterable[Proof]) -> dict[str, int]:
    c = dict.fromkeys(_COLUMNS, 0)
    for p in proofs:
        c["total"] += 1
        if p.verdict is Verdict.PROVED:
            key = {Method.Z3: "proved (Z3)", Method.SYMPY: "proved (sympy)",
                   Method.DATA: "checked on data"}[p.method]
            c[key] += 1
        elif p.verdict is Verdict.REFUTED_AS_EXPECTED:
            c["refuted as expected"] += 1
        elif p.verdict is Verdict.UNKNOWN:
            c["unknown"] += 1
        else:
            c["failed"] += 1
    return c


def _groups(proofs: Sequence[Proof]) -> dict[str, list[Proof]]:
    out: dict[str, list[Proof]] = {}
    for p in proofs:
        out.setdefault(p.group, []).append(p)
    return out


def _proof_json(p: Proof, ob: Obligation, change: str) -> dict[str, Any]:
    return {
        "id": p.id, "group": p.group, "paper_ref": ob.paper_ref, "statement": ob.statement,
        "method": p.method.value, "expected": p.expected.value, "verdict": p.verdict.value,
        "as_expected": p.as_expected, "seconds": round(p.seconds, 3), "sha256": p.sha256,
        "file": _query_file(p), "change": change, "statistics": p.statistics,
        "counterexample": p.counterexample, "reason": p.reason,
        "reason_unknown": p.reason_unknown,
        "vcs": [{"name": v.name, "vacuity": v.vacuity, "answer": v.answer, "depth": v.depth,
                 "sha256": v.sha256, "solvers": list(v.solvers), "cvc5": v.cvc5,
                 "cvc5_reason": v.cvc5_reason, "note": v.note, "nonlinear": v.nonlinear,
                 "cvc5_from_pin": v.cvc5_from_pin, "rlimit_count": list(v.rlimit_count),
                 "cvc5_strategy": v.cvc5_strategy}
                for v in p.vcs],
        "cvc5_tally": cvc5_tally(p),
        "depth": p.depth, "label": p.label, "solvers": list(p.solvers),
        "kind": kind_of(p.id), "kind_why": DEFINITIONAL.get(p.id, ""),
        "smoke": [{"name": s.name, "answer": s.answer, "how": s.how} for s in p.smoke],
        "cvc5_seconds": p.cvc5_seconds, "rlimit": p.rlimit,
    }


def _results_json(run: ProveRun, previous: dict[str, dict[str, Any]]) -> str:
    by_id = {o.id: o for o in run.obligations}
    entries = [_proof_json(p, by_id[p.id], run.changes[p.id]) for p in run.proofs]
    ran = {p.id for p in run.proofs}
    # Obligations not selected this time keep their last recorded result.
    carried = [dict(v, change="not run") for k, v in previous.items() if k not in ran]
    doc = {
        "tool": "cfmpa prove", "version": __version__, "z3": z3.get_version_string(),
        "sympy": sympy.__version__, "ok": run.ok, "run": run.record,
        "summary": {g: _counts(ps) for g, ps in _groups(run.proofs).items()},
        "totals": _counts(run.proofs),
        "kinds": kind_counts(run.proofs),
        "missing_ids": list(run.missing_ids), "unexpected_ids": list(run.unexpected_ids),
        "verdict_mismatch": list(run.verdict_mismatch), "duplicate_ids": list(run.duplicate_ids),
        "scenarios_note": run.scenarios_note,
        "removed_since_last_run": list(run.removed),
        "depth": depth_table(run.proofs), "second_solver": solver_table(run.proofs),
        "pins": {"mismatch": [{"id": i, "what": w} for i, w in run.pin_mismatch],
                 "kind_mismatch": [{"id": i, "what": w} for i, w in run.kind_mismatch],
                 "repinned": None if run.repinned is None else list(run.repinned)},
        "obligations": entries + carried,
        "controls": [c.as_json() for c in run.controls],
        "controls_summary": control_summary(run.controls),
        "assumptions": [{"id": a.id, "what": a.what, "why": a.why, "used_by": a.used_by}
                        for a in run.assumptions],
        "seconds": round(run.seconds, 3),
    }
    return dumps_json(doc, ascii_only=False, allow_nan=True)


def cvc5_tally(p: Proof) -> str:
    """Per obligation, what cvc5 did with its VCs: how many it decided this run, how many it
    left undecided this run, and how many undecided answers were taken from the lock (not
    re-run; docs/model.md §6). "" for an obligation without VCs."""
    if not p.vcs:
        return ""
    pinned = sum(v.cvc5_from_pin for v in p.vcs)
    decided = sum(v.cvc5 in ("sat", "unsat") for v in p.vcs)
    ran = sum(bool(v.cvc5) and not v.cvc5_from_pin for v in p.vcs)
    text = f"cvc5 decided {decided} of {len(p.vcs)} VCs"
    if ran - decided:
        text += f", {ran - decided} undecided this run"
    if pinned:
        text += f", {pinned} undecided when pinned (taken from the lock, not re-run)"
    if len(p.vcs) - ran - pinned:
        text += f", {len(p.vcs) - ran - pinned} not replayed"
    return text


def kind_counts(proofs: Iterable[Proof]) -> dict[str, int]:
    """How many obligations are theorems and how many definitional (DEFINITIONAL)."""
    out = {"theorem": 0, "definitional": 0}
    for p in proofs:
        out[kind_of(p.id)] += 1
    return out


def control_summary(controls: Sequence[ControlResult]) -> dict[str, int]:
    """How the negative controls ended: as expected or not, and by which outcome."""
    out = {"total": len(controls), "as_expected": sum(c.ok for c in controls)}
    for c in controls:
        out[c.outcome] = out.get(c.outcome, 0) + 1
    return out


#: What ``depth`` measures, said in results.json beside the table.
DEPTH_MEASURES = ("quantifier instantiation: the weakest reasoning that proves a VC, "
                  "propositional (its Boolean skeleton), ground (theories, no quantifier "
                  "instantiated) or full (quantifiers instantiated); nonlinear arithmetic is "
                  "counted apart (nonlinear_vcs)")


def depth_table(proofs: Iterable[Proof]) -> dict[str, Any]:
    """Counts per depth level (_depth.LEVELS) of the proved Z3 obligations and of their VCs,
    and how many of those VCs hold nonlinear arithmetic."""
    from ._depth import LEVELS

    obs = dict.fromkeys(LEVELS, 0)
    vcs = dict.fromkeys(LEVELS, 0)
    nonlinear = 0
    for p in proofs:
        if p.depth is not None:
            obs[p.depth] += 1
            for v in p.vcs:
                if v.depth is not None:
                    vcs[v.depth] += 1
                    nonlinear += v.nonlinear
    return {"measures": DEPTH_MEASURES, "obligations": obs, "vcs": vcs,
            "nonlinear_vcs": nonlinear}


def solver_table(proofs: Iterable[Proof]) -> dict[str, Any]:
    """Which solvers confirm the VCs that Z3 decided as wanted: Z3 and cvc5, Z3 and a sympy
    SOS certificate, Z3 only (each with its reason)."""
    from ._cvc5 import cvc5_version

    both = sos = pinned = 0
    only: list[dict[str, str]] = []
    for p in proofs:
        for v in p.vcs:
            pinned += v.cvc5_from_pin
            if "z3" not in v.solvers:
                continue
            if "cvc5" in v.solvers:
                both += 1
            elif "sympy-sos" in v.solvers:
                sos += 1
            else:
                only.append({"id": p.id, "vc": v.name, "why": v.note or "not replayed"})
    return {"cvc5": cvc5_version(), "z3_and_cvc5": both, "z3_and_sos": sos,
            "z3_only": len(only), "z3_only_vcs": only, "cvc5_from_pin": pinned}


def render_report(run: ProveRun) -> str:
    """The gnatprove.out-like text: summary table, one line per obligation, changes, ledger."""
    groups = _groups(run.proofs)
    width = max([len(g) for g in groups] + [len("Total")])
    heads = [f"{c:>{max(len(c), 5)}}" for c in _COLUMNS]
    lines = ["Summary of proof obligations", ""] + ([run.scenarios_note, ""] if run.scenarios_note
                                                  else []) + [
             f"{'Group':<{width}}  " + "  ".join(heads),
             "-" * (width + 2 + sum(len(h) + 2 for h in heads))]

    def row(name: str, c: dict[str, int]) -> str:
        return f"{name:<{width}}  " + "  ".join(f"{c[k]:>{len(h)}}" for k, h in zip(_COLUMNS, heads))
    for g, ps in groups.items():
        lines.append(row(g, _counts(ps)))
    lines.append("-" * (width + 2 + sum(len(h) + 2 for h in heads)))
    lines.append(row("Total", _counts(run.proofs)))
    dt = depth_table(run.proofs)
    lines += ["", "Depth of the proved Z3 obligations (an obligation is as deep as its deepest "
              "VC): " + ", ".join(f"{n} {lv}" for lv, n in dt["obligations"].items())
              + "; their VCs: " + ", ".join(f"{n} {lv}" for lv, n in dt["vcs"].items()),
              "Propositional obligations (proved by their Boolean skeleton alone): "
              f"{dt['obligations']['propositional']}",
              "Depth measures quantifier instantiation; proved VCs with nonlinear arithmetic: "
              f"{dt['nonlinear_vcs']}"]
    st = solver_table(run.proofs)
    lines += [f"Second solver (cvc5 {st['cvc5'] or 'not installed'}) on the standard SMT-LIB: "
              f"{st['z3_and_cvc5']} VCs confirmed by Z3 and cvc5, {st['z3_and_sos']} by Z3 and "
              f"an SOS certificate (sympy), {st['z3_only']} by Z3 only"
              + (f"; {st['cvc5_from_pin']} VCs cvc5 did not decide when pinned were not "
                 "re-run, their answer taken from the lock (--recheck-undecided re-runs them)"
                 if st["cvc5_from_pin"] else "")]
    lines += [f"    Z3 only: {o['id']} / {o['vc']}: {o['why']}" for o in st["z3_only_vcs"]]
    lines += ["", "Obligations", ""]
    idw = max([len(p.id) for p in run.proofs] + [10])
    for p in run.proofs:
        pin = pinned_verdict(p.id)
        want = pin if pin is not None else p.expected
        flag = "" if p.as_expected and p.verdict is want else f"  << expected {want}"
        # The verdict is "proved" either way; the line says how: a data check is not a proof.
        shown = ("checked on data" if p.method is Method.DATA and p.verdict is Verdict.PROVED
                 else p.verdict.value)
        how = ""
        if p.method is Method.Z3 and p.verdict in (Verdict.PROVED, Verdict.REFUTED_AS_EXPECTED):
            how = "  " + ", ".join(x for x in (p.depth, "+".join(p.solvers) or "z3",
                                               p.label) if x)
        elif p.label:
            how = f"  {p.label}"
        lines.append(f"{p.id:<{idw}}  {shown:<20} {p.seconds:7.2f}s  "
                     f"[{run.changes[p.id]}]{how}{flag}")
        if any(v.cvc5_from_pin for v in p.vcs):
            lines.append(f"{'':<{idw}}  {cvc5_tally(p)}")
        if p.verdict in (Verdict.UNKNOWN, Verdict.FAILED) or not p.as_expected:
            lines.append(f"{'':<{idw}}  reason: {p.reason}"
                         + (f" ({p.reason_unknown})" if p.reason_unknown else ""))
        if p.counterexample:
            lines += [f"{'':<{idw}}  | {ln}" for ln in p.counterexample.splitlines()]
    changed = {k: sum(1 for v in run.changes.values() if v == k) for k in ("new", "changed", "same")}
    lines += ["", "Since the last run: " + ", ".join(f"{v} {k}" for k, v in changed.items())
              + (f", {len(run.removed)} removed ({', '.join(run.removed)})" if run.removed else "")]
    if run.missing_ids:
        lines.append("MISSING obligations (expected, not produced): " + ", ".join(run.missing_ids))
    if run.unexpected_ids:
        lines.append("UNEXPECTED obligations (produced, not in the expected list): "
                     + ", ".join(run.unexpected_ids))
    if run.verdict_mismatch:
        lines.append("VERDICTS differing from the pinned expectation (EXPECTED_VERDICTS): "
                     + ", ".join(run.verdict_mismatch))
    if run.duplicate_ids:
        lines.append("DUPLICATE obligation ids: " + ", ".join(run.duplicate_ids))
    if run.repinned is not None:
        lines.append("Re-pinned proofs/obligations.lock: " + (
            "no change" if not run.repinned else f"{len(run.repinned)} change(s)"))
        lines += [f"    {ln}" for ln in run.repinned]
    for ident, what in run.pin_mismatch:
        lines.append(f"STATEMENT NOT PINNED: {ident}: {what} (review, then cfmpa prove --repin)")
    for ident, what in run.kind_mismatch:
        lines.append(f"KIND NOT AS PINNED: {ident}: {what}")
    if run.controls:
        cs = control_summary(run.controls)
        lines += ["", "Controls (wrong inputs each checker must reject, right inputs it must "
                  "accept, the harness's own; each safety composition without one of its "
                  "premises, which must not be proved)", "",
                  f"{cs['as_expected']} of {cs['total']} as expected: "
                  + ", ".join(f"{v} {k}" for k, v in cs.items()
                              if k not in ("total", "as_expected"))]
        cw = max(len(c.id) for c in run.controls)
        for c in run.controls:
            flag = "" if c.ok else f"  << expected {' or '.join(c.expected)}"
            lines.append(f"{c.id:<{cw}}  {c.outcome:<9} {c.seconds:6.2f}s  {c.what}{flag}")
            if not c.ok or c.outcome == "unknown":
                lines.append(f"{'':<{cw}}  {c.detail}")
    lines += ["", "Assumptions (not proved)", ""]
    for a in run.assumptions:
        lines += [f"{a.id}: {a.what}", f"    why: {a.why}", f"    used by: {a.used_by}"]
    kinds = kind_counts(run.proofs)
    defs = [p.id for p in run.proofs if kind_of(p.id) == "definitional"]
    if defs:
        lines += ["", f"Definitional (counted apart from the theorems): {', '.join(defs)}"]
    verdict = "OK: every verdict as expected" if run.ok else "NOT OK"
    lines += ["", f"{verdict}; {len(run.proofs)} obligations ({kinds['theorem']} theorems, "
              f"{kinds['definitional']} definitional) in {run.seconds:.1f} s"
              + (f"; {sum(c.ok for c in run.controls)} of {len(run.controls)} "
                 "controls as expected" if run.controls else "")]
    return "\n".join(lines) + "\n"
