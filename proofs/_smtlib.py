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

import ctypes
import hashlib
import sys
import threading
from collections.abc import Callable, Iterable
from dataclasses import dataclass
from enum import Enum
from fractions import Fraction
from typing import Any

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


# --- Z3's C API, called directly ------------------------------------------------------------
# z3py's wrapper of a C function converts each argument in Python and asks Z3 for the error code
# after every call: most of the printer's time when it went through them. Here each function is
# Z3's own entry point (the address z3py loaded), taking and returning pointers as ints. The
# accessors built with ``checked=False`` are called only where their precondition holds by
# construction (an application's decl and arguments, an expression's sort, an AST's kind, a
# decl's kind), so they cannot fail; every other one asks for the error code afterwards, and
# raises z3.Z3Exception as z3py would.

_P, _U = ctypes.c_void_p, ctypes.c_uint


def _entry(name: str, restype: Any, argtypes: tuple[Any, ...]) -> Callable[..., Any] | None:
    """Z3's C function ``name`` itself, or None if z3py does not expose it as expected."""
    try:
        loaded = getattr(z3.z3core, name).__defaults__[-1].f   # z3core's Elementaries
        addr = ctypes.cast(loaded, ctypes.c_void_p).value
    except (AttributeError, IndexError, TypeError, ctypes.ArgumentError):
        return None
    return None if addr is None else ctypes.CFUNCTYPE(restype, *argtypes)(addr)


def _via_z3py(name: str, argtypes: tuple[Any, ...]) -> Callable[..., Any]:
    """z3py's checked wrapper of ``name``, pointers wrapped and unwrapped (the fallback)."""
    wrapper = getattr(z3.z3core, name)

    def call(*args: Any) -> Any:
        out = wrapper(*(ctypes.c_void_p(x) if t is _P else x
                        for x, t in zip(args, argtypes, strict=True)))
        return out.value if isinstance(out, ctypes.c_void_p) else out
    return call


_raw_error_code = _entry("Z3_get_error_code", _U, (_P,))
_raw_error_msg = _entry("Z3_get_error_msg", ctypes.c_char_p, (_P, _U))


def _check(c: int) -> None:
    """Raise z3.Z3Exception if the last call on context ``c`` failed (as z3py does)."""
    assert _raw_error_code is not None and _raw_error_msg is not None   # see _native
    err = _raw_error_code(c)
    if err != z3.Z3_OK:
        raise z3.Z3Exception(_raw_error_msg(c, err).decode(sys.getdefaultencoding(), "replace"))


def _native(name: str, restype: Any, *argtypes: Any, checked: bool = True
            ) -> Callable[..., Any]:
    """Z3's C function ``name``: pointers as ints, strings decoded (as z3py decodes them)."""
    fn = _entry(name, restype, argtypes)
    if fn is None or _raw_error_code is None or _raw_error_msg is None:
        return _via_z3py(name, argtypes)       # z3py's wrappers check themselves
    raw = fn
    if restype is ctypes.c_char_p:
        def text(*args: Any) -> str:
            out = raw(*args)
            _check(args[0])
            return "" if out is None else str(out.decode(sys.getdefaultencoding()))
        return text
    if not checked:
        return raw

    def call(*args: Any) -> Any:
        out = raw(*args)
        _check(args[0])
        return out
    return call


# Unchecked: the hot accessors, each called only where it cannot fail (above).
_ast_kind = _native("Z3_get_ast_kind", _U, _P, _P, checked=False)
_app_decl = _native("Z3_get_app_decl", _P, _P, _P, checked=False)
_app_num_args = _native("Z3_get_app_num_args", _U, _P, _P, checked=False)
_app_arg = _native("Z3_get_app_arg", _P, _P, _P, _U, checked=False)
_decl_kind = _native("Z3_get_decl_kind", _U, _P, _P, checked=False)
_get_sort = _native("Z3_get_sort", _P, _P, _P, checked=False)
_sort_kind = _native("Z3_get_sort_kind", _U, _P, _P, checked=False)
# Checked: the rest.
_ast_id = _native("Z3_get_ast_id", _U, _P, _P)
_is_numeral_ast = _native("Z3_is_numeral_ast", ctypes.c_bool, _P, _P)
_is_algebraic = _native("Z3_is_algebraic_number", ctypes.c_bool, _P, _P)
_symbol_kind = _native("Z3_get_symbol_kind", _U, _P, _P)
_symbol_int = _native("Z3_get_symbol_int", ctypes.c_int, _P, _P)
_symbol_string = _native("Z3_get_symbol_string", ctypes.c_char_p, _P, _P)
_array_arity = _native("Z3_get_array_arity", _U, _P, _P)
_array_range = _native("Z3_get_array_sort_range", _P, _P, _P)
_array_domain_n = _native("Z3_get_array_sort_domain_n", _P, _P, _P, _U)
_sort_name = _native("Z3_get_sort_name", _P, _P, _P)
_arity = _native("Z3_get_arity", _U, _P, _P)
_domain = _native("Z3_get_domain", _P, _P, _P, _U)
_range = _native("Z3_get_range", _P, _P, _P)
_decl_name = _native("Z3_get_decl_name", _P, _P, _P)
_numeral_string = _native("Z3_get_numeral_string", ctypes.c_char_p, _P, _P)
_index_value = _native("Z3_get_index_value", _U, _P, _P)
_is_lambda = _native("Z3_is_lambda", ctypes.c_bool, _P, _P)
_is_forall = _native("Z3_is_quantifier_forall", ctypes.c_bool, _P, _P)
_num_bound = _native("Z3_get_quantifier_num_bound", _U, _P, _P)
_bound_name = _native("Z3_get_quantifier_bound_name", _P, _P, _P, _U)
_bound_sort = _native("Z3_get_quantifier_bound_sort", _P, _P, _P, _U)
_quantifier_body = _native("Z3_get_quantifier_body", _P, _P, _P)


def _symbol_text(c: int, s: int) -> str:
    if _symbol_kind(c, s) == z3.Z3_INT_SYMBOL:
        return f"k!{_symbol_int(c, s)}"
    return str(_symbol_string(c, s))


def _ptr(x: Any) -> int:
    """The C pointer of a z3py object's handle (its context's, its AST's)."""
    return int(x.value)


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


# --- decoded nodes, shared by the queries of one obligation ---------------------------------
# Reading a node through the C API (kind, decl, decl kind, arguments, Boolean or not) costs
# more than printing it, and the queries of one obligation (three modes per VC, VCs sharing
# hypotheses) read the same nodes again and again. What a node is does not depend on the mode,
# the frame or the polarity, so it is read once, kept by its pointer. A pointer names one node
# only while the node lives: the cache holds every formula it was filled from (the roots), so
# every node it knows stays alive, and its pointer cannot be reused, for the cache's life. The
# texts are the same with the cache or without (the statements docs/model.md §6.4 pins).

#: (AST kind, decl, decl kind, arguments, Boolean sort?); for a bound variable its de Bruijn
#: index stands in the decl's place; decl and kind are 0 for any other non-application.
_Node = tuple[int, int, int, tuple[int, ...], bool]
#: A declaration's (name, domain sorts, range sort).
_Decl = tuple[str, tuple[int, ...], int]
#: A cache holding more nodes is dropped at the next query that starts a new one.
_NODES_MAX = 200_000


class _Nodes:
    """Decoded nodes of one context, and the formulas (roots) that keep them alive."""

    __slots__ = ("c", "ctx", "decls", "nodes", "roots")

    def __init__(self, ctx: z3.Context) -> None:
        self.ctx = ctx                      # held: the context's pointer stays its own
        self.c = _ptr(ctx.ref())
        self.roots: dict[int, z3.ExprRef] = {}
        self.nodes: dict[int, _Node] = {}
        self.decls: dict[int, _Decl] = {}

    def decode(self, a: int) -> _Node:
        """Read node ``a`` (reachable from a root) and keep it."""
        c = self.c
        kind = _ast_kind(c, a)
        if kind == z3.Z3_APP_AST or kind == z3.Z3_NUMERAL_AST:
            d = _app_decl(c, a)
            node = (kind, d, _decl_kind(c, d),
                    tuple([_app_arg(c, a, i) for i in range(_app_num_args(c, a))]),
                    _sort_kind(c, _get_sort(c, a)) == z3.Z3_BOOL_SORT)
        elif kind == z3.Z3_VAR_AST:
            node = (kind, _index_value(c, a), 0, (),
                    _sort_kind(c, _get_sort(c, a)) == z3.Z3_BOOL_SORT)
        elif kind == z3.Z3_QUANTIFIER_AST:
            node = (kind, 0, 0, (), _sort_kind(c, _get_sort(c, a)) == z3.Z3_BOOL_SORT)
        else:       # not an expression (no sort): the printer refuses it
            node = (kind, 0, 0, (), False)
        self.nodes[a] = node
        return node

    def decl(self, d: int) -> _Decl:
        """Read declaration ``d`` (of a node kept) and keep it."""
        out = self.decls.get(d)
        if out is None:
            c = self.c
            out = self.decls[d] = (
                _symbol_text(c, _decl_name(c, d)),
                tuple([_domain(c, d, i) for i in range(_arity(c, d))]), _range(c, d))
        return out


# One cache per thread (a Z3 context is used by one thread). It keeps the last obligation's
# formulas alive until the thread's next obligation starts a new one: a bounded cost.
_local = threading.local()


def _nodes_for(forms: list[z3.BoolRef]) -> _Nodes:
    """The node cache for a query of ``forms``, which it then holds: the last query's cache if
    the query is in the same context and shares a hypothesis with the queries before (the next
    VC, mode or abstraction of one obligation), else a new one (the old one and its roots let
    go, so the cache holds about one obligation's terms)."""
    ctx = forms[0].ctx
    c = _ptr(ctx.ref())
    ptrs = [_ptr(f.as_ast()) for f in forms]
    cache: _Nodes | None = getattr(_local, "nodes", None)
    if (cache is None or cache.c != c or len(cache.nodes) > _NODES_MAX
            or not any(p in cache.roots for p in ptrs[:-1])):
        cache = _local.nodes = _Nodes(ctx)
    for p, f in zip(ptrs, forms, strict=True):
        cache.roots.setdefault(p, f)
    return cache


class _Printer:
    """One query's printer: declarations found on the way, the logic's features, memo.

    ASTs are handled as their C pointers (ints): every one is reachable from the query's
    formulas, which the caller holds for the printer's life, so within one query a pointer names
    one term (Z3 shares equal terms: equal terms, equal pointers), as its AST id would."""

    def __init__(self, ctx: z3.Context, mode: Mode, open_premises: bool,
                 nodes: _Nodes) -> None:
        self.c = _ptr(ctx.ref())
        self.cache = nodes
        self.known = self.cache.nodes
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
    def _sym(self, s: int) -> str:
        return _symbol_text(self.c, s)

    def _new_name(self, base: str) -> str:
        name, n = _quote(base), 1
        while name in self.used:
            n += 1
            name = _quote(f"{base}~{n}")
        self.used.add(name)
        return name

    def sort(self, s: int) -> str:
        c = self.c
        k = _sort_kind(c, s)
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
            n = _array_arity(c, s)
            out = self.sort(_array_range(c, s))
            for i in reversed(range(n)):
                out = f"(Array {self.sort(_array_domain_n(c, s, i))} {out})"
            return out
        if k == z3.Z3_UNINTERPRETED_SORT:
            self.uf = True
            name = _quote(self._sym(_sort_name(c, s)))
            self.sorts.setdefault(name, f"(declare-sort {name} 0)")
            return name
        raise NotStandard(f"a sort of kind {k} has no standard rendering here")

    def symbol(self, d: int) -> str:
        name = self.decl_names.get(d)
        if name is None:
            base, domain, range_ = self.cache.decl(d)
            dom = " ".join(self.sort(s) for s in domain)
            rng = self.sort(range_)
            name = self._new_name(base)
            if domain:
                self.uf = True
            self.decls.append(f"(declare-fun {name} ({dom}) {rng})")
            self.decl_names[d] = name
        return name

    def fresh(self, base: str, sort: str) -> str:
        name = self._new_name(base)
        self.decls.append(f"(declare-fun {name} () {sort})")
        return name

    # --- terms -------------------------------------------------------------------------------
    def term(self, a: int, frame: tuple[str, ...], pol: int = 0) -> str:
        # The text of a term depends on the names its free de Bruijn variables stand for and,
        # at the Boolean top level, on its polarity: memoised on both, a shared subterm costs
        # one rendering.
        key = (a, frame, pol)
        out = self.memo.get(key)
        if out is None:
            out = self.memo[key] = self._term(a, frame, pol)
        return out

    def node(self, a: int) -> _Node:
        return self.known.get(a) or self.cache.decode(a)

    def _term(self, a: int, frame: tuple[str, ...], pol: int) -> str:
        c = self.c
        kind, d, k, args, is_bool = self.known.get(a) or self.cache.decode(a)
        if kind == z3.Z3_VAR_AST:
            i = d                                   # the variable's index (_Node)
            if i >= len(frame):
                raise NotStandard("a free de Bruijn variable")
            return str(frame[i])
        if kind == z3.Z3_QUANTIFIER_AST:
            return self._quantifier(a, frame, pol)
        if kind == z3.Z3_NUMERAL_AST:
            return self._numeral(a)
        if kind != z3.Z3_APP_AST:
            raise NotStandard(f"an AST of kind {kind}")
        n = len(args)
        if self.mode is Mode.PROPOSITIONAL and is_bool:
            connective = (k in _CONNECTIVE or (k == z3.Z3_OP_UNINTERPRETED and n == 0)
                          or (k in (z3.Z3_OP_EQ, z3.Z3_OP_ITE) and self.node(args[-1])[4]))
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
        raise NotStandard(f"operator {self._sym(_decl_name(c, d))} (kind {k}) has "
                          "no standard rendering here")

    def _atom(self, a: int, frame: tuple[str, ...]) -> str:
        key = (a, frame)
        if key not in self.atoms:
            self.atoms[key] = self.fresh(f"!atom{len(self.atoms) + 1}", "Bool")
        return self.atoms[key]

    def _numeral(self, a: int) -> str:
        c = self.c
        k = _sort_kind(c, _get_sort(c, a))
        fr = Fraction(_numeral_string(c, a))
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

    def _is_numeral(self, a: int) -> bool:
        kind, _, k, args, _ = self.node(a)
        if kind == z3.Z3_NUMERAL_AST:
            return True
        if kind == z3.Z3_APP_AST and len(args) == 1 and k in (z3.Z3_OP_TO_REAL, z3.Z3_OP_UMINUS):
            return self._is_numeral(args[0])
        return False

    def _quantifier(self, a: int, frame: tuple[str, ...], pol: int) -> str:
        c = self.c
        if _is_lambda(c, a):
            raise NotStandard("a lambda term that is not applied (not beta-reducible)")
        forall = _is_forall(c, a)
        nv = _num_bound(c, a)
        names = [self._sym(_bound_name(c, a, i)) for i in range(nv)]
        sorts = [_bound_sort(c, a, i) for i in range(nv)]
        body = _quantifier_body(c, a)
        if self.mode is not Mode.PROPOSITIONAL and pol != 0 and forall == (pol < 0):
            # An outer existential: its variables become fresh constants (skolemisation).
            self.skolems += 1
            sk = [self.fresh(f"{nm}!sk{self.skolems}", self.sort(s))
                  for nm, s in zip(names, sorts)]
            return self.term(body, tuple(reversed(sk)) + frame, pol)
        if self.mode is not Mode.FULL:
            return self._atom(a, frame)
        self.quantifiers = True
        qn = self.qindex.setdefault(a, len(self.qindex) + 1)
        bound = [_quote(f"{nm}!{qn}.{i}") for i, nm in enumerate(names)]
        decl = " ".join(f"({b} {self.sort(s)})" for b, s in zip(bound, sorts))
        text = self.term(body, tuple(reversed(bound)) + frame)
        return f"({'forall' if forall else 'exists'} ({decl}) {text})"

    def _select(self, args: tuple[int, ...], frame: tuple[str, ...]) -> str:
        c = self.c
        arr, idx = args[0], [self.term(x, frame) for x in args[1:]]
        if self.node(arr)[0] == z3.Z3_QUANTIFIER_AST and _is_lambda(c, arr):
            # Beta reduction: the lambda's variables stand for the index texts.
            if _num_bound(c, arr) != len(idx):
                raise NotStandard("a lambda applied to the wrong number of indices")
            return self.term(_quantifier_body(c, arr), tuple(reversed(idx)) + frame)
        out = self.term(arr, frame)
        for i in idx:
            out = f"(select {out} {i})"
        return out

    def _store(self, args: tuple[int, ...], frame: tuple[str, ...]) -> str:
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

    def _power(self, args: tuple[int, ...], frame: tuple[str, ...]) -> str:
        c = self.c
        base, ex = args
        if self.node(ex)[0] == z3.Z3_NUMERAL_AST:
            n = Fraction(_numeral_string(c, ex))
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
    pr = _Printer(forms[0].ctx, mode, open_premises, _nodes_for(forms))
    body = [f"(assert {pr.term(_ptr(f.as_ast()), (), 1)})" for f in forms]
    head = [f"(set-logic {pr.logic()})", *pr.sorts.values(), *pr.decls]
    text = "\n".join(head + body + ["(check-sat)", "(exit)"]) + "\n"
    return SmtLib(text, pr.logic(), hashlib.sha256(text.encode()).hexdigest(), len(pr.atoms))
