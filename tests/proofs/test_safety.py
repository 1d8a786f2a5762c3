"""Safety.* (docs/model.md §10): every obligation is proved, none by its Boolean skeleton, and
each fails, with Z3 answering sat, once a key premise is dropped or a constant is mutated: the
margin lemma's 1/8 -> 1/16, sweep_margin's 1/8 -> 1/16, the modified box's sign flipped, the
subordinate allowed to jump two cells, N dt < Tf. The box rules are spec.left_box's and
spec.right_box's on the bundled scenarios, and the margin read from impl is impl's formula."""

from __future__ import annotations

from pathlib import Path

import pytest
import z3

from cfmpa.impl import SNAP, link_reach, sweep_margin
from cfmpa.proofs import FIXED_IDS, collect_obligations
from cfmpa.proofs import _obl_arc_chord as ARC
from cfmpa.proofs import _obl_safety as S
from cfmpa.proofs import _obl_safety_principal as SA
from cfmpa.proofs import _obl_safety_region as SC
from cfmpa.proofs import _obl_safety_separation as SD
from cfmpa.proofs import _obl_safety_subordinate as SB
from cfmpa.proofs._obligation import VC
from cfmpa.spec import exact_n, exact_tf, left_angles, left_box, load_scenario, make_grid, right_box
from z3answer import answer, as_float, exact_real

REPO = Path(__file__).resolve().parents[2]
IDS = [f"Safety.{v}.principal_in_layer_box" for v in S.VARIANTS] + [
    "Safety.subordinate_in_cell_box", "Safety.region_soundness", "Safety.region_statement",
    "Safety.separation"] + [
    f"Safety.{v}.composition" for v in S.VARIANTS]
#: Tools and heights (proofs/_obl_tools.py), tested in tests/proofs/test_obl_tools.py.
TOOL_IDS = ["Safety.height_rule", "Safety.tool_region"]


def _check(hyps, goal=None, pins=(), seeds=3, timeout=20_000) -> z3.CheckSatResult:
    """Z3 on hyps (and not goal), with the pins: sat, unsat, or unknown after the seeds."""
    return answer(list(hyps) + ([z3.Not(goal)] if goal is not None else [])
                  + [c == v for c, v in pins], seeds=seeds, timeout_ms=timeout)


def _hyps(vc: VC, drop: str | None = None) -> list[z3.BoolRef]:
    return [h for n, h in vc.hypotheses if n != drop]


def _proved(vc: VC) -> bool:
    return (_check(_hyps(vc), pins=vc.witness, seeds=1) == z3.sat
            and _check(_hyps(vc), vc.goal, seeds=1) == z3.unsat)


def _refuted(vc: VC, drop: str | None = None, pins=None) -> bool:
    return _check(_hyps(vc, drop), vc.goal,
                  pins=vc.counter_witness if pins is None else pins) == z3.sat


@pytest.fixture(scope="module")
def queries() -> dict[str, tuple[VC, ...]]:
    obs = {o.id: o for o in collect_obligations("/nonexistent", ["Safety"])}
    return {i: obs[i].build().vcs for i in IDS}


def test_the_safety_ids_are_registered_and_pinned():
    obs = [o.id for o in collect_obligations("/nonexistent", ["Safety"])]
    assert obs == IDS + TOOL_IDS
    assert all(i in FIXED_IDS for i in IDS + TOOL_IDS)


def test_every_safety_vc_is_proved_with_satisfiable_hypotheses(queries):
    for ident, vcs in queries.items():
        for vc in vcs:
            assert _proved(vc), f"{ident}/{vc.name}"


# --- not by the Boolean skeleton -----------------------------------------------------------------

_CONNECTIVES = {z3.Z3_OP_AND, z3.Z3_OP_OR, z3.Z3_OP_NOT, z3.Z3_OP_IMPLIES, z3.Z3_OP_XOR,
                z3.Z3_OP_TRUE, z3.Z3_OP_FALSE}


def _skeleton(f: z3.ExprRef, atoms: dict[int, z3.BoolRef]) -> z3.BoolRef:
    """f with every atom (a Boolean term whose head is not a connective: a comparison, an
    application, a quantifier) replaced by a fresh Boolean, equal atoms by the same one."""
    if z3.is_quantifier(f) or not z3.is_app(f):
        key = f.get_id()
    else:
        k = f.decl().kind()
        if k in _CONNECTIVES:
            return f.decl()(*[_skeleton(c, atoms) for c in f.children()]) if f.num_args() else f
        if k == z3.Z3_OP_ITE and z3.is_bool(f):
            return z3.If(_skeleton(f.arg(0), atoms), _skeleton(f.arg(1), atoms),
                         _skeleton(f.arg(2), atoms))
        if k == z3.Z3_OP_EQ and z3.is_bool(f.arg(0)):
            return _skeleton(f.arg(0), atoms) == _skeleton(f.arg(1), atoms)
        key = f.get_id()
    if key not in atoms:
        atoms[key] = z3.Bool(f"atom!{len(atoms)}")
    return atoms[key]


def test_no_safety_vc_is_proved_by_its_boolean_skeleton(queries):
    for ident, vcs in queries.items():
        for vc in vcs:
            atoms: dict[int, z3.BoolRef] = {}
            hyps = [_skeleton(h, atoms) for h in _hyps(vc)]
            goal = _skeleton(vc.goal, atoms)
            s = z3.Solver()
            s.add(hyps)
            s.add(z3.Not(goal))
            assert s.check() == z3.sat, f"{ident}/{vc.name} holds by its Boolean skeleton"


def test_the_skeleton_test_catches_a_propositional_vc():
    a, b = z3.Ints("a b")
    vc = VC("p", (("a < b", a < b), ("a < b implies b > a", z3.Implies(a < b, b > a))), b > a)
    atoms: dict[int, z3.BoolRef] = {}
    s = z3.Solver()
    s.add([_skeleton(h, atoms) for h in _hyps(vc)])
    s.add(z3.Not(_skeleton(vc.goal, atoms)))
    assert s.check() == z3.unsat


# --- (a) the principal -------------------------------------------------------------------------

@pytest.mark.parametrize("variant", S.VARIANTS)
def test_principal_needs_its_step_window(variant):
    motion, rest = SA.principal_lemmas(variant)
    assert _refuted(motion.vc, motion.vc.key_premise)
    assert _refuted(rest.vc, rest.vc.key_premise)      # N's definition dropped


@pytest.mark.parametrize("variant", S.VARIANTS)
def test_principal_rest_fails_when_N_dt_falls_short_of_Tf(variant):
    P = SA.Principal.named()
    short = ("N >= 1, N dt < Tf", z3.And(P.N >= 1, z3.ToReal(P.N) * P.dt < P.Tf))
    _, rest = SA.principal_lemmas(variant, n_def=short)
    assert _refuted(rest.vc)


@pytest.mark.parametrize("variant", S.VARIANTS)
def test_principal_motion_needs_the_speed_bound(variant):
    # Without Tf = max_q |goal_q - start_q| / omega_q a joint may outrun its box.
    motion, _ = SA.principal_lemmas(variant)
    tf = SA.Principal.named().tf_def()[0]
    if variant == "tight":
        # The tight box follows the motion itself: it holds for any Tf >= 0.
        assert not _refuted(motion.vc, tf)
    else:
        assert _refuted(motion.vc, tf)


def test_the_modified_box_with_its_sign_flipped_misses_the_motion():
    motion, rest = SA.principal_lemmas("modified", sign_flip=True)
    assert _refuted(motion.vc)
    assert _refuted(rest.vc)


def _scenarios():
    return sorted((REPO / "scenarios").glob("*.toml"))




@pytest.mark.parametrize("path", _scenarios(), ids=lambda p: p.stem)
def test_the_box_rules_are_spec_left_box_and_right_box(path):
    s = load_scenario(path)
    P = SA.Principal.named()
    pins = [(P.start[q], exact_real(s.left.start[q])) for q in range(2)]
    pins += [(P.goal[q], exact_real(s.left.goal[q])) for q in range(2)]
    pins += [(P.omega[q], exact_real(s.left.omega[q])) for q in range(2)]
    pins += [(P.dt, exact_real(s.dt)), (P.Tf, exact_real(exact_tf(s))), (P.N, z3.IntVal(exact_n(s)))]

    def sub(e: z3.ExprRef) -> z3.ExprRef:
        return z3.substitute(e, *pins)
    N = exact_n(s)
    for variant in S.VARIANTS:
        for k in sorted({0, 1, N // 2, N - 1}):
            box = P.box(variant, z3.RealVal(k))
            want = left_box(s, variant, k)
            for q in range(2):
                for side in range(2):
                    assert as_float(sub(box[q][side])) == pytest.approx(want[q][side], abs=1e-12)
        rest = P.rest_box(variant)
        want = (tuple((g, g) for g in s.left.goal) if variant == "tight"
                else left_box(s, variant, N - 1))
        for q in range(2):
            for side in range(2):
                assert as_float(sub(rest[q][side])) == pytest.approx(want[q][side], abs=1e-12)
    # The PTP formula is spec.left_angles'.
    for t in (0.0, s.dt / 3, 0.5 * float(exact_tf(s)), 2.0 * float(exact_tf(s)) + 1):
        th = P.theta(exact_real(t))
        a = left_angles(s, t)
        for q in range(2):
            assert as_float(sub(th[q])) == pytest.approx(float(a[q]), abs=1e-12)
    # The subordinate's box is spec.right_box's.
    g = make_grid(s)
    R = SB.Subordinate.named()
    rpins = ([(R.lo[q], exact_real(g.lo[q])) for q in range(2)]
             + [(R.h[q], exact_real(g.h[q])) for q in range(2)])
    for cell in ((0, 0), (g.m - 1, g.n - 1), (g.m // 2, 1)):
        box = R.box((z3.IntVal(cell[0]), z3.IntVal(cell[1])))
        want = right_box(g, cell)
        for q in range(2):
            for side in range(2):
                assert (as_float(z3.substitute(box[q][side], *rpins))
                        == pytest.approx(want[q][side], abs=1e-12))


# --- (b) the subordinate -----------------------------------------------------------------------

def test_a_jump_of_two_cells_leaves_the_box():
    move, _ = SB.subordinate_lemmas(reach=2)
    assert _refuted(move.vc)
    move, on_path = SB.subordinate_lemmas()
    assert _refuted(move.vc, move.vc.key_premise)
    assert _refuted(on_path.vc, on_path.vc.key_premise)


# --- (c) region soundness ------------------------------------------------------------------------

def _sixteenth(arm, link, g, moving=(True, True)):
    """sweep_margin with g^2/16 for g^2/8: a margin too small for the lemma."""
    reach = link_reach(arm, link)
    delta = 0.0
    for q in range(2):
        if moving[q]:
            delta += g[q] ** 2 / 16.0 * reach[q]
        delta += SNAP * g[q] * reach[q]
    return delta


def _arc_with(constant: int) -> VC:
    """Margin.arc_chord's VC with its bound r g^2/8 written r g^2/constant."""
    arc = ARC.arc_chord()
    goal = z3.substitute(arc.vc.goal, (arc.delta, arc.r * arc.g * arc.g / constant))
    assert not z3.eq(goal, arc.vc.goal)
    return VC(arc.vc.name, arc.vc.hypotheses, goal, arc.vc.key_premise)


def test_region_soundness_instantiates_the_proved_arc_lemma(queries):
    from cfmpa.proofs import collect_obligations as all_obs
    arc = next(o for o in all_obs("/nonexistent", ["Margin.arc_chord"])).build().vcs[0]
    first = queries["Safety.region_soundness"][0]
    assert first.name == "Margin.arc_chord" and z3.eq(first.goal, arc.goal)
    # Its premises, then only instances of the proved steps (arc_weight, arc_dist, arc_gap,
    # square_monotone), each itself a VC of the obligation.
    names = [n for n, _ in first.hypotheses]
    assert names[:len(arc.hypotheses)] == [n for n, _ in arc.hypotheses]
    assert all(z3.eq(h, h0) for (_, h), (_, h0) in zip(first.hypotheses, arc.hypotheses))
    steps = [n.split()[1] for n in names[len(arc.hypotheses):]]
    assert steps == ["arc_weight", "arc_dist", "arc_gap", "square_monotone"]
    assert set(steps) <= {vc.name for vc in queries["Safety.region_soundness"]}


def test_a_margin_lemma_with_1_16_is_refuted():
    kit = SC.region_kit(arc_vc=_arc_with(16))
    # The step where the constant is paid (cos x >= 1 - x^2/2 gives g^2/8, not g^2/16) fails.
    assert _refuted(kit["arc_gap"].vc, pins=())
    assert not _refuted(kit["arc_weight"].vc, pins=()) and not _refuted(kit["arc_dist"].vc, pins=())


def test_a_weaker_margin_lemma_no_longer_covers_sweep_margin():
    # r g^2/4 is true of an arc, but more than sweep_margin adds: margin_covers fails.
    kit = SC.region_kit(arc_vc=_arc_with(4))
    assert not _refuted(SC.region_query(kit).vcs[0], pins=()) and not _refuted(kit["arc_gap"].vc)
    for name in ("margin_covers_link1", "margin_covers_link2"):
        assert _refuted(kit[name].vc, pins=())


def test_sweep_margin_with_1_16_fails_the_margin_comparison():
    kit = SC.region_kit(margin=_sixteenth)
    for name in ("margin_covers_link1", "margin_covers_link2"):
        assert _refuted(kit[name].vc, pins=())
    # ... and the composition reads the same mutant: its margin hypothesis changed.
    good = SC.region_kit()
    for name in ("link1_in_region", "link2_in_region"):
        key = good[name].vc.key_premise
        mutated = dict(kit[name].vc.hypotheses)[key]
        assert not z3.eq(mutated, dict(good[name].vc.hypotheses)[key])


def test_the_margin_read_from_impl_is_its_formula():
    g1, g2, rb, re = z3.Reals("g1 g2 Rb Re")
    for link in (0, 1):
        for flags in ((True, True), (True, False), (False, True), (False, False)):
            if link == 0 and flags[1]:
                continue
            read = SC.impl_margin_term(link, (g1, g2), (rb, re), flags)
            reach = (rb, re if link == 1 else z3.RealVal(0))
            want = sum((g * g / 8 * r if f else 0) + SC.SNAP_Q * g * r
                       for g, r, f in zip((g1, g2), reach, flags))
            s = z3.Solver()
            s.add(read != want)
            assert s.check() == z3.unsat, (link, flags)
    # A margin function the reading cannot follow is refused, not read wrong.
    with pytest.raises(ValueError, match="the margin read"):
        SC.impl_margin_term(1, (g1, g2), (rb, re), (True, True),
                           lambda arm, link, g, moving: sweep_margin(arm, link, (0.5, 0.5), moving))


def test_the_lattice_model_is_lattice_range():
    SC.check_lattice_reading()


def test_a_widened_snap_fails_lattice_span(monkeypatch):
    # Seeded fault: impl.lattice_range snapping within 1000 SNAP g (a copy run on the symbols):
    # the lattice may then stop short of the box by more than the margin pays for.
    from cfmpa.spec import cases, ceil_of, floor_of, max_of, min_of

    def wide(lo, hi, anchor, g):
        def span():
            i_lo = floor_of((lo - anchor) / g + 1000 * SNAP)
            i_hi = ceil_of((hi - anchor) / g - 1000 * SNAP)
            return (min_of(i_lo, i_hi), max_of(i_lo, i_hi))
        return cases(g <= 0, lambda: (0, 0), span)
    good = {L.vc.name: L.vc for L in SC._lattice()}
    assert not _refuted(good["lattice_span"], pins=())
    monkeypatch.setattr(SC, "lattice_range", wide)
    span, snap, whole = SC._lattice()
    assert span.vc.name == "lattice_span" and _refuted(span.vc, pins=())


def test_region_lemmas_need_their_key_premises():
    kit = SC.region_kit()
    for name, L in kit.lemmas.items():
        assert _refuted(L.vc, L.vc.key_premise), name


# --- (d), (e) ------------------------------------------------------------------------------------

def test_separation_needs_the_rounding_bound_and_the_distance():
    margin, common = SD.separation_lemmas()
    assert _refuted(margin.vc, margin.vc.key_premise)
    assert _refuted(common.vc, common.vc.key_premise)
    assert _refuted(common.vc, "(c) link a of the principal at theta_L lies in A (at p)")


@pytest.mark.parametrize("eps", ["0", "1e-12", "2e-11"])
def test_an_eps_below_the_rounding_bound_is_refuted(eps):
    # Seeded fault: spec.EPS set below spec.DISTANCE_ERROR_M (2.8e-11 m); eps_margin must fail.
    margin, _ = SD.separation_lemmas()
    vc = margin.vc
    hyps = tuple((n, z3.Real("eps") == z3.RealVal(eps)) if n == S.EPS_HYP else (n, h)
                 for n, h in vc.hypotheses)
    assert _refuted(VC(vc.name, hyps, vc.goal))


@pytest.mark.parametrize("variant", S.VARIANTS)
def test_composition_needs_the_postcondition_and_the_regions(variant):
    vc = S.composition_vc(variant)
    assert _refuted(vc, vc.key_premise)
    # Without (c), nothing puts the links in the regions D_R was decided on.
    stripped = VC(vc.name, tuple(h for h in vc.hypotheses
                                 if not h[0].startswith("(c) Safety.region_soundness")),
                  vc.goal, counter_witness=vc.counter_witness)
    assert len(stripped.hypotheses) == len(vc.hypotheses) - 3
    assert _refuted(stripped)


@pytest.mark.parametrize("variant", S.VARIANTS)
def test_a_strengthened_region_hypothesis_is_refuted_by_the_instance_check(variant, monkeypatch):
    # Seeded fault: the principal's layer-k region hypothesis without its box condition. The
    # composition still proves (a stronger hypothesis), the instance check must not.
    real = S.region_hypotheses

    def strong(v, at):
        hs = real(v, at)
        region_l, _, _ = S._regions(v)
        hs[0] = (hs[0][0], z3.And([z3.Implies(z3.And(0 <= at.k, at.k < at.d.N), z3.Implies(
            SD.link_l(x, at.theta_l, at.p), S.member(region_l(at.k, x), at.p)))
            for x in S.LINKS]))
        return hs
    assert _proved(S.region_instance_vc(variant))
    monkeypatch.setattr(S, "region_hypotheses", strong)
    assert _refuted(S.region_instance_vc(variant))


def test_the_time_step_needs_t_nonnegative():
    L = S._step_lemma()
    assert _refuted(L.vc, L.vc.key_premise)


def test_composition_rests_on_the_proved_parts(queries):
    # The (a), (b), (d) lemmas and Def4.is_path_fixed_safe enter by substitution of their VCs.
    vc = S.composition_vc("modified")
    names = " | ".join(n for n, _ in vc.hypotheses)
    for part in ("by motion at", "by rest at", "by neighbour_move at", "by time_step at",
                 "by pair_apart at", S.EPS_HYP, S.ERR_HYP, "A12 at the eighteen pairs",
                 "is_path L (fixed", S.HEIGHT_HYP):
        assert part in names


# --- every part: the tools and the height rule (docs/model.md §10 (e)) ---------------------------

def test_the_composition_ranges_over_every_part_pair():
    # The goal names the prisms of all nine (left part, right part) pairs, tools included, and
    # BuiltDR's postcondition the pairs the height rule keeps.
    vc = S.composition_vc("tight")
    pairs = [tuple(c.arg(0).as_long() for c in conj.arg(0).children())
             for conj in vc.goal.children()]
    assert pairs == [(x, y) for x in S.PARTS for y in S.PARTS]
    post = dict(vc.hypotheses)[vc.key_premise]
    names = set()
    todo = [post]
    while todo:
        t = todo.pop()
        if z3.is_const(t) and t.decl().kind() == z3.Z3_OP_UNINTERPRETED:
            names.add(str(t))
        todo += t.children()
    assert {"L.has_tool", "R.has_tool", "L.z3.lo", "R.z3.hi"} <= names


@pytest.mark.parametrize("variant", S.VARIANTS)
def test_the_composition_needs_the_height_rule_and_the_tool_regions(variant):
    # The negative controls' premises: without the height rule a pair at disjoint heights may
    # share a point; without the tool's region hypothesis the tool is nowhere BuiltDR looked.
    vc = S.composition_vc(variant)
    assert _refuted(vc, S.HEIGHT_HYP)
    tool = [n for n, _ in vc.hypotheses if n.startswith("(c) Safety.tool_region")]
    assert len(tool) == 3
    stripped = VC(vc.name, tuple(h for h in vc.hypotheses if h[0] not in tool), vc.goal)
    assert _refuted(stripped, pins=vc.counter_witness)


def test_the_height_instances_follow_from_the_prisms():
    vc = S.height_instance_vc()
    assert _proved(vc)
    assert _refuted(vc, vc.key_premise)


def test_heights_compared_strictly_fail_the_height_instances():
    # Seeded fault: heights_overlap with < where <= is meant (touching ends called apart).
    def strict(a, b):
        if a is None or b is None:
            return True
        return a[0] < b[1] and b[0] < a[1]
    assert _refuted(S.height_instance_vc(strict), pins=())


def test_a_pair_the_height_rule_keeps_must_be_free():
    # Seeded fault: the postcondition read without the tool pairs (the links' pairs only, as
    # before the tools): the composition must fail.
    real = S.pair_kept

    def links_only(hl, hr, x, y, overlap=None):
        return z3.And(z3.BoolVal(x != S.TOOL and y != S.TOOL), real(hl, hr, x, y, overlap))
    import unittest.mock as um
    with um.patch.object(S, "pair_kept", links_only):
        bad = S.composition_vc("modified")
    assert _refuted(bad)
