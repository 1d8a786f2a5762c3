"""The exact re-decision reaches the wiring (docs/model.md §7.2, §7.4, §10): its cells are the ones
the fixed is_path reads (checked in every translation check), its rest-layer control and right
input, and Exact.gap_formula's polygon VCs (proofs/_obl_exact_polygon.py)."""

from __future__ import annotations

import sys

import pytest
import z3

import cfmpa.spec
from cfmpa.proofs import _controls as C
from cfmpa.proofs import _controls_wiring as W
from cfmpa.proofs._obl_constants import exact_vcs
from cfmpa.proofs._obl_exact_polygon import VERTICES, polygon_gap_vcs, tool_points_on_terms
from cfmpa.proofs._obl_scenario import _translation
from cfmpa.proofs._obl_wiring import exact_cells, exact_coverage_failures, is_path_reads
from cfmpa.scenarios import BUNDLED_DIR
from cfmpa.spec import Variant, load_scenario
from cfmpa.spec._exact import ExactCell, ExactGaps
from mutant_module import mutated_module
from z3answer import answer

# --- coverage --------------------------------------------------------------------------------


@pytest.mark.parametrize("extra", [-10, -1, 0, 1, 2, 5])
def test_the_exact_cells_are_the_ones_is_path_reads(extra):
    """Paths shorter than N, of N, N + 1 and longer cells, ending in waits or not."""
    c = C._case()
    N = c.grid.N
    best = list(c.best.path)
    path = best[:max(1, min(len(best), N + 1 + extra))] if extra <= 0 else (
        best + [best[-1]] * extra)
    assert exact_coverage_failures(c.scenario, "modified", c.grid, path) == []
    reads = is_path_reads(path, N)
    assert (N, tuple(path[-1])) in reads                       # the rest layer
    assert {layer for layer, _ in reads} == set(range(N + 1))


def test_a_one_cell_path_is_read_in_every_layer():
    c = C._case()
    assert is_path_reads([(3, 4)], c.grid.N) == [(k, (3, 4)) for k in range(c.grid.N + 1)]


def test_exact_cells_runs_the_code_s_own_loop_in_milliseconds():
    c = C._case()
    path = list(c.best.path)
    real = cfmpa.spec.exact_path_gaps(c.scenario, "modified", c.grid, path)
    assert exact_cells(c.scenario, "modified", c.grid, path) == [(x.layer, x.cell)
                                                                  for x in real.cells]


def test_a_re_decision_of_an_extra_layer_is_a_coverage_failure(monkeypatch):
    mod = mutated_module("extra_layer", "spec/_exact.py",
                         [("path_layer_cells(path, grid.N)", "path_layer_cells(path, grid.N + 1)")],
                         lambda k, v: monkeypatch.setitem(sys.modules, k, v))
    c = C._case()
    bad = exact_coverage_failures(c.scenario, "modified", c.grid, list(c.best.path),
                                  mod.exact_path_gaps)
    assert bad and any("which is_path does not read" in b for b in bad), bad


def test_the_translation_check_reads_the_exact_re_decision(monkeypatch):
    s = load_scenario(BUNDLED_DIR / "original-fails.toml")
    ok = _translation(s, Variant.TIGHT)
    assert ok.holds and "rest layer included" in ok.detail, ok.detail
    mod = mutated_module("short", "spec/_exact.py",
                         [("range(max(len(cells) - 1, N) + 1)", "range(max(len(cells) - 1, N))")],
                         lambda k, v: monkeypatch.setitem(sys.modules, k, v))
    monkeypatch.setattr(cfmpa.spec, "exact_path_gaps", mod.exact_path_gaps)
    bad = _translation(s, Variant.TIGHT)
    assert bad.holds is False and "exact.coverage" in bad.detail and "rest layer" in bad.detail


# --- the controls ----------------------------------------------------------------------------


def _control(ident: str) -> C.Control:
    return next(c for c in C.collect_controls() if c.id == ident)


def test_the_rest_layer_control_is_rejected_and_its_right_input_accepted():
    r = C.run_control(_control("Control.exact.rest_layer_contact"))
    assert r.ok and r.outcome == "rejected" and "undecided" in r.detail, r.detail
    assert C.run_control(_control("Control.accept.exact")).ok


def test_the_contact_cell_is_visited_in_the_rest_layer_only():
    c = C._case()
    path, last = W._rest_layer_path()
    N = c.grid.N
    assert len(path) == N + 1 and path[-1] == last and last not in path[:-1]
    assert c.dr[N][last] != 0 and not c.dr[:N, path[0][0], path[0][1]].any()
    assert max(abs(a - b) for a, b in zip(path[-2], last)) == 1      # one move


def test_undecided_elsewhere_is_an_error_and_nothing_decided_fails_the_right_input(monkeypatch):
    def elsewhere(s, v, g, path):
        cells = (ExactCell(0, tuple(path[0]), 0.0, False),)
        return ExactGaps(cells, 0.0, (0, tuple(path[0])))
    monkeypatch.setattr(cfmpa.spec, "exact_path_gaps", elsewhere)
    r = C.run_control(_control("Control.exact.rest_layer_contact"))
    assert r.outcome == "error" and not r.ok, r.detail
    assert not C.run_control(_control("Control.accept.exact")).ok


# --- Exact.gap_formula's polygon VCs ---------------------------------------------------------


def test_the_polygon_vcs_are_in_exact_gap_formula():
    names = [vc.name for vc in exact_vcs()]
    assert names[3:] == ["tool_points", "tool_frame", "tool_max_A", "tool_max_B", "tool_hull_A",
                         "tool_hull_B"]


@pytest.mark.parametrize("vc", polygon_gap_vcs(), ids=lambda vc: vc.name)
def test_each_polygon_vc_is_proved_not_vacuous_and_needs_its_key(vc):
    hyps = [h for _, h in vc.hypotheses]
    assert answer(hyps + [z3.Not(vc.goal)]) == z3.unsat
    assert answer(hyps) == z3.sat
    assert vc.key_premise is not None
    assert answer([h for n, h in vc.hypotheses if n != vc.key_premise]
                  + [z3.Not(vc.goal)]) == z3.sat


def test_the_tool_points_are_four_per_vertex_from_the_code():
    arm = type("A", (), {"base": z3.Reals("bx by"), "links": z3.Reals("l1 l2"),
                         "tool": type("T", (), {"polygon": [z3.Reals(f"x{i} y{i}")
                                                            for i in range(VERTICES)]})()})()
    pts = tool_points_on_terms(arm, z3.Real("t1"), z3.Real("t2"), z3.Real("g"))
    assert len(pts) == 4 * VERTICES


def test_a_tool_in_link_1_s_frame_is_refuted(monkeypatch):
    mod = mutated_module("link1", "spec/_exact.py",
                         [("    a1, phi = arb(t1), arb(t1) + arb(t2)\n",
                           "    a1, phi = arb(t1), arb(t1)\n")],
                         lambda k, v: monkeypatch.setitem(sys.modules, k, v))
    (vc,) = [v for v in polygon_gap_vcs(mod._tool_points) if v.name == "tool_points"]
    assert answer([h for _, h in vc.hypotheses] + [z3.Not(vc.goal)]) == z3.sat
