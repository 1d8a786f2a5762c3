"""The command line as a user runs it: exit codes, messages without tracebacks, atomic output."""

from __future__ import annotations

import re
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

import factory
from cfmpa.cli import main
from cfmpa.spec import load_scenario, make_grid

ROOT = Path(__file__).resolve().parents[1]


@pytest.fixture
def tiny_file(tmp_path):
    text = factory.FORMER_DEFAULT.read_text()
    p = tmp_path / "tiny.toml"
    # The former default workcell at dt = 0.25 s (grid 7 x 27 x 27), with cells between which a
    # path exists under every variant.
    p.write_text(factory.edited(text, ("dt = 0.02", "dt = 0.25"),
                                ("start_cell = [40, 100]", "start_cell = [2, 8]"),
                                ("goal_cell = [150, 60]", "goal_cell = [13, 5]")))
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


def _without_timings(path: Path) -> bytes:
    """plan.json's raw bytes with only the timings_s block cut out (keys are sorted, indent 2)."""
    lines = path.read_bytes().splitlines(keepends=True)
    at = lines.index(b'  "timings_s": {\n')
    end = next(k for k in range(at, len(lines)) if lines[k].startswith(b"  }"))
    assert b'"timings_s"' not in b"".join(lines[:at] + lines[end + 1:])
    return b"".join(lines[:at] + lines[end + 1:])


def test_plan_writes_stable_json_and_a_summary(tiny_file, tmp_path, capsys):
    outs = [tmp_path / "a", tmp_path / "b"]
    texts = []
    for out in outs:
        assert main(["plan", str(tiny_file), "--variant", "modified", "--out", str(out),
                     "--contracts", "off"]) == 0
        texts.append(capsys.readouterr().out)
    # byte-identical apart from timings_s, compared on the raw bytes (not re-serialised)
    a, b = (_without_timings(o / "plan.json") for o in outs)
    assert a == b
    assert (outs[0] / "dr.npy").read_bytes() == (outs[1] / "dr.npy").read_bytes()
    import json

    doc = json.loads((outs[0] / "plan.json").read_text())
    for key in ("scenario", "scenario_sha256", "variant", "grid", "status", "reason", "path",
                "angles", "J1", "J2", "clearance", "contracts", "timings_s", "versions",
                "dr_sha256", "kernel"):
        assert key in doc
    assert set(doc["grid"]) >= {"N", "m", "n", "dt", "lo", "h"}
    assert np.load(outs[0] / "dr.npy").shape == (doc["grid"]["N"] + 1, doc["grid"]["m"],
                                                 doc["grid"]["n"])
    assert doc["status"] == "found"
    assert doc["path"][0] == [2, 8] and doc["path"][-1] == [13, 5]
    assert len(doc["angles"]) == len(doc["path"])
    # the summary: variant, grid, free fraction, status, J1, J2, length, both clearance figures,
    # and the times of every stage
    text = texts[0]
    g = doc["grid"]
    assert "variant   modified" in text and f"N={g['N']} m={g['m']} n={g['n']}" in text
    assert f"free      {doc['free_fraction']:.4%} of cells" in text
    assert (f"status    found: J1={doc['J1']} J2={doc['J2']} length={len(doc['path'])} cells"
            in text)
    c = doc["clearance"]
    assert (f"proved >= {c['lower_bound_m'] * 1000:.6g} mm at every instant; sampled minimum "
            f"{c['min_m'] * 1000:.6g} mm at t={c['t_s']:.4f} s" in text)
    time_line = next(x for x in text.splitlines() if x.startswith("time "))
    for stage in ("build_dr", "search", "certificate"):
        assert re.search(rf"{stage} \d+\.\d{{3}} s", time_line), stage


def test_the_atomic_writer_leaves_the_old_file_and_no_temporary_when_interrupted(
        tmp_path, monkeypatch):
    from cfmpa import files as _io

    target = tmp_path / "plan.json"
    target.write_bytes(b"old")

    def boom(*args):
        raise OSError(28, "No space left on device")

    for name in ("replace", "fsync"):
        with monkeypatch.context() as m:
            m.setattr(_io.os, name, boom)
            with pytest.raises(OSError, match="No space"):
                _io.write_bytes_atomic(target, b"new and complete")
        assert target.read_bytes() == b"old", name
        assert sorted(p.name for p in tmp_path.iterdir()) == ["plan.json"], name
    _io.write_bytes_atomic(target, b"new")           # and without the fault it is replaced
    assert target.read_bytes() == b"new"


def test_plan_interrupted_at_the_rename_exits_2_and_keeps_the_old_files(tiny_file, tmp_path,
                                                                         monkeypatch, capsys):
    from cfmpa import files as _io

    out = tmp_path / "out"
    assert main(["plan", str(tiny_file), "--out", str(out), "--contracts", "off"]) == 0
    before = {p.name: p.read_bytes() for p in out.iterdir()}
    capsys.readouterr()

    def boom(src, dst):
        raise OSError(5, "Input/output error", str(dst))

    monkeypatch.setattr(_io.os, "replace", boom)
    assert main(["plan", str(tiny_file), "--variant", "tight", "--out", str(out),
                 "--contracts", "off"]) == 2
    err = capsys.readouterr().err
    assert "Input/output error" in err and "Traceback" not in err
    assert {p.name: p.read_bytes() for p in out.iterdir()} == before


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

    import cfmpa.impl as impl
    from cfmpa.impl import build_dr_fast
    from cfmpa.runs._selftest import FAULTS, WORKCELLS

    fault = next(f for f in FAULTS if "early" in f.name)
    doc = WORKCELLS[fault.workcell]
    toml = tmp_path / "early.toml"
    toml.write_text(factory.toml(doc))
    s = load_scenario(toml)
    bad = fault.make(s, fault.variant, make_grid(s)).search
    monkeypatch.setattr(impl, "kernels", lambda name: (build_dr_fast, bad))
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


def test_prove_with_a_bad_scenarios_folder_writes_no_report(tmp_path, capsys):
    # A bad folder is exit 2 and no report is written (the report process fails on the same
    # input; the stop mechanism itself is the next test's).
    code = main(["prove", "--scenarios", str(tmp_path / "none"), "--out", str(tmp_path / "p"),
                 "--audit", str(tmp_path / "a")])
    err = capsys.readouterr().err
    assert code == 2 and "--scenarios" in err and "Traceback" not in err
    assert not (tmp_path / "a").exists()


def test_prove_refuses_an_audit_of_a_partial_run(tmp_path, capsys):
    # --only with --audit would write a report of a selection: refused before any work.
    code = main(["prove", "--only", "Prop8", "--out", str(tmp_path / "p"), "--audit",
                 str(tmp_path / "a")])
    err = capsys.readouterr().err
    assert code == 2 and "--audit needs every obligation" in err and "Traceback" not in err
    assert not (tmp_path / "p").exists() and not (tmp_path / "a").exists()


def test_prove_that_stops_opens_the_gate_with_stop_and_the_report_writes_nothing(
        tmp_path, capsys, monkeypatch):
    # The report process (forked) waits at the gate for the proofs; a prove run that stops must
    # release it with `stopped`, so that it ends writing nothing. A stand-in report writes a
    # marker as soon as the gate hands it the results path; a stand-in prove run stops.
    import time

    import cfmpa.proofs
    import cfmpa.report
    from cfmpa.errors import InputError

    marker = tmp_path / "a" / "written"

    def report(files, out_dir, *, proofs_json, **kw):
        path = proofs_json()
        marker.parent.mkdir(parents=True, exist_ok=True)
        marker.write_text(str(path))
        return 0
    monkeypatch.setattr(cfmpa.report, "run_audit", report)

    def proving(stops):
        def run(**kw):
            time.sleep(0.3)                       # the report process is waiting by now
            if stops:
                raise InputError("--scenarios", "x", "stands for any stop")
            return 0
        return run

    monkeypatch.setattr(cfmpa.proofs, "run_prove", proving(True))
    code = main(["prove", "--out", str(tmp_path / "p"), "--audit", str(tmp_path / "a")])
    assert code == 2 and "stands for any stop" in capsys.readouterr().err
    assert not marker.exists()
    # The stand-in writes when the prove run goes through, so its silence above means something.
    monkeypatch.setattr(cfmpa.proofs, "run_prove", proving(False))
    assert main(["prove", "--out", str(tmp_path / "p"), "--audit", str(tmp_path / "a")]) == 0
    assert marker.read_text().endswith("results.json")


def test_prove_audit_prints_the_reports_stage_lines_on_stderr(tmp_path, capfd, monkeypatch):
    # As `cfmpa audit` does: the report process (forked) writes a line per
    # stage on its stderr. A stand-in report writes a stage line to the progress stream it is
    # given; a stand-in prove run succeeds. capfd: the child writes to the inherited fd 2.
    import cfmpa.proofs
    import cfmpa.report

    def report(files, out_dir, *, proofs_json, progress=None, **kw):
        proofs_json()
        if progress is not None:
            progress.write("audit: proofs (read from the prove run)   1.0 s\n")
        return 0
    monkeypatch.setattr(cfmpa.report, "run_audit", report)
    monkeypatch.setattr(cfmpa.proofs, "run_prove", lambda **kw: 0)
    assert main(["prove", "--out", str(tmp_path / "p"), "--audit", str(tmp_path / "a")]) == 0
    out, err = capfd.readouterr()
    assert "audit: proofs (read from the prove run)" in err and "audit: " not in out


# --- outputs checked before the work -----------------------------------------------------------

def _no_work(monkeypatch):
    """Every computation a command could start raises: a command that gets past its checks
    fails the test loudly instead of computing."""
    import cfmpa.proofs
    import cfmpa.report
    import cfmpa.runs

    def computes(*args, **kw):
        raise AssertionError("the command computed before refusing its output")
    for module, name in [(cfmpa.runs, "run_dr"), (cfmpa.runs, "run_plan"),
                         (cfmpa.runs, "run_batch"), (cfmpa.runs, "run_certify"),
                         (cfmpa.runs, "run_monitor"), (cfmpa.runs, "run_simulate"),
                         (cfmpa.runs, "run_code_selftest"), (cfmpa.report, "run_audit"),
                         (cfmpa.report, "run_compare"), (cfmpa.report, "run_prove_audit"),
                         (cfmpa.proofs, "run_prove")]:
        monkeypatch.setattr(module, name, computes)


#: (command line with {bad} for the output, the option named) for every output option.
OUTPUTS = [
    (["dr", "default", "--out", "{bad}"], "--out"),
    (["plan", "default", "--out", "{bad}"], "--out"),
    (["plan", "default", "--out", "{ok}", "--witness-out", "{bad}"], "--witness-out"),
    (["plan", "default", "--out", "{ok}", "--witness", "{bad}"], "--witness-out"),   # old
    (["check-batch", "{ok}", "--json", "{bad}"], "--json"),
    (["check", "--batch", "{ok}", "--json", "{bad}"], "--json"),                     # old
    (["mutants", "--json", "{bad}"], "--json"),
    (["selftest", "--code", "--json", "{bad}"], "--json"),                           # old
    (["prove", "--out", "{bad}"], "--out"),
    (["prove", "--out", "{ok}", "--audit", "{bad}"], "--audit"),
    (["audit", "--out", "{bad}"], "--out"),
    (["compare", "--out", "{bad}"], "--out"),
    (["certify", "default", "--traj", "t.csv", "--json", "{bad}"], "--json"),
    (["monitor", "default", "--traj", "t.csv", "--log", "l.csv", "--json", "{bad}"], "--json"),
    (["simulate", "default", "--traj", "t.csv", "--log-out", "{bad}"], "--log-out"),
    (["simulate", "default", "--traj", "t.csv", "--out", "{bad}"], "--log-out"),      # old
]


def _is_file_option(argv, option):
    return option in ("--json", "--witness-out") or argv[0] == "simulate"


@pytest.mark.parametrize("argv, option", OUTPUTS, ids=lambda x: " ".join(x)
                         if isinstance(x, list) else x)
@pytest.mark.parametrize("bad", ["wrong kind", "dangling link", "under a file"])
def test_a_bad_output_is_exit_2_before_any_work(tmp_path, monkeypatch, capsys, argv, option,
                                                 bad):
    _no_work(monkeypatch)
    ok = tmp_path / "ok"
    ok.mkdir()
    blocker = tmp_path / "blocker"
    blocker.write_text("a file")
    target = {"wrong kind": (ok if _is_file_option(argv, option) else blocker),
              "dangling link": tmp_path / "link",
              "under a file": blocker / "x"}[bad]
    if bad == "dangling link":
        target.symlink_to(tmp_path / "nowhere")
    before = sorted(p.name for p in tmp_path.rglob("*"))
    line = [a.format(bad=target, ok=ok) for a in argv]
    assert main(line) == 2
    err = capsys.readouterr().err
    assert f"error: {option} " in err and str(target) in err and "Traceback" not in err
    assert {"wrong kind": "not a", "dangling link": "dangling symbolic link",
            "under a file": "is a file, not a folder"}[bad] in err
    assert sorted(p.name for p in tmp_path.rglob("*")) == before       # nothing written


def test_plan_into_an_existing_file_fails_before_planning(tmp_path, monkeypatch, capsys):
    # The case: `cfmpa plan default --out victim.txt` planned the whole workcell first.
    _no_work(monkeypatch)
    victim = tmp_path / "victim.txt"
    victim.write_text("keep me")
    assert main(["plan", "default", "--out", str(victim)]) == 2
    assert "error: --out is a file, not a folder" in capsys.readouterr().err
    assert victim.read_text() == "keep me"


def test_an_unwritable_folder_is_exit_2_before_any_work(tmp_path, monkeypatch, capsys):
    import os

    _no_work(monkeypatch)
    locked = tmp_path / "locked"
    locked.mkdir()
    locked.chmod(0o555)
    if os.geteuid() == 0:
        # root may write anywhere: stand in for the permission a user would lack.
        real = os.access
        monkeypatch.setattr(os, "access", lambda p, mode, **kw: (
            False if Path(p) == locked and mode & os.W_OK else real(p, mode, **kw)))
    try:
        assert main(["plan", "default", "--out", str(locked / "plan")]) == 2
        err = capsys.readouterr().err
        assert "error: --out cannot be written: this user may not write in the folder" in err
        assert main(["certify", "default", "--traj", "t.csv", "--json",
                     str(locked / "c.json")]) == 2
        assert "error: --json cannot be written" in capsys.readouterr().err
    finally:
        locked.chmod(0o755)
    assert list(locked.iterdir()) == []


def test_a_good_output_gets_through_the_check(tmp_path, monkeypatch, capsys):
    # The check refuses only what cannot be written: a new folder under a writable one, an
    # existing folder, an existing file to replace get through to the command (here a stub).
    import cfmpa.runs

    seen = []
    monkeypatch.setattr(cfmpa.runs, "run_dr", lambda *a, **kw: seen.append(a[2]) or 0)
    monkeypatch.setattr(cfmpa.runs, "run_certify", lambda *a, **kw: seen.append(kw["json_out"])
                        or 0)
    (tmp_path / "old.json").write_text("{}")
    assert main(["dr", "default", "--out", str(tmp_path / "new" / "deeper")]) == 0
    assert main(["dr", "default", "--out", str(tmp_path)]) == 0
    assert main(["certify", "default", "--traj", "t", "--json", str(tmp_path / "old.json")]) == 0
    assert len(seen) == 3


# --- exceptions to exit codes, in one place (cfmpa.errors) ---------------------------------------

@pytest.mark.parametrize("exc, code, said", [
    (lambda: __import__("cfmpa.errors").errors.InputError("--n", 5, "is bad"), 2,
     "error: --n is bad, got 5"),
    (lambda: __import__("cfmpa.errors").errors.ContractViolation("T", "post.x: broke"), 1,
     "error: T: post.x: broke"),
    (lambda: OSError(28, "No space left on device", "/full/x"), 2,
     "/full/x: error: No space left on device"),
    (lambda: KeyboardInterrupt(), 130, "interrupted"),
])
def test_handled_maps_each_error_to_its_exit_code_and_one_line(exc, code, said):
    import io

    from cfmpa.errors import exit_code, handled

    err = io.StringIO()

    def run() -> int:
        raise exc()
    assert handled(run, err) == code and exit_code(exc()) == code
    assert err.getvalue() == said + "\n"


def test_handled_lets_a_bug_keep_its_traceback():
    from cfmpa.errors import exit_code, handled

    def run() -> int:
        raise ZeroDivisionError("a bug")
    assert exit_code(ZeroDivisionError()) is None
    with pytest.raises(ZeroDivisionError):
        handled(run)


# --- numeric budgets ------------------------------------------------------------------------------

@pytest.fixture
def rest_traj(tmp_path):
    """A two-row trajectory of the default workcell at rest: simulate reads it in milliseconds."""
    p = tmp_path / "traj.csv"
    p.write_text("t,left1,left2,right1,right2\n0,0.1,0.2,0.3,0.4\n1,0.1,0.2,0.3,0.4\n")
    return p


@pytest.mark.parametrize("extra, said", [
    (["--samples", "10000000000"], "--samples must be at most 1000000 (the simulated log's "
                                   "budget), got 10000000000"),
    (["--period", "1e-12"], "--period must be at least 1e-06"),
    (["--period", "0.0001", "--tail", "3600"], "--period gives 3.601e+07 samples over 3601 s, "
                                               "more than the simulated log's budget of 1000000"),
    (["--lag", "nan"], "--lag must be a finite number, got nan"),
    (["--noise", "inf"], "--noise must be a finite number"),
    (["--seed", "-1"], "--seed must be at least 0"),
])
def test_simulate_over_budget_is_exit_2_and_writes_nothing(tmp_path, rest_traj, capsys, extra,
                                                          said):
    log = tmp_path / "log.csv"
    assert main(["simulate", "default", "--traj", str(rest_traj), "--out", str(log),
                 *extra]) == 2
    err = capsys.readouterr().err
    assert said in err and "Traceback" not in err
    assert sorted(p.name for p in tmp_path.iterdir()) == ["traj.csv"]


def test_simulate_within_budget_still_writes(tmp_path, rest_traj):
    # The budget refuses what is over it, not what is at it: a million samples exactly pass
    # the option's check (the run's own count is the same number).
    from cfmpa.runs import MAX_LOG_SAMPLES, simulate_log
    from cfmpa.scenarios import resolve
    from cfmpa.spec import load_scenario, load_trajectory

    traj = load_trajectory(rest_traj, load_scenario(resolve("default")))
    assert len(simulate_log(traj, samples=MAX_LOG_SAMPLES)[0]) == MAX_LOG_SAMPLES
    assert main(["simulate", "default", "--traj", str(rest_traj), "--out",
                 str(tmp_path / "log.csv"), "--samples", "3"]) == 0
    assert len((tmp_path / "log.csv").read_text().splitlines()) == 4


@pytest.mark.parametrize("argv, said", [
    (["compare", "--n", "1000000000000"], "--n must be at most 1000000 (the campaign's budget)"),
    (["compare", "--n", "2", "--workers", "100000"], "--workers must be at most"),
    (["compare", "--n", "2", "--connect-timeout", "inf"], "--connect-timeout must be a finite"),
    (["compare", "--n", "2", "--dt", "nan"], "--dt must be a finite number"),
    (["compare", "--n", "2", "--seed", "-3"], "--seed must be at least 0"),
])
def test_compare_over_budget_is_exit_2_and_leaves_no_store(tmp_path, monkeypatch, capsys, argv,
                                                           said):
    _no_work(monkeypatch)
    out = tmp_path / "c"
    assert main([*argv, "--out", str(out)]) == 2
    err = capsys.readouterr().err
    assert said in err and "Traceback" not in err
    assert not out.exists()


def test_the_campaign_refuses_too_many_workcells_before_its_store(tmp_path):
    # The run's own budget, for a caller that is not the command line.
    from cfmpa.errors import InputError
    from cfmpa.runs import MAX_WORKCELLS, run_campaign

    with pytest.raises(InputError, match="--n must be at most"):
        run_campaign(MAX_WORKCELLS + 1, out=tmp_path / "c")
    assert not (tmp_path / "c").exists()


@pytest.mark.parametrize("argv, said", [
    (["plan", "default", "--out", "{tmp}", "--sample", str(2**60)], "--sample must be at most"),
    (["plan", "default", "--out", "{tmp}", "--seed", str(2**64)], "--seed must be at most"),
    (["check", "--batch", "{tmp}", "--workers", "100000"], "--workers must be at most"),
    (["prove", "--out", "{tmp}", "--jobs", "100000"], "--jobs must be at most"),
    (["prove", "--out", "{tmp}", "--workers", "100000"], "--jobs must be at most"),   # old
    (["audit", "--out", "{tmp}", "--compare-n", str(10**9)], "--compare-n must be at most"),
])
def test_every_other_numeric_option_has_a_budget(tmp_path, monkeypatch, capsys, argv, said):
    _no_work(monkeypatch)
    assert main([a.format(tmp=tmp_path / "o") for a in argv]) == 2
    assert said in capsys.readouterr().err
    assert not (tmp_path / "o").exists()


def test_every_numeric_option_is_budgeted():
    # Every option parsed as a number (int, float or the whole-number type) is recorded with a
    # Budget: a new numeric option without one fails here.
    import argparse

    from cfmpa._arguments import Budget
    from cfmpa.cli import _parser

    sub = next(a for a in _parser()._actions if isinstance(a, argparse._SubParsersAction))
    unbudgeted = []
    for name, p in sub.choices.items():
        checked = {(dest, option) for dest, option, check in p.get_default("_checks") or ()
                   if isinstance(check, Budget)}
        for a in p._actions:
            if ((a.type in (int, float) or getattr(a.type, "__name__", "") == "positive")
                    and (a.dest, a.option_strings[0]) not in checked):
                unbudgeted.append(f"{name} {a.option_strings[0]}")
    assert unbudgeted == []


# --- help for users -------------------------------------------------------------------------------

def _subparsers():
    import argparse

    from cfmpa.cli import _parser

    p = _parser()
    sub = next(a for a in p._actions if isinstance(a, argparse._SubParsersAction))
    return p, sub


def test_the_top_help_says_what_the_tool_does_a_first_command_and_the_exit_codes(capsys):
    with pytest.raises(SystemExit) as info:
        main(["--help"])
    assert info.value.code == 0
    text = capsys.readouterr().out
    assert "The command line" not in text and "main(argv)" not in text   # not the developer's
    assert "cfmpa plans the subordinate arm's collision-free motion" in text
    assert "cfmpa plan default --out plan" in text
    codes = text[text.index("exit codes:"):]
    for code, words in ((0, "success"), (1, "a check failed"), (2, "bad input"),
                        (130, "interrupted")):
        assert re.search(rf"^  {code} +{words}", codes, re.M), (code, codes)


def test_every_subcommand_has_a_one_line_description_and_an_example_that_parses():
    p, sub = _subparsers()
    listed = {a.dest: a.help for a in sub._choices_actions}
    assert set(listed) == set(sub.choices)
    for name, sp in sub.choices.items():
        assert listed[name] and "\n" not in listed[name], name
        assert sp.description and sp.description.rstrip(".").lower() == listed[name].lower()
        assert sp.epilog and sp.epilog.startswith("example:\n  cfmpa " + name), name
        example = sp.epilog.splitlines()[1].split()[1:]
        args = p.parse_args(example)             # the example is a command line the parser takes
        assert args.command == name and args.func is sp.get_default("func")


def test_a_batch_folder_that_cannot_take_its_summary_is_refused_before_any_check(
        tmp_path, monkeypatch, capsys):
    # Without --json the summary is written into DIR: a DIR this user may not write is exit 2
    # before a plan is checked; with --json elsewhere the same DIR is only read.
    import os

    import cfmpa.runs

    _no_work(monkeypatch)
    locked = tmp_path / "plans"
    locked.mkdir()
    real = os.access
    monkeypatch.setattr(os, "access", lambda p, mode, **kw: (
        False if Path(p) == locked and mode & os.W_OK else real(p, mode, **kw)))
    assert main(["check", "--batch", str(locked), "--workers", "0"]) == 2
    assert "error: --batch cannot be written" in capsys.readouterr().err
    monkeypatch.setattr(cfmpa.runs, "run_batch", lambda *a, **kw: 0)
    assert main(["check", "--batch", str(locked), "--workers", "0", "--json",
                 str(tmp_path / "summary.json")]) == 0


def test_a_budget_checks_each_value_of_a_repeated_option():
    from cfmpa._arguments import Budget
    from cfmpa.errors import InputError

    b = Budget(0, 10, "why")
    b("--x", [1.0, 10.0])
    with pytest.raises(InputError, match=r"--x must be at most 10 \(why\), got 11.0"):
        b("--x", [1.0, 11.0])
    with pytest.raises(InputError, match="--x must be a finite number"):
        b("--x", (float("nan"),))


# --- every run_* prints on the streams it is given ------------------------------------------------

def test_the_commands_runs_print_on_the_streams_they_are_given(tiny_file, tmp_path, capsys):
    import io

    from cfmpa.runs import run_check, run_dr, run_plan, run_scenarios

    out, err = io.StringIO(), io.StringIO()
    assert run_dr(tiny_file, "tight", tmp_path / "d", kernel="reference", stdout=out) == 0
    assert "variant   tight (reference kernel)" in out.getvalue()
    assert run_plan(tiny_file, "modified", tmp_path / "p", contracts="off", stdout=out,
                    stderr=err) == 0
    assert "contracts off:" in out.getvalue() and err.getvalue() == ""
    assert run_check(tiny_file, tmp_path / "p" / "dr.npy", tmp_path / "p" / "plan.json",
                     stdout=out) == 0
    assert "result: all checks hold" in out.getvalue()
    assert run_scenarios(stdout=out) == 0 and "bundled scenarios in" in out.getvalue()
    from cfmpa.report import run_compare

    assert run_compare(n=1, dt=0.5, workers=0, progress=False, stdout=out) == 0
    assert "workcell(s) planned in" in out.getvalue()
    assert capsys.readouterr() == ("", "")        # nothing went to the process's own streams


#: A trajectory of the bundled default workcell that holds still (clear), and one that sweeps
#: the subordinate's upper arm into the principal's (in contact at t ~ 1.25 s).
STILL = "t,left1,left2,right1,right2\n0,0.3,0.8,3.3,0.5\n2,0.3,0.8,3.3,0.5\n"
SWEEP = "t,left1,left2,right1,right2\n0,0.3,0.8,3.3,0.5\n12,0.3,0.8,1.2,0.5\n"


def test_certify_monitor_simulate_print_verdict_and_details_on_the_stdout_given(tmp_path,
                                                                               capsys):
    """docs/model.md §7: each run_* takes its streams and returns the exit code; a verdict and
    its details go to the stdout it is given (stderr is for errors proper, which are raised)."""
    import io

    from cfmpa.runs import Excursion, run_certify, run_monitor, run_simulate
    from cfmpa.scenarios import resolve

    scen = resolve("default")
    still, sweep = tmp_path / "still.csv", tmp_path / "sweep.csv"
    still.write_text(STILL)
    sweep.write_text(SWEEP)

    def run(f, *a, **kw):
        out, err = io.StringIO(), io.StringIO()
        return f(*a, stdout=out, stderr=err, **kw), out.getvalue(), err.getvalue()

    code, out, err = run(run_certify, scen, still)
    assert code == 0 and "clearance clear: proved >=" in out and err == ""
    code, out, err = run(run_certify, scen, sweep)
    assert code == 1 and "clearance NOT CLEAR: contact at t=1.25" in out and err == ""
    code, out, err = run(run_simulate, scen, still, tmp_path / "log.csv", period=0.01)
    assert code == 0 and f"wrote     {tmp_path / 'log.csv'} (CSV)" in out and err == ""
    code, out, err = run(run_monitor, scen, still, tmp_path / "log.csv")
    assert code == 0 and "inside;" in out and err == ""
    code, out, err = run(run_simulate, scen, still, tmp_path / "bad.csv", period=0.01,
                         excursions=[Excursion(1.0, "right1", 0.2)])
    assert code == 0 and err == ""
    code, out, err = run(run_monitor, scen, still, tmp_path / "bad.csv")
    assert code == 1 and err == ""
    verdict, first = out.splitlines()[:2]
    assert "outside (" in verdict and first.startswith("first     outside at t=1")
    code, out, err = run(run_monitor, scen, sweep, tmp_path / "log.csv")
    assert code == 1 and "is not certified clear" in out and err == ""
    assert capsys.readouterr() == ("", "")        # nothing went to the process's own streams


# --- one name, one meaning; old spellings still work (docs/model.md §7) -------------------------

def _calls(monkeypatch, module, name):
    """Record the keyword arguments (and positional ones as "args") of ``module.name``'s
    calls, instead of running it."""
    seen: list[dict] = []
    monkeypatch.setattr(module, name, lambda *a, **kw: seen.append({"args": a, **kw}) or 0)
    return seen


@pytest.mark.parametrize("new, old, where, key", [
    (["plan", "default", "--out", "{d}", "--witness-out", "{d}/w.npz"],
     ["plan", "default", "--out", "{d}", "--witness", "{d}/w.npz"], "run_plan", "witness"),
    (["simulate", "default", "--traj", "t.csv", "--log-out", "{d}/log.csv"],
     ["simulate", "default", "--traj", "t.csv", "--out", "{d}/log.csv"], "run_simulate",
     "args"),
    (["prove", "--out", "{d}", "--jobs", "1"], ["prove", "--out", "{d}", "--workers", "1"],
     "run_prove", "workers"),
    (["check-batch", "{d}", "--workers", "0", "--json", "{d}/s.json"],
     ["check", "--batch", "{d}", "--workers", "0", "--json", "{d}/s.json"], "run_batch",
     "args"),
    (["mutants", "--mutant", "margin_halved", "--checks", "prove", "--json", "{d}/m.json"],
     ["selftest", "--code", "--mutant", "margin_halved", "--checks", "prove", "--json",
      "{d}/m.json"], "run_code_selftest", "args"),
], ids=["plan --witness", "simulate --out", "prove --workers", "check --batch",
        "selftest --code"])
def test_an_old_spelling_makes_the_same_call_as_the_new(tmp_path, monkeypatch, new, old,
                                                        where, key):
    import cfmpa.proofs
    import cfmpa.runs

    module = cfmpa.proofs if where == "run_prove" else cfmpa.runs
    seen = _calls(monkeypatch, module, where)
    d = str(tmp_path)
    assert main([a.format(d=d) for a in new]) == 0
    assert main([a.format(d=d) for a in old]) == 0
    for call in seen:            # a message names the folder as the user spelled it
        call.pop("folder_option", None)
    assert len(seen) == 2 and seen[0] == seen[1] and seen[0][key], seen
    if key == "args" and where == "run_simulate":
        assert str(seen[0]["args"][2]) == f"{d}/log.csv"


def test_the_help_shows_the_new_names_and_hides_the_old_spellings(capsys):
    with pytest.raises(SystemExit):
        main(["--help"])
    top = capsys.readouterr().out
    assert "check-batch" in top and "mutants" in top
    for argv, shown, hidden in [
        (["plan"], "--witness-out FILE", "--witness "),
        (["simulate"], "--log-out LOG", "--out "),
        (["prove"], "--jobs K", "--workers"),
        (["check"], "--witness FILE", "--batch"),
        (["selftest"], "cfmpa selftest", "--code"),
        (["check-batch"], "--workers K", "--batch"),
        (["mutants"], "--prove-only ID", "--code"),
    ]:
        with pytest.raises(SystemExit):
            main([*argv, "--help"])
        text = capsys.readouterr().out
        assert shown in text and hidden not in text, (argv, text)


def _shared_names(parser):
    """The options that name a file or folder written (``_arguments.output`` or ``checked``,
    not a number's Budget) in one command and an input in another."""
    import argparse

    from cfmpa._arguments import Budget, visible_options

    outputs, inputs = set(), set()
    for action in parser._actions:
        if isinstance(action, argparse._SubParsersAction):
            for sub in action.choices.values():
                written = {option for _, option, check in sub.get_default("_checks") or ()
                           if not isinstance(check, Budget)}
                for a in sub._actions:
                    for o in visible_options(a):
                        (outputs if o in written else inputs).add(o)
    return outputs, outputs & inputs


def test_an_input_and_an_output_never_share_a_name():
    from cfmpa import _arguments as opt
    from cfmpa.cli import _parser

    outputs, shared = _shared_names(_parser())
    assert shared == set()
    assert {"--witness-out", "--log-out", "--json", "--out", "--audit"} <= outputs
    # Seeded fault: plan writing a file named by --dr, which check reads, is caught.
    planted = _parser()
    plan = next(a for a in planted._actions if hasattr(a, "choices") and a.choices
                and "plan" in a.choices).choices["plan"]
    plan.add_argument("--dr")
    opt.output(plan, "dr", "--dr", opt.FILE)
    assert _shared_names(planted)[1] == {"--dr"}
