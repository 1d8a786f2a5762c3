"""Monitor.between_samples (docs/model.md §12): proved on the spec's own bound, refuted for a bound
whose h term is halved, and false without the robot's speed bound from the gap's first end. Not
registered here: the lead registers ``monitor_obligations`` in proofs/_runner.py."""

from __future__ import annotations

import z3

from cfmpa.proofs import Verdict, discharge
from cfmpa.proofs._obl_monitor import KEY_PREMISE, between_samples_vc, monitor_obligations
from cfmpa.proofs._obligation import VC
from cfmpa.spec import between_samples_bound, max_of
from z3answer import answer


def _answer(vc: VC) -> z3.CheckSatResult:
    return answer([h for _, h in vc.hypotheses] + [z3.Not(vc.goal)])


def _halved(d0, d1, h, w_robot, w_ref):
    """The seeded fault: the spec's bound with its h term halved."""
    return max_of(d0, d1) + (w_robot + w_ref) * h / 4


def test_proved():
    (ob,) = monitor_obligations()
    assert ob.id == "Monitor.between_samples" and ob.expected is Verdict.PROVED
    p = discharge(ob)
    assert p.verdict is Verdict.PROVED, p.reason
    assert [(v.name, v.answer, v.vacuity) for v in p.vcs] == [("between_samples", "unsat", "sat")]


def test_the_statement_is_the_spec_function_on_terms():
    # Built with the spec's function passed explicitly, the goal is the very same term.
    assert between_samples_vc().goal.eq(between_samples_vc(between_samples_bound).goal)
    assert not between_samples_vc().goal.eq(between_samples_vc(_halved).goal)


def test_a_bound_with_its_h_term_halved_is_refuted():
    assert _answer(between_samples_vc()) == z3.unsat
    assert _answer(between_samples_vc(_halved)) == z3.sat
    # ... and so is one without the trajectory's speed.
    assert _answer(between_samples_vc(
        lambda d0, d1, h, wx, wr: max_of(d0, d1) + wx * h / 2)) == z3.sat


def test_false_without_the_speed_bound_from_the_first_end():
    vc = between_samples_vc()
    assert vc.key_premise == KEY_PREMISE
    assert _answer(vc.without(KEY_PREMISE)) == z3.sat
