"""The audit lists the negative controls before it forks its fresh prove run
(``_Context.start_proofs``): the run inherits the controls' compositions and builds none."""

from __future__ import annotations

from pathlib import Path
from typing import Any

import pytest

import cfmpa.proofs._controls as controls
import cfmpa.proofs._obl_safety as safety
import cfmpa.report._audit as audit
from cfmpa.report._obligations import ProofData

BUILT: list[str] = []


def _context() -> Any:
    return audit._Context(sdir=Path("."), paths=[], loaded=[], given=False, argv=None,
                          compare_n=0, compare_seed=0, recorded=None, campaign=None,
                          proofs_json=None, expected_ids=None, stages=audit._Progress(None),
                          plans=audit._Plans("full"))


def _clear() -> None:
    controls._composition.cache_clear()
    getattr(audit._control_checkers, "cache_clear", lambda: None)()   # a test's stand-in: none


def _child_builds(monkeypatch: pytest.MonkeyPatch) -> tuple[int, int]:
    """(compositions built here, compositions the forked run built listing the controls)."""
    real = safety.composition_vc

    def counted(variant: str, **kw: Any) -> Any:
        BUILT.append(variant)
        return real(variant, **kw)

    monkeypatch.setattr(safety, "composition_vc", counted)
    _clear()
    BUILT.clear()

    def fresh_run(told: Any) -> ProofData:          # runs in the forked process
        before = len(BUILT)
        controls.collect_controls()
        return ProofData(available=False, source="test", note=str(len(BUILT) - before),
                         rows=(), ledger=(), ledger_available=False)

    ctx = _context()
    ctx._load = lambda source, progress: fresh_run(progress)
    try:
        ctx.start_proofs()
        here = len(BUILT)
        data = ctx.background.result()
    finally:
        if ctx.background is not None:
            ctx.background.close()
        _clear()
    assert data is not None
    return here, int(data.note)


def test_the_fresh_run_inherits_the_controls(monkeypatch: pytest.MonkeyPatch) -> None:
    here, child = _child_builds(monkeypatch)
    assert here == len(safety.VARIANTS) and child == 0


def test_a_fork_before_the_list_is_caught(monkeypatch: pytest.MonkeyPatch) -> None:
    # Seeded fault: no list before the fork; the fresh run builds every composition itself.
    monkeypatch.setattr(audit, "_control_checkers", lambda: ())
    here, child = _child_builds(monkeypatch)
    assert here == 0 and child == len(safety.VARIANTS)
