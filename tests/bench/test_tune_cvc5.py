"""bench/tune_cvc5.py's choice of a cvc5 strategy per statement (docs/model.md §6.4), and the
lock's record of it."""

from __future__ import annotations

import importlib.util
import json
from pathlib import Path
from typing import Any

import pytest

from cfmpa.proofs._pins import cvc5_strategies, load_lock, record_cvc5_strategies

ROOT = Path(__file__).resolve().parents[2]


def _tune() -> Any:
    spec = importlib.util.spec_from_file_location("cfmpa_bench_tune", ROOT / "bench" /
                                                  "tune_cvc5.py")
    assert spec is not None and spec.loader is not None
    mod = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(mod)
    return mod


T = _tune()


def test_a_decided_statement_switches_only_for_a_clear_saving():
    # 2.3 s -> 0.1 s under internal: switched.
    assert T.choose(("unsat", 2.3), {"internal": ("unsat", 0.1)}, "unsat") == "internal"
    # The quickest of those that decide.
    assert T.choose(("unsat", 2.0), {"internal": ("unsat", 1.0),
                                     "internal-relevance": ("unsat", 0.5)},
                    "unsat") == "internal-relevance"
    # Within the ratio or the margin: noise, the default stays.
    assert T.choose(("unsat", 1.0), {"internal": ("unsat", 0.8)}, "unsat") == "justification"
    assert T.choose(("unsat", 0.1), {"internal": ("unsat", 0.06)}, "unsat") == "justification"


def test_a_strategy_that_does_not_give_z3s_answer_is_never_chosen():
    # Seeded faults: quicker, but undecided, or the other answer.
    assert T.choose(("unsat", 2.0), {"internal": ("unknown", 0.1)}, "unsat") == "justification"
    assert T.choose(("unsat", 2.0), {"internal": ("sat", 0.1)}, "unsat") == "justification"
    assert T.choose(("unknown", 0.0), {"internal": ("sat", 0.1)}, "unsat") == "justification"


def test_an_undecided_statement_is_replayed_from_then_on_only_if_cheaply_decided():
    assert T.choose(("unknown", 0.0), {"internal": ("unsat", 0.4)}, "unsat") == "internal"
    assert T.choose(("unknown", 0.0), {"internal": ("unsat", 3.0)}, "unsat") == "justification"


def test_a_disagreement_is_not_tuned_away():
    with pytest.raises(ValueError, match="a disagreement"):
        T.choose(("sat", 0.5), {"internal": ("unsat", 0.1)}, "unsat")


def _lock(tmp_path: Path) -> Path:
    lock = tmp_path / "obligations.lock"
    lock.write_text(json.dumps({"format": "cfmpa obligations lock 1", "note": "",
                                "obligations": {"A.b": {
                                    "cvc5": {"x": "unsat", "y": "undecided: incomplete"},
                                    "expected": "proved", "kind": "theorem", "kind_why": "",
                                    "vcs": {"x": "1" * 64, "y": "2" * 64}}}}))
    return lock


def test_the_lock_records_the_choice_and_the_answer_under_it(tmp_path: Path):
    lock = _lock(tmp_path)
    lines = record_cvc5_strategies({("A.b", "x"): ("internal", "unsat"),
                                    ("A.b", "y"): ("internal-relevance", "unsat")}, lock)
    entry = load_lock(lock)["A.b"]
    assert entry["cvc5_strategy"] == {"x": "internal", "y": "internal-relevance"}
    assert entry["cvc5"] == {"x": "unsat", "y": "unsat"}
    assert cvc5_strategies(load_lock(lock)) == {"1" * 64: "internal", "2" * 64: "internal-relevance"}
    assert lines == ["A.b x: justification (unsat) -> internal (unsat)",
                     "A.b y: justification (undecided: incomplete) -> internal-relevance (unsat)"]
    # Back to the default: no entry written for it.
    record_cvc5_strategies({("A.b", "x"): ("justification", "unsat"),
                            ("A.b", "y"): ("justification", "undecided: incomplete")}, lock)
    assert "cvc5_strategy" not in load_lock(lock)["A.b"]
    with pytest.raises(KeyError, match="pins no VC 'z'"):
        record_cvc5_strategies({("A.b", "z"): ("internal", "unsat")}, lock)
    # A strategy that does not exist is never written (a run would then refuse the lock).
    before = lock.read_text()
    with pytest.raises(ValueError, match="strategy='fast' is not one of"):
        record_cvc5_strategies({("A.b", "x"): ("fast", "unsat")}, lock)
    assert lock.read_text() == before


def test_a_switch_is_measured_again_and_the_slower_runs_kept(monkeypatch):
    # The first measurements favour internal (0.5 s against 1.0 s); measured again, internal
    # takes 0.9 s: with the slower run of each side kept, the default stays (0.9 > 0.7 x 1.0).
    times = {"justification": [1.0, 1.0], "internal": [0.5, 0.9],
             "internal-relevance": [2.0, 2.0]}

    def measure(workers, strategy, text):
        return "unsat", times[strategy].pop(0)
    monkeypatch.setattr(T, "_measure", measure)
    row = {"key": "A.b", "vc": "x", "sha256": "1" * 64, "text": "(check-sat)", "want": "unsat"}
    import io
    (got,) = T.tune([row], floor=0.15, log=io.StringIO())
    assert got["default"] == ["unsat", 1.0] and got["others"]["internal"] == ["unsat", 0.9]
    assert got["chosen"] == "justification" and got["answer"] == "unsat"
    # A statement undecided when pinned is not run under the default again.
    times.update({"internal": [0.3], "internal-relevance": [0.4]})
    (got,) = T.tune([dict(row, undecided=True)], floor=0.15, log=io.StringIO())
    assert got["default"] == ["unknown", 0.0] and got["chosen"] == "internal"
