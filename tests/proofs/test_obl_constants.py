"""Certificate.lipschitz, Tolerance.tube_factor and Exact.gap_formula: proved as
the code is; each seeded fault of CONSTANT_MUTANTS, applied to a copy of its source file, refutes
its obligation; each VC is false without its key premise."""

from __future__ import annotations

import sys

import pytest
import z3

import cfmpa.spec
from cfmpa.proofs import Verdict, discharge
from cfmpa.proofs._obl_constants import (
    ExtractionError,
    constants_obligations,
    on_terms,
    sqrt_free,
    tolerance_parts,
)
from cfmpa.proofs._obligation import VC, Obligation, Z3Query
from cfmpa.proofs._summaries import SUMMARIES as ALL_SUMMARIES
from cfmpa.runs._code_mutants import CODE_MUTANTS
from mutant_module import mutated_module, source
from z3answer import answer

IDS = ["Certificate.lipschitz", "Tolerance.tube_factor", "Exact.gap_formula"]
SUMMARIES = {i: ALL_SUMMARIES[i] for i in IDS}

#: The public names of cfmpa.spec each mutated file defines (what the obligations read).
READS = {"spec/_certificate.py": ("link_speeds", "interval_bound", "pair_lipschitz"),
         "spec/_kinematics.py": ("reach",),
         "spec/_trajectory.py": ("tolerance_rad", "tube_lipschitz"),
         "spec/_exact.py": ("projection_bounds", "gap_over_norm")}

#: The obligation and the VC each mutant must refute.
CAUGHT_BY = {"link_speed_halved": ("Certificate.lipschitz", {"speed_link1", "speed_link2"}),
             "interval_lipschitz_halved": ("Certificate.lipschitz", {"interval"}),
             "pair_lipschitz_halved": ("Certificate.lipschitz", {"distance_rate"}),
             "reach_without_cap": ("Certificate.lipschitz", {"reach_link2_elbow"}),
             "tube_factor_halved": ("Tolerance.tube_factor", {"factor"}),
             "tolerance_early_return_loosened": ("Tolerance.tube_factor", {"factor"}),
             "tube_lipschitz_left_only": ("Tolerance.tube_factor", {"lipschitz"}),
             "gap_without_norm": ("Exact.gap_formula", {"gap"}),
             "gap_sign_flipped": ("Exact.gap_formula", {"gap"}),
             "gap_projection_min": ("Exact.gap_formula", {"bounds_A"}),
             "tube_lipschitz_without_tool": ("Tolerance.tube_factor", {"lipschitz_tool"}),
             "tool_speed_from_forearm": ("Certificate.lipschitz", {"speed_tool"})}
#: The constants' mutants of selftest --code (runs/_code_mutants.py), as (name, what, file, edits).
CONSTANT_MUTANTS = [(m.name, m.what, m.file, m.edits) for m in CODE_MUTANTS if m.name in CAUGHT_BY]


def _obligation(oid: str) -> Obligation:
    (ob,) = [o for o in constants_obligations() if o.id == oid]
    return ob


def _vcs(oid: str) -> tuple[VC, ...]:
    q = _obligation(oid).build()
    assert isinstance(q, Z3Query)
    return q.vcs


def _proof_answer(vc: VC, pins=()) -> z3.CheckSatResult:
    return answer([h for _, h in vc.hypotheses] + [z3.Not(vc.goal)]
                  + [c == v for c, v in pins])


def _plant(monkeypatch: pytest.MonkeyPatch, mutant: tuple) -> None:
    """Load the mutated copy of the mutant's file as a module of its package (its source
    registered for inspect) and point the public names the obligations read at it."""
    name, what, file, edits = mutant
    mod = mutated_module(name, file, edits,
                         lambda key, value: monkeypatch.setitem(sys.modules, key, value))
    for attr in READS[file]:
        monkeypatch.setattr(cfmpa.spec, attr, getattr(mod, attr))


# --- as the code is -----------------------------------------------------------------------------

def test_three_obligations_with_summaries():
    obs = constants_obligations()
    assert [o.id for o in obs] == IDS
    assert all(o.expected is Verdict.PROVED for o in obs)
    assert set(SUMMARIES) == set(IDS)
    assert all(0 < len(s) <= 240 and "spec" not in s and "_" not in s for s in SUMMARIES.values())


@pytest.mark.parametrize("oid", IDS)
def test_every_vc_unsat_with_satisfiable_hypotheses(oid: str):
    for vc in _vcs(oid):
        assert _proof_answer(vc) == z3.unsat, vc.name
        pins = [c == v for c, v in vc.witness]
        assert answer([h for _, h in vc.hypotheses] + pins) == z3.sat, vc.name


@pytest.mark.parametrize("oid", IDS)
def test_every_vc_is_keyed_and_false_without_its_key(oid: str):
    for vc in _vcs(oid):
        assert vc.key_premise is not None, vc.name
        # With the VC's counter-witness pins where it has them (the tool's lemmas: a model of
        # 16 vertices is found with them, as in tests/proofs/test_negative.py).
        assert _proof_answer(vc.without(vc.key_premise), vc.counter_witness) == z3.sat, vc.name


@pytest.mark.slow
@pytest.mark.parametrize("oid", IDS)
def test_discharged_proved(oid: str):
    p = discharge(_obligation(oid))
    assert p.verdict is Verdict.PROVED, p.reason
    assert all(v.vacuity == "sat" and v.answer == "unsat" for v in p.vcs)


def test_tube_factor_discharged_proved():
    """The quick one of the three discharged in full (the others: test_discharged_proved, slow)."""
    p = discharge(_obligation("Tolerance.tube_factor"))
    assert p.verdict is Verdict.PROVED, p.reason
    assert [v.name for v in p.vcs] == ["factor", "lipschitz", "deviation", "lipschitz_tool"]


# --- the seeded faults --------------------------------------------------------------------------

def test_each_mutant_edits_todays_source_once_and_is_checked_here():
    assert {m[0] for m in CONSTANT_MUTANTS} == set(CAUGHT_BY)
    for name, what, file, edits in CONSTANT_MUTANTS:
        assert file in READS and what and edits
        _, src = source(file)
        for old, new in edits:
            assert src.count(old) == 1, (name, old)
            assert old != new


@pytest.mark.parametrize("mutant", CONSTANT_MUTANTS, ids=[m[0] for m in CONSTANT_MUTANTS])
def test_each_mutant_refutes_its_obligation(monkeypatch: pytest.MonkeyPatch, mutant: tuple):
    oid, vcs = CAUGHT_BY[mutant[0]]
    before = {vc.name: vc for vc in _vcs(oid)}
    _plant(monkeypatch, mutant)
    after = {vc.name: vc for vc in _vcs(oid)}
    changed = {n for n in after if not after[n].goal.eq(before[n].goal)
               or len(after[n].hypotheses) != len(before[n].hypotheses)
               or any(not x[1].eq(y[1]) for x, y in zip(after[n].hypotheses,
                                                          before[n].hypotheses))}
    assert vcs <= changed, changed
    for n in vcs:
        assert _proof_answer(after[n]) == z3.sat, n
    # Discharged: the obligation restricted to the VCs the fault must refute is FAILED (the
    # whole obligation: test_each_mutant_fails_the_whole_obligation, slow).
    ob = _obligation(oid)
    only = Obligation(ob.id, ob.group, ob.paper_ref, ob.statement, ob.method, ob.expected,
                      lambda: Z3Query(tuple(after[n] for n in sorted(vcs))))
    p = discharge(only)
    assert p.verdict is Verdict.FAILED and p.reason.startswith("refuted"), p.reason


@pytest.mark.slow
@pytest.mark.parametrize("mutant", CONSTANT_MUTANTS, ids=[m[0] for m in CONSTANT_MUTANTS])
def test_each_mutant_fails_the_whole_obligation(monkeypatch: pytest.MonkeyPatch, mutant: tuple):
    oid, _ = CAUGHT_BY[mutant[0]]
    _plant(monkeypatch, mutant)
    p = discharge(_obligation(oid))
    assert p.verdict is Verdict.FAILED and p.reason.startswith("refuted"), p.reason


def test_the_planted_copy_is_what_the_obligation_reads(monkeypatch: pytest.MonkeyPatch):
    """The fault is seen through cfmpa.spec, and undone after the test (monkeypatch)."""
    original = cfmpa.spec.gap_over_norm
    _plant(monkeypatch, next(m for m in CONSTANT_MUTANTS if m[0] == "gap_without_norm"))
    assert cfmpa.spec.gap_over_norm is not original
    assert cfmpa.spec.gap_over_norm(0.0, 3.0, 2.0, 0.0) == 3.0
    assert original(0.0, 3.0, 2.0, 0.0) == 1.5


# --- the readings of the code -------------------------------------------------------------------

def test_sqrt_free_gives_each_root_its_exact_meaning():
    x, y = z3.Reals("x y")
    (t,), hyps = sqrt_free([cfmpa.spec.hypot_of(x, y) + cfmpa.spec.sqrt_of(x * x)])
    assert len(hyps) == 2
    assert "**" not in str(t)
    # With the meaning, sqrt(x^2) = |x|; without it, it could be anything.
    s = [h for _, h in hyps]
    r = z3.Real("sqrt(x*x)")
    assert answer(s + [r != z3.If(x >= 0, x, -x)]) == z3.unsat
    assert answer([r != z3.If(x >= 0, x, -x)]) == z3.sat


def test_tube_lipschitz_on_terms_is_the_same_function_on_floats():
    from cfmpa.scenarios import BUNDLED_DIR, bundled_names

    for name in bundled_names():
        s = cfmpa.spec.load_scenario(BUNDLED_DIR / f"{name}.toml")
        assert on_terms(cfmpa.spec.tube_lipschitz)(s) == cfmpa.spec.tube_lipschitz(s)


def test_tolerance_rad_is_read_off_its_syntax_tree():
    c, lip, k = z3.Reals("c L k")
    sym = object()
    cert = type("C", (), {"clear": z3.Bool("clear"), "lower_bound_m": c})()
    parts = tolerance_parts(cfmpa.spec.tolerance_rad,
                            {"s": sym, "cert": cert, "k": k, "tube_lipschitz": lambda s: lip})
    assert z3.simplify(parts.two_l - 2 * lip).eq(z3.RealVal(0))
    # The guard is k > 0 and two_l (k / per) > c - EPS, per = 10^6.
    sol = z3.Solver()
    sol.add(parts.guard != z3.And(k > 0, 2 * lip * (k / 1_000_000) > c - cfmpa.spec.EPS))
    assert sol.check() == z3.unsat


def test_tolerance_parts_refuses_code_outside_its_subset():
    def tolerance_rad(s, cert):
        for _ in range(3):
            pass
        return 0.0

    with pytest.raises(ExtractionError, match="outside the subset"):
        tolerance_parts(tolerance_rad, {})
