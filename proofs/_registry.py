"""The registry of the fixed obligations (docs/model.md §6.1): ``COLLECTORS``, one collector per
catalogue module, and the views of their declarations (``EXPECTED_VERDICTS``, ``DEFINITIONAL``,
``FIXED_IDS``, ``kind_of``).

The one engine module besides the runner that reads the catalogue: the runner
(``proofs/_runner.py``) collects and discharges what it lists, and the controls of the kinds
(``proofs/_controls_wiring.py``) read its views, so neither imports the other.
"""

from __future__ import annotations

from collections.abc import Callable, Iterable, Sequence
from dataclasses import dataclass
from typing import Any

from ._obl_builtdr import builtdr_obligations
from ._obl_constants import constants_obligations
from ._obl_geometry import geometry_obligations
from ._obl_margin import margin_obligations
from ._obl_monitor import monitor_obligations
from ._obl_paths import path_obligations, prop8_obligations, theorem_obligations
from ._obl_safety import safety_obligations
from ._obl_tolerance import tolerance_obligations
from ._obl_tools import tools_obligations
from ._obl_wiring import wiring_obligations
from ._obl_witness import witness_obligations
from ._obligation import Obligation, Verdict
from ._pins import LOCK, load_lock

__all__ = ["COLLECTORS", "DEFINITIONAL", "EXPECTED_VERDICTS", "FIXED_IDS", "Declared", "declared",
           "fixed_ids", "kind_and_why", "kind_of"]

#: The collector of each module of fixed obligations, in the order a run discharges them: the
#: registry the views below and ``collect_obligations`` read (the per-scenario checks,
#: ``scenario_obligations``, come after them). A new module of obligations is one entry here;
#: a new obligation is one ``Obligation(...)`` in its module's collector.
COLLECTORS: tuple[Callable[[], Sequence[Obligation]], ...] = (
    geometry_obligations, margin_obligations, builtdr_obligations, path_obligations,
    theorem_obligations, witness_obligations, prop8_obligations, tolerance_obligations,
    monitor_obligations, constants_obligations, safety_obligations, tools_obligations,
    wiring_obligations)


@dataclass(frozen=True)
class Declared:
    """What the declarations (``Obligation(...)`` in each collector) say, by id: the expected
    verdicts, why each definitional one is (docs/model.md §10), and the plain summaries."""

    expected: dict[str, Verdict]
    definitional: dict[str, str]
    summaries: dict[str, str]


def declared(collectors: Iterable[Callable[[], Sequence[Obligation]]] = COLLECTORS) -> Declared:
    """The views of the fixed obligations' declarations (cheap: no query is built). An id
    declared twice is an error here (the run would count it as a duplicate)."""
    expected: dict[str, Verdict] = {}
    definitional: dict[str, str] = {}
    summaries: dict[str, str] = {}
    for collect in collectors:
        for o in collect():
            if o.id in expected:
                raise ValueError(f"obligation id {o.id!r} declared twice")
            expected[o.id] = o.expected
            if o.definitional:
                definitional[o.id] = o.definitional
            if o.summary:
                summaries[o.id] = o.summary
    return Declared(expected, definitional, summaries)


_DECLARED = declared()

#: Every fixed obligation id and the verdict it must get, as declared (``Obligation.expected``).
#: proofs/obligations.lock pins it independently (a drifted expectation is a changed statement),
#: and every id it pins is expected of a full run (FIXED_IDS), so an obligation that
#: disappears from the code is a missing id.
EXPECTED_VERDICTS: dict[str, Verdict] = dict(_DECLARED.expected)

#: Obligations whose proof is definitional: true by a definition's own clauses, a termination
#: measure or a named choice instance rather than a theorem about the robot (docs/model.md
#: §10), with why, as declared (``Obligation.definitional``); results.json, the summary and
#: the report count them apart from the theorems, and the lock pins each kind.
DEFINITIONAL: dict[str, str] = dict(_DECLARED.definitional)


def kind_of(ident: str) -> str:
    """``definitional`` for the ids of DEFINITIONAL, else ``theorem``."""
    return "definitional" if ident in DEFINITIONAL else "theorem"


def kind_and_why(ident: str) -> tuple[str, str]:
    """(kind, why) of an id, as proofs/obligations.lock pins it (``_pins.check_kinds``)."""
    return kind_of(ident), DEFINITIONAL.get(ident, "")


def fixed_ids(declared_ids: Iterable[str], lock: dict[str, Any]) -> tuple[str, ...]:
    """The fixed ids a run must produce: ``declared_ids``, then (sorted) every id ``lock`` pins
    that none of them is, the per-scenario keys left out: an obligation that disappeared from
    the code stays expected, so a run misses it."""
    ids = tuple(declared_ids)
    return ids + tuple(sorted(k for k in lock if not k.startswith("Scenario.") and k not in ids))


#: The obligations every run must produce, besides the per-scenario ones: the declared ids,
#: then any id proofs/obligations.lock pins that no declaration has (a missing id).
FIXED_IDS: tuple[str, ...] = fixed_ids(EXPECTED_VERDICTS, load_lock(LOCK))
