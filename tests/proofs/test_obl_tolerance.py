"""Tolerance.tube (docs/model.md §12): proved, registered, and false without its key premise
c > 2 L delta, or with it weakened to c > L delta."""

from __future__ import annotations

import z3

from cfmpa.proofs import Verdict, collect_obligations, discharge
from cfmpa.proofs._obl_tolerance import KEY_PREMISE, tolerance_obligations, tube_vc
from cfmpa.proofs._obligation import VC
from cfmpa.proofs._runner import EXPECTED_VERDICTS
from z3answer import answer


def _answer(vc: VC) -> z3.CheckSatResult:
    return answer([h for _, h in vc.hypotheses] + [z3.Not(vc.goal)])


def test_registered_once_and_pinned():
    ids = [o.id for o in collect_obligations(scenarios_dir="/nonexistent")]
    assert ids.count("Tolerance.tube") == 1
    assert EXPECTED_VERDICTS["Tolerance.tube"] is Verdict.PROVED


def test_proved_with_its_three_vcs():
    (ob,) = tolerance_obligations()
    p = discharge(ob)
    assert p.verdict is Verdict.PROVED, p.reason
    assert [v.name for v in p.vcs] == ["triangle", "speed", "tube"]
    assert all(v.answer == "unsat" and v.vacuity == "sat" for v in p.vcs)


def test_without_the_key_premise_or_with_c_above_l_delta_only_z3_answers_sat():
    vc = tube_vc()
    assert vc.key_premise == KEY_PREMISE == "c > 2 L delta"
    assert _answer(vc.without(KEY_PREMISE)) == z3.sat
    c, lip, delta = z3.Reals("c L delta")
    assert _answer(tube_vc(c > lip * delta)) == z3.sat
    assert _answer(vc) == z3.unsat


def test_every_vc_is_keyed_and_false_without_its_key():
    (ob,) = tolerance_obligations()
    for vc in ob.build().vcs:
        assert vc.key_premise is not None
        assert _answer(vc.without(vc.key_premise)) == z3.sat, vc.name
