"""What a person reads, in one style (docs/contributing.md, "Standards"): lengths in mm, angles
in rad with degrees, each status word once, a verdict and its details on one stream, every file
written named, a wrong scenario name pointing to `cfmpa scenarios`, `--variant`'s choices in the
help, where docs/model.md is (`cfmpa docs`), a speed error naming its sample once with the value
and the limit in one sentence, every message one line."""

from __future__ import annotations

import json
import math
from pathlib import Path

import numpy as np
import pytest

import factory
from cfmpa.cli import main, model_doc
from cfmpa.errors import ContractViolation, InputError, error_text
from cfmpa.files import angle_text, cause_text, mm_text
from cfmpa.spec import load_trajectory, tolerance_rad, trajectory_csv

DOC = factory.doc(right__start_cell=[2, 8], right__goal_cell=[13, 5])
ROOT = Path(__file__).resolve().parents[1]


@pytest.fixture(scope="module")
def cell(tmp_path_factory):
    s, scen, folder, p = factory.planned(tmp_path_factory.mktemp("messages"), DOC)
    return s, scen, folder, p


def test_lengths_in_mm_and_angles_in_rad_with_degrees():
    assert mm_text(0.0110044) == "11.0044 mm"
    assert angle_text(0.005433) == "0.005433 rad (0.3113 deg)"
    assert angle_text(math.pi, 3) == "3.14 rad (180 deg)"


def test_certify_prints_the_tolerance_in_rad_degrees_and_mm_and_its_json_has_them(cell, tmp_path,
                                                                                  capsys):
    s, scen, folder, p = cell
    out = tmp_path / "c.json"
    assert main(["certify", str(scen), "--traj", str(folder / "traj.csv"), "--json",
                 str(out)]) == 0
    doc = json.loads(out.read_text())
    tol = tolerance_rad(s, p.certificate)
    assert doc["tolerance_rad"] == tol and doc["tolerance_deg"] == pytest.approx(math.degrees(tol))
    assert doc["tolerance_farthest_point_mm"] == pytest.approx(
        1000 * doc["tube_lipschitz_m_per_rad"] * tol)
    line = next(x for x in capsys.readouterr().out.splitlines() if x.startswith("tolerance"))
    assert f"{tol:.6f} rad ({math.degrees(tol):.4g} deg)" in line
    assert f"at most {doc['tolerance_farthest_point_mm']:.3g} mm" in line


def test_monitor_says_outside_once_with_its_count_and_details_on_the_same_stream(cell, tmp_path,
                                                                                  capsys):
    # "outside, 51 outside" was the summary; the first outside instant went to stderr.
    s, scen, folder, p = cell
    traj = load_trajectory(folder / "traj.csv", s)
    tol = tolerance_rad(s, p.certificate)
    t = np.linspace(traj.t[0], traj.t[-1], 1001)
    a = traj.at(t)
    a[500:551, 3] += 3 * tol                                # 51 samples outside
    log = tmp_path / "log.csv"
    log.write_text("t,left1,left2,right1,right2\n" + "".join(
        ",".join(repr(float(x)) for x in (tk, *ak)) + "\n" for tk, ak in zip(t, a)))
    assert main(["monitor", str(scen), "--traj", str(folder / "traj.csv"), "--log",
                 str(log)]) == 1
    got = capsys.readouterr()
    assert got.err == ""
    summary, first = got.out.splitlines()[:2]
    verdict = summary.split(" deg)): ", 1)[1]          # after the paths and the tolerance
    assert verdict.startswith("outside (51 of 1001 samples);") and verdict.count("outside") == 1
    assert f"(tolerance {angle_text(tol)})" in summary
    assert first.startswith("first     outside at t=") and "(line 502)" in first
    assert "right2 off by " in first and " deg); " in first


def test_a_wrong_scenario_name_points_to_cfmpa_scenarios(tmp_path, capsys, monkeypatch):
    monkeypatch.chdir(tmp_path)
    assert main(["plan", "nosuch", "--out", str(tmp_path / "p")]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "Traceback" not in err
    assert err.startswith("error: SCENARIO is neither a file nor a bundled scenario (`cfmpa "
                          "scenarios` lists them: default, ")
    assert err.rstrip().endswith("got 'nosuch'") and not (tmp_path / "p").exists()
    # A path (a folder or a .toml suffix) is still reported as the file that cannot be read.
    assert main(["plan", "nosuch.toml", "--out", str(tmp_path / "p")]) == 2
    assert "cannot be read" in capsys.readouterr().err


def test_plan_names_every_file_it_wrote(tmp_path, capsys):
    scen = tmp_path / "tiny.toml"
    scen.write_text(factory.toml(DOC))
    out = tmp_path / "p"
    assert main(["plan", str(scen), "--out", str(out), "--contracts", "off", "--witness",
                 str(tmp_path / "w.npz")]) == 0
    wrote = next(x for x in capsys.readouterr().out.splitlines() if x.startswith("wrote"))
    named = wrote.split(None, 1)[1].split(", ")
    assert named == [str(out / "dr.npy"), str(out / "plan.json"), str(out / "traj.csv"),
                     str(tmp_path / "w.npz")]
    assert all(Path(x).is_file() for x in named)
    assert sorted(x.name for x in out.iterdir()) == ["dr.npy", "plan.json", "traj.csv"]


def test_variant_shows_its_choices_in_the_help(capsys):
    for command in ("dr", "plan"):
        with pytest.raises(SystemExit):
            main([command, "--help"])
        text = capsys.readouterr().out
        assert "--variant {original,modified,tight}" in text, command
    with pytest.raises(SystemExit) as info:
        main(["plan", "default", "--out", "x", "--variant", "sideways"])
    assert info.value.code == 2
    assert "argument --variant: must be one of original, modified, tight, got 'sideways'" in (
        capsys.readouterr().err)


def test_cfmpa_docs_prints_where_model_md_is_and_the_help_says_so(capsys):
    assert main(["docs"]) == 0
    path = Path(capsys.readouterr().out.strip())
    assert path == model_doc() and path.read_text(encoding="utf-8").startswith("# The cfmpa model")
    with pytest.raises(SystemExit):
        main(["--help"])
    assert "cfmpa docs " in capsys.readouterr().out
    # The wheel carries it (setup.py's build_py; MANIFEST.in for an sdist).
    assert "docs/model.md" in (ROOT / "MANIFEST.in").read_text()
    assert '"docs" / "model.md"' in (ROOT / "setup.py").read_text()


def test_the_speed_error_names_a_bag_message_once_without_a_line(cell, tmp_path, capsys):
    from cfmpa.runs import BagOptions
    from cfmpa.runs._rosbag import write_bag

    s, scen, folder, p = cell
    t = np.array([0.0, 1.0, 1.5])
    a = np.array([[0.3, 0.8, 0.5, 1.0], [0.3, 0.8, 0.5, 1.0], [0.3, 0.8, 1.5, 1.0]])
    bag = write_bag(tmp_path / "fast.mcap", t, a, BagOptions())
    csv = tmp_path / "fast.csv"
    csv.write_text(trajectory_csv(type(load_trajectory(folder / "traj.csv", s))(t, a)))
    assert main(["certify", str(scen), "--traj", str(csv)]) == 2
    assert capsys.readouterr().err.strip() == (
        f"{csv}:4: error: right1 speed is 2.0 rad/s from the previous row, above its omega of "
        "1.0 rad/s (--allow-speed certifies it anyway)")
    assert main(["certify", str(scen), "--traj", str(bag)]) == 2
    assert capsys.readouterr().err.strip() == (
        f"{bag}: error: right1 speed of message 3 on /joint_states is 2.0 rad/s from the "
        "previous message, above its omega of 1.0 rad/s (--allow-speed certifies it anyway)")


def test_every_message_is_one_line():
    e = InputError("--log", "x", "is not a readable ROS 2 bag (while parsing a block\n  in "
                   "\"metadata.yaml\", line 2\nexpected ',' or ']')")
    assert "\n" not in e.render() and "line 2; expected" in e.render()
    v = ContractViolation("Theorem 3 [BuiltDR, modified]", "post.cells: a cell is free",
                          {"layer": 3, "distance_m": 0.0012, "angles_rad": [math.pi, 0.0]})
    assert "\n" in str(v)                                  # the exception keeps its lines
    assert error_text(v) == (
        "error: Theorem 3 [BuiltDR, modified]: post.cells: a cell is free (layer was 3; "
        "distance was 1.2 mm; angles was [3.141592653589793, 0.0] rad ([180, 0] deg))")
    cause = cause_text(OverflowError("Python int too large to convert to C long " + "9" * 300))
    assert cause.startswith("OverflowError: Python int too large") and len(cause) < 120


def test_the_scenarios_listing_is_at_most_100_wide_and_the_default_purpose_short(capsys):
    from cfmpa.spec import load_scenario

    assert main(["scenarios"]) == 0
    lines = capsys.readouterr().out.splitlines()
    assert max(len(x) for x in lines[1:]) <= 100
    purpose = load_scenario(ROOT / "scenarios" / "default.toml").purpose
    assert len(purpose) <= 240
    for fact in ("give way", "layer 32", "backs away", "Manhattan length (161)"):
        assert fact in purpose, fact
