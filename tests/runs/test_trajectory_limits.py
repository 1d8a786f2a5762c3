"""The streamed trajectory readers' limits (docs/model.md §12): `cfmpa certify` reads a CSV or a
ROS 2 bag (mcap, sqlite3) in one pass with no byte limit, each line bounded, at most
CFMPA_MAX_TRAJECTORY_ROWS rows (a one-line message naming the limit and how to raise it, exit
2, nothing written); a trajectory read whole (JSON) is refused by its size before it is read.
A streamed bag certifies as the bag loaded whole. Seeded faults: the budget checked one row
late, the size checked after the read."""

from __future__ import annotations

import json
import os
from pathlib import Path

import numpy as np
import pytest

import factory
import mutant_module
from cfmpa.cli import main
from cfmpa.errors import InputError
from cfmpa.runs import BagOptions, certify_json
from cfmpa.runs._rosbag import bag_row_name, bag_trajectory_rows, load_bag_trajectory, write_bag
from cfmpa.spec import _trajectory as tr
from cfmpa.spec import certify_trajectory, certify_trajectory_file, load_trajectory

ROWS = "CFMPA_MAX_TRAJECTORY_ROWS"


@pytest.fixture(scope="module")
def cell(tmp_path_factory):
    s, scen, folder, _ = factory.planned(tmp_path_factory.mktemp("limits"), factory.doc(
        right__start_cell=[2, 8], right__goal_cell=[13, 5]))
    return s, scen, folder / "traj.csv"


def _certify(scen, traj, out: Path, capsys, *extra: str) -> tuple[int, str]:
    out.unlink(missing_ok=True)
    rc = main(["certify", str(scen), "--traj", str(traj), "--json", str(out), *extra])
    return rc, capsys.readouterr().err


def test_the_row_budget_refuses_the_row_past_it_with_one_line(cell, tmp_path, capsys,
                                                               monkeypatch):
    s, scen, traj = cell
    rows = load_trajectory(traj, s).rows
    out = tmp_path / "c.json"
    monkeypatch.setenv(ROWS, str(rows))
    assert _certify(scen, traj, out, capsys)[0] == 0 and out.exists()
    monkeypatch.setenv(ROWS, str(rows - 1))
    rc, err = _certify(scen, traj, out, capsys)
    # The row past the budget is on line rows + 1 (the header is line 1).
    assert rc == 2 and not out.exists() and err.count("\n") == 1 and "Traceback" not in err
    assert err.startswith(f"{traj}:{rows + 1}: error: trajectory has more than {rows - 1:,} "
                          "rows") and f"set the environment variable {ROWS} higher" in err
    for bad in ("0", "-3", "many"):
        monkeypatch.setenv(ROWS, bad)
        rc, err = _certify(scen, traj, out, capsys)
        assert rc == 2 and f"{ROWS} must be a positive integer (rows)" in err


def test_no_byte_limit_on_the_streamed_reader_but_the_line_stays_bounded(cell, tmp_path, capsys,
                                                                         monkeypatch):
    s, scen, traj = cell
    text = traj.read_text()
    out = tmp_path / "c.json"
    monkeypatch.setenv("CFMPA_MAX_TRAJECTORY_BYTES", "100")         # far below the file
    assert _certify(scen, traj, out, capsys)[0] == 0
    assert json.loads(out.read_text())["trajectory"]["rows"] == text.count("\n") - 1
    long = tmp_path / "long.csv"
    lines = text.splitlines(keepends=True)
    long.write_text("".join(lines[:3]) + lines[3].rstrip("\n") + "0" * 200 + "\n"
                    + "".join(lines[4:]))
    monkeypatch.setenv("CFMPA_MAX_LINE_BYTES", "150")
    rc, err = _certify(scen, long, out, capsys)
    assert rc == 2 and err.startswith(f"{long}:4: error: line is longer than the limit of 150")


def test_a_json_trajectory_is_refused_by_its_size_before_it_is_read(cell, tmp_path, capsys,
                                                                    monkeypatch):
    s, scen, traj = cell
    t = load_trajectory(traj, s)
    js = tmp_path / "t.json"
    js.write_text(json.dumps({"t": t.t.tolist(), **{c: t.angles[:, i].tolist()
                                                    for i, c in enumerate(tr.JOINTS)}}))
    size = js.stat().st_size
    out = tmp_path / "c.json"
    assert _certify(scen, js, out, capsys)[0] == 0
    monkeypatch.setenv("CFMPA_MAX_TRAJECTORY_BYTES", str(size - 1))

    def refused() -> str:
        reads: list[str] = []
        real = tr.read_bounded

        def spy(*a, **k):
            reads.append("read")
            return real(*a, **k)
        monkeypatch.setattr(tr, "read_bounded", spy)
        with pytest.raises(InputError) as e:
            certify_trajectory_file(js, s)
        monkeypatch.setattr(tr, "read_bounded", real)
        assert "CFMPA_MAX_TRAJECTORY_BYTES" in e.value.render() and e.value.line is None
        return "read" if reads else "not read"

    assert refused() == "not read"
    # Seeded fault: the size check dropped, the file is read (read_bounded, at its limit) first.
    monkeypatch.setattr(tr, "check_trajectory_size", lambda p, source: None)
    assert refused() == "read"


def test_seeded_fault_a_budget_checked_one_row_late_is_caught(cell, tmp_path, monkeypatch):
    s, _, traj = cell
    rows = load_trajectory(traj, s).rows
    monkeypatch.setenv(ROWS, str(rows - 1))

    def refused(module) -> bool:
        try:
            module.certify_trajectory_file(traj, s)
        except InputError as exc:
            return ROWS in exc.render()
        return False

    assert refused(tr)
    mutant = mutant_module.mutated_module(
        "late_budget", "spec/_trajectory.py",
        [("if c.rows + len(where) >= cap:", "if c.rows + len(where) > cap:")],
        lambda name, mod: monkeypatch.setitem(__import__("sys").modules, name, mod))
    assert not refused(mutant)


def _bag(tmp_path: Path, traj, kind: str) -> Path:
    # stamps on the ns grid, as a bag holds them
    t = np.round(traj.t * 1e9) / 1e9
    return write_bag(tmp_path / f"traj.{kind}", t, traj.angles, kind=kind)


def _doc(s, traj_or_info, cert) -> dict:
    doc = certify_json(s, traj_or_info, cert, None, None)
    doc.pop("timings_s")
    return doc


@pytest.mark.parametrize("kind", ["mcap", "db3"])
def test_a_bag_streamed_certifies_as_the_bag_loaded_whole(cell, tmp_path, kind, monkeypatch):
    s, _, traj_csv = cell
    opts = BagOptions()
    sweep = tr.Trajectory(np.concatenate([[0.0], np.linspace(2.0, 12.0, 30)]),
                          np.tile([0.3, 0.8, 3.3, 0.5], (31, 1)))
    sweep.angles[1:, 2] = np.linspace(3.3, 1.2, 30)      # the subordinate into the principal
    verdicts = set()
    seen: list[int] = []
    real = tr._Certifier.add

    def spy(self, part, offset):
        seen.append(part.rows)
        real(self, part, offset)
    monkeypatch.setattr(tr._Certifier, "add", spy)
    for name, traj in (("plan", load_trajectory(traj_csv, s)), ("sweep", sweep)):
        folder = tmp_path / name
        folder.mkdir()
        bag = _bag(folder, traj, kind)
        whole = load_bag_trajectory(bag, s, opts)
        want = _doc(s, whole, certify_trajectory(s, whole))
        for chunk in (2, 5, tr.CHUNK_ROWS):
            seen.clear()
            info, cert = tr.certify_trajectory_rows(
                bag_trajectory_rows(bag, opts), s, source=str(bag), chunk_rows=chunk,
                name_row=bag_row_name(opts))
            got = _doc(s, info, cert)
            if chunk == tr.CHUNK_ROWS:
                assert got == want, (name, kind)
            else:           # smaller parts: the verdict, the contact and the rows the same
                assert {k: got[k] for k in ("clear", "contact", "trajectory")} == {
                    k: want[k] for k in ("clear", "contact", "trajectory")}, (name, chunk)
            assert max(seen) <= chunk + 1            # no part holds more than its rows + 1
        verdicts.add(want["clear"])
    assert verdicts == {True, False}                # both verdicts compared


def test_a_bag_over_the_row_budget_is_one_line_naming_it(cell, tmp_path, capsys, monkeypatch):
    s, scen, traj_csv = cell
    traj = load_trajectory(traj_csv, s)
    bag = _bag(tmp_path, traj, "mcap")
    out = tmp_path / "c.json"
    monkeypatch.setenv(ROWS, str(traj.rows))
    assert _certify(scen, bag, out, capsys)[0] == 0
    monkeypatch.setenv(ROWS, str(traj.rows - 2))
    rc, err = _certify(scen, bag, out, capsys)
    assert rc == 2 and not out.exists() and err.count("\n") == 1
    assert err.startswith(f"{bag}: error: trajectory has more than {traj.rows - 2:,} rows")
    assert ROWS in err and os.environ[ROWS] == str(traj.rows - 2)
