"""The negative controls of cfmpa prove (proofs/_controls.py): each wrong input is rejected by
its checker, each composition premise is needed, and a checker that accepts everything, or a
premise the composition does not need, makes the control (and so the prove run) fail."""

from __future__ import annotations

import json

import pytest
import z3

from cfmpa.proofs import _controls as C
from cfmpa.proofs import _obl_safety as S
from cfmpa.proofs import collect_controls, run_obligations
from cfmpa.proofs._obligation import VC


@pytest.mark.parametrize("control", C.checker_controls(), ids=lambda c: c.id)
def test_every_checker_rejects_its_wrong_input(control):
    r = C.run_control(control)
    assert r.ok and r.outcome == "rejected", r.detail


@pytest.mark.parametrize("name,target", [
    ("Control.witness.forged", "check_witness"),
    ("Control.witness.worse_path", "check_witness"),
    ("Control.dr.unsound_free_cell", "dr_cell_failures"),
    ("Control.path.through_blocked", "path_violations"),
])
def test_a_checker_that_accepts_everything_fails_its_control(monkeypatch, name, target):
    # Seeded fault: the checker replaced by one that finds nothing wrong.
    fake = (lambda *a, **k: (0, [])) if target == "dr_cell_failures" else (lambda *a, **k: [])
    monkeypatch.setattr(C, target, fake)
    control = next(c for c in C.checker_controls() if c.id == name)
    r = C.run_control(control)
    assert r.outcome == "accepted" and not r.ok


def test_a_certificate_that_clears_everything_fails_its_control(monkeypatch):
    real = C.certify

    def lenient(*a, **k):
        from dataclasses import replace
        return replace(real(*a, **k), clear=True)
    monkeypatch.setattr(C, "certify", lenient)
    control = next(c for c in C.checker_controls() if c.id == "Control.certificate.contact")
    assert not C.run_control(control).ok


def test_a_control_that_cannot_build_its_input_is_an_error_not_a_pass(monkeypatch):
    monkeypatch.setattr(C, "is_path", lambda *a, **k: False)      # no valid worse path exists
    control = next(c for c in C.checker_controls() if c.id == "Control.witness.worse_path")
    r = C.run_control(control)
    assert r.outcome == "error" and not r.ok and "ControlNotMade" in r.detail


def test_premise_controls_cover_every_hypothesis_but_the_lemma_instances():
    for v in S.VARIANTS:
        names = [n for n, _ in S.composition_vc(v).hypotheses]
        ids = [c.what for c in C.premise_controls() if c.checker == f"Safety.{v}.composition"]
        assert ids == [f"without: {n}" for n in names if not n.startswith(C.LEMMA_INSTANCE)]
        assert len(ids) >= 15


@pytest.mark.parametrize("index", [6, 9, 11])   # the postcondition, eps, A12
def test_dropping_a_needed_premise_is_refuted(index):
    # A counter-model exists, and Z3 finds it within the control's resource limit: the same
    # answer on a loaded machine (a wall-clock budget there used to end `unknown`).
    vc = S.composition_vc("modified")
    name = vc.hypotheses[index][0]
    assert not name.startswith(C.LEMMA_INSTANCE)
    outcome, detail = C._without("modified", index)
    assert outcome == "refuted", (name, detail)


def test_a_redundant_premise_fails_its_control(monkeypatch):
    # Seeded fault: a composition with a premise it does not need (a copy of t >= 0, renamed).
    real = S.composition_vc

    def padded(variant, **k):
        vc = real(variant, **k)
        extra = ("t >= 0, again", z3.Real("t") >= 0)
        return VC(vc.name, vc.hypotheses + (extra,), vc.goal, vc.key_premise, vc.witness,
                  counter_witness=vc.counter_witness)
    monkeypatch.setattr(S, "composition_vc", padded)
    index = len(padded("tight").hypotheses) - 1
    outcome, _ = C._without("tight", index)
    assert outcome == "proved"
    control = C.Control("c", "Safety.tight.composition", "without: t >= 0, again",
                        ("refuted", "unknown"), lambda: C._without("tight", index))
    assert not C.run_control(control).ok


def test_controls_are_results_and_gate_the_run(tmp_path):
    good = C.checker_controls()[:1]
    bad = [C.Control("Control.planted", "nothing", "a control that cannot pass", ("rejected",),
                     lambda: ("accepted", "planted"))]
    run = run_obligations([], tmp_path, [], controls=good)
    assert run.ok and run.controls[0].ok
    doc = json.loads((tmp_path / "results.json").read_text())
    assert doc["controls"][0]["id"] == "Control.witness.forged"
    assert doc["controls_summary"] == {"total": 1, "as_expected": 1, "rejected": 1}
    run = run_obligations([], tmp_path, [], controls=good + bad)
    assert not run.ok


def test_only_selects_controls_by_id_or_by_their_composition():
    assert [c.id for c in collect_controls(["Control.witness"])] == [
        "Control.witness.forged", "Control.witness.worse_path", "Control.witness.raised_start"]
    picked = collect_controls(["Safety.tight.composition"])
    assert picked and all(c.checker == "Safety.tight.composition" for c in picked)
    assert collect_controls(["Thm1"]) == []


def test_premise_controls_wall_clock_is_only_a_net(monkeypatch):
    """Each premise control's check runs under its resource limit with the wall clock as the
    same net the obligations' checks have (``_limits.wall_net_ms``): a loaded machine must not
    end a check on the clock before its resource count. Seeded fault: the bare 10 s (the limit
    ``without[35]`` once hit under load) fails this."""
    from cfmpa.proofs import _obligation as O
    from cfmpa.proofs._limits import WALL_NET_FACTOR

    seen = []
    real = O._solver

    def spy(timeout_ms, *a, **k):
        seen.append((timeout_ms, k.get("rlimit")))
        return real(timeout_ms, *a, **k)
    monkeypatch.setattr(O, "_solver", spy)
    C._without("modified", 9)
    assert seen and all(ms >= WALL_NET_FACTOR * C.PREMISE_PINNED_MS and rl is not None
                        for ms, rl in seen)
