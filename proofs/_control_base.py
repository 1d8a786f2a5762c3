"""What the controls of ``cfmpa prove`` are made of (docs/model.md §10.3): the ``Control``
record, ``ControlNotMade`` (a control that cannot build its input), how a checker's answer is
read (``_rejected``), and the case the checkers' controls share (the built-in workcell
``small``, its D_R and optimal answer).

Kept apart from the controls themselves (``proofs/_controls.py``, which runs them, and the
wiring's ``proofs/_controls_wiring.py``) so that both read it and the wiring's module imports
nothing back: no import cycle (tests/proofs/test_proofs_layers.py).
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np

from ..scenarios import SELFCHECK_WORKCELLS
from ..spec import SearchResult, SearchStatus, make_grid, parse_scenario

__all__ = ["Control", "ControlNotMade"]


@dataclass(frozen=True)
class Control:
    """A seeded wrong input and the checker that must reject it (or a composition that must not
    be proved). ``run`` returns (outcome, detail); ``expected`` lists the outcomes that pass."""

    id: str
    checker: str
    what: str
    expected: tuple[str, ...]
    run: Callable[[], tuple[str, str]]


class ControlNotMade(AssertionError):
    """A control's wrong input is not what the control says (a bug in the control)."""


def _require(ok: bool, what: str) -> None:
    if not ok:
        raise ControlNotMade(what)


@dataclass(frozen=True)
class _Case:
    """The workcell, its D_R (reference BuiltDR, modified variant) and the optimal answer."""

    scenario: Any
    grid: Any
    dr: np.ndarray
    start: tuple[int, int]
    goal: tuple[int, int]
    best: SearchResult


_CASE: list[_Case] = []


def _case() -> _Case:
    if not _CASE:
        from ..impl import build_dr, search_opt_path

        s = parse_scenario(SELFCHECK_WORKCELLS["small"], check_budget=False)
        g = make_grid(s)
        dr = build_dr(s, "modified", g)
        start, goal = s.right.start_cell, s.right.goal_cell
        best = search_opt_path(dr, start, goal, with_witness=True)
        _require(best.status is SearchStatus.FOUND, "the small workcell has no path")
        _CASE.append(_Case(s, g, dr, start, goal, best))
    return _CASE[0]


def _rejected(failures: list[Any], want: Sequence[str] = ()) -> tuple[str, str]:
    """``rejected`` when the checker's first failure is at a condition of ``want`` (any, for a
    positive control's empty ``want``), ``accepted`` when it raised nothing, and ``error`` when
    it failed elsewhere: the input is then not the fault the control plants."""
    if failures:
        f = failures[0]
        what = getattr(f, "condition", None) or getattr(f, "clause", None) or type(f).__name__
        text = f"{what}: {getattr(f, 'message', f)}"
        if want and what not in want:
            return "error", (f"rejected at {what}, not at {' or '.join(want)} where the control "
                             f"plants its fault (its input is not what it says); {text}")
        return "rejected", text
    return "accepted", "the checker raised nothing"
