"""`make prove`: collect the obligations, discharge them, compare with the last run, report.

The run passes only if every verdict is the expected one and the set of obligation ids equals
the expected list (the fixed ids below plus three per scenario file found): nothing can be
dropped silently. Every obligation's query is saved under the output directory with its
sha256, and results.json says which obligations are new, changed or the same since last time.
"""

from __future__ import annotations

import fnmatch
import json
import os
import tempfile
import time
from collections.abc import Iterable, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import sympy
import z3

from .. import __version__
from ._ledger import ASSUMPTIONS, Assumption
from ._obl_builtdr import builtdr_obligations
from ._obl_geometry import geometry_obligations
from ._obl_margin import margin_obligations
from ._obl_paths import path_obligations, prop8_obligations, theorem_obligations
from ._obl_scenario import scenario_files, scenario_ids, scenario_obligations
from ._obligation import Method, Obligation, Proof, Verdict, discharge

__all__ = [
    "FIXED_IDS",
    "ProveRun",
    "collect_obligations",
    "expected_ids",
    "render_report",
    "run_obligations",
    "selected",
]

#: The obligations every run must produce, besides three per scenario file. Kept by hand, on
#: purpose: an obligation that disappears from the code makes the run fail.
FIXED_IDS: tuple[str, ...] = (
    "Def1.segment", "Def1.segment_printed", "Def2.is_convex", "Def3.convex_hull",
    "Lemma1.convex_monotone", "Lemma2.convex_union",
    "Sep.separating_axis", "Sep.distance_monotone",
    "Margin.cos_bound", "Margin.arc_chord", "Lemma.sweep_margin", "Margin.naive_hull",
    "Thm1.builtdr", "Thm1.termination", "Thm3.builtdr", "Thm3.termination",
    "Thm3.builtdr_tight", "Thm3.termination_tight",
    "Prop1.state_meaning", "Prop2.endpoints", "Prop3.layer_free", "Prop4.rest_free",
    "Prop5.optpath_is_path", "Prop5.printed", "Prop6.opt_layer_free", "Prop7.opt_rest_free",
    "Def4.is_path_printed", "Def4.is_path_fixed_safe",
    "Thm2.searchoptpath", "Thm4.searchoptpath", "Thm4.searchoptpath_tight",
    "Prop8.printed", "Prop8.intersection_monotone", "Prop8.subset_monotone",
    "Prop8.valid_transfer", "Prop8.path_exists", "Prop8.optimal_cost", "Prop8.prestrength_thm4",
)

_COLUMNS = ("total", "proved (Z3)", "proved (sympy)", "checked on data", "refuted as expected",
            "unknown", "failed")


def collect_obligations(scenarios_dir: str | Path = "scenarios",
                        only: Iterable[str] | None = None) -> tuple[Obligation, ...]:
    """Every obligation (cheap: queries are built when discharged), optionally filtered."""
    obs = (geometry_obligations() + margin_obligations() + builtdr_obligations()
           + path_obligations() + theorem_obligations() + prop8_obligations()
           + scenario_obligations(scenarios_dir))
    return tuple(o for o in obs if selected(o.id, only))


def expected_ids(scenarios_dir: str | Path = "scenarios") -> tuple[str, ...]:
    """The ids a full run must produce: FIXED_IDS and three per scenario file found."""
    return FIXED_IDS + tuple(scenario_ids(scenario_files(scenarios_dir)))


def selected(ident: str, only: Iterable[str] | None) -> bool:
    """Whether ``ident`` is picked by ``only``: an exact id, a prefix ending at a dot (``Prop8``
    picks ``Prop8.printed``), or a glob (``Thm*``). None picks everything."""
    if only is None:
        return True
    for pat in only:
        if ident == pat or ident.startswith(pat.rstrip(".") + ".") or fnmatch.fnmatchcase(ident, pat):
            return True
    return False


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

    @property
    def ok(self) -> bool:
        return (all(p.as_expected for p in self.proofs) and not self.missing_ids
                and not self.unexpected_ids)


def run_obligations(obligations: Sequence[Obligation], out_dir: str | Path,
                    expected: Sequence[str]) -> ProveRun:
    """Discharge each obligation, save its query and the results, compare with the last run."""
    out = Path(out_dir)
    out.mkdir(parents=True, exist_ok=True)
    previous = _load_previous(out / "results.json")
    t0 = time.perf_counter()
    proofs = tuple(discharge(o) for o in obligations)
    seconds = time.perf_counter() - t0
    changes = {}
    for p in proofs:
        old = previous.get(p.id)
        changes[p.id] = "new" if old is None else ("same" if old.get("sha256") == p.sha256
                                                  else "changed")
        _write_atomic(out / _query_file(p), p.smtlib)
    ids = [p.id for p in proofs]
    exp = list(expected)
    run = ProveRun(proofs=proofs, obligations=tuple(obligations), changes=changes,
                   removed=tuple(sorted(set(previous) - set(exp) - set(ids))),
                   missing_ids=tuple(i for i in exp if i not in ids),
                   unexpected_ids=tuple(i for i in ids if i not in exp), seconds=seconds)
    _write_atomic(out / "results.json", _results_json(run, previous))
    return run


def _query_file(p: Proof) -> str:
    return f"{p.id}.smt2" if p.method is Method.Z3 else f"{p.id}.txt"


def _load_previous(path: Path) -> dict[str, dict[str, Any]]:
    try:
        doc = json.loads(path.read_text())
        return {o["id"]: o for o in doc.get("obligations", []) if isinstance(o, dict) and "id" in o}
    except (OSError, ValueError, KeyError, TypeError, AttributeError):
        return {}


def _write_atomic(path: Path, text: str) -> None:
    """Write to a temporary name in the same directory, then rename over the target."""
    fd, tmp = tempfile.mkstemp(prefix=f".{path.name}.", dir=path.parent)
    try:
        with os.fdopen(fd, "w", encoding="utf-8") as fh:
            fh.write(text)
        os.replace(tmp, path)
    except BaseException:
        Path(tmp).unlink(missing_ok=True)
        raise


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
        "vcs": [{"name": v.name, "vacuity": v.vacuity, "answer": v.answer} for v in p.vcs],
    }


def _results_json(run: ProveRun, previous: dict[str, dict[str, Any]]) -> str:
    by_id = {o.id: o for o in run.obligations}
    entries = [_proof_json(p, by_id[p.id], run.changes[p.id]) for p in run.proofs]
    ran = {p.id for p in run.proofs}
    # Obligations not selected this time keep their last recorded result.
    carried = [dict(v, change="not run") for k, v in previous.items() if k not in ran]
    doc = {
        "tool": "cfmpa prove", "version": __version__, "z3": z3.get_version_string(),
        "sympy": sympy.__version__, "ok": run.ok,
        "summary": {g: _counts(ps) for g, ps in _groups(run.proofs).items()},
        "totals": _counts(run.proofs),
        "missing_ids": list(run.missing_ids), "unexpected_ids": list(run.unexpected_ids),
        "removed_since_last_run": list(run.removed),
        "obligations": entries + carried,
        "assumptions": [{"id": a.id, "what": a.what, "why": a.why, "used_by": a.used_by}
                        for a in run.assumptions],
        "seconds": round(run.seconds, 3),
    }
    return json.dumps(doc, indent=2, sort_keys=True, ensure_ascii=False) + "\n"


def render_report(run: ProveRun) -> str:
    """The gnatprove.out-like text: summary table, one line per obligation, changes, ledger."""
    groups = _groups(run.proofs)
    width = max([len(g) for g in groups] + [len("Total")])
    heads = [f"{c:>{max(len(c), 5)}}" for c in _COLUMNS]
    lines = ["Summary of proof obligations", "",
             f"{'Group':<{width}}  " + "  ".join(heads),
             "-" * (width + 2 + sum(len(h) + 2 for h in heads))]

    def row(name: str, c: dict[str, int]) -> str:
        return f"{name:<{width}}  " + "  ".join(f"{c[k]:>{len(h)}}" for k, h in zip(_COLUMNS, heads))
    for g, ps in groups.items():
        lines.append(row(g, _counts(ps)))
    lines.append("-" * (width + 2 + sum(len(h) + 2 for h in heads)))
    lines.append(row("Total", _counts(run.proofs)))
    lines += ["", "Obligations", ""]
    idw = max([len(p.id) for p in run.proofs] + [10])
    for p in run.proofs:
        flag = "" if p.as_expected else f"  << expected {p.expected}"
        lines.append(f"{p.id:<{idw}}  {p.verdict.value:<20} {p.seconds:7.2f}s  "
                     f"[{run.changes[p.id]}]{flag}")
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
    lines += ["", "Assumptions (not proved)", ""]
    for a in run.assumptions:
        lines += [f"{a.id}: {a.what}", f"    why: {a.why}", f"    used by: {a.used_by}"]
    verdict = "OK: every verdict as expected" if run.ok else "NOT OK"
    lines += ["", f"{verdict}; {len(run.proofs)} obligations in {run.seconds:.1f} s"]
    return "\n".join(lines) + "\n"
