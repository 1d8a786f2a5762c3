"""Z3's text of a sub-list of formulas, cut from one print (proofs/_z3text.py): byte for byte
the text printing the sub-list gives, on every bundled VC and premise control and on small
cases made to break a splitter (quoted symbols, strings, sorts, bound names)."""

from __future__ import annotations

import functools
import itertools
import re
from collections.abc import Callable, Iterator
from typing import Any

import pytest
import z3

from cfmpa.proofs import Method, Z3Query, _controls, _obligation, _z3text, collect_obligations
from cfmpa.proofs._obligation import _check_texts, _text_of
from cfmpa.proofs._z3text import Printed, commands


@functools.cache
def _queries() -> tuple[tuple[str, Z3Query], ...]:
    out = []
    for ob in collect_obligations("/nonexistent"):
        if ob.method is Method.Z3:
            q = ob.build()
            assert isinstance(q, Z3Query)
            out.append((ob.id, q))
    return tuple(out)


def test_every_vc_s_two_texts_are_the_printed_ones() -> None:
    """Every bundled VC's vacuity and proof checks read the text printing their formulas gives."""
    for ident, q in _queries():
        for vc, (vac, proof) in zip(q.vcs, _check_texts(q), strict=True):
            hyps = [h for _, h in vc.hypotheses]
            assert vac == _text_of(hyps + [c == v for c, v in vc.witness]), (ident, vc.name)
            assert proof == _text_of(hyps + [z3.Not(vc.goal)]), (ident, vc.name)


class _Undecided:
    """A solver that answers unknown: each premise control then runs both its checks."""

    def check(self) -> z3.CheckSatResult:
        return z3.unknown

    def reason_unknown(self) -> str:
        return "planted"

    def statistics(self) -> list[tuple[str, int]]:
        return []


def test_every_premise_control_checks_the_printed_text(monkeypatch: pytest.MonkeyPatch) -> None:
    """Every check of every premise control reads the text printing its formulas gives."""
    seen: list[tuple[list[z3.BoolRef], str | None]] = []

    def record(timeout_ms: int, ctx: Any = None, formulas: Any = (), text: str | None = None,
               rlimit: int | None = None) -> _Undecided:
        seen.append((list(formulas), text))
        return _Undecided()

    monkeypatch.setattr(_obligation, "_solver", record)
    controls = _controls.premise_controls()
    assert controls
    for c in controls:
        assert c.run()[0] == "unknown"
    # Two checks each, three where the premise has its own pins (tried first).
    assert len(seen) == 2 * len(controls) + len(_controls.PREMISE_COUNTER_WITNESSES)
    for formulas, text in seen:
        assert text is not None and text == _text_of(formulas)


# --- small cases --------------------------------------------------------------------------------

U = z3.DeclareSort("U")
x, y, z = z3.Ints("x y z")
f = z3.Function("f", z3.IntSort(), z3.IntSort())
u = z3.Const("u", U)
g = z3.Function("g", U, z3.IntSort())


def _cases() -> Iterator[tuple[str, list[z3.BoolRef], list[int], int]]:
    """(what, formulas, the kept indices, the prints beyond the first it may need)."""
    yield "a symbol only in the dropped formula", [x + y > 0, y > 1], [1], 0
    # Alone, the second formula meets x before y; in the list, the first met y first.
    yield ("symbols met first by the dropped formula, in another order",
           [f(y) > f(x), f(x) > y + z], [1], 1)
    yield "an uninterpreted sort only in the dropped formula", [g(u) > 0, x > 0], [1], 0
    V = z3.DeclareSort("V")
    v = z3.Const("v", V)
    yield ("a sort named only by a bound variable",
           [x > 0, z3.ForAll([v], v == v), g(u) > y], [1, 2], 0)
    yield ("a sort met first by the dropped formula", [g(u) > x, z3.ForAll([u], g(u) > y)], [1], 1)
    q1, q2 = z3.Int("a(b"), z3.Int("c) (d")
    yield "quoted symbols with parentheses in their names", [q1 > 0, q2 > q1, q2 < 3], [0, 1], 0
    s = z3.String("s")
    yield ("a string literal with a parenthesis",
           [s == z3.StringVal("(x"), z3.Length(s) > x, x > 2], [0, 1], 0)
    yield "a symbol first met in the goal", [x > 0, y > 0, z3.Not(z > x)], [0, 2], 0
    yield ("a bound variable named like a declared constant",
           [x > 1, z3.ForAll([x], f(x) > y)], [1], 0)
    yield ("an attribute naming a declared constant",
           [x > 1, z3.ForAll([y], f(y) > z, qid="x", skid="x")], [1], 0)
    yield ("a let shared inside one formula",
           [x > 2, z3.And(f(f(x) + y) > 0, f(f(x) + y) < f(f(x) + y) * f(f(x) + y))], [1], 1)


CASES = list(_cases())


def _check(formulas: list[z3.BoolRef], keep: list[int], reprints: int) -> None:
    p = Printed(formulas)
    assert p.full == _text_of(formulas)
    assert p.text(keep) == _text_of([formulas[k] for k in keep])
    assert p.reprints <= reprints       # derived, not printed again


@pytest.mark.parametrize("what,formulas,keep,reprints", CASES, ids=[c[0] for c in CASES])
def test_a_small_case_is_cut_as_printed(what: str, formulas: list[z3.BoolRef], keep: list[int],
                                        reprints: int) -> None:
    _check(formulas, keep, reprints)


def test_every_sub_list_of_a_mixed_list_is_cut_as_printed() -> None:
    fs = [f(y) > f(x), z3.ForAll([x], f(x) > g(u)), z3.Int("a(b") > z, z3.Not(z > y + x),
          x == 3, g(u) == y]
    p = Printed(fs)
    for n in range(len(fs) + 1):
        for keep in itertools.combinations(range(len(fs)), n):
            assert p.text(keep) == _text_of([fs[k] for k in keep]), keep


def test_commands_keep_quotes_strings_and_refuse_stray_text() -> None:
    text = '(declare-fun |a)(| () Int)\n(assert (= |a)(| (str.len ")(")))\n'
    assert commands(text) == ['(declare-fun |a)(| () Int)', '(assert (= |a)(| (str.len ")(")))']
    assert commands("(assert true) x\n") is None
    assert commands("(assert (and true)\n") is None
    with pytest.raises(ValueError, match="does not increase"):
        Printed([x > 0, y > 0]).text([1, 0])
    with pytest.raises(IndexError, match="not within"):
        Printed([x > 0]).text([1])


# --- seeded faults: each shortcut done wrong fails a case above -----------------------------------

_NO_QUOTES = r'"(?:[^"]|"")*"|;[^\n]*|[()]'


def _ignore_quotes(mp: pytest.MonkeyPatch) -> None:
    mp.setattr(_z3text, "_STRUCTURE", re.compile(_NO_QUOTES))


def _ignore_strings(mp: pytest.MonkeyPatch) -> None:
    mp.setattr(_z3text, "_STRUCTURE", re.compile(r"\|[^|]*\||;[^\n]*|[()]"))


def _keep_every_declaration(mp: pytest.MonkeyPatch) -> None:
    mp.setattr(_z3text, "_free_uses", lambda cmd, names: set(names))


def _ignore_binders(mp: pytest.MonkeyPatch) -> None:
    mp.setattr(_z3text, "_free_uses",
               lambda cmd, names: set(_z3text._TOKEN.findall(cmd)) & names)


def _whole_list_order(mp: pytest.MonkeyPatch) -> None:
    mp.setattr(Printed, "_own_order",
               lambda self, k: sorted(self._uses[k], key=self._pos.__getitem__))


FAULTS: list[Callable[[pytest.MonkeyPatch], None]] = [
    _ignore_quotes, _ignore_strings, _keep_every_declaration, _ignore_binders, _whole_list_order]


@pytest.mark.parametrize("fault", FAULTS, ids=[f.__name__ for f in FAULTS])
def test_a_seeded_fault_fails_a_small_case(fault: Callable[[pytest.MonkeyPatch], None],
                                           monkeypatch: pytest.MonkeyPatch) -> None:
    """The small cases catch each shortcut done wrong: a wrong text, or a print it should not
    need (a splitter blind to quotes or strings gives up, safely, but then prints)."""
    fault(monkeypatch)
    caught = []
    for what, formulas, keep, reprints in CASES:
        try:
            _check(formulas, keep, reprints)
        except AssertionError:
            caught.append(what)
    assert caught, f"{fault.__name__} passed every case"
