"""A small while-language with weakest preconditions, producing verification conditions for Z3.

Commands: Skip, Assign, Store (array update), Seq, If, While (with invariant and variant), For
(a counted loop, sugar for While), Assume and Havoc (to model a callee by its contract). The
rules are Dijkstra's; a loop contributes its invariant to the enclosing precondition, its exit
condition with the loop's modified variables universally quantified (so facts about the other
variables flow past the loop), and a side VC: the invariant is preserved. Partial correctness
and termination are generated separately: for termination every loop adds that its variant is
>= 0 while it runs and decreases in every iteration. All VCs of both valid => total correctness.

Smoke tests (``smoke_tests``, after Frama-C WP's): every Assume, every branch of an If, every
case its condition names, and every loop's entry, body and exit must be reachable from the
precondition. Each point in turn is marked by a command whose weakest precondition is a fresh
Boolean ``smoke!point``; the VCs of the marked program are generated for the postcondition
true, and the one holding the mark is taken with the mark set to false: it is valid iff no
state reaches the point (there wp(abort) = false), so the smoke test is its negation, which
must be satisfiable. The point's context is what the VC knows there: the precondition and the
path through ifs and assumes at the top level, the loop invariant (and guard) inside a loop
body. An Assume's cases are the branch conditions its condition names (the premises g of
conjuncts g => ..., and both ways of a conditional): an Assume that leaves one of them
impossible, such as a callee's contract strengthened to "the search always finds a path", is
vacuous there.
"""

from __future__ import annotations

from dataclasses import dataclass

import z3

from ._obligation import VC, Smoke
from ._z3vec import constants

__all__ = [
    "Assign",
    "Assume",
    "Cmd",
    "For",
    "Havoc",
    "If",
    "Seq",
    "Skip",
    "Store",
    "While",
    "modifies",
    "smoke_tests",
    "verification_conditions",
    "wp",
]


@dataclass(frozen=True)
class Skip:
    pass


@dataclass(frozen=True)
class Assign:
    """var := value."""

    var: z3.ExprRef
    value: z3.ExprRef


@dataclass(frozen=True)
class Store:
    """array[index...] := value."""

    array: z3.ExprRef
    index: tuple[z3.ExprRef, ...]
    value: z3.ExprRef


@dataclass(frozen=True)
class Seq:
    cmds: tuple[Cmd, ...]


@dataclass(frozen=True)
class If:
    cond: z3.BoolRef
    then: Cmd
    orelse: Cmd = Skip()


@dataclass(frozen=True)
class While:
    """while cond invariant inv variant var do body; ``label`` names its VCs."""

    label: str
    cond: z3.BoolRef
    invariant: z3.BoolRef
    variant: z3.ArithRef
    body: Cmd


@dataclass(frozen=True)
class For:
    """for var in [lo, hi) invariant inv do body (body may modify neither var nor lo, hi).

    Means var := lo; while var < hi invariant (lo <= var <= max(lo, hi) ∧ inv)
    variant hi - var do (body; var := var + 1).
    """

    label: str
    var: z3.ArithRef
    lo: z3.ArithRef
    hi: z3.ArithRef
    invariant: z3.BoolRef
    body: Cmd

    def desugar(self, counters_only: bool = False) -> Seq:
        """The While loop this For means; ``counters_only`` keeps just lo <= var <= hi as the
        invariant (all termination needs: the body can change neither var nor the bounds)."""
        reads = {_key(c) for c in _consts(self.lo) + _consts(self.hi)} | {_key(self.var)}
        clash = reads & {_key(v) for v in modifies(self.body)}
        if clash:
            raise ValueError(f"loop {self.label}: body modifies its counter or bounds {sorted(clash)}")
        # range(lo, hi) in Python: runs no iteration when hi <= lo, leaving var at lo.
        top = z3.If(self.hi >= self.lo, self.hi, self.lo)
        bounds = z3.And(self.lo <= self.var, self.var <= top)
        inv = bounds if counters_only else z3.And(bounds, self.invariant)
        return Seq((Assign(self.var, self.lo),
                    While(self.label, self.var < self.hi, inv, self.hi - self.var,
                          Seq((self.body, Assign(self.var, self.var + 1))))))


@dataclass(frozen=True)
class Assume:
    """Continue only in states where cond holds (a callee's postcondition)."""

    cond: z3.BoolRef


@dataclass(frozen=True)
class Havoc:
    """Give the variables arbitrary values (a callee's outputs)."""

    vars: tuple[z3.ExprRef, ...]


@dataclass(frozen=True)
class _Mark:
    """A smoke test's marker: wp(mark, Q) = the Boolean ``smoke!<tag>``, whatever Q."""

    tag: str

    @property
    def flag(self) -> z3.BoolRef:
        return z3.Bool(f"smoke!{self.tag}")


Cmd = Skip | Assign | Store | Seq | If | While | For | Assume | Havoc | _Mark


def modifies(c: Cmd) -> list[z3.ExprRef]:
    """The variables a command may change, each once, in order of first appearance."""
    out: dict[tuple[str, str], z3.ExprRef] = {}

    def walk(c: Cmd) -> None:
        if isinstance(c, Assign):
            out.setdefault(_key(c.var), c.var)
        elif isinstance(c, Store):
            out.setdefault(_key(c.array), c.array)
        elif isinstance(c, Seq):
            for x in c.cmds:
                walk(x)
        elif isinstance(c, If):
            walk(c.then)
            walk(c.orelse)
        elif isinstance(c, While):
            walk(c.body)
        elif isinstance(c, For):
            out.setdefault(_key(c.var), c.var)
            walk(c.body)
        elif isinstance(c, Havoc):
            for v in c.vars:
                out.setdefault(_key(v), v)
    walk(c)
    return list(out.values())


class _Gen:
    """Collects side VCs and hands out deterministic names for quantified copies of variables."""

    def __init__(self, termination: bool = False, collect: bool = True) -> None:
        self.side: list[VC] = []
        self.counter = 0
        self.termination = termination
        self.collect = collect      # False: no side VCs (a smoke test needs one VC only)

    def fresh(self, v: z3.ExprRef, label: str) -> z3.ExprRef:
        self.counter += 1
        return z3.Const(f"{v}@{label}#{self.counter}", v.sort())


def wp(c: Cmd, post: z3.BoolRef, gen: _Gen | None = None) -> z3.BoolRef:
    """The weakest precondition of c for post; side VCs of loops go into ``gen.side``."""
    g = gen if gen is not None else _Gen()
    return _wp(c, post, g)


def _wp(c: Cmd, q: z3.BoolRef, g: _Gen) -> z3.BoolRef:
    if isinstance(c, Skip):
        return q
    if isinstance(c, Assign):
        return z3.substitute(q, (c.var, c.value))
    if isinstance(c, Store):
        return z3.substitute(q, (c.array, z3.Store(c.array, *c.index, c.value)))
    if isinstance(c, Seq):
        for x in reversed(c.cmds):
            q = _wp(x, q, g)
        return q
    if isinstance(c, If):
        return z3.And(z3.Implies(c.cond, _wp(c.then, q, g)),
                      z3.Implies(z3.Not(c.cond), _wp(c.orelse, q, g)))
    if isinstance(c, For):
        return _wp(c.desugar(counters_only=g.termination), q, g)
    if isinstance(c, Assume):
        return z3.Implies(c.cond, q)
    if isinstance(c, Havoc):
        return _forall_fresh(list(c.vars), q, g, "havoc")
    if isinstance(c, _Mark):
        return c.flag
    if isinstance(c, While):
        return _wp_while(c, q, g)
    raise TypeError(f"not a command: {c!r}")


def _forall_fresh(vs: list[z3.ExprRef], q: z3.BoolRef, g: _Gen, label: str) -> z3.BoolRef:
    """∀ vs. q, with the bound copies named deterministically."""
    if not vs:
        return q
    fresh = [g.fresh(v, label) for v in vs]
    return z3.ForAll(fresh, z3.substitute(q, *zip(vs, fresh)))


def _wp_while(c: While, q: z3.BoolRef, g: _Gen) -> z3.BoolRef:
    inv, cond = c.invariant, c.cond
    kind = "termination" if g.termination else "correctness"
    # Preservation: one iteration from a state where the invariant and the guard hold.
    if g.collect:
        g.side.append(VC(f"{c.label}.preserve", (("invariant", inv), ("guard", cond)),
                         _wp(c.body, inv, g), key_premise="invariant", kind=kind))
    if g.termination and g.collect:
        # The variant is bounded below while the loop runs, and every iteration lowers it; V0
        # is its value at the start of the iteration. The bound needs the guard: without it a
        # For loop with hi < lo sits at var = lo > hi, a negative variant.
        v0 = z3.Int(f"{c.label}.V0")
        g.side.append(VC(f"{c.label}.variant_bounded", (("invariant", inv), ("guard", cond)),
                         c.variant >= 0, key_premise="guard", kind=kind))
        # Nested loops' side VCs do not depend on the postcondition and were just collected
        # by the preservation VC's wp: compute this one with a scratch collector.
        scratch = _Gen(termination=True)
        scratch.counter = g.counter
        decreases = _wp(c.body, c.variant < v0, scratch)
        g.counter = scratch.counter
        g.side.append(VC(f"{c.label}.variant_decreases",
                         (("invariant", inv), ("guard", cond), ("entry", c.variant == v0)),
                         decreases, key_premise="entry", kind=kind))
    # Exit: whatever the loop did to the variables it modifies, invariant ∧ ¬guard gives q.
    return z3.And(inv, _forall_fresh(modifies(c.body), z3.Implies(z3.And(inv, z3.Not(cond)), q),
                                     g, c.label))


def verification_conditions(name: str, pre: z3.BoolRef, c: Cmd, post: z3.BoolRef,
                            *, termination: bool = False,
                            witness: tuple[tuple[z3.ExprRef, z3.ExprRef], ...] = ()
                            ) -> tuple[VC, ...]:
    """{pre} c {post}: the main VC pre => wp(c, post), then every loop's preservation VC.

    With ``termination``: the VCs that c terminates from pre instead; For loops keep only their
    counter bounds as invariant (inductive on their own), every loop adds its variant's VCs,
    and the main VC shows the bounds hold on entry (post is ignored)."""
    g = _Gen(termination=termination)
    goal = _wp(c, z3.BoolVal(True) if termination else post, g)
    # For termination the entry condition is trivial for For loops: no key premise then.
    main = VC(f"{name}.main", (("pre", pre),), goal, witness=witness,
              key_premise=None if termination else "pre",
              kind="termination" if termination else "correctness")
    return (main, *g.side)


def _cases(cond: z3.BoolRef) -> list[z3.BoolRef]:
    """The branch conditions an Assume's condition names: g for each conjunct g => ..., and c
    and not c for each conjunct If(c, ...), in order, each once."""
    out: list[z3.BoolRef] = []
    todo = [cond]
    while todo:
        f = todo.pop(0)
        if z3.is_and(f):
            todo = list(f.children()) + todo
        elif z3.is_implies(f):
            out.append(f.arg(0))
        elif z3.is_app_of(f, z3.Z3_OP_ITE):
            out += [f.arg(0), z3.Not(f.arg(0))]
    uniq: list[z3.BoolRef] = []
    for g in out:
        if not any(z3.eq(g, h) for h in uniq):
            uniq.append(g)
    return uniq


def _short(f: z3.ExprRef, width: int = 60) -> str:
    text = " ".join(str(f).split())
    return text if len(text) <= width else text[: width - 3] + "..."


Marked = tuple[str, "Cmd", "While | None"]


def _marked(c: Cmd, m: _Mark, where: str = "") -> list[Marked]:
    """Every smoke-test point of c: (label, c with the mark at that point, the innermost loop
    whose body holds the mark, or None at the top level)."""
    at = f"{where}: " if where else ""
    out: list[Marked] = []
    if isinstance(c, Assume):
        out.append((f"{at}assume {_short(c.cond)}", Seq((c, m)), None))
        for g in _cases(c.cond):
            out.append((f"{at}assume ..., case {_short(g)}", Seq((c, Assume(g), m)), None))
    elif isinstance(c, If):
        cond = _short(c.cond)
        out.append((f"{at}if {cond}: then", If(c.cond, Seq((m, c.then)), c.orelse), None))
        out.append((f"{at}if {cond}: else", If(c.cond, c.then, Seq((m, c.orelse))), None))
        out += [(lbl, If(c.cond, x, c.orelse), loop)
                for lbl, x, loop in _marked(c.then, m, f"{at}if {cond}: then")]
        out += [(lbl, If(c.cond, c.then, x), loop)
                for lbl, x, loop in _marked(c.orelse, m, f"{at}if {cond}: else")]
    elif isinstance(c, Seq):
        for n, x in enumerate(c.cmds):
            out += [(lbl, Seq(c.cmds[:n] + (y,) + c.cmds[n + 1:]), loop)
                    for lbl, y, loop in _marked(x, m, where)]
    elif isinstance(c, For):
        return _marked(c.desugar(), m, where)
    elif isinstance(c, While):
        out.append((f"loop {c.label}: entry (invariant)", Seq((Assume(c.invariant), m, c)), None))
        body = While(c.label, c.cond, c.invariant, c.variant, Seq((m, c.body)))
        out.append((f"loop {c.label}: body (guard true)", body, body))
        out.append((f"loop {c.label}: exit (guard false)", Seq((c, m)), None))
        for lbl, x, loop in _marked(c.body, m, where):
            w = While(c.label, c.cond, c.invariant, c.variant, x)
            out.append((lbl, w, loop if loop is not None else w))
    return out


def smoke_tests(name: str, pre: z3.BoolRef, c: Cmd,
                witness: tuple[tuple[z3.ExprRef, z3.ExprRef], ...] = (),
                lemmas: tuple[tuple[str, z3.BoolRef], ...] = (),
                lemma_witness: tuple[tuple[z3.ExprRef, z3.ExprRef], ...] = ()
                ) -> tuple[Smoke, ...]:
    """The smoke tests of {pre} c (module docstring): one per Assume, Assume case, If branch
    and loop entry, body and exit; none may be unsatisfiable. ``witness`` pins constants (e.g.
    small sizes) to help Z3 find the models; a test unsat with the pins is retried without.
    ``lemmas`` and ``lemma_witness``: see ``Smoke`` (a model fixed by substitution, in which
    closed facts such as "no path exists" are proved, then taken as true)."""
    m = _Mark("point")
    out = []
    for label, prog, loop in _marked(c, m):
        # Only the VC that holds the mark: the main one at the top level, else the
        # preservation VC of the innermost loop around the mark (no other side VC is built).
        g = _Gen(collect=False)
        if loop is None:
            hyps: tuple[tuple[str, z3.BoolRef], ...] = (("pre", pre),)
            goal = _wp(prog, z3.BoolVal(True), g)
        else:
            hyps = (("invariant", loop.invariant), ("guard", loop.cond))
            goal = _wp(loop.body, loop.invariant, g)
        dead = z3.substitute(goal, (m.flag, z3.BoolVal(False)))
        if z3.eq(dead, goal):
            raise ValueError(f"smoke test {label!r}: the mark is not in its VC")
        out.append(Smoke(f"{name}: {label}", hyps, dead, witness, lemmas, lemma_witness))
    return tuple(out)


def _key(v: z3.ExprRef) -> tuple[str, str]:
    return (str(v), str(v.sort()))


def _consts(e: z3.ExprRef) -> list[z3.ExprRef]:
    """The uninterpreted constants occurring in e."""
    return constants(e)
