"""The report on workcells with tools and heights (docs/model.md §8): the safety theorem covers
tools and heights, so their rows read "safe" with no scope label, resting on ledger A13 as well
(a row with a scope would be "certified", never "safe": a planted label shows it); the tolerance
in mm is at the farthest point of either arm (the tool tip); the clearance pictures see the tools.

Built from real plans (modified variant, contracts off) of the bundled gripper, levels and default
workcells, without a whole audit: ``workcell_summary`` and section 1's template directly.
"""

from __future__ import annotations

import json
import re
from pathlib import Path

import jsonschema
import numpy as np
import pytest

from cfmpa.report._audit import template_env, workcell_summary
from cfmpa.report._findings import sample_clearance
from cfmpa.runs import plan, plan_json
from cfmpa.scenarios import BUNDLED_DIR
from cfmpa.spec import Variant, load_scenario, parse_scenario, parts, reach, tube_lipschitz
from cfmpa.spec._scope import SCOPE_CHECKED

SCHEMA = Path(__file__).resolve().parents[2] / "report" / "schema.json"
NAMES = ("gripper", "levels", "default")
SCOPES = {"gripper": None, "levels": None, "default": None}
#: Rows of a workcell with a tool or heights rest on the ledger's A13 too.
A13 = {"gripper": True, "levels": True, "default": False}


@pytest.fixture(scope="module")
def planned():
    out = {}
    for name in NAMES:
        s = load_scenario(BUNDLED_DIR / f"{name}.toml")
        out[name] = (s, plan(s, Variant.MODIFIED, contracts="off"))
    return out


def _summary(planned, complete=None):
    """Section 1's rows of the plans: with every obligation and control each row rests on as
    expected (``complete``: the ``complete_proofs`` fixture), or with no proof data (None)."""
    loaded = [planned[n][0] for n in NAMES]
    entries = []
    for n in NAMES:
        j = plan_json(planned[n][1])
        j["contracts"] = {"mode": "off", "violations": []}
        entries.append({"name": n, "variants": [j]})
    doc = {"obligations": {"available": False, "items": [], "source": "none"},
           "scenarios": entries}
    return workcell_summary(loaded, doc if complete is None else complete(doc, NAMES))


def test_a_workcell_with_a_tool_or_heights_is_safe_by_the_theorem(planned, complete_proofs):
    rows = {r["scenario"]: r for r in _summary(planned, complete_proofs)}
    for name, scope in SCOPES.items():
        r = rows[name]
        assert r["ok"] is True and r["scope"] == scope
        assert r["verdict"] == "safe" and "safety theorem" not in r["why"]
        assert ("A13.tools_and_heights" in r["assumptions"]) == A13[name], r["assumptions"]
    items = json.loads(SCHEMA.read_text())["properties"]["summary"]
    jsonschema.validate(list(rows.values()), items)
    # Without its proofs, no row is certified or safe: each is incomplete, whatever its scope.
    bare = {r["scenario"]: r for r in _summary(planned)}
    for name, scope in SCOPES.items():
        r = bare[name]
        assert (r["ok"], r["verdict"], r["scope"]) == (None, "incomplete", scope), r
        assert "Safety.modified.composition" in r["missing"] and r["why"].startswith(
            scope or "incomplete: it would be safe")
    jsonschema.validate(list(bare.values()), items)


def test_a_scoped_row_would_be_certified_not_safe(planned, complete_proofs, monkeypatch):
    # Seeded: a feature the theorem does not cover (the tool, planted in NOT_COVERED) makes the
    # gripper's row "certified", its why led by the label.
    from cfmpa.report import _audit
    label = f"tool: {SCOPE_CHECKED}"
    monkeypatch.setattr(_audit, "theorem_scope",
                        lambda s: label if s.right.tool is not None else None)
    rows = {r["scenario"]: r for r in _summary(planned, complete_proofs)}
    assert rows["gripper"]["verdict"] == "certified" and rows["gripper"]["why"].startswith(label)
    assert rows["default"]["verdict"] == "safe"


def test_section_one_shows_the_scope_on_the_workcells_row(planned, complete_proofs):
    rows = _summary(planned, complete_proofs)
    html = template_env().get_template("section_summary.html").render(
        doc={"summary": rows, "verdict": {"ok": True, "status": "no failure",
                                          "not_available": []}},
        number={"summary": 1, "provenance": 2, "assumptions": 5})
    body = html.split("<tr", 2)[2]                       # the rows, after the heading's
    cells = {n: body[body.index(f">{n}</a>"):] for n in NAMES}
    for name, scope in SCOPES.items():
        row = cells[name].split("</tr>")[0]
        if scope is None:
            assert 'class="scope"' not in row and 'class="badge ok">safe<' in row
        else:
            assert f'<span class="scope">{scope}</span>' in row
            assert 'class="badge ok">certified<' in row and ">safe<" not in row
    assert "mm at the farthest point" in html and "at the tool tip" not in html


def test_the_tolerance_in_mm_is_at_the_farthest_point_the_tool_tip(planned):
    rows = {r["scenario"]: r for r in _summary(planned)}
    s = planned["gripper"][0]
    # The right arm's gripper reaches farthest: L is its tip's R_base + R_elbow.
    far = max(sum(reach(arm, p)) for arm in (s.left, s.right) for p in parts(arm))
    assert sum(reach(s.right, 2)) == far == tube_lipschitz(s) == rows["gripper"]["reach_m_per_rad"]
    assert far > max(sum(reach(arm, p)) for arm in (s.left, s.right) for p in (0, 1))
    r = rows["gripper"]
    assert r["tolerance_farthest_point_mm"] == pytest.approx(1000 * far * r["tolerance_rad"],
                                                             rel=1e-12)
    assert r["tolerance_tip_mm"] == r["tolerance_farthest_point_mm"]   # the former name
    assert 2 * r["tolerance_farthest_point_mm"] < r["lower_bound_mm"]


def test_the_clearance_picture_sees_the_tools(planned):
    # The gripper's motion planned without the tools: clear for the arms alone, in contact once
    # the tools are there, and the sampled clearance the report draws says so.
    s = planned["gripper"][0]
    text = (BUNDLED_DIR / "gripper.toml").read_text()
    bare = re.sub(r"^\[(left|right)\.tool\][^\n]*\n(?:(?!\[)[^\n]*\n)*", "", text, flags=re.M)
    import tomllib

    plain = parse_scenario(tomllib.loads(bare), check_budget=False)
    p = plan(plain, Variant.MODIFIED, contracts="off")
    assert p.certificate.clear
    _, without = sample_clearance(plain, p.grid, p.search.path)
    _, with_tools = sample_clearance(s, p.grid, p.search.path)
    assert without.min() > 0.01 and with_tools.min() == 0.0
    assert np.all(with_tools <= without + 1e-15)
