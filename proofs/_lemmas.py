"""Lemmas and their use by substitution (docs/model.md §10): the kit the safety theorem's proofs
are built with.

A lemma is a VC over free names; a proof that uses it instantiates it by substitution
(``Lemma.use``, ``Lemma.at``): its premises are then Z3's to discharge, and the facts it rests on
(the ledger's A3 instances and instances of other proved lemmas, true at any point) are carried
into the proof's hypotheses, substituted. An ``abstract`` lemma's VC keeps the norms abstract
(proofs/_z3vec.py's ``sq``, ``dt``): it is then proved for every sq and dt, hence for the
polynomials.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass
from typing import Any, cast

import z3

from ._obligation import VC, Obligation, Z3Query
from ._z3vec import Hyp, concrete

__all__ = ["CARRIED", "PROVED", "Lemma", "Pairs", "Substitution", "dedupe", "lemma",
           "obligation_vc", "pairs"]

#: A lemma's trigonometric facts (A3, assumed at any point): a proof that uses the lemma carries
#: them, substituted, into its own hypotheses. Its instances of other proved lemmas ("by ...")
#: are not carried: they hold wherever the norms mean |v|^2 and the dot product, where the
#: user's conclusion is read.
CARRIED = ("A3 ",)
PROVED = "by "

Pairs = Sequence[tuple[z3.ExprRef, z3.ExprRef]]


class Substitution:
    """``z3.substitute(f, *pairs)`` for many terms f at the same pairs: the same Z3 call
    (``Z3_substitute``, simultaneous), so the same term, but the pairs are checked (expressions of
    equal sorts, as z3.substitute checks them) and laid out once, not at every call, where
    z3.substitute's per-call check of the sorts dominated the cost of a proof's many
    substitutions at a lemma's hundreds of names."""

    def __init__(self, pairs: Pairs) -> None:
        self.pairs = tuple(pairs)        # held: the arrays below point into these terms
        for p in self.pairs:
            if not (isinstance(p, tuple) and len(p) == 2 and z3.is_expr(p[0])
                    and z3.is_expr(p[1])):
                raise TypeError(f"a substitution pair is two Z3 expressions, not {p!r}")
            # Sorts are hash-consed: equal iff the same Z3 object (z3's SortRef.eq), compared
            # without wrapping each in a SortRef.
            ctx = p[0].ctx_ref()
            if (z3.Z3_get_sort(ctx, p[0].as_ast()).value
                    != z3.Z3_get_sort(ctx, p[1].as_ast()).value):
                raise TypeError(f"substitution of {p[0]} ({p[0].sort()}) by {p[1]} "
                                f"({p[1].sort()}): the sorts differ")
        n = len(self.pairs)
        self._from = (z3.Ast * n)(*[a.as_ast() for a, _ in self.pairs])
        self._to = (z3.Ast * n)(*[b.as_ast() for _, b in self.pairs])

    def __call__(self, f: Any) -> Any:
        if not z3.is_expr(f):
            raise TypeError(f"substitution in {f!r}, not a Z3 expression")
        # z3.substitute's own last line, the pairs' arrays built above.
        return z3.z3._to_expr_ref(z3.Z3_substitute(f.ctx.ref(), f.as_ast(), len(self.pairs),
                                                   self._from, self._to), f.ctx)


@dataclass(frozen=True)
class Lemma:
    """A proved VC and the form a proof instantiates: ``hyps``/``goal`` in abstract norms
    (``vc`` holds them concrete unless the lemma is abstract: its VC is then proved for every
    sq, dt). ``names`` are its free names, by key, for ``at``."""

    vc: VC
    hyps: tuple[Hyp, ...]
    goal: z3.BoolRef
    names: tuple[tuple[str, object], ...] = ()

    def use(self, pairs: Pairs, at: str) -> list[Hyp]:
        """The hypotheses a proof adds to use this lemma at ``pairs`` (names -> terms): its
        trigonometric facts, substituted, and the lemma instantiated under its other premises.
        Sound: the lemma's VC is proved with those facts and its instances of proved lemmas
        as hypotheses, and the instances hold where the norms are |v|^2 (for an abstract
        lemma) or are none (for a concrete one)."""
        at_pairs = Substitution(pairs)

        def sub(f: Any) -> Any:
            return at_pairs(f) if pairs else f
        carried = [(n, h) for n, h in self.hyps if n.startswith(CARRIED)]
        rest = [h for n, h in self.hyps if not n.startswith(CARRIED + (PROVED,))]
        out = [(f"{n} [{at}]", sub(h)) for n, h in carried]
        body = z3.Implies(z3.And(rest), self.goal) if rest else self.goal
        out.append((f"by {self.vc.name} at {at}", sub(body)))
        return out

    def at(self, at: str, **terms: object) -> list[Hyp]:
        """``use`` with the free names given by key (a vector name takes a pair of terms)."""
        names = dict(self.names)
        unknown = set(terms) - set(names)
        if unknown:
            raise KeyError(f"{self.vc.name} has no names {sorted(unknown)}")
        return self.use(pairs(*[(names[k], v) for k, v in terms.items()]), at)

    def term(self, f: z3.ExprRef, **terms: object) -> z3.ExprRef:
        """A term in this lemma's names, at ``terms``."""
        names = dict(self.names)
        ps = pairs(*[(names[k], v) for k, v in terms.items()])
        return z3.substitute(f, *ps) if ps else f


def lemma(name: str, hyps: Sequence[Hyp], goal: z3.BoolRef, key: str, *, abstract: bool = False,
          names: dict[str, object] | None = None, witness: Pairs = (),
          counter_witness: Pairs = (), z3_tactic: str | None = None) -> Lemma:
    """The lemma ``hyps`` imply ``goal`` (``key`` the premise its negative test drops), as a VC
    over the abstract norms (``abstract``) or the polynomials; ``z3_tactic``: the solver of its
    proof check (``VC.z3_tactic``)."""
    hyps = dedupe(hyps)
    if key not in [n for n, _ in hyps]:
        raise KeyError(f"{name}: no hypothesis {key!r}")
    if abstract:
        vc = VC(name, hyps, goal, key_premise=key, witness=tuple(witness),
                counter_witness=tuple(counter_witness), z3_tactic=z3_tactic)
    else:
        vc = VC(name, tuple((n, concrete(h)) for n, h in hyps), concrete(goal), key_premise=key,
                witness=tuple(witness), counter_witness=tuple(counter_witness),
                z3_tactic=z3_tactic)
    return Lemma(vc, hyps, goal, tuple((names or {}).items()))


def dedupe(hyps: Sequence[Hyp]) -> tuple[Hyp, ...]:
    """``hyps`` without the repeats of a formula (the first kept), names' spaces normalised."""
    out: list[Hyp] = []
    # z3.eq is identity of the hash-consed terms of one context: their (context, id) while they
    # are alive (``out`` holds them), looked up in a set rather than compared pairwise.
    seen: set[tuple[int, int]] = set()
    for n, h in hyps:
        key = (id(h.ctx), h.get_id())
        if key in seen:
            continue
        seen.add(key)
        out.append((" ".join(n.split()), h))
    return tuple(out)


def pairs(*groups: tuple[object, object]) -> list[tuple[z3.ExprRef, z3.ExprRef]]:
    """Substitution pairs; a vector pairs component by component."""
    out: list[tuple[z3.ExprRef, z3.ExprRef]] = []
    for name, term in groups:
        if isinstance(name, tuple):
            out += list(zip(name, cast("Sequence[z3.ExprRef]", term)))
        else:
            out.append((cast(z3.ExprRef, name), cast(z3.ExprRef, term)))
    return out


def obligation_vc(ident: str, vc_name: str, obligations: Sequence[Obligation]) -> VC:
    """A VC of another obligation, as the prove run discharges it."""
    ob = next(o for o in obligations if o.id == ident)
    q = ob.build()
    assert isinstance(q, Z3Query)
    return next(v for v in q.vcs if v.name == vc_name)
