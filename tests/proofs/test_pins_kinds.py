"""Kinds pinned (proofs/_pins.py): obligations.lock records each obligation's kind and the
reason; --repin writes a new obligation's kind and never changes a pinned one, so a theorem moved
into the definitional list (or back) fails every run, --repin or not."""

from __future__ import annotations

from pathlib import Path

import z3

from cfmpa.proofs import (
    DEFINITIONAL,
    VC,
    Method,
    Obligation,
    Verdict,
    Z3Query,
    _runner,
    expected_ids,
    kind_of,
    render_report,
    run_obligations,
)
from cfmpa.proofs._pins import check_kinds, load_lock, pin_key


def _ob(ident: str) -> Obligation:
    x = z3.Int("x")
    return Obligation(ident, "test", "none", "x > 1 implies x > 0", Method.Z3, Verdict.PROVED,
                      lambda: Z3Query((VC("v", (("x > 1", x > 1),), x > 0,
                                          key_premise="x > 1"),)))


def test_the_shipped_lock_pins_every_kind_as_the_code_says():
    lock = load_lock()
    pinned = [i for i in expected_ids() if pin_key(i) in lock]   # (a missing pin: test_pins)
    assert len(pinned) > 50
    for ident in pinned:
        entry = lock[pin_key(ident)]
        assert entry["kind"] == kind_of(ident), ident
        assert entry["kind_why"] == DEFINITIONAL.get(ident, ""), ident


def test_repin_pins_a_new_kind_and_never_changes_one(tmp_path: Path, monkeypatch):
    lock = tmp_path / "obligations.lock"
    first = run_obligations([_ob("T.kind")], tmp_path / "a", ["T.kind"], lock=lock, repin=True)
    assert first.ok and load_lock(lock)["T.kind"]["kind"] == "theorem"
    # Seeded fault: the theorem moved into the definitional list.
    monkeypatch.setitem(_runner.DEFINITIONAL, "T.kind", "a definition restated")
    for repin in (False, True):
        run = run_obligations([_ob("T.kind")], tmp_path / "a", ["T.kind"], lock=lock,
                              repin=repin)
        assert not run.ok and run.proofs[0].verdict is Verdict.PROVED
        ((ident, what),) = run.kind_mismatch
        assert ident == "T.kind" and "kind definitional in the code, theorem pinned" in what
        assert "KIND NOT AS PINNED: T.kind" in render_report(run)
        assert load_lock(lock)["T.kind"]["kind"] == "theorem"        # --repin kept it


def test_a_lock_without_kinds_is_not_as_pinned_until_repinned(tmp_path: Path):
    lock = tmp_path / "obligations.lock"
    run_obligations([_ob("T.old")], tmp_path / "a", ["T.old"], lock=lock, repin=True)
    entries = load_lock(lock)
    del entries["T.old"]["kind"]
    mismatch = check_kinds(run_obligations([_ob("T.old")], tmp_path / "b", ["T.old"],
                                           lock=lock).proofs, entries,
                           lambda i: (kind_of(i), ""))
    assert mismatch and "not pinned" in mismatch[0][1]


def test_the_kind_is_not_part_of_the_statement(tmp_path: Path):
    # A kind mismatch is its own failure, not a changed statement a --repin would accept.
    lock = tmp_path / "obligations.lock"
    run_obligations([_ob("T.s")], tmp_path / "a", ["T.s"], lock=lock, repin=True)
    run = run_obligations([_ob("T.s")], tmp_path / "a", ["T.s"], lock=lock)
    assert run.ok and run.pin_mismatch == () and run.kind_mismatch == ()
