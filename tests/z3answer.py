"""One way for the tests to ask Z3: as cfmpa prove does (the query rebuilt from its text in a
context of its own, so the answer does not depend on the tests that ran before), with an
unknown retried under other seeds, since only sat or unsat is an answer."""

from __future__ import annotations

from collections.abc import Sequence
from fractions import Fraction

import z3

from cfmpa.proofs._obligation import _solver


def answer(formulas: Sequence[z3.BoolRef], *, seeds: int = 3,
           timeout_ms: int = 20_000) -> z3.CheckSatResult:
    """Z3's answer on the conjunction of ``formulas``: the first sat or unsat over the seeds,
    else unknown."""
    result = z3.unknown
    for seed in range(seeds):
        s = _solver(timeout_ms, formulas=list(formulas))
        s.set("random_seed", seed)
        result = s.check()
        if result != z3.unknown:
            return result
    return result


def exact_real(x: float | Fraction) -> z3.ArithRef:
    """The exact rational value of a double (or Fraction) as a Z3 real."""
    f = Fraction(x)
    return z3.RealVal(f"{f.numerator}/{f.denominator}")


def as_float(e: z3.ExprRef) -> float:
    """A closed Z3 term's value as the nearest double (asserting it simplifies to a rational)."""
    v = z3.simplify(e)
    assert z3.is_rational_value(v), v
    return float(v.as_fraction())
