"""How deep a proved VC is: the weakest reasoning that proves it, found by running it.

Levels, weakest first:

- ``propositional``: the Boolean abstraction of the proof check (hypotheses and the negated
  goal) is unsat. Every Boolean term whose head is not a connective (an equation, an
  inequality, an application of a predicate, a quantified formula) is replaced by a fresh
  Boolean constant, equal terms by the same one (``_smtlib.Mode.PROPOSITIONAL``). The VC then
  holds by its Boolean skeleton: it would hold for any meaning of its atoms.
- ``ground``: the check, with its outer existentials skolemised and every quantified formula
  left replaced by a fresh Boolean constant (equal ones by the same), is unsat
  (``_smtlib.Mode.GROUND``). Z3 then proves it with its theories (arithmetic, arrays,
  uninterpreted functions) and no quantifier instantiated: there is none left to instantiate.
  Skolemising is not instantiation (it names the witness of an existential, keeping
  satisfiability), and a lambda applied by ``select`` is beta-reduced as the text is written.
  This is the sound reading of "no quantifier instantiated": turning off Z3's e-matching and
  MBQI instead would leave its preprocessing free to eliminate quantifiers (destructive
  equality resolution, macro finding), which is instantiation by another name. A VC with no
  quantifier left once skolemised (nothing abstracted) is ground by its own proof.
- ``full``: neither abstraction is unsat (or the solver did not decide it within
  ``DEPTH_RLIMIT``, Z3's deterministic resource count, so the level does not depend on the
  machine's load; ``DEPTH_TIMEOUT_MS`` times ``_limits.WALL_NET_FACTOR`` is a wall-clock safety
  net); the proof needs quantifier instantiation (or more work).

Both abstractions over-approximate the check (a model of the check gives one of the
abstraction), so their unsat is a proof of the VC by the weaker reasoning: the level is an upper
bound on the weakest reasoning that proves it, exact unless a check ran out of time. The texts
are standard SMT-LIB (``_smtlib``), parsed by Z3.
"""

from __future__ import annotations

import z3

from ._smtlib import (
    Mode,
    NotStandard,
    _app_arg,
    _app_decl,
    _app_num_args,
    _ast_id,
    _ast_kind,
    _decl_kind,
    _get_sort,
    _is_algebraic,
    _is_numeral_ast,
    _ptr,
    _quantifier_body,
    _sort_kind,
    smtlib_query,
)

__all__ = ["DEPTH_RLIMIT", "DEPTH_TIMEOUT_MS", "LEVELS", "NonlinearMemo", "deepest", "is_nonlinear",
           "vc_depth"]

#: Per abstraction check; the abstractions are small, or they fail fast.
DEPTH_TIMEOUT_MS = 3_000
#: Z3's resource limit per abstraction check: every abstraction proved unsat on the bundled
#: obligations needs under 5 000 (docs/model.md §6.4), a satisfiable one up to about 550 000.
DEPTH_RLIMIT = 1_000_000

#: Weakest first.
LEVELS = ("propositional", "ground", "full")


def _unsat(text: str, timeout_ms: int, ctx: z3.Context | None, rlimit: int | None = None
           ) -> bool:
    """Whether Z3 shows ``text`` unsat within ``rlimit`` (resource count, counted from the
    check's start) and ``timeout_ms`` (wall clock)."""
    s = z3.Solver(ctx=ctx or z3.Context())
    s.set("timeout", timeout_ms)
    if rlimit is not None:
        s.set("rlimit", rlimit)
    s.from_string(text)
    return bool(s.check() == z3.unsat)


def vc_depth(hypotheses: list[z3.BoolRef], goal: z3.BoolRef,
             timeout_ms: int = DEPTH_TIMEOUT_MS, ctx: z3.Context | None = None,
             rlimit: int | None = DEPTH_RLIMIT) -> str:
    """The weakest level (LEVELS) at which ``hypotheses ∧ ¬goal`` is unsat; call it only for
    a VC already proved (the level is then ``full`` at worst). The abstractions are parsed
    into ``ctx`` (default: a fresh context), each by a fresh solver, under ``rlimit`` (None:
    ``timeout_ms`` alone; with it, ``timeout_ms`` is only a safety net, made that much
    longer)."""
    from ._limits import wall_net_ms

    timeout_ms = wall_net_ms(timeout_ms, rlimit)
    for level, mode in (("propositional", Mode.PROPOSITIONAL), ("ground", Mode.GROUND)):
        try:
            q = smtlib_query(hypotheses, goal, mode)
        except NotStandard:
            continue
        if mode is Mode.GROUND and q.abstracted == 0:
            # Nothing was abstracted: once skolemised the check has no quantifier at all, and
            # it is the proof itself (proved unsat), which instantiated nothing.
            return level
        if _unsat(q.text, timeout_ms, ctx, rlimit):
            return level
    return "full"


def deepest(levels: list[str]) -> str | None:
    """An obligation is as deep as its deepest VC (None: no proved VC)."""
    return max(levels, key=LEVELS.index) if levels else None


_NONLINEAR_OPS = frozenset((z3.Z3_OP_MUL, z3.Z3_OP_DIV, z3.Z3_OP_IDIV, z3.Z3_OP_MOD,
                            z3.Z3_OP_REM, z3.Z3_OP_POWER))
_CONSTANT_OPS = frozenset((z3.Z3_OP_UMINUS, z3.Z3_OP_MUL, z3.Z3_OP_ADD, z3.Z3_OP_SUB,
                           z3.Z3_OP_DIV, z3.Z3_OP_TO_REAL))


class NonlinearMemo:
    """What ``is_nonlinear`` found of formulas already scanned, for later calls: VCs of one
    obligation share most hypotheses, each then scanned once. It holds the formulas it knows
    (so their AST ids, its keys, name them for its life), in any number of contexts. The
    flag (docs/model.md §6.4) is the same with a memo or without."""

    __slots__ = ("_known",)

    def __init__(self) -> None:
        self._known: dict[tuple[int, int], tuple[z3.ExprRef, bool]] = {}


class _Scan:
    """One call's scan: a DAG walk over the C API (``_smtlib``'s direct calls), every AST
    visited once (keyed by its pointer: all are reachable from formulas the caller holds)."""

    def __init__(self, ctx: z3.Context) -> None:
        self.c = _ptr(ctx.ref())
        self.seen: set[int] = set()
        self.constant: dict[int, bool] = {}

    def _constant_value(self, a: int) -> bool:
        """A numeral, or arithmetic of numerals only (e.g. -(1/2), 3 * 7)."""
        out = self.constant.get(a)
        if out is None:
            out = self.constant[a] = self._constant(a)
        return out

    def _constant(self, a: int) -> bool:
        c = self.c
        kind = _ast_kind(c, a)
        if kind not in (z3.Z3_APP_AST, z3.Z3_NUMERAL_AST):
            return False
        sk = _sort_kind(c, _get_sort(c, a))
        # z3.is_int_value / is_rational_value / is_algebraic_value: an Int or Real numeral,
        # or a Real algebraic number.
        if (sk == z3.Z3_INT_SORT or sk == z3.Z3_REAL_SORT) and (
                _is_numeral_ast(c, a) or (sk == z3.Z3_REAL_SORT and _is_algebraic(c, a))):
            return True
        n = _app_num_args(c, a)
        if n > 0 and _decl_kind(c, _app_decl(c, a)) in _CONSTANT_OPS:
            return all(self._constant_value(_app_arg(c, a, i)) for i in range(n))
        return False

    def nonlinear(self, root: int) -> bool:
        """Whether the term ``root`` holds nonlinear arithmetic, skipping the subterms an
        earlier root of this scan reached (each was found linear, or the scan would have
        stopped)."""
        c = self.c
        seen = self.seen
        todo = [root]
        while todo:
            a = todo.pop()
            if a in seen:
                continue
            seen.add(a)
            kind = _ast_kind(c, a)
            if kind == z3.Z3_QUANTIFIER_AST:
                todo.append(_quantifier_body(c, a))
                continue
            if kind != z3.Z3_APP_AST and kind != z3.Z3_NUMERAL_AST:
                continue
            n = _app_num_args(c, a)
            args = [_app_arg(c, a, i) for i in range(n)]
            if n >= 2:
                op = _decl_kind(c, _app_decl(c, a))
                if op in _NONLINEAR_OPS and (
                        sum(not self._constant_value(x) for x in args) >= 2
                        if op == z3.Z3_OP_MUL else not self._constant_value(args[1])):
                    return True
            todo.extend(args)
        return False


def _formula_key(f: z3.ExprRef) -> tuple[int, int]:
    # AST ids are per context: two contexts number their terms alike.
    c = _ptr(f.ctx.ref())
    return c, _ast_id(c, _ptr(f.as_ast()))


def is_nonlinear(formulas: list[z3.ExprRef], memo: NonlinearMemo | None = None) -> bool:
    """Whether the formulas hold nonlinear arithmetic: a product of two non-constant terms, or a
    division, modulus or power whose divisor or exponent is not a numeral (quantifier bodies
    included). This is not what ``depth`` measures (quantifier instantiation): a VC can be
    ground and nonlinear, or full and linear. ``memo`` (one per obligation, say) keeps each
    formula's answer for later calls; the answer is the same with it or without."""
    scans: dict[int, _Scan] = {}
    for f in formulas:
        key = _formula_key(f)
        if memo is not None and key in memo._known:
            answer = memo._known[key][1]
        else:
            scan = scans.get(key[0])
            if scan is None:
                scan = scans[key[0]] = _Scan(f.ctx)
            answer = scan.nonlinear(_ptr(f.as_ast()))
            if memo is not None:
                memo._known[key] = (f, answer)
        if answer:
            return True
    return False
