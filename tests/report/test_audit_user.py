"""Audits of the user's own workcells: the per-scenario obligations shown are exactly
those of the files reported on, a results.json must cover them, and a failing one fails the
report with its row named.
"""

from __future__ import annotations

import io
import json
import shutil
from pathlib import Path

import pytest

import factory
from cfmpa import cli
from cfmpa.errors import InputError
from cfmpa.proofs import FIXED_IDS, CheckOutcome, run_prove
from cfmpa.report import build_audit
from cfmpa.report._audit import _proofs_of_this_tree
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
