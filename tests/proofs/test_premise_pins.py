"""The premise controls' own counter-model pins (proofs/_controls.py PREMISE_COUNTER_WITNESSES,
docs/model.md §10.3): each refutes its control (Z3 answers sat), tried first and cut from the
composition's one print; a wrong pin only costs its budget and falls through to the one-cell
pins and the free try; a pin keyed to a name the composition lacks is an error."""

from __future__ import annotations

from typing import Any

import pytest
import z3

from cfmpa.proofs import _controls as C
from cfmpa.proofs import _obligation as O
from cfmpa.proofs._obligation import VC, _text_of, rlimit_count

ENTRIES = sorted(C.PREMISE_COUNTER_WITNESSES)


def _index(variant: str, name: str) -> int:
    return [n for n, _ in C._composition(variant).hypotheses].index(name)


@pytest.mark.parametrize("variant,name", ENTRIES, ids=lambda x: x[:40])
def test_each_own_pin_refutes_its_control_first_from_the_printed_text(monkeypatch, variant, name):
    seen: list[tuple[Any, bool, int | None]] = []
    real = O._solver

    def spy(timeout_ms, *a, **k):
        s = real(timeout_ms, *a, **k)
        seen.append((s, k.get("text") == _text_of(k["formulas"]), k.get("rlimit")))
        return s
    monkeypatch.setattr(O, "_solver", spy)
    index = _index(variant, name)
    outcome, detail = C._without(variant, index)
    assert (outcome, detail) == ("refuted", "a counter-model with the premise's own pins")
    # One check, Z3's sat with the own pins, on the text cut from the one print, well inside
    # its budget.
    [(s, printed, rlimit)] = seen
    assert printed and rlimit == C.PREMISE_OWN_RLIMIT
    assert rlimit_count(s) < C.PREMISE_OWN_RLIMIT // 2
    # The control for that premise is the composition without it, ending refuted (as expected).
    control = next(c for c in C.premise_controls()
                   if c.id == f"Control.Safety.{variant}.composition.without[{index}]")
    assert control.what == f"without: {name}" and "refuted" in control.expected


def test_the_one_cell_pins_alone_give_no_counter_model_there(monkeypatch):
    # Why the own pins are needed: with one layer the rest box holds theta_L(t). Run without
    # the table (the old order): unsat with the one-cell pins; the free try is cut short.
    C._composition_text("modified")         # printed (and cached) with the own pins first
    monkeypatch.setattr(C, "PREMISE_FREE_RLIMIT", 1_000)
    monkeypatch.setattr(C, "_own_pins", lambda v: {})
    outcome, detail = C._without("modified", _index("modified", C._LINKS_IN_LAYER))
    assert outcome == "unknown" and detail.startswith("unsat with the one-cell pins;"), detail


@pytest.mark.parametrize("variant,wrong", [
    # Planted: two layers; original's rest box (layer 1's, [0, 2]) then holds theta_L(t).
    ("original", (("N", 2), ("Tf", 2), ("L.goal.x", 2))),
    # Planted: one layer, as the one-cell pins.
    ("modified", (("N", 1), ("Tf", 1), ("L.goal.x", 1))),
])
def test_a_wrong_pin_is_not_refuted_by_it_and_falls_through(monkeypatch, variant, wrong):
    monkeypatch.setattr(C, "PREMISE_FREE_RLIMIT", 1_000)
    index = _index(variant, C._LINKS_IN_LAYER)
    pins = dict(C._THREE_LAYERS) | dict(wrong)
    outcome, detail = C._without(variant, index, own=tuple(pins.items()))
    assert outcome == "unknown", detail
    assert detail.startswith("unsat with the premise's own pins; unsat with the one-cell pins; "
                             "unknown without pins"), detail


def test_an_inconsistent_pin_costs_only_its_budget(monkeypatch):
    # Planted: dt = 0 contradicts dt > 0 (a statement that changed under its pin): the own try
    # ends unsat, never refuted, and the one-cell and free tries run as before.
    index = 6               # the postcondition, refuted with the one-cell pins
    limits: list[int | None] = []
    real = O._solver

    def spy(*args: Any, **kwargs: Any) -> Any:
        limits.append(kwargs.get("rlimit"))
        return real(*args, **kwargs)
    with monkeypatch.context() as m:
        m.setattr(O, "_solver", spy)
        outcome, detail = C._without("modified", index, own=(("dt", 0),))
    assert (outcome, detail) == ("refuted", "a counter-model with the one-cell pins")
    # The own pins were tried, on their own budget, before the one-cell pins.
    assert limits == [C.PREMISE_OWN_RLIMIT, C.PREMISE_PINNED_RLIMIT]
    monkeypatch.setattr(C, "PREMISE_OWN_RLIMIT", 1)
    outcome, detail = C._without("modified", index, own=C._THREE_LAYERS)
    assert outcome == "refuted" and detail == "a counter-model with the one-cell pins"


def test_a_pin_keyed_to_a_missing_name_is_an_error(monkeypatch):
    vc = C._composition("original")
    stale = {("original", C._LINKS_IN_LAYER + " (renamed)"): C._THREE_LAYERS}
    with pytest.raises(KeyError, match="has 0 hypotheses named"):
        C.premise_pins(vc, "original", stale)
    lemma = next(n for n, _ in vc.hypotheses if n.startswith(C.LEMMA_INSTANCE))
    with pytest.raises(KeyError, match="lemma's instance"):
        C.premise_pins(vc, "original", {("original", lemma): C._THREE_LAYERS})
    with pytest.raises(KeyError, match=r"no constant .*N2"):
        C.premise_pins(vc, "original", {("original", C._LINKS_IN_LAYER): (("N2", 3),)})
    with pytest.raises(ValueError, match="N = 'three'"):
        C.premise_pins(vc, "original", {("original", C._LINKS_IN_LAYER): (("N", "three"),)})
    # And where the controls are collected: a stale table stops them, saying which name.
    monkeypatch.setattr(C, "PREMISE_COUNTER_WITNESSES", stale)
    C._own_pins.cache_clear()
    try:
        with pytest.raises(KeyError, match="renamed"):
            C.premise_controls()
    finally:
        C._own_pins.cache_clear()


def test_pins_follow_the_name_when_the_hypotheses_are_reordered():
    vc = C._composition("modified")
    flipped = VC(vc.name, tuple(reversed(vc.hypotheses)), vc.goal, vc.key_premise, vc.witness,
                 counter_witness=vc.counter_witness)
    here, there = C.premise_pins(vc, "modified"), C.premise_pins(flipped, "modified")
    n = len(vc.hypotheses)
    assert {n - 1 - i for i in here} == set(there)
    for i, pins in here.items():
        assert flipped.hypotheses[n - 1 - i][0] == vc.hypotheses[i][0]
        assert all(z3.eq(a, b) and z3.eq(x, y) for (a, x), (b, y) in zip(pins, there[n - 1 - i],
                                                                       strict=True))
    # The one-cell pins of other constants are kept, the own ones replace N's.
    names = [c.decl().name() for c, _ in here[_index("modified", C._LINKS_IN_LAYER)]]
    assert names.count("N") == 1 and {"m", "n", "L.len"} <= set(names)


@pytest.mark.parametrize("variant,holds", [("tight", True), ("modified", False), ("original", False)])
def test_tight_needs_no_tf_so_its_two_controls_have_no_counter_model(variant, holds):
    # Why tight's controls without omega_q > 0 and without Tf's definition stay unknown: with Tf
    # left free, theta_L(t) is still in layer k's box (k < N) or in the rest box, from the
    # composition's own dt > 0, N's definition, t >= 0 and k's (the code's boxes on the terms).
    # The same statement fails for the other variants' boxes (Z3 finds where).
    from cfmpa.proofs._obl_safety_principal import Principal, in_box

    vc = C._composition(variant)
    named = dict(vc.hypotheses)
    hyps = [named[n] for n in ("dt > 0", "N = max(1, ceil(Tf / dt)) (spec.exact_n)", "t >= 0",
                               "k = floor(t / dt), the step at t (named)")]
    P, t, k = Principal.named(), z3.Real("t"), z3.Int("kk")
    theta = P.theta(t)
    placed = z3.Or(z3.And(0 <= k, k < P.N, in_box(theta, P.box(variant, z3.ToReal(k)))),
                   in_box(theta, P.rest_box(variant)))
    s = z3.Solver()
    s.set("timeout", 20_000)
    s.add(*hyps, z3.Not(placed))
    assert s.check() == (z3.unsat if holds else z3.sat)
