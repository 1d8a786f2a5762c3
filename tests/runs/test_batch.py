"""`cfmpa check --batch DIR [SCENARIO]`: one task per plan folder, one table, one JSON; exit 0
when every plan passes, 1 when any fails or cannot be checked, 2 for a bad batch."""

from __future__ import annotations

import json
import shutil
from pathlib import Path

import pytest

import factory
from cfmpa.cli import main
from cfmpa.errors import InputError
from cfmpa.runs import run_batch
from cfmpa.runs._batch import BATCH_JSON, find_plan_folders
from cfmpa.runs._plan import plan, write_plan
from cfmpa.runs._selftest import WORKCELLS
from cfmpa.spec import load_scenario


@pytest.fixture(scope="module")
def plans(tmp_path_factory):
    """A scenario file and a folder of plan folders: three good ones (one nested), one with a
    misreported cost, one without its dr.npy."""
    d = tmp_path_factory.mktemp("batch")
    (d / "small.toml").write_text(factory.toml(WORKCELLS["small"]))
    s = load_scenario(d / "small.toml")
    root = d / "plans"
    for name, variant in (("a-modified", "modified"), ("b-original", "original"),
                          ("nested/c-tight", "tight")):
        write_plan(plan(s, variant, contracts="off"), root / name)
    shutil.copytree(root / "a-modified", root / "d-costs")
    doc = json.loads((root / "d-costs" / "plan.json").read_text())
    doc["J1"] += 1
    (root / "d-costs" / "plan.json").write_text(json.dumps(doc))
    (root / "e-no-dr").mkdir()
    shutil.copy(root / "a-modified" / "plan.json", root / "e-no-dr" / "plan.json")
    return d


def _good_only(plans: Path, tmp_path: Path) -> Path:
    root = tmp_path / "good"
    for name in ("a-modified", "b-original", "nested/c-tight"):
        shutil.copytree(plans / "plans" / name, root / name)
    return root


def test_plan_folders_are_found_at_any_depth_sorted(plans):
    root = plans / "plans"
    assert [p.relative_to(root).as_posix() for p in find_plan_folders(root)] == [
        "a-modified", "b-original", "d-costs", "e-no-dr", "nested/c-tight"]


@pytest.mark.parametrize("command", [["check-batch"], ["check", "--batch"]],
                         ids=["check-batch", "old spelling check --batch"])
def test_a_batch_lists_every_plan_and_exits_1_when_one_fails(plans, tmp_path, capsys, command):
    out = tmp_path / "summary.json"
    code = main([*command, str(plans / "plans"), str(plans / "small.toml"),
                 "--workers", "0", "--json", str(out)])
    text = capsys.readouterr().out
    assert code == 1
    doc = json.loads(out.read_text())
    assert not (plans / "plans" / BATCH_JSON).exists()          # --json puts it elsewhere
    rows = {r["folder"]: r for r in doc["rows"]}
    assert [r["folder"] for r in doc["rows"]] == sorted(rows)
    assert {k: r["status"] for k, r in rows.items()} == {
        "a-modified": "ok", "b-original": "ok", "nested/c-tight": "ok", "d-costs": "FAIL",
        "e-no-dr": "error"}
    assert (doc["plans"], doc["passed"], doc["failed"], doc["errors"], doc["ok"]) == (
        5, 3, 1, 1, False)
    (failed,) = rows["d-costs"]["failed"]
    assert "post.costs: the reported costs are not the path's" in failed
    assert "dr cannot be read" in rows["e-no-dr"]["message"]
    assert rows["nested/c-tight"]["variant"] == "tight" and rows["a-modified"]["checks"] > 10
    for folder in rows:
        assert any(line.startswith(folder) for line in text.splitlines()), folder
    assert "result: 3 of 5 plans pass, 1 fail, 1 could not be checked" in text


def test_a_batch_of_good_plans_passes_on_a_local_cluster(plans, tmp_path, capsys):
    """The same checks as tasks of a local Dask cluster (one worker: a few seconds to start)."""
    root = _good_only(plans, tmp_path)
    assert run_batch(root, plans / "small.toml", workers=1) == 0
    text = capsys.readouterr().out
    assert "local Dask cluster, 1 worker process(es)" in text
    doc = json.loads((root / BATCH_JSON).read_text())
    assert doc["ok"] and doc["passed"] == 3 and all(r["status"] == "ok" for r in doc["rows"])
    serial = tmp_path / "serial.json"
    assert run_batch(root, plans / "small.toml", json_out=serial) == 0

    def strip(d: dict) -> dict:
        return {k: v for k, v in d.items() if k != "timings_s"}

    assert strip(json.loads(serial.read_text())) == strip(doc)


def test_without_scenario_each_plan_names_its_bundled_one(plans, tmp_path, capsys):
    root = tmp_path / "named"
    for folder, name in (("bundled", "narrow-gap"), ("unknown", "not-bundled")):
        shutil.copytree(plans / "plans" / "a-modified", root / folder)
        doc = json.loads((root / folder / "plan.json").read_text())
        doc["scenario"] = name
        (root / folder / "plan.json").write_text(json.dumps(doc))
    assert main(["check", "--batch", str(root), "--workers", "0"]) == 1
    rows = {r["folder"]: r for r in json.loads((root / BATCH_JSON).read_text())["rows"]}
    # Found among the bundled scenarios and checked against it (the small plan's D_R has the
    # wrong shape for narrow-gap, so it fails: the scenario was the bundled one).
    assert rows["bundled"]["scenario"] == "narrow-gap" and rows["bundled"]["status"] == "FAIL"
    assert any("post.shape" in f for f in rows["bundled"]["failed"])
    assert rows["unknown"]["status"] == "error"
    assert "scenario is not a bundled scenario" in rows["unknown"]["message"]
    assert "got 'not-bundled'" in rows["unknown"]["message"]


@pytest.mark.parametrize("args, field", [
    # cfmpa check-batch, and its old spelling cfmpa check --batch (docs/model.md §7.3).
    (["check-batch", "{missing}"], "DIR"),
    (["check-batch", "{empty}"], "DIR"),
    (["check-batch", "{plans}", "{missing}.toml"], "scenario"),
    (["check-batch", "{plans}", "--workers", "1", "--scheduler", "tcp://127.0.0.1:8786"],
     "--workers"),
    (["check-batch", "{plans}", "--scheduler", "nonsense"], "--scheduler"),
    (["check", "--batch", "{missing}"], "--batch"),
    (["check", "--batch", "{empty}"], "--batch"),
    (["check", "--batch", "{plans}", "{missing}.toml"], "scenario"),
    (["check", "--batch", "{plans}", "--dr", "x.npy"], "--dr"),
    (["check", "--batch", "{plans}", "--workers", "1", "--scheduler", "tcp://127.0.0.1:8786"],
     "--workers"),
    (["check", "--batch", "{plans}", "--scheduler", "nonsense"], "--scheduler"),
    (["check", "{small}", "--plan", "p.json"], "--dr"),
    (["check", "{small}", "--dr", "d.npy", "--plan", "p.json", "--workers", "2"], "--workers"),
])
def test_bad_batch_input_is_exit_2_before_any_task(plans, tmp_path, capsys, args, field):
    (tmp_path / "empty").mkdir()
    subst = {"missing": str(tmp_path / "missing"), "empty": str(tmp_path / "empty"),
             "plans": str(plans / "plans"), "small": str(plans / "small.toml")}
    code = main([a.format(**subst) for a in args])
    err = capsys.readouterr().err
    assert code == 2 and f"error: {field}" in err and "Traceback" not in err, err
    assert not (plans / "plans" / BATCH_JSON).exists()


def test_run_batch_refuses_a_file_as_the_folder(plans):
    with pytest.raises(InputError, match="DIR must be a folder of plan folders"):
        run_batch(plans / "small.toml")
