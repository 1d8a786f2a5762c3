"""plan() re-decides the found path's cells in ball arithmetic and records it in plan.json; a
cell that cannot be proved free is a violation in every contract mode."""

from __future__ import annotations

import json

import pytest

import factory
from cfmpa.cli import main
from cfmpa.runs import plan, plan_json
from cfmpa.spec import _exact as exact_mod

#: Cells between which a path exists under every variant of the factory workcell.
CELLS = {"right__start_cell": [0, 8], "right__goal_cell": [15, 5]}


def test_a_found_plan_records_its_least_proved_gap():
    p = plan(factory.scenario(**CELLS), "modified")
    doc = plan_json(p)["exact_gaps"]
    assert doc["ok"] is True and doc["undecided"] == []
    assert doc["cells"] == len(p.exact.cells) > len(p.search.path) - 1
    assert doc["least_gap_m"] > 1e-9 and doc["least_gap_m"] == p.exact.least_gap_m
    assert "exact_gaps" in p.timings_s


def test_no_path_no_exact_record():
    s = factory.scenario(right__start_cell=[3, 8], right__goal_cell=[12, 5])
    p = plan(s, "original")
    assert p.exact is None and plan_json(p)["exact_gaps"] is None


@pytest.mark.parametrize("mode", ["off", "sampled"])
def test_a_cell_not_proved_free_is_a_violation_and_exits_1(tmp_path, monkeypatch, mode):
    toml = tmp_path / "w.toml"
    toml.write_text(factory.toml(factory.doc(**CELLS)))
    # A seeded fault in the decision's threshold: eps raised to 1 m, so no cell is proved free.
    monkeypatch.setattr(exact_mod, "EPS", 1.0)
    out = tmp_path / "out"
    assert main(["plan", str(toml), "--out", str(out), "--contracts", mode]) == 1
    doc = json.loads((out / "plan.json").read_text())
    assert doc["exact_gaps"]["ok"] is False
    ids = [v["condition_id"] for v in doc["contracts"]["violations"]]
    assert "exact.path_cells" in ids
    p = plan(factory.scenario(**CELLS), "modified", stop=False)
    assert any(v.condition_id == "exact.path_cells" for v in p.violations)
    with pytest.raises(Exception, match="exact.path_cells"):
        plan(factory.scenario(**CELLS), "modified")
