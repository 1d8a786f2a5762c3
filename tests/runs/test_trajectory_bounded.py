"""Bounded input (docs/model.md §3, §12): the scenario, trajectory, log and witness readers end at
their limits with exit 2 and one line naming the file, the line and the limit, in bounded memory:
/dev/zero, a sparse 2 GB file, a 100 MB line, a file over its size limit (the limits overridden
through their environment variables); an echoed value is cut to 80 characters."""

from __future__ import annotations

import os
import resource
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

import factory
from cfmpa.cli import main
from cfmpa.errors import InputError
from cfmpa.files import ECHO_CHARS, LIMITS, bounded_lines, echo, read_bounded
from cfmpa.spec import load_scenario, load_trajectory, load_witness, trajectory_csv

CFMPA = str(Path(sys.executable).with_name("cfmpa"))
HEADER = "t,left1,left2,right1,right2\n"
GIB = 1 << 30
ZERO = "/dev/zero"
needs_dev_zero = pytest.mark.skipif(not os.path.exists(ZERO), reason="no /dev/zero")


@pytest.fixture(scope="module")
def cell(tmp_path_factory):
    folder = tmp_path_factory.mktemp("bounded")
    s, scen, plan_dir, _ = factory.planned(folder, factory.doc(right__start_cell=[2, 8],
                                                               right__goal_cell=[13, 5]))
    return s, scen, plan_dir / "traj.csv"


def _limited() -> None:
    resource.setrlimit(resource.RLIMIT_AS, (GIB, GIB))


def _cli(*args: str, env: dict[str, str] | None = None) -> subprocess.CompletedProcess[str]:
    """The console script in a process of its own, its address space limited to 1 GiB."""
    return subprocess.run([CFMPA, *args], capture_output=True, text=True, preexec_fn=_limited,
                          env={**os.environ, **(env or {})}, timeout=120)


def _one_line_error(r: subprocess.CompletedProcess[str], source: str, line: int | None,
                    env: str) -> str:
    assert r.returncode == 2, (r.returncode, r.stderr[-500:])
    err = r.stderr
    assert "Traceback" not in err and err.count("\n") == 1, err[-500:]
    where = f"{source}:{line}: error:" if line is not None else f"{source}: error:"
    assert err.startswith(where) and env in err and "limit of" in err, err
    return err


def _sparse(path: Path, head: str = "") -> Path:
    path.write_text(head)
    os.truncate(path, 2 * GIB)                    # a hole: costs no disk
    return path


@needs_dev_zero
def test_dev_zero_as_scenario_trajectory_and_log(cell):
    _, scen, traj = cell
    _one_line_error(_cli("certify", ZERO, "--traj", str(traj)), ZERO, 1, "CFMPA_MAX_LINE_BYTES")
    _one_line_error(_cli("certify", str(scen), "--traj", ZERO), ZERO, 1, "CFMPA_MAX_LINE_BYTES")
    _one_line_error(_cli("monitor", str(scen), "--traj", str(traj), "--log", ZERO), ZERO, 1,
                    "CFMPA_MAX_LINE_BYTES")
    with pytest.raises(InputError) as e:
        load_witness(ZERO)
    assert e.value.field == "witness" and "regular file" in e.value.render()


def test_a_sparse_2_gb_file_cut_short(cell, tmp_path):
    _, scen, traj = cell
    rows = traj.read_text()
    big = _sparse(tmp_path / "cut.csv", rows)     # the rows, then 2 GB of zero bytes
    after = rows.count("\n") + 1
    _one_line_error(_cli("certify", str(scen), "--traj", str(big)), str(big), after,
                    "CFMPA_MAX_LINE_BYTES")
    log = _sparse(tmp_path / "log.csv", HEADER + "0,0.3,0.8,1,1\n")
    _one_line_error(_cli("monitor", str(scen), "--traj", str(traj), "--log", str(log)),
                    str(log), 3, "CFMPA_MAX_LINE_BYTES")
    toml = _sparse(tmp_path / "w.toml", scen.read_text())
    _one_line_error(_cli("certify", str(toml), "--traj", str(traj)), str(toml),
                    scen.read_text().count("\n") + 1, "CFMPA_MAX_LINE_BYTES")
    js = _sparse(tmp_path / "t.json", '{"t": [0')
    _one_line_error(_cli("certify", str(scen), "--traj", str(js)), str(js), None,
                    "CFMPA_MAX_TRAJECTORY_BYTES")
    wit = _sparse(tmp_path / "w.npz")
    # Under the witness limit (32 GiB: it is read a layer at a time in place), it is no npz.
    with pytest.raises(InputError) as e:
        load_witness(wit)
    assert "is not an .npz witness file" in e.value.render()
    # Over a lowered limit, the limit is named.
    monkeypatch = pytest.MonkeyPatch()
    monkeypatch.setenv("CFMPA_MAX_WITNESS_BYTES", str(2**30))
    try:
        with pytest.raises(InputError) as e:
            load_witness(wit)
    finally:
        monkeypatch.undo()
    assert "CFMPA_MAX_WITNESS_BYTES" in e.value.render()


def test_a_100_mb_line_is_refused_at_its_line_and_not_echoed(cell, tmp_path):
    s, scen, traj = cell
    f = tmp_path / "long.csv"
    with open(f, "w") as fh:
        fh.write(HEADER + "0,0.3,0.8,1,1\n1,")
        fh.write("1" * 100_000_000)
        fh.write(",0.8,1,1\n")
    for args in (("certify", str(scen), "--traj", str(f)),
                 ("monitor", str(scen), "--traj", str(traj), "--log", str(f))):
        err = _one_line_error(_cli(*args), str(f), 3, "CFMPA_MAX_LINE_BYTES")
        assert len(err) < 400


def test_a_file_over_its_size_limit_names_the_line_and_the_limit(cell, tmp_path, capsys,
                                                                  monkeypatch):
    s, scen, traj = cell
    text = traj.read_text()
    monkeypatch.setenv("CFMPA_MAX_TRAJECTORY_BYTES", str(len(text) - 1))
    # A trajectory held whole is refused by its size, before its first line is read; the
    # streamed certify has no byte limit (docs/model.md §12; tests/runs/test_trajectory_limits).
    with pytest.raises(InputError) as e:
        load_trajectory(traj, s)
    err = e.value.render()
    assert err.startswith(f"{traj}: error: file is larger than the limit of {len(text) - 1:,} "
                          "bytes") and "CFMPA_MAX_TRAJECTORY_BYTES" in err
    assert main(["certify", str(scen), "--traj", str(traj)]) == 0
    monkeypatch.setenv("CFMPA_MAX_TRAJECTORY_BYTES", str(len(text)))
    assert load_trajectory(traj, s).rows == text.count("\n") - 1
    capsys.readouterr()
    monkeypatch.setenv("CFMPA_MAX_SCENARIO_BYTES", "100")
    with pytest.raises(InputError) as e:
        load_scenario(scen)
    assert "CFMPA_MAX_SCENARIO_BYTES" in e.value.render() and e.value.line is not None
    monkeypatch.setenv("CFMPA_MAX_SCENARIO_BYTES", "many")
    assert main(["certify", str(scen), "--traj", str(traj)]) == 2
    assert "CFMPA_MAX_SCENARIO_BYTES must be a positive integer" in capsys.readouterr().err


def test_the_line_limit_is_the_limit(tmp_path, monkeypatch):
    monkeypatch.setenv("CFMPA_MAX_LINE_BYTES", "10")
    f = tmp_path / "x"
    f.write_bytes(b"123456789\n1234567890\n")          # 10 bytes, then 11 with the newline
    with open(f, "rb") as fh:
        lines = bounded_lines(fh, str(f))
        assert next(lines) == "123456789\n"
        with pytest.raises(InputError) as e:
            next(lines)
    assert e.value.line == 2 and "10 bytes" in e.value.render()
    with pytest.raises(InputError) as e:
        read_bounded(f, LIMITS["scenario"], str(f))
    assert e.value.line == 2
    f.write_bytes(b"a\r\nb\xff\n")
    with open(f, "rb") as fh:
        lines = bounded_lines(fh, str(f))
        assert next(lines) == "a\n"
        with pytest.raises(InputError) as e:
            next(lines)
    assert e.value.line == 2 and "UTF-8" in e.value.render()


def test_an_echoed_value_is_cut_to_80_characters(cell, tmp_path):
    s, _, _ = cell
    assert echo("short") == "short" and echo(3.0) == 3.0
    assert len(repr(echo("x" * 1000))) == ECHO_CHARS + 3
    f = tmp_path / "t.csv"
    f.write_text(HEADER + "0,0.3,0.8,1,1\n1," + "9" * 50 + "z" * 500 + ",0.8,1,1\n")
    with pytest.raises(InputError) as e:
        load_trajectory(f, s)
    msg = e.value.render()
    assert e.value.line == 3 and "must be a number" in msg and len(msg) - len(str(f)) < 160
    assert msg.endswith("...") and "z" * 20 in msg and "z" * 100 not in msg


def test_streamed_csv_agrees_with_text(cell, tmp_path):
    s, _, traj_csv = cell
    traj = load_trajectory(traj_csv, s)
    f = tmp_path / "crlf.csv"
    f.write_bytes(trajectory_csv(traj).replace("\n", "\r\n").encode() + b"\r\n\r\n")
    back = load_trajectory(f, s)
    assert np.array_equal(back.t, traj.t) and np.array_equal(back.angles, traj.angles)
    assert back.lines == traj.lines


def test_the_seeded_fault_of_an_unbounded_reader_is_caught(cell, tmp_path, monkeypatch):
    # The check above, in process on a smaller limit: a reader that reads lines unbounded (the
    # fault, planted in the trajectory module) no longer refuses the long line at its limit.
    s, _, _ = cell
    f = tmp_path / "long.csv"
    f.write_text(HEADER + "0,0.3,0.8,1,1\n1," + "1" * 5000 + ",0.8,1,1\n")
    monkeypatch.setenv("CFMPA_MAX_LINE_BYTES", "1000")

    def refused() -> bool:
        try:
            load_trajectory(f, s)
        except InputError as exc:
            return exc.line == 3 and "CFMPA_MAX_LINE_BYTES" in exc.render()
        return False

    assert refused()
    from cfmpa.spec import _trajectory
    monkeypatch.setattr(_trajectory, "bounded_lines",
                        lambda fh, source, total=None: (x.decode() for x in fh))
    assert not refused()
