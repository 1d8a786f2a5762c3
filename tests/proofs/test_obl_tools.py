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
from cfmpa.impl import link_reach, link_rectangles, sweep_margin
from cfmpa.proofs import FIXED_IDS, Verdict, collect_obligations
from cfmpa.proofs import _obl_tools as T
from cfmpa.proofs._obl_constants import ExtractionError
from cfmpa.proofs._obligation import VC
from cfmpa.runs._code_mutants import CODE_MUTANTS
from mutant_module import mutated_module
from z3answer import answer

IDS = ["Safety.height_rule", "Safety.tool_region"]
ALL_IDS = IDS + ["Certificate.height_gap"]

#: Each seeded fault, the obligation and the VC it must refute.
CAUGHT_BY = {"heights_compared_strictly": ("Safety.height_rule", "disjoint_no_common_point"),
             "height_gap_far_ends": ("Certificate.height_gap", "gap_vertical"),
             "tool_vertex_left_out": ("Safety.tool_region", "tool_points"),
             "tool_margin_nearest_vertex": ("Safety.tool_region", "far_vertex"),
             "tool_in_link1_frame": ("Safety.tool_region", "tool_points"),
             "travel_time_min": ("Safety.modified.principal_in_layer_box", "travel"),
             "spacing_bound_above_pi": ("Safety.modified.composition", "spacing_below_pi")}
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
                                       "tool_points", "tool_in_region", "tool_statement_L",
                                       "tool_statement_R"]
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


# --- the tool's statement, the compositions' premise (docs/model.md §10 (e)) -------------------

def test_the_tool_statement_is_the_composition_premise(tool_kit: T.ToolKit):
    from cfmpa.proofs import _obl_safety as S
    vc = S.region_instance_vc("tight")
    premises = dict(vc.hypotheses)
    for tag, whose in (("L", "principal"), ("R", "subordinate")):
        st = T.tool_statement_vc(tag, tool_kit)
        assert z3.eq(premises[f"{S.TOOL_STATEMENT} for the {whose}'s tool"],
                     z3.ForAll(*T.tool_statement(tag)))
        assert z3.eq(st.goal, T.tool_statement(tag)[1])


@pytest.mark.slow
def test_the_tool_statement_rests_on_tool_in_region(tool_kit: T.ToolKit):
    # The lemma's instance is used, not a copy, and the tool's definition places the point.
    vc = T.tool_statement_vc("R", tool_kit)
    for drop in ("by tool_in_region", "R: the tool's definition"):
        name = next(n for n, _ in vc.hypotheses if n.startswith(drop))
        assert answer([h for n, h in vc.hypotheses if n != name] + [z3.Not(vc.goal)], seeds=1,
                      timeout_ms=4_000) != z3.unsat, drop


@pytest.mark.slow
def test_a_tool_region_grown_by_half_the_margin_fails_the_statement(tool_kit: T.ToolKit,
                                                                      monkeypatch):
    # Seeded fault: the tool's region (the hull's definition) grown by half of sweep_margin;
    # tool_in_region keeps the full margin.
    real = T.tool_margin
    monkeypatch.setattr(T, "tool_margin", lambda *a: real(*a) / 2)
    vc = T.tool_statement_vc("L", tool_kit)
    assert answer([h for _, h in vc.hypotheses] + [z3.Not(vc.goal)], seeds=1,
                  timeout_ms=10_000) != z3.unsat


@pytest.mark.slow
def test_a_vertex_left_out_of_the_tool_fails_the_statement(tool_kit: T.ToolKit, monkeypatch):
    # Seeded fault: the tool's definition with the last vertex left out of the chain (the
    # region's hull has every vertex): the lemma's point is no longer the tool's.
    real = T.ToolModel.definition

    def short(self, theta, p):
        body = real(self, theta, p)
        conds = list(body.arg(1).children())
        return z3.Implies(body.arg(0), z3.And([c for c in conds if "16" not in str(c)]))
    monkeypatch.setattr(T.ToolModel, "definition", short)
    vc = T.tool_statement_vc("L", tool_kit)
    assert answer([h for _, h in vc.hypotheses] + [z3.Not(vc.goal)], seeds=1,
                  timeout_ms=10_000) != z3.unsat


# --- what the compositions read of the code: Tf, N and the loader's spacing bound ----------------

def test_tf_and_n_are_the_codes_on_floats():
    # counts_on_terms runs spec.exact_tf / exact_n's own code; on numbers it gives their values.
    from fractions import Fraction

    from cfmpa.proofs import _obl_safety_principal as SA
    from cfmpa.spec import exact_n, exact_tf
    s = cfmpa.spec.load_scenario(Path(cfmpa.spec.__file__).parents[1] / "scenarios"
                                 / "default.toml")
    vals = [z3.RealVal(Fraction(x)) for x in (*s.left.start, *s.left.goal, *s.left.omega, s.dt)]
    tf, n = SA.counts_on_terms(tuple(vals[0:2]), tuple(vals[2:4]), tuple(vals[4:6]), vals[6])
    assert z3.simplify(tf).as_fraction() == exact_tf(s)
    assert z3.simplify(n).as_long() == exact_n(s)


def test_tf_max_made_min_refutes_the_travel_lemma(monkeypatch):
    from cfmpa.proofs import _obl_safety as S
    from cfmpa.proofs import _obl_safety_principal as SA
    mod = _planted("travel_time_min")
    real = SA.counts_on_terms
    monkeypatch.setattr(SA, "counts_on_terms",
                        lambda *a, **k: real(*a, travel=mod.travel_time, **k))
    vcs = {v.name: v for v in S._principal_query("modified").vcs}
    assert _refuted(vcs[CAUGHT_BY["travel_time_min"][1]])
    # ... and the composition reads the same Tf: its hypothesis is the mutant's.
    hyp = dict(S.composition_vc("modified").hypotheses)[SA.Principal.named().tf_def()[0]]
    assert z3.eq(hyp.arg(1), real(*_principal_args(SA), travel=mod.travel_time)[0])
    assert not z3.eq(hyp.arg(1), real(*_principal_args(SA))[0])


def _principal_args(SA):
    P = SA.Principal.named()
    return P.start, P.goal, P.omega, P.dt


def test_the_ceiling_on_terms_is_the_codes_on_fractions():
    # counts_on_terms runs exact_n with spec.ceil_of for the code's exact ceiling.
    from fractions import Fraction

    from cfmpa.spec import ceil_of
    from cfmpa.spec._counts import ceil_fraction
    for x in (Fraction(7, 2), Fraction(-7, 2), Fraction(3), Fraction(1, 10**9), Fraction(-5, 3)):
        assert ceil_of(x) == ceil_fraction(x)
        assert z3.simplify(ceil_of(z3.RealVal(x))).as_long() == ceil_fraction(x)


def test_the_proofs_read_the_loaders_spacing_bound():
    from fractions import Fraction

    from cfmpa.proofs import _obl_safety as S
    from cfmpa.spec import MAX_SPACING
    assert S.G_MAX.as_fraction() == MAX_SPACING == Fraction(157, 50)
    assert _proved(S.spacing_bound_vc())


def test_a_spacing_bound_past_pi_is_refuted():
    from cfmpa.proofs import _obl_safety as S
    mod = _planted("spacing_bound_above_pi")
    bound = z3.Q(mod.MAX_SPACING.numerator, mod.MAX_SPACING.denominator)
    assert _refuted(S.spacing_bound_vc(bound))


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
