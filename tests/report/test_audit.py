"""The audit report: schema, content and order, no external URL, provenance, golden text, browser.

One report is built per module (a coarse copy of the default workcell: 13 layers of 52 x 52
cells, where original's start is blocked and modified/tight find a path; the four findings on the
bundled scenarios, a real `run_prove` over a subset of the obligations, a 4-workcell campaign).

Golden files live in tests/report/golden/. After an intended change of the findings' text or of
report.json's keys, regenerate them with

    CFMPA_REGEN_GOLDEN=1 .venv/bin/python -m pytest tests/report

and review the diff before committing.
"""

from __future__ import annotations

import base64
import copy
import dataclasses
import hashlib
import html as html_lib
import io
import json
import os
import re
import shutil
import struct
import subprocess
import urllib.parse
import zlib
from pathlib import Path
from xml.etree import ElementTree

import jsonschema
import pytest
from markupsafe import escape

import factory
from cfmpa.errors import InputError
from cfmpa.files import dumps_json
from cfmpa.gitstate import MAX_PATHS, git_state
from cfmpa.proofs import expected_ids, obligation_summary, run_prove
from cfmpa.proofs._runner import selected
from cfmpa.report import build_audit, run_audit
from cfmpa.report._audit import (
    SECTIONS,
    AuditResult,
    _controls_item,
    _proof_sections,
    _verdict,
    contract_rows,
    render_html,
    row_requirements,
    workcell_summary,
    write_report,
)
from cfmpa.report._figures import workcell_instants
from cfmpa.report._obligations import BADGES, audited_ids, load_proofs
from cfmpa.report._provenance import REPORTED_DISTRIBUTIONS, VERSION_GROUPS
from cfmpa.report._sections import Section, compute_order, verdict_of

ROOT = Path(__file__).resolve().parents[2]
GOLDEN = Path(__file__).parent / "golden"
SCHEMA = ROOT / "report" / "schema.json"
CHROMIUM = Path("/usr/bin/chromium")
#: A subset of obligations that discharges in a few seconds, across several groups and verdicts,
#: and the negative controls of three checkers (a second in all).
OBLIGATIONS = ["Def1", "Lemma1", "Prop8", "Def4", "Margin.naive_hull", "Scenario.early-arrival",
               "Control.witness", "Control.dr", "Control.path"]
#: The ids that subset must produce, picked the way `cfmpa prove --only` picks them.
EXPECTED = [i for i in expected_ids(ROOT / "scenarios") if selected(i, OBLIGATIONS)]


@pytest.fixture(scope="module")
def tiny_file(tmp_path_factory):
    return factory.tiny_default(tmp_path_factory.mktemp("scen"))


@pytest.fixture(scope="module")
def results_json(tmp_path_factory):
    out = tmp_path_factory.mktemp("proofs")
    stream = io.StringIO()
    code = run_prove(out_dir=out, scenarios_dir=ROOT / "scenarios", only=OBLIGATIONS,
                     stream=stream)
    assert code == 0, "\n".join(line for line in stream.getvalue().splitlines()
                                 if not line.startswith((" ", "A")))
    return out / "results.json"


@pytest.fixture(scope="module")
def report(tiny_file, results_json, tmp_path_factory):
    import cfmpa.report._figures as figures

    out = tmp_path_factory.mktemp("audit")
    argv = ["cfmpa", "audit", str(tiny_file), "--out", str(out)]
    progress = io.StringIO()
    layout: dict[str, list[str]] = {}   # figure id -> its legends over axis or tick labels
    save = figures._save

    def saved(fig, fid, caption, alt):
        layout[fid] = figures.legend_overlaps(fig)
        return save(fig, fid, caption, alt)
    with pytest.MonkeyPatch.context() as mp:
        mp.setattr(figures, "_save", saved)
        result = build_audit([str(tiny_file)], argv=argv, proofs_json=str(results_json),
                             compare_n=4, compare_seed=3, expected_ids=EXPECTED,
                             progress=progress)
    write_report(result, out)
    doc = json.loads((out / "report.json").read_text())
    html = (out / "report.html").read_text()
    return {"result": result, "out": out, "doc": doc, "html": html, "argv": argv,
            "progress": progress.getvalue(), "layout": layout}


def test_no_legend_covers_an_axis_label(report):
    # Every picture of the report, the workcell figure (whose legend covered "x (m)") included.
    layout = report["layout"]
    assert set(layout) == set(report["result"].figures)
    assert any(fid.endswith("-workcell") for fid in layout)
    assert {fid: bad for fid, bad in layout.items() if bad} == {}


def test_a_six_panel_workcell_figure_keeps_its_legend_off_the_labels(tiny_file, monkeypatch):
    # Six instants fill the 2 x 3 panels, so the legend goes under them (the default workcell's
    # case, where it covered the bottom row's "x (m)"); the fixture's tiny plan has five.
    import cfmpa.report._figures as figures
    from cfmpa.spec import Variant, load_scenario, make_grid

    s = load_scenario(tiny_file)
    g = make_grid(s)
    path = [s.right.start_cell] * (g.N + 8)           # still after Tf: t_end past the principal
    t_end = (len(path) - 1) * s.dt
    t_min = (g.Tf + t_end) / 2
    assert len(workcell_instants(g.Tf, t_end, s.dt, t_min)) == 6
    seen = {}
    monkeypatch.setattr(figures, "_save", lambda fig, fid, *a: seen.setdefault(
        fid, figures.legend_overlaps(fig)))
    figures.workcell_figure("w", s, g, path, Variant.MODIFIED, t_min, 0.01)
    assert seen == {"w": []}


def test_the_layout_check_sees_a_legend_over_an_axis_label():
    import matplotlib.pyplot as plt

    from cfmpa.report._figures import legend_overlaps

    fig, ax = plt.subplots(figsize=(4, 3))
    ax.plot([0, 1], [0, 1], label="a line with a long legend entry")
    ax.set_xlabel("x (m)")
    ax.set_ylabel("y (m)")
    fig.tight_layout()
    assert legend_overlaps(fig) == []
    # The seeded fault: a figure legend at the figure's foot, where the x label is.
    fig.legend(loc="lower center", frameon=False)
    bad = legend_overlaps(fig)
    plt.close(fig)
    assert any("x label 'x (m)'" in b for b in bad), bad


def test_the_audit_prints_a_line_per_stage_with_its_time(report):
    lines = report["progress"].splitlines()
    assert lines and all(re.fullmatch(r"audit: .+ +\d+\.\d s", line) for line in lines), lines
    labels = [re.sub(r" +\d+\.\d s$", "", line).removeprefix("audit: ").rstrip()
              for line in lines]
    name = report["doc"]["scenarios"][0]["name"]
    for stage in [*(f"plan {name}, {v}" for v in ("original", "modified", "tight")),
                  f"figures and tube of {name}", "findings (their plans listed above)",
                  "mutation self-check", "monitored run", "campaign (4 workcells)",
                  "proofs (read from the prove run)"]:
        assert labels.count(stage) == 1, (stage, labels)
    # A plan's line comes before the stage that asked for it; the proofs are read last.
    assert labels.index(f"plan {name}, modified") < labels.index(f"figures and tube of {name}")
    assert labels[-1] == "proofs (read from the prove run)"


def test_run_audit_adds_the_writing_and_the_total(report, tmp_path, monkeypatch, capsys):
    import cfmpa.report._audit as audit

    def built(*args, progress, **kw):
        with progress.stage("plan x, modified"):
            pass
        return report["result"]
    monkeypatch.setattr(audit, "build_audit", built)
    stream = io.StringIO()
    assert run_audit(None, str(tmp_path / "a"), progress=stream) == 0
    labels = [line.split("  ")[0] for line in stream.getvalue().splitlines()]
    assert labels == ["audit: plan x, modified", "audit: write report.html and report.json",
                      "audit: audit, in all"]
    # The progress goes to the stream given, never to stdout (which has the summary).
    assert "audit: " not in capsys.readouterr().out


def _cheap_context(monkeypatch, stream):
    """An audit context whose fresh prove run is two cheap obligations (and no controls)."""
    import cfmpa.proofs as proofs
    import cfmpa.report._audit as audit

    cheap = proofs.collect_obligations("/nonexistent", ["Def1.segment", "Margin.naive_hull"])
    monkeypatch.setattr(proofs, "collect_obligations", lambda *a, **k: list(cheap))
    return audit._Context(sdir=ROOT / "scenarios", paths=[], loaded=[], given=False,
                          argv=None, compare_n=0, compare_seed=0, recorded=None,
                          campaign=None, proofs_json=None, expected_ids=[o.id for o in cheap],
                          stages=audit._Progress(stream), plans=None)  # type: ignore[arg-type]


@pytest.mark.parametrize("early", [False, True], ids=["here", "forked early"])
def test_proofs_discharged_afresh_tell_each_group_before_the_stage_line(monkeypatch, early):
    import cfmpa.report._audit as audit

    ids = ["Def1.segment", "Margin.naive_hull"]

    def told() -> list[str]:
        stream = io.StringIO()
        ctx = _cheap_context(monkeypatch, stream)
        if early:
            ctx.start_proofs()
            assert ctx.background is not None
        data = ctx.proofs()
        assert [r.id for r in data.rows] == ids and not data.missing_ids
        assert [r.verdict for r in data.rows] == ["proved", "refuted as expected"]
        assert ctx.background is None
        return stream.getvalue().splitlines()
    lines = told()
    assert sorted(ln.split(": ")[1] for ln in lines[:2]) == [
        "Definitions 1-3, Lemmas 1-2", "Swept regions (docs/model.md §4)"]
    assert all(ln.startswith("prove: ") and ": 1 done, " in ln for ln in lines[:2]), lines
    assert len(lines) == 3 and lines[2].startswith("audit: proofs (discharged afresh)")
    # Seeded fault: the stream not handed on to the run: only the stage's own line, at its end.
    monkeypatch.setattr(audit, "load_proofs", lambda *a, progress=None, **k: load_proofs(*a, **k))
    assert len(told()) == 1


def test_proofs_begun_early_give_what_a_run_here_gives_and_raise_its_errors(monkeypatch):
    import cfmpa.report._audit as audit

    def rows(ctx):
        return [dataclasses.replace(r, seconds=0.0) for r in ctx.proofs().rows]
    ctx = _cheap_context(monkeypatch, None)
    ctx.start_proofs()
    early = rows(ctx)
    # A forked run that dies without an answer: the obligations are run here instead, and the
    # data is the same.
    real = audit.load_proofs
    monkeypatch.setattr(audit, "load_proofs", lambda *a, **k: os._exit(3))
    ctx = _cheap_context(monkeypatch, None)
    ctx.start_proofs()
    monkeypatch.setattr(audit, "load_proofs", real)
    assert rows(ctx) == early and len(early) == 2
    # An error there is the error here, as if run here.
    def bad(*a, **k):
        raise InputError("--proofs", "x", "planted")
    monkeypatch.setattr(audit, "load_proofs", bad)
    ctx = _cheap_context(monkeypatch, None)
    ctx.start_proofs()
    with pytest.raises(InputError, match="planted"):
        ctx.proofs()
    # Not taken (another section failed): closing ends the process, nothing left running.
    monkeypatch.setattr(audit, "load_proofs", lambda *a, **k: __import__("time").sleep(60))
    ctx = _cheap_context(monkeypatch, None)
    ctx.start_proofs()
    proc = ctx.background._proc
    ctx.background.close()
    assert not proc.is_alive() and proc.exitcode is not None


def test_report_json_validates_against_the_schema(report):
    schema = json.loads(SCHEMA.read_text())
    jsonschema.Draft202012Validator.check_schema(schema)
    errors = list(jsonschema.Draft202012Validator(schema).iter_errors(report["doc"]))
    assert not errors, [f"{list(e.absolute_path)}: {e.message}" for e in errors[:5]]


def test_schema_rejects_a_report_missing_a_part(report):
    schema = json.loads(SCHEMA.read_text())
    broken = {k: v for k, v in report["doc"].items() if k != "findings"}
    with pytest.raises(jsonschema.ValidationError, match="findings"):
        jsonschema.validate(broken, schema)


def test_report_passes_and_both_files_are_written_atomically(report):
    assert report["doc"]["verdict"]["ok"] is True, report["doc"]["verdict"]
    # Nothing failed, but the fixture's prove run is a subset: the rows rest on more than ran.
    assert report["doc"]["verdict"]["status"] == "incomplete"
    assert report["doc"]["verdict"]["not_available"] == ["verdict rows rest on what ran"]
    assert sorted(p.name for p in report["out"].iterdir()) == ["report.html", "report.json"]
    assert report["doc"] == json.loads(dumps_json(report["result"].doc))


def test_html_names_every_obligation_and_scenario(report):
    doc, html = report["doc"], report["html"]
    ids = [o["id"] for o in json.loads(_results(report)["text"])["obligations"]]
    assert ids and [o["id"] for o in doc["obligations"]["items"]] == ids
    for i in ids:
        assert f'<span class="id">{i}</span>' in html, i
    for s in doc["scenarios"]:
        assert f'id="scenario-{s["name"]}"' in html and s["name"] in html
    for f in doc["findings"]:
        assert f["available"] and f"finding-{f['id'].replace('_', '-')}" in html


def test_html_has_no_external_url(report):
    html = report["html"]
    assert "http://" not in html and "https://" not in html
    refs = re.findall(r'(?:src|href)\s*=\s*"([^"]*)"', html)
    assert refs, "the page has pictures and links"
    for ref in refs:
        assert ref.startswith(("data:image/png;base64,", "#")), ref[:60]
    assert "<script" not in html and "<link" not in html and "@import" not in html
    assert "url(" not in html


def test_sections_come_in_the_order_of_the_model(report):
    html = report["html"]
    marks = ['id="workcells"', 'id="provenance"', 'id="summary"', 'id="obligations"', 'id="assumptions"',
             'id="findings"', 'id="selftest"', 'id="scenarios"', 'id="compare"']
    where = [html.index(m) for m in marks]
    assert where == sorted(where)


def test_provenance_records_the_run(report, tiny_file):
    p = report["doc"]["provenance"]
    assert p["command_line"] == " ".join(report["argv"])
    assert p["scenarios"] == [{"name": "tiny-default", "path": str(tiny_file),
                               "sha256": hashlib.sha256(tiny_file.read_bytes()).hexdigest()}]
    git = shutil.which("git")
    if git and (ROOT / ".git").exists():
        # The shared tree may move while tests run: check the commit exists, not that it is HEAD.
        kind = subprocess.run([git, "-C", str(ROOT), "cat-file", "-t", p["git"]["commit"]],
                              capture_output=True, text=True, check=False).stdout.strip()
        assert kind == "commit"
        assert p["git"]["clean"] is (p["git"]["modified"] + p["git"]["untracked"] == 0)
    for lib in ("python", "numpy", "z3", "cvc5", "shapely", "python-flint", "numba",
                *REPORTED_DISTRIBUTIONS):
        assert p["versions"][lib] and p["versions"][lib] != "not installed", lib
        assert f"{lib} {p['versions'][lib]}" in report["html"], lib
    # Every version is shown in one group: the solvers and the numerics libraries by name.
    grouped = [k for _, keys in VERSION_GROUPS for k in keys]
    assert sorted(grouped) == sorted(p["versions"]), "each version in exactly one group"
    rows = dict(re.findall(r"<tr><th>versions: (\w+)</th><td>([^<]*)</td></tr>", report["html"]))
    assert rows["solvers"] == "; ".join(f"{k} {p['versions'][k]}" for k in ("z3", "cvc5", "sympy"))
    for k in ("numpy", "shapely", "python-flint", "numba"):
        assert f"{k} {p['versions'][k]}" in rows["numerics"], k
    assert "other" not in rows
    for entry in p["git"]["paths"]:
        assert str(escape(entry["path"])) in report["html"]


@pytest.mark.skipif(shutil.which("git") is None, reason="git is not installed")
def test_git_state_tells_clean_from_modified_and_untracked(tmp_path):
    def git(*args):
        subprocess.run(["git", "-C", str(tmp_path), *args], check=True, capture_output=True)
    assert git_state(tmp_path)["available"] is False
    git("init", "-q")
    (tmp_path / "a.txt").write_text("a\n")
    git("add", "a.txt")
    git("-c", "user.name=t", "-c", "user.email=t@t", "commit", "-q", "-m", "a")
    state = git_state(tmp_path)
    assert state["available"] and state["clean"] is True and len(state["commit"]) == 40
    assert state["paths"] == [] and state["paths_omitted"] == 0
    (tmp_path / "b.txt").write_text("b\n")
    after = git_state(tmp_path)
    assert after | {"note": ""} == state | {"clean": False, "untracked": 1, "note": "",
                                            "paths": [{"status": "??", "path": "b.txt"}]}
    (tmp_path / "a.txt").write_text("changed\n")
    now = git_state(tmp_path)
    assert (now["modified"], now["clean"]) == (1, False)
    assert now["paths"] == [{"status": "M", "path": "a.txt"}, {"status": "??", "path": "b.txt"}]
    for k in range(MAX_PATHS + 3):
        (tmp_path / f"u{k:02d}.txt").write_text("u\n")
    many = git_state(tmp_path)
    assert len(many["paths"]) == MAX_PATHS and many["paths_omitted"] == 5
    assert many["untracked"] == MAX_PATHS + 4 and "the first 20 listed" in many["note"]


def test_summary_counts_match_the_obligations(report):
    ob = report["doc"]["obligations"]
    items, total = ob["items"], ob["summary"]["total"]
    assert total["total"] == len(items) == sum(r["total"] for r in ob["summary"]["rows"])
    assert total["refuted_as_expected"] == sum(i["verdict"] == "refuted as expected" for i in items)
    assert total["proved_z3"] == sum(i["verdict"] == "proved" and i["method"] == "z3"
                                     for i in items)
    assert total["checked_data"] == sum(i["verdict"] == "proved" and i["method"] == "data"
                                        for i in items)
    # Every refuted-as-expected obligation prints its counterexample.
    for i in items:
        if i["verdict"] == "refuted as expected":
            first = i["counterexample"].splitlines()[0]
            assert str(escape(first)) in report["html"], first


def test_scenario_section_reports_each_variant(report):
    (s,) = report["doc"]["scenarios"]
    assert [v["variant"] for v in s["variants"]] == ["original", "modified", "tight"]
    html = report["html"]
    table = html[html.index("<h4>Results per variant</h4>"):]
    table = table[:table.index("</table>")]
    heads = re.findall(r"<th[^>]*>([^<]*)</th>", table)
    # The proved bound before the sampled minimum; no two columns under one heading.
    assert heads.index("proved clearance (certificate's lower bound)") < heads.index(
        "sampled minimum (upper bound)")
    assert "certificate verdict" in heads and "certificate time (s)" in heads
    assert len(heads) == len(set(heads)), heads
    for v in s["variants"]:
        if v["status"] == "found":
            assert v["J1"] is not None and v["clearance"]["clear"] is True
            row = table[table.index(f"<tr><td>{v['variant']}</td>"):]
            row = row[:row.index("</tr>")]
            bound = f'≥ {1000 * v["clearance"]["lower_bound_m"]:.2f} mm'
            sampled = f'{1000 * v["clearance"]["min_m"]:.2f} mm'
            assert bound in row and sampled in row
            assert row.index(bound) < row.rindex(sampled)
    assert {f["id"].rsplit("-", 1)[1] for f in s["figures"]} == {"workcell", "cspace", "variants",
                                                                "clearance"}


def test_section_one_gives_the_verdict_per_workcell_first(report, tiny_file, complete_proofs):
    doc, html = report["doc"], report["html"]
    (s,) = doc["scenarios"]
    rows = doc["summary"]
    assert [(r["scenario"], r["variant"]) for r in rows] == [
        (s["name"], v["variant"]) for v in s["variants"]]
    ledger = {e["id"] for e in doc["assumptions"]["entries"]}
    # The fixture's prove run is a subset: no found plan's row is "safe" on it (see the partial
    # runs' tests below); with every obligation and control it rests on, each is.
    whole = workcell_summary([_scenario_of(report)],
                             complete_proofs(report["result"].doc, [tiny_file.stem]))
    for r, v, w in zip(rows, s["variants"], whole):
        assert r["status"] == v["status"]
        if v["status"] == "found":
            cl, tol = v["clearance"], v["tolerance_rad"]
            assert r["ok"] is None and r["verdict"] == "incomplete", r
            assert f"Safety.{v['variant']}.composition" in r["missing"]
            assert w["ok"] is True and w["verdict"] == "safe" and w["missing"] == [], w
            rest = ("ok", "verdict", "missing", "why", "assumptions")
            assert {k: x for k, x in w.items() if k not in rest} == {
                k: x for k, x in r.items() if k not in rest}
            # The translation check of the workcell and variant ran: A5 is not assumed.
            assert set(r["assumptions"]) - set(w["assumptions"]) == {"A5.while_model"}
            assert r["lower_bound_mm"] == pytest.approx(1000 * cl["lower_bound_m"], rel=1e-12)
            assert r["min_mm"] == pytest.approx(1000 * cl["min_m"], rel=1e-12)
            # The proved bound is below the sampled minimum (a bound, and an upper bound on it).
            assert 0 < r["lower_bound_mm"] <= r["min_mm"]
            assert (r["tolerance_rad"], r["tolerance_deg"]) == (tol, pytest.approx(
                tol * 180 / 3.141592653589793, rel=1e-12))
            lip = s["tube"]["lipschitz_m_per_rad"]
            assert r["tolerance_farthest_point_mm"] == pytest.approx(1000 * lip * tol, rel=1e-12)
            # The former name, kept for format version 1: the same number.
            assert r["tolerance_tip_mm"] == r["tolerance_farthest_point_mm"]
            # Each arm may stray by L delta, and 2 L delta stays below the proved clearance.
            assert 2 * r["tolerance_farthest_point_mm"] < r["lower_bound_mm"]
            assert {"A1.rectangles", "A11.safety_scope"} <= set(r["assumptions"])
            # The subset of obligations proved for the fixture has no translation check of it.
            assert "A5.while_model" in r["assumptions"]
            assert f"{r['lower_bound_mm']:.2f} mm" in html and f"{r['min_mm']:.2f} mm" in html
        else:
            assert r["ok"] is None and r["lower_bound_mm"] is None and r["tolerance_rad"] is None
            assert r["verdict"] == w["verdict"] == "no plan" and r["missing"] == []
        assert r["assumptions"] and set(r["assumptions"]) <= ledger
        for a in r["assumptions"]:
            assert f'href="#assumption-{a.replace(".", "-").replace("_", "-").lower()}"' in html
            assert f'id="assumption-{a.replace(".", "-").replace("_", "-").lower()}"' in html
    first = html[:html.index('id="provenance"')]
    assert "1. Verdict per workcell" in first and "sampled minimum" in first
    assert "proved clearance" in first and "mm at the farthest point" in first


def test_section_one_fails_a_plan_whose_proof_or_certificate_fails(report):
    doc = copy.deepcopy(report["result"].doc)
    (s,) = doc["scenarios"]
    found = [k for k, v in enumerate(s["variants"]) if v["status"] == "found"]
    assert len(found) >= 2
    # A failed obligation of the workcell's theorem fails that variant's row, not the others'.
    ob = doc["obligations"]
    ob["items"].append({"id": f"Safety.{s['variants'][found[0]]['variant']}.composition",
                        "verdict": "failed", "expected": "proved", "as_expected": False})
    # A plan whose certificate is not clear: its row fails and shows no proved bound.
    s["variants"][found[1]]["clearance"] = dict(s["variants"][found[1]]["clearance"], clear=False)
    loaded = [_scenario_of(report)]
    rows = workcell_summary(loaded, doc)
    assert rows[found[0]]["ok"] is False and "Safety." in rows[found[0]]["why"]
    assert rows[found[1]]["ok"] is False and rows[found[1]]["lower_bound_mm"] is None
    assert "not certified clear" in rows[found[1]]["why"]
    again = workcell_summary(loaded, report["result"].doc)
    assert all(r["ok"] is not False for r in again)


def test_a_partial_proofs_file_leaves_every_row_incomplete_naming_what_is_missing(
        report, tiny_file, tmp_path, complete_proofs):
    # A results.json holding 7 obligations, the workcell's own checks on data: they hold, yet
    # the rows rest on the safety theorem, the tube and the controls too, which did not run.
    out = tmp_path / "proofs"
    assert run_prove(out_dir=out, scenarios_dir=tiny_file.parent, only=[f"Scenario.{tiny_file.stem}"],
                     stream=io.StringIO()) == 0
    results = out / "results.json"
    assert len(json.loads(results.read_text())["obligations"]) == 7
    loaded = [_scenario_of(report)]
    found = [v["variant"] for v in report["doc"]["scenarios"][0]["variants"]
             if v["status"] == "found"]
    assert found

    def audited(expected):
        audit = copy.deepcopy(report["result"].doc)
        audit.update(_proof_sections(load_proofs(str(results), ROOT / "scenarios", expected,
                                                 files=[tiny_file])))
        audit["summary"] = workcell_summary(loaded, audit)
        audit["verdict"] = _verdict(audit)
        return audit
    # As `cfmpa audit TINY --proofs results.json` reads it: every obligation expected.
    audit = audited(None)
    for r in audit["summary"]:
        if r["variant"] not in found:
            assert r["verdict"] == "no plan"
            continue
        assert (r["ok"], r["verdict"]) == (None, "incomplete"), r
        obligations, controls = row_requirements(tiny_file.stem, r["variant"])
        mine = [i for i in obligations if i.startswith(f"Scenario.{tiny_file.stem}.")]
        assert r["missing"] == [i for i in obligations if i not in mine] + list(controls)
        for i in (f"Safety.{r['variant']}.composition", "Safety.region_soundness",
                  "Safety.region_statement", "Tolerance.tube"):
            assert i in r["missing"] and i in r["why"], i
        assert f"{len(mine)} of {len(obligations) + len(controls)} of its obligations" in r["why"]
        assert f"{len(controls)} negative controls not in this run" in r["why"]
        assert not any(i.startswith("Scenario.") for i in r["missing"])
    assert audit["verdict"]["status"] == "FAILED"        # the ids a whole run has are missing
    # Read for exactly those 7 ids: nothing failed, nothing is safe, and the page says so.
    audit = audited([i for i in audited_ids([tiny_file]) if i.startswith("Scenario.")])
    assert audit["verdict"]["ok"] is True and audit["verdict"]["status"] == "incomplete"
    assert "verdict rows rest on what ran" in audit["verdict"]["not_available"]
    assert all(r["verdict"] == "incomplete" for r in audit["summary"] if r["variant"] in found)
    text = render_html(AuditResult(audit, report["result"].figures))
    first = text[:text.index('id="provenance"')]
    assert first.count('<span class="badge incomplete">incomplete</span>') == len(found)
    assert ">safe<" not in first and _pills(text) == ["incomplete", "incomplete"]
    # Under each badge, what did not run: the first obligations by name, the controls counted.
    for r in audit["summary"]:
        if r["variant"] in found:
            mo = [i for i in r["missing"] if not i.startswith("Control.")]
            mc = len(r["missing"]) - len(mo)
            assert (f"not run: {mo[0]}, {mo[1]} and {len(mo) - 2} more; {mc} negative "
                    "controls</span>") in first
            assert str(escape(r["why"])) in first          # the tooltip names every id
    # The seeded fault's repair: with every id present and as expected, the same rows are safe.
    whole = workcell_summary(loaded, complete_proofs(audit, [tiny_file.stem]))
    assert all(r["verdict"] == "safe" for r in whole if r["variant"] in found)
    # One of them not as expected: that row FAILED, naming it.
    bad = complete_proofs(audit, [tiny_file.stem])
    (ctl,) = [c for c in bad["controls"]["items"]
              if c["id"] == f"Control.Safety.{found[0]}.composition.without[0]"]
    ctl.update(outcome="proved", ok=False)
    rows = {r["variant"]: r for r in workcell_summary(loaded, bad)}
    assert rows[found[0]]["verdict"] == "FAILED" and ctl["id"] in rows[found[0]]["why"]
    assert all(rows[v]["verdict"] == "safe" for v in found[1:])


def test_a_row_is_incomplete_when_its_results_were_carried_over_or_of_another_tree(
        report, tiny_file, complete_proofs):
    loaded = [_scenario_of(report)]
    whole = complete_proofs(report["result"].doc, [tiny_file.stem])
    assert all(r["verdict"] in ("safe", "no plan") for r in workcell_summary(loaded, whole))
    carried = copy.deepcopy(whole)
    (item,) = [i for i in carried["obligations"]["items"] if i["id"] == "Tolerance.tube"]
    item["change"] = "not run"
    rows = [r for r in workcell_summary(loaded, carried) if r["status"] == "found"]
    assert rows and all(r["verdict"] == "incomplete" and r["missing"] == ["Tolerance.tube"]
                        for r in rows)
    other = copy.deepcopy(whole)
    other["obligations"]["run"]["git"]["commit"] = "0" * 40
    rows = [r for r in workcell_summary(loaded, other) if r["status"] == "found"]
    assert rows and all(r["verdict"] == "incomplete" and r["missing"] == [] for r in rows)
    assert all("proof results not of this tree (proved at commit " + "0" * 40 in r["why"]
               for r in rows)


def test_a_plan_stopped_by_a_contract_fails_its_row_and_the_report(report):
    # A plan that raised (a violated precondition) records no counts: it must still fail.
    doc = copy.deepcopy(report["result"].doc)
    (s,) = doc["scenarios"]
    assert _verdict(doc)["ok"] is True
    s["variants"][1].update(status="contract_violation", reason="pre.grid.h violated",
                            clearance=None, contracts={"violations": ["pre.grid.h violated"]})
    verdict = _verdict(doc)
    item = next(i for i in verdict["items"] if i["check"] == "contracts hold")
    assert verdict["ok"] is False and item["ok"] is False
    assert f"stopped by a violation: {s['name']}/{s['variants'][1]['variant']}" in item["detail"]
    row = workcell_summary([_scenario_of(report)], doc)[1]
    assert row["ok"] is False and row["verdict"] == "FAILED" and "stopped" in row["why"]


def _scenario_of(report):
    from cfmpa.spec import load_scenario
    return load_scenario(report["doc"]["provenance"]["scenarios"][0]["path"])


def test_obligation_cards_are_plain_grouped_and_collapsed(report):
    doc, html = report["doc"], report["html"]
    ob = doc["obligations"]
    grouped = [i for g in ob["cards"] for i in g["ids"]]
    assert sorted(grouped) == sorted(i["id"] for i in ob["items"]), "each card in one group"
    for item in ob["items"]:
        assert item["summary"] == obligation_summary(item["id"]) and item["summary"]
        assert str(escape(item["summary"])) in html, item["id"]
        card = html[html.index(f'id="ob-{item["id"].replace(".", "-").replace("_", "-").lower()}"'):]
        card = card[:card.index('<div class="obligation"', 10) if '<div class="obligation"' in
                    card[10:] else len(card)]
        # The summary comes first; the full statement is folded in a <details> below it.
        assert card.index(str(escape(item["summary"]))) < card.index("<details")
        assert card.index("<details") < card.index(str(escape(item["statement"][:40])))
    keys = [g["key"] for g in ob["cards"]]
    assert keys == sorted(keys, key=["safety", "tolerance", "workcells", "planner", "geometry",
                                     "findings", "other"].index)
    assert "findings" in keys and all(i["expected"] == "refuted as expected" for i in ob["items"]
                                      if i["id"] in ob["cards"][keys.index("findings")]["ids"])
    # Everything as expected: every group and card collapsed.
    assert '<details class="group" id="cards-' in html and " open>" not in html


#: What a proved obligation's badge must say, by its method: only a solver's proof is "proved".
_PROVED_BY_METHOD = {"z3": "proved", "sympy": "proved", "data": "checked on data",
                     "test": "tested only"}


def _card_heads(html):
    """Each obligation card's head (id -> the HTML before its summary)."""
    out = {}
    for m in re.finditer(r'<div class="obligation" id="ob-[^"]*">\s*<div class="head">(.*?)'
                         r'<p class="summary">', html, re.S):
        out[re.search(r'<span class="id">([^<]*)</span>', m.group(1)).group(1)] = m.group(1)
    return out


def _badge_problems(doc, html):
    """Where a badge does not say what was done: report.json's obligations (by method and
    verdict), the ledger ("assumed"), the findings' related obligations, and each card's head."""
    out = []
    items = doc["obligations"]["items"]
    for i in items:
        want = (_PROVED_BY_METHOD.get(i["method"], "unknown") if i["verdict"] == "proved"
                else i["verdict"])
        if i["badge"] != want:
            out.append(f"{i['id']}: badge {i['badge']!r}, method {i['method']}")
    out += [f"ledger {e['id']}: {e['badge']!r}" for e in doc["assumptions"]["entries"]
            if e["badge"] != "assumed"]
    badge = {i["id"]: i["badge"] for i in items}
    out += [f"finding's {r['id']}: {r['badge']!r}" for f in doc["findings"]
            for r in f["related_obligations"] if r["badge"] != badge[r["id"]]]
    heads = _card_heads(html)
    for i in items:
        shown = re.findall(r'<span class="badge v-[^"]*"[^>]*>([^<]*)</span>', heads[i["id"]])
        if shown != [i["badge"]]:
            out.append(f"{i['id']}'s card shows {shown}, not {i['badge']!r}")
    return out


def test_every_badge_says_what_was_done(report):
    doc, html = report["doc"], report["html"]
    methods = {i["method"] for i in doc["obligations"]["items"]}
    assert {"z3", "data"} <= methods, methods          # solver proofs and checks on data
    assert _badge_problems(doc, html) == []
    data = [i for i in doc["obligations"]["items"] if i["method"] == "data"]
    assert data and all(i["badge"] == "checked on data" for i in data)
    heads = _card_heads(html)
    assert all(">proved<" not in heads[i["id"]] for i in data)
    assert {i["badge"] for i in doc["obligations"]["items"]} <= set(BADGES)
    # The ledger's entries are "assumed" on the page too.
    ledger = html[html.index('id="assumptions"'):html.index('id="findings"')]
    assert ledger.count('<span class="badge v-assumed">assumed</span>') == len(
        doc["assumptions"]["entries"]) > 0
    # Seeded faults: a check on data badged "proved" is caught by this test and by the schema.
    bad = copy.deepcopy(report["result"].doc)
    (first,) = [i for i in bad["obligations"]["items"] if i["id"] == data[0]["id"]]
    first["badge"] = "proved"
    text = render_html(AuditResult(bad, report["result"].figures))
    assert any(p.startswith(first["id"]) for p in _badge_problems(bad, text))
    errors = list(jsonschema.Draft202012Validator(json.loads(SCHEMA.read_text())).iter_errors(
        json.loads(dumps_json(bad))))
    assert any("'checked on data' was expected" in e.message for e in errors), errors[:3]


def test_a_cards_scope_label_is_on_its_face(report):
    html = report["html"]
    heads = _card_heads(html)
    labelled = [i for i in report["doc"]["obligations"]["items"] if i["label"]]
    assert any(i["label"] == "wrapper proved, search assumed" for i in labelled), labelled
    for i in labelled:
        assert f'<span class="badge scope-label" title="the scope of this proof or check">' \
               f'{escape(i["label"])}</span>' in heads[i["id"]], i["id"]


def test_a_failed_obligation_opens_its_group_and_card(report, tmp_path):
    doc = json.loads(_results(report)["text"])
    doc["obligations"][0]["verdict"] = "failed"
    bad = tmp_path / "results.json"
    bad.write_text(json.dumps(doc))
    audit = copy.deepcopy(report["result"].doc)
    audit.update(_proof_sections(load_proofs(str(bad), ROOT / "scenarios", EXPECTED)))
    failed = doc["obligations"][0]["id"]
    (group,) = [g for g in audit["obligations"]["cards"] if failed in g["ids"]]
    assert group["not_as_expected"] == 1
    assert sum(g["not_as_expected"] for g in audit["obligations"]["cards"]) == 1
    text = render_html(AuditResult(audit, report["result"].figures))
    assert f'<details class="group" id="cards-{group["key"]}" open>' in text
    assert text.count(" open>") == 2      # the group and the failed card, nothing else


def _record(*checks):
    """A contracts record of one BuiltDR and one searchoptpath triple with the given checks."""
    def check(part, condition, scope, count, ok):
        return {"part": part, "condition": condition, "scope": scope, "count": count, "ok": ok}
    built = [check(*c) for c in checks if c[1].startswith("post.cells")]
    search = [check(*c) for c in checks if not c[1].startswith("post.cells")]
    return {"triples": [
        {"name": "Theorem 3", "title": "BuiltDR over the modified box", "checks": built},
        {"name": "Theorem 4", "title": "searchoptpath, modified", "checks": search}]}


def test_contract_table_shows_a_failed_first_record_as_failed():
    # BuiltDR's post.cells is recorded twice: the random sample, then the path's cells. A failed
    # sample with held path cells must not read "held".
    rec = _record(("post", "post.cells", "4096 random cells of 9000 (seed 0)", 4096, False),
                  ("post", "post.cells", "the 13 cells the path occupies", 13, True),
                  ("pre", "pre.dr.spec", "by Theorem 3's post.cells check: 4096 random", 0, False),
                  ("post", "post.is_path", "0 cells, 0 step checks", 0, True),
                  ("post", "post.optimal", "not checked in sampled mode", 0, None))
    held = _record(("post", "post.cells", "4096 random cells of 9000 (seed 0)", 4096, True),
                   ("post", "post.cells", "the 13 cells the path occupies", 13, True),
                   ("pre", "pre.dr.spec", "on a sample only: Theorem 3's post.cells at 4096 "
                    "random cells of 9000", 0, True))
    rows = {r["condition"]: r for r in contract_rows({"modified": rec, "tight": held})}
    cells = rows["post.cells"]["variants"]
    assert (cells["modified"]["count"], cells["modified"]["ok"], cells["modified"]["state"]) == (
        4096 + 13, False, "failed")
    assert [r["ok"] for r in cells["modified"]["records"]] == [False, True]
    assert (cells["tight"]["ok"], cells["tight"]["state"]) == (True, "held")
    assert rows["pre.dr.spec"]["variants"]["modified"]["state"] == "failed"
    assert rows["pre.dr.spec"]["variants"]["tight"]["state"] == "delegated"
    assert rows["post.is_path"]["variants"]["modified"]["state"] == "n/a"
    assert rows["post.optimal"]["variants"]["modified"]["state"] == "not checked"
    # Swapping the records' order changes nothing but the order of "records".
    swapped = _record(*[(c["part"], c["condition"], c["scope"], c["count"], c["ok"])
                        for c in rec["triples"][0]["checks"][::-1]])
    again = {r["condition"]: r for r in contract_rows({"modified": swapped})}
    assert again["post.cells"]["variants"]["modified"]["state"] == "failed"


def test_contract_table_renders_failed_and_zero_counts_honestly(report):
    audit = copy.deepcopy(report["result"].doc)
    (s,) = audit["scenarios"]
    rec = _record(("post", "post.cells", "4096 random cells of 9000 (seed 0)", 4096, False),
                  ("post", "post.cells", "the 13 cells the path occupies", 13, True),
                  ("pre", "pre.dr.spec", "by Theorem 3's post.cells check: 4096 random", 0, True),
                  ("post", "post.costs", "J1 and J2 recomputed", 0, True))
    s["contract_checks"] = contract_rows({"original": rec})
    text = render_html(AuditResult(audit, report["result"].figures))
    table = text[text.index("<th>command</th><th>condition</th>"):]
    table = table[:table.index("</table>")]
    row = table[table.index("post.cells"):]
    row = row[:row.index("</tr>")]
    assert "4096 + 13" in row and "FAILED" in row and ">held<" not in row
    assert "by post.cells" in table and ">n/a<" in table
    assert "0 <span" not in table, "a zero count is shown with a badge"


def test_additive_plan_keys_validate_and_render(report):
    # plan.json may gain keys (kernel, dr_sha256, more violation fields): the report keeps them.
    audit = copy.deepcopy(report["result"].doc)
    v = audit["scenarios"][0]["variants"][1]
    v.update(kernel={"builtdr": "fast", "search": "fast"}, dr_sha256="ab" * 32)
    v["clearance"]["lower_bound_m"] = 0.001
    v["contracts"]["violations"] = [{"triple": "Theorem 3", "condition": "post.cells",
                                     "values": {"cell": [0, 1, 2]}, "message": "a new field"}]
    jsonschema.validate(audit, json.loads(SCHEMA.read_text()))
    text = render_html(AuditResult(audit, report["result"].figures))
    assert "ab" * 32 in text and "builtdr: fast" in text
    assert "message: a new field" in text and "cell was [0, 1, 2]" in text


def test_workcell_instants_spread_over_the_principals_motion():
    # Default: Tf = 1.4 s, the subordinate arrives at 3 s, least clearance at t = 0.
    times = workcell_instants(1.4, 3.0, 0.02, 0.0)
    assert times == pytest.approx([0.0, 1.4 / 3, 2.8 / 3, 1.4, 3.0])
    assert sum(t <= 1.4 for t in times) == 4 and times[-1] == 3.0
    # A least-clearance instant near an inner instant replaces it; one far away is added.
    assert workcell_instants(1.6, 2.2, 0.04, 0.565) == pytest.approx([0, 0.565, 3.2 / 3, 1.6, 2.2])
    assert len(workcell_instants(1.6, 2.2, 0.04, 2.0)) == 6
    # A path that ends before Tf: no instant after Tf.
    assert max(workcell_instants(1.6, 1.0, 0.04, None)) == 1.6


def test_findings_text_matches_golden(report):
    text = "\n\n".join(f"[{f['id']}] {f['title']}\n{f['text']}" for f in report["doc"]["findings"])
    _golden("findings.txt", text + "\n")
    assert all(f["reproduced"] for f in report["doc"]["findings"])


def test_report_json_key_set_matches_golden(report):
    _golden("report_keys.txt", "\n".join(sorted(_keys(report["doc"]))) + "\n")


def test_a_failed_obligation_fails_the_audit(report, tmp_path):
    # A results.json recording one failed obligation, read the way build_audit reads it.
    doc = json.loads(_results(report)["text"])
    doc["obligations"][0]["verdict"] = "failed"
    bad = tmp_path / "results.json"
    bad.write_text(json.dumps(doc))
    audit = copy.deepcopy(report["result"].doc)
    audit.update(_proof_sections(load_proofs(str(bad), ROOT / "scenarios", EXPECTED)))
    audit["verdict"] = _verdict(audit)
    assert audit["verdict"]["ok"] is False
    assert not audit["obligations"]["missing_ids"] and not audit["obligations"]["unexpected_ids"]
    assert audit["obligations"]["summary"]["total"]["unproved"] == 1
    text = render_html(AuditResult(audit, report["result"].figures))
    assert f"expected: {doc['obligations'][0]['expected']}" in text and "FAILED" in text


def test_ids_of_a_doctored_results_json_are_checked_not_copied(report, tmp_path):
    # One id deleted, one renamed, and the file still claims none missing and none extra.
    doc = json.loads(_results(report)["text"])
    assert not doc["missing_ids"] and not doc["unexpected_ids"]
    gone, renamed = doc["obligations"][0]["id"], doc["obligations"][1]["id"]
    doc["obligations"] = doc["obligations"][1:]
    doc["obligations"][0]["id"] = renamed + ".typo"
    bad = tmp_path / "results.json"
    bad.write_text(json.dumps(doc))
    proofs = load_proofs(str(bad), ROOT / "scenarios", EXPECTED)
    assert proofs.missing_ids == (gone, renamed)
    assert proofs.unexpected_ids == (renamed + ".typo",)
    audit = copy.deepcopy(report["result"].doc)
    audit.update(_proof_sections(proofs))
    audit["verdict"] = _verdict(audit)
    assert audit["verdict"]["ok"] is False and audit["obligations"]["all_as_expected"] is False
    text = render_html(AuditResult(audit, report["result"].figures))
    assert "all present, none extra" not in text
    assert f"missing</span> {gone}, {renamed}" in text and renamed + ".typo" in text
    # A repeated id is not "present" twice over: it is reported.
    doc = json.loads(_results(report)["text"])
    doc["obligations"].append(dict(doc["obligations"][0]))
    bad.write_text(json.dumps(doc))
    twice = load_proofs(str(bad), ROOT / "scenarios", EXPECTED)
    assert twice.unexpected_ids == (f"{doc['obligations'][0]['id']} (twice)",)
    # Without a list, every obligation is expected: a partial run shows what it left out.
    partial = load_proofs(str(_results(report)["path"]), ROOT / "scenarios")
    assert set(partial.missing_ids) == set(expected_ids(ROOT / "scenarios")) - set(EXPECTED)


def test_negative_controls_are_shown_from_results_json(report):
    doc, html = report["doc"], report["html"]
    recorded = json.loads(_results(report)["text"])["controls"]
    n = len(recorded)         # the witness checker's, the D_R postcondition's, the path's
    assert {"Control.witness.forged", "Control.dr.unsound_free_cell",
            "Control.path.through_blocked"} <= {c["id"] for c in recorded}, recorded
    ctl = doc["controls"]
    assert ctl["available"] and not ctl["missing_ids"]
    assert [(c["id"], c["outcome"], c["expected"], c["what"]) for c in ctl["items"]] == [
        (c["id"], c["outcome"], c["expected"], c["what"]) for c in recorded]
    assert ctl["summary"] == {"total": n, "as_expected": n, "rejected": n}
    table = html[html.index('id="controls"'):]
    table = table[:table.index("</table>")]
    for c in recorded:
        row = table[table.index(f'id="control-{c["id"].replace(".", "-").replace("_", "-").lower()}"'):]
        row = row[:row.index("</tr>")]
        assert c["id"] in row and str(escape(c["what"])) in row and ">rejected<" in row
        assert "as expected" in row and "FAILED" not in row
    assert f"{n} of {n} as expected: rejected {n}." in table
    item = _check(doc, "negative controls as expected")
    assert item["ok"] is True and item["detail"] == f"{n} of {n} (rejected {n})"


def test_a_control_not_as_expected_fails_the_verdict(report, tmp_path):
    # A checker that accepted its forged input; the file still claims ok.
    doc = json.loads(_results(report)["text"])
    doc["controls"][0].update(outcome="accepted", ok=True)
    bad = tmp_path / "results.json"
    bad.write_text(json.dumps(doc))
    audit = copy.deepcopy(report["result"].doc)
    audit.update(_proof_sections(load_proofs(str(bad), ROOT / "scenarios", EXPECTED)))
    audit["verdict"] = _verdict(audit)
    item = _check(audit, "negative controls as expected")
    assert audit["verdict"]["ok"] is False and item["ok"] is False
    cid = doc["controls"][0]["id"]
    assert f"not as expected: {cid} (accepted, expected rejected)" in item["detail"]
    assert audit["controls"]["summary"]["as_expected"] == len(doc["controls"]) - 1
    text = render_html(AuditResult(audit, report["result"].figures))
    row = text[text.index(f'id="control-{cid.replace(".", "-").replace("_", "-").lower()}"'):]
    assert "FAILED" in row[:row.index("</tr>")]
    # A control whose outcome is expected but whose record says not ok is not ok either.
    doc["controls"][0].update(outcome="rejected", ok=False)
    bad.write_text(json.dumps(doc))
    again = load_proofs(str(bad), ROOT / "scenarios", EXPECTED)
    assert [c.ok for c in again.controls] == [False] + [True] * (len(doc["controls"]) - 1)


def test_premise_controls_are_folded_unless_one_fails(report):
    audit = copy.deepcopy(report["result"].doc)

    def premise(i, outcome):
        return {"id": f"Control.Safety.tight.composition.without[{i}]",
                "checker": "Safety.tight.composition", "what": f"without: premise {i}",
                "expected": ["refuted", "unknown"], "outcome": outcome,
                "ok": outcome in ("refuted", "unknown"), "detail": "", "seconds": 1.0}
    audit["controls"]["items"] += [premise(0, "refuted"), premise(1, "unknown")]
    text = render_html(AuditResult(audit, report["result"].figures))
    fold = text[text.index('<details class="group" id="controls-premises">'):]
    fold = fold[:fold.index("</details>")]
    assert "2 controls, 2 as expected" in fold and "without: premise 1" in fold
    assert "as expected (undecided)" in fold        # unknown: weaker evidence, said so
    checkers = text[text.index('id="controls"'):text.index('id="controls-premises"')]
    assert "without: premise" not in checkers and "Control.witness.forged" in checkers
    # A composition proved without its premise: the fold opens and says how many failed.
    audit["controls"]["items"].append(premise(2, "proved"))
    text = render_html(AuditResult(audit, report["result"].figures))
    assert '<details class="group" id="controls-premises" open>' in text
    assert "3 controls, 2 as expected" in text and ">1 FAILED</span>" in text
    assert _controls_item(audit)["ok"] is False


def test_a_whole_run_without_its_controls_fails_the_verdict(report, tmp_path):
    # Controls deleted from a results.json that must be a whole run: not "not available".
    from cfmpa.proofs import collect_controls

    doc = json.loads(_results(report)["text"])
    del doc["controls"]
    bad = tmp_path / "results.json"
    bad.write_text(json.dumps(doc))
    audit = copy.deepcopy(report["result"].doc)
    audit.update(_proof_sections(load_proofs(str(bad), ROOT / "scenarios")))
    assert audit["controls"]["available"] is False
    assert audit["controls"]["missing_ids"] == [c.id for c in collect_controls()]
    assert _check({"verdict": _verdict(audit)}, "negative controls as expected")["ok"] is False
    # The same file read for a subset of obligations: nothing to show, not counted either way.
    audit.update(_proof_sections(load_proofs(str(bad), ROOT / "scenarios", EXPECTED)))
    item = _check({"verdict": _verdict(audit)}, "negative controls as expected")
    assert item["ok"] is None and "records no negative controls" in item["detail"]
    assert "Not available in this run" in render_html(AuditResult(audit,
                                                                  report["result"].figures))


def test_definitional_obligations_are_counted_apart_and_labelled(report):
    from cfmpa.proofs import DEFINITIONAL

    doc, html = report["doc"], report["html"]
    ob = doc["obligations"]
    recorded = {o["id"]: o for o in json.loads(_results(report)["text"])["obligations"]}
    defs = [i["id"] for i in ob["items"] if i["kind"] == "definitional"]
    assert defs and set(defs) == set(DEFINITIONAL) & set(recorded)
    assert all(i["kind"] == recorded[i["id"]]["kind"] for i in ob["items"])
    kinds = ob["summary"]["kinds"]
    assert kinds == {"theorem": len(ob["items"]) - len(defs), "definitional": len(defs)}
    assert (f"{len(ob['items'])} obligations: {kinds['theorem']} theorems, "
            f"{kinds['definitional']} definitional.") in html
    for i in ob["items"]:
        card = html[html.index(f'id="ob-{i["id"].replace(".", "-").replace("_", "-").lower()}"'):]
        card = card[:card.index('<div class="obligation"', 10) if '<div class="obligation"' in
                    card[10:] else card.index('<h2 id="assumptions">')]
        head = card[:card.index('<p class="summary">')]
        assert ("definitional</span>" in head) is (i["kind"] == "definitional"), i["id"]
        # Each VC is listed in the folded details with its nonlinear flag.
        rows = re.findall(r'<tr><td class="mono">([^<]*)</td>.*?<td>(?:<span class="badge na">'
                          r'(nonlinear)</span>|linear)</td></tr>', card)
        assert [(n, f == "nonlinear") for n, f in rows] == [
            (str(escape(v["name"])), v["nonlinear"]) for v in recorded[i["id"]]["vcs"]], i["id"]
    nl = sum(v["nonlinear"] for o in recorded.values() for v in o["vcs"])
    assert ob["depth"]["nonlinear_vcs"] == nl and ob["depth"]["measures"].startswith("quantifier")


def test_a_fresh_run_shows_no_controls_and_does_not_count_them():
    from cfmpa.report._obligations import ProofData

    fresh = ProofData(available=True, source="fresh", note="", rows=(), ledger=(),
                      ledger_available=True, controls_note="not run for this report")
    part = _proof_sections(fresh)["controls"]
    assert part == {"available": False, "note": "not run for this report",
                    "summary": {"total": 0, "as_expected": 0}, "items": [], "missing_ids": []}


def test_a_fresh_run_of_every_obligation_runs_the_controls_too(monkeypatch):
    # The prove runner stood in for (a whole run takes minutes): what the fresh run asks of it.
    import types

    import cfmpa.proofs as proofs
    from cfmpa.proofs import ControlResult, collect_controls
    from cfmpa.report._obligations import _fresh

    asked = {}

    def run(obligations, out, expected, *, workers, controls=(), progress=None):
        asked["controls"] = [c.id for c in controls]
        return types.SimpleNamespace(proofs=(), controls=tuple(
            ControlResult(c.id, c.checker, c.what, c.expected, c.expected[0], "", 0.1)
            for c in controls))
    monkeypatch.setattr(proofs, "run_obligations", run)
    # Every scenario-independent obligation in the run (none here, as there are none to run).
    monkeypatch.setattr(proofs, "FIXED_IDS", ())
    data = _fresh([], [])
    every = [c.id for c in collect_controls()]
    assert asked["controls"] == every and [c.id for c in data.controls] == every
    assert all(c.ok for c in data.controls) and data.controls_note.startswith("run for this")
    part = _proof_sections(data)["controls"]
    assert part["available"] and part["summary"]["as_expected"] == len(every)
    # A narrower run (a test's stand-in for the user's checks) has none to run, and says so.
    monkeypatch.undo()
    monkeypatch.setattr(proofs, "run_obligations", run)
    data = _fresh([], [])
    assert asked["controls"] == [] and data.controls is None
    assert data.controls_note.startswith("not run for this report")


def test_run_audit_prints_the_overall_status_last(report, tmp_path, monkeypatch):
    import cfmpa.report._audit as audit

    monkeypatch.setattr(audit, "build_audit", lambda *a, **k: report["result"])
    printed = io.StringIO()
    assert run_audit(None, str(tmp_path / "a"), stdout=printed) == 0
    lines = printed.getvalue().splitlines()
    assert lines[-2] == (f"{'overall':<38} incomplete (not available: verdict rows rest on what "
                         "ran)")
    assert lines[0].startswith("verdict rows rest on what ran          not available: ")


def _check(audit, name):
    return next(i for i in audit["verdict"]["items"] if i["check"] == name)


def test_results_of_another_tree_fail_the_audit(report, tmp_path):
    # The fixture's results are of this checkout: commit and scenario bytes match.
    here = _check(report["doc"], "proof results are of this tree")
    assert here["ok"] is True, here
    doc = json.loads(_results(report)["text"])
    assert doc["run"]["git"]["commit"] == report["doc"]["provenance"]["git"]["commit"]
    assert doc["run"]["scenarios"]["default.toml"] == hashlib.sha256(
        (ROOT / "scenarios" / "default.toml").read_bytes()).hexdigest()

    def audited(d):
        bad = tmp_path / "results.json"
        bad.write_text(json.dumps(d))
        audit = copy.deepcopy(report["result"].doc)
        audit.update(_proof_sections(load_proofs(str(bad), ROOT / "scenarios", EXPECTED)))
        audit["verdict"] = _verdict(audit)
        return audit

    other = copy.deepcopy(doc)
    other["run"]["git"]["commit"] = "0" * 40
    audit = audited(other)
    assert audit["verdict"]["ok"] is False
    assert "proved at commit " + "0" * 40 in _check(audit, "proof results are of this tree")["detail"]
    # The report's scenario (tiny.toml) under another's bytes.
    name = Path(report["doc"]["provenance"]["scenarios"][0]["path"]).name
    changed = copy.deepcopy(doc)
    changed["run"]["scenarios"][name] = "f" * 64
    assert "changed since the prove run" in _check(audited(changed),
                                                   "proof results are of this tree")["detail"]
    carried = copy.deepcopy(doc)
    carried["obligations"][0]["change"] = "not run"
    assert _check(audited(carried), "proof results are of this tree")["ok"] is False
    # An older results.json with no record: cannot tell, said so, not counted as a failure.
    old = {k: v for k, v in doc.items() if k != "run"}
    unknown = _check(audited(old), "proof results are of this tree")
    assert unknown["ok"] is None and "records no run" in unknown["detail"]


def test_missing_parts_are_labelled_not_available(report, tiny_file, complete_proofs):
    # Everything the rows rest on ran: the overall pill says "no failure".
    audit = complete_proofs(report["result"].doc, [tiny_file.stem])
    audit["summary"] = workcell_summary([_scenario_of(report)], audit)
    audit["verdict"] = _verdict(audit)
    assert audit["verdict"]["status"] == "no failure", audit["verdict"]
    text = render_html(AuditResult(audit, report["result"].figures))
    assert _pills(text) == ["no failure", "no failure"]
    # `--compare-n 0`: the campaign is not available, so the verdict is incomplete, not green.
    audit["compare"] = {"available": False, "note": "not run for this report (compare_n = 0)"}
    audit["verdict"] = _verdict(audit)
    assert audit["verdict"]["ok"] is True          # nothing failed: exit code 0
    assert audit["verdict"]["status"] == "incomplete"
    assert audit["verdict"]["not_available"] == ["campaign checks"]
    text = render_html(AuditResult(audit, report["result"].figures))
    assert "not run for this report (compare_n = 0)" in text
    # Both pills, section 1's and the provenance's, say so, with what is not available.
    assert _pills(text) == ["incomplete", "incomplete"]
    first = text[:text.index('id="provenance"')]
    assert "not available: campaign checks" in first and '"badge ok">no failure<' not in text
    if not audit["selftest"]["available"]:
        assert "Not available in this run" in text


def _pills(html):
    """The overall pills of the page (section 1's total row, then "What this run checked")."""
    return re.findall(r'<tr class="total"><td[^>]*>(?:overall).*?<span class="badge [^"]*"'
                      r'(?: title="[^"]*")?>([^<]*)</span>', html, re.S)


def test_unreadable_proofs_json_is_an_input_error(tmp_path, tiny_file):
    with pytest.raises(InputError, match="cannot be read"):
        build_audit([str(tiny_file)], proofs_json=str(tmp_path / "none.json"), compare_n=0)
    (tmp_path / "bad.json").write_text("{not json")
    with pytest.raises(InputError, match="not valid JSON"):
        build_audit([str(tiny_file)], proofs_json=str(tmp_path / "bad.json"), compare_n=0)


def _check_data_uri(uri: str) -> None:
    """Raise unless ``uri`` is a decodable, non-blank PNG or a parseable SVG."""
    from PIL import Image

    head, _, body = uri.partition(",")
    if head == "data:image/png;base64":
        data = base64.b64decode(body, validate=True)
        assert data[:8] == b"\x89PNG\r\n\x1a\n", head
        with Image.open(io.BytesIO(data)) as img:
            img.load()                    # decodes every scanline; raises if truncated
            assert img.width > 100 and img.height > 100, img.size
            assert len(img.getcolors(maxcolors=1 << 16) or range(1 << 16)) > 8, "blank"
    elif head.startswith("data:image/svg+xml"):
        text = (base64.b64decode(body).decode() if head.endswith(";base64")
                else urllib.parse.unquote(body))
        assert ElementTree.fromstring(text).tag.endswith("svg")
    else:
        raise AssertionError(f"unexpected data URI kind {head!r}")


def test_every_embedded_picture_decodes(report):
    uris = re.findall(r'(?:src|href)\s*=\s*"(data:[^"]*)"', report["html"])
    wanted = {f["id"] for f in _figure_refs(report["doc"])}
    assert len(uris) == len(wanted) > 0, "one embedded picture per figure of report.json"
    for uri in uris:
        _check_data_uri(uri)


def test_picture_check_catches_a_broken_picture(report):
    # The check above must fail on a truncated PNG, or it checks nothing.
    (uri,) = re.findall(r'src="(data:image/png;base64,[^"]*)"', report["html"])[:1]
    head, _, body = uri.partition(",")
    data = base64.b64decode(body)
    cut = head + "," + base64.b64encode(data[: len(data) // 2]).decode()
    with pytest.raises((OSError, SyntaxError)):
        _check_data_uri(cut)


#: Appended to a scratch copy of the page: after load, lists every picture that did not decode.
_IMG_PROBE = """<script>
window.addEventListener("load", () => {
  const imgs = Array.from(document.images);
  const bad = imgs.filter(i => !(i.complete && i.naturalWidth > 0))
                  .map(i => i.alt || i.src.slice(0, 40));
  const out = document.createElement("pre");
  out.id = "img-probe";
  out.textContent = JSON.stringify({count: imgs.length, bad: bad});
  document.body.appendChild(out);
});
</script>"""


def _chromium(tmp_path, *args):
    return subprocess.run(
        [str(CHROMIUM), "--headless", "--no-sandbox", "--disable-gpu", "--disable-quic",
         "--no-first-run", "--disable-background-networking", "--disable-component-update",
         "--disable-sync", f"--user-data-dir={tmp_path / 'profile'}", "--enable-logging=stderr",
         "--v=0", *args], capture_output=True, text=True, timeout=180, check=False)


@pytest.mark.browser
def test_report_renders_in_headless_chromium(report, tmp_path):
    if not CHROMIUM.exists():
        pytest.skip("/usr/bin/chromium is absent (Debian package 'chromium'; .ci/run installs it)")
    shot = tmp_path / "report.png"
    url = (report["out"] / "report.html").resolve().as_uri()
    proc = _chromium(tmp_path, f"--screenshot={shot}", "--window-size=1280,4000", url)
    assert proc.returncode == 0, proc.stderr[-2000:]
    # A resource that failed to load, or a script error, is logged as a console message.
    assert not re.search(r"Failed to load resource|Uncaught|net::ERR_", proc.stderr), proc.stderr
    width, height, distinct = _png_stats(shot.read_bytes())
    assert (width, height) == (1280, 4000)
    assert distinct > 50, "the screenshot is (nearly) blank"
    # Every picture decoded in the browser: a scratch copy with a probe, read back from the DOM.
    probe = tmp_path / "probe.html"
    probe.write_text(report["html"].replace("</body>", _IMG_PROBE + "\n</body>"))
    dom = _chromium(tmp_path, "--dump-dom", "--virtual-time-budget=10000", probe.as_uri())
    assert dom.returncode == 0, dom.stderr[-2000:]
    found = re.search(r'<pre id="img-probe">(.*?)</pre>', dom.stdout, re.S)
    assert found, "the probe did not run: " + dom.stderr[-1000:]
    result = json.loads(html_lib.unescape(found.group(1)))
    assert result["count"] == len(_figure_refs(report["doc"])) and result["bad"] == [], result


#: Appended to a scratch copy of the page: after load, where section 1 is in the window and
#: each obligation card's short summary, read from the DOM as the browser laid it out.
_FIRST_SCREEN_PROBE = """<script>
window.addEventListener("load", () => {
  const s1 = document.getElementById("workcells");
  const box = s1 ? s1.getBoundingClientRect() : null;
  const table = s1 ? s1.querySelector("table") : null;
  const cards = Array.from(document.querySelectorAll("div.obligation")).map(c => {
    const p = c.querySelector(":scope > p.summary");
    return {id: c.querySelector(".id").textContent,
            summary: p ? p.textContent.trim() : null,
            placeholder: p ? p.querySelector("em") !== null : true,
            badges: Array.from(c.querySelectorAll(".head .badge")).map(b => b.textContent.trim())};
  });
  // Section 1's verdicts as laid out: each row's last cell's badge, with its box on the page.
  const verdicts = table ? Array.from(table.querySelectorAll("tr")).slice(1).map(tr => {
    const b = tr.lastElementChild.querySelector(".badge");
    const r = b ? b.getBoundingClientRect() : null;
    return {text: b ? b.textContent.trim() : null, shown: !!r && r.width > 0 && r.height > 0,
            top: r && r.top};
  }) : [];
  const out = document.createElement("pre");
  out.id = "screen-probe";
  out.textContent = JSON.stringify({
    width: window.innerWidth, height: window.innerHeight,
    top: box && box.top, table_top: table && table.getBoundingClientRect().top,
    heading: s1 && s1.querySelector("h2").textContent, cards: cards, verdicts: verdicts});
  document.body.appendChild(out);
});
</script>"""


def _first_screen(tmp_path, html, name):
    """The probe's reading of ``html`` in a 1400 x 900 headless Chromium window."""
    probe = tmp_path / f"{name}.html"
    probe.write_text(html.replace("</body>", _FIRST_SCREEN_PROBE + "\n</body>"))
    dom = _chromium(tmp_path, "--window-size=1400,900", "--dump-dom",
                    "--virtual-time-budget=10000", probe.as_uri())
    assert dom.returncode == 0, dom.stderr[-2000:]
    found = re.search(r'<pre id="screen-probe">(.*?)</pre>', dom.stdout, re.S)
    assert found, "the probe did not run: " + dom.stderr[-1000:]
    return json.loads(html_lib.unescape(found.group(1)))


def _screen_problems(got, doc):
    """What the first-screen reading shows wrong: section 1 not within the first 900 pixels,
    a card missing, or a card without its short summary; a verdict of section 1 (its rows, then
    the overall pill) that is not report.json's or not visible; a card of a check on data with
    a "proved" badge."""
    out = []
    want = [r["verdict"] for r in doc["summary"]] + [doc["verdict"]["status"]]
    shown = [v["text"] for v in got["verdicts"]]
    if shown != want or not all(v["shown"] for v in got["verdicts"]):
        out.append(f"section 1 shows the verdicts {shown}, not {want} (or not all visibly)")
    method = {i["id"]: i["method"] for i in doc["obligations"]["items"]}
    out += [f"{c['id']}: a check on data badged proved" for c in got["cards"]
            if method.get(c["id"]) == "data" and "proved" in c["badges"]]
    if got["heading"] != "1. Verdict per workcell" or not (0 <= got["top"] < 900):
        out.append(f"section 1 ({got['heading']!r}) starts at {got['top']} px")
    if got["table_top"] is None or not (0 <= got["table_top"] < 900):
        out.append(f"section 1's table starts at {got['table_top']} px")
    summaries = {i["id"]: i["summary"] for i in doc["obligations"]["items"]}
    if sorted(c["id"] for c in got["cards"]) != sorted(summaries):
        out.append("the cards are not the obligations")
    out += [f"{c['id']}: no short summary" for c in got["cards"]
            if c["placeholder"] or c["summary"] != summaries.get(c["id"])]
    return out


@pytest.mark.browser
def test_section_one_is_on_the_first_screen_and_every_card_has_its_summary(report, tmp_path):
    if not CHROMIUM.exists():
        pytest.skip("/usr/bin/chromium is absent (Debian package 'chromium'; .ci/run installs it)")
    got = _first_screen(tmp_path, report["html"], "screen")
    # Chromium's headless window of 1400 x 900 gives the page 1400 pixels' width and, with its
    # window frame taken off, a little less height: section 1 must start within both.
    assert got["width"] == 1400 and 0 < got["height"] <= 900, got
    assert got["table_top"] < got["height"], got
    assert _screen_problems(got, report["doc"]) == []
    # The fixture's run is partial: its found plans' rows read "incomplete", on the first screen,
    # and no check on data is called proved.
    incomplete = [v for v in got["verdicts"] if v["text"] == "incomplete"]
    assert len(incomplete) == 1 + sum(r["verdict"] == "incomplete" for r in report["doc"]["summary"])
    assert all(v["top"] < got["height"] for v in incomplete[:-1]), got["verdicts"]
    assert any(c["badges"][:1] == ["checked on data"] for c in got["cards"])
    # Seeded faults: a block that pushes section 1 below the first screen, a card without its
    # summary (rendered from a doc whose first obligation has none).
    # A check on data badged "proved"; a found plan's row "safe" on the partial run.
    doc = copy.deepcopy(report["result"].doc)
    first = doc["obligations"]["items"][0]
    first["summary"] = None
    (data,) = [i for i in doc["obligations"]["items"] if i["method"] == "data"][:1]
    data["badge"] = "proved"
    (row,) = [r for r in doc["summary"] if r["verdict"] == "incomplete"][:1]
    row.update(ok=True, verdict="safe")
    html = render_html(AuditResult(doc, report["result"].figures)).replace(
        '<section id="workcells">', '<div style="height: 1000px"></div><section id="workcells">')
    bad = _screen_problems(_first_screen(tmp_path, html, "seeded"), report["doc"])
    assert any(b.startswith("section 1 (") for b in bad), bad
    assert f"{first['id']}: no short summary" in bad, bad
    assert f"{data['id']}: a check on data badged proved" in bad, bad
    assert any(b.startswith("section 1 shows the verdicts") for b in bad), bad


# --- helpers --------------------------------------------------------------------------------------

def _results(report):
    path = Path(report["doc"]["obligations"]["source"].removeprefix("read from "))
    return {"path": path, "text": path.read_text()}


def _figure_refs(doc):
    """Every figure report.json refers to (findings, scenarios and their tubes, the monitored
    run, the campaign's two)."""
    refs = [f["figure"] for f in doc["findings"] if f.get("figure")]
    refs += [f for s in doc["scenarios"] for f in s["figures"]]
    refs += [s["tube"]["figure"] for s in doc["scenarios"] if s["tube"]]
    refs += [m["figure"] for m in doc["monitor"]["workcells"] if m["available"]]
    return refs + [doc["compare"][k] for k in ("figure", "rate_figure") if doc["compare"].get(k)]


def _golden(name: str, text: str) -> None:
    path = GOLDEN / name
    if os.environ.get("CFMPA_REGEN_GOLDEN") == "1":
        path.write_text(text)
    assert path.exists(), f"no golden file {path}; run with CFMPA_REGEN_GOLDEN=1 to create it"
    assert text == path.read_text(), f"{name} differs from the golden file (see module docstring)"


#: Parts of report.json whose keys belong to other modules' records (contracts, certificate,
#: a finding's own numbers, the campaign's cases) or to the environment (versions, git paths).
_OPEN = ("findings[].data", "scenarios[].variants[].contracts", "scenarios[].variants[].clearance",
         "scenarios[].variants[].kernel", "provenance.git.paths",
         "scenarios[].variants[].timings_s", "selftest.rows[]", "provenance.versions",
         "compare.cases[].outcomes", "compare.table[].no_path_reasons", "compare.checks",
         "controls.summary")


def _keys(x, prefix: str = "") -> set[str]:
    out: set[str] = set()
    if prefix in _OPEN:
        return {prefix + ".*"}
    if isinstance(x, dict):
        for k, v in x.items():
            p = f"{prefix}.{k}" if prefix else k
            out.add(p)
            out |= _keys(v, p)
    elif isinstance(x, list):
        for v in x:
            out |= _keys(v, prefix + "[]")
    return out


def _png_stats(data: bytes) -> tuple[int, int, int]:
    """Width, height and the number of distinct byte values of the decoded scanlines."""
    assert data[:8] == b"\x89PNG\r\n\x1a\n"
    pos, idat, width, height = 8, b"", 0, 0
    while pos < len(data):
        (length,) = struct.unpack(">I", data[pos:pos + 4])
        kind = data[pos + 4:pos + 8]
        body = data[pos + 8:pos + 8 + length]
        if kind == b"IHDR":
            width, height = struct.unpack(">II", body[:8])
        elif kind == b"IDAT":
            idat += body
        pos += 12 + length
    return width, height, len(set(zlib.decompress(idat)))


#: report.json's fields documented as varying between builds from the same inputs (see the
#: docstring of cfmpa.report._audit): times anywhere, and the provenance's date and git state.
_VARYING_KEYS = ("seconds", "timings_s", "mean_seconds")


def _without_varying(x, path=""):
    if isinstance(x, dict):
        return {k: _without_varying(v, f"{path}.{k}") for k, v in x.items()
                if k not in _VARYING_KEYS and f"{path}.{k}" not in (".provenance.date_utc",
                                                                   ".provenance.git")}
    if isinstance(x, list):
        return [_without_varying(v, path) for v in x]
    return x


def test_varying_fields_are_only_the_documented_ones(report):
    doc = report["doc"]
    stripped = _without_varying(doc)
    assert "date_utc" not in stripped["provenance"] and "git" not in stripped["provenance"]
    assert stripped["scenarios"][0]["variants"][0]["variant"] == "original"
    assert all("timings_s" not in v for v in stripped["scenarios"][0]["variants"])
    # Nothing else is dropped: the same key set apart from the varying ones.
    assert len(_keys(stripped)) > 0.9 * len(_keys(doc))


@pytest.mark.slow
def test_report_json_is_deterministic(report, tiny_file, results_json, tmp_path):
    """A second build from the same inputs gives the same report.json but for the documented
    varying fields (about 30 s: the findings replan three bundled scenarios)."""
    again = build_audit([str(tiny_file)], argv=report["argv"], proofs_json=str(results_json),
                        compare_n=4, compare_seed=3, expected_ids=EXPECTED)
    write_report(again, tmp_path)
    second = json.loads((tmp_path / "report.json").read_text())
    first = report["doc"]
    assert first["provenance"]["date_utc"] and second["provenance"]["date_utc"]
    a, b = _without_varying(first), _without_varying(second)
    diff = [k for k in a if a[k] != b[k]]
    assert not diff, diff
    # The pictures are the same bytes too (PNG without date metadata).
    assert {k: f.png for k, f in again.figures.items()} == {
        k: f.png for k, f in report["result"].figures.items()}


@pytest.mark.slow
def test_full_audit_of_the_bundled_scenarios(tmp_path, capsys):
    """`cfmpa audit` as `make prove` ends: every scenario, fresh obligations, 100 workcells."""
    out = tmp_path / "audit"
    code = run_audit(None, str(out), argv=["cfmpa", "audit", "--out", str(out)])
    printed = capsys.readouterr().out
    doc = json.loads((out / "report.json").read_text())
    assert code == 0, printed
    assert "wrote" in printed and str(out / "report.html") in printed
    jsonschema.validate(doc, json.loads(SCHEMA.read_text()))
    names = {p.stem for p in (ROOT / "scenarios").glob("*.toml")}
    assert {s["path"].rsplit("/", 1)[-1][:-5] for s in doc["scenarios"]} == names
    assert doc["obligations"]["source"].startswith("a fresh run")
    assert not doc["obligations"]["missing_ids"] and doc["compare"]["n"] == 100
    # A whole fresh run runs the negative controls too, so every row rests on what ran.
    assert doc["controls"]["available"] and not doc["controls"]["missing_ids"]
    assert doc["verdict"]["status"] == "no failure", doc["verdict"]["not_available"]
    assert not [r for r in doc["summary"] if r["verdict"] == "incomplete"]
    assert f"{'overall':<38} no failure" in printed
    html = (out / "report.html").read_text()
    assert all(f'<span class="id">{o["id"]}</span>' in html for o in doc["obligations"]["items"])


# --- the sections (report/_sections.py, docs/model.md §8) ---------------------------------------
# The order they are computed and shown in, the verdict made of their checks, and a planted extra
# section, which must appear in report.json, the HTML and the verdict with nothing else touched
# but its Section and its template.

def _section(key, *, needs=(), deferred=False, more=(), seen=None):
    def compute(ctx):
        if seen is not None:
            seen.append(key)
        return {k: {} for k in (key, *more)}
    return Section(key, key, compute, f"section_{key}.html", needs=needs, deferred=deferred,
                   more=more)


def test_compute_order_defers_and_follows_needs():
    a, b = _section("a", deferred=True), _section("b", needs=("c",))
    c, d = _section("c"), _section("d", needs=("a",))
    assert [s.key for s in compute_order((a, b, c, d))] == ["c", "b", "a", "d"]
    # The bundled tuple: the proofs after everything that does not need them, section 1 after
    # the parts it summarises.
    order = [s.key for s in compute_order(SECTIONS)]
    assert order.index("obligations") > max(order.index(k) for k in
                                            ("findings", "scenarios", "monitor", "compare"))
    assert order.index("summary") > order.index("obligations") > order.index("scenarios")
    assert order.index("findings") < order.index("scenarios")   # the triples of every plan


@pytest.mark.parametrize("sections, message", [
    ((_section("a"), _section("b", more=("a",))), "both write 'a'"),
    ((_section("a", needs=("zz",)),), "which no section writes"),
    ((_section("a", needs=("b",)), _section("b", needs=("a",))), "need each other"),
])
def test_compute_order_refuses_a_bad_tuple(sections, message):
    with pytest.raises(ValueError, match=message):
        compute_order(sections)


def test_verdict_is_the_sections_checks_in_their_order():
    def check(name, ok):
        return lambda doc: {"check": name, "ok": ok, "detail": ""}
    s1 = Section("a", "a", lambda c: {"a": 1}, "x", checks=(check("one", True),))
    s2 = Section("b", "b", lambda c: {"b": 1}, "x", checks=(check("two", None),
                                                            check("three", True)))
    v = verdict_of({}, (s1, s2))
    assert [i["check"] for i in v["items"]] == ["one", "two", "three"] and v["ok"] is True
    s3 = Section("c", "c", lambda c: {"c": 1}, "x", checks=(check("four", False),))
    assert verdict_of({}, (s1, s2, s3))["ok"] is False


def test_schema_names_every_sections_part():
    # A section's part is a top-level key of report.json: the schema must require it.
    schema = json.loads((ROOT / "report" / "schema.json").read_text())
    parts = {k for s in SECTIONS for k in s.keys}
    assert set(schema["required"]) == parts | {"format", "verdict"}


def _replayed(report):
    """The bundled sections with their computations replaced by the fixture's parts."""
    doc, figures = report["doc"], report["result"].figures

    def replay(sec):
        def compute(ctx):
            ctx.figures.update(figures)
            return {k: copy.deepcopy(doc[k]) for k in sec.keys}
        return compute
    return tuple(dataclasses.replace(s, compute=replay(s)) for s in SECTIONS)


def test_a_planted_section_is_in_the_json_the_html_and_the_verdict(report, tiny_file,
                                                                   results_json, tmp_path,
                                                                   monkeypatch):
    import cfmpa.report._audit as audit

    doc = report["doc"]
    seen = {}

    def compute(ctx):
        # computed after the parts it needs, which it reads from the build's context
        seen["scenarios"] = [s["name"] for s in ctx.doc["scenarios"]]
        return {"extra": {"note": "a planted part", "ok": holds[0]}}

    def check(d):
        return {"check": "extra part holds", "ok": d["extra"]["ok"], "detail": "planted"}

    extra = Section("extra", "Extra", compute, "section_extra.html", checks=(check,),
                    needs=("scenarios",))
    block = ('<h2 id="extra">{{ number.extra }}. Extra</h2>\n'
             '<p class="extra">{{ doc.extra.note }}</p>\n')
    source = audit._template_source
    monkeypatch.setattr(audit, "_template_source",
                        lambda name: block if name == "section_extra.html" else source(name))
    for ok in (True, False):
        holds = [ok]
        result = build_audit([str(tiny_file)], argv=report["argv"],
                             proofs_json=str(results_json), compare_n=4, compare_seed=3,
                             expected_ids=EXPECTED, sections=_replayed(report) + (extra,))
        out = tmp_path / str(ok)
        write_report(result, out)
        written = json.loads((out / "report.json").read_text())
        html = (out / "report.html").read_text()
        assert written["extra"] == {"note": "a planted part", "ok": ok}
        assert seen["scenarios"] == [s["name"] for s in doc["scenarios"]]
        items = written["verdict"]["items"]
        assert items[:-1] == doc["verdict"]["items"] and items[-1]["check"] == "extra part holds"
        assert written["verdict"]["ok"] is ok
        # Shown last, after the campaign, before the page's footer.
        assert '<p class="extra">a planted part</p>' in html
        assert html.index('id="compare"') < html.index('id="extra"') < html.index("<footer>")
        # And listed last in the page's contents (a link named by its title).
        nav = html[html.index("<nav>"):html.index("</nav>")]
        assert nav.rstrip().endswith('<li><a href="#extra">Extra</a></li>\n</ol>')
        assert html == render_html(result)
        assert '<h2 id="extra">11. Extra</h2>' in html
    # Placed second instead, it is section 2 and the ones after it are renumbered, references
    # to them included.
    moved = render_html(AuditResult(doc=result.doc, figures=result.figures,
                                    sections=SECTIONS[:1] + (extra,) + SECTIONS[1:]))
    assert '<h2 id="extra">2. Extra</h2>' in moved and "<h2>3. Provenance" in moved
    assert '<h2 id="summary">4. Summary of obligations' in moved
    assert '<h2 id="obligations">5. Obligations' in moved and "assumptions (section 6)" in moved
    assert '<h2 id="compare">11. Comparison' in moved
    # The rest of the page is the bundled sections' own: without the planted one, the same.
    plain = build_audit([str(tiny_file)], argv=report["argv"], proofs_json=str(results_json),
                        compare_n=4, compare_seed=3, expected_ids=EXPECTED,
                        sections=_replayed(report))
    assert plain.doc["verdict"] == doc["verdict"]
    assert "extra" not in plain.doc and 'id="extra"' not in render_html(plain)


def test_a_section_computing_other_parts_than_it_declares_is_refused(report, tiny_file,
                                                                    results_json):
    bad = Section("extra", "Extra", lambda ctx: {"extra": 1, "stray": 2}, "section_extra.html")
    with pytest.raises(ValueError, match="computed"):
        build_audit([str(tiny_file)], argv=report["argv"], proofs_json=str(results_json),
                    compare_n=0, expected_ids=EXPECTED, sections=_replayed(report) + (bad,))
