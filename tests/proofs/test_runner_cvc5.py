"""The prove run's cost rules (docs/model.md §6): cvc5 replays every statement it decided when
pinned and takes the answer of the undecided ones from the lock (said per VC and per
obligation) unless asked to re-run them; obligations and controls share one pool, the longest
first."""

from __future__ import annotations

import io
import json
import time
from concurrent.futures import Future
from pathlib import Path

import pytest
import z3

from cfmpa.proofs import (
    VC,
    Method,
    Obligation,
    Verdict,
    Z3Query,
    cvc5_tally,
    render_report,
    run_obligations,
)
from cfmpa.proofs._controls import Control
from cfmpa.proofs._cvc5 import CVC5_TIMEOUT_MS, Cvc5Answer
from cfmpa.proofs._obligation import discharge_pending


def _ob(ident: str = "T.cvc5") -> Obligation:
    x, y = z3.Int("x"), z3.Int("y")
    return Obligation(ident, "test", "none", "x > 1 implies x > 0, and y > 2 implies y > 0",
                      Method.Z3, Verdict.PROVED,
                      lambda: Z3Query((VC("a", (("x > 1", x > 1),), x > 0, key_premise="x > 1"),
                                       VC("b", (("y > 2", y > 2),), y > 0,
                                          key_premise="y > 2"))))


class _Pool:
    """A stand-in for Cvc5Pool: records each query and its limit, answers ``answer``."""

    def __init__(self, answer: str = "unsat") -> None:
        self.answer = answer
        self.asked: list[int | None] = []
        self.strategies: list[str] = []

    def submit(self, text: str, timeout_ms: int | None = None,
               strategy: str = "justification") -> Future:
        self.asked.append(timeout_ms)
        self.strategies.append(strategy)
        f: Future = Future()
        f.set_result(Cvc5Answer(self.answer, ""))
        return f


def _shas() -> dict[str, str]:
    pr = discharge_pending(_ob(), _Pool()).settle()
    return {v.name: v.sha256 for v in pr.vcs}


def test_an_undecided_pinned_statement_is_taken_from_the_lock_a_decided_one_is_rerun():
    sha = _shas()
    skip = {sha["b"]: "timeout at 5000 ms"}
    pool = _Pool()
    pr = discharge_pending(_ob(), pool, skip).settle()
    a, b = pr.vcs
    assert pr.verdict is Verdict.PROVED           # Z3 decides both VCs either way
    assert pool.asked == [None]                   # only a, at the pool's own (full) limit
    assert a.solvers == ("z3", "cvc5") and not a.cvc5_from_pin
    assert b.solvers == ("z3",) and b.cvc5_from_pin and b.cvc5 == "unknown"
    assert b.cvc5_reason == "timeout at 5000 ms" and "taken from the lock, not re-run" in b.note
    assert cvc5_tally(pr) == ("cvc5 decided 1 of 2 VCs, 1 undecided when pinned (taken from "
                              "the lock, not re-run)")
    # Seeded fault: a cvc5 that now refutes the decided statement is still caught (re-run).
    liar = discharge_pending(_ob(), _Pool("sat"), skip).settle()
    assert liar.verdict is Verdict.FAILED and "a (Z3 unsat, cvc5 sat)" in liar.reason


def test_recheck_undecided_replays_them_on_the_full_budget():
    sha = _shas()
    pool = _Pool()
    pr = discharge_pending(_ob(), pool, {sha["b"]: "incomplete"}, recheck=True).settle()
    assert pool.asked == [None, None]   # both at the pool's full limit
    assert all(v.solvers == ("z3", "cvc5") and not v.cvc5_from_pin for v in pr.vcs)
    assert f"re-run for {CVC5_TIMEOUT_MS} ms" in pr.vcs[1].note
    assert cvc5_tally(pr) == "cvc5 decided 2 of 2 VCs"


def _pinned(tmp_path: Path, monkeypatch) -> tuple[_Pool, Path, dict]:
    """A stand-in pool in place of Cvc5Pool, and a lock pinned by a --repin run of ``_ob()``
    through it: (the pool, the lock's path, the lock's JSON)."""
    import cfmpa.proofs._cvc5 as cvc5_mod

    pool = _Pool()
    monkeypatch.setattr(cvc5_mod, "Cvc5Pool", lambda: _Pool_cm(pool))
    lock = tmp_path / "obligations.lock"
    run_obligations([_ob()], tmp_path / "r", ["T.cvc5"], lock=lock, repin=True)
    return pool, lock, json.loads(lock.read_text())


def test_the_summary_and_results_say_what_was_taken_from_the_lock(tmp_path: Path, monkeypatch):
    pool, lock, doc = _pinned(tmp_path, monkeypatch)
    doc["obligations"]["T.cvc5"]["cvc5"]["b"] = "undecided: timeout at 5000 ms"
    lock.write_text(json.dumps(doc))
    pool.asked.clear()
    run = run_obligations([_ob()], tmp_path / "r", ["T.cvc5"], lock=lock)
    assert run.ok and pool.asked == [None]
    text = render_report(run)
    assert "cvc5 decided 1 of 2 VCs, 1 undecided when pinned (taken from the lock" in text
    assert "1 VCs cvc5 did not decide when pinned were not re-run" in text
    res = json.loads((tmp_path / "r" / "results.json").read_text())
    (entry,) = [o for o in res["obligations"] if o["id"] == "T.cvc5"]
    assert entry["cvc5_tally"] == cvc5_tally(run.proofs[0])
    assert [v["cvc5_from_pin"] for v in entry["vcs"]] == [False, True]
    assert res["second_solver"]["cvc5_from_pin"] == 1
    # --recheck-undecided: both replayed, nothing taken from the lock.
    pool.asked.clear()
    again = run_obligations([_ob()], tmp_path / "r", ["T.cvc5"], lock=lock,
                            recheck_undecided=True)
    assert again.ok and pool.asked == [None, None]   # both at the pool's full limit
    assert "taken from the lock" not in render_report(again)


class _Pool_cm:
    def __init__(self, pool: _Pool) -> None:
        self.pool = pool

    def __enter__(self) -> _Pool:
        return self.pool

    def __exit__(self, *exc: object) -> None:
        pass


def _logged(log: Path, ident: str, result):
    def run():
        with open(log, "a") as f:
            f.write(ident + "\n")
        time.sleep(0.3)
        return result()
    return run


def _started_order(tmp_path: Path) -> list[str]:
    """Three 0.3 s obligations and a 0.3 s control on two jobs, the control the longest last
    time: the order they started in."""
    from cfmpa.proofs import CheckOutcome, CheckQuery

    log = tmp_path / "started.txt"
    obs = [Obligation(f"D.{k}", "Data", "none", "holds", Method.DATA, Verdict.PROVED,
                      lambda k=k: CheckQuery(_logged(log, f"D.{k}",
                                                     lambda: CheckOutcome(True, "holds")),
                                             f"check {k}\n"))
           for k in range(3)]
    control = Control("Control.slow", "test", "a control", ("rejected",),
                      _logged(log, "Control.slow", lambda: ("rejected", "as planted")))
    out = tmp_path / "out"
    out.mkdir(parents=True)
    # The last run's seconds: the control was the longest.
    (out / "results.json").write_text(json.dumps(
        {"obligations": [{"id": f"D.{k}", "seconds": 1.0} for k in range(3)],
         "controls": [{"id": "Control.slow", "seconds": 50.0}]}))
    stream = io.StringIO()
    run = run_obligations(obs, out, [o.id for o in obs], workers=2, controls=[control],
                          progress=stream)
    assert [p.verdict for p in run.proofs] == [Verdict.PROVED] * 3
    assert [c.outcome for c in run.controls] == ["rejected"] and run.controls[0].ok
    assert "prove: negative controls: 1 done, " in stream.getvalue()
    return log.read_text().split()


def test_obligations_and_controls_share_one_pool_the_longest_first(tmp_path: Path, monkeypatch):
    import cfmpa.proofs._runner as runner

    # Submitted first (one of the first two to start), not after every obligation (4th).
    started = _started_order(tmp_path / "ordered")
    assert "Control.slow" in started[:2], started
    # Seeded fault: the controls' last seconds not read: the control starts after the others.
    monkeypatch.setattr(runner, "_previous_control_seconds", lambda path: {})
    started = _started_order(tmp_path / "unordered")
    assert "Control.slow" not in started[:2], started


def test_with_no_last_run_the_longest_time_limit_goes_first(tmp_path: Path):
    from cfmpa.proofs import CheckOutcome, CheckQuery

    log = tmp_path / "started.txt"
    obs = [Obligation(f"D.{k}", "Data", "none", "holds", Method.DATA, Verdict.PROVED,
                      lambda k=k: CheckQuery(_logged(log, f"D.{k}",
                                                     lambda: CheckOutcome(True, "holds")),
                                             f"check {k}\n"),
                      timeout_ms=600_000 if k == 3 else 20_000)
           for k in range(4)]
    run = run_obligations(obs, tmp_path / "fresh", [o.id for o in obs], workers=2)
    assert [p.verdict for p in run.proofs] == [Verdict.PROVED] * 4
    assert "D.3" in log.read_text().split()[:2]      # given last, started first


def test_a_statement_replays_under_the_strategy_the_lock_names(tmp_path: Path, monkeypatch):
    from cfmpa.errors import InputError

    pool, lock, doc = _pinned(tmp_path, monkeypatch)
    assert "cvc5_strategy" not in doc["obligations"]["T.cvc5"]     # the default is not written
    assert pool.strategies == ["justification"] * 2
    doc["obligations"]["T.cvc5"]["cvc5_strategy"] = {"b": "internal"}
    lock.write_text(json.dumps(doc))
    pool.strategies.clear()
    run = run_obligations([_ob()], tmp_path / "r", ["T.cvc5"], lock=lock)
    # Not part of the statement: no pin mismatch; b ran under the lock's choice, a the default.
    assert run.ok and pool.strategies == ["justification", "internal"]
    res = json.loads((tmp_path / "r" / "results.json").read_text())
    (entry,) = [o for o in res["obligations"] if o["id"] == "T.cvc5"]
    assert [v["cvc5_strategy"] for v in entry["vcs"]] == ["justification", "internal"]
    # --repin keeps what each statement ran under.
    run_obligations([_ob()], tmp_path / "r", ["T.cvc5"], lock=lock, repin=True)
    assert json.loads(lock.read_text())["obligations"]["T.cvc5"]["cvc5_strategy"] == {
        "b": "internal"}
    # Seeded faults in the lock: a strategy that does not exist, a VC the entry does not pin.
    for bad, what in (({"b": "fast"}, "T.cvc5.cvc5_strategy.b is not one of"),
                      ({"b": ["internal"]}, "T.cvc5.cvc5_strategy.b is not one of"),
                      ({"c": "internal"}, "names a VC the entry does not pin")):
        doc["obligations"]["T.cvc5"]["cvc5_strategy"] = bad
        lock.write_text(json.dumps(doc))
        with pytest.raises(InputError, match=what) as err:
            run_obligations([_ob()], tmp_path / "r", ["T.cvc5"], lock=lock)
        assert str(lock) in str(err.value)


def test_a_changed_statement_runs_under_the_default_strategy():
    sha = _shas()
    pool = _Pool()
    discharge_pending(_ob(), pool, {}, strategies={sha["a"]: "internal-relevance",
                                                   "0" * 64: "internal"}).settle()
    assert pool.strategies == ["internal-relevance", "justification"]
