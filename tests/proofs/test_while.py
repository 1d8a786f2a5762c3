"""The while-language: weakest preconditions, loop VCs, termination, Python's range semantics."""

from __future__ import annotations

import pytest
import z3

from cfmpa.proofs._while import (
    Assign,
    Assume,
    For,
    Havoc,
    Seq,
    Store,
    While,
    modifies,
    verification_conditions,
    wp,
)


def _valid(f: z3.BoolRef) -> bool:
    s = z3.Solver()
    s.set("timeout", 5_000)
    s.add(z3.Not(f))
    r = s.check()
    assert r != z3.unknown
    return r == z3.unsat


def _failing(vcs) -> list[str]:
    out = []
    for vc in vcs:
        f = z3.Implies(z3.And([h for _, h in vc.hypotheses]), vc.goal)
        if not _valid(f):
            out.append(vc.name)
    return out


def test_assignment_and_store_substitute():
    x = z3.Int("x")
    assert _valid(wp(Assign(x, x + 1), x > 0) == (x + 1 > 0))
    a = z3.Array("a", z3.IntSort(), z3.IntSort())
    assert _valid(wp(Store(a, (x,), z3.IntVal(7)), a[x] == 7))
    assert not _valid(wp(Store(a, (x,), z3.IntVal(7)), a[x + 1] == 7))


def test_counted_loop_is_proved_and_needs_its_precondition():
    s, i, n = z3.Ints("s i n")
    prog = Seq((Assign(s, z3.IntVal(0)),
                For("L", i, z3.IntVal(0), n, s == 2 * i, Assign(s, s + 2))))
    assert _failing(verification_conditions("sum", n >= 0, prog, s == 2 * n)) == []
    # range(0, n) with n < 0 runs no iteration: s stays 0, not 2 n.
    assert _failing(verification_conditions("sum", z3.BoolVal(True), prog, s == 2 * n)) == ["sum.main"]
    assert _failing(verification_conditions("sum", z3.BoolVal(True), prog, s == 0,
                                            termination=True)) == []


def test_a_wrong_invariant_is_caught():
    s, i, n = z3.Ints("s i n")
    prog = Seq((Assign(s, z3.IntVal(0)),
                For("L", i, z3.IntVal(0), n, s == 3 * i, Assign(s, s + 2))))
    assert "L.preserve" in _failing(verification_conditions("sum", n >= 0, prog, s == 2 * n))


def test_facts_about_unmodified_variables_flow_past_a_loop():
    x, y, i, n = z3.Ints("x y i n")
    prog = Seq((Assign(y, z3.IntVal(5)),
                For("L", i, z3.IntVal(0), n, z3.BoolVal(True), Assign(x, x + 1))))
    assert _failing(verification_conditions("frame", n >= 0, prog, y == 5)) == []


def test_a_loop_that_does_not_progress_fails_termination():
    x = z3.Int("x")
    stuck = While("W", x > 0, z3.BoolVal(True), x, Assign(x, x))
    vcs = verification_conditions("stuck", z3.BoolVal(True), stuck, z3.BoolVal(True),
                                  termination=True)
    assert _failing(vcs) == ["W.variant_decreases"]
    down = While("W", x > 0, z3.BoolVal(True), x, Assign(x, x - 1))
    assert _failing(verification_conditions("down", z3.BoolVal(True), down, x <= 0,
                                            termination=True)) == []
    assert _failing(verification_conditions("down", z3.BoolVal(True), down, x <= 0)) == []


def test_havoc_and_assume_model_a_callee_contract():
    x, y = z3.Ints("x y")
    call = Seq((Havoc((y,)), Assume(y > x)))
    assert _valid(wp(call, y > x))
    assert not _valid(wp(Havoc((y,)), y > x))


def test_for_rejects_a_body_that_moves_its_counter():
    i, n = z3.Ints("i n")
    with pytest.raises(ValueError, match="counter or bounds"):
        wp(For("L", i, z3.IntVal(0), n, z3.BoolVal(True), Assign(i, i + 1)), z3.BoolVal(True))
    with pytest.raises(ValueError, match="counter or bounds"):
        wp(For("L", i, z3.IntVal(0), n, z3.BoolVal(True), Assign(n, n + 1)), z3.BoolVal(True))


def test_modifies_lists_each_variable_once():
    x, y, i, n = z3.Ints("x y i n")
    a = z3.Array("a", z3.IntSort(), z3.IntSort())
    prog = Seq((Assign(x, y), For("L", i, z3.IntVal(0), n, z3.BoolVal(True),
                                  Seq((Store(a, (i,), x), Assign(x, x + 1))))))
    assert [str(v) for v in modifies(prog)] == ["x", "i", "a"]
