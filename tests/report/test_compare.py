"""`cfmpa compare` as printed and written: honest counts in compare.json, the table, a recorded
campaign shown by the report (the workcells themselves: tests/runs/test_campaign_workcells.py)."""

from __future__ import annotations

import json

import pytest

from cfmpa.report import run_compare
from cfmpa.report._compare import campaign_json
from cfmpa.runs import load_campaign, run_campaign
from cfmpa.spec import Variant

SEED = 11


@pytest.fixture(scope="module")
def campaign():
    return run_campaign(6, SEED)


def test_table_counts_agree_with_the_cases(campaign):
    doc = campaign_json(campaign)
    found = {v: [x.found(v) for x in campaign.cases] for v in Variant}
    for row in doc["table"]:
        v = Variant(row["variant"])
        assert row["found"] == sum(found[v])
        assert row["success_rate"] == sum(found[v]) / campaign.n
    assert doc["original_fails_modified_succeeds"] == sum(
        m and not o for o, m in zip(found[Variant.ORIGINAL], found[Variant.MODIFIED]))
    # The corrected Property 8 predicts these counts; the campaign measures them.
    assert doc["checks_ok"] and not any(doc["checks"].values())
    json.dumps(doc, allow_nan=False)


def test_run_compare_prints_the_table_and_writes_json(tmp_path, capsys):
    assert run_compare(n=3, seed=SEED, out=str(tmp_path)) == 0
    text = capsys.readouterr().out
    assert "original fails, modified succeeds" in text and "checks    all hold" in text
    doc = json.loads((tmp_path / "compare.json").read_text())
    assert doc["n"] == 3 and doc["seed"] == SEED and len(doc["cases"]) == 3


def test_a_recorded_campaign_reads_back_to_the_same_compare_json(tmp_path, capsys):
    from cfmpa.report._audit import _compare

    assert run_compare(n=3, seed=SEED, out=str(tmp_path)) == 0
    capsys.readouterr()
    written = json.loads((tmp_path / "compare.json").read_text())
    store = (tmp_path / "compare.jsonl").read_bytes()
    back = campaign_json(load_campaign(tmp_path))
    drop = {"timings_s", "reused"}
    assert {k: v for k, v in back.items() if k not in drop} == \
        {k: v for k, v in written.items() if k not in drop}
    assert (tmp_path / "compare.jsonl").read_bytes() == store          # read, not written
    figures: dict = {}
    part = _compare(0, 0, figures, load_campaign(tmp_path), tmp_path)
    assert part["available"] and part["n"] == 3 and "recorded in" in part["note"]
    assert part["table"] == written["table"] and set(figures) == {"fig-compare", "fig-compare-rate"}


def test_audit_with_a_campaign_folder_that_holds_none_is_exit_2(tmp_path, capsys):
    from cfmpa.cli import main

    rc = main(["audit", "--campaign", str(tmp_path / "nowhere"), "--out", str(tmp_path / "r")])
    err = capsys.readouterr().err
    assert rc == 2 and "compare.jsonl" in err and "Traceback" not in err
    assert not (tmp_path / "r").exists()
