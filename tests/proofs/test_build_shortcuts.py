"""The builders' shortcuts give the terms and numbers of the plain computation they replace:
``Substitution`` is z3.substitute (simultaneous, all pairs), ``dedupe`` drops exactly Z3's
equal formulas, the compiled reading (``_compile``/``_run``) gives the floats of a recursion on the terms, and
Exact.gap_formula's tool_points goal is the search at every model point. Each check is shown to
catch a seeded fault planted in a copy of the module. (The pinned statement hashes in
proofs/obligations.lock are the end-to-end check: ``cfmpa prove --only ID`` fails on a change.)"""

from __future__ import annotations

import math
import random
import sys
import types
from collections.abc import Callable
from typing import Any

import pytest
import z3

from cfmpa.proofs import _lemmas as L
from cfmpa.proofs import _obl_exact_polygon as XP
from cfmpa.proofs import _obl_tools as T
from mutant_module import mutated_module


def _planted(name: str, file: str, old: str, new: str) -> types.ModuleType:
    return mutated_module(name, file, [(old, new)], sys.modules.__setitem__)


# --- Substitution -------------------------------------------------------------------------------

def _substitution_agrees(subst: Callable[..., Callable[[z3.ExprRef], z3.ExprRef]]) -> bool:
    """``subst(pairs)(f)`` is z3.substitute(f, *pairs) on formulas of a lemma and on a swap of
    two names (where substituting one pair after another would differ)."""
    x, y, z = z3.Reals("sub.x sub.y sub.z")
    lemma_fs = [h for _, h in T._hull_step({"comb_id": T._comb_id()}).hyps]
    names = sorted({str(c) for f in lemma_fs for c in _consts(f)})
    pairs = [(z3.Real(n), z3.Real(n) * 2 + k) for k, n in enumerate(names)]
    cases = [(f, pairs) for f in lemma_fs]
    cases += [(x * x + y - z, [(x, y), (y, x)]), (x + y, [(x, y + z), (z, x)])]
    return all(z3.eq(subst(ps)(f), z3.substitute(f, *ps)) for f, ps in cases)


def _consts(f: z3.ExprRef) -> list[z3.ExprRef]:
    if z3.is_const(f) and f.decl().kind() == z3.Z3_OP_UNINTERPRETED:
        return [f]
    return [c for k in f.children() for c in _consts(k)]


def test_substitution_is_z3_substitute():
    assert _substitution_agrees(L.Substitution)


def test_substitution_checks_its_pairs_once():
    x, b = z3.Real("sub.x"), z3.Bool("sub.b")
    with pytest.raises(TypeError, match="sorts differ"):
        L.Substitution([(x, b)])
    ints, reals = (z3.Array(n, z3.IntSort(), s) for n, s in (("sub.A", z3.IntSort()),
                                                              ("sub.B", z3.RealSort())))
    with pytest.raises(TypeError, match="sorts differ"):
        L.Substitution([(x, x + 1), (ints, reals)])
    L.Substitution([(reals, z3.Array("sub.C", z3.IntSort(), z3.RealSort()))])  # equal sorts
    with pytest.raises(TypeError, match="two Z3 expressions"):
        L.Substitution([(x, 1)])            # type: ignore[list-item]
    with pytest.raises(TypeError, match="not a Z3 expression"):
        L.Substitution([(x, x + 1)])(3)


def test_a_substitution_that_drops_a_pair_is_caught():
    bad = _planted("drops_last_pair", "proofs/_lemmas.py",
                   "f.as_ast(), len(self.pairs),",
                   "f.as_ast(), len(self.pairs) - 1,")
    assert not _substitution_agrees(bad.Substitution)


def test_substituting_pair_after_pair_is_caught():
    def sequential(pairs):
        def run(f):
            for p in pairs:
                f = z3.substitute(f, p)
            return f
        return run
    assert not _substitution_agrees(sequential)


# --- dedupe -------------------------------------------------------------------------------------

def _dedupe_right(dedupe: Callable[..., tuple]) -> bool:
    """Repeats of a formula (built anew: another Python object, the same Z3 term) go, the first
    name kept with its spaces normalised; formulas Z3 tells apart stay, in order."""
    def build(k: int) -> z3.BoolRef:
        x, y = z3.Reals("dd.x dd.y")
        return x + k <= y
    hyps = [("a  first", build(1)), ("b", build(2)), ("a again", build(1)), ("c", z3.Not(build(1))),
            ("b again", build(2))]
    got = dedupe(hyps)
    want = [("a first", build(1)), ("b", build(2)), ("c", z3.Not(build(1)))]
    return ([n for n, _ in got] == [n for n, _ in want]
            and all(z3.eq(g, w) for (_, g), (_, w) in zip(got, want)))


def test_dedupe_drops_exactly_the_equal_formulas():
    assert _dedupe_right(L.dedupe)


def test_a_dedupe_by_python_object_is_caught():
    bad = _planted("dedupe_by_object", "proofs/_lemmas.py",
                   "key = (id(h.ctx), h.get_id())", "key = (id(h.ctx), id(h))")
    assert not _dedupe_right(bad.dedupe)


# --- the compiled reading of the tool -----------------------------------------------------------

@pytest.fixture(scope="module")
def reading() -> T.ToolReading:
    return T.read_tool()


def _value(t: z3.ExprRef, env: dict[str, float], memo: dict[int, Any]) -> Any:
    """A term's value by recursion on its DAG (the reference): constants from ``env`` (by
    name), Cos/Sin as math's, the rest by the reading's table of operations."""
    key = t.get_id()
    if key in memo:
        return memo[key]
    if z3.is_rational_value(t):
        out: Any = float(t.as_fraction())
    elif z3.is_true(t) or z3.is_false(t):
        out = z3.is_true(t)
    elif z3.is_const(t):
        out = env[t.decl().name()]
    else:
        kids = [_value(c, env, memo) for c in t.children()]
        d = t.decl()
        if d.eq(T._COS):
            out = math.cos(kids[0])
        elif d.eq(T._SIN):
            out = math.sin(kids[0])
        else:
            out = T._OPS[d.kind()](*kids)
    memo[key] = out
    return out


def _compiled_is_value(mod: types.ModuleType, reading: T.ToolReading) -> bool:
    """The compiled terms' values are the recursion's, bit for bit, at a sample environment:
    the margins (If, products, quotients, differences) and the generating points (Cos, Sin)."""
    g1, g2, re = z3.Reals("cmp.g1 cmp.g2 cmp.Re")
    alpha, beta, delta = z3.Reals("cmp.alpha cmp.beta cmp.delta")
    terms = [reading.margin((g1, g2), re, (f1, f2)) for f1 in (True, False) for f2 in (True, False)]
    terms += [c for p in reading.points(alpha, beta, delta) for c in p]
    rnd = random.Random(1)
    env = {T._name(c): rnd.uniform(0.1, 1.0) for t in terms for c in _consts(t)}
    memo: dict[int, Any] = {}
    want = [_value(t, env, memo) for t in terms]
    got = mod._run(mod._compile(terms), env)
    return len(got) == len(want) and all(a == b or (math.isnan(a) and math.isnan(b))
                                         for a, b in zip(got, want))


def test_the_compiled_reading_is_values(reading: T.ToolReading):
    assert _compiled_is_value(T, reading)


def test_a_program_that_reads_its_arguments_reversed_is_caught(reading: T.ToolReading):
    bad = _planted("args_reversed", "proofs/_obl_tools.py",
                   "vals.append(op(*[vals[i] for i in arg]))",
                   "vals.append(op(*[vals[i] for i in reversed(arg)]))")
    assert not _compiled_is_value(bad, reading)


# --- Exact.gap_formula's tool_points: the search at every model point ---------------------------

def _goal_is_the_search(mod: types.ModuleType) -> bool:
    """tool_points' goal pairs each model point with the code's point nearest it at the random
    values, each evaluated afresh for each model point (as the search reads them)."""
    T_ = XP._Tool()
    G = XP.tool_points_on_terms(T_.arm, T_.t1, T_.t2, T_.grow, None)
    names = [(z3.Real(f"G{k + 1}.x"), z3.Real(f"G{k + 1}.y")) for k in range(len(G))]
    rnd = random.Random(0)
    env = {str(v): rnd.uniform(0.1, 1.0) for v in (*T_.arm.base, *T_.arm.links, T_.t1, T_.t2,
                                                  T_.grow, *[c for q in T_.verts for c in q])}
    goal = []
    for u, v in T_.frame:
        want = T_.at(u, v)
        m = (XP._value(want[0], env), XP._value(want[1], env))
        k = min(range(len(G)), key=lambda i: abs(XP._value(G[i][0], env) - m[0])
                + abs(XP._value(G[i][1], env) - m[1]))
        goal.append(z3.And(want[0] == names[k][0], want[1] == names[k][1]))
    return bool(z3.eq(mod._points_vc(None).goal, z3.And(*goal)))


def test_tool_points_goal_is_the_search_at_every_point():
    assert _goal_is_the_search(XP)


def test_a_search_that_keeps_the_first_model_point_is_caught():
    bad = _planted("stale_model_point", "proofs/_obl_exact_polygon.py",
                   "        m = (_value(want[0], env), _value(want[1], env))\n        if at_g",
                   "        m = m if at_g is not None else (_value(want[0], env), "
                   "_value(want[1], env))\n        if at_g")
    assert not _goal_is_the_search(bad)


# --- Lemma.sweep_margin's abstract norms: a shared subterm rewritten once --------------------------

def _abstract_norms(f: z3.ExprRef, sq: z3.FuncDeclRef) -> z3.ExprRef:
    """The rewrite by plain recursion (the reference): every u*u + v*v becomes sq(u, v)."""
    if z3.is_add(f) and f.num_args() == 2:
        lt, rt = f.arg(0), f.arg(1)
        if (z3.is_mul(lt) and z3.is_mul(rt) and lt.num_args() == 2 and rt.num_args() == 2
                and z3.eq(lt.arg(0), lt.arg(1)) and z3.eq(rt.arg(0), rt.arg(1))):
            return sq(lt.arg(0), rt.arg(0))
    if z3.is_app(f) and f.num_args() > 0:
        return f.decl()(*[_abstract_norms(c, sq) for c in f.children()])
    return f


def _norms_rewritten(mod: types.ModuleType) -> bool:
    """On formulas where norms and other sums share subterms, the memoised rewrite is the
    recursion's."""
    sq = z3.Function("sq", z3.RealSort(), z3.RealSort(), z3.RealSort())
    a, b, c, d, t = z3.Reals("an.a an.b an.c an.d an.t")
    n_ab, n_cd = a * a + b * b, c * c + d * d
    fs = [z3.Implies(z3.And(n_ab <= t * t, a + b <= n_cd), n_ab + n_cd <= (a + b) * t),
          z3.And(n_ab == n_cd, (a - c) * (a - c) + (b - d) * (b - d) >= 0, a * a <= n_ab)]
    return all(z3.eq(mod._abstract_norms(f, sq), _abstract_norms(f, sq)) for f in fs)


def test_abstract_norms_is_the_recursion():
    from cfmpa.proofs import _obl_margin as M
    assert _norms_rewritten(M)


def test_abstract_norms_memoised_by_the_wrong_key_is_caught():
    bad = _planted("memo_by_arity", "proofs/_obl_margin.py",
                   "    key = f.get_id()\n    if key in memo:",
                   "    key = f.num_args()\n    if key in memo:")
    assert not _norms_rewritten(bad)
