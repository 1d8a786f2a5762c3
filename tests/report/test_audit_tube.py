"""The report's tolerance tubes and its monitored simulated run (docs/model.md §8, §12).

One report per module, built as test_audit.py builds its own (the coarse copy of the default
workcell, a small prove run, no campaign): per found plan its tolerance_rad, proved clearance,
the tube's margin 2 L delta and `cfmpa certify` on its traj.csv; one monitored run of the audited
workcell's modified plan, inside, and with an injected excursion, flagged at its first sample.
The numbers are checked against the commands themselves (`cfmpa plan`, `certify`, `simulate`,
`monitor`, in process), and seeded faults (a corrupted tolerance, a log outside the tube) must
fail the report's own checks.
"""

from __future__ import annotations

import copy
import io
import json
from pathlib import Path

import jsonschema
import pytest

import factory
from cfmpa import cli
from cfmpa.files import dumps_json
from cfmpa.proofs import expected_ids, run_prove
from cfmpa.proofs._runner import selected
from cfmpa.report import _audit, build_audit
from cfmpa.report._audit import (
    MONITOR_EXCURSION,
    MONITOR_SIMULATION,
    AuditResult,
    _monitor,
    _Plans,
    _verdict,
    monitor_problems,
    render_html,
    tube_problems,
    write_report,
)
from cfmpa.spec import load_scenario, tube_lipschitz

ROOT = Path(__file__).resolve().parents[2]
SCHEMA = ROOT / "report" / "schema.json"
OBLIGATIONS = ["Def1", "Tolerance.tube"]
EXPECTED = [i for i in expected_ids(ROOT / "scenarios") if selected(i, OBLIGATIONS)]


@pytest.fixture(scope="module")
def tiny_file(tmp_path_factory):
    return factory.tiny_default(tmp_path_factory.mktemp("scen"))


@pytest.fixture(scope="module")
def report(tiny_file, tmp_path_factory):
    proofs = tmp_path_factory.mktemp("proofs")
    assert run_prove(out_dir=proofs, scenarios_dir=ROOT / "scenarios", only=OBLIGATIONS,
                     stream=io.StringIO()) == 0
    out = tmp_path_factory.mktemp("audit")
    result = build_audit([str(tiny_file)], argv=["cfmpa", "audit"],
                         proofs_json=str(proofs / "results.json"), compare_n=0,
                         expected_ids=EXPECTED)
    write_report(result, out)
    return {"result": result, "doc": json.loads((out / "report.json").read_text()),
            "html": (out / "report.html").read_text()}


@pytest.fixture(scope="module")
def tiny_plan(tiny_file, tmp_path_factory):
    """`cfmpa plan TINY --out DIR` (the modified variant): plan.json and traj.csv."""
    out = tmp_path_factory.mktemp("plan-tiny")
    assert cli.main(["plan", str(tiny_file), "--out", str(out)]) == 0
    return out


def _mon(doc):
    """The monitored runs of the report's one workcell."""
    (mon,) = doc["monitor"]["workcells"]
    return mon


def _schema_errors(doc):
    """Every schema error, those under a oneOf's branches included, as "path: message"."""
    schema = json.loads(SCHEMA.read_text())
    out, todo = [], list(jsonschema.Draft202012Validator(schema).iter_errors(doc))
    while todo:
        e = todo.pop()
        out.append(f"{list(e.absolute_path)}: {e.message}")
        todo.extend(e.context or ())
    return out


def _item(doc, check):
    return next(i for i in doc["verdict"]["items"] if i["check"] == check)


def _reverdict(doc):
    doc["verdict"] = _verdict(doc)
    return doc


# --- the tube, per found plan --------------------------------------------------------------------

def test_each_found_plan_has_its_tube_in_json_and_html(report):
    doc, html = report["doc"], report["html"]
    assert not _schema_errors(doc)
    (s,) = doc["scenarios"]
    found = [v for v in s["variants"] if v["status"] == "found"]
    assert [v["variant"] for v in found] == ["modified", "tight"]    # original: no path here
    tube = s["tube"]
    assert tube["lipschitz_m_per_rad"] == tube_lipschitz(load_scenario(s["path"]))
    assert [pl["variant"] for pl in tube["plans"]] == [v["variant"] for v in found]
    text = html[html.index(f'id="tube-{s["name"]}"'):]
    table = text[text.index("<table>"):text.index("</table>")]
    for v, pl in zip(found, tube["plans"]):
        assert pl["tolerance_rad"] == v["tolerance_rad"] > 0
        assert pl["lower_bound_m"] == v["clearance"]["lower_bound_m"]
        assert pl["margin_m"] == 2 * tube["lipschitz_m_per_rad"] * pl["tolerance_rad"]
        # The tolerance is the largest on its 1e-6 grid under the lemma's premise c > 2 L delta.
        assert 0 < pl["lower_bound_m"] - pl["margin_m"] < (
            2 * tube["lipschitz_m_per_rad"] * 1e-6 + 1e-9)
        assert f'<td class="n">{pl["tolerance_rad"]:.6f}</td>' in table
        assert f"{1000 * pl['margin_m']:.2f} mm" in table
        assert f"{500 * pl['margin_m']:.2f} mm" in table           # L delta, at the farthest point
    # The table says what the condition is and why c - 2 L delta is small.
    assert "The condition is c − 2 L δ &gt; 0, and δ is\nchosen as large as it allows" in text
    assert "c − 2 L δ (must be &gt; 0)" in table
    assert tube["plans"][1]["same_path_as"] == "modified"
    assert f'id="tube-{s["name"]}"' in html and f'id="{tube["figure"]["id"]}"' in html
    assert report["result"].figures[tube["figure"]["id"]].png[:4] == b"\x89PNG"
    item = _item(doc, "tolerance tubes agree with certify")
    assert item["ok"] is True and "2 found plans" in item["detail"]
    assert doc["verdict"]["ok"] is True, doc["verdict"]


def test_the_monitored_run_comes_between_the_scenarios_and_the_campaign(report):
    html = report["html"]
    marks = ['id="scenarios"', 'id="tube-tiny-default"', 'id="monitor"',
             'id="monitor-tiny-default"', 'id="fig-monitor-tiny-default"', 'id="compare"']
    where = [html.index(m) for m in marks]
    assert where == sorted(where)
    assert '<a href="#monitor">' in html


def test_tube_numbers_agree_with_cfmpa_plan_and_certify(report, tiny_file, tmp_path):
    # `cfmpa plan` of the same workcell (the modified variant), then `cfmpa certify` on the
    # traj.csv it writes: the report shows the same tolerance and proved bound.
    plan_dir = tmp_path / "plan"
    assert cli.main(["plan", str(tiny_file), "--out", str(plan_dir)]) == 0
    plan = json.loads((plan_dir / "plan.json").read_text())
    cert_json = tmp_path / "certify.json"
    assert cli.main(["certify", str(tiny_file), "--traj", str(plan_dir / "traj.csv"),
                     "--json", str(cert_json)]) == 0
    cert = json.loads(cert_json.read_text())
    (s,) = report["doc"]["scenarios"]
    pl = next(p for p in s["tube"]["plans"] if p["variant"] == "modified")
    assert plan["tolerance_rad"] == cert["tolerance_rad"] == pl["tolerance_rad"]
    assert pl["certify"]["tolerance_rad"] == cert["tolerance_rad"]
    assert pl["lower_bound_m"] == plan["clearance"]["lower_bound_m"]
    assert pl["certify"]["lower_bound_m"] == cert["lower_bound_m"]
    assert abs(cert["lower_bound_m"] - pl["lower_bound_m"]) <= _audit.BOUND_AGREEMENT_M
    assert pl["certify"]["rows"] == cert["trajectory"]["rows"]
    assert pl["certify"]["intervals"] == cert["intervals"]


# --- the monitored run -------------------------------------------------------------------------

def test_monitored_run_is_inside_and_the_excursion_outside_at_its_time(report):
    # The audited workcell's run (tiny-default), not the bundled default's.
    assert report["doc"]["monitor"]["available"] is True
    mon = _mon(report["doc"])
    assert mon["available"] and (mon["scenario"], mon["variant"]) == ("tiny-default", "modified")
    (s,) = report["doc"]["scenarios"]
    (planned,) = [v for v in s["variants"] if v["variant"] == "modified"]
    assert mon["tolerance_rad"] == mon["plan_tolerance_rad"] == planned["tolerance_rad"] > 0
    # Its tube is wide enough for the settings as they are (monitor_settings: not scaled).
    assert mon["simulation"] == MONITOR_SIMULATION
    tracking, excursion = mon["runs"]
    t_end = mon["trajectory"]["t_end_s"] + MONITOR_SIMULATION["tail_s"]
    samples = round(t_end / MONITOR_SIMULATION["period_s"]) + 1
    res = tracking["result"]
    assert (res["status"], res["outside"], res["samples"]) == ("inside", 0, samples)
    assert 0 < res["max_deviation_rad"] <= res["tolerance_rad"] == mon["tolerance_rad"]
    assert res["first_outside_t"] is None and res["contact"] is None
    res = excursion["result"]
    # The excursion at least 2 tol (here wider than MONITOR_EXCURSION's), at its time.
    assert excursion["excursion"] == {**MONITOR_EXCURSION, "rad": 2 * mon["tolerance_rad"]}
    assert excursion["excursion"]["rad"] > MONITOR_EXCURSION["rad"]
    assert res["status"] == "outside" and res["samples"] == samples
    # Flagged at the excursion's first sample (t = 0.6 s is on the 1 ms grid: line 602), on its
    # joint, and only in its window [0.6, 0.65] s: 51 samples.
    assert res["first_outside_t"] == MONITOR_EXCURSION["t_s"] == 0.6
    assert res["first_outside_line"] == 2 + 600
    assert res["first_outside_joint"] == "right1" and res["outside"] == 51
    assert res["first_outside_deviation_rad"] > (excursion["excursion"]["rad"]
                                                 - tracking["result"]["max_deviation_rad"])
    assert res["contact"]["in_contact"] is False
    assert excursion["expected"] == {"status": "outside", "first_outside_t": 0.6,
                                     "first_outside_joint": "right1", "outside": 51}
    assert monitor_problems(mon) == []
    item = _item(report["doc"], "monitored run as expected")
    assert item["ok"] is True and item["detail"].startswith("tiny-default (modified plan): ")
    assert "default" not in item["detail"].removeprefix("tiny-default")
    html = report["html"]
    sect = html[html.index('id="monitor"'):html.index('id="compare"')]
    assert "t = 0.6 s (line 602), right1 off by" in sect
    assert f'{res["samples"]}</td><td class="n">0</td>' in sect
    assert f'{res["samples"]}</td><td class="n">51</td>' in sect
    assert "badge ok\">inside" in sect and "badge bad\">outside" in sect


def test_monitored_run_matches_cfmpa_simulate_and_monitor(report, tiny_file, tiny_plan,
                                                           tmp_path):
    # The same logs written by `cfmpa simulate` and read back by `cfmpa monitor`, with the
    # settings the report records.
    mon = _mon(report["doc"])
    sim = mon["simulation"]
    common = ["--lag", str(sim["lag_s"]), "--noise", str(sim["noise_rad"]), "--seed",
              str(sim["seed"]), "--period", str(sim["period_s"]), "--tail", str(sim["tail_s"])]
    exc = mon["runs"][1]["excursion"]
    traj = str(tiny_plan / "traj.csv")
    excursion = f"{exc['t_s']!r}:{exc['joint']}:{exc['rad']!r}:{exc['duration_s']!r}"
    for run, extra, code in zip(mon["runs"], ([], ["--excursion", excursion]), (0, 1)):
        log, out = tmp_path / f"{run['name']}.csv", tmp_path / f"{run['name']}.json"
        assert cli.main(["simulate", str(tiny_file), "--traj", traj, "--out", str(log),
                         *common, *extra]) == 0
        assert cli.main(["monitor", str(tiny_file), "--traj", traj, "--log", str(log),
                         "--json", str(out)]) == code
        got = json.loads(out.read_text())
        assert {k: got[k] for k in run["result"]} == run["result"], run["name"]


# --- seeded faults --------------------------------------------------------------------------------

def test_a_corrupted_tolerance_fails_the_consistency_check(report):
    base = copy.deepcopy(report["result"].doc)
    assert tube_problems(base) == []
    # A doubled tolerance in the tube: plan.json and cfmpa certify disagree, and 2 L delta is
    # no longer below the proved clearance.
    doc = copy.deepcopy(base)
    pl = doc["scenarios"][0]["tube"]["plans"][0]
    pl["tolerance_rad"] *= 2
    pl["margin_m"] = 2 * doc["scenarios"][0]["tube"]["lipschitz_m_per_rad"] * pl["tolerance_rad"]
    assert not _schema_errors(json.loads(dumps_json(doc))), "the schema cannot see this one"
    problems = tube_problems(doc)
    assert any("plan.json's tolerance_rad" in p for p in problems), problems
    assert any("cfmpa certify gives tolerance_rad" in p for p in problems), problems
    assert any("Tolerance.tube's premise" in p for p in problems), problems
    _reverdict(doc)
    item = _item(doc, "tolerance tubes agree with certify")
    assert item["ok"] is False and "tiny-default/modified" in item["detail"]
    assert doc["verdict"]["ok"] is False
    text = render_html(AuditResult(doc, report["result"].figures))
    row = text[text.index("tolerance tubes agree with certify"):]
    assert "FAILED" in row[:row.index("</tr>")]
    # The same fault in plan.json's copy alone (variants[].tolerance_rad).
    doc = copy.deepcopy(base)
    doc["scenarios"][0]["variants"][1]["tolerance_rad"] += 1e-6
    told = base["scenarios"][0]["tube"]["plans"][0]["tolerance_rad"]
    tnew = doc["scenarios"][0]["variants"][1]["tolerance_rad"]
    assert tube_problems(doc) == [
        f"tiny-default/modified: plan.json's tolerance_rad {tnew!r}, the tube's {told!r}"]
    # A margin that is not 2 L delta.
    doc = copy.deepcopy(base)
    doc["scenarios"][0]["tube"]["plans"][1]["margin_m"] /= 2
    assert any("is not 2 L delta" in p for p in tube_problems(doc))
    # A found plan without its tube.
    doc = copy.deepcopy(base)
    doc["scenarios"][0]["tube"]["plans"].pop()
    assert tube_problems(doc) == ["tiny-default/tight: no tube entry"]


def test_the_schema_rejects_a_negative_or_missing_tolerance(report):
    doc = json.loads(dumps_json(report["result"].doc))
    bad = copy.deepcopy(doc)
    bad["scenarios"][0]["tube"]["plans"][0]["tolerance_rad"] = -0.005
    assert any("tolerance_rad" in e and "minimum" in e for e in _schema_errors(bad))
    bad = copy.deepcopy(doc)
    del bad["scenarios"][0]["variants"][1]["tolerance_rad"]
    assert any("'tolerance_rad' is a required property" in e for e in _schema_errors(bad))
    bad = copy.deepcopy(doc)
    bad["monitor"]["workcells"][0]["runs"][0]["result"]["status"] = "maybe"
    assert _schema_errors(bad)


def test_a_log_outside_the_tube_is_reported_outside(report, tiny_file, monkeypatch):
    # A tracking model far noisier than the tube (the settings' scaling to the tube bypassed):
    # the "tracking" log is outside, and the report says so instead of calling the run inside.
    tol = _mon(report["doc"])["tolerance_rad"]
    settings = _audit.monitor_settings

    def noisy(s, traj, tol):
        sim, exc = settings(s, traj, tol)
        return {**sim, "noise_rad": 3 * tol}, exc

    monkeypatch.setattr(_audit, "monitor_settings", noisy)
    whole = _monitor([load_scenario(tiny_file)], _Plans("off"), {})
    (mon,) = whole["workcells"]
    tracking = mon["runs"][0]["result"]
    assert tracking["status"] == "outside" and tracking["outside"] > 0
    assert tracking["max_deviation_rad"] > tol
    assert tracking["first_outside_t"] < MONITOR_EXCURSION["t_s"]
    problems = monitor_problems(mon)
    assert "tracking: status 'outside', expected 'inside'" in problems
    # The excursion's log is now first outside before the excursion: also not as expected.
    assert any(p.startswith("excursion: first_outside_t") for p in problems), problems
    doc = copy.deepcopy(report["result"].doc)
    doc["monitor"] = whole
    _reverdict(doc)
    item = _item(doc, "monitored run as expected")
    assert item["ok"] is False and "tiny-default (modified plan): tracking: outside" in (
        item["detail"])
    assert doc["verdict"]["ok"] is False


def test_a_flag_at_the_wrong_instant_is_not_as_expected(report):
    mon = copy.deepcopy(_mon(report["doc"]))
    res = mon["runs"][1]["result"]
    res["first_outside_t"] += MONITOR_SIMULATION["period_s"]
    res["first_outside_joint"] = "left1"
    assert monitor_problems(mon) == [
        f"excursion: first_outside_t {res['first_outside_t']!r}, expected 0.6",
        "excursion: first_outside_joint 'left1', expected 'right1'"]


def test_no_workcell_leaves_the_monitored_run_not_available(report):
    mon = _monitor([], _Plans("off"), {})
    assert mon["available"] is False and mon["workcells"] == []
    assert mon["note"] == "not available in this run: no workcell audited"
    doc = copy.deepcopy(report["result"].doc)
    doc["monitor"] = mon
    _reverdict(doc)
    assert _item(doc, "monitored run as expected")["ok"] is None
    assert doc["verdict"]["ok"] is True
    assert not _schema_errors(json.loads(dumps_json(doc)))
    text = render_html(AuditResult(doc, report["result"].figures))
    assert '<p class="unavailable">not available in this run: no workcell audited' in text
