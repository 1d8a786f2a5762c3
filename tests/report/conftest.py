"""Shared by the report's tests: a report.json doc completed with everything its verdict rows
rest on (``complete_proofs``), so that a row can be "safe" without a whole prove run."""

from __future__ import annotations

import copy
from collections.abc import Callable, Iterable
from pathlib import Path
from typing import Any

import pytest

from cfmpa.report._audit import _control_checkers, row_requirements
from cfmpa.report._obligations import badge_of

VARIANTS = ("original", "modified", "tight")


def completed(doc: dict[str, Any], stems: Iterable[str]) -> dict[str, Any]:
    """A copy of ``doc`` whose obligations and negative controls hold, as expected, every id
    that a row of the workcells ``stems`` (file stems) rests on (``row_requirements``): the ids
    ``doc`` lacks are added as a prove run would record them (a Scenario.* check on data, the
    rest by Z3; each control rejected, as it expects), and the prove run's record holds the
    hashes of those workcells' files."""
    stems = list(stems)
    doc = copy.deepcopy(doc)
    ob = doc.setdefault("obligations", {})
    ob["available"] = True
    ob.setdefault("source", "a test's stand-in for a whole prove run")
    items = {i["id"]: i for i in ob.get("items", [])}
    ctl = doc.get("controls") or {}
    controls = {c["id"]: c for c in ctl.get("items", [])}
    checker = dict(_control_checkers())
    for stem in stems:
        for v in VARIANTS:
            obligations, cids = row_requirements(stem, v)
            for i in obligations:
                method = "data" if i.startswith("Scenario.") else "z3"
                items.setdefault(i, {"id": i, "method": method, "verdict": "proved",
                                     "expected": "proved", "as_expected": True,
                                     "badge": badge_of(method, "proved"), "change": "new"})
            for c in cids:
                controls.setdefault(c, {"id": c, "checker": checker[c], "what": "a stand-in",
                                        "expected": ["rejected"], "outcome": "rejected",
                                        "detail": "", "seconds": 0.0, "ok": True})
    ob["items"] = list(items.values())
    run = ob.get("run")
    if run is not None:       # the prove run read these workcells' files: their hashes
        for f in doc.get("provenance", {}).get("scenarios", []):
            if Path(f["path"]).stem in stems:
                run.setdefault("scenarios", {})[Path(f["path"]).name] = f["sha256"]
    doc["controls"] = {**ctl, "available": True, "items": list(controls.values()),
                       "missing_ids": ctl.get("missing_ids", [])}
    return doc


@pytest.fixture
def complete_proofs() -> Callable[[dict[str, Any], Iterable[str]], dict[str, Any]]:
    """``completed``, as a fixture."""
    return completed
