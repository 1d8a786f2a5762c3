"""Thm3.box_nesting: the statement is spec's rule table run on Z3 terms; a shortened or flipped
rule (a copy in the table) fails it."""

from __future__ import annotations

import dataclasses

import z3

from cfmpa.proofs._obl_builtdr import _box_nesting
from cfmpa.spec import _grid as grid
from cfmpa.spec import if_then, max_of, min_of


def _answer(hyps, goal) -> z3.CheckSatResult:
    s = z3.Solver()
    s.set("timeout", 10_000)
    s.add([h for _, h in hyps])
    s.add(z3.Not(goal))
    return s.check()


def _with_rule(monkeypatch, variant, joint_box):
    """Seeded fault: a copy of the rule table's row of ``variant`` with another joint_box."""
    row = grid._RULES[variant]
    monkeypatch.setitem(grid._RULES, variant, dataclasses.replace(row, joint_box=joint_box))


def test_box_nesting_is_proved():
    outer, inner = _box_nesting().vcs
    assert _answer(outer.hypotheses, outer.goal) == z3.unsat
    assert _answer(inner.hypotheses, inner.goal) == z3.unsat


def test_box_nesting_runs_the_code_s_rules(monkeypatch):
    # The statement is built from the rule table: another rule, another statement.
    before = [vc.goal for vc in _box_nesting().vcs]
    _with_rule(monkeypatch, "original", lambda a, b, step, up: (a - 2 * step, a + 2 * step))
    after = [vc.goal for vc in _box_nesting().vcs]
    assert not z3.eq(before[0], after[0]) and z3.eq(before[1], after[1])


def test_an_original_box_with_a_shortened_bound_fails(monkeypatch):
    # [a - w dt / 2, a + w dt / 2]: the modified box [a, a + s w dt] sticks out.
    _with_rule(monkeypatch, "original", lambda a, b, step, up: (a - step / 2, a + step / 2))
    outer, _ = _box_nesting().vcs
    assert _answer(outer.hypotheses, outer.goal) == z3.sat


def test_a_modified_box_with_a_shortened_bound_fails(monkeypatch):
    # [a, a + s w dt / 2]: at full speed the principal travels w dt in a step.
    def half(a, b, step, up):
        end = a + if_then(up, 1.0, -1.0) * step / 2
        return (min_of(a, end), max_of(a, end))
    _with_rule(monkeypatch, "modified", half)
    outer, inner = _box_nesting().vcs
    assert _answer(outer.hypotheses, outer.goal) == z3.unsat
    assert _answer(inner.hypotheses, inner.goal) == z3.sat


def test_a_modified_box_pointing_away_from_the_goal_fails(monkeypatch):
    def flipped(a, b, step, up):
        end = a + if_then(up, -1.0, 1.0) * step
        return (min_of(a, end), max_of(a, end))
    _with_rule(monkeypatch, "modified", flipped)
    _, inner = _box_nesting().vcs
    assert _answer(inner.hypotheses, inner.goal) == z3.sat


def test_the_boxes_agree_with_spec_left_box_on_a_scenario():
    # The Z3 rules evaluated at a real layer give the intervals spec.left_box computes.
    from pathlib import Path

    from cfmpa.spec import load_scenario
    from cfmpa.spec._grid import left_angles, left_box
    s = load_scenario(Path(__file__).resolve().parents[2] / "scenarios" / "default.toml")
    k, q = 3, 0
    a0 = float(left_angles(s, k * s.dt)[q])
    a1 = float(left_angles(s, (k + 1) * s.dt)[q])
    w = s.left.omega[q] * s.dt
    sign = 1.0 if s.left.goal[q] > s.left.start[q] else -1.0
    assert left_box(s, "original", k)[q] == (a0 - w, a0 + w)
    assert left_box(s, "modified", k)[q] == (min(a0, a0 + sign * w), max(a0, a0 + sign * w))
    assert left_box(s, "tight", k)[q] == (min(a0, a1), max(a0, a1))
