"""Safety.height_rule and Safety.tool_region (docs/model.md §2 "Tools and heights", §10): proved as
the code is, each VC false without its key premise, and each seeded fault of selftest --code
(runs/_code_mutants.py), planted in a copy of its source file, refutes the VC that must catch it."""

from __future__ import annotations

import importlib
import sys
import types
from pathlib import Path

import numpy as np
import pytest
import z3

import cfmpa.spec
from z3answer import answer
from mutant_module import mutated_module
from cfmpa.impl import link_reach, link_rectangles, sweep_margin
from cfmpa.proofs import FIXED_IDS, Verdict, collect_obligations
from cfmpa.proofs import _obl_tools as T
from cfmpa.proofs._obl_constants import ExtractionError
from cfmpa.proofs._obligation import VC
from cfmpa.runs import CODE_MUTANTS

IDS = ["Safety.height_rule", "Safety.tool_region"]
ALL_IDS = IDS + ["Certificate.height_gap"]

#: Each seeded fault, the obligation and the VC it must refute.
CAUGHT_BY = {"heights_compared_strictly": ("Safety.height_rule", "disjoint_no_common_point"),
             "height_gap_far_ends": ("Certificate.height_gap", "gap_vertical"),
             "tool_vertex_left_out": ("Safety.tool_region", "tool_points"),
             "tool_margin_nearest_vertex": ("Safety.tool_region", "far_vertex"),
             "tool_in_link1_frame": ("Safety.tool_region", "tool_points")}
MUTANTS = {m.name: m for m in CODE_MUTANTS if m.name in CAUGHT_BY}


def _refuted(vc: VC, pins=()) -> bool:
    return answer([h for _, h in vc.hypotheses] + [z3.Not(vc.goal)]
                  + [c == v for c, v in pins]) == z3.sat


def _proved(vc: VC) -> bool:
    return (answer([h for _, h in vc.hypotheses] + [c == v for c, v in vc.witness]) == z3.sat
            and answer([h for _, h in vc.hypotheses] + [z3.Not(vc.goal)]) == z3.unsat)


def _planted(name: str) -> types.ModuleType:
    """The mutant's file, edited, loaded as a module of its package (its source registered for
    inspect, which the readings use)."""
    m = MUTANTS[name]
    return mutated_module(name, m.file, m.edits, sys.modules.__setitem__)


@pytest.fixture(scope="module")
def tool_kit() -> T.ToolKit:
    reading = T.read_tool()
    T.check_tool_reading(reading)
    return T.tool_kit(reading)


def test_registered_pinned_and_summarised():
    obs = [o for o in collect_obligations("/nonexistent", ["Safety"]) if o.id in IDS]
    assert [o.id for o in obs] == IDS
    assert all(i in FIXED_IDS and o.expected is Verdict.PROVED for i, o in zip(IDS, obs))
    from cfmpa.proofs import summary_problems
    assert summary_problems(ALL_IDS) == []
    (gap,) = [o for o in collect_obligations("/nonexistent", ["Certificate"])
              if o.id == "Certificate.height_gap"]
    assert "Certificate.height_gap" in FIXED_IDS and gap.expected is Verdict.PROVED


def test_the_tool_lemma_covers_the_loaders_largest_polygon():
    from cfmpa.spec._scenario import MAX_TOOL_VERTICES
    assert T.V == MAX_TOOL_VERTICES


# --- reading code on terms ------------------------------------------------------------------------

def test_run_on_terms_reads_the_height_functions():
    a, b = (z3.Real("a0"), z3.Real("a1")), (z3.Real("b0"), z3.Real("b1"))
    got = T.run_on_terms(cfmpa.spec.heights_overlap, a, b)
    assert answer([got != z3.And(a[0] <= b[1], b[0] <= a[1])]) == z3.unsat
    assert T.run_on_terms(cfmpa.spec.heights_overlap, None, b) is True
    gap = T.run_on_terms(cfmpa.spec.height_gap, a, b)
    for va, vb in (((0.0, 1.0), (2.0, 3.0)), ((2.0, 3.0), (0.0, 1.5)), ((0.0, 1.0), (0.5, 3.0))):
        pins = [a[0] == va[0], a[1] == va[1], b[0] == vb[0], b[1] == vb[1]]
        want = cfmpa.spec.height_gap(va, vb)
        assert answer(pins + [gap != want]) == z3.unsat


def test_run_on_terms_refuses_code_outside_its_subset():
    def loops(a, b):
        for _ in a:
            pass
        return True

    with pytest.raises(ExtractionError, match="outside the subset"):
        T.run_on_terms(loops, (1, 2), (3, 4))


# --- the height rule ------------------------------------------------------------------------------

def test_height_rule_proved_and_needs_its_key():
    (vc,) = T.height_rule_vcs()
    assert _proved(vc)
    assert _refuted(vc.without(vc.key_premise), vc.counter_witness)


def test_strict_comparison_is_refuted_at_touching_ends():
    mod = _planted("heights_compared_strictly")
    assert not mod.heights_overlap((0.0, 1.0), (1.0, 2.0))           # the fault: touching apart
    (vc,) = T.height_rule_vcs(mod.heights_overlap)
    one, two = z3.RealVal(1), z3.RealVal(2)
    a, b = T._interval("a"), T._interval("b")
    assert _refuted(vc)
    # The counter-model is the touching case: [0, 1] and [1, 2] share z = 1.
    assert _refuted(vc, ((a[0], z3.RealVal(0)), (a[1], one), (b[0], one), (b[1], two),
                         (z3.Real("z"), one)))


def test_a_part_without_heights_must_be_kept():
    T.check_none_reading()

    def forgets_none(a, b):
        if a is None:
            return False
        return a[0] <= b[1] and b[0] <= a[1]

    with pytest.raises(ValueError, match="would not be tested"):
        T.check_none_reading(forgets_none)


def test_pairs_to_test_is_read_against_the_height_test(monkeypatch: pytest.MonkeyPatch):
    T.check_pairs_reading()
    original = cfmpa.spec.pairs_to_test
    monkeypatch.setattr(cfmpa.spec, "pairs_to_test", lambda left, right: original(left, right)[1:])
    with pytest.raises(ValueError, match="pairs_to_test gives"):
        T.check_pairs_reading()


# --- the certificate's 3-D distance ---------------------------------------------------------------

def test_height_gap_proved_and_needs_its_keys():
    for vc in T.height_gap_vcs():
        assert _proved(vc), vc.name
        assert _refuted(vc.without(vc.key_premise), vc.counter_witness), vc.name


def test_a_gap_from_the_far_ends_is_refuted():
    mod = _planted("height_gap_far_ends")
    assert mod.height_gap((0.0, 1.0), (2.0, 3.0)) == 3.0            # the fault: 3, not 1
    vcs = {v.name: v for v in T.height_gap_vcs(mod.height_gap)}
    assert _refuted(vcs["gap_vertical"])


def test_part_distances_is_the_hypot_the_obligation_restates():
    from cfmpa.scenarios import BUNDLED_DIR
    s = cfmpa.spec.load_scenario(BUNDLED_DIR / "levels.toml")
    pl, pr = cfmpa.spec.parts(s.left), cfmpa.spec.parts(s.right)
    planar = np.random.default_rng(1).uniform(0.0, 0.5, size=(len(pl), len(pr)))
    got = cfmpa.spec.part_distances(s, planar)
    for a in pl:
        for b in pr:
            gap = cfmpa.spec.height_gap(cfmpa.spec.part_height(s.left, a),
                                        cfmpa.spec.part_height(s.right, b))
            want = np.hypot(planar[a, b], gap) if gap > 0 else planar[a, b]
            assert got[a, b] == want, (a, b)
    assert (got > planar).any()                         # levels has parts at disjoint heights


# --- the tool's region ----------------------------------------------------------------------------

def test_the_reading_is_impls_floats(tool_kit: T.ToolKit):
    T.check_tool_reading(tool_kit.reading)
    # A reading of other code than the floats' fails the check.
    with pytest.raises(ExtractionError, match="sweep_margin"):
        T.check_tool_reading(tool_kit.reading,
                             margin=lambda arm, link, g, m: 2 * sweep_margin(arm, link, g, m))


def test_every_tool_vc_proved_with_satisfiable_hypotheses(tool_kit: T.ToolKit):
    q = T.tool_region_query(tool_kit)
    assert [v.name for v in q.vcs] == ["comb_id", "hull_step", "root_norm", "far_vertex", "tool_reach",
                                       "margin_covers_tool", "grow_square", "grown_in_region",
                                       "tool_points", "tool_in_region"]
    for vc in q.vcs:
        assert _proved(vc), vc.name
        assert _refuted(vc.without(vc.key_premise), vc.counter_witness), vc.name


def test_only_the_final_composition_holds_by_its_boolean_skeleton(tool_kit: T.ToolKit):
    """tool_in_region is tool_reach and grown_in_region chained by their instances (its Boolean
    skeleton suffices, by design); every other VC needs arithmetic."""
    from test_safety import _skeleton  # type: ignore[import-not-found]
    for vc in T.tool_region_query(tool_kit).vcs + T.height_rule_vcs():
        atoms: dict[int, z3.BoolRef] = {}
        s = z3.Solver()
        s.add([_skeleton(h, atoms) for _, h in vc.hypotheses])
        s.add(z3.Not(_skeleton(vc.goal, atoms)))
        assert (s.check() == z3.unsat) == (vc.name == "tool_in_region"), vc.name


@pytest.mark.parametrize("name", ["tool_vertex_left_out", "tool_margin_nearest_vertex",
                                  "tool_in_link1_frame"])
def test_each_tool_fault_refutes_its_vc(tool_kit: T.ToolKit, name: str):
    mod = _planted(name)
    reading = T.read_tool(reach=mod.link_reach, rectangles=mod.link_rectangles)
    tk = T.tool_kit(reading, tool_kit.kit)
    vcs = {v.name: v for v in T.tool_region_query(tk).vcs}
    target = CAUGHT_BY[name][1]
    assert _refuted(vcs[target]), name
    # The rest still holds: the fault is caught where it is, not by a broken encoding.
    assert _proved(vcs["grow_square"])


def test_the_tool_faults_change_impls_floats():
    s = cfmpa.spec.load_scenario(Path(cfmpa.spec.__file__).parents[1] / "scenarios" / "gripper.toml")
    arm = s.right
    t1, t2 = np.array(0.4), np.array(1.2)
    want = link_rectangles(arm, t1, t2, 2, grow=0.01)
    for name in ("tool_vertex_left_out", "tool_in_link1_frame"):
        got = _planted(name).link_rectangles(arm, t1, t2, 2, grow=0.01)
        assert got.shape != want.shape or not np.allclose(got, want), name
    far = _planted("tool_margin_nearest_vertex").link_reach(arm, 2)
    assert far[1] < link_reach(arm, 2)[1]


def test_the_mutants_edit_todays_source_once():
    assert set(MUTANTS) == set(CAUGHT_BY)
    for m in MUTANTS.values():
        src = Path(importlib.import_module(
            f"cfmpa.{m.file.split('/')[0]}.{Path(m.file).stem}").__file__).read_text()  # type: ignore[arg-type]
        for old, new in m.edits:
            assert src.count(old) == 1 and old != new, m.name
