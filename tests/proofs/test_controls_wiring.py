"""The wiring's controls and the controls' own checks (proofs/_controls_wiring.py,
proofs/_controls.py): each wrong input is rejected at its own condition, each right input
accepted, and the faults ``cfmpa selftest --code`` plants in the wiring make them fail."""

from __future__ import annotations

import inspect
import textwrap

import pytest

from cfmpa import spec
from cfmpa.proofs import _controls as C
from cfmpa.proofs import _controls_wiring as W


def _control(ident: str) -> C.Control:
    return next(c for c in C.collect_controls() if c.id == ident)


def _replaced(owner, name: str, old: str, new: str):
    """``owner.name`` with ``old`` made ``new`` in its source (the seeded fault)."""
    f = inspect.getattr_static(owner, name)
    f = getattr(f, "__func__", f)
    src = textwrap.dedent(inspect.getsource(f))
    assert src.count(old) == 1, old
    ns: dict = {}
    exec(src.replace(old, new), dict(f.__globals__), ns)   # noqa: S102
    return ns[name]


@pytest.mark.parametrize("control", W.wiring_controls(), ids=lambda c: c.id)
def test_each_wiring_control_is_rejected_at_its_own_condition(control):
    r = C.run_control(control)
    assert r.ok and r.outcome == "rejected", r.detail


@pytest.mark.parametrize("control", C.positive_controls(), ids=lambda c: c.id)
def test_each_right_input_is_accepted(control):
    r = C.run_control(control)
    assert r.ok and r.outcome == "accepted", r.detail


def test_the_harness_control_holds():
    (h,) = C.harness_controls()
    assert C.run_control(h).ok


def test_the_previous_segment_s_speed_certifies_the_moving_contact(monkeypatch):
    monkeypatch.setattr(spec.GridMotion, "lipschitz", _replaced(
        spec.GridMotion, "lipschitz", "steps[np.maximum(seg, 0)]", "steps[np.maximum(seg - 1, 0)]"))
    r = C.run_control(_control("Control.certificate.moving_contact"))
    assert r.outcome == "accepted" and not r.ok, r.detail


def test_the_moving_contact_is_between_grid_instants_after_a_wait():
    k, cell, target, d0, d1, touch = W._moving_near_contact()
    assert k >= 1 and d0 > W.MARGIN_M and d1 > W.MARGIN_M
    c = C._case()
    assert k * c.grid.dt < touch < (k + 1) * c.grid.dt
    assert max(abs(a - b) for a, b in zip(cell, target)) >= 2       # a jump: a fast segment


def test_a_gap_slice_without_its_last_piece_covers_the_gap(monkeypatch):
    monkeypatch.setattr(spec.ReferenceSpeeds, "over", _replaced(
        spec.ReferenceSpeeds, "over", "self.per_piece[lo[g]:hi[g] + 1]",
        "self.per_piece[lo[g]:hi[g]]"))
    r = C.run_control(_control("Control.monitor.gap_last_piece"))
    assert r.outcome == "accepted" and not r.ok, r.detail
    assert C.run_control(_control("Control.accept.monitor.gap")).ok   # inside one piece: same


def test_a_start_test_with_and_accepts_a_raised_start_label(monkeypatch):
    import cfmpa.spec._witness as SW  # the checker reads its module's function

    monkeypatch.setattr(SW, "start_label_breaks", lambda j1, j2: (j1 != 0) & (j2 != 0))
    r = C.run_control(_control("Control.witness.raised_start"))
    assert r.outcome == "accepted" and not r.ok, r.detail


@pytest.mark.parametrize("name,target", [
    ("Control.accept.witness", "check_witness"),
    ("Control.accept.dr", "dr_cell_failures"),
    ("Control.accept.path", "path_violations"),
])
def test_a_checker_that_rejects_everything_fails_its_positive_control(monkeypatch, name, target):
    failure = type("F", (), {"condition": "planted", "message": "rejects everything"})()
    fake = ((lambda *a, **k: (0, [failure])) if target == "dr_cell_failures"
            else (lambda *a, **k: [failure]))
    monkeypatch.setattr(C, target, fake)
    r = C.run_control(_control(name))
    assert r.outcome == "rejected" and not r.ok


def test_a_certificate_that_clears_nothing_fails_its_positive_control(monkeypatch):
    real = C.certify

    def strict(*a, **k):
        from dataclasses import replace
        return replace(real(*a, **k), clear=False, undecided=((0.0, 1.0),))
    monkeypatch.setattr(C, "certify", strict)
    assert not C.run_control(_control("Control.accept.certificate")).ok


def test_a_rejection_at_another_condition_is_an_error_not_a_pass(monkeypatch):
    # The forged witness rejected at witness.form (not where its fault is): not its fault.
    form = type("F", (), {"condition": "witness.form", "message": "wrong dtype"})()
    monkeypatch.setattr(C, "check_witness", lambda *a, **k: [form])
    r = C.run_control(_control("Control.witness.forged"))
    assert r.outcome == "error" and not r.ok and "not at witness.edge" in r.detail


def test_an_undecided_certificate_is_not_the_contact(monkeypatch):
    real = C.certify

    def undecided(*a, **k):
        from dataclasses import replace
        return replace(real(*a, **k), clear=False, contact=None, undecided=((0.0, 1.0),))
    monkeypatch.setattr(C, "certify", undecided)
    r = C.run_control(_control("Control.certificate.contact"))
    assert r.outcome == "error" and not r.ok


def test_a_harness_that_counts_an_error_as_rejected_fails_its_control(monkeypatch):
    real = C.run_control

    def lenient(c):
        r = real(c)
        if r.outcome == "error":
            from dataclasses import replace
            return replace(r, outcome="rejected")
        return r
    monkeypatch.setattr(C, "run_control", lenient)
    (h,) = C.harness_controls()
    assert h.run()[0] == "accepted"


def test_a_loader_bound_above_the_proofs_admits_the_step_and_fails_its_control(monkeypatch):
    from fractions import Fraction

    import cfmpa.spec._scenario as SS

    monkeypatch.setattr(SS, "_G_MAX", SS.MAX_SPACING + Fraction(1, 100))
    r = C.run_control(_control("Control.loader.spacing_above_bound"))
    assert r.outcome == "accepted" and not r.ok, r.detail
    assert C.run_control(_control("Control.accept.loader.spacing_at_bound")).ok


def test_a_refusal_of_another_field_is_not_the_loader_s_spacing_refusal(monkeypatch):
    def refuse_all(doc, **k):
        raise C_InputError("dt", doc["dt"], "planted")
    from cfmpa.errors import InputError as C_InputError
    monkeypatch.setattr(W, "parse_scenario", refuse_all)
    r = C.run_control(_control("Control.loader.spacing_above_bound"))
    assert r.outcome == "error" and not r.ok
