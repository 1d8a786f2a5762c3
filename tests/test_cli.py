"""The command line as a user runs it: exit codes, messages without tracebacks, atomic output."""

from __future__ import annotations

import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

from cfmpa.cli import main
from cfmpa.spec import load_scenario, make_grid

ROOT = Path(__file__).resolve().parents[1]


@pytest.fixture
def tiny_file(tmp_path):
    text = (ROOT / "scenarios" / "default.toml").read_text()
    p = tmp_path / "tiny.toml"
    p.write_text(text.replace("dt = 0.02", "dt = 0.25").replace("start_cell = [40, 100]",
                 "start_cell = [3, 8]").replace("goal_cell = [150, 60]", "goal_cell = [12, 5]"))
    return p


def test_dr_writes_the_array_and_reports_the_grid(tiny_file, tmp_path, capsys):
    out = tmp_path / "out"
    assert main(["dr", str(tiny_file), "--variant", "tight", "--out", str(out)]) == 0
    dr = np.load(out / "dr.npy")
    g = make_grid(load_scenario(tiny_file))
    assert dr.shape == (g.N + 1, g.m, g.n) and dr.dtype == np.uint8
    text = capsys.readouterr().out
    assert f"N={g.N} m={g.m} n={g.n}" in text and "free" in text and "time" in text
    assert not list(out.glob(".*tmp"))  # no temporary left behind


def test_bad_scenario_exits_2_with_file_line_message(tiny_file, tmp_path, capsys):
    tiny_file.write_text(tiny_file.read_text().replace("omega = [1.0, 1.0]\nlimits",
                                                       "omega = [1.0, -1.0]\nlimits"))
    out = tmp_path / "out"
    assert main(["dr", str(tiny_file), "--out", str(out)]) == 2
    err = capsys.readouterr().err
    assert "error: right.omega[1] must be > 0, got -1.0" in err
    assert err.startswith(f"{tiny_file}:")
    assert "Traceback" not in err
    assert not out.exists()


def test_unknown_variant_and_missing_file_exit_2(tmp_path, capsys):
    with pytest.raises(SystemExit) as info:
        main(["dr", "x.toml", "--variant", "sideways", "--out", str(tmp_path)])
    assert info.value.code == 2
    assert main(["dr", str(tmp_path / "missing.toml"), "--out", str(tmp_path)]) == 2
    assert "cannot be read" in capsys.readouterr().err


def test_console_script_runs_without_traceback(tmp_path):
    proc = subprocess.run([sys.executable, "-m", "cfmpa", "dr", str(tmp_path / "nope.toml"),
                           "--out", str(tmp_path)], capture_output=True, text=True)
    assert proc.returncode == 2
    assert "Traceback" not in proc.stderr and "error:" in proc.stderr


def _without_timings(path: Path) -> str:
    import json

    doc = json.loads(path.read_text())
    doc.pop("timings_s")
    return json.dumps(doc, sort_keys=True)


def test_plan_writes_stable_json_and_a_summary(tiny_file, tmp_path, capsys):
    outs = [tmp_path / "a", tmp_path / "b"]
    for out in outs:
        assert main(["plan", str(tiny_file), "--variant", "modified", "--out", str(out),
                     "--contracts", "off"]) == 0
    text = capsys.readouterr().out
    for word in ("variant", "grid", "free", "status", "time"):
        assert word in text
    a, b = (_without_timings(o / "plan.json") for o in outs)
    assert a == b
    import json

    doc = json.loads((outs[0] / "plan.json").read_text())
    for key in ("scenario", "scenario_sha256", "variant", "grid", "status", "reason", "path",
                "angles", "J1", "J2", "clearance", "contracts", "timings_s", "versions"):
        assert key in doc
    assert set(doc["grid"]) >= {"N", "m", "n", "dt", "lo", "h"}
    assert np.load(outs[0] / "dr.npy").shape == (doc["grid"]["N"] + 1, doc["grid"]["m"],
                                                 doc["grid"]["n"])
    if doc["status"] == "found":
        assert doc["path"][0] == [3, 8] and doc["path"][-1] == [12, 5]
        assert len(doc["angles"]) == len(doc["path"])


def test_plan_into_an_unwritable_place_exits_2(tiny_file, tmp_path, capsys):
    blocker = tmp_path / "file"
    blocker.write_text("not a folder")
    assert main(["plan", str(tiny_file), "--out", str(blocker / "x"), "--contracts", "off"]) == 2
    assert "error" in capsys.readouterr().err


def test_plan_with_a_contact_exits_1_in_every_mode_and_keeps_the_evidence(tmp_path, monkeypatch,
                                                                           capsys):
    # The early-arrival fault's path waits at its goal while the principal sweeps it: a real
    # contact. --contracts off waives the triples, not the certificate.
    import json

    import cfmpa.cli as cli
    from cfmpa.impl import build_dr_fast
    from cfmpa.proofs._selftest import FAULTS, WORKCELLS

    fault = next(f for f in FAULTS if "early" in f.name)
    doc = WORKCELLS[fault.workcell]
    lines = [f"{k} = {json.dumps(doc[k])}" for k in ("name", "purpose", "dt")]
    for side in ("left", "right"):
        lines += [f"[{side}]"] + [f"{k} = {json.dumps(v)}" for k, v in doc[side].items()]
    toml = tmp_path / "early.toml"
    toml.write_text("\n".join(lines) + "\n")
    s = load_scenario(toml)
    bad = fault.make(s, fault.variant, make_grid(s)).search
    monkeypatch.setattr(cli, "_kernels", lambda name: (build_dr_fast, bad))
    for mode in ("off", "sampled"):
        out = tmp_path / mode
        assert main(["plan", str(toml), "--variant", fault.variant.value, "--out", str(out),
                     "--contracts", mode]) == 1
        text, err = capsys.readouterr()
        assert "clearance NOT CLEAR: contact at t=" in text and "resting at the last cell" in text
        assert "violation continuous-time certificate: the arms' link rectangles touch" in err
        assert "exit 1; the files above are written as the evidence" in err
        plan_doc = json.loads((out / "plan.json").read_text())
        assert plan_doc["clearance"]["clear"] is False and (out / "dr.npy").exists()
        assert plan_doc["contracts"]["violations"][-1]["triple"] == "continuous-time certificate"
