"""``Exact.gap_formula`` for polygon pairs: the exact re-decision's points of a tool, run on Z3
terms, bound the projection of the whole grown tool (docs/model.md §7.2, §10 (f)).

The exact re-decision (``spec.exact_path_gaps``) decides a pair of parts by the separating
direction n: ``projection_bounds`` over each part's points, then ``gap_over_norm``. A tool (a
convex polygon fixed to link 2) enters through ``spec._exact._tool_points``: its vertices each
moved by +-grow along the forearm and its normal, in balls. ``bounds_A`` and ``bounds_B`` of
``Exact.gap_formula`` prove the bounds for a point of the hull of the points; these VCs prove
that the hull of the tool's points, as ``_tool_points`` makes them, holds the part itself grown
by the square of half-side grow in the forearm's frame (which holds the disc of radius grow:
Safety.tool_region's ``grow_square``), on either side of the pair:

The statement, on either side (the tool the principal's part, A, or the subordinate's, B):
projection_bounds' end over the points _tool_points makes is at or above (A) / below (B) n.x
for every point x = W + R(phi)(p + e) of the grown tool (p a convex combination of three
vertices, e in the square), W the wrist and R(phi) the forearm's frame of docs/model.md §2 at
the angles (t1, t2). In six VCs, joined by substitution:

- ``tool_points``: each vertex moved by each corner of the square, placed at (t1, t2), is one of
  the points ``_tool_points`` makes (G1, G2, ...);
- ``tool_frame``: n . (W + R(phi)(u, v)) = K + a u + b v, (a, b) n in the forearm's frame,
  K = n . W, at those points and at x;
- ``tool_max_A``, ``tool_max_B``: ``projection_bounds``' end is at or above / below each point's
  projection (the code's reduction run on the projections P_k = n . G_k);
- ``tool_hull_A``, ``tool_hull_B``: then K + a (p + e)_u + b (p + e)_v, i.e. n.x, is too.

``_tool_points`` is run as written: ``arb`` replaced by a stand-in whose values are Z3 terms (an
arb of a number is the number; ``cos`` and ``sin`` of an angle are reals named by the angle's
term, so nothing is assumed of them), the arm's dimensions and the tool's vertices
symbols. A tool of three vertices stands for any: a point of a convex polygon is a combination of
three of its vertices (Caratheodory, in the plane; named) and the code treats each vertex alike.
Pairs with a link (a rectangle's corners) are ``bounds_A``/``bounds_B`` themselves.
"""

from __future__ import annotations

import math
import random
import types
from typing import Any

import z3

from .. import spec
from ._obligation import VC

__all__ = ["VERTICES", "polygon_gap_vcs", "tool_points_on_terms"]

#: Vertices of the symbolic tool (a point of a convex polygon is a combination of three).
VERTICES = 3

def _COS(x: Any) -> z3.ArithRef:
    """cos x as a real named by x (the same term, the same real; nothing else assumed)."""
    return z3.Real(f"cos({z3.simplify(x).sexpr()})")


def _SIN(x: Any) -> z3.ArithRef:
    """sin x as a real named by x."""
    return z3.Real(f"sin({z3.simplify(x).sexpr()})")


def _term(x: Any) -> Any:
    return x.t if isinstance(x, _Ball) else (x if z3.is_expr(x) else z3.RealVal(x))


class _Ball:
    """Stands for an ``arb`` in the code under proof: its value is a Z3 term."""

    def __init__(self, x: Any) -> None:
        self.t = _term(x)

    def __add__(self, o: Any) -> _Ball:
        return _Ball(self.t + _term(o))

    __radd__ = __add__

    def __sub__(self, o: Any) -> _Ball:
        return _Ball(self.t - _term(o))

    def __rsub__(self, o: Any) -> _Ball:
        return _Ball(_term(o) - self.t)

    def __mul__(self, o: Any) -> _Ball:
        return _Ball(self.t * _term(o))

    __rmul__ = __mul__

    def __neg__(self) -> _Ball:
        return _Ball(-self.t)

    def cos(self) -> _Ball:
        return _Ball(_COS(self.t))

    def sin(self) -> _Ball:
        return _Ball(_SIN(self.t))


def tool_points_on_terms(arm: Any, t1: Any, t2: Any, grow: Any, tool_points: Any = None
                         ) -> list[tuple[Any, Any]]:
    """``spec._exact._tool_points`` (or ``tool_points``, a function of that module) run with
    ``arb`` a stand-in on Z3 terms: the points as terms."""
    f = spec.exact_path_gaps.__globals__["_tool_points"] if tool_points is None else tool_points
    g = dict(f.__globals__)
    g["arb"] = _Ball
    run = types.FunctionType(f.__code__, g, f.__name__, f.__defaults__, f.__closure__)
    return [(_term(x), _term(y)) for x, y in run(arm, t1, t2, _Ball(grow))]


def _arm() -> tuple[Any, list[tuple[z3.ArithRef, z3.ArithRef]]]:
    verts = [(z3.Real(f"x{i + 1}"), z3.Real(f"y{i + 1}")) for i in range(VERTICES)]
    arm = types.SimpleNamespace(base=z3.Reals("bx by"), links=z3.Reals("l1 l2"),
                                tool=types.SimpleNamespace(polygon=verts))
    return arm, verts


#: The square's corners, in the order the model's points are listed (any order would do).
_SQUARE = ((-1, -1), (1, -1), (1, 1), (-1, 1))


class _Tool:
    """The symbols of the polygon VCs and the model's points (docs/model.md §2: the tool is
    fixed to link 2, in the forearm's frame at the wrist W, turned by R(phi), phi = t1 + t2)."""

    def __init__(self) -> None:
        self.arm, self.verts = _arm()
        self.t1, self.t2, self.grow = z3.Reals("t1 t2 grow")
        self.n = z3.Reals("n.x n.y")
        self.e = z3.Reals("e.x e.y")
        self.w = z3.Reals(" ".join(f"w{i + 1}" for i in range(VERTICES)))
        self.a, self.b, self.K = z3.Reals("a b K")
        (bx, by), (l1, l2) = self.arm.base, self.arm.links
        phi = self.t1 + self.t2
        self.c, self.s = _COS(phi), _SIN(phi)
        self.W = (bx + l1 * _COS(self.t1) + l2 * self.c, by + l1 * _SIN(self.t1) + l2 * self.s)
        #: (U, V) in the forearm's frame of each vertex moved by each corner of the square.
        self.frame = [(x + sx * self.grow, y + sy * self.grow)
                      for x, y in self.verts for sx, sy in _SQUARE]
        self.p = (sum(wi * v[0] for wi, v in zip(self.w, self.verts)),
                  sum(wi * v[1] for wi, v in zip(self.w, self.verts)))

    def at(self, u: Any, v: Any) -> tuple[Any, Any]:
        """W + R(phi) (u, v)."""
        return (self.W[0] + u * self.c - v * self.s, self.W[1] + u * self.s + v * self.c)

    def dot(self, q: tuple[Any, Any]) -> Any:
        return self.n[0] * q[0] + self.n[1] * q[1]

    def in_frame(self, u: Any, v: Any) -> Any:
        """K + a u + b v: n . (W + R(phi)(u, v)) with n read in the forearm's frame."""
        return self.K + self.a * u + self.b * v

    def defs(self) -> tuple[tuple[str, z3.BoolRef], ...]:
        n = self.n
        return (("a = n . R(phi)(1, 0), b = n . R(phi)(0, 1): n in the forearm's frame",
                 z3.And(self.a == n[0] * self.c + n[1] * self.s,
                        self.b == n[1] * self.c - n[0] * self.s)),
                ("K = n . W", self.K == self.dot(self.W)))

    def grown_point(self) -> tuple[Any, Any]:
        """x = W + R(phi)(p + e): a point of the tool grown by the square."""
        return self.at(self.p[0] + self.e[0], self.p[1] + self.e[1])

    def premises(self) -> tuple[tuple[str, z3.BoolRef], ...]:
        g, e = self.grow, self.e
        return (("grow >= 0", g >= 0),
                ("the weights of p are >= 0 and sum to 1 (p a point of the polygon)",
                 z3.And(*[wi >= 0 for wi in self.w], sum(self.w) == 1)),
                ("e in the square [-grow, grow]^2 of the forearm's frame",
                 z3.And(-g <= e[0], e[0] <= g, -g <= e[1], e[1] <= g)))


def _points_vc(tool_points: Any) -> VC:
    """Each model point (a vertex moved by a corner of the square, placed at (t1, t2)) is one of
    the points ``_tool_points`` makes, run on terms (named G1, G2, ...)."""
    T = _Tool()
    G = tool_points_on_terms(T.arm, T.t1, T.t2, T.grow, tool_points)
    names = [(z3.Real(f"G{k + 1}.x"), z3.Real(f"G{k + 1}.y")) for k in range(len(G))]
    key = "G = spec._exact._tool_points(arm, t1, t2, grow) run on terms (its points G1, G2, ...)"
    # Which of the code's points each model point is, found at random values (the choice only
    # names the point the goal compares with; the identity is Z3's to prove).
    rnd = random.Random(0)
    env = {str(v): rnd.uniform(0.1, 1.0) for v in (*T.arm.base, *T.arm.links, T.t1, T.t2, T.grow,
                                                  *[c for q in T.verts for c in q])}
    goal = []
    at_g: list[tuple[float, float]] | None = None
    for u, v in T.frame:
        want = T.at(u, v)
        m = (_value(want[0], env), _value(want[1], env))
        if at_g is None:
            # The code's points' values, once: read where the search first reads them (after
            # the first model point, G1 first), since a symbol's value is set by the order in
            # which symbols are first read; env only grows, so they never change after.
            at_g = [(_value(x, env), _value(y, env)) for x, y in G]
        at = at_g
        k = min(range(len(G)), key=lambda i: abs(at[i][0] - m[0]) + abs(at[i][1] - m[1]))
        goal.append(z3.And(want[0] == names[k][0], want[1] == names[k][1]))
    hyps = ((key, z3.And(*[z3.And(n[0] == g[0], n[1] == g[1]) for n, g in zip(names, G)])),)
    return VC("tool_points", hyps, z3.And(*goal), key_premise=key)


def _value(term: Any, env: dict[str, float]) -> float:
    """``term`` at the values ``env`` gives its symbols (a symbol not in it gets one)."""
    if z3.is_rational_value(term):
        return float(term.as_fraction())
    if z3.is_const(term):
        return env.setdefault(str(term), 0.1 + 0.9 * ((len(env) * 0.6180339887) % 1.0))
    args = [_value(x, env) for x in term.children()]
    k = term.decl().kind()
    if k == z3.Z3_OP_ADD:
        return sum(args)
    if k == z3.Z3_OP_SUB:
        return args[0] - sum(args[1:])
    if k == z3.Z3_OP_MUL:
        return math.prod(args)
    if k == z3.Z3_OP_UMINUS:
        return -args[0]
    raise ValueError(f"no value for {term}")


def _frame_vc() -> VC:
    """n . (W + R(phi)(u, v)) = K + a u + b v at each model point and at x = W + R(phi)(p + e)."""
    T = _Tool()
    key = T.defs()[0][0]
    pts = [*T.frame, (T.p[0] + T.e[0], T.p[1] + T.e[1])]
    goal = z3.And(*[T.dot(T.at(u, v)) == T.in_frame(u, v) for u, v in pts])
    return VC("tool_frame", T.defs(), goal, key_premise=key)


def _max_vc(side: str, tool_points: Any) -> VC:
    """``projection_bounds``' end over the tool's points (as many as ``_tool_points`` makes) is
    at or above (A) / below (B) the projection P_k = n . G_k of each. The reduction is the
    code's, run on the projections (direction (1, 0), point k at (P_k, 0)): the products n . G_k
    are bounds_A/bounds_B's, and a max over products is past Z3's non-linear arithmetic."""
    T = _Tool()
    G = tool_points_on_terms(T.arm, T.t1, T.t2, T.grow, tool_points)
    proj = [(z3.Real(f"P{k + 1}"), z3.RealVal(0)) for k in range(len(G))]
    other = [(z3.Real("o.x"), z3.Real("o.y"))]
    one, zero = z3.RealVal(1), z3.RealVal(0)
    hi_a, lo_b = (spec.projection_bounds(one, zero, proj, other) if side == "A"
                  else spec.projection_bounds(one, zero, other, proj))
    end = z3.Real("end")
    which = "upper end over A" if side == "A" else "lower end over B"
    key = (f"end = spec.projection_bounds' {which}, on the projections P1, P2, ... of the "
           f"{len(G)} points of spec._exact._tool_points (VC tool_points) on that side")
    goal = z3.And(*[(end >= q) if side == "A" else (end <= q) for q, _ in proj])
    return VC(f"tool_max_{side}", ((key, end == (hi_a if side == "A" else lo_b)),), goal,
              key_premise=key)


def _hull_vc(side: str) -> VC:
    """With end at or above (A) / below (B) n . M for every model point M (tool_max, tool_points
    and tool_frame by substitution), n . x is too, x = W + R(phi)(p + e) any point of the grown
    tool (tool_frame: n . x = K + a (p + e)_u + b (p + e)_v)."""
    T = _Tool()
    end = z3.Real("end")
    bound = [T.in_frame(u, v) for u, v in T.frame]
    key = ("end " + (">=" if side == "A" else "<=") + " K + a U + b V at every model point "
           "(tool_max, tool_points, tool_frame)")
    x = T.in_frame(T.p[0] + T.e[0], T.p[1] + T.e[1])
    hyps = ((key, z3.And(*[(end >= q) if side == "A" else (end <= q) for q in bound])),
            *T.premises())
    return VC(f"tool_hull_{side}", hyps, x <= end if side == "A" else x >= end,
              key_premise=key)


def polygon_gap_vcs(tool_points: Any = None) -> tuple[VC, ...]:
    """The polygon VCs of Exact.gap_formula (``tool_points`` default the spec's)."""
    return (_points_vc(tool_points), _frame_vc(), _max_vc("A", tool_points),
            _max_vc("B", tool_points), _hull_vc("A"), _hull_vc("B"))
