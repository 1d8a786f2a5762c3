"""`cfmpa audit`: one self-contained HTML report for a safety reviewer, and its JSON twin.

Content, in order (docs/model.md §8): provenance; the obligations' summary table and each obligation;
the assumptions ledger; the findings about the paper, drawn; the mutation self-check; per
scenario the plans of the three variants with contracts, certificate and pictures; the seeded
comparison campaign. Where a part's data is not available in this run, the part says so.

report.json holds every number of the HTML (not the pictures). For the same inputs and version
it is the same apart from the provenance (date, git state, command line), the times (keys
``seconds``, ``timings_s``, ``mean_seconds``) and, after a fresh run of the obligations, the
total time in ``obligations.note``. Obligation data: see ``_obligations`` (results.json when
given, else a fresh run).
"""

from __future__ import annotations

import dataclasses
from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass
from importlib import resources
from pathlib import Path
from typing import Any

import jinja2

from ..files import dumps_json, jsonable, write_bytes_atomic
from ..errors import CfmpaError, InputError
from ..scenarios import BUNDLED_DIR
from ..impl import left_regions
from ..spec import Scenario, SearchStatus, Variant, load_scenario
from . import _figures as F
from ._compare import campaign_json, format_campaign, run_campaign
from ._findings import (Finding, early_arrival_finding, inconsistency_finding, naive_hull_finding,
                        prop8_finding, sample_clearance)
from ._obligations import ProofData, load_proofs, load_selftest, summary_table
from ._provenance import provenance

__all__ = ["AuditResult", "FORMAT", "DEFAULT_COMPARE_N", "build_audit", "contract_rows",
           "render_html", "run_audit", "write_report", "default_scenarios_dir"]

#: report.json's format name and version (bump the version when a key changes meaning).
FORMAT = {"name": "cfmpa-audit-report", "version": 1}
DEFAULT_COMPARE_N = 100
#: plan.json keys a variant's entry copies when the plan has them (the schema allows them).
_OPTIONAL_PLAN_KEYS = ("kernel", "dr_sha256")
#: The scenarios the findings are shown on (file stems under the scenarios folder).
FINDING_SCENARIOS = {"naive_hull": "default", "inconsistency": "original-fails",
                     "prop8_literal": "original-fails", "is_path_flaw": "early-arrival"}


@dataclass(frozen=True)
class AuditResult:
    """The report's data (report.json) and its pictures (id -> Figure)."""

    doc: dict[str, Any]
    figures: dict[str, F.Figure]


def default_scenarios_dir() -> Path:
    """The bundled scenarios (the checkout's scenarios/, or the installed package's)."""
    return BUNDLED_DIR


def run_audit(scenarios: list[str] | None, out_dir: str, *, argv: list[str] | None = None,
              proofs_json: str | None = None, scenarios_dir: str | None = None,
              contracts: str = "sampled", compare_n: int = DEFAULT_COMPARE_N,
              compare_seed: int = 0, expected_ids: Sequence[str] | None = None) -> int:
    """Write ``out_dir``/report.json and ``out_dir``/report.html (each atomically); print a summary.

    ``scenarios``: scenario files (None: every scenarios/*.toml). ``proofs_json``: a results.json
    of ``make prove`` to report (None: run the obligations afresh). Exit code 0 when everything
    the report checks holds (see the report's first table), 1 otherwise (the report is written
    either way), 2 for bad input. ``expected_ids``: the obligation ids the report must find
    (None: every obligation of the prove machinery).
    """
    result = build_audit(scenarios, argv=argv, proofs_json=proofs_json,
                         scenarios_dir=scenarios_dir, contracts=contracts, compare_n=compare_n,
                         compare_seed=compare_seed, expected_ids=expected_ids)
    html_path, json_path = write_report(result, out_dir)
    v = result.doc["verdict"]
    for item in v["items"]:
        state = {True: "ok", False: "FAILED", None: "not available"}[item["ok"]]
        print(f"{item['check']:<38} {state}: {item['detail']}")
    print(f"wrote     {html_path} ({html_path.stat().st_size} bytes), {json_path}")
    return 0 if v["ok"] else 1


def write_report(result: AuditResult, out_dir: str | Path) -> tuple[Path, Path]:
    """Write report.json, then report.html, each atomically; returns (html path, json path)."""
    out = Path(out_dir)
    json_path = write_bytes_atomic(out / "report.json", dumps_json(result.doc).encode("utf-8"))
    html_path = write_bytes_atomic(out / "report.html", render_html(result).encode("utf-8"))
    return html_path, json_path


def build_audit(scenarios: Sequence[str] | None, *, argv: Sequence[str] | None = None,
                proofs_json: str | None = None, scenarios_dir: str | None = None,
                contracts: str = "sampled", compare_n: int = DEFAULT_COMPARE_N,
                compare_seed: int = 0, expected_ids: Sequence[str] | None = None) -> AuditResult:
    """Compute everything the report shows (no files written)."""
    sdir = Path(scenarios_dir) if scenarios_dir is not None else default_scenarios_dir()
    paths = _scenario_paths(scenarios, sdir)
    loaded = [load_scenario(p) for p in paths]          # input errors before any work
    stems: dict[str, Path] = {}
    for p in paths:   # per-scenario obligation ids carry the stem, so it must be unique
        if p.stem in stems:
            raise InputError("scenarios", str(p), f"has the same stem {p.stem!r} as "
                             f"{stems[p.stem]}: their obligation ids would clash; rename one")
        stems[p.stem] = p
    if isinstance(compare_n, bool) or not isinstance(compare_n, int) or compare_n < 0:
        raise InputError("compare_n", compare_n, "must be an integer >= 0 (0: no campaign)")
    plans = _Plans(contracts)
    figures: dict[str, F.Figure] = {}

    # The user's workcells are the ones to prove: given files bring their own per-scenario
    # obligations (the bundled set, by default, its pinned ones).
    proofs = load_proofs(proofs_json, sdir, expected_ids,
                         files=paths if scenarios else None)
    doc = {
        "format": FORMAT,
        "provenance": provenance(argv, loaded),
        **_proof_sections(proofs),
        "findings": _findings(sdir, loaded, plans, figures),
        "selftest": load_selftest(),
        "scenarios": [_scenario_entry(s, plans, figures) for s in loaded],
        "compare": _compare(compare_n, compare_seed, figures),
    }
    _relate(doc["findings"], proofs)
    doc["triples"] = _triples(plans)
    doc["verdict"] = _verdict(doc)
    return AuditResult(doc=doc, figures=figures)


def render_html(result: AuditResult) -> str:
    """The self-contained HTML page (CSS inline, pictures as data URIs, no external URL)."""
    env = jinja2.Environment(autoescape=jinja2.select_autoescape(["html"], default=True),
                             undefined=jinja2.StrictUndefined, trim_blocks=True,
                             lstrip_blocks=True, keep_trailing_newline=True)
    env.filters.update(num=_num, pct=_pct, mm=_mm, secs=_secs, anchor=_anchor)
    text = resources.files("cfmpa.report").joinpath("template.html").read_text(encoding="utf-8")
    return env.from_string(text).render(doc=result.doc, figures=result.figures,
                                        columns=result.doc["obligations"]["summary"]["columns"])


def _proof_sections(proofs: ProofData) -> dict[str, Any]:
    """The report's "obligations" and "assumptions" parts."""
    return {
        "obligations": {
            "available": proofs.available, "source": proofs.source, "note": proofs.note,
            "summary": summary_table(proofs.rows),
            "items": [r.as_json() for r in proofs.rows],
            "missing_ids": list(proofs.missing_ids), "unexpected_ids": list(proofs.unexpected_ids),
            "all_as_expected": (all(r.as_expected for r in proofs.rows) and not proofs.missing_ids
                                and not proofs.unexpected_ids) if proofs.available else None,
            "run": proofs.run, "not_run": list(proofs.not_run),
        },
        "assumptions": {"available": proofs.ledger_available,
                        "source": proofs.source if proofs.ledger_available else
                        "not available in this run", "entries": list(proofs.ledger)},
    }


def _relate(findings: list[dict[str, Any]], proofs: ProofData) -> None:
    """Give each finding the obligations that state it (by id prefix), with their verdicts."""
    for f in findings:
        f["related_obligations"] = [{"id": r.id, "verdict": r.verdict} for r in proofs.rows
                                    if any(r.id.startswith(pre) for pre in f["related"])]


# --- plans ----------------------------------------------------------------------------------------

class _Plans:
    """Plans by (scenario file, variant), each computed once; a contract violation is kept."""

    def __init__(self, contracts: str) -> None:
        self.contracts = contracts
        self._done: dict[tuple[str, str, Variant], Any] = {}

    def get(self, s: Scenario, v: Variant) -> Any:
        """The PlanResult, or the CfmpaError that stopped it."""
        from ..runs import plan
        key = (s.source, s.sha256, v)
        if key not in self._done:
            try:
                # stop=False: every failed postcondition is recorded, not only the first.
                self._done[key] = plan(s, v, contracts=self.contracts, seed=0, stop=False)
            except CfmpaError as exc:
                self._done[key] = exc
        return self._done[key]

    def all(self) -> list[Any]:
        """Every completed plan so far, in the order computed."""
        return [p for p in self._done.values() if not isinstance(p, Exception)]

    def require(self, s: Scenario, v: Variant) -> Any:
        p = self.get(s, v)
        if isinstance(p, Exception):
            raise p
        return p


# --- findings ----------------------------------------------------------------------------------

_FINDING_FNS: dict[str, tuple[Callable[..., Finding], bool, Callable[..., F.Figure]]] = {
    "inconsistency": (inconsistency_finding, True, F.inconsistency_figure),
    "prop8_literal": (prop8_finding, True, F.prop8_figure),
    "is_path_flaw": (early_arrival_finding, True, F.early_arrival_figure),
    "naive_hull": (naive_hull_finding, False, F.naive_hull_figure),
}


def _findings(sdir: Path, loaded: Sequence[Scenario], plans: _Plans,
              figures: dict[str, F.Figure]) -> list[dict[str, Any]]:
    by_path = {Path(s.source).resolve(): s for s in loaded}
    out = []
    for fid, (fn, needs_plans, draw) in _FINDING_FNS.items():
        path = sdir / f"{FINDING_SCENARIOS[fid]}.toml"
        try:
            s = by_path.get(path.resolve()) or load_scenario(path)
            f = fn(s, plans.require) if needs_plans else fn(s)
        except CfmpaError as exc:
            out.append({"id": fid, "available": False, "title": fid, "text": "",
                        "note": f"not available in this run: {exc}", "related": [],
                        "reproduced": None, "data": {}, "figure": None})
            continue
        fig = draw(f"fig-finding-{fid}", f.drawing)
        figures[fig.id] = fig
        out.append({"id": f.id, "available": True, "title": f.title, "text": f.text, "note": "",
                    "related": list(f.related), "reproduced": f.reproduced,
                    "data": jsonable(f.data), "scenario": s.name,
                    "figure": {"id": fig.id, "caption": fig.caption}})
    return out


# --- per scenario --------------------------------------------------------------------------------

def _scenario_entry(s: Scenario, plans: _Plans, figures: dict[str, F.Figure]) -> dict[str, Any]:
    from ..runs import plan_json

    results = {v: plans.get(s, v) for v in Variant}
    ok = {v: p for v, p in results.items() if not isinstance(p, Exception)}
    variants = []
    for v, p in results.items():
        if isinstance(p, Exception):
            variants.append({"variant": v.value, "status": "contract_violation",
                             "reason": str(p), "J1": None, "J2": None, "path_length": 0,
                             "path": [], "free_fraction": None, "clearance": None,
                             "contracts": {"violations": [str(p)]}, "timings_s": {},
                             **{k: None for k in _OPTIONAL_PLAN_KEYS}})
            continue
        j = plan_json(p)
        entry_v = {k: j[k] for k in ("variant", "status", "reason", "J1", "J2", "path_length",
                                     "path", "free_fraction", "clearance", "contracts",
                                     "timings_s")}
        # Keys plan.json may carry (added, never renamed): null when this version has none, so
        # report.json keeps one key set.
        entry_v.update({k: j.get(k) for k in _OPTIONAL_PLAN_KEYS})
        variants.append(entry_v)
    checks = contract_rows({v.value: p.contracts for v, p in ok.items()})
    any_plan = next(iter(ok.values()), None)
    grid = any_plan.grid.as_json() if any_plan is not None else None
    entry: dict[str, Any] = {
        "name": s.name, "path": s.source, "sha256": s.sha256, "purpose": s.purpose,
        "parameters": {"dt": s.dt, "left": _arm_json(s.left), "right": _arm_json(s.right)},
        "grid": None if grid is None else {
            **grid, "cells": (grid["N"] + 1) * grid["m"] * grid["n"]},
        "variants": variants, "contract_checks": checks, "figures": [],
    }
    if any_plan is None:
        return entry
    entry["figures"] = _scenario_figures(s, ok, figures)
    return entry


def contract_rows(records: Mapping[str, Mapping[str, Any] | None]) -> list[dict[str, Any]]:
    """The per-condition contract table: one row per (command, part, condition), one cell per
    variant; ``records`` maps a variant to its plan's ``contracts`` record (or None).

    A condition checked by several records (BuiltDR's post.cells: the random sample, then the
    path's cells) is one cell whose counts add up and whose ``ok`` is False if any record failed,
    None if none was checked, else True; ``records`` keeps each record and ``state`` says what
    the report shows: held, FAILED, not checked, n/a (nothing to check) or delegated.
    """
    rows: dict[tuple[str, str, str], dict[str, Any]] = {}
    for variant, rec in records.items():
        for tr in (rec or {}).get("triples", []):
            command = str(tr["title"]).split(",")[0].split(" over")[0]   # BuiltDR | searchoptpath
            for c in tr["checks"]:
                row = rows.setdefault((command, c["part"], c["condition"]), {
                    "command": command, "part": c["part"], "condition": c["condition"],
                    "scope": None, "variants": {}})
                cell = row["variants"].setdefault(variant, {"triple": tr["name"], "records": []})
                cell["records"].append({"count": int(c["count"]), "ok": c["ok"],
                                        "scope": str(c["scope"])})
    out = []
    for row in rows.values():
        for cell in row["variants"].values():
            cell.update(_aggregate(cell["records"]))
        first = next(iter(row["variants"].values()))
        row["scope"] = first["scope"]
        # Key order as report.json prints it: the row's fields, then its cells.
        out.append({k: row[k] for k in ("command", "part", "condition", "scope", "variants")})
    return out


def _aggregate(recs: Sequence[Mapping[str, Any]]) -> dict[str, Any]:
    oks = [r["ok"] for r in recs]
    count = sum(r["count"] for r in recs)
    ok = False if False in oks else (None if all(o is None for o in oks) else True)
    if ok is False:
        state = "failed"
    elif ok is None:
        state = "not checked"
    elif count == 0:
        # Nothing examined here: either another check stands for it (pre.dr.spec is BuiltDR's
        # post.cells) or there was nothing to examine (no path): never a green "0 held".
        checked = [r for r in recs if r["ok"] is not None]
        state = "delegated" if all("post.cells" in r["scope"] for r in checked) else "n/a"
    else:
        state = "held"
    return {"count": count, "ok": ok, "state": state,
            "scope": "; ".join(r["scope"] for r in recs)}


def _triples(plans: _Plans) -> list[dict[str, str]]:
    """The distinct Hoare triples the plans' contracts checked, with their printed statements."""
    seen: dict[str, dict[str, str]] = {}
    for p in plans.all():
        for tr in (p.contracts or {}).get("triples", []):
            seen.setdefault(tr["name"], {k: str(tr.get(k, "")) for k in
                                         ("name", "title", "reference", "statement")})
    return [seen[k] for k in sorted(seen)]


def _primary(ok: dict[Variant, Any]) -> Variant:
    """The plan drawn in the workcell and C-space pictures: modified (the paper's), if found."""
    for v in (Variant.MODIFIED, Variant.TIGHT, Variant.ORIGINAL):
        if v in ok and ok[v].search.status is SearchStatus.FOUND:
            return v
    return Variant.MODIFIED if Variant.MODIFIED in ok else next(iter(ok))


def _scenario_figures(s: Scenario, ok: dict[Variant, Any], figures: dict[str, F.Figure]
                      ) -> list[dict[str, str]]:
    slug = _anchor(s.name)
    v0 = _primary(ok)
    p0 = ok[v0]
    g = p0.grid
    cert = p0.certificate
    made = [
        F.workcell_figure(f"fig-{slug}-workcell", s, g, p0.search.path, v0,
                          cert.t_min_s if cert else None, cert.min_clearance_m if cert else None),
        F.cspace_figure(f"fig-{slug}-cspace", s, g, p0.dr, p0.search.path, v0),
    ]
    layer = g.N // 2
    made.append(F.variants_figure(
        f"fig-{slug}-variants", s, g, {v: p.dr for v, p in ok.items()},
        {v: left_regions(s, v, g).links[layer] for v in ok}, layer))
    series, minima, same, bounds = {}, {}, {}, {}
    for v, p in ok.items():
        if p.search.status is not SearchStatus.FOUND:
            continue
        for u in series:                       # identical paths are drawn once, and said so
            if ok[u].search.path == p.search.path:
                same[v] = u
                break
        series[v] = sample_clearance(s, g, p.search.path)
        if p.certificate is not None:
            minima[v] = (p.certificate.t_min_s, p.certificate.min_clearance_m)
            # The proved figure is a bound only when every interval was proved clear.
            if p.certificate.clear:
                bounds[v] = p.certificate.lower_bound_m
    if series:
        missing = [v for v in ok if v not in series]
        made.append(F.clearance_figure(f"fig-{slug}-clearance", s, g, series, minima, missing,
                                       same, bounds))
    for f in made:
        figures[f.id] = f
    return [{"id": f.id, "caption": f.caption} for f in made]


def _arm_json(arm: Any) -> dict[str, Any]:
    return jsonable(dataclasses.asdict(arm))


# --- campaign -----------------------------------------------------------------------------------

def _compare(n: int, seed: int, figures: dict[str, F.Figure]) -> dict[str, Any]:
    if n == 0:
        return {"available": False, "note": "not run for this report (compare_n = 0)"}
    doc = campaign_json(run_campaign(n, seed))
    fig = F.compare_figure("fig-compare", doc)
    rate = F.campaign_rate_figure("fig-compare-rate", doc)
    figures[fig.id], figures[rate.id] = fig, rate
    return {"available": True, "note": "", "text": format_campaign(doc),
            "figure": {"id": fig.id, "caption": fig.caption},
            "rate_figure": {"id": rate.id, "caption": rate.caption}, **doc}


# --- the report's own verdict -------------------------------------------------------------------

def _verdict(doc: dict[str, Any]) -> dict[str, Any]:
    """What the report checks, each ok True / False / None (not available), and the conjunction."""
    ob = doc["obligations"]
    items = []
    if ob["available"]:
        bad = [r["id"] for r in ob["items"] if not r["as_expected"]]
        gaps = ob["missing_ids"] + ob["unexpected_ids"]
        items.append(_item("obligations as expected", not bad and not gaps,
                           f"{len(ob['items']) - len(bad)} of {len(ob['items'])}"
                           + (f"; not as expected: {', '.join(bad)}" if bad else "")
                           + (f"; missing ids: {', '.join(ob['missing_ids'])}"
                              if ob["missing_ids"] else "")
                           + (f"; unexpected ids: {', '.join(ob['unexpected_ids'])}"
                              if ob["unexpected_ids"] else "")))
    else:
        items.append(_item("obligations as expected", None, ob["source"]))
    items.append(_proofs_of_this_tree(ob, doc["provenance"]))
    fnd = [f for f in doc["findings"] if f["available"]]
    missing = [f["id"] for f in doc["findings"] if not f["available"]]
    not_rep = [f["id"] for f in fnd if not f["reproduced"]]
    items.append(_item("findings reproduced on data", (not not_rep) if fnd else None,
                       f"{len(fnd) - len(not_rep)} of {len(doc['findings'])}"
                       + (f"; not reproduced: {', '.join(not_rep)}" if not_rep else "")
                       + (f"; not available: {', '.join(missing)}" if missing else "")))
    plans = [(s["name"], v) for s in doc["scenarios"] for v in s["variants"]]
    found = [(n, v) for n, v in plans if v["status"] == "found"]
    unclear = [f"{n}/{v['variant']}" for n, v in found
               if not (v["clearance"] and v["clearance"]["clear"])]
    items.append(_item("found paths certified clear", not unclear if found else None,
                       f"{len(found) - len(unclear)} of {len(found)} found paths"
                       + (f"; not clear: {', '.join(unclear)}" if unclear else "")))
    # Off mode still writes a record (checked = 0); only records that checked something count.
    recorded = [(n, v) for n, v in plans if v["contracts"] and v["contracts"].get("checked", 0) > 0]
    violated = [f"{n}/{v['variant']}" for n, v in recorded if v["contracts"].get("violations")]
    items.append(_item("contracts hold", (not violated) if recorded else None,
                       f"{len(recorded)} of {len(plans)} plans recorded contracts"
                       + (f"; violated: {', '.join(violated)}" if violated else "")))
    st = doc["selftest"]
    if st["available"]:
        missed = [r["fault"] for r in st["rows"] if r.get("caught_full") is False]
        items.append(_item("self-check faults caught (full mode)", not missed,
                           f"{len(st['rows']) - len(missed)} of {len(st['rows'])}"
                           + (f"; missed: {', '.join(map(str, missed))}" if missed else "")))
    else:
        items.append(_item("self-check faults caught (full mode)", None, st["source"]))
    cmp_ = doc["compare"]
    if cmp_["available"]:
        bad = {k: v for k, v in cmp_["checks"].items() if v}
        raised = len(cmp_["errors"])
        items.append(_item("campaign checks", not bad and not raised, f"{cmp_['n']} workcells"
                           + (f"; failed: {bad}" if bad else "; all counts 0")
                           + (f"; {raised} workcell(s) raised" if raised else "")))
    else:
        items.append(_item("campaign checks", None, cmp_["note"]))
    return {"ok": all(i["ok"] is not False for i in items), "items": items}


def _proofs_of_this_tree(ob: dict[str, Any], prov: dict[str, Any]) -> dict[str, Any]:
    """Whether the obligation results are of the tree and scenario files this report describes:
    a results.json from another commit, other scenario bytes, or carried-over rows fail it."""
    check = "proof results are of this tree"
    if not ob["available"]:
        return _item(check, None, ob["source"])
    if ob["run"] is None:
        if ob["source"].startswith("read from"):
            return _item(check, None, "results.json records no run (commit, scenario hashes)")
        return _item(check, True, "discharged afresh for this report")
    run, problems = ob["run"], []
    mine, theirs = prov["git"].get("commit"), (run.get("git") or {}).get("commit")
    if mine != theirs:
        problems.append(f"proved at commit {theirs}, report at {mine}")
    hashes = run.get("scenarios") or {}
    shown = {".".join(i["id"].split(".")[1:-1]) for i in ob["items"]
             if i["id"].startswith("Scenario.")}
    for s in prov["scenarios"]:
        name = Path(s["path"]).name
        if name in hashes and hashes[name] != s["sha256"]:
            problems.append(f"{name} changed since the prove run")
        elif name not in hashes and Path(name).stem in shown:
            problems.append(f"results.json records no hash for {name}, whose checks are shown")
    if ob["not_run"]:
        problems.append(f"{len(ob['not_run'])} results carried over from an earlier run "
                        f"(e.g. {ob['not_run'][0]})")
    return _item(check, not problems, "; ".join(problems) or
                 f"commit {theirs}, proved {run.get('date_utc')}, scenario hashes match")


def _item(check: str, ok: bool | None, detail: str) -> dict[str, Any]:
    return {"check": check, "ok": ok, "detail": detail}


# --- helpers ------------------------------------------------------------------------------

def _scenario_paths(scenarios: Sequence[str] | None, sdir: Path) -> list[Path]:
    if scenarios:
        return [Path(p) for p in scenarios]
    found = sorted(sdir.glob("*.toml"))
    if not found:
        raise InputError("scenarios", str(sdir), "holds no *.toml scenario files")
    cwd = Path.cwd().resolve()
    # Relative to the working folder when inside it: the report reads the same on any checkout.
    return [p.resolve().relative_to(cwd) if p.resolve().is_relative_to(cwd) else p for p in found]


def _num(x: Any, digits: int = 3) -> str:
    if x is None:
        return "–"
    if isinstance(x, bool):
        return "yes" if x else "no"
    if isinstance(x, int):
        return str(x)
    return f"{x:.{digits}g}"


def _pct(x: Any, digits: int = 2) -> str:
    return "–" if x is None else f"{100 * x:.{digits}f} %"


def _mm(x: Any, digits: int = 2) -> str:
    return "–" if x is None else f"{1000 * x:.{digits}f} mm"


def _secs(x: Any) -> str:
    return "–" if x is None else f"{x:.3f} s"


def _anchor(name: str) -> str:
    return "".join(c if c.isalnum() else "-" for c in str(name)).strip("-").lower() or "x"

