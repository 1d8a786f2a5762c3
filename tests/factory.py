"""Small scenarios for tests: a coarse default workcell with overrides (not part of the package)."""

from __future__ import annotations

import copy
import json
from pathlib import Path
from typing import Any

from cfmpa.spec import Scenario, parse_scenario

BASE_DOC: dict[str, Any] = {
    "name": "tiny",
    "purpose": "a coarse workcell for tests",
    "dt": 0.25,
    "left": {"base": [0.0, 0.0], "links": [0.35, 0.30], "width": 0.06, "omega": [1.0, 1.0],
             "start": [0.3, 0.8], "goal": [1.6, 2.2]},
    "right": {"base": [0.6, 0.0], "links": [0.35, 0.30], "width": 0.06, "omega": [1.0, 1.0],
              "limits": [[0.0, 6.283185307179586], [0.0, 6.283185307179586]],
              "start_cell": [3, 8], "goal_cell": [12, 5]},
}


def doc(**changes: Any) -> dict[str, Any]:
    """A copy of BASE_DOC; keys like ``right__omega`` set nested fields, ``None`` deletes."""
    d = copy.deepcopy(BASE_DOC)
    for key, value in changes.items():
        parts = key.split("__")
        target = d
        for p in parts[:-1]:
            target = target[p]
        if value is None:
            target.pop(parts[-1], None)
        else:
            target[parts[-1]] = value
    return d


def scenario(**changes: Any) -> Scenario:
    """A validated tiny scenario (grid 27 x 27, 6 layers) with ``changes`` applied."""
    return parse_scenario(doc(**changes), check_budget=False)


def toml(doc: dict[str, Any]) -> str:
    """A scenario document (top-level keys, then [left] and [right]) as TOML text."""
    lines = [f"{k} = {json.dumps(doc[k])}" for k in ("name", "purpose", "dt")]
    for side in ("left", "right"):
        lines += [f"[{side}]"] + [f"{k} = {json.dumps(v)}" for k, v in doc[side].items()]
    return "\n".join(lines) + "\n"


#: The bundled default before it was made to show avoidance (its optimal path is a straight L);
#: tests that build coarse copies by editing its text, or quote figures measured on it, read it.
FORMER_DEFAULT = Path(__file__).resolve().parent / "data" / "former-default.toml"


def edited(text: str, *pairs: tuple[str, str]) -> str:
    """``text`` with each (old, new) replaced; an ``old`` that is not there is an error, so a
    changed source file cannot turn the edit into a silent no-op."""
    for old, new in pairs:
        assert old in text, f"{old!r} is not in the text being edited"
        text = text.replace(old, new)
    return text


def tiny_default(folder: Path) -> Path:
    """folder/tiny.toml: the former default at dt = 0.125 s (a grid planned in a blink), for
    report tests that need a workcell of their own."""
    text = edited(FORMER_DEFAULT.read_text(), ('name = "former-default"', 'name = "tiny-default"'),
                  ("dt = 0.02", "dt = 0.125"), ("start_cell = [40, 100]", "start_cell = [6, 16]"),
                  ("goal_cell = [150, 60]", "goal_cell = [24, 10]"))
    p = folder / "tiny.toml"
    p.write_text(text)
    return p


def planned(folder: Path, doc: dict[str, Any]) -> tuple[Scenario, Path, Path, Any]:
    """``doc`` written to folder/tiny.toml and planned (modified variant) into folder/plan:
    (the scenario, its file, the plan folder, the PlanResult)."""
    from cfmpa.runs import plan, write_plan
    from cfmpa.spec import load_scenario

    scen = folder / "tiny.toml"
    scen.write_text(toml(doc))
    s = load_scenario(scen)
    p = plan(s, "modified")
    write_plan(p, folder / "plan")
    return s, scen, folder / "plan", p
