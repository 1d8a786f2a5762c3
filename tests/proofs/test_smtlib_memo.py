"""The printer's and the nonlinearity scan's shortcuts (direct C calls, decoded nodes shared by
the queries of one obligation, the per-obligation nonlinearity memo) change no output: each is
compared with a straightforward reference (the printer as it read every node through z3py's
checked wrappers, one query at a time, and the scan over z3py objects), on VCs of bundled
obligations and on hand-made terms, in orders that reuse what the caches hold; each seeded fault
(a cache keyed or kept wrongly) is caught by the same comparison."""

from __future__ import annotations

import gc
import hashlib
from collections.abc import Iterator
from fractions import Fraction
from typing import Any

import pytest
import z3

from cfmpa.proofs import Method, _depth, _smtlib, collect_obligations
from cfmpa.proofs._depth import NonlinearMemo, is_nonlinear
from cfmpa.proofs._smtlib import Mode, NotStandard, smtlib_query

_NARY = _smtlib._NARY
_FIXED = _smtlib._FIXED
_CONNECTIVE = _smtlib._CONNECTIVE
_quote = _smtlib._quote

# --- the reference: every node read through z3py's checked wrappers, one query at a time ------

_C = z3  # the C API, as z3 exports it


class _RefPrinter:
    """One query's printer: declarations found on the way, the logic's features, memo."""

    def __init__(self, ctx: z3.Context, mode: Mode, open_premises: bool = False) -> None:
        self.c = ctx.ref()
        self.mode = mode
        self.open_premises = open_premises
        self.sorts: dict[str, str] = {}
        self.decls: list[str] = []
        self.decl_names: dict[int, str] = {}
        self.used: set[str] = set()
        self.qindex: dict[int, int] = {}
        self.atoms: dict[tuple[int, tuple[str, ...]], str] = {}
        self.memo: dict[tuple[int, tuple[str, ...], int], str] = {}
        self.skolems = 0
        self.lets = 0
        self.quantifiers = self.arrays = self.uf = self.nonlinear = False
        self.ints = self.reals = False

    # --- C API helpers -----------------------------------------------------------------------
    def _sym(self, s: object) -> str:
        c = self.c
        if _C.Z3_get_symbol_kind(c, s) == z3.Z3_INT_SYMBOL:
            return f"k!{_C.Z3_get_symbol_int(c, s)}"
        return str(_C.Z3_get_symbol_string(c, s))

    def _new_name(self, base: str) -> str:
        name, n = _quote(base), 1
        while name in self.used:
            n += 1
            name = _quote(f"{base}~{n}")
        self.used.add(name)
        return name

    def sort(self, s: object) -> str:
        c = self.c
        k = _C.Z3_get_sort_kind(c, s)
        if k == z3.Z3_BOOL_SORT:
            return "Bool"
        if k == z3.Z3_INT_SORT:
            self.ints = True
            return "Int"
        if k == z3.Z3_REAL_SORT:
            self.reals = True
            return "Real"
        if k == z3.Z3_ARRAY_SORT:
            self.arrays = True
            n = _C.Z3_get_array_arity(c, s)
            out = self.sort(_C.Z3_get_array_sort_range(c, s))
            for i in reversed(range(n)):
                out = f"(Array {self.sort(_C.Z3_get_array_sort_domain_n(c, s, i))} {out})"
            return out
        if k == z3.Z3_UNINTERPRETED_SORT:
            self.uf = True
            name = _quote(self._sym(_C.Z3_get_sort_name(c, s)))
            self.sorts.setdefault(name, f"(declare-sort {name} 0)")
            return name
        raise NotStandard(f"a sort of kind {k} has no standard rendering here")

    def symbol(self, d: object) -> str:
        c = self.c
        key = _C.Z3_get_ast_id(c, _C.Z3_func_decl_to_ast(c, d))
        name = self.decl_names.get(key)
        if name is None:
            arity = _C.Z3_get_arity(c, d)
            dom = " ".join(self.sort(_C.Z3_get_domain(c, d, i)) for i in range(arity))
            rng = self.sort(_C.Z3_get_range(c, d))
            name = self._new_name(self._sym(_C.Z3_get_decl_name(c, d)))
            if arity:
                self.uf = True
            self.decls.append(f"(declare-fun {name} ({dom}) {rng})")
            self.decl_names[key] = name
        return name

    def fresh(self, base: str, sort: str) -> str:
        name = self._new_name(base)
        self.decls.append(f"(declare-fun {name} () {sort})")
        return name

    # --- terms -------------------------------------------------------------------------------
    def term(self, a: object, frame: tuple[str, ...], pol: int = 0) -> str:
        # The text of a term depends on the names its free de Bruijn variables stand for and,
        # at the Boolean top level, on its polarity: memoised on both, a shared subterm costs
        # one rendering.
        key = (_C.Z3_get_ast_id(self.c, a), frame, pol)
        out = self.memo.get(key)
        if out is None:
            out = self.memo[key] = self._term(a, frame, pol)
        return out

    def _is_bool(self, a: object) -> bool:
        return bool(_C.Z3_get_sort_kind(self.c, _C.Z3_get_sort(self.c, a)) == z3.Z3_BOOL_SORT)

    def _term(self, a: object, frame: tuple[str, ...], pol: int) -> str:
        c = self.c
        kind = _C.Z3_get_ast_kind(c, a)
        if kind == z3.Z3_VAR_AST:
            i = _C.Z3_get_index_value(c, a)
            if i >= len(frame):
                raise NotStandard("a free de Bruijn variable")
            return str(frame[i])
        if kind == z3.Z3_QUANTIFIER_AST:
            return self._quantifier(a, frame, pol)
        if kind == z3.Z3_NUMERAL_AST:
            return self._numeral(a)
        if kind != z3.Z3_APP_AST:
            raise NotStandard(f"an AST of kind {kind}")
        d = _C.Z3_get_app_decl(c, a)
        k = _C.Z3_get_decl_kind(c, d)
        n = _C.Z3_get_app_num_args(c, a)
        args = [_C.Z3_get_app_arg(c, a, i) for i in range(n)]
        if self.mode is Mode.PROPOSITIONAL and self._is_bool(a):
            connective = (k in _CONNECTIVE or (k == z3.Z3_OP_UNINTERPRETED and n == 0)
                          or (k in (z3.Z3_OP_EQ, z3.Z3_OP_ITE) and self._is_bool(args[-1])))
            if not connective:
                return self._atom(a, frame)
        if k == z3.Z3_OP_TRUE:
            return "true"
        if k == z3.Z3_OP_FALSE:
            return "false"
        if k == z3.Z3_OP_UNINTERPRETED:
            sym = self.symbol(d)
            return sym if n == 0 else f"({sym} {' '.join(self.term(x, frame) for x in args)})"
        if k == z3.Z3_OP_SELECT:
            return self._select(args, frame)
        if k == z3.Z3_OP_STORE:
            return self._store(args, frame)
        if k == z3.Z3_OP_POWER:
            return self._power(args, frame)
        if k in (z3.Z3_OP_AND, z3.Z3_OP_OR):
            if not args:
                return "true" if k == z3.Z3_OP_AND else "false"
            kids = [self.term(x, frame, pol) for x in args]
            return kids[0] if len(kids) == 1 else f"({_NARY[k]} {' '.join(kids)})"
        if k == z3.Z3_OP_NOT:
            return f"(not {self.term(args[0], frame, -pol)})"
        if k == z3.Z3_OP_IMPLIES:
            # The premise is not opened by default: a universal there (a hypothesis' premise)
            # is usually a formula stated elsewhere too, and kept whole it stays one atom.
            pre = -pol if self.open_premises else 0
            return f"(=> {self.term(args[0], frame, pre)} {self.term(args[1], frame, pol)})"
        if k in _NARY or k in _FIXED:
            op = _NARY.get(k) or _FIXED[k]
            if k in (z3.Z3_OP_TO_INT, z3.Z3_OP_TO_REAL, z3.Z3_OP_IS_INT):
                # to_int, to_real and is_int are declared only in the mixed logics (IRA): a
                # query whose only integer is ToInt of a real is not QF_NRA.
                self.ints = self.reals = True
            if k in (z3.Z3_OP_ADD, z3.Z3_OP_MUL) and len(args) == 1:
                return self.term(args[0], frame)
            if k == z3.Z3_OP_MUL and sum(1 for x in args if not self._is_numeral(x)) > 1:
                self.nonlinear = True
            if k in (z3.Z3_OP_DIV, z3.Z3_OP_IDIV, z3.Z3_OP_MOD) and not self._is_numeral(args[1]):
                self.nonlinear = True
            return f"({op} {' '.join(self.term(x, frame) for x in args)})"
        raise NotStandard(f"operator {self._sym(_C.Z3_get_decl_name(c, d))} (kind {k}) has "
                          "no standard rendering here")

    def _atom(self, a: object, frame: tuple[str, ...]) -> str:
        key = (_C.Z3_get_ast_id(self.c, a), frame)
        if key not in self.atoms:
            self.atoms[key] = self.fresh(f"!atom{len(self.atoms) + 1}", "Bool")
        return self.atoms[key]

    def _numeral(self, a: object) -> str:
        c = self.c
        k = _C.Z3_get_sort_kind(c, _C.Z3_get_sort(c, a))
        fr = Fraction(_C.Z3_get_numeral_string(c, a))
        if k == z3.Z3_INT_SORT:
            self.ints = True
            return str(fr.numerator) if fr >= 0 else f"(- {-fr.numerator})"
        if k != z3.Z3_REAL_SORT:
            raise NotStandard(f"a numeral of sort kind {k}")
        self.reals = True
        mag = abs(fr)
        txt = (f"{mag.numerator}.0" if mag.denominator == 1
               else f"(/ {mag.numerator}.0 {mag.denominator}.0)")
        return txt if fr >= 0 else f"(- {txt})"

    def _is_numeral(self, a: object) -> bool:
        c = self.c
        kind = _C.Z3_get_ast_kind(c, a)
        if kind == z3.Z3_NUMERAL_AST:
            return True
        if kind == z3.Z3_APP_AST and _C.Z3_get_app_num_args(c, a) == 1 and _C.Z3_get_decl_kind(
                c, _C.Z3_get_app_decl(c, a)) in (z3.Z3_OP_TO_REAL, z3.Z3_OP_UMINUS):
            return self._is_numeral(_C.Z3_get_app_arg(c, a, 0))
        return False

    def _quantifier(self, a: object, frame: tuple[str, ...], pol: int) -> str:
        c = self.c
        if _C.Z3_is_lambda(c, a):
            raise NotStandard("a lambda term that is not applied (not beta-reducible)")
        forall = _C.Z3_is_quantifier_forall(c, a)
        nv = _C.Z3_get_quantifier_num_bound(c, a)
        names = [self._sym(_C.Z3_get_quantifier_bound_name(c, a, i)) for i in range(nv)]
        sorts = [_C.Z3_get_quantifier_bound_sort(c, a, i) for i in range(nv)]
        body = _C.Z3_get_quantifier_body(c, a)
        if self.mode is not Mode.PROPOSITIONAL and pol != 0 and forall == (pol < 0):
            # An outer existential: its variables become fresh constants (skolemisation).
            self.skolems += 1
            sk = [self.fresh(f"{nm}!sk{self.skolems}", self.sort(s))
                  for nm, s in zip(names, sorts)]
            return self.term(body, tuple(reversed(sk)) + frame, pol)
        if self.mode is not Mode.FULL:
            return self._atom(a, frame)
        self.quantifiers = True
        qn = self.qindex.setdefault(_C.Z3_get_ast_id(c, a), len(self.qindex) + 1)
        bound = [_quote(f"{nm}!{qn}.{i}") for i, nm in enumerate(names)]
        decl = " ".join(f"({b} {self.sort(s)})" for b, s in zip(bound, sorts))
        text = self.term(body, tuple(reversed(bound)) + frame)
        return f"({'forall' if forall else 'exists'} ({decl}) {text})"

    def _select(self, args: list[object], frame: tuple[str, ...]) -> str:
        c = self.c
        arr, idx = args[0], [self.term(x, frame) for x in args[1:]]
        if _C.Z3_get_ast_kind(c, arr) == z3.Z3_QUANTIFIER_AST and _C.Z3_is_lambda(c, arr):
            # Beta reduction: the lambda's variables stand for the index texts.
            if _C.Z3_get_quantifier_num_bound(c, arr) != len(idx):
                raise NotStandard("a lambda applied to the wrong number of indices")
            return self.term(_C.Z3_get_quantifier_body(c, arr), tuple(reversed(idx)) + frame)
        out = self.term(arr, frame)
        for i in idx:
            out = f"(select {out} {i})"
        return out

    def _store(self, args: list[object], frame: tuple[str, ...]) -> str:
        arr = self.term(args[0], frame)
        ids = [self.term(x, frame) for x in args[1:-1]]
        val = self.term(args[-1], frame)
        if len(ids) == 1:
            return f"(store {arr} {ids[0]} {val})"
        # a[i1]..[in] := v, curried: each level's array bound once by let.
        self.lets += 1
        names = [f"|!row{self.lets}.{n}|" for n in range(len(ids))]
        inner = val
        for n in reversed(range(len(ids))):
            inner = f"(store {names[n]} {ids[n]} {inner})"
        out = inner
        for n in reversed(range(len(ids))):
            bound = arr if n == 0 else f"(select {names[n - 1]} {ids[n - 1]})"
            out = f"(let (({names[n]} {bound})) {out})"
        return out

    def _power(self, args: list[object], frame: tuple[str, ...]) -> str:
        c = self.c
        base, ex = args
        if _C.Z3_get_ast_kind(c, ex) == z3.Z3_NUMERAL_AST:
            n = Fraction(_C.Z3_get_numeral_string(c, ex))
            if n.denominator == 1 and 1 <= n.numerator <= 8:
                b = self.term(base, frame)
                if n.numerator > 1 and not self._is_numeral(base):
                    self.nonlinear = True
                return b if n == 1 else f"(* {' '.join([b] * n.numerator)})"
        raise NotStandard("a power with an exponent other than a small natural numeral")

    def logic(self) -> str:
        arith = ""
        if self.ints or self.reals:
            arith = ("N" if self.nonlinear else "L") + (
                "IRA" if self.ints and self.reals else "IA" if self.ints else "RA")
        if self.arrays and not self.uf and not arith:
            core = "AX"
        else:
            core = ("A" if self.arrays else "") + ("UF" if self.uf or not (arith or self.arrays)
                                                   else "") + arith
        return ("" if self.quantifiers else "QF_") + core


def reference_query(hyps: list[Any], goal: Any, mode: Mode = Mode.FULL,
                    open_premises: bool = False) -> tuple[str, str, str, int] | str:
    """(text, logic, sha256, abstracted), or the NotStandard message."""
    forms = [*hyps, z3.Not(goal)]
    pr = _RefPrinter(forms[0].ctx, mode, open_premises)
    try:
        body = [f"(assert {pr.term(f.as_ast(), (), 1)})" for f in forms]
    except NotStandard as exc:
        return f"NotStandard: {exc}"
    head = [f"(set-logic {pr.logic()})", *pr.sorts.values(), *pr.decls]
    text = "\n".join(head + body + ["(check-sat)", "(exit)"]) + "\n"
    return text, pr.logic(), hashlib.sha256(text.encode()).hexdigest(), len(pr.atoms)


def _ref_constant(e: Any) -> bool:
    if z3.is_rational_value(e) or z3.is_int_value(e) or z3.is_algebraic_value(e):
        return True
    if z3.is_app(e) and e.num_args() > 0 and e.decl().kind() in (
            z3.Z3_OP_UMINUS, z3.Z3_OP_MUL, z3.Z3_OP_ADD, z3.Z3_OP_SUB, z3.Z3_OP_DIV,
            z3.Z3_OP_TO_REAL):
        return all(_ref_constant(c) for c in e.children())
    return False


def reference_nonlinear(formulas: list[Any]) -> bool:
    ops = (z3.Z3_OP_MUL, z3.Z3_OP_DIV, z3.Z3_OP_IDIV, z3.Z3_OP_MOD, z3.Z3_OP_REM,
           z3.Z3_OP_POWER)
    seen: set[int] = set()
    todo = list(formulas)
    while todo:
        e = todo.pop()
        if e.get_id() in seen:
            continue
        seen.add(e.get_id())
        if z3.is_quantifier(e):
            todo.append(e.body())
            continue
        if not z3.is_app(e):
            continue
        kind = e.decl().kind()
        if kind in ops and e.num_args() >= 2:
            args = e.children()
            if kind == z3.Z3_OP_MUL:
                if sum(not _ref_constant(a) for a in args) >= 2:
                    return True
            elif not _ref_constant(args[1]):
                return True
        todo.extend(e.children())
    return False


# --- the comparison ---------------------------------------------------------------------------

#: Every rendering the prover asks for: the statement, its two abstractions, premises opened.
MODES = [(Mode.FULL, False), (Mode.PROPOSITIONAL, False), (Mode.GROUND, False),
         (Mode.FULL, True), (Mode.GROUND, True)]

Case = tuple[list[Any], Any]


def actual_query(hyps: list[Any], goal: Any, mode: Mode = Mode.FULL,
                 open_premises: bool = False) -> tuple[str, str, str, int] | str:
    try:
        q = smtlib_query(hyps, goal, mode, open_premises=open_premises)
    except NotStandard as exc:
        return f"NotStandard: {exc}"
    return q.text, q.logic, q.sha256, q.abstracted


def mismatches(cases: list[Case], memo: NonlinearMemo | None = None) -> list[str]:
    """Where the printer or the scan differs from the reference, each VC in the prover's order
    (its statement, then its abstractions), so the decoded nodes of one are reused by the next."""
    out = []
    for i, (hyps, goal) in enumerate(cases):
        for mode, opened in MODES:
            if actual_query(hyps, goal, mode, opened) != reference_query(hyps, goal, mode, opened):
                out.append(f"case {i}: {mode.value}, open_premises={opened}")
        if is_nonlinear(hyps + [goal], memo) != reference_nonlinear(hyps + [goal]):
            out.append(f"case {i}: is_nonlinear")
    return out


def hand_made(ctx: z3.Context | None = None) -> list[Case]:
    """Terms that reach every branch of the printer, sharing hypotheses as VCs do."""
    x, y = z3.Reals("x y", ctx)
    i, j = z3.Ints("i j", ctx)
    x_int = z3.Int("x", ctx)                            # a second decl named x: x~2
    p, q = z3.Bools("p q", ctx)
    u = z3.DeclareSort("U", ctx)
    f = z3.Function("f", z3.RealSort(ctx), z3.RealSort(ctx))
    g = z3.Function("g", u, z3.BoolSort(ctx))
    e = z3.Const("e", u)
    a2 = z3.Array("a2", z3.IntSort(ctx), z3.IntSort(ctx), z3.RealSort(ctx))
    a1 = z3.Array("a1", z3.IntSort(ctx), z3.RealSort(ctx))
    t, s = z3.Reals("t s", ctx)
    lam = z3.Lambda([t, s], t * s + 1)
    convex = z3.ForAll([t], z3.Implies(t > 0, f(t) >= 0))
    witness = z3.Exists([t], z3.And(f(t) == x, t * t == y))
    shared = [x > 0, y >= x / 2, convex, p == (x > y)]
    return [
        (shared, x * y > 0),                                        # nonlinear product
        (shared, z3.Implies(convex, f(x) + f(y) >= 0)),             # a universal in a premise
        (shared, witness),                                          # an existential goal
        (shared, z3.Not(witness)),
        (shared, z3.Or(p, q, z3.Xor(p, q), z3.If(p, q, z3.Not(q)))),
        (shared + [q == (y > 0)], z3.Distinct(x, y, x + y)),
        ([x_int + i > j, i % 3 == 1, j / 2 >= i, z3.ToReal(x_int) < x],    # Int, div, mod,
         x_int ** 2 >= 0),                                          # power; x and x~2
        ([z3.Implies(convex, x > 0)], x >= 0),                      # a premise to open
        ([z3.ToReal(i) <= x, z3.ToInt(y) == j, z3.IsInt(x)], x - 1 < y),
        ([x == z3.Q(-3, 8, ctx), y == -z3.RealVal(5, ctx), i == -7],
         x * z3.Q(1, 2, ctx) + 2 * y < z3.ToReal(i)),
        ([z3.Store(a2, i, j, x)[i, j] == x, a1[i] >= 0], z3.Store(a1, i, y)[i] == y),
        ([lam[x, y] > 0], x * y > -1),                              # a lambda applied
        ([a1 == z3.Lambda([i], z3.ToReal(i))], a1[0] == 0),         # one not applied
        ([x ** 9 > 0], x > 0),                                      # a power not rendered
        ([x ** y > 0], x > 0),
        ([g(e), z3.ForAll([e], g(e))], z3.Exists([e], g(e))),       # a sort of its own
        ([z3.ForAll([t], z3.ForAll([s], f(t) * s >= f(s) * t))], f(x) * y >= f(y) * x),
        ([], z3.BoolVal(True, ctx)),
    ]


# --- the shortcuts change no output ---------------------------------------------------------

def test_hand_made_terms_print_as_the_reference_prints_them():
    cases = hand_made()
    assert mismatches(cases) == []
    assert mismatches(list(reversed(cases))) == []         # other queries, other reuse
    assert mismatches(cases, NonlinearMemo()) == []
    # In a context of their own, after the first: the cache starts afresh, same texts.
    assert mismatches(hand_made(z3.Context())) == []


_SAMPLE = ("Def2.is_convex", "Lemma2.convex_union", "Thm1.builtdr", "Prop8.optimal_cost",
           "Sep.distance_monotone")


@pytest.fixture(scope="module")
def bundled() -> list[list[Case]]:
    obs = [o for o in collect_obligations("/nonexistent")
           if o.method is Method.Z3 and o.id in _SAMPLE]
    assert len(obs) == len(_SAMPLE)
    return [[([h for _, h in vc.hypotheses], vc.goal) for vc in o.build().vcs] for o in obs]


def test_bundled_vcs_print_as_the_reference_prints_them(bundled: list[list[Case]]):
    for cases in bundled:
        assert mismatches(cases, NonlinearMemo()) == []


def test_through_z3pys_wrappers_the_printer_prints_the_same(monkeypatch: pytest.MonkeyPatch):
    # Where z3py does not expose its C functions as expected, each call goes through z3py's
    # checked wrapper instead: the same texts, more slowly.
    fallback = {
        "_ast_kind": ("Z3_get_ast_kind", (_smtlib._P, _smtlib._P)),
        "_app_decl": ("Z3_get_app_decl", (_smtlib._P, _smtlib._P)),
        "_app_num_args": ("Z3_get_app_num_args", (_smtlib._P, _smtlib._P)),
        "_app_arg": ("Z3_get_app_arg", (_smtlib._P, _smtlib._P, _smtlib._U)),
        "_decl_kind": ("Z3_get_decl_kind", (_smtlib._P, _smtlib._P)),
        "_get_sort": ("Z3_get_sort", (_smtlib._P, _smtlib._P)),
        "_sort_kind": ("Z3_get_sort_kind", (_smtlib._P, _smtlib._P)),
        "_numeral_string": ("Z3_get_numeral_string", (_smtlib._P, _smtlib._P)),
        "_symbol_string": ("Z3_get_symbol_string", (_smtlib._P, _smtlib._P)),
        "_bound_name": ("Z3_get_quantifier_bound_name", (_smtlib._P, _smtlib._P, _smtlib._U)),
    }
    for attr, (name, argtypes) in fallback.items():
        monkeypatch.setattr(_smtlib, attr, _smtlib._via_z3py(name, argtypes))
    monkeypatch.setattr(_smtlib, "_local", type(_smtlib._local)())     # no node decoded yet
    assert mismatches(hand_made()) == []


def test_a_failed_checked_call_raises_as_z3py_does():
    x = z3.Real("x")
    c = _smtlib._ptr(x.ctx.ref())
    with pytest.raises(z3.Z3Exception):
        _smtlib._numeral_string(c, _smtlib._ptr(x.as_ast()))   # x is not a numeral
    assert _smtlib._numeral_string(c, _smtlib._ptr(z3.RealVal("3/4").as_ast())) == "3/4"


# --- seeded faults: each is caught by the same comparison ---------------------------------------

def test_seeded_fault_a_text_memo_shared_across_modes_is_caught(monkeypatch: pytest.MonkeyPatch):
    # A node's text depends on the mode (an atom, a skolem constant, a quantifier): keyed by
    # node, frame and polarity alone and kept from query to query, the abstractions would get
    # the statement's texts.
    shared: dict[Any, str] = {}
    init = _smtlib._Printer.__init__

    def faulty(self: Any, *args: Any, **kwargs: Any) -> None:
        init(self, *args, **kwargs)
        self.memo = shared
    monkeypatch.setattr(_smtlib._Printer, "__init__", faulty)
    assert mismatches(hand_made()) != []


def test_seeded_fault_a_wrong_decoded_node_is_caught(monkeypatch: pytest.MonkeyPatch):
    # A decoded node with its Boolean flag wrong (here: an equation's read as its first
    # argument's sort): the propositional abstraction would no longer abstract x == 3/8.
    decode = _smtlib._Nodes.decode

    def faulty(self: Any, a: int) -> Any:
        node = decode(self, a)
        if node[2] == z3.Z3_OP_EQ:
            node = (*node[:4], self.nodes.get(node[3][0], decode(self, node[3][0]))[4])
            self.nodes[a] = node
        return node
    monkeypatch.setattr(_smtlib._Nodes, "decode", faulty)
    monkeypatch.setattr(_smtlib, "_local", type(_smtlib._local)())
    assert mismatches(hand_made()) != []


def _churn(rounds: int) -> Iterator[str]:
    """Queries whose goals die between them (freed nodes, whose memory Z3 reuses), sharing one
    live hypothesis; yields the differences from the reference."""
    ctx = z3.Context()
    x, y = z3.Reals("x y", ctx)
    keep = x > 0
    for n in range(rounds):
        goal = (x * y > n) if n % 2 else z3.And(x + n > y, z3.Not(y < x))
        for mode, _ in MODES[:3]:
            if actual_query([keep], goal, mode) != reference_query([keep], goal, mode):
                yield f"round {n}: {mode.value}"
        del goal
        gc.collect()


def test_dead_goals_do_not_leave_stale_nodes():
    assert list(_churn(40)) == []


def test_seeded_fault_nodes_kept_past_their_terms_life_is_caught(
        monkeypatch: pytest.MonkeyPatch):
    # The cache holds its roots so that their nodes, its keys, stay alive: with only their
    # pointers kept, a goal freed and another built in its memory would read the old node.
    def faulty(forms: list[Any]) -> Any:
        ctx = forms[0].ctx
        c = _smtlib._ptr(ctx.ref())
        ptrs = [_smtlib._ptr(f.as_ast()) for f in forms]
        cache = getattr(_smtlib._local, "nodes", None)
        if cache is None or cache.c != c or not any(p in cache.roots for p in ptrs[:-1]):
            cache = _smtlib._local.nodes = _smtlib._Nodes(ctx)
        for p in ptrs:
            cache.roots.setdefault(p, None)                  # the fault: the term not held
        return cache
    monkeypatch.setattr(_smtlib, "_nodes_for", faulty)
    monkeypatch.setattr(_smtlib, "_local", type(_smtlib._local)())
    assert list(_churn(40)) != []


def test_the_nonlinear_memo_tells_contexts_apart():
    # Two fresh contexts number their terms alike: the same AST id, different terms.
    c1, c2 = z3.Context(), z3.Context()
    x1, y1 = z3.Reals("x y", c1)
    x2, y2 = z3.Reals("x y", c2)
    f1, f2 = x1 * y1 > 0, x2 + y2 > 0
    assert f1.get_id() == f2.get_id()                        # what makes the test bite
    memo = NonlinearMemo()
    assert is_nonlinear([f1], memo) and not is_nonlinear([f2], memo)
    assert is_nonlinear([f1], memo) and not is_nonlinear([f2], memo)   # from the memo


def test_seeded_fault_a_nonlinear_memo_keyed_by_id_alone_is_caught(
        monkeypatch: pytest.MonkeyPatch):
    monkeypatch.setattr(_depth, "_formula_key", lambda f: (0, f.get_id()))
    c1, c2 = z3.Context(), z3.Context()
    x1, y1 = z3.Reals("x y", c1)
    x2, y2 = z3.Reals("x y", c2)
    f1, f2 = x1 * y1 > 0, x2 + y2 > 0
    assert f1.get_id() == f2.get_id()
    memo = NonlinearMemo()
    assert is_nonlinear([f1], memo)
    assert is_nonlinear([f2], memo) != reference_nonlinear([f2])


def test_seeded_fault_a_scan_stopping_at_the_first_product_is_caught(
        monkeypatch: pytest.MonkeyPatch):
    # The scan's constant test, made to say every factor is a constant: products of
    # unknowns would pass for linear.
    monkeypatch.setattr(_depth._Scan, "_constant_value", lambda self, a: True)
    assert mismatches(hand_made()) != []


def test_seeded_fault_declarations_kept_by_name_are_caught(monkeypatch: pytest.MonkeyPatch):
    # Declarations are kept by their pointer: kept by name, the Int x would be read as the Real
    # x (one declaration, the wrong sort) where both occur.
    by_name: dict[tuple[int, str], Any] = {}
    decl = _smtlib._Nodes.decl

    def faulty(self: Any, d: int) -> Any:
        name = _smtlib._symbol_text(self.c, _smtlib._decl_name(self.c, d))
        return by_name.setdefault((id(self), name), decl(self, d))
    monkeypatch.setattr(_smtlib._Nodes, "decl", faulty)
    monkeypatch.setattr(_smtlib, "_local", type(_smtlib._local)())
    assert mismatches(hand_made()) != []
