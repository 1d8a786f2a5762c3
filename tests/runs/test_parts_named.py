"""Contacts name the part (docs/model.md §2, §12): the gripper workcell planned without its tools
gives a motion whose tools collide, and `cfmpa certify`, `cfmpa monitor` and `cfmpa check` with
the tools say "left tool and right tool", in their messages and in the JSON's ``parts``."""

from __future__ import annotations

import json
import re

import numpy as np
import pytest

from cfmpa.cli import main
from cfmpa.scenarios import BUNDLED_DIR
from cfmpa.spec import load_scenario, load_trajectory, trajectory_distances

GRIPPER = BUNDLED_DIR / "gripper.toml"
TOOLS = "left tool and right tool"
HEADER = "t,left1,left2,right1,right2\n"


def _without_tools(text: str) -> str:
    """The scenario text with its [left.tool] and [right.tool] tables removed."""
    out = re.sub(r"^\[(left|right)\.tool\][^\n]*\n(?:(?!\[)[^\n]*\n)*", "", text, flags=re.M)
    assert out != text and "[left.tool]" not in out and "[right.tool]" not in out
    return out.replace('name = "gripper"', 'name = "gripper-without-tools"')


@pytest.fixture(scope="module")
def toolless(tmp_path_factory):
    """The gripper workcell planned without its tools (`cfmpa plan`, modified): its folder."""
    folder = tmp_path_factory.mktemp("gripper")
    scen = folder / "no-tools.toml"
    scen.write_text(_without_tools(GRIPPER.read_text()))
    s = load_scenario(scen)
    assert s.left.tool is None and s.right.tool is None
    assert main(["plan", str(scen), "--out", str(folder / "plan"), "--contracts", "off"]) == 0
    return folder / "plan"


def test_certify_with_the_tools_names_them(toolless, tmp_path, capsys):
    capsys.readouterr()
    out = tmp_path / "c.json"
    assert main(["certify", "gripper", "--traj", str(toolless / "traj.csv"), "--json",
                 str(out)]) == 1
    printed = capsys.readouterr()
    err = printed.out + printed.err
    assert "clearance NOT CLEAR: contact at t=" in err and TOOLS in err
    c = json.loads(out.read_text())["contact"]
    assert c["links"] == [3, 3] and c["links_text"] == TOOLS
    assert c["parts"] == ["left tool", "right tool"]
    # Without the tools the same motion is clear: it is the tools that touch.
    doc = json.loads((toolless / "plan.json").read_text())
    assert doc["clearance"]["clear"] is True and doc["clearance"]["contact"] is None


def test_check_with_the_tools_names_them(toolless, capsys):
    capsys.readouterr()
    assert main(["check", "gripper", "--dr", str(toolless / "dr.npy"), "--plan",
                 str(toolless / "plan.json")]) == 1
    text = capsys.readouterr().out
    line = next(x for x in text.splitlines() if x.startswith("FAIL  continuous-time"))
    assert "the arms' parts touch" in line
    assert f"links was '{TOOLS}'" in text


def test_monitor_names_the_tools_of_a_sample_in_contact(toolless, tmp_path, capsys):
    s = load_scenario(GRIPPER)
    traj = load_trajectory(toolless / "traj.csv", s)
    # Sampled instants where the tools overlap and no other pair touches; the middle one.
    t = np.linspace(traj.t[0], traj.t[-1], 4001)
    poses = np.array([traj.at(x) for x in t])
    d = trajectory_distances(s, poses)                  # (K, 3, 3): links, then the tool
    only_tools = np.flatnonzero((d[:, 2, 2] == 0.0) & ((d == 0.0).sum(axis=(1, 2)) == 1))
    assert len(only_tools) > 2
    pose = poses[only_tools[len(only_tools) // 2]]
    # A trajectory at rest at the motion's last pose (certified clear, with the tools), and a log
    # with one sample at the contact pose.
    rest = [float(x) for x in traj.at(traj.t[-1])]
    ref = tmp_path / "rest.csv"
    ref.write_text(HEADER + "".join(",".join(repr(x) for x in [ti, *rest]) + "\n"
                                    for ti in (0.0, 1.0)))
    rows = [[ti, *rest] for ti in np.linspace(0.0, 1.0, 11)]
    rows[5] = [rows[5][0], *(float(x) for x in pose)]
    log = tmp_path / "log.csv"
    log.write_text(HEADER + "".join(",".join(repr(float(x)) for x in r) + "\n" for r in rows))
    capsys.readouterr()
    out = tmp_path / "m.json"
    assert main(["monitor", "gripper", "--traj", str(ref), "--log", str(log), "--json",
                 str(out)]) == 1
    printed = capsys.readouterr()
    assert f"IN CONTACT ({TOOLS})" in printed.out + printed.err
    c = json.loads(out.read_text())["contact"]
    assert c["in_contact"] is True and c["links"] == [3, 3]
    assert c["links_text"] == TOOLS and c["parts"] == ["left tool", "right tool"]
