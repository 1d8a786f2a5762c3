"""The command line's own process freezes its objects for the collector as it ends, and a call
of ``main`` with arguments does not (docs/model.md §7.5): the interpreter's exit then skips the
sweep of numba's and numpy's modules, and a caller in process keeps its collector. The output
is the same either way. Seeded fault: a ``main`` that froze on every call is caught."""

from __future__ import annotations

import contextlib
import gc
import io
import subprocess
import sys
from pathlib import Path

import factory
from cfmpa import cli

ROOT = Path(__file__).resolve().parents[1]


def _freezes(monkeypatch, argv, sys_argv=("cfmpa", "scenarios")) -> tuple[int, list[int]]:
    """(exit code, the gc.freeze calls) of cli.main(argv), sys.argv set to ``sys_argv``."""
    calls: list[int] = []
    monkeypatch.setattr(gc, "freeze", lambda: calls.append(1))
    monkeypatch.setattr(sys, "argv", list(sys_argv))
    with contextlib.redirect_stdout(io.StringIO()):
        code = cli.main(argv)
    return code, calls


def test_main_with_arguments_freezes_nothing(monkeypatch):
    assert _freezes(monkeypatch, ["scenarios"]) == (0, [])


def test_the_command_lines_own_process_freezes_once(monkeypatch):
    assert _freezes(monkeypatch, None) == (0, [1])


def test_seeded_fault_a_main_freezing_on_every_call_is_caught(monkeypatch):
    real = cli.main

    def always(argv=None):
        code = real(argv)
        gc.freeze()
        return code
    monkeypatch.setattr(cli, "main", always)
    assert _freezes(monkeypatch, ["scenarios"]) != (0, [])


def test_the_process_prints_and_writes_what_main_in_process_does(tmp_path, monkeypatch):
    toml = tmp_path / "tiny.toml"
    toml.write_text(factory.toml(factory.doc()))
    argv = ["dr", str(toml), "--variant", "tight", "--kernel", "reference"]
    out = io.StringIO()
    with contextlib.redirect_stdout(out):
        assert cli.main([*argv, "--out", str(tmp_path / "in")]) == 0
    proc = subprocess.run([sys.executable, "-m", "cfmpa", *argv, "--out", str(tmp_path / "cli")],
                          cwd=ROOT, capture_output=True, text=True, timeout=120)
    assert proc.returncode == 0 and proc.stderr == ""

    def lines(text: str) -> list[str]:     # the time and the path differ
        return [x for x in text.splitlines() if not x.startswith(("time", "wrote"))]
    assert lines(proc.stdout) == lines(out.getvalue())
    assert (tmp_path / "cli" / "dr.npy").read_bytes() == (tmp_path / "in" / "dr.npy").read_bytes()
