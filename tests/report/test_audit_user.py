"""Audits of the user's own workcells: the per-scenario obligations shown are exactly
those of the files reported on, a results.json must cover them, and a failing one fails the
report with its row named; the monitored runs are of the audited workcells (or say why a
workcell has none); "proof results are of this tree" is never ok without a known commit.
"""

from __future__ import annotations

import copy
import io
import json
import math
import shutil
from pathlib import Path

import pytest

import factory
from cfmpa import cli
from cfmpa.errors import InputError
from cfmpa.proofs import FIXED_IDS, CheckOutcome, run_prove
from cfmpa.report import build_audit, run_audit
from cfmpa.report._audit import (
    MONITOR_MAX_SAMPLES,
    MONITOR_SIMULATION,
    _proofs_of_this_tree,
    _verdict,
    monitor_settings,
)
from cfmpa.report._obligations import audited_ids, load_proofs

ROOT = Path(__file__).resolve().parents[2]
CHECKS = ("time_grid", "cspace_grid", "margin_side", "containment",
          "translation_original", "translation_modified", "translation_tight")
MINE = [f"Scenario.mine.{c}" for c in CHECKS]


@pytest.fixture
def mine(tmp_path: Path) -> Path:
    """A coarse workcell outside the bundled set, with a joint on the rounding boundary."""
    doc = factory.doc(dt=0.04, right__omega=[5.0, 5.0],
                      right__limits=[[0.0, 3.0], [0.0, 3.0]],
                      right__start_cell=[2, 3], right__goal_cell=[14, 13])
    doc["name"] = "mine"
    d = tmp_path / "user"
    d.mkdir()
    p = d / "mine.toml"
    p.write_text(factory.toml(doc))
    return p


def _no_fixed(monkeypatch: pytest.MonkeyPatch) -> None:
    """Stub the scenario-independent obligations (Z3, minutes) out of a fresh run."""
    import cfmpa.proofs as proofs
    monkeypatch.setattr(proofs, "collect_obligations", lambda *a, **k: ())


def test_audited_ids_are_the_fixed_ones_then_four_per_file(mine: Path) -> None:
    assert audited_ids([mine]) == FIXED_IDS + tuple(MINE)


def test_a_fresh_run_discharges_the_files_own_checks(mine: Path, monkeypatch) -> None:
    _no_fixed(monkeypatch)
    data = load_proofs(None, ROOT / "scenarios", files=[mine])
    assert [r.id for r in data.rows] == MINE
    assert all(r.verdict == "proved" for r in data.rows), [r.reason for r in data.rows]
    assert data.missing_ids == FIXED_IDS and not data.unexpected_ids
    assert not any(r.id.startswith("Scenario.default.") for r in data.rows)


def _failing_cspace(s):  # a seeded fault: the check's source is hashed, so it is a function
    return CheckOutcome(False, "seeded fault", "seeded fault")


def test_a_failing_check_of_the_users_file_is_a_failed_row(mine: Path, monkeypatch) -> None:
    import cfmpa.proofs._obl_scenario as obl
    _no_fixed(monkeypatch)
    monkeypatch.setattr(obl, "_cspace_grid", _failing_cspace)
    data = load_proofs(None, ROOT / "scenarios", files=[mine])
    verdicts = {r.id: r.verdict for r in data.rows}
    assert verdicts["Scenario.mine.cspace_grid"] == "failed"
    assert verdicts["Scenario.mine.time_grid"] == "proved"


def test_results_json_rows_of_other_workcells_are_left_out_and_named(mine: Path,
                                                                        tmp_path: Path) -> None:
    folder = mine.parent
    shutil.copy(ROOT / "scenarios" / "early-arrival.toml", folder / "early-arrival.toml")
    out = tmp_path / "proofs"
    rc = run_prove(out_dir=out, scenarios_dir=folder,
                   only=["Scenario.mine.time_grid", "Scenario.mine.cspace_grid",
                         "Scenario.early-arrival.time_grid"], stream=io.StringIO())
    assert rc == 0
    data = load_proofs(str(out / "results.json"), ROOT / "scenarios", files=[mine])
    assert [r.id for r in data.rows] == ["Scenario.mine.time_grid", "Scenario.mine.cspace_grid"]
    assert "left out" in data.note and "early-arrival" in data.note
    # --proofs must cover the file's ids: those not run are missing.
    assert set(data.missing_ids) == set(FIXED_IDS) | {f"Scenario.mine.{c}" for c in CHECKS[2:]}
    assert data.run is not None and "mine.toml" in data.run["scenarios"]


def test_a_results_json_without_the_files_hash_does_not_pass() -> None:
    ob = {"available": True, "source": "read from x", "run": {"git": {"commit": "c"},
          "scenarios": {"other.toml": "ab"}}, "not_run": [],
          "items": [{"id": "Scenario.mine.time_grid"}]}
    prov = {"git": {"commit": "c"}, "scenarios": [{"path": "/x/mine.toml", "sha256": "cd"}]}
    item = _proofs_of_this_tree(ob, prov)
    assert item["ok"] is False and "records no hash for mine.toml" in item["detail"]
    ob["run"]["scenarios"]["mine.toml"] = "cd"
    assert _proofs_of_this_tree(ob, prov)["ok"] is True


def test_two_files_with_the_same_stem_are_refused(mine: Path, tmp_path: Path) -> None:
    other = tmp_path / "elsewhere"
    other.mkdir()
    shutil.copy(mine, other / "mine.toml")
    with pytest.raises(InputError) as info:
        build_audit([str(mine), str(other / "mine.toml")], compare_n=0)
    assert info.value.field == "scenarios" and "same stem 'mine'" in str(info.value)


@pytest.mark.slow
def test_cfmpa_audit_on_a_users_workcell_shows_and_fails_on_its_checks(mine: Path,
                                                                          tmp_path: Path,
                                                                          monkeypatch) -> None:
    out = tmp_path / "audit"
    code = cli.main(["audit", str(mine), "--out", str(out), "--compare-n", "0"])
    doc = json.loads((out / "report.json").read_text())
    ids = [r["id"] for r in doc["obligations"]["items"]]
    assert [i for i in ids if i.startswith("Scenario.")] == MINE
    rows = {r["id"]: r for r in doc["obligations"]["items"]}
    assert all(rows[i]["verdict"] == "proved" for i in MINE), [rows[i] for i in MINE]
    item = next(i for i in doc["verdict"]["items"] if i["check"] == "obligations as expected")
    assert "Scenario." not in item["detail"]
    assert code == 0, doc["verdict"]

    import cfmpa.proofs._obl_scenario as obl
    monkeypatch.setattr(obl, "_cspace_grid", _failing_cspace)
    out2 = tmp_path / "audit2"
    code = cli.main(["audit", str(mine), "--out", str(out2), "--compare-n", "0"])
    doc = json.loads((out2 / "report.json").read_text())
    assert code == 1
    item = next(i for i in doc["verdict"]["items"] if i["check"] == "obligations as expected")
    assert item["ok"] is False and "Scenario.mine.cspace_grid" in item["detail"]


# --- the monitored runs are of the audited workcells (docs/model.md §8) -------------------------

def test_the_audit_monitors_each_audited_workcell_and_names_it(mine: Path, tmp_path: Path,
                                                               monkeypatch) -> None:
    # Two user files in a folder of their own (so no bundled workcell is planned: the findings
    # say they are not available): `mine` has a modified path, `blocked` none (the subordinate's
    # base on the principal's, its start in contact). One small prove run is reused (--proofs).
    blocked = factory.doc(right__base=[0.05, 0.0])
    blocked["name"] = "blocked"
    (mine.parent / "blocked.toml").write_text(factory.toml(blocked))
    proofs = tmp_path / "proofs"
    assert run_prove(out_dir=proofs, scenarios_dir=mine.parent,
                     only=["Scenario.mine.time_grid"], stream=io.StringIO()) == 0
    # Parts this test does not look at, left out for speed: the mutation self-check (a run of
    # its own) and the per-scenario pictures (the tube's and the monitor's are still drawn).
    import cfmpa.report._audit as audit
    monkeypatch.setattr(audit, "load_selftest", lambda: {
        "available": False, "rows": [], "source": "left out by this test", "note": ""})
    monkeypatch.setattr(audit, "_scenario_figures", lambda *a, **k: [])
    out, printed = tmp_path / "audit", io.StringIO()
    run_audit([str(mine), str(mine.parent / "blocked.toml")], str(out), compare_n=0,
              proofs_json=str(proofs / "results.json"), scenarios_dir=str(mine.parent),
              stdout=printed)
    doc = json.loads((out / "report.json").read_text())
    mon = doc["monitor"]
    assert mon["available"] is True
    shown, none = mon["workcells"]
    assert (shown["scenario"], shown["variant"], shown["available"]) == ("mine", "modified", True)
    (planned,) = [v for v in doc["scenarios"][0]["variants"] if v["variant"] == "modified"]
    assert shown["tolerance_rad"] == planned["tolerance_rad"] > 0
    (tube,) = [pl for pl in doc["scenarios"][0]["tube"]["plans"] if pl["variant"] == "modified"]
    assert shown["trajectory"]["rows"] == tube["certify"]["rows"]      # the plan's traj.csv
    tracking, excursion = shown["runs"]
    assert tracking["result"]["status"] == "inside" and tracking["result"]["outside"] == 0
    assert excursion["result"]["status"] == "outside"
    assert excursion["result"]["first_outside_t"] == excursion["expected"]["first_outside_t"]
    # `blocked`: no path, said so.
    assert none == {"available": False, "scenario": "blocked",
                    "note": none["note"]} and none["note"].startswith("no modified path was found")
    # The verdict row names each workcell, in the JSON and as `cfmpa audit` prints it.
    (item,) = [i for i in doc["verdict"]["items"] if i["check"] == "monitored run as expected"]
    assert item["ok"] is True
    assert item["detail"].startswith("mine (modified plan): tracking: inside, 0 of "
                                     f"{tracking['result']['samples']} samples outside; "
                                     "excursion: outside, ")
    assert " | blocked: none (no modified path was found" in item["detail"]
    assert "default" not in item["detail"]
    (line,) = [ln for ln in printed.getvalue().splitlines()
               if ln.startswith("monitored run as expected")]
    assert "ok: mine (modified plan): tracking: inside" in line
    html = (out / "report.html").read_text()
    sect = html[html.index('id="monitor"'):html.index('id="compare"')]
    assert 'id="monitor-mine"' in sect and 'id="fig-monitor-mine"' in sect
    assert 'id="monitor-blocked"' in sect and "No monitored run of blocked: no modified path" in sect
    assert "plan of default" not in sect
    # A seeded fault: mine's tracking log outside fails the row, and the row says whose.
    bad = copy.deepcopy(doc)
    bad["monitor"]["workcells"][0]["runs"][0]["result"]["status"] = "outside"
    (item,) = [i for i in _verdict(bad)["items"] if i["check"] == "monitored run as expected"]
    assert item["ok"] is False
    assert "mine (modified plan): tracking: outside" in item["detail"]
    assert "not as expected: tracking: status 'outside', expected 'inside'" in item["detail"]


def test_a_narrow_tube_scales_the_simulation_to_fit_it() -> None:
    from cfmpa.runs import parse_max_speed, plan
    from cfmpa.spec import ReferenceSpeeds, executed_trajectory

    s = factory.scenario(dt=0.04, right__omega=[5.0, 5.0], right__limits=[[0.0, 3.0], [0.0, 3.0]],
                         right__start_cell=[2, 3], right__goal_cell=[14, 13])
    p = plan(s, "modified", contracts="off")
    traj = executed_trajectory(s, p.grid, p.search.path)
    w_ref = float(ReferenceSpeeds.of(traj).top().max())
    w_robot = float(parse_max_speed(None, s, traj).max())

    def worst(sim):
        return sim["noise_rad"] + sim["lag_s"] * w_ref + (w_robot + w_ref) * sim["period_s"] / 2

    wide, exc = monitor_settings(s, traj, 1.0)
    assert wide == MONITOR_SIMULATION and exc["rad"] == 2.0       # as they are; rad >= 2 tol
    assert worst(MONITOR_SIMULATION) > 0.002 / 2                   # too wide for a 2 mrad tube
    sim, exc = monitor_settings(s, traj, 0.002)
    assert math.isclose(worst(sim), 0.001, rel_tol=1e-12)         # half the tube
    assert sim["period_s"] < MONITOR_SIMULATION["period_s"] and exc["rad"] == 0.02
    assert float(traj.t[0]) <= exc["t_s"] <= float(traj.t[-1])
    # Far narrower: the log would exceed the report's budget, and it says so.
    why = monitor_settings(s, traj, 1e-9)
    assert isinstance(why, str) and f"more than the report's {MONITOR_MAX_SAMPLES}" in why


# --- provenance: a commit must be known on both sides (docs/model.md §8) ------------------------

def _tree_check(mine: str | None, theirs: str | None, note: str = "n") -> dict:
    ob = {"available": True, "source": "read from x", "not_run": [],
          "run": {"git": {"commit": theirs, "clean": None}, "scenarios": {"mine.toml": "cd"},
                  "date_utc": "d"}, "items": [{"id": "Scenario.mine.time_grid"}]}
    prov = {"git": {"commit": mine, "note": note},
            "scenarios": [{"path": "/x/mine.toml", "sha256": "cd"}]}
    return _proofs_of_this_tree(ob, prov)


def test_proof_results_without_a_commit_are_unknown_not_ok() -> None:
    c = "a" * 40
    assert _tree_check(c, c)["ok"] is True
    assert _tree_check(c, "b" * 40)["ok"] is False
    # An installed package without a build record and a prove run that recorded none: equal
    # (None == None), yet nothing ties the results to this tree.
    item = _tree_check(None, None, note="site-packages is not the top of a git work tree")
    assert item["ok"] is None and item["detail"].startswith("unknown: ")
    assert "the report's code has no known commit (site-packages is not" in item["detail"]
    assert "results.json records no commit" in item["detail"]
    item = _tree_check(c, None)
    assert item["ok"] is None and "results.json records no commit" in item["detail"]
    assert "the report's code" not in item["detail"]
    item = _tree_check(None, c)
    assert item["ok"] is None and "the report's code has no known commit" in item["detail"]
    # Another problem still fails it, the unknown commit said too.
    ob_bad = _tree_check(None, None)
    assert ob_bad["ok"] is None
    ob = {"available": True, "source": "read from x", "not_run": ["Def1"],
          "run": {"git": {"commit": None}, "scenarios": {"mine.toml": "cd"}}, "items": []}
    prov = {"git": {"commit": None, "note": "n"}, "scenarios": []}
    item = _proofs_of_this_tree(ob, prov)
    assert item["ok"] is False and "carried over" in item["detail"]
    assert "no known commit" in item["detail"]
