"""Every obligation has a plain summary for the report's cards (proofs/_summaries.py): at most
240 characters, no module, code or ledger names; a missing or overlong one is caught."""

from __future__ import annotations

import pytest

from cfmpa.proofs import collect_obligations, expected_ids, obligation_summary, summary_problems
from cfmpa.proofs._summaries import MAX_CHARS, SUMMARIES


def _registered() -> list[str]:
    """Every obligation the prove machinery registers (the bundled workcells' checks included),
    and every id a full run must produce."""
    return sorted({o.id for o in collect_obligations()} | set(expected_ids()))


def test_every_registered_obligation_has_a_plain_summary():
    ids = _registered()
    assert len(ids) > 50
    assert summary_problems(ids) == []
    for i in ids:
        assert 20 < len(obligation_summary(i)) <= MAX_CHARS, i


def test_a_per_workcell_summary_names_its_workcell():
    text = obligation_summary("Scenario.narrow-gap.containment")
    assert text.startswith("narrow-gap: ") and "{" not in text
    assert obligation_summary("Scenario.a.b.containment") is None   # the pattern's * is one part
    assert obligation_summary("Nothing.like.this") is None


def test_a_planted_missing_summary_fails_the_check():
    ids = _registered()
    planted = {k: v for k, v in SUMMARIES.items() if k != "Safety.region_soundness"}
    assert summary_problems(ids, planted) == ["Safety.region_soundness: no summary"]
    no_pattern = {k: v for k, v in SUMMARIES.items() if k != "Scenario.*.containment"}
    assert "Scenario.default.containment: no summary" in summary_problems(ids, no_pattern)


@pytest.mark.parametrize("bad, what", [
    ("The regions impl.lattice_range builds are sound.", "a module path"),
    ("Safety.region_soundness holds for the box.", "a dotted code name"),
    ("As Prop8.printed shows, the chain fails.", "an obligation id"),
    ("The lattice_range indices cover the box.", "a code identifier"),
    ("Rests on A6, the search's contract.", "a ledger id"),
    ("The slack SNAP g R is added.", "a code constant"),
    ("x" * (MAX_CHARS + 1), "characters, more than"),
])
def test_a_planted_bad_summary_fails_the_check(bad, what):
    planted = dict(SUMMARIES, **{"Tolerance.tube": bad})
    problems = summary_problems(["Tolerance.tube"], planted)
    assert problems and all(p.startswith("Tolerance.tube: ") for p in problems)
    assert any(what in p for p in problems), problems
