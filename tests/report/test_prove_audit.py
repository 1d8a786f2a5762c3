"""`cfmpa prove --audit`: the report's process runs its kernels on one thread beside the prove
run, and on the machine's (kernel_threads) once the prove run has ended (docs/model.md §6.1)."""

from __future__ import annotations

import os
import time
from pathlib import Path


def _threads_seen(tmp_path: Path, monkeypatch, stops: bool) -> str:
    import cfmpa.proofs
    import cfmpa.report
    from cfmpa.cli import main
    from cfmpa.errors import InputError
    from cfmpa.impl import kernel_threads

    tmp_path.mkdir(parents=True)
    seen = tmp_path / "threads.txt"

    def report(files, out_dir, *, proofs_json, **kw):
        before = kernel_threads()
        seen.write_text(f"{before}")
        proofs_json()
        t0 = time.monotonic()
        while kernel_threads() == before and time.monotonic() - t0 < 2.0:
            time.sleep(0.01)
        seen.write_text(f"{before} {kernel_threads()}")
        return 0

    def run_prove(**kw):
        time.sleep(0.2)                 # the report process is running by now
        if stops:
            raise InputError("--scenarios", "x", "stands for any stop")
        return 0
    monkeypatch.setattr(cfmpa.report, "run_audit", report)
    monkeypatch.setattr(cfmpa.proofs, "run_prove", run_prove)
    main(["prove", "--out", str(tmp_path / "p"), "--audit", str(tmp_path / "a")])
    return seen.read_text() if seen.exists() else ""


def test_the_report_widens_its_kernels_once_the_prove_run_has_ended(tmp_path, monkeypatch):
    from cfmpa.impl import kernel_threads

    wide = kernel_threads()
    assert _threads_seen(tmp_path / "ok", monkeypatch, stops=False) == f"1 {wide}"
    assert wide == min(2, os.cpu_count() or 1)
    # A prove run that stops: the report process is ended, never widened.
    assert _threads_seen(tmp_path / "stop", monkeypatch, stops=True) in ("", "1")
