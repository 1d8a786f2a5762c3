"""Standard SMT-LIB 2.6 for a VC's proof check, and its two abstractions (the depth check).

Z3's own printer (``Solver.sexpr``) writes Z3's dialect: lambda terms, arrays indexed by several
sorts, no logic. ``smtlib_query`` writes the proof check of one VC (hypotheses and the negated
goal; unsat wanted) in the standard language instead, with its own printer, which reads the
terms through Z3's C API:

- a lambda applied by ``select`` is beta-reduced as it is printed (its bound variables stand
  for the argument texts); any other lambda is refused (``NotStandard``), as are Z3-only
  constructs (constant arrays, ``as-array``, other theories);
- an array of several index sorts is curried: ``(Array I1 I2 R)`` becomes
  ``(Array I1 (Array I2 R))``, a select a chain of selects, a store a nest of stores (bound by
  ``let``, so the text stays linear in the term);
- ``x ** n`` for a numeral 1 <= n <= 8 becomes a product; Int/Real conversions are explicit (Z3
  writes them into the term); numerals are ``5``, ``(- 5)``, ``2.0``, ``(/ 1.0 8.0)``;
- outer existentials (an ``exists`` under an even number of negations, or a ``forall`` under an
  odd one, reached through and, or, not and the conclusion of =>, so under no universal and in
  no premise) are skolemised: satisfiability is preserved, and a query without other
  quantifiers gets a quantifier-free logic, where cvc5 has complete procedures (cylindrical
  algebraic coverings for QF_NRA);
- every symbol is quoted (``|start.i|``), bound variables are named apart by their quantifier's
  index in the query (equal quantifiers print equally), declarations come in order of first
  use, and ``set-logic`` names the least logic of SMT-LIB's lattice used (QF_ or not, A, UF, L
  or N, IA, RA or IRA).

The text is a function of the terms alone (not of Z3's version or its printer), so its hash is
the statement's fingerprint that proofs/obligations.lock pins (``_pins``).

Two abstractions, for the depth check (``_depth``), are printed the same way:

- ``Mode.PROPOSITIONAL`` (the Boolean abstraction): every Boolean term whose head is not a
  connective (and, or, not, =>, xor, =/ite over Bool), a quantified formula included, becomes a
  fresh Boolean constant, equal terms the same one; nothing is skolemised;
- ``Mode.GROUND``: skolemised as above, then every quantified formula left (each needs
  instantiation to be used) becomes a fresh Boolean constant, equal ones the same.

Both over-approximate the query: a model of it gives one of the abstraction (each fresh constant
set to the truth value of the term it replaces; skolemisation keeps satisfiability). So unsat of
the abstraction implies unsat of the query, by propositional reasoning alone, or by ground
reasoning with no quantifier instantiated.
"""

from __future__ import annotations

import hashlib
from collections.abc import Iterable
from dataclasses import dataclass
from enum import Enum
from fractions import Fraction

import z3

__all__ = ["Mode", "NotStandard", "SmtLib", "smtlib_query"]


class NotStandard(ValueError):
    """The term uses a construct with no standard SMT-LIB 2.6 rendering here."""


class Mode(Enum):
    FULL = "full"
    GROUND = "ground"
    PROPOSITIONAL = "propositional"


@dataclass(frozen=True)
class SmtLib:
    """A VC's proof check in standard SMT-LIB 2.6."""

    text: str
    logic: str
    sha256: str
    abstracted: int = 0      # fresh Boolean constants standing for terms (the abstractions)


_C = z3  # the C API, as z3 exports it
_NARY = {z3.Z3_OP_AND: "and", z3.Z3_OP_OR: "or", z3.Z3_OP_ADD: "+", z3.Z3_OP_MUL: "*",
         z3.Z3_OP_SUB: "-", z3.Z3_OP_DISTINCT: "distinct"}
_FIXED = {z3.Z3_OP_NOT: "not", z3.Z3_OP_IMPLIES: "=>", z3.Z3_OP_XOR: "xor", z3.Z3_OP_ITE: "ite",
          z3.Z3_OP_EQ: "=", z3.Z3_OP_IFF: "=", z3.Z3_OP_LE: "<=", z3.Z3_OP_GE: ">=",
          z3.Z3_OP_LT: "<", z3.Z3_OP_GT: ">", z3.Z3_OP_UMINUS: "-", z3.Z3_OP_DIV: "/",
          z3.Z3_OP_IDIV: "div", z3.Z3_OP_MOD: "mod", z3.Z3_OP_TO_REAL: "to_real",
          z3.Z3_OP_TO_INT: "to_int", z3.Z3_OP_IS_INT: "is_int"}
_CONNECTIVE = {z3.Z3_OP_AND, z3.Z3_OP_OR, z3.Z3_OP_NOT, z3.Z3_OP_IMPLIES, z3.Z3_OP_XOR,
               z3.Z3_OP_TRUE, z3.Z3_OP_FALSE, z3.Z3_OP_IFF}


def _quote(name: str) -> str:
    return "|" + name.replace("|", "/").replace("\\", "/") + "|"


class _Printer:
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


def smtlib_query(hypotheses: Iterable[z3.BoolRef], goal: z3.BoolRef,
                 mode: Mode = Mode.FULL, *, open_premises: bool = False) -> SmtLib:
    """The proof check ``hypotheses ∧ ¬goal`` (unsat wanted) as standard SMT-LIB 2.6, or one
    of its abstractions (module docstring). ``open_premises``: skolemise also the universals
    in the premise of an implication (each must then be proved, at one fresh point: what a
    premise such as "the half-plane is convex" needs, at the price of no longer sharing it as
    one atom with the same formula elsewhere)."""
    forms = [*hypotheses, z3.Not(goal)]
    pr = _Printer(forms[0].ctx, mode, open_premises)
    body = [f"(assert {pr.term(f.as_ast(), (), 1)})" for f in forms]
    head = [f"(set-logic {pr.logic()})", *pr.sorts.values(), *pr.decls]
    text = "\n".join(head + body + ["(check-sat)", "(exit)"]) + "\n"
    return SmtLib(text, pr.logic(), hashlib.sha256(text.encode()).hexdigest(), len(pr.atoms))
