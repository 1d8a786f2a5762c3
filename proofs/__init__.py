"""Proof obligations of the paper discharged by Z3, sympy and checks on data (`make prove`).

``run_prove`` is the command; ``collect_obligations`` and ``run_obligations`` give the report
the same results as values (``Proof``, ``ProveRun``), ``ASSUMPTIONS`` is the ledger, and
``obligation_summary`` gives each obligation's one plain sentence (the report's cards).
"""

from __future__ import annotations

import sys
from collections.abc import Iterable
from pathlib import Path
from typing import TextIO

from ..errors import InputError
from ._controls import Control, ControlResult, collect_controls
from ._ledger import ASSUMPTIONS, Assumption
from ._obl_scenario import CHECKS as SCENARIO_CHECKS
from ._obl_scenario import scenario_check_id, scenario_files, scenario_obligations
from ._obligation import (
    VC,
    CheckOutcome,
    CheckQuery,
    Method,
    Obligation,
    Proof,
    VCResult,
    Verdict,
    Z3Query,
    discharge,
)
from ._runner import (
    BUNDLED_DIR,
    BUNDLED_SCENARIOS,
    DEFINITIONAL,
    EXPECTED_VERDICTS,
    FIXED_IDS,
    ProveRun,
    collect_obligations,
    compare_ids,
    cvc5_tally,
    default_workers,
    expected_ids,
    is_bundled,
    kind_of,
    pinned_verdict,
    render_report,
    run_obligations,
    run_record,
    scenarios_note,
    selected,
)
from ._summaries import obligation_summary, summary_problems

__all__ = [
    "ASSUMPTIONS", "Assumption", "BUNDLED_DIR", "BUNDLED_SCENARIOS", "CheckOutcome",
    "Control", "ControlResult", "collect_controls",
    "SCENARIO_CHECKS", "scenario_check_id", "scenario_files", "scenario_obligations",
    "CheckQuery", "DEFINITIONAL", "EXPECTED_VERDICTS", "FIXED_IDS", "Method", "Obligation",
    "Proof", "ProveRun",
    "VC", "VCResult", "Verdict", "Z3Query", "collect_obligations", "compare_ids", "cvc5_tally",
    "default_workers",
    "discharge", "expected_ids", "is_bundled", "kind_of", "obligation_summary", "pinned_verdict",
    "render_report", "summary_problems",
    "run_obligations", "run_prove", "run_record", "scenarios_note", "selected",
]


def run_prove(*, out_dir: str | Path = "build/proofs", scenarios_dir: str | Path | None = None,
              only: Iterable[str] | None = None, stream: TextIO | None = None,
              repin: bool = False, workers: int | None = None,
              recheck_undecided: bool = False) -> int:
    """Discharge the obligations (all, or those ``only`` selects), print the summary (a line per
    group on stderr as it ends, before), write ``out_dir/results.json``; 0 iff every verdict
    is the pinned one and no id is missing, extra or repeated, 1 otherwise. Raises InputError
    (exit 2) for a ``--scenarios`` that is not a folder, a folder other than the bundled one
    with no scenario file, or an ``--only`` pattern that selects no expected obligation, or
    ``workers`` below 1 (``--workers``). ``recheck_undecided``: replay in cvc5 the statements it
    did not decide when pinned too (else their answer is the lock's, said so)."""
    picks = None if only is None else list(only)
    if workers is not None and workers < 1:
        raise InputError("--workers", str(workers), "must be at least 1 (1: one process)")
    sdir = BUNDLED_DIR if scenarios_dir is None else Path(scenarios_dir)
    if not sdir.is_dir():
        raise InputError("--scenarios", str(scenarios_dir), "must be a folder of *.toml files")
    if not is_bundled(sdir) and not scenario_files(sdir):
        raise InputError("--scenarios", str(scenarios_dir),
                         f"holds no *.toml scenario file (the bundled folder is {BUNDLED_DIR})")
    every = expected_ids(sdir)
    controls = collect_controls(picks)
    for pat in picks or ():
        if not any(selected(i, [pat]) for i in every) and not any(
                selected(c.id, [pat]) for c in controls):
            raise InputError("--only", pat, "selects no obligation (give an id such as "
                             "Prop8.printed, a prefix such as Prop8, or a glob such as 'Thm*')")
    obligations = collect_obligations(sdir, picks)
    expected = [i for i in every if selected(i, picks)]
    run = run_obligations(obligations, out_dir, expected, note=scenarios_note(sdir),
                          record=run_record(sdir), repin=repin,
                          workers=default_workers() if workers is None else workers,
                          controls=controls, progress=sys.stderr,
                          recheck_undecided=recheck_undecided)
    (stream or sys.stdout).write(render_report(run))
    return 0 if run.ok else 1

