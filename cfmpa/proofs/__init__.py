"""Proof obligations of the paper discharged by Z3, sympy and checks on data (`make prove`).

``run_prove`` is the command; ``collect_obligations`` and ``run_obligations`` give the report
the same results as values (``Proof``, ``ProveRun``), and ``ASSUMPTIONS`` is the ledger.
"""

from __future__ import annotations

import sys
from collections.abc import Iterable
from pathlib import Path
from typing import TextIO

from ._ledger import ASSUMPTIONS, Assumption
from ._obligation import (VC, CheckOutcome, CheckQuery, Method, Obligation, Proof, VCResult,
                          Verdict, Z3Query, discharge)
from ._runner import (FIXED_IDS, ProveRun, collect_obligations, expected_ids, render_report,
                      run_obligations, selected)

__all__ = [
    "ASSUMPTIONS", "Assumption", "CheckOutcome", "CheckQuery", "FIXED_IDS", "Method",
    "Obligation", "Proof", "ProveRun", "VC", "VCResult", "Verdict", "Z3Query",
    "collect_obligations", "discharge", "expected_ids", "render_report", "run_obligations",
    "run_prove", "selected",
]


def run_prove(*, out_dir: str | Path = "build/proofs", scenarios_dir: str | Path = "scenarios",
              only: Iterable[str] | None = None, stream: TextIO | None = None) -> int:
    """Discharge the obligations (all, or those ``only`` selects), print the summary, write
    ``out_dir/results.json``; 0 iff every verdict is as expected and no id is missing or extra."""
    picks = None if only is None else list(only)
    obligations = collect_obligations(scenarios_dir, picks)
    expected = [i for i in expected_ids(scenarios_dir) if selected(i, picks)]
    run = run_obligations(obligations, out_dir, expected)
    (stream or sys.stdout).write(render_report(run))
    return 0 if run.ok else 1


# Contract-checked runs, `cfmpa check` and `cfmpa selftest` (imported last: they use impl/).
from ._check import run_check  # noqa: E402
from ._selftest import run_selftest  # noqa: E402

__all__ += ["run_check", "run_selftest"]
