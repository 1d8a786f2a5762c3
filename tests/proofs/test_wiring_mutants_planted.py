"""The wiring's mutants of ``cfmpa selftest --code`` (runs/_code_mutants.py), each applied to a
copy of its source file as the table writes it (tests/mutant_module.py), and caught by the one
proof or control that must catch it (docs/model.md §7.3): never by a pin."""

from __future__ import annotations

import sys

import pytest
import z3

import cfmpa.spec
from cfmpa.proofs import _controls as C
from cfmpa.proofs import _controls_wiring as W
from cfmpa.proofs._obl_exact_polygon import polygon_gap_vcs
from cfmpa.proofs._obl_wiring import (
    exact_coverage_failures,
    grid_motion_vcs,
    reference_speed_vcs,
    trajectory_motion_vcs,
)
from cfmpa.runs._code_mutants import CODE_MUTANTS
from mutant_module import mutated_module, source
from z3answer import answer

#: What catches each wiring mutant (a VC refuted, a control not as expected).
CAUGHT_BY = {
    "certificate_previous_segment_speed": "Certificate.wiring's right_rate; "
                                          "Control.certificate.moving_contact",
    "trajectory_previous_row_speed": "Certificate.wiring's trajectory VC",
    "monitor_gap_slice_short": "Monitor.reference_speeds; Control.monitor.gap_last_piece",
    "witness_start_or_and": "Control.witness.raised_start",
    "control_error_counted_rejected": "Control.harness.error_is_not_a_pass",
    "theorem_made_definitional": "Control.accept.kinds; Control.kinds.theorem_moved",
    "exact_rest_layer_skipped": "Control.exact.rest_layer_contact; the translation checks' "
                                "exact.coverage",
    "exact_tool_square_corner_dropped": "Exact.gap_formula's tool_points",
}
MUTANTS = {m.name: m for m in CODE_MUTANTS if m.name in CAUGHT_BY}


def _plant(monkeypatch: pytest.MonkeyPatch, name: str):
    m = MUTANTS[name]
    return mutated_module(name, m.file, m.edits,
                          lambda key, value: monkeypatch.setitem(sys.modules, key, value))


def _refuted(vcs, names=None) -> set[str]:
    """The VCs (of ``names``, default all) that Z3 refutes (sat) within 10 s each."""
    out = set()
    for vc in vcs:
        if (names is None or any(n in vc.name for n in names)) and answer(
                [h for _, h in vc.hypotheses] + [z3.Not(vc.goal)], timeout_ms=10_000) == z3.sat:
            out.add(vc.name)
    return out


def _control(ident: str) -> C.Control:
    return next(c for c in C.collect_controls() if c.id == ident)


def test_each_mutant_is_in_the_table_and_edits_today_s_source_once():
    assert set(MUTANTS) == set(CAUGHT_BY)
    for m in MUTANTS.values():
        _, src = source(m.file)
        for old, new in m.edits:
            assert src.count(old) == 1 and old != new, (m.name, old)


def test_certificate_previous_segment_speed(monkeypatch):
    mod = _plant(monkeypatch, "certificate_previous_segment_speed")
    assert _refuted(grid_motion_vcs(mod.GridMotion), ["right_rate"])
    monkeypatch.setattr(cfmpa.spec.GridMotion, "lipschitz", mod.GridMotion.lipschitz)
    r = C.run_control(_control("Control.certificate.moving_contact"))
    assert r.outcome == "accepted" and not r.ok, r.detail


def test_trajectory_previous_row_speed(monkeypatch):
    mod = _plant(monkeypatch, "trajectory_previous_row_speed")
    assert _refuted(trajectory_motion_vcs(mod.TrajectoryMotion, mod.Trajectory))


def test_monitor_gap_slice_short(monkeypatch):
    mod = _plant(monkeypatch, "monitor_gap_slice_short")
    assert _refuted(reference_speed_vcs(mod.ReferenceSpeeds))
    monkeypatch.setattr(W, "ReferenceSpeeds", mod.ReferenceSpeeds)
    r = C.run_control(_control("Control.monitor.gap_last_piece"))
    assert r.outcome == "accepted" and not r.ok, r.detail


def test_witness_start_or_and(monkeypatch):
    import cfmpa.spec._witness as SW  # check_witness reads its module's start test

    mod = _plant(monkeypatch, "witness_start_or_and")
    monkeypatch.setattr(SW, "start_label_breaks", mod.start_label_breaks)
    r = C.run_control(_control("Control.witness.raised_start"))
    assert r.outcome == "accepted" and not r.ok, r.detail


def test_control_error_counted_rejected(monkeypatch):
    mod = _plant(monkeypatch, "control_error_counted_rejected")
    (h,) = C.harness_controls()
    assert C.run_control(h).ok
    monkeypatch.setattr(C, "run_control", mod.run_control)
    r = mod.run_control(h)
    assert r.outcome == "accepted" and not r.ok, r.detail


def test_exact_rest_layer_skipped(monkeypatch):
    mod = _plant(monkeypatch, "exact_rest_layer_skipped")
    c = C._case()
    path = list(c.best.path)
    assert exact_coverage_failures(c.scenario, "modified", c.grid, path) == []
    bad = exact_coverage_failures(c.scenario, "modified", c.grid, path, mod.exact_path_gaps)
    assert bad and "(the rest layer)" in bad[0], bad
    monkeypatch.setattr(cfmpa.spec, "exact_path_gaps", mod.exact_path_gaps)
    r = C.run_control(_control("Control.exact.rest_layer_contact"))
    assert r.outcome == "accepted" and not r.ok, r.detail
    # The translation check reads spec.exact_path_gaps too: its coverage now fails.
    assert exact_coverage_failures(c.scenario, "modified", c.grid, path)


def test_exact_tool_square_corner_dropped(monkeypatch):
    mod = _plant(monkeypatch, "exact_tool_square_corner_dropped")
    assert not _refuted(polygon_gap_vcs(), ["tool_points"])
    assert _refuted(polygon_gap_vcs(mod._tool_points), ["tool_points"]) == {"tool_points"}


def test_theorem_made_definitional(monkeypatch):
    import cfmpa.proofs._registry as R  # the views kind_of reads

    mod = _plant(monkeypatch, "theorem_made_definitional")
    assert all(C.run_control(_control(i)).ok
               for i in ("Control.accept.kinds", "Control.kinds.theorem_moved"))
    # The kinds are a view of the declarations: the mutated module's declare it definitional.
    monkeypatch.setattr(R, "DEFINITIONAL", {**R.DEFINITIONAL,
                                            **R.declared((mod.safety_obligations,)).definitional})
    r = C.run_control(_control("Control.accept.kinds"))
    assert r.outcome == "rejected" and not r.ok and "Safety.separation" in r.detail, r.detail
    r = C.run_control(_control("Control.kinds.theorem_moved"))
    assert r.outcome == "error" and not r.ok, r.detail
