"""The constants the certificate, the tolerance tube and the ball-arithmetic gaps rest on, each
proved as the code computes it (docs/model.md §2, §7.2, §12).

Every formula here is the spec's own function run on Z3 terms, never re-written: ``spec.reach``
(the links' reach R_base, R_elbow), ``spec.link_speeds`` (a link point's speed bound),
``spec.pair_lipschitz`` (L_ab = v_a + v_b), ``spec.interval_bound`` (the certificate's bound
on an interval), ``spec.tube_lipschitz`` (its bytecode, with Python's ``max`` taken as
``spec.max_of``), the factor and the loop guard of ``spec.tolerance_rad`` (read off its syntax
tree, evaluated on terms), and ``spec.projection_bounds`` / ``spec.gap_over_norm`` (the
separating-axis gap of the exact re-decision). The functions are looked up in ``cfmpa.spec`` when
an obligation is built, so a changed constant changes the proved statement and a weakened one is
refuted. A square root the code takes (``hypot_of``, ``sqrt_of``: Z3's ``x ** (1/2)``) becomes a
real s with s >= 0 and s^2 = x, its exact meaning, so every VC is polynomial and standard
SMT-LIB. Lengths are reals n >= 0 with n^2 = |v|^2, as in Tolerance.tube.

Three obligations (registered by the proofs' registry, not by this module):

- ``Certificate.lipschitz``: every point of a link's rectangle is within R_base of the base and
  R_elbow of the elbow; its velocity is the sum over the joints that move it of w_j J(p -
  joint_j); so its speed is at most ``link_speeds``; the distance between two links then changes
  by at most ``pair_lipschitz`` per second, and on an interval the distance is at least
  ``interval_bound``.
- ``Tolerance.tube_factor``: what ``tolerance_rad`` returns is >= 0 and satisfies c > 2 L delta,
  the premise of Tolerance.tube, with its own factor (``two_l``), start and loop guard; and a
  joint deviation of at most delta moves any link point by at most L delta with L =
  ``tube_lipschitz``. Tolerance.tube
  states c > 2 L delta and "L the largest R_base + R_elbow" by hand and reads neither; this
  obligation is what joins it to the code.
- ``Exact.gap_formula``: ``projection_bounds`` bounds n.x over the hull of A from above and n.y
  over the hull of B from below, and ``gap_over_norm`` = (lo_b - hi_a) / |n| is then at most
  |y - x| for every x of hull A and y of hull B.
"""

from __future__ import annotations

import ast
import builtins
import functools
import inspect
import textwrap
import types
from collections.abc import Callable
from dataclasses import dataclass
from typing import Any, cast

import numpy as np
import z3

from .. import spec
from ._obl_groups import GROUP_CERTIFICATE, GROUP_EXACT, GROUP_TUBE
from ._obligation import VC, Method, Obligation, Verdict, Z3Query
from ._onterms import ExtractionError, sqrt_free
from ._onterms import term as _term
from ._z3vec import Hyp
from ._z3vec import add as _add
from ._z3vec import dot as _dot
from ._z3vec import j as _j
from ._z3vec import norm as _norm
from ._z3vec import scale as _scale
from ._z3vec import sub as _sub
from ._z3vec import unit_poly as _unit
from ._z3vec import vec as _vec
from ._z3vec import veq as _eq
from ._z3vec import within as _within

__all__ = ["GROUP_CERTIFICATE", "GROUP_EXACT", "GROUP_TUBE",
           "ExtractionError", "ToleranceParts", "certificate_vcs", "constants_obligations",
           "exact_vcs", "on_terms", "sqrt_free", "tolerance_parts", "tube_factor_vcs"]


# --- small helpers ------------------------------------------------------------------------------

@dataclass(frozen=True)
class _SymArm:
    """An arm of symbolic dimensions: what ``reach`` and ``link_speeds`` read of an Arm."""

    links: tuple[z3.ArithRef, z3.ArithRef]
    width: z3.ArithRef


@dataclass(frozen=True)
class _SymScenario:
    """What ``tube_lipschitz`` reads of a Scenario: both arms."""

    left: _SymArm
    right: _SymArm


def _arm(prefix: str = "") -> tuple[_SymArm, list[Hyp]]:
    """An arm with links ``<prefix>l1``, ``<prefix>l2`` and width ``<prefix>w``, all > 0."""
    l1, l2, w = (z3.Real(prefix + x) for x in ("l1", "l2", "w"))
    return _SymArm((l1, l2), w), [(f"the {prefix}arm's links and width are positive "
                                   f"({prefix}l1, {prefix}l2, {prefix}w > 0)",
                                   z3.And(l1 > 0, l2 > 0, w > 0))]


# --- Certificate.lipschitz ----------------------------------------------------------------------

def _rectangle(arm: _SymArm, link: int, a: z3.ArithRef, b: z3.ArithRef) -> Hyp:
    """The point joint_link + a u + b J u lies on link ``link``'s rectangle (docs/model.md §2):
    width w around the segment, extended by w/2 past both ends."""
    half = arm.width / 2
    return (f"p lies on link {link + 1}'s rectangle: -w/2 <= a <= l{link + 1} + w/2, |b| <= w/2",
            z3.And(-half <= a, a <= arm.links[link] + half, _within(b, half)))


def _reach_vc(link: int, of: str) -> VC:
    """Link ``link``'s points are within R_base of the base (``of`` "base") or R_elbow of the
    elbow (``of`` "elbow"), (R_base, R_elbow) = ``spec.reach`` on the terms."""
    arm, hyps = _arm()
    a, b = z3.Reals("a b")
    u1, u2 = _vec("u1"), _vec("u2")
    base = (z3.RealVal(0), z3.RealVal(0))
    elbow = _scale(arm.links[0], u1)
    rb, re_ = spec.reach(cast(Any, arm), link)     # a _SymArm: the fields reach reads
    (rb, re_), roots = sqrt_free([_term(rb), _term(re_)])
    nb, ne, nl = z3.Reals("|p-base| |p-elbow| |elbow-base|")
    one, zero = z3.RealVal(1), z3.RealVal(0)
    pins: list[tuple[z3.ExprRef, z3.ExprRef]] = [
        (arm.links[0], one), (arm.links[1], one), (arm.width, z3.RealVal("1/10")),
        (u1[0], one), (u1[1], zero), (u2[0], one), (u2[1], zero), (a, zero), (b, zero)]
    if link == 0:
        # The base at the origin, link 1 along u1: p = a u1 + b J u1.
        key = _rectangle(arm, 0, a, b)
        p = _add(_scale(a, u1), _scale(b, _j(u1)))
        hyps += [("u1 = (cos theta1, sin theta1) is a unit vector", _unit(u1)), key,
                 ("|p - base| is its length", _norm(nb, _sub(p, base)))] + roots
        return VC("reach_link1", tuple(hyps), nb <= rb, key_premise=key[0], witness=tuple(pins))
    if of == "elbow":
        # Link 2 from the elbow along u2: p - elbow = a u2 + b J u2.
        key = _rectangle(arm, 1, a, b)
        d = _add(_scale(a, u2), _scale(b, _j(u2)))
        hyps += [("u2 = (cos(theta1 + theta2), sin(theta1 + theta2)) is a unit vector",
                  _unit(u2)), key, ("|p - elbow| is its length", _norm(ne, d))] + roots
        return VC("reach_link2_elbow", tuple(hyps), ne <= re_, key_premise=key[0],
                  witness=tuple(pins))
    p = _vec("p")
    key2 = ("|p - elbow| <= R_elbow (VC reach_link2_elbow)", ne <= re_)
    hyps += [("u1 = (cos theta1, sin theta1) is a unit vector", _unit(u1)),
             ("|p - base| is its length", _norm(nb, _sub(p, base))),
             ("|p - elbow| is its length", _norm(ne, _sub(p, elbow))),
             ("|elbow - base| is its length, elbow = base + l1 u1", _norm(nl, _sub(elbow, base))),
             key2,
             ("triangle inequality at p, elbow, base: |p - base| <= |p - elbow| + "
              "|elbow - base| (Tolerance.tube's triangle VC)", nb <= ne + nl)] + roots
    return VC("reach_link2_base", tuple(hyps), nb <= rb, key_premise=key2[0],
              witness=tuple(pins[:5]) + ((p[0], one), (p[1], zero)))


def _velocity_vc() -> VC:
    """The velocity of a point fixed on a link is the sum over the joints that move it of
    w_j J(p - joint_j): the term-by-term time derivative of its position equals that sum."""
    l1, a1, b1, a2, b2, w1, w2 = z3.Reals("l1 a1 b1 a2 b2 w1 w2")
    u1, u2 = _vec("u1"), _vec("u2")
    p1, p2, v1, v2 = _vec("p1"), _vec("p2"), _vec("v1"), _vec("v2")
    elbow = _scale(l1, u1)
    key = "p2 = base + l1 u1 + a2 u2 + b2 J u2 (a point fixed on link 2, base at the origin)"
    return VC("velocity", (
        ("p1 = base + a1 u1 + b1 J u1 (a point fixed on link 1, base at the origin)",
         _eq(p1, _add(_scale(a1, u1), _scale(b1, _j(u1))))),
        (key, _eq(p2, _add(elbow, _add(_scale(a2, u2), _scale(b2, _j(u2)))))),
        ("v1 = d p1 / dt term by term, with d u(phi) / dt = phi' J u(phi), theta1' = w1",
         _eq(v1, _scale(w1, _add(_scale(a1, _j(u1)), _scale(b1, _j(_j(u1))))))),
        ("v2 = d p2 / dt term by term, theta1' = w1, (theta1 + theta2)' = w1 + w2",
         _eq(v2, _add(_scale(w1 * l1, _j(u1)),
                      _scale(w1 + w2, _add(_scale(a2, _j(u2)), _scale(b2, _j(_j(u2)))))))),
    ), z3.And(_eq(v1, _scale(w1, _j(p1))),
              _eq(v2, _add(_scale(w1, _j(p2)), _scale(w2, _j(_sub(p2, elbow)))))),
        key_premise=key,
        witness=tuple((x, z3.RealVal(0)) for x in (l1, a1, b1, a2, b2, w1, w2, *u1, *u2)))


def _speed_vc(link: int) -> VC:
    """A link point's speed is at most ``spec.link_speeds`` (run on an object array of terms)."""
    arm, hyps = _arm()
    w1, w2 = z3.Reals("w1 w2")
    p, elbow = _vec("p"), _vec("elbow")
    base = (z3.RealVal(0), z3.RealVal(0))
    rb, re_ = spec.reach(cast(Any, arm), link)     # a _SymArm: the fields they read
    bound = spec.link_speeds(cast(Any, arm), np.array([[w1, w2]], dtype=object))[0, link]
    (rb, re_, bound), roots = sqrt_free([_term(rb), _term(re_), _term(bound)])
    nb, ne, nv = z3.Reals("|p-base| |p-elbow| |v|")
    if link == 0:
        v = _scale(w1, _j(_sub(p, base)))
        how = "v = w1 J(p - base): joint 1 alone moves link 1 (VC velocity)"
    else:
        v = _add(_scale(w1, _j(_sub(p, base))), _scale(w2, _j(_sub(p, elbow))))
        how = "v = w1 J(p - base) + w2 J(p - elbow): both joints move link 2 (VC velocity)"
    key = "|p - base| <= R_base (VC reach)"
    hyps += [("|p - base| is its length", _norm(nb, _sub(p, base))), (key, nb <= rb),
             (f"|v| is the length of the velocity, {how}", _norm(nv, v))] + roots
    if link == 1:
        hyps += [("|p - elbow| is its length", _norm(ne, _sub(p, elbow))),
                 ("|p - elbow| <= R_elbow (VC reach)", ne <= re_)]
    zero = z3.RealVal(0)
    return VC(f"speed_link{link + 1}", tuple(hyps), nv <= bound, key_premise=key,
              witness=((arm.links[0], z3.RealVal(1)), (arm.links[1], z3.RealVal(1)),
                       (arm.width, z3.RealVal("1/10")), (w1, zero), (w2, zero), (p[0], zero),
                       (p[1], zero), (elbow[0], zero), (elbow[1], zero)))


def _distance_rate_vc() -> VC:
    """The distance between a left and a right link changes by at most ``pair_lipschitz(v_a,
    v_b)`` h over a time h: nearest points move by at most v h each."""
    p, q, pp, qp = _vec("p"), _vec("q"), _vec("p'"), _vec("q'")
    va, vb, h, d0, d1 = z3.Reals("v_a v_b h d(t) d(t+h)")
    n_pq, n_pp, n_qq, n_ppq, n_ppqp = z3.Reals("|p-q| |p-p'| |q-q'| |p'-q| |p'-q'|")
    lip = _term(spec.pair_lipschitz(va, vb))
    key = "|p - p'| <= v_a h (link a's speed bound integrated over [t, t + h])"
    return VC("distance_rate", (
        ("h >= 0 and the speed bounds v_a, v_b >= 0", z3.And(h >= 0, va >= 0, vb >= 0)),
        ("|p - q| is its length", _norm(n_pq, _sub(p, q))),
        ("|p - p'| is its length", _norm(n_pp, _sub(p, pp))),
        ("|q - q'| is its length", _norm(n_qq, _sub(q, qp))),
        ("|p' - q| is its length", _norm(n_ppq, _sub(pp, q))),
        ("|p' - q'| is its length", _norm(n_ppqp, _sub(pp, qp))),
        ("p of link a and q of link b are nearest at t: d(t) = |p - q|", d0 == n_pq),
        ("d(t + h) <= |p' - q'|: p', q' (where p, q are at t + h) lie on the links then",
         d1 <= n_ppqp),
        (key, n_pp <= va * h),
        ("|q - q'| <= v_b h (link b's speed bound integrated over [t, t + h])", n_qq <= vb * h),
        ("triangle at p', p, q", n_ppq <= n_pp + n_pq),
        ("triangle at p', q, q'", n_ppqp <= n_ppq + n_qq),
    ), d1 <= d0 + lip * h, key_premise=key,
        witness=tuple((x, z3.RealVal(0)) for x in (*p, *q, *pp, *qp, va, vb, h)))


def _interval_vc() -> VC:
    """On [t0, t1], a distance changing by at most L per second is at least ``interval_bound``."""
    t0, t, t1, lip, d0, dt, d1 = z3.Reals("t0 t t1 L d(t0) d(t) d(t1)")
    bound = _term(spec.interval_bound(d0, d1, lip, t1 - t0))
    key = "d(t) >= d(t0) - L (t - t0) (VC distance_rate from t back to t0, time reversed)"
    return VC("interval", (
        ("t0 <= t <= t1", z3.And(t0 <= t, t <= t1)),
        ("L >= 0", lip >= 0),
        (key, dt >= d0 - lip * (t - t0)),
        ("d(t) >= d(t1) - L (t1 - t) (VC distance_rate from t to t1)",
         dt >= d1 - lip * (t1 - t)),
    ), dt >= bound, key_premise=key,
        witness=tuple((x, z3.RealVal(0)) for x in (t0, t, lip, d0, dt, d1)) + (
            (t1, z3.RealVal(1)),))


def certificate_vcs() -> tuple[VC, ...]:
    """Certificate.lipschitz's VCs, from the spec's functions as they are now; then the tool's
    (its reach and speed, proofs/_obl_tools.py)."""
    from ._obl_tools import tool_certificate_vcs
    return (_reach_vc(0, "base"), _reach_vc(1, "elbow"), _reach_vc(1, "base"), _velocity_vc(),
            _speed_vc(0), _speed_vc(1), _distance_rate_vc(), _interval_vc(),
            *tool_certificate_vcs())


# --- Tolerance.tube_factor ----------------------------------------------------------------------

def _max_terms(*args: Any) -> Any:
    """Python's ``max`` (of an iterable, or of arguments) folded with ``spec.max_of``: the same
    value on floats (the first of equal maxima), an If on terms."""
    items = list(args[0]) if len(args) == 1 else list(args)
    return functools.reduce(spec.max_of, items)


def on_terms(f: Callable[..., Any]) -> Callable[..., Any]:
    """``f``'s own bytecode with Python's builtin ``max`` taken as ``_max_terms`` (``f`` runs on
    Z3 terms then; everything else it reads is its module's)."""
    g = dict(f.__globals__)
    g["max"] = _max_terms
    return types.FunctionType(f.__code__, g, f.__name__, f.__defaults__, f.__closure__)


@dataclass(frozen=True)
class _SymCertificate:
    """What ``tolerance_rad`` reads of a Certificate: clear and the proved clearance."""

    clear: z3.BoolRef
    lower_bound_m: z3.ArithRef


def _as_bool(x: Any) -> z3.BoolRef:
    return x if isinstance(x, z3.BoolRef) else z3.BoolVal(bool(x))


def _eval(node: ast.AST, env: dict[str, Any], glb: dict[str, Any]) -> Any:
    """A Python expression of the subset ``tolerance_rad`` is written in, on terms: names (env,
    then the function's module, then builtins), attributes, calls, + - * /, comparisons, not,
    and, or; anything else is refused."""
    ev = functools.partial(_eval, env=env, glb=glb)
    if isinstance(node, ast.Constant):
        return node.value
    if isinstance(node, ast.Name):
        for scope in (env, glb, vars(builtins)):
            if node.id in scope:
                return scope[node.id]
        raise ExtractionError(f"line {node.lineno}: unknown name {node.id!r}")
    if isinstance(node, ast.Attribute):
        return getattr(ev(node.value), node.attr)
    if isinstance(node, ast.Call) and not node.keywords:
        return ev(node.func)(*[ev(a) for a in node.args])
    if isinstance(node, ast.BinOp):
        x, y = ev(node.left), ev(node.right)
        ops = {ast.Add: lambda: x + y, ast.Sub: lambda: x - y, ast.Mult: lambda: x * y,
               ast.Div: lambda: x / y}
        if type(node.op) in ops:
            return ops[type(node.op)]()
    if isinstance(node, ast.UnaryOp):
        x = ev(node.operand)
        if isinstance(node.op, ast.Not):
            return z3.Not(x) if isinstance(x, z3.ExprRef) else not x
        if isinstance(node.op, ast.USub):
            return -x
    if isinstance(node, ast.BoolOp):
        vals = [_as_bool(ev(v)) for v in node.values]
        return z3.And(*vals) if isinstance(node.op, ast.And) else z3.Or(*vals)
    if isinstance(node, ast.Compare) and len(node.ops) == 1:
        x, y = ev(node.left), ev(node.comparators[0])
        cmps: dict[type[ast.cmpop], Callable[[], Any]] = {
            ast.Lt: lambda: x < y, ast.LtE: lambda: x <= y, ast.Gt: lambda: x > y,
            ast.GtE: lambda: x >= y}
        if type(node.ops[0]) in cmps:
            return cmps[type(node.ops[0])]()
    raise ExtractionError(f"line {getattr(node, 'lineno', '?')}: {ast.dump(node)[:80]} is "
                          "outside the subset")


@dataclass(frozen=True)
class ToleranceParts:
    """What ``tolerance_rad`` says, on terms: when it returns 0 at once (``early``), its factor
    (``two_l``), the guard of its loop (``guard``: k is lowered by 1 while it holds), its result
    after the loop (``result``) and k before it (``start``)."""

    early: z3.BoolRef
    two_l: z3.ArithRef
    guard: z3.BoolRef
    result: z3.ArithRef
    #: k's value before the loop (an integer term: ``math.floor`` is ``spec.floor_of``).
    start: z3.ArithRef


def tolerance_parts(f: Callable[..., Any], env: dict[str, Any]) -> ToleranceParts:
    """Read ``f`` (``spec.tolerance_rad``) off its syntax tree: an early ``if ...: return 0.0``,
    the assignments (``two_l``, ``per``, and ``k``'s start, ``math.floor`` taken as
    ``spec.floor_of``), the ``while`` guard (its body must be ``k -= 1``) and the final
    ``return``, all evaluated with ``env`` (``k`` in it is k at the loop's end)."""
    tree = ast.parse(textwrap.dedent(inspect.getsource(f)))
    fn = tree.body[0]
    if not isinstance(fn, ast.FunctionDef):
        raise ExtractionError(f"{f.__name__} is not a plain function")
    glb = f.__globals__
    env = {"math": types.SimpleNamespace(floor=spec.floor_of, ceil=spec.ceil_of), **env}
    early = guard = result = start = None
    for st in fn.body:
        if isinstance(st, ast.Expr) and isinstance(st.value, ast.Constant):
            continue                                            # the docstring
        if (isinstance(st, ast.If) and not st.orelse and len(st.body) == 1
                and isinstance(st.body[0], ast.Return) and early is None):
            if _eval(st.body[0].value, env, glb) != 0.0:       # type: ignore[arg-type]
                raise ExtractionError(f"line {st.lineno}: the early return is not 0.0")
            early = _as_bool(_eval(st.test, env, glb))
        elif (isinstance(st, ast.Assign) and len(st.targets) == 1
              and isinstance(st.targets[0], ast.Name)):
            name = st.targets[0].id
            if name == "k":                     # env's k is k at the loop's end
                start = _eval(st.value, env, glb)
            else:
                env[name] = _eval(st.value, env, glb)
        elif isinstance(st, ast.While) and guard is None:
            body = st.body[0] if len(st.body) == 1 and not st.orelse else None
            if not (isinstance(body, ast.AugAssign) and isinstance(body.op, ast.Sub)
                    and isinstance(body.target, ast.Name) and body.target.id == "k"
                    and isinstance(body.value, ast.Constant) and body.value.value == 1):
                raise ExtractionError(f"line {st.lineno}: the loop's body is not k -= 1")
            guard = _as_bool(_eval(st.test, env, glb))
        elif isinstance(st, ast.Return) and result is None and st.value is not None:
            result = _term(_eval(st.value, env, glb))
        else:
            raise ExtractionError(f"line {st.lineno}: a statement outside the subset")
    if early is None or guard is None or result is None or start is None or "two_l" not in env:
        raise ExtractionError(f"{f.__name__}: no early return, two_l, k, loop or result found")
    return ToleranceParts(early, _term(env["two_l"]), guard, result, start)


def _factor_vc() -> VC:
    """What ``tolerance_rad`` returns is >= 0 and satisfies Tolerance.tube's premise
    c > 2 L delta."""
    c, lip, k, delta = z3.Reals("c L k delta")
    clear = z3.Bool("clear")
    sym = object()
    parts = tolerance_parts(spec.tolerance_rad, {
        "s": sym, "cert": _SymCertificate(clear, c), "k": k,
        # L is read in the VC lipschitz; here it is any L > 0 the code computes.
        "tube_lipschitz": lambda s: lip if s is sym else spec.tube_lipschitz(s)})
    guard = "the loop has ended: its guard is false (tolerance_rad's while)"
    # The loop only corrects float rounding: over the reals k0 itself meets the goal, so the key
    # is where k ends up, not the guard.
    key = ("the loop lowers k by 1 only while k > 0, from its start k0: k <= k0, and k >= 0 "
           "when k0 >= 0")
    # k0 a named integer: its declaration puts the query in a logic with to_int (standard
    # SMT-LIB; without an Int symbol _smtlib's logic was QF_NRA, which cvc5 refused).
    k0 = z3.Int("k0") if z3.is_int(parts.start) else z3.Real("k0")
    return VC("factor", (
        ("L = tube_lipschitz(s) > 0 (VC lipschitz: at least a sum of positive lengths)",
         lip > 0),
        ("the certificate is clear and c > EPS: tolerance_rad's early return is not taken",
         z3.Not(parts.early)),
        ("k0 is k before the loop (tolerance_rad's assignment)", k0 == parts.start),
        (key, z3.And(k <= z3.ToReal(k0) if z3.is_int(k0) else k <= k0,
                     z3.Implies(k0 >= 0, k >= 0))),
        (guard, z3.Not(parts.guard)),
        ("delta is what tolerance_rad returns after its loop", delta == parts.result),
    ), z3.And(delta >= 0, c > 2 * lip * delta), key_premise=key,
        witness=((c, z3.RealVal(1)), (lip, z3.RealVal(1)), (k, z3.RealVal(0)),
                 (clear, z3.BoolVal(True))))


def _lipschitz_vc() -> VC:
    """L = ``spec.tube_lipschitz`` (its bytecode on terms) is at least R_base + R_elbow of every
    link of either arm, each from ``spec.reach``."""
    left, hl = _arm("left.")
    right, hr = _arm("right.")
    lip = z3.Real("L")
    terms = [_term(on_terms(spec.tube_lipschitz)(_SymScenario(left, right)))]
    names = []
    for side, arm in (("left", left), ("right", right)):
        for link in (0, 1):
            terms += [_term(x) for x in spec.reach(cast(Any, arm), link)]
            names.append(f"{side} link {link + 1}")
    # The roots' meaning (s >= 0, s^2 = x) is not needed: L bounds the four sums whatever the
    # roots are, and without it the VC is linear (with it, nlsat ran out of its 20 s).
    free, _ = sqrt_free(terms)
    key = "L = tube_lipschitz(s)"
    goal = z3.And(*[free[1 + 2 * n] + free[2 + 2 * n] <= lip for n in range(len(names))])
    return VC("lipschitz", tuple(hl + hr + [(key, lip == free[0])]), goal,
              key_premise=key,
              witness=tuple((x, z3.RealVal(1)) for x in (*left.links, *right.links))
              + ((left.width, z3.RealVal("1/10")), (right.width, z3.RealVal("1/10"))))


def _deviation_vc() -> VC:
    """A joint deviation of at most delta moves a point of a link with R_base + R_elbow <= L by
    at most L delta."""
    delta, lip, d1, d2, rb, re_, move = z3.Reals("delta L |dtheta1| |dtheta2| R_base R_elbow "
                                                  "move")
    key = "|dtheta1| <= delta and |dtheta2| <= delta (the max-norm joint deviation)"
    return VC("deviation", (
        ("R_base, R_elbow >= 0 (lengths) and R_base + R_elbow <= L (VC lipschitz)",
         z3.And(rb >= 0, re_ >= 0, rb + re_ <= lip)),
        ("|dtheta1|, |dtheta2| >= 0", z3.And(d1 >= 0, d2 >= 0)),
        (key, z3.And(d1 <= delta, d2 <= delta)),
        ("a point of the link moves by at most |dtheta1| R_base + |dtheta2| R_elbow (the "
         "speed bound of Certificate.lipschitz integrated along the joint-space segment; prose)",
         move <= d1 * rb + d2 * re_),
    ), move <= lip * delta, key_premise=key,
        witness=tuple((x, z3.RealVal(0)) for x in (delta, lip, d1, d2, rb, re_, move)))


def tube_factor_vcs() -> tuple[VC, ...]:
    """Tolerance.tube_factor's VCs, from the spec's functions as they are now; lipschitz_tool
    with a tool on each arm (proofs/_obl_tools.py)."""
    from ._obl_tools import tube_tool_vc
    return (_factor_vc(), _lipschitz_vc(), _deviation_vc(), tube_tool_vc())


# --- Exact.gap_formula --------------------------------------------------------------------------

#: Corners per hull in VC bounds: in the plane a point of a hull is a combination of three.
_CORNERS = 3


def _bounds_vc(side: str) -> VC:
    """``projection_bounds`` bounds n.x over the hull of A's points from above (``side`` "A")
    or n.y over the hull of B's from below (``side`` "B"); one side per VC keeps each small."""
    n = _vec("n")
    a = [_vec(f"a{i + 1}") for i in range(_CORNERS)]
    b = [_vec(f"b{i + 1}") for i in range(_CORNERS)]
    hi_a, lo_b = spec.projection_bounds(n[0], n[1], a, b)
    z = _vec("x" if side == "A" else "y")
    w = z3.Reals(" ".join(f"{'lambda' if side == 'A' else 'mu'}{i + 1}" for i in range(_CORNERS)))
    pts = a if side == "A" else b
    end = z3.Real("hi_a" if side == "A" else "lo_b")
    key = ("hi_a = projection_bounds' upper end over A" if side == "A"
           else "lo_b = projection_bounds' lower end over B")
    comb = functools.reduce(_add, (_scale(wi, pi) for wi, pi in zip(w, pts)))
    what = "x (a point of hull A)" if side == "A" else "y (a point of hull B)"
    goal = _dot(n, z) <= end if side == "A" else _dot(n, z) >= end
    return VC(f"bounds_{side}", (
        (key, end == (hi_a if side == "A" else lo_b)),
        (f"the weights of {what} are >= 0 and sum to 1",
         z3.And(*[wi >= 0 for wi in w], sum(w) == 1)),
        (f"{what} is their combination of the corners", _eq(z, comb)),
    ), goal, key_premise=key,
        witness=tuple((v, z3.RealVal(0)) for v in (*n, *z))
        + tuple((v, z3.RealVal(0)) for p in pts for v in p) + ((w[0], z3.RealVal(1)),))


def _gap_vc() -> VC:
    """With n.x <= hi_a and n.y >= lo_b, |y - x| >= ``gap_over_norm(hi_a, lo_b, n)``."""
    n, x, y = _vec("n"), _vec("x"), _vec("y")
    hi, lo, dist = z3.Reals("hi_a lo_b |y-x|")
    (gap,), roots = sqrt_free([_term(spec.gap_over_norm(hi, lo, n[0], n[1]))])
    key = "n.y >= lo_b (VC bounds)"
    return VC("gap", (
        ("n != 0 (the code returns 0 before, when the float hulls meet)",
         z3.Or(n[0] != 0, n[1] != 0)),
        ("n.x <= hi_a (VC bounds)", _dot(n, x) <= hi),
        (key, _dot(n, y) >= lo),
        ("|y - x| is its length", _norm(dist, _sub(y, x))),
        *roots,
    ), dist >= gap, key_premise=key,
        witness=((n[0], z3.RealVal(1)), (n[1], z3.RealVal(0)), (x[0], z3.RealVal(0)),
                 (x[1], z3.RealVal(0)), (y[0], z3.RealVal(1)), (y[1], z3.RealVal(0)),
                 (hi, z3.RealVal(0)), (lo, z3.RealVal(1))))


def exact_vcs() -> tuple[VC, ...]:
    """Exact.gap_formula's VCs, from the spec's functions as they are now; a tool's polygon on
    either side of a pair (proofs/_obl_exact_polygon.py)."""
    from ._obl_exact_polygon import polygon_gap_vcs
    return (_bounds_vc("A"), _bounds_vc("B"), _gap_vc(), *polygon_gap_vcs())


# --- the obligations ----------------------------------------------------------------------------

def constants_obligations() -> list[Obligation]:
    """Certificate.lipschitz, Tolerance.tube_factor and Exact.gap_formula."""
    return [
        Obligation(
            "Certificate.lipschitz", GROUP_CERTIFICATE, "docs/model.md §2, §7.2 (the bound)",
            "The certificate's Lipschitz bound as the code computes it: every point of a link's "
            "rectangle (width w, extended by w/2 past both joints) is within R_base of the base "
            "and R_elbow of the elbow, (R_base, R_elbow) = spec.reach on the arm's symbolic "
            "dimensions; a point fixed on a link moves with velocity sum_j w_j J(p - joint_j) "
            "over the joints that move it (its position's derivative term by term); so its speed "
            "is at most spec.link_speeds; two links' distance changes by at most "
            "spec.pair_lipschitz(v_a, v_b) h over a time h (either way: reversed time has the same "
            "bounds); and on [t0, t1] it is at least "
            "spec.interval_bound(d0, d1, L, t1 - t0). A tool (a convex polygon of 16 symbolic "
            "vertices fixed to link 2; fewer: a vertex repeated): every point, a chain of two-point "
            "convex combinations of its vertices, is within R_elbow of the elbow and R_base of the "
            "base, (R_base, R_elbow) = spec.reach(arm, TOOL) run on terms (its max as an If, its "
            "farthest vertex: tool_far_vertex, tool_reach_frame, reach_point, reach_tool, with "
            "hull_step from comb_id), and moves at most spec.link_speeds(arm, w)[0, TOOL] "
            "(speed_term, speed_tool; rot_norm, kin, square_monotone and triangle as proved in "
            "Safety.region_soundness). Named, not checked: the triangle "
            "inequality at the instances used (proved in Tolerance.tube); that a speed bound v "
            "gives a move of at most v h (integration); that nearest points exist. That the "
            "joint speeds handed to link_speeds for a piece bound the motion's on it: "
            "Certificate.wiring.",
            Method.Z3, Verdict.PROVED, lambda: Z3Query(certificate_vcs()),
            label="speed integrated in prose",
            summary=("The speed bound the motion certificate uses is safe as computed: no point of "
                     "a link moves faster than it says, so the arms' distance changes no faster "
                     "than the sum of two links' bounds, and the interval bound holds.")),
        Obligation(
            "Tolerance.tube_factor", GROUP_TUBE, "docs/model.md §12 (tolerance tube)",
            "What spec.tolerance_rad returns is >= 0 and meets Tolerance.tube's premise "
            "c > 2 L delta: its factor two_l, its early return, k's start (math.floor as "
            "ToInt) and its loop guard read off its syntax tree and run on terms, the loop "
            "(body k -= 1) summed up as k <= k0 and k >= 0 when k0 >= 0, L > 0 any; and a "
            "max-norm joint deviation delta moves "
            "any point of any link of either arm by at most L delta, L = spec.tube_lipschitz "
            "(its bytecode on terms, Python's max as an If) over spec.reach of each link; "
            "lipschitz_tool: with a tool of 16 symbolic vertices on each arm, L (spec.tube_"
            "lipschitz and spec.reach run on terms) is at least R_base + R_elbow of every part, "
            "the tools' included. Named, "
            "not checked: a point moves by at most |dtheta1| R_base + |dtheta2| R_elbow (the "
            "speed bound of Certificate.lipschitz integrated along the joint-space segment).",
            Method.Z3, Verdict.PROVED, lambda: Z3Query(tube_factor_vcs()),
            label="integration in prose",
            summary=("The tolerance the tube reports is small enough: with the factor and the "
                     "constant the code uses, twice the constant times the tolerance stays below "
                     "the proved clearance, and no link point moves more than the constant times "
                     "the tolerance.")),
        Obligation(
            "Exact.gap_formula", GROUP_EXACT, "docs/model.md §7.2 (exact re-decision)",
            "The ball-arithmetic gap is a lower bound on the distance between the two convex "
            "hulls: for any n, spec.projection_bounds gives hi_a >= n.x for every x of hull A "
            "and lo_b <= n.y for every y of hull B (convex combinations of three corners each), "
            "and then |y - x| >= spec.gap_over_norm(hi_a, lo_b, n) = (lo_b - hi_a) / |n| when "
            "n != 0 (on exact reals, the square root its exact meaning). A tool's polygon on "
            "either side (tool_points, tool_frame, tool_max_A/B, tool_hull_A/B): "
            "spec._exact._tool_points run on terms makes every vertex of a symbolic tool moved "
            "by each corner of the square [-grow, grow]^2 in the forearm's frame at the wrist, "
            "and projection_bounds' end over those points bounds n.x for every point x of the "
            "tool grown by that square. Named, not checked: a "
            "point of the hull of many corners is a combination of three (Caratheodory, in the "
            "plane); arb's balls contain the exact values, upper() and lower() bound a ball.",
            Method.Z3, Verdict.PROVED, lambda: Z3Query(exact_vcs()),
            label="ball enclosure assumed",
            summary=("The gap the exact re-check computes along a separating direction, divided by "
                     "that direction's length, never exceeds the true distance between the two "
                     "regions, a tool's polygon included.")),
    ]

