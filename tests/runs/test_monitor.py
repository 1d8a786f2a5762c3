"""`cfmpa monitor` and `cfmpa simulate` (docs/model.md §12): a noisy log inside the tube passes, an
excursion is flagged at its first sample, malformed logs are refused with their line."""

from __future__ import annotations

import io
import json

import numpy as np
import pytest

import factory
from cfmpa.cli import main
from cfmpa.errors import InputError
from cfmpa.runs import Excursion, monitor_log, parse_excursion, simulate_log
from cfmpa.spec import load_trajectory, tolerance_rad

DOC = factory.doc(right__start_cell=[2, 8], right__goal_cell=[13, 5])
HEADER = "t,left1,left2,right1,right2\n"


@pytest.fixture(scope="module")
def cell(tmp_path_factory):
    s, scen, folder, p = factory.planned(tmp_path_factory.mktemp("monitor"), DOC)
    traj = load_trajectory(folder / "traj.csv", s)
    return s, scen, folder / "traj.csv", traj, tolerance_rad(s, p.certificate)


def test_a_noisy_lagging_log_inside_the_tube_passes(cell, tmp_path):
    s, scen, traj_csv, traj, tol = cell
    log, out = tmp_path / "log.csv", tmp_path / "m.json"
    assert main(["simulate", str(scen), "--traj", str(traj_csv), "--out", str(log),
                 "--noise", str(tol / 4), "--lag", "0.001", "--seed", "3", "--tail", "1"]) == 0
    assert main(["monitor", str(scen), "--traj", str(traj_csv), "--log", str(log),
                 "--json", str(out)]) == 0
    doc = json.loads(out.read_text())
    assert doc["status"] == "inside" and doc["outside"] == 0 and doc["contact"] is None
    assert doc["samples"] == len(log.read_text().splitlines()) - 1
    assert doc["first_outside_t"] is None and doc["first_outside_joint"] is None
    assert doc["first_outside_deviation_rad"] is None and doc["max_deviation_rad"] <= tol


def test_an_excursion_is_flagged_at_its_first_sample(cell, tmp_path):
    s, scen, traj_csv, traj, tol = cell
    log, out = tmp_path / "log.csv", tmp_path / "m.json"
    assert main(["simulate", str(scen), "--traj", str(traj_csv), "--out", str(log), "--noise",
                 str(tol / 4), "--excursion", f"1.5:right2:{3 * tol}:0.1"]) == 0
    assert main(["monitor", str(scen), "--traj", str(traj_csv), "--log", str(log), "--json",
                 str(out)]) == 1
    doc = json.loads(out.read_text())
    t = np.loadtxt(log, delimiter=",", skiprows=1)[:, 0]
    first = int(np.argmax(t >= 1.5))
    assert doc["status"] == "outside" and doc["first_outside_joint"] == "right2"
    assert doc["first_outside_t"] == t[first] and doc["first_outside_line"] == first + 2
    assert doc["outside"] == int(np.count_nonzero((t >= 1.5) & (t <= 1.6)))
    assert 2 * tol < doc["first_outside_deviation_rad"] < 4 * tol
    assert doc["contact"]["in_contact"] in (True, False)
    # The same, streamed on standard input; byte-identical JSON apart from timings_s.
    import sys
    sys_stdin = sys.stdin
    try:
        sys.stdin = io.StringIO(log.read_text())
        assert main(["monitor", str(scen), "--traj", str(traj_csv), "--log", "-", "--json",
                     str(tmp_path / "m2.json")]) == 1
    finally:
        sys.stdin = sys_stdin
    a, b = doc, json.loads((tmp_path / "m2.json").read_text())
    for x in (a, b):
        x.pop("timings_s"), x.pop("log")
    assert a == b


@pytest.mark.parametrize("body,line,words", [
    ("", 1, "empty"),
    (HEADER, 1, "no samples"),
    ("t,left1\n0,1\n", 1, "missing"),
    (HEADER + "0,0.3,0.8,1,1\n0.1,0.3,0.8,1\n", 3, "5 values"),
    (HEADER + "0,0.3,0.8,1,1\n0.1,0.3,oops,1,1\n", 3, "number"),
    (HEADER + "0,0.3,0.8,1,1\n0.1,0.3,nan,1,1\n", 3, "finite"),
    (HEADER + "0,0.3,0.8,1,1\n0,0.3,0.8,1,1\n", 3, "strictly increase"),
    (HEADER + "0,0.3,0.8,1,1\n\n0.1,0.3,0.8,1,1\n", 3, "blank"),
])
@pytest.mark.parametrize("block", [1, 2, 4096])
def test_malformed_logs_are_refused_with_their_line(cell, body, line, words, block):
    s, _, _, traj, tol = cell
    with pytest.raises(InputError) as e:
        monitor_log(s, traj, tol, io.StringIO(body), source="log.csv", block_rows=block)
    assert e.value.line == line and words in e.value.render()


def test_trailing_blank_lines_and_blocks_agree(cell):
    s, _, _, traj, tol = cell
    t, a = simulate_log(traj, noise=tol, seed=1, excursions=[Excursion(1.0, "left1", 2 * tol)])
    text = HEADER + "".join(",".join(repr(float(x)) for x in (ti, *ai)) + "\n"
                            for ti, ai in zip(t, a)) + "\n\n"
    r = [monitor_log(s, traj, tol, io.StringIO(text), block_rows=b) for b in (7, 1000, 10**6)]
    assert len({(x.samples, x.outside, x.contacts, json.dumps(x.first)) for x in r}) == 1
    assert r[0].samples == len(t) and r[0].outside > 0


def test_a_trajectory_not_certified_clear_is_not_monitored(cell, tmp_path, capsys):
    _, scen, _, _, _ = cell
    f = tmp_path / "sweep.csv"
    f.write_text(HEADER + "0,0.3,0.8,3.3,0.5\n12,0.3,0.8,1.2,0.5\n")
    log = tmp_path / "log.csv"
    log.write_text(HEADER + "0,0.3,0.8,3.3,0.5\n")
    assert main(["monitor", str(scen), "--traj", str(f), "--log", str(log), "--json",
                 str(tmp_path / "m.json")]) == 1
    got = capsys.readouterr()           # a verdict (exit 1), not an error: on stdout
    assert not (tmp_path / "m.json").exists() and "not certified clear" in got.out
    assert got.err == ""


def test_excursion_syntax():
    assert parse_excursion("1.5:right2:0.1") == Excursion(1.5, "right2", 0.1, 0.05)
    assert parse_excursion("1:left1:-0.2:0.5") == Excursion(1.0, "left1", -0.2, 0.5)
    for bad in ("1:elbow:0.1", "1:left1", "a:left1:0.1", "1:left1:0.1:-1"):
        with pytest.raises(InputError):
            parse_excursion(bad)
