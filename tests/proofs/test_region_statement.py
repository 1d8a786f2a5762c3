"""Safety.region_statement (docs/model.md §10 (c')): the compositions' region statement derived
from Safety.region_soundness's lemmas and the definitions of a link and a region; each seeded
fault (the region grown by half the margin, link 2's frame turned by theta1 only, the region's
lattice one index short, the loader's spacing check dropped) fails it. The two definitions are
checked against impl's own rectangles and swept points on random arms, boxes and lattices."""

from __future__ import annotations

import math

import numpy as np
import pytest
import z3
from hypothesis import given, settings
from hypothesis import strategies as st

from cfmpa.impl import lattice_range, link_reach, link_rectangles, sweep_margin
from cfmpa.impl._regions import swept_points  # the points impl.swept_region hulls
from cfmpa.proofs import _obl_safety as S
from cfmpa.proofs import _obl_safety_region as SC
from cfmpa.proofs._obligation import VC
from cfmpa.spec import Arm
from z3answer import answer

ARMS = ("L", "R")


@pytest.fixture(scope="module")
def kit() -> SC.Kit:
    return SC.region_kit()


def _proves(vc: VC) -> bool:
    hyps = [h for _, h in vc.hypotheses]
    vacuous = answer(hyps + [c == v for c, v in vc.witness], seeds=1, timeout_ms=20_000)
    return vacuous == z3.sat and answer(hyps + [z3.Not(vc.goal)], seeds=1,
                                        timeout_ms=20_000) == z3.unsat


def _refuted(vc: VC, drop: str) -> bool:
    """A counter-model without ``drop``, at the VC's small arm (its counter-witness pins)."""
    hyps = [h for n, h in vc.hypotheses if n != drop]
    return answer(hyps + [z3.Not(vc.goal)] + [c == v for c, v in vc.counter_witness], seeds=1,
                  timeout_ms=10_000) == z3.sat


def _not_proved(vc: VC, drop: str | None = None) -> bool:
    hyps = [h for n, h in vc.hypotheses if n != drop]
    return answer(hyps + [z3.Not(vc.goal)], seeds=1, timeout_ms=10_000) != z3.unsat


@pytest.mark.parametrize("tag", ARMS)
@pytest.mark.parametrize("x", S.LINKS)
def test_the_statement_is_derived_and_needs_the_hull(kit, tag, x):
    vc = S.region_statement_vc(S.ArmModel.named(tag), x, kit)
    assert _proves(vc)
    # Without the hull's definition: a counter-model (found at once; no wait for a timeout).
    assert _refuted(vc, vc.key_premise)
    # The lemma's instance is used, not a copy: without it nothing gives the corners.
    lemma = next(n for n, _ in vc.hypotheses if n.startswith(f"by link{x + 1}_in_region"))
    assert _not_proved(vc, lemma)


def test_the_statement_is_the_composition_premise(kit):
    # region_instances' premise is the derived goal, universally closed: the same term.
    vc = S.region_instance_vc("modified")
    premise = dict(vc.hypotheses)["Safety.region_statement for the principal's links"]
    arm = S.ArmModel.named("L")
    closed = z3.And([z3.ForAll(*S.region_statement(arm, x)) for x in S.LINKS])
    assert z3.eq(premise, closed)
    for x in S.LINKS:
        assert z3.eq(S.region_statement_vc(arm, x, kit).goal, S.region_statement(arm, x)[1])


@pytest.mark.parametrize("x", S.LINKS)
def test_a_region_grown_by_half_the_margin_fails(kit, x):
    # Seeded fault: the region built with half of sweep_margin (the lemma keeps the full one).
    def half(arm, link, g, moving=(True, True)):
        return sweep_margin(arm, link, g, moving) / 2
    vc = S.region_statement_vc(S.ArmModel.named("L"), x, kit, margin=half)
    assert _not_proved(vc)


def test_link2_turned_by_theta1_only_fails(kit, monkeypatch):
    # Seeded fault: the link's definition with link 2's frame at theta1, not theta1 + theta2.
    monkeypatch.setattr(S.ArmModel, "point",
                        lambda self, x, theta, uv: self.frame_point(x, theta[0], theta[0], uv))
    assert _not_proved(S.region_statement_vc(S.ArmModel.named("R"), 1, kit))


@pytest.mark.parametrize("x", S.LINKS)
def test_a_lattice_one_index_short_fails(kit, monkeypatch, x):
    # Seeded fault: the region's lattice stops one index before lattice_range's end.
    real = S.lattice_range

    def short(lo, hi, anchor, g):
        i_lo, i_hi = real(lo, hi, anchor, g)
        return i_lo, i_hi - 1
    monkeypatch.setattr(S, "lattice_range", short)
    assert _not_proved(S.region_statement_vc(S.ArmModel.named("L"), x, kit))


@pytest.mark.parametrize("variant", S.VARIANTS)
def test_the_instances_need_the_loader_spacing_check(variant):
    vc = S.region_instance_vc(variant)
    drop = "the loader's spacing checks: 0 < omega_q dt <= 157/50, 0 < h_q <= 157/50"
    assert drop in dict(vc.hypotheses)
    # A counter-model at the small pins where Z3 finds one at once, else no proof in 10 s.
    assert _refuted(vc, drop) or _not_proved(vc, drop)


# --- the definitions against impl's construction ------------------------------------------------

@pytest.mark.parametrize("x", S.LINKS)
def test_the_rectangle_is_impls_read_on_terms(x):
    # impl.link_rectangles, run on terms, has the corners of the definitions' rectangle.
    vc = S.rectangle_vc(x)
    assert _proves(vc)
    hyps = [h for n, h in vc.hypotheses if n != vc.key_premise]
    assert answer(hyps + [z3.Not(vc.goal)], seeds=1, timeout_ms=10_000) == z3.sat


@pytest.mark.parametrize("x", S.LINKS)
def test_a_rectangle_not_extended_past_its_joint_fails(x, monkeypatch):
    # Seeded fault, planted in a copy of impl's source: the rectangle starts at its joint.
    import sys

    from mutant_module import mutated_module
    mod = mutated_module("rect_short", "impl/_kinematics.py",
                         (("    back = start - r * along\n", "    back = start\n"),),
                         lambda n, m: monkeypatch.setitem(sys.modules, n, m))
    vc = S.rectangle_vc(x, mod.link_rectangles)
    assert answer([h for _, h in vc.hypotheses] + [z3.Not(vc.goal)], seeds=1,
                  timeout_ms=10_000) == z3.sat


def _num(f: z3.ExprRef, env: dict[str, float]) -> float:
    """f evaluated in floats, Cos and Sin read as math.cos and math.sin."""
    if z3.is_rational_value(f):
        return float(f.as_fraction())
    if z3.is_const(f):
        return env[str(f)]
    args = [_num(c, env) for c in f.children()]
    name = f.decl().name()
    if name == "Cos":
        return math.cos(args[0])
    if name == "Sin":
        return math.sin(args[0])
    if z3.is_add(f):
        return sum(args)
    if z3.is_mul(f):
        return math.prod(args)
    if z3.is_sub(f):
        return args[0] - sum(args[1:])
    if f.decl().kind() == z3.Z3_OP_UMINUS:
        return -args[0]
    raise ValueError(f"cannot evaluate {f}")


def _env(arm: Arm, tag: str) -> dict[str, float]:
    r = arm.width / 2
    return {f"{tag}.b.x": arm.base[0], f"{tag}.b.y": arm.base[1], f"{tag}.l1": arm.links[0],
            f"{tag}.l2": arm.links[1], f"{tag}.r1": r, f"{tag}.r2": r}


def _rect_corners(r: float, ell: float) -> list[tuple[float, float]]:
    return [(-r, -r), (ell + r, -r), (ell + r, r), (-r, r)]


def _model_points(model: S.ArmModel, x: int, arm: Arm, configs, grow: float) -> np.ndarray:
    env = _env(arm, model.tag)
    ell = arm.links[x]
    out = []
    for a, b in configs:
        for u, v in _rect_corners(arm.width / 2 + grow, ell):
            p = model.frame_point(x, SC._q(a), SC._q(a) + SC._q(b), (SC._q(u), SC._q(v)))
            out.append((_num(p[0], env), _num(p[1], env)))
    return np.array(out)


def _same_set(a: np.ndarray, b: np.ndarray) -> bool:
    def covered(p: np.ndarray, q: np.ndarray) -> bool:
        d = np.abs(p[:, None, :] - q[None, :, :]).max(axis=-1)
        return bool((d.min(axis=1) <= 1e-9).all())
    return covered(a, b) and covered(b, a)


arms = st.builds(
    lambda bx, by, l1, l2, w: Arm(base=(bx, by), links=(l1, l2), width=w, omega=(1.0, 1.0)),
    st.floats(-1, 1), st.floats(-1, 1), st.floats(0.1, 1), st.floats(0.1, 1),
    st.floats(0.01, 0.2))


@settings(max_examples=25, deadline=None)
@given(arm=arms, x=st.sampled_from(S.LINKS), t1=st.floats(-3, 3), t2=st.floats(-3, 3))
def test_the_link_definition_is_impl_s_rectangle(arm, x, t1, t2):
    want = link_rectangles(arm, np.array(t1), np.array(t2), x)
    got = _model_points(S.ArmModel.named("L"), x, arm, [(t1, t2)], 0.0)
    assert _same_set(got, want.reshape(-1, 2))


@settings(max_examples=25, deadline=None)
@given(arm=arms, x=st.sampled_from(S.LINKS), lo1=st.floats(-2, 2), w1=st.floats(0, 0.3),
       lo2=st.floats(-2, 2), w2=st.floats(0, 0.3), a1=st.floats(-2, 2), a2=st.floats(-2, 2),
       g1=st.floats(0.05, 0.3), g2=st.floats(0.05, 0.3))
def test_the_hull_definition_generates_impl_s_swept_points(arm, x, lo1, w1, lo2, w2, a1, a2,
                                                         g1, g2):
    # The region's generators by the hull's definition (lattice_range's indices, the grown
    # rectangles' corners at the lattice configurations, sweep_margin's margin) are the points
    # impl.swept_points hulls.
    box = ((lo1, lo1 + w1), (lo2, lo2 + w2))
    g = (g1, g2)
    want = swept_points(arm, x, box, (a1, a2), g)
    lat = [lattice_range(box[q][0], box[q][1], (a1, a2)[q], g[q]) for q in range(2)]
    if x == 0:
        lat[1] = (0, 0)
    moving = (lat[0][1] > lat[0][0], x == 1 and lat[1][1] > lat[1][0])
    grow = sweep_margin(arm, x, g, moving)
    configs = [(a1 + i * g1, (a2 + j * g2) if x == 1 else a2)
               for i in range(lat[0][0], lat[0][1] + 1) for j in range(lat[1][0], lat[1][1] + 1)]
    model = S.ArmModel.named("R")
    got = _model_points(model, x, arm, configs, grow)
    assert _same_set(got, want)
    # The margin the definition reads is sweep_margin's at those values.
    rb, re = link_reach(arm, x)
    env = {**_env(arm, "R"), "R.Rb1": rb if x == 0 else 0.0, "R.Re2": re}
    # Read on symbols (impl_margin reads sweep_margin on symbolic spacings), then evaluated.
    names = ["lo1", "hi1", "lo2", "hi2", "A1", "A2", "g1", "g2"]
    sym = z3.Reals(" ".join(f"m!{n}" for n in names))
    term = model.margin(x, ((sym[0], sym[1]), (sym[2], sym[3])), (sym[4], sym[5]),
                        (sym[6], sym[7]))
    values = (box[0][0], box[0][1], box[1][0], box[1][1], a1, a2, g1, g2)
    pairs = [(z3.Real(k), SC._q(v)) for k, v in env.items()] + [
        (c, SC._q(v)) for c, v in zip(sym, values)]
    val = z3.simplify(z3.substitute(term, *pairs))
    assert abs(float(val.as_fraction()) - grow) <= 1e-12 * max(1.0, grow)


def test_the_comparison_with_impl_catches_a_wrong_frame(monkeypatch):
    # Seeded fault for the two checks above: link 2's frame turned by theta1 only.
    arm = Arm(base=(0.1, -0.2), links=(0.5, 0.4), width=0.05, omega=(1.0, 1.0))
    want = link_rectangles(arm, np.array(0.3), np.array(0.7), 1).reshape(-1, 2)
    assert _same_set(_model_points(S.ArmModel.named("L"), 1, arm, [(0.3, 0.7)], 0.0), want)
    monkeypatch.setattr(S.ArmModel, "frame_point",
                        lambda self, x, alpha, phi, uv: SC._point2(self.b, self.l1, alpha, alpha,
                                                                  uv[0], uv[1]))
    assert not _same_set(_model_points(S.ArmModel.named("L"), 1, arm, [(0.3, 0.7)], 0.0), want)
