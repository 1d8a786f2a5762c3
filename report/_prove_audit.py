"""`cfmpa prove --audit DIR`: the obligations discharged and the audit report written side by side.

The report's plans, pictures and campaign need no proof, so a second process (forked, so that it
starts at once with everything imported) computes them while this one discharges the
obligations; it reads results.json only once the gate opens. If the prove run stops with an
error, the gate opens with ``stopped`` set and the report process ends writing nothing.
"""

from __future__ import annotations

import multiprocessing
import os
import sys
import threading
from collections.abc import Sequence
from pathlib import Path
from typing import TextIO

from ..errors import InputError, handled
from ..impl import kernel_threads, progress_silenced, set_kernel_threads

__all__ = ["run_prove_audit"]


def run_prove_audit(audit: str | Path, *, out_dir: str | Path = "build/proofs",
                    scenarios_dir: str | Path | None = None, only: Sequence[str] | None = None,
                    repin: bool = False, workers: int | None = None,
                    recheck_undecided: bool = False, argv: Sequence[str] | None = None,
                    stdout: TextIO | None = None, progress: bool = True) -> int:
    """Discharge every obligation into ``out_dir`` (``proofs.run_prove``) and write the audit
    report of that run to ``audit`` (``report.run_audit``); the exit code is the prove run's,
    else the report's. InputError (exit 2, nothing run) for ``only``: a report a reviewer trusts
    is of a whole run, a selection would show the rest missing. ``stdout`` gets the prove run's
    summary; the report process prints on sys.stdout and sys.stderr as it inherits them through
    the fork (a stream of this process's memory would not reach the terminal from there).
    ``progress``: the report process writes a line per stage with its time on its sys.stderr,
    as `cfmpa audit` does (the proofs' stage last: it waits for this run's results.json)."""
    # Through the packages, not their modules: the names a caller (or a test's stand-in) sees;
    # the report's read now, so the forked process starts with its modules imported.
    from .. import proofs, report
    run_audit = report.run_audit

    so = sys.stdout if stdout is None else stdout
    if only:
        raise InputError("--audit", str(audit), "needs every obligation; run it without --only")
    results = str(Path(out_dir) / "results.json")
    mp = multiprocessing.get_context("fork")
    gate, stopped = mp.Event(), mp.Event()

    def proofs_ready() -> str:
        gate.wait()
        if stopped.is_set():
            raise InputError("--audit", str(audit), "not written: the prove run stopped")
        return results

    def write_audit() -> int:
        return int(run_audit(None, str(audit), argv=list(argv or ["cfmpa"]),
                             proofs_json=proofs_ready, progress=sys.stderr if progress else None,
                             scenarios_dir=None if scenarios_dir is None else str(scenarios_dir)))

    def child() -> None:
        wide = kernel_threads()
        set_kernel_threads(1)          # beside the prove run's processes

        def widen() -> None:           # once the prove run has ended, its cores are the report's
            gate.wait()                # (the kernels' results do not depend on their threads)
            if not stopped.is_set():
                set_kernel_threads(wide)
        threading.Thread(target=widen, name="cfmpa-audit-widen", daemon=True).start()
        try:
            code = write_audit()
        except BaseException as exc:   # said after the proofs, or not at all if they stopped
            gate.wait()
            if stopped.is_set():
                os._exit(1)

            def again(exc: BaseException = exc) -> int:
                raise exc
            code = handled(again, sys.stderr)
        sys.stdout.flush()
        sys.stderr.flush()
        os._exit(code)

    with progress_silenced():          # two processes' bars would cut up the summary
        worker = mp.Process(target=child, name="cfmpa-audit", daemon=True)
        worker.start()
        try:
            code = proofs.run_prove(out_dir=out_dir, scenarios_dir=scenarios_dir, only=only,
                                    repin=repin, workers=workers, stream=so,
                                    recheck_undecided=recheck_undecided)
        except BaseException:
            stopped.set()
            gate.set()
            worker.join(timeout=5)
            raise
        print(file=so, flush=True)
        gate.set()
        worker.join()
    return code or worker.exitcode or 0
