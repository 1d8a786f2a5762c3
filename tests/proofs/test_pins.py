"""Pinned statements: proofs/obligations.lock, a changed statement failing the run, --repin."""

from __future__ import annotations

import dataclasses
import io
import json
import shutil
from pathlib import Path

import z3

from cfmpa.proofs import (
    VC,
    Method,
    Obligation,
    Verdict,
    Z3Query,
    collect_obligations,
    expected_ids,
    render_report,
    run_obligations,
)
from cfmpa.proofs._pins import LOCK, check_pins, cvc5_skips, load_lock, pin_key

REPO = Path(__file__).resolve().parents[2]


def _ob(threshold: int, ident: str = "T.pin") -> Obligation:
    x = z3.Int("x")
    return Obligation(ident, "test", "none", "x > t implies x > 0", Method.Z3, Verdict.PROVED,
                      lambda: Z3Query((VC("v", (("x > t", x > threshold),), x > 0,
                                          key_premise="x > t"),)))


def test_the_lock_pins_every_expected_obligation_and_is_shipped():
    lock = load_lock()
    assert set(lock) == {pin_key(i) for i in expected_ids()}
    assert {k for k in lock if k.startswith("Scenario.")} == {
        f"Scenario.*.{c}" for c in ("time_grid", "cspace_grid", "margin_side", "containment",
                                    "translation_original", "translation_modified",
                                    "translation_tight")}
    text = LOCK.read_text()
    assert text == json.dumps(json.loads(text), indent=1, sort_keys=True,
                              ensure_ascii=False) + "\n"         # sorted, as repin writes it
    assert '"cfmpa.proofs" = ["obligations.lock"]' in (REPO / "pyproject.toml").read_text()
    # Every Z3 obligation is pinned VC by VC, with its expected verdict.
    assert lock["Prop2.endpoints"]["vcs"].keys() == {"endpoints"}
    assert lock["Prop5.printed"]["expected"] == "refuted as expected"


def test_a_changed_constant_fails_the_run_until_it_is_repinned(tmp_path: Path):
    lock = tmp_path / "obligations.lock"
    first = run_obligations([_ob(1)], tmp_path / "a", ["T.pin"], lock=lock, repin=True)
    assert first.repinned == ("added   T.pin",) and first.ok
    assert run_obligations([_ob(1)], tmp_path / "a", ["T.pin"], lock=lock).ok
    # Another constant: still a valid VC, but not the pinned statement.
    changed = run_obligations([_ob(2)], tmp_path / "a", ["T.pin"], lock=lock)
    assert changed.proofs[0].verdict is Verdict.PROVED and not changed.ok
    ((ident, what),) = changed.pin_mismatch
    assert ident == "T.pin" and what.startswith("statement changed, not re-pinned: VC v: ")
    assert "STATEMENT NOT PINNED: T.pin" in render_report(changed)
    old = load_lock(lock)["T.pin"]["vcs"]["v"]
    again = run_obligations([_ob(2)], tmp_path / "a", ["T.pin"], lock=lock, repin=True)
    new = load_lock(lock)["T.pin"]["vcs"]["v"]
    assert again.ok and again.repinned == (f"changed T.pin: VC v: {old[:12]} -> {new[:12]}",)
    assert "Re-pinned proofs/obligations.lock: 1 change(s)" in render_report(again)


def test_a_new_obligation_is_not_pinned_and_repin_removes_what_is_gone(tmp_path: Path):
    lock = tmp_path / "obligations.lock"
    run_obligations([_ob(1, "T.a"), _ob(1, "T.b")], tmp_path, ["T.a", "T.b"], lock=lock,
                    repin=True)
    run = run_obligations([_ob(1, "T.a"), _ob(1, "T.c")], tmp_path, ["T.a", "T.c"], lock=lock)
    assert run.pin_mismatch == (("T.c", "not pinned (a new obligation)"),)
    lines = run_obligations([_ob(1, "T.a"), _ob(1, "T.c")], tmp_path, ["T.a", "T.c"],
                            lock=lock, repin=True).repinned
    assert lines is not None and "added   T.c" in lines
    # Not a whole run (the paper's ids are not among the expected): T.b is kept.
    assert "T.b" in load_lock(lock)


def test_scenario_checks_are_pinned_by_their_source_not_their_data(tmp_path: Path):
    for name in ("a", "b"):
        shutil.copy(REPO / "scenarios" / "default.toml", tmp_path / f"{name}.toml")
    (tmp_path / "b.toml").write_text((tmp_path / "b.toml").read_text() + "\n# another file\n")
    obs = collect_obligations(tmp_path, ["Scenario.a.time_grid", "Scenario.b.time_grid"])
    run = run_obligations(obs, tmp_path / "out", [o.id for o in obs])
    a, b = run.proofs
    assert a.sha256 != b.sha256                 # different data: another query text
    assert a.pins == b.pins                     # the same check: the same pin
    assert not check_pins(run.proofs, load_lock())


def test_cvc5_takes_a_statement_it_did_not_decide_when_pinned_from_the_lock(tmp_path: Path):
    lock = tmp_path / "obligations.lock"
    run_obligations([_ob(1)], tmp_path, ["T.pin"], lock=lock, repin=True)
    doc = json.loads(lock.read_text())
    sha = doc["obligations"]["T.pin"]["vcs"]["v"]
    assert doc["obligations"]["T.pin"]["cvc5"]["v"] in ("unsat", "undecided: cvc5 is not installed")
    doc["obligations"]["T.pin"]["cvc5"]["v"] = "undecided: timeout at 5000 ms"
    lock.write_text(json.dumps(doc))
    assert cvc5_skips(load_lock(lock)) == {sha: "timeout at 5000 ms"}
    run = run_obligations([_ob(1)], tmp_path, ["T.pin"], lock=lock)
    v = run.proofs[0].vcs[0]
    # Not re-run: the pinned answer, said so; Z3 still proves it.
    assert run.ok and v.cvc5 == "unknown" and v.cvc5_from_pin and v.solvers == ("z3",)
    assert "taken from the lock" in v.note and "timeout at 5000 ms" in v.note
    # --recheck-undecided re-runs it: cvc5 decides this small VC now, and confirms it.
    run = run_obligations([_ob(1)], tmp_path, ["T.pin"], lock=lock, recheck_undecided=True)
    v = run.proofs[0].vcs[0]
    assert run.ok and not v.cvc5_from_pin and v.cvc5 in ("unsat", "unknown")
    if v.cvc5 == "unsat":
        assert v.solvers == ("z3", "cvc5")
    assert "re-run for 5000 ms" in v.note and "timeout at 5000 ms" in v.note


def test_the_words_of_a_statement_are_not_pinned(tmp_path: Path):
    obs = collect_obligations("/nonexistent", ["Prop2.endpoints"])
    edited = [dataclasses.replace(o, statement=o.statement + " (edited)") for o in obs]
    run = run_obligations(edited, tmp_path, [o.id for o in obs])
    assert not run.pin_mismatch and run.changes["Prop2.endpoints"] == "new"
    io.StringIO().write(render_report(run))


def test_the_lock_records_why_cvc5_did_not_decide_without_the_seconds_it_took():
    from cfmpa.proofs._pins import _reason_class
    a = _reason_class("killed after 6.0 s (cvc5 overran its 5000 ms limit)")
    b = _reason_class("killed after 8.3 s (cvc5 overran its 5000 ms limit)")
    assert a == b == "overran its 5000 ms limit (killed)"
    assert _reason_class("timeout at 5000 ms") == "timeout at 5000 ms"
    assert _reason_class("incomplete") == "incomplete" and _reason_class(None) == "not replayed"
