"""Witness.labels_sound and Witness.reachable_sound: the checker's soundness, for any grid.

Both are proved (slow test; `cfmpa prove` runs them too); each VC fails once its key premise (the
start, edge, goal, closure or exclusion condition, or is_path) is dropped; none is true by its
Boolean skeleton alone; and the costs the obligation sums over the padded path are the spec's
J1 and J2.
"""

from __future__ import annotations

import pytest
import z3
from hypothesis import given, settings
from hypothesis import strategies as st

from cfmpa.proofs import EXPECTED_VERDICTS, Verdict, collect_obligations, discharge
from cfmpa.proofs._obl_witness import witness_obligations, witness_vcs
from cfmpa.proofs._obligation import VC
from cfmpa.spec import J1, J2

VCS = [(kind, vc) for kind in ("labels", "reachable") for vc in witness_vcs(kind)]
KEYS = {"labels.base": "witness.start", "labels.walk": "is_path L",
        "labels.step": "witness.edge", "labels.conclusion": "witness.goal",
        "labels.optimal": "witness.goal's comparison",
        "reachable.base": "witness.start", "reachable.walk": "is_path L",
        "reachable.step": "witness.closure", "reachable.conclusion": "witness.exclusion"}


def _answer(vc: VC, hypotheses=None, goal=None) -> z3.CheckSatResult:
    answer = z3.unknown
    for seed in range(3):
        s = z3.Solver()
        s.set("timeout", 20_000)
        s.set("random_seed", seed)
        s.add([h for _, h in (vc.hypotheses if hypotheses is None else hypotheses)])
        s.add(z3.Not(vc.goal if goal is None else goal))
        answer = s.check()
        if answer != z3.unknown:
            return answer
    return answer


def test_registered_and_pinned_as_proved():
    ids = [o.id for o in collect_obligations(scenarios_dir="/nonexistent")]
    for ob in witness_obligations():
        assert ids.count(ob.id) == 1
        assert EXPECTED_VERDICTS[ob.id] is Verdict.PROVED is ob.expected
        assert "induction" in ob.statement and "ledger A6" in ob.statement


def test_each_vc_is_keyed_by_the_condition_it_rests_on():
    assert [vc.name for _, vc in VCS] == list(KEYS)
    for _, vc in VCS:
        assert vc.key_premise.startswith(KEYS[vc.name]), vc.name


@pytest.mark.parametrize("name", ["labels.base", "labels.step", "labels.optimal",
                                  "reachable.base", "reachable.step"])
def test_dropping_the_start_or_edge_condition_makes_z3_answer_sat(name):
    vc = next(v for _, v in VCS if v.name == name)
    assert _answer(vc.without(vc.key_premise)) == z3.sat


def _skeleton(e: z3.ExprRef, atoms: dict[int, z3.BoolRef]) -> z3.BoolRef:
    """e with every maximal non-propositional sub-formula (comparisons, array reads,
    quantifiers) replaced by a Boolean variable, the same one for the same sub-formula."""
    kinds = {z3.Z3_OP_AND: z3.And, z3.Z3_OP_OR: z3.Or, z3.Z3_OP_NOT: z3.Not,
             z3.Z3_OP_IMPLIES: z3.Implies}
    if z3.is_true(e) or z3.is_false(e):
        return e
    if z3.is_app(e) and e.decl().kind() in kinds:
        return kinds[e.decl().kind()](*[_skeleton(c, atoms) for c in e.children()])
    if z3.is_eq(e) and z3.is_bool(e.arg(0)):
        return _skeleton(e.arg(0), atoms) == _skeleton(e.arg(1), atoms)
    if z3.is_app_of(e, z3.Z3_OP_ITE) and z3.is_bool(e):
        return z3.If(*[_skeleton(c, atoms) for c in e.children()])
    return atoms.setdefault(e.get_id(), z3.Bool(f"atom{len(atoms)}"))


@pytest.mark.parametrize("kind,vc", VCS, ids=[vc.name for _, vc in VCS])
def test_no_vc_follows_from_its_boolean_skeleton(kind, vc):
    atoms: dict[int, z3.BoolRef] = {}
    hyps = [(n, _skeleton(h, atoms)) for n, h in vc.hypotheses]
    assert _answer(vc, hyps, _skeleton(vc.goal, atoms)) == z3.sat


@pytest.mark.slow
def test_both_obligations_are_proved():
    for ob in witness_obligations():
        proof = discharge(ob)
        assert proof.verdict is Verdict.PROVED, (ob.id, proof.reason, proof.vcs)
        assert len(proof.vcs) == (5 if ob.id == "Witness.labels_sound" else 4)


@st.composite
def _lists(draw):
    """A list of cells with steps of -1, 0, +1 per coordinate, and N >= 1."""
    n = draw(st.integers(1, 8))
    cells = [(draw(st.integers(-3, 3)), draw(st.integers(-3, 3)))]
    for _ in range(n - 1):
        d = (draw(st.integers(-1, 1)), draw(st.integers(-1, 1)))
        cells.append((cells[-1][0] + d[0], cells[-1][1] + d[1]))
    return cells, draw(st.integers(1, 10))


@settings(max_examples=300, deadline=None)
@given(_lists())
def test_the_obligations_costs_are_the_specs_j1_and_j2(case):
    # A1, A2 summed over the list padded with its last cell to T = max(len - 1, N) moves, plus
    # the stop term |d_{T-1}|_1 (the obligation's (J1, J2)(L)), against spec J1 and J2.
    cells, N = case
    T = max(len(cells) - 1, N)
    pos = [cells[min(k, len(cells) - 1)] for k in range(T + 1)]
    prev = [(0, 0)] + [(pos[k][0] - pos[k - 1][0], pos[k][1] - pos[k - 1][1])
                       for k in range(1, T + 1)]
    a1 = sum(abs(d[0]) + abs(d[1]) for d in prev[1:])
    a2 = sum(abs(prev[k + 1][0] - prev[k][0]) + abs(prev[k + 1][1] - prev[k][1])
             for k in range(T))
    assert (a1, a2 + abs(prev[T][0]) + abs(prev[T][1])) == (J1(cells), J2(cells))


def _refuted(name, kind="labels", **patch):
    """Z3's answer on VC ``name`` of Witness.labels_sound (or reachable_sound) with spec's
    conditions replaced."""
    import cfmpa.proofs._obl_witness as W
    saved = {k: getattr(W, k) for k in patch}
    try:
        for k, f in patch.items():
            setattr(W, k, f)
        vc = next(v for v in W.witness_vcs(kind) if v.name == name)
    finally:
        for k, f in saved.items():
            setattr(W, k, f)
    return _answer(vc)


def test_the_proof_reads_the_checkers_edge_and_goal_conditions():
    # The proof runs spec's own conditions on Z3 terms: loosened, they fail it (the mutants
    # witness_edge_loosened and witness_goal_inequality of runs/_code_mutants.py).
    assert _refuted("labels.step", edge_holds=lambda t, b: t <= b + 1) == z3.sat
    assert _refuted("labels.optimal",
                    goal_holds=lambda c, m: (c[0] >= m[0]) & (c[1] >= m[1])) == z3.sat
    assert _refuted("labels.step") == z3.unsat


def test_the_proof_reads_the_checkers_reachable_set_conditions():
    # Seeded faults: each of spec's no-path conditions switched off (it never reports a break);
    # the VC that rests on it fails.
    never = z3.BoolVal(False)
    assert _refuted("reachable.base", "reachable", start_breaks=lambda f, s: never) == z3.sat
    assert _refuted("reachable.step", "reachable",
                    closure_breaks=lambda a, f, b: never) == z3.sat
    assert _refuted("reachable.conclusion", "reachable",
                    exclusion_breaks=lambda f, s: never) == z3.sat
    for name in ("reachable.base", "reachable.step", "reachable.conclusion"):
        assert _refuted(name, "reachable") == z3.unsat


def test_the_conclusion_reads_the_checkers_goal_keys():
    # Seeded fault: the checker's stop term loosened by one (a goal state's key one too big).
    assert _refuted("labels.conclusion",
                    stop_key=lambda k, p: k + abs(p[0]) + abs(p[1]) + 1) == z3.sat
    assert _refuted("labels.conclusion") == z3.unsat
    # Without witness.form's range at the goal states the key order is not the pair order.
    import cfmpa.proofs._obl_witness as W
    vc = next(v for v in W.witness_vcs("labels") if v.name == "labels.conclusion")
    assert _answer(vc.without("witness.form at the goal states: labels unsigned, in range")) \
        == z3.sat


def _vacuity(vc: VC) -> tuple[z3.CheckSatResult, int]:
    from cfmpa.proofs._obligation import _solver, rlimit_count
    hyps = [h for _, h in vc.hypotheses]
    s = _solver(20_000, formulas=hyps + [c == v for c, v in vc.witness], rlimit=2_000_000)
    return s.check(), rlimit_count(s)


def test_labels_step_vacuity_pins_give_a_model_cheaply():
    """labels.step's vacuity pins (a one-cell list on a 2 x 2 grid, one layer, edge 0) extend
    to a model of its hypotheses within 200 k of Z3's resource units (unpinned it took 4.5 M);
    pins the hypotheses exclude (edge 1 of a one-cell list: k < T fails) make it unsat, which
    the prove reports as vacuous: the pins are part of what the check shows."""
    import dataclasses

    vc = next(v for v in witness_vcs("labels") if v.name == "labels.step")
    assert [str(c) for c, _ in vc.witness] == ["k", "N", "L.len", "m", "n"]
    answer, count = _vacuity(vc)
    assert answer == z3.sat and count < 200_000
    k = vc.witness[0][0]
    wrong = tuple((c, z3.IntVal(1)) if c.eq(k) else (c, v) for c, v in vc.witness)
    assert _vacuity(dataclasses.replace(vc, witness=wrong))[0] == z3.unsat
