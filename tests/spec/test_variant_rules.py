"""Variant owns its box and rest rules (one table): a value without a row raises, and the same
functions give on Z3 terms the numbers they give on floats."""

from __future__ import annotations

import dataclasses
from pathlib import Path

import pytest
import z3

from cfmpa.impl import lattice_range
from cfmpa.spec import Variant, cell_box, exact_tf, left_box, load_scenario, make_grid, rest_box
from cfmpa.spec._grid import rule_of
from z3answer import as_float, exact_real

REPO = Path(__file__).resolve().parents[2]




def test_every_member_has_a_rule_and_an_unknown_value_raises():
    for v in Variant:
        assert rule_of(v) is v.rule
    assert [v for v in Variant if v.rest_at_goal] == [Variant.TIGHT]
    with pytest.raises(ValueError, match="has no box rule"):
        rule_of("diagonal")


def test_the_triples_rest_layer_follows_the_rule_not_the_name(monkeypatch):
    # Theorem 3 (tight)'s rest layer is the goal because tight's rule says so; a rule table
    # giving original a rest at the goal (a seeded fault) changes Theorem 1's statement with it.
    from cfmpa.spec import _grid, _triples

    def rest_of(v: Variant) -> str:
        return _triples._builtdr("T", v, "ref", "note").postcondition[1].text

    assert [v for v in Variant if "at rest at its goal" in rest_of(v)] == [Variant.TIGHT]
    planted = dict(_grid._RULES, original=dataclasses.replace(_grid._RULES["original"],
                                                              rest_at_goal=True))
    monkeypatch.setattr(_grid, "_RULES", planted)
    assert "at rest at its goal" in rest_of(Variant.ORIGINAL)


@pytest.mark.parametrize("name", ["default", "narrow-gap"])
def test_the_rules_on_terms_give_the_floats(name):
    s = load_scenario(REPO / "scenarios" / f"{name}.toml")
    L = s.left
    tf = float(exact_tf(s))
    sym = [exact_real(x) for x in (*L.start, *L.goal, *L.omega, s.dt, tf)]
    start, goal, omega, dt, T = sym[0:2], sym[2:4], sym[4:6], sym[6], sym[7]
    g = make_grid(s)
    for v in Variant:
        for k in (0, 1, g.N - 1):
            box = v.layer_box(start, goal, omega, dt, T, z3.RealVal(k))
            want = left_box(s, v, k)
            for q in range(2):
                for side in range(2):
                    assert as_float(box[q][side]) == pytest.approx(want[q][side], abs=1e-12)
        rb = v.rest_box(start, goal, omega, dt, T, z3.IntVal(g.N))
        want = rest_box(s, v, g.N)
        for q in range(2):
            for side in range(2):
                assert as_float(rb[q][side]) == pytest.approx(want[q][side], abs=1e-12)
    cb = cell_box([exact_real(x) for x in g.lo], [exact_real(x) for x in g.h], (z3.IntVal(2), z3.IntVal(1)))
    fb = cell_box(g.lo, g.h, (2, 1))
    for q in range(2):
        for side in range(2):
            assert as_float(cb[q][side]) == pytest.approx(fb[q][side], abs=1e-12)


def test_lattice_range_on_terms_is_lattice_range():
    for lo, hi, a, gg in ((-0.04, 0.04, 0.0, 0.04), (0.3, 0.32, 0.3, 0.02), (1.0, 1.0, 1.0, 0.5),
                          (-1.3, 0.7, 0.25, 0.1)):
        got = lattice_range(exact_real(lo), exact_real(hi), exact_real(a), exact_real(gg))
        assert tuple(z3.simplify(x).as_long() for x in got) == lattice_range(lo, hi, a, gg)
    assert lattice_range(0.0, 1.0, 0.0, 0.0) == (0, 0)
