"""Honest scope (docs/model.md §10): where a workcell has a tool or heights, `cfmpa plan` (its
summary and plan.json) and `cfmpa prove --scenarios` (each of the workcell's obligations, printed
and in results.json) say that the safety theorem does not yet cover them; ``default`` says
nothing of the kind."""

from __future__ import annotations

import io
import json

import pytest

from cfmpa.proofs import run_prove
from cfmpa.runs import run_plan
from cfmpa.scenarios import BUNDLED_DIR
from cfmpa.spec._scope import SCOPE_CHECKED

#: The theorem covers tools and heights (docs/model.md §10 (e)): no workcell carries a label.
SCOPES = {"gripper": None, "levels": None, "default": None}
assert SCOPE_CHECKED


@pytest.mark.parametrize("name", list(SCOPES))
def test_plan_says_the_scope_on_the_workcells_summary_and_json(name, tmp_path):
    out = io.StringIO()
    assert run_plan(BUNDLED_DIR / f"{name}.toml", "modified", tmp_path, contracts="off",
                    stdout=out, stderr=io.StringIO()) == 0
    doc = json.loads((tmp_path / "plan.json").read_text())
    assert doc["status"] == "found" and doc["clearance"]["clear"] is True
    assert doc["theorem_scope"] == SCOPES[name]
    lines = out.getvalue().splitlines()
    scoped = [x for x in lines if x.startswith("scope ")]
    if SCOPES[name] is None:
        assert scoped == [] and "safety theorem" not in out.getvalue()
    else:
        assert scoped == [f"scope     {SCOPES[name]}"]
        # Right after the certificate's line, which it qualifies.
        assert lines[lines.index(scoped[0]) - 1].startswith("clearance clear: proved >= ")


def test_prove_labels_each_obligation_of_a_workcell_with_a_tool_or_heights(tmp_path):
    only = [f"Scenario.{name}.time_grid" for name in SCOPES]
    stream = io.StringIO()
    assert run_prove(out_dir=tmp_path, scenarios_dir=BUNDLED_DIR, only=only, stream=stream) == 0
    printed = {line.split()[0]: line for line in stream.getvalue().splitlines()
               if line.startswith("Scenario.")}
    results = {o["id"]: o for o in json.loads((tmp_path / "results.json").read_text())[
        "obligations"] if o["change"] != "not run"}
    assert set(printed) == set(results) == set(only)
    for name, scope in SCOPES.items():
        ident = f"Scenario.{name}.time_grid"
        assert "checked on data" in printed[ident]         # never a bare "proved"
        if scope is None:
            assert results[ident]["label"] == "" and "safety theorem" not in printed[ident]
        else:
            assert results[ident]["label"] == scope and printed[ident].endswith(scope)


def test_prove_keeps_the_every_cell_label_beside_the_scope():
    from cfmpa.proofs import scenario_obligations

    obs = {o.id: o for o in scenario_obligations([BUNDLED_DIR / "gripper.toml",
                                                  BUNDLED_DIR / "default.toml"])}
    assert obs["Scenario.gripper.translation_modified"].label == "every cell"
    assert obs["Scenario.default.translation_modified"].label == "every cell"
    assert not any("safety theorem" in o.label for o in obs.values())
