"""Plane vectors and trigonometry as Z3 terms: the one set of helpers the catalogue's obligations
build their statements with (docs/model.md §6, §10).

A vector is a pair of real terms; ``vec("p")`` names one ``p.x``, ``p.y``. Two kinds of norm:
the polynomials (``n2``, ``dot``, ``norm``) and the abstract ``N2``, ``DOT`` (the uninterpreted
``sq``, ``dt``; ``concrete`` makes them the polynomials), with which a VC that only chains norm
bounds is valid for every sq and dt. sin and cos are the uninterpreted ``Sin``, ``Cos``; all that
is known of them are the ledger's facts (A3), stated by ``a3_*`` at the points a proof names.

The names of the Z3 symbols built here are part of every statement's hash
(proofs/obligations.lock): they do not depend on the module that builds them.
"""

from __future__ import annotations

from typing import Any

import z3

from ..spec import MAX_SPACING

__all__ = [
    "COS", "DOT", "DT", "G_MAX", "N2", "SIN", "SQ", "Hyp", "Vec", "a3_cos_bound", "a3_cos_mono",
    "a3_cos_nonneg", "a3_diff", "a3_sin_nonneg", "a3_sum", "a3_unit", "abs_", "add", "comb",
    "concrete", "constants", "diff_rule", "dot", "e", "j", "n2", "norm", "occurs", "rot", "same",
    "scale", "sub", "subterms", "sum_rule", "unit", "unit_poly", "vec", "veq", "within",
]

Vec = tuple[z3.ArithRef, z3.ArithRef]
Hyp = tuple[str, z3.BoolRef]
_R = z3.RealSort()

#: A rational below pi: the loader's spacing bound (spec.MAX_SPACING, 157/50); the ledger's facts
#: on [0, pi] are stated for angles up to it.
G_MAX = z3.Q(MAX_SPACING.numerator, MAX_SPACING.denominator)


# --- vectors --------------------------------------------------------------------------------------

def vec(name: str) -> Vec:
    """The vector named ``name``: the reals ``name.x``, ``name.y``."""
    return z3.Real(f"{name}.x"), z3.Real(f"{name}.y")


def add(a: Vec, b: Vec) -> Vec:
    return (a[0] + b[0], a[1] + b[1])


def sub(a: Vec, b: Vec) -> Vec:
    return (a[0] - b[0], a[1] - b[1])


def scale(c: Any, a: Vec) -> Vec:
    """c a (c a term or a number)."""
    return (c * a[0], c * a[1])


def comb(a: Vec, b: Vec, t: z3.ArithRef) -> Vec:
    """(1 - t) a + t b."""
    return ((1 - t) * a[0] + t * b[0], (1 - t) * a[1] + t * b[1])


def veq(a: Vec, b: Vec) -> z3.BoolRef:
    return z3.And(a[0] == b[0], a[1] == b[1])


def j(a: Vec) -> Vec:
    """The quarter turn J(x, y) = (-y, x)."""
    return (-a[1], a[0])


def rot(cs: Vec, v: Vec) -> Vec:
    """v turned by the angle whose (cos, sin) is cs."""
    return (cs[0] * v[0] - cs[1] * v[1], cs[1] * v[0] + cs[0] * v[1])


def dot(a: Vec, b: Vec) -> z3.ArithRef:
    """a . b, the polynomial."""
    return a[0] * b[0] + a[1] * b[1]


def n2(v: Vec) -> z3.ArithRef:
    """|v|^2, the polynomial."""
    return v[0] * v[0] + v[1] * v[1]


def norm(n: z3.ArithRef, v: Vec) -> z3.BoolRef:
    """n is the length of v: n >= 0 and n^2 = |v|^2."""
    return z3.And(n >= 0, n * n == v[0] * v[0] + v[1] * v[1])


def unit_poly(u: Vec) -> z3.BoolRef:
    """|u|^2 = 1, the polynomial."""
    return u[0] * u[0] + u[1] * u[1] == 1


def abs_(a: z3.ArithRef) -> z3.ArithRef:
    """|a| as an if-then-else."""
    return z3.If(a >= 0, a, -a)


def within(x: z3.ArithRef, b: Any) -> z3.BoolRef:
    """|x| <= b as -b <= x <= b."""
    return z3.And(x <= b, -x <= b)


def subterms(*roots: z3.ExprRef) -> Any:
    """The subterms of ``roots``, each shared subterm once (a quantifier's children are its
    body), depth first."""
    seen: set[int] = set()
    todo = list(roots)
    while todo:
        x = todo.pop()
        if x.get_id() in seen:
            continue
        seen.add(x.get_id())
        yield x
        todo += x.children()


def occurs(term: z3.ExprRef, inside: z3.ExprRef) -> bool:
    """Whether ``term`` is a subterm of ``inside`` (each shared subterm visited once)."""
    return any(z3.eq(x, term) for x in subterms(inside))


def constants(*roots: z3.ExprRef) -> list[z3.ExprRef]:
    """The uninterpreted constants occurring in ``roots``, in the order first met."""
    return [x for x in subterms(*roots)
            if z3.is_const(x) and x.decl().kind() == z3.Z3_OP_UNINTERPRETED]


# --- abstract norms -------------------------------------------------------------------------------

SQ = z3.Function("sq", _R, _R, _R)
DT = z3.Function("dt", _R, _R, _R, _R, _R)
_V0, _V1, _V2, _V3 = (z3.Var(i, _R) for i in range(4))
#: sq(a, b) := a^2 + b^2 and dt(a, b, c, d) := a c + b d: what the abstract norms stand for.
_CONCRETE = ((SQ, _V0 * _V0 + _V1 * _V1), (DT, _V0 * _V2 + _V1 * _V3))


def concrete(f: z3.ExprRef) -> z3.ExprRef:
    """f with sq and dt replaced by the polynomials they stand for."""
    return z3.substitute_funs(f, *_CONCRETE)


def N2(v: Vec) -> z3.ArithRef:
    """|v|^2, abstract: ``concrete`` makes it v.x^2 + v.y^2."""
    return SQ(v[0], v[1])


def DOT(a: Vec, b: Vec) -> z3.ArithRef:
    """a . b, abstract."""
    return DT(a[0], a[1], b[0], b[1])


# --- trigonometry ---------------------------------------------------------------------------------

COS = z3.Function("Cos", _R, _R)
SIN = z3.Function("Sin", _R, _R)


def e(x: z3.ArithRef) -> Vec:
    """(cos x, sin x)."""
    return (COS(x), SIN(x))


def unit(cs: Vec) -> z3.BoolRef:
    """(cos, sin) on the unit circle, |cs|^2 = 1 (abstract norm: concrete, c^2 + s^2 = 1)."""
    return N2(cs) == 1


def sum_rule(t: Vec, x: Vec, y: Vec) -> z3.BoolRef:
    """e(x + y) = e(x) e(y) on values: t is (cos, sin) of x + y."""
    return z3.And(t[0] == x[0] * y[0] - x[1] * y[1], t[1] == x[1] * y[0] + x[0] * y[1])


def diff_rule(t: Vec, x: Vec, y: Vec) -> z3.BoolRef:
    """e(x - y) from e(x), e(y)."""
    return z3.And(t[0] == x[0] * y[0] + x[1] * y[1], t[1] == x[1] * y[0] - x[0] * y[1])


def same(a: z3.ArithRef, b: z3.ArithRef) -> None:
    """a and b are the same real for every value of their names (else the fact is not one)."""
    if z3.is_true(z3.simplify(a == b)):
        return
    s = z3.Solver()
    s.set("timeout", 2000)
    s.add(a != b)
    if s.check() != z3.unsat:
        raise ValueError(f"not an identity: {a} = {b}")


# The ledger's trigonometric facts (A3), each at the points given; ``at`` names them.
def a3_unit(x: z3.ArithRef, at: str) -> Hyp:
    return (f"A3 cos^2 + sin^2 = 1 at {at}", unit(e(x)))


def a3_sum(total: z3.ArithRef, x: z3.ArithRef, y: z3.ArithRef, at: str) -> Hyp:
    same(total, x + y)
    return (f"A3 cos, sin of a sum at {at}", sum_rule(e(total), e(x), e(y)))


def a3_diff(total: z3.ArithRef, x: z3.ArithRef, y: z3.ArithRef, at: str) -> Hyp:
    same(total, x - y)
    return (f"A3 cos, sin of a difference at {at}", diff_rule(e(total), e(x), e(y)))


def a3_cos_bound(x: z3.ArithRef, at: str) -> Hyp:
    return (f"A3 cos x >= 1 - x^2/2 at {at}", COS(x) >= 1 - x * x / 2)


def a3_cos_mono(x: z3.ArithRef, y: z3.ArithRef, at: str) -> Hyp:
    return (f"A3 cos even, non-increasing on [0, pi], at {at}",
            z3.Implies(z3.And(-y <= x, x <= y, y <= G_MAX), COS(x) >= COS(y)))


def a3_sin_nonneg(x: z3.ArithRef, at: str) -> Hyp:
    return (f"A3 sin >= 0 on [0, pi] at {at}",
            z3.Implies(z3.And(0 <= x, x <= G_MAX), SIN(x) >= 0))


def a3_cos_nonneg(x: z3.ArithRef, at: str) -> Hyp:
    return (f"A3 cos >= 0 on [0, pi/2] at {at}",
            z3.Implies(z3.And(0 <= x, 2 * x <= G_MAX), COS(x) >= 0))
