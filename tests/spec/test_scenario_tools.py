"""The scenario format's tools and heights (docs/model.md §3): read as written, refused by name with
the value and file:line, exit 2; the pair rule keeps exactly the parts whose closed height
intervals overlap (docs/model.md §2, "Tools and heights")."""

from __future__ import annotations

import math
from pathlib import Path

import pytest

import factory
from cfmpa import cli
from cfmpa.errors import InputError
from cfmpa.spec import (
    TOOL,
    Tool,
    heights_overlap,
    link_name,
    load_scenario,
    pairs_to_test,
    parse_scenario,
    parts,
)

BUNDLED = Path(__file__).resolve().parents[2] / "scenarios"
GRIPPER = [[-0.02, -0.04], [0.12, -0.025], [0.12, 0.025], [-0.02, 0.04]]


def refused(**changes: object) -> InputError:
    with pytest.raises(InputError) as info:
        parse_scenario(factory.doc(**changes), check_budget=True)
    return info.value


def test_a_tool_and_heights_are_read_counter_clockwise_in_the_forearms_frame():
    s = parse_scenario(factory.doc(right__tool={"polygon": GRIPPER[::-1], "z": [0.05, 0.26]},
                                   right__z=[[0.30, 0.36], [0.20, 0.26]]))
    assert s.right.tool == Tool(polygon=tuple(map(tuple, GRIPPER)), z=(0.05, 0.26))
    assert s.right.z == ((0.30, 0.36), (0.20, 0.26))
    assert s.left.tool is None and s.left.z is None
    assert parts(s.right) == (0, 1, TOOL) and parts(s.left) == (0, 1)
    assert link_name("right", TOOL + 1) == "right tool"
    assert link_name("left", 2) == "left link 2 (forearm)"


@pytest.mark.parametrize("changes, field, words", [
    ({"right__tool": {"polygon": [[0.0, 0.0], [0.1, 0.0]]}}, "right.tool.polygon", "3 to 16"),
    ({"right__tool": {"polygon": [[0.01 * k, (0.01 * k) ** 2] for k in range(17)]}},
     "right.tool.polygon", "3 to 16"),
    ({"right__tool": {"polygon": [[0.0, 0.0], [0.1, 0.0], [0.05, 0.0]]}}, "right.tool.polygon",
     "degenerate"),
    ({"right__tool": {"polygon": [[0.0, 0.0], [0.1, 0.0], [0.1, 0.0], [0.0, 0.1]]}},
     "right.tool.polygon", "strictly convex"),
    # Non-convex (an arrow head) and self-intersecting (a bow tie).
    ({"left__tool": {"polygon": [[0.0, 0.0], [0.1, 0.05], [0.0, 0.1], [0.03, 0.05]]}},
     "left.tool.polygon", "strictly convex"),
    ({"left__tool": {"polygon": [[0.0, 0.0], [0.1, 0.1], [0.1, 0.0], [0.0, 0.1]]}},
     "left.tool.polygon", "strictly convex"),
    ({"left__tool": {"polygon": [[0.0, 0.0], [0.1, math.nan], [0.0, 0.1]]}},
     "left.tool.polygon[1][1]", "must be finite"),
    ({"left__tool": {"polygon": [[0.0, 0.0], [0.1, math.inf], [0.0, 0.1]]}},
     "left.tool.polygon[1][1]", "must be finite"),
    ({"left__tool": {"polygon": [[0.0, 0.0], [0.1, 0.0], [0.0, 0.1]], "colour": "red"}},
     "left.tool.colour", "not a known key"),
    ({"left__tool": {"z": [0.0, 0.1]}}, "left.tool.polygon", "is required"),
    ({"left__tool": [1, 2]}, "left.tool", "must be a table"),
    ({"left__tool": {"polygon": GRIPPER, "z": [0.3, 0.2]}}, "left.tool.z", "lo <= hi"),
    ({"right__z": [[0.3, 0.2], [0.1, 0.2]]}, "right.z[0]", "lo <= hi"),
    ({"right__z": [[0.1, 0.2]]}, "right.z", "list of 2"),
    ({"right__z": [[0.1, math.nan], [0.1, 0.2]]}, "right.z[0][1]", "must be finite"),
    ({"left__z": [[0.1, 0.2], [0.1, 0.2, 0.3]]}, "left.z[1]", "list of 2"),
])
def test_bad_tools_and_heights_are_refused_by_name(changes, field, words):
    err = refused(**changes)
    assert err.field == field
    assert words in str(err)
    assert err.exit_code == 2


def test_a_single_height_is_a_closed_interval():
    s = parse_scenario(factory.doc(left__z=[[0.2, 0.2], [0.3, 0.3]]))
    assert s.left.z == ((0.2, 0.2), (0.3, 0.3))


def test_the_pair_rule_closed_intervals_and_none_for_every_height():
    assert heights_overlap((0.1, 0.2), (0.2, 0.3))            # touching ends overlap
    assert not heights_overlap((0.1, 0.2), (0.2000001, 0.3))
    assert heights_overlap(None, (5.0, 6.0)) and heights_overlap((5.0, 6.0), None)
    s = parse_scenario(factory.doc(left__z=[[0.5, 0.6], [0.3, 0.4]],
                                   left__tool={"polygon": GRIPPER, "z": [0.1, 0.2]},
                                   right__z=[[0.0, 0.1], [0.4, 0.5]],
                                   right__tool={"polygon": GRIPPER}))
    # left link 1 (0.5-0.6) meets the right link 2 at 0.5 and the tool (every height); left
    # link 2 (0.3-0.4) the right link 2 at 0.4 and the tool; the left tool (0.1-0.2) the right
    # link 1 at 0.1 and the tool. Never: left links against the right link 1 (0.0-0.1).
    assert pairs_to_test(s.left, s.right) == ((0, 1), (0, 2), (1, 1), (1, 2), (2, 0), (2, 2))


def test_an_unknown_table_is_refused_with_its_line(tmp_path, capsys):
    text = (BUNDLED / "gripper.toml").read_text()
    bad = tmp_path / "bad.toml"
    bad.write_text(text + "\n[left.gadget]\nx = 1\n")
    line = len(bad.read_text().splitlines()) - 1
    code = cli.main(["dr", str(bad), "--out", str(tmp_path / "out")])
    err = capsys.readouterr().err
    assert code == 2
    assert err.startswith(f"{bad}:{line}: error: left.gadget is not a known key")
    assert err.count("\n") == 1 and not (tmp_path / "out").exists()


def test_a_bad_tool_vertex_is_refused_with_its_file_and_line(tmp_path):
    text = (BUNDLED / "gripper.toml").read_text()
    bad = tmp_path / "bad.toml"
    bad.write_text(text.replace("[0.12, 0.025], [-0.02, 0.04]]", "[0.12, 0.025], [0.5, 0.0]]"))
    err = pytest.raises(InputError, load_scenario, bad).value
    lines = bad.read_text().splitlines()
    assert err.field == "right.tool.polygon"
    assert lines[err.line - 1].startswith("polygon = ") and "[0.5, 0.0]" in lines[err.line - 1]
    assert err.render().startswith(f"{bad}:{err.line}: error: right.tool.polygon must be a "
                                   "strictly convex polygon")


def test_the_bundled_tool_and_height_workcells():
    g = load_scenario(BUNDLED / "gripper.toml")
    assert g.left.tool is not None and g.right.tool is not None
    assert pairs_to_test(g.left, g.right) == tuple((a, b) for a in range(3) for b in range(3))
    lv = load_scenario(BUNDLED / "levels.toml")
    assert lv.left.tool is None and lv.right.tool is None
    # The forearms work at disjoint heights: only the left upper arm and the right forearm.
    assert pairs_to_test(lv.left, lv.right) == ((0, 1),)
