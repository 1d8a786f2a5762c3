"""The BuiltDR, searchoptpath and per-scenario obligations ask the variant rules
(spec.Variant.rule), never the variants' names (docs/model.md §4): a seeded fault in one rule
field changes what they state, so a proof turns red, a check fails or the pinned statement no
longer matches."""

from __future__ import annotations

import dataclasses
from pathlib import Path

import pytest
import z3

import factory
from cfmpa.impl import check_containment
from cfmpa.proofs._obl_builtdr import _box_nesting, builtdr_model, builtdr_obligations
from cfmpa.proofs._obl_paths import rest_region, theorem_obligations
from cfmpa.proofs._obl_scenario import scenario_obligations
from cfmpa.proofs._obligation import standard_smtlib
from cfmpa.proofs._pins import load_lock
from cfmpa.proofs._runner import compare_ids
from cfmpa.spec import Variant, _grid

LOCK = load_lock()
SCENARIOS = Path(__file__).resolve().parents[2] / "scenarios"


def _plant(monkeypatch, variant: str, **fields) -> None:
    """Replace fields of one row of spec's rule table (the seeded fault)."""
    rules = dict(_grid._RULES)
    rules[variant] = dataclasses.replace(rules[variant], **fields)
    monkeypatch.setattr(_grid, "_RULES", rules)


def _obligation(ident: str):
    (ob,) = [o for o in builtdr_obligations() + theorem_obligations() if o.id == ident]
    return ob


def _pins(ident: str) -> dict[str, str]:
    """The VC hashes of the obligation as the code states it now, as the lock pins them."""
    return {vc.name: standard_smtlib(vc)[1] for vc in _obligation(ident).build().vcs}


IDS = ("Thm1.builtdr", "Thm3.builtdr_tight", "Thm4.searchoptpath_tight", "Thm3.box_nesting")


@pytest.mark.parametrize("ident", IDS)
def test_the_statements_read_from_the_rules_are_the_pinned_ones(ident):
    assert _pins(ident) == LOCK[ident]["vcs"]


def test_a_flipped_rest_rule_changes_the_extracted_program_and_its_pins(monkeypatch):
    # The tight rule's rest layer moved to layer N - 1 (the paper's): the loop form's
    # conditional, decided at extraction from the rule, now reads SL[N - 1], and so does the
    # postcondition; the statements of the tight BuiltDR and searchoptpath no longer match the
    # lock ("statement changed, not re-pinned": the run fails).
    before = builtdr_model("tight")
    assert "regionRest_tight" in repr(before.program) and "regionRest_tight" in before.post.sexpr()
    _plant(monkeypatch, "tight", rest_at_goal=False)
    model = builtdr_model("tight")
    assert "regionRest_tight" not in repr(model.program)
    assert "regionRest_tight" not in model.post.sexpr()
    assert "regionL_tight" in rest_region("tight").sexpr()
    for ident in ("Thm3.builtdr_tight", "Thm4.searchoptpath_tight"):
        assert _pins(ident) != LOCK[ident]["vcs"], ident


def test_a_paper_variant_given_a_rest_at_the_goal_changes_theorem_1(monkeypatch):
    _plant(monkeypatch, "original", rest_at_goal=True)
    assert "regionRest_original" in builtdr_model("original").post.sexpr()
    assert _pins("Thm1.builtdr") != LOCK["Thm1.builtdr"]["vcs"]


def _answer(vc) -> z3.CheckSatResult:
    s = z3.Solver()
    s.set("timeout", 20_000)
    s.add([h for _, h in vc.hypotheses])
    s.add(z3.Not(vc.goal))
    return s.check()


def test_the_box_nesting_follows_the_rules_within(monkeypatch):
    # As the rules stand, each box lies within its rule's 'within'.
    q = _box_nesting()
    assert [vc.name for vc in q.vcs] == ["modified_in_original", "tight_in_modified"]
    assert [_answer(vc) for vc in q.vcs] == [z3.unsat, z3.unsat]
    # Seeded fault: the rules claim the modified box lies within the tight one. The proof
    # turns red (a counterexample), and so does the per-scenario containment check.
    _plant(monkeypatch, "modified", within="tight")
    _plant(monkeypatch, "tight", within=None)
    assert Variant.nesting() == ((Variant.MODIFIED, Variant.TIGHT),)
    (vc,) = _box_nesting().vcs
    assert vc.name == "modified_in_tight" and _answer(vc) == z3.sat
    rep = check_containment(factory.scenario())
    assert not rep.ok and "modified not within tight" in rep.detail


def test_a_cycle_of_within_is_refused(monkeypatch):
    _plant(monkeypatch, "original", within="tight")
    with pytest.raises(ValueError, match="cycle"):
        Variant.nesting()


def test_the_theorem_numbers_name_the_obligations(monkeypatch):
    # The tight rule said to be proved under Theorems 1 and 2: its obligations get other ids,
    # so the lock's ids go missing and new ones appear (the run fails).
    _plant(monkeypatch, "tight", theorems=(1, 2))
    ids = [o.id for o in builtdr_obligations() + theorem_obligations()]
    assert {"Thm1.builtdr_tight", "Thm2.searchoptpath_tight"} <= set(ids)
    missing, unexpected, _ = compare_ids(ids, [i for i in LOCK if i.startswith("Thm")])
    assert "Thm3.builtdr_tight" in missing and "Thm1.builtdr_tight" in unexpected
    # And the per-scenario translation statements cite the rule's theorems.
    (tr,) = [o for o in scenario_obligations([SCENARIOS / "default.toml"])
             if o.id.endswith("translation_tight")]
    assert "Theorem 1's postcondition" in tr.statement


def test_a_variant_outside_the_paper_carries_its_name_in_its_ids(monkeypatch):
    _plant(monkeypatch, "modified", in_paper=False)
    ids = {o.id for o in builtdr_obligations() + theorem_obligations()}
    assert {"Thm3.builtdr_modified", "Thm4.searchoptpath_modified"} <= ids
    assert "Thm3.builtdr" not in ids
