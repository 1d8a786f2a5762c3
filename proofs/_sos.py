"""Sum-of-squares certificates for nonlinear VCs, checked as exact identities by sympy.

Where cvc5 does not decide a VC of polynomial real arithmetic, a certificate gives a second
confirmation that needs no solver at all. For a VC whose goal is ``lhs <= rhs`` (or ``>=``,
or ``==``) and whose hypotheses include atoms ``a <= b``, ``a >= b`` or ``a == b`` (named by the
hypothesis and, in a conjunction, the conjunct's index), a certificate is a list of terms

    SOS term:    c * s_1 * ... * s_k * q^2      (c >= 0 rational, s_i inequality slacks)
    ideal term:  p * e                          (p any polynomial, e an equation's slack)

where the slack of ``a <= b`` is ``b - a`` (``>= 0`` under the hypotheses), of ``a == b`` is
``a - b`` (``= 0``). The check: ``slack(goal) - Σ terms`` expands to 0, exactly (rationals, no
floats). Every SOS term is ``>= 0`` and every ideal term ``= 0`` under the hypotheses, so then
``slack(goal) >= 0`` (for an equation goal only ideal terms are allowed, so ``slack(goal) =
0``): the goal holds. The certificate is read against the VC's own Z3 terms (converted to sympy),
so it certifies the statement the run proves, not a copy of it.
"""

from __future__ import annotations

from dataclasses import dataclass
from fractions import Fraction

import sympy as sp
import z3

__all__ = ["Certificate", "Ideal", "Square", "check_certificate", "to_sympy"]

Ref = tuple[str, int]      # (hypothesis name, conjunct index; 0 for an atom)


@dataclass(frozen=True)
class Square:
    """c * (product of the slacks named) * q^2, c >= 0."""

    coeff: Fraction
    slacks: tuple[Ref, ...]
    q: z3.ArithRef | int = 1


@dataclass(frozen=True)
class Ideal:
    """p * (the slack of the equation named): zero under the hypotheses."""

    equation: Ref
    p: z3.ArithRef | int


@dataclass(frozen=True)
class Certificate:
    terms: tuple[Square | Ideal, ...]
    name: str = "SOS certificate"


def to_sympy(e: z3.ExprRef | int, syms: dict[str, sp.Symbol]) -> sp.Expr:
    """A polynomial (or rational function) Z3 term as a sympy expression, exactly."""
    if isinstance(e, int):
        return sp.Integer(e)
    if z3.is_int_value(e):
        return sp.Integer(e.as_long())
    if z3.is_rational_value(e):
        fr = e.as_fraction()
        return sp.Rational(fr.numerator, fr.denominator)
    if z3.is_const(e) and e.decl().kind() == z3.Z3_OP_UNINTERPRETED:
        name = e.decl().name()
        return syms.setdefault(name, sp.Symbol(name, real=True))
    kids = [to_sympy(c, syms) for c in e.children()]
    k = e.decl().kind()
    if k == z3.Z3_OP_ADD:
        return sp.Add(*kids)
    if k == z3.Z3_OP_SUB:
        return kids[0] - sp.Add(*kids[1:])
    if k == z3.Z3_OP_MUL:
        return sp.Mul(*kids)
    if k == z3.Z3_OP_UMINUS:
        return -kids[0]
    if k == z3.Z3_OP_DIV:
        return kids[0] / kids[1]
    if k == z3.Z3_OP_POWER:
        return kids[0] ** kids[1]
    if k == z3.Z3_OP_TO_REAL:
        return kids[0]
    raise ValueError(f"not a polynomial term: {e}")


def _atoms(f: z3.BoolRef) -> list[z3.BoolRef]:
    return list(f.children()) if z3.is_and(f) else [f]


def _slack(atom: z3.BoolRef, syms: dict[str, sp.Symbol]) -> tuple[str, sp.Expr]:
    """('ineq', b - a) for a <= b or b >= a; ('eq', a - b) for a == b."""
    if not (z3.is_le(atom) or z3.is_ge(atom) or z3.is_eq(atom)):
        raise ValueError(f"not an atom a <= b, a >= b or a == b: {atom}")
    a, b = (to_sympy(x, syms) for x in atom.children())
    if z3.is_le(atom):
        return "ineq", b - a
    if z3.is_ge(atom):
        return "ineq", a - b
    return "eq", a - b


def check_certificate(vc: object) -> tuple[bool, str]:
    """(holds, what): whether ``vc.certificate`` proves ``vc``'s goal from its hypotheses."""
    cert: Certificate = vc.certificate  # type: ignore[attr-defined]
    syms: dict[str, sp.Symbol] = {}
    hyps = dict(vc.hypotheses)  # type: ignore[attr-defined]
    try:
        kind, goal = _slack(vc.goal, syms)  # type: ignore[attr-defined]

        def slack(ref: Ref, want: str) -> sp.Expr:
            name, i = ref
            k, s = _slack(_atoms(hyps[name])[i], syms)
            if k != want:
                raise ValueError(f"{name}[{i}] is not an "
                                 f"{'inequality' if want == 'ineq' else 'equation'}")
            return s
        total = sp.Integer(0)
        for term in cert.terms:
            if isinstance(term, Square):
                if term.coeff < 0:
                    raise ValueError("a negative coefficient")
                if kind == "eq":
                    raise ValueError("an equation's certificate has only ideal terms")
                prod: sp.Expr = sp.Rational(term.coeff.numerator, term.coeff.denominator)
                for ref in term.slacks:
                    prod *= slack(ref, "ineq")
                total += prod * to_sympy(term.q, syms) ** 2
            else:
                total += to_sympy(term.p, syms) * slack(term.equation, "eq")
        rest = sp.expand(goal - total)
    except (KeyError, IndexError, ValueError) as exc:
        return False, f"{cert.name} does not apply ({exc})"
    if rest != 0:
        return False, f"{cert.name}: slack(goal) - (the terms) = {sp.factor(rest)}, not 0"
    return True, f"{cert.name} ({len(cert.terms)} terms, an exact sympy identity)"
