"""Cvc5Pool runs a text it was given before only once: the second submission gets the first's
answer with no time of its own; a different text, or the same text under another limit or
another strategy, is run (docs/model.md §6.4: the same text gets the same answer)."""

from __future__ import annotations

import threading
import uuid
from collections.abc import Callable

import pytest

from cfmpa.proofs._cvc5 import (
    OPTIONS,
    STRATEGIES,
    Cvc5Answer,
    Cvc5Pool,
    Cvc5Worker,
    _taken,
    cvc5_version,
    strategy_flags,
)

needs_cvc5 = pytest.mark.skipif(cvc5_version() is None, reason="cvc5 is not installed")

_PROVED = "(set-logic QF_LIA)\n(declare-fun |x| () Int)\n(assert (> |x| 1))\n" \
          "(assert (not (> |x| 0)))\n(check-sat)\n(exit)\n"
_REFUTED = "(set-logic QF_LIA)\n(declare-fun |x| () Int)\n(assert (> |x| 1))\n" \
           "(assert (not (> |x| 5)))\n(check-sat)\n(exit)\n"


class _Worker:
    """A stand-in for Cvc5Worker: answers by the text ("sat" if it says 5, else "unsat"),
    takes 1.5 s of pretend time, records each run; ``gate`` holds every run until set."""

    def __init__(self) -> None:
        self.ran: list[tuple[str, int, str]] = []
        self.gate = threading.Event()
        self.gate.set()

    def check(self, text: str, timeout_ms: int, strategy: str = "justification") -> Cvc5Answer:
        self.gate.wait(10)
        self.ran.append((text, timeout_ms, strategy))
        return Cvc5Answer("sat" if "5" in text else "unsat", f"limit {timeout_ms}", 1.5,
                          strategy)

    def close(self) -> None:
        pass


def _problems(make: Callable[[], Cvc5Pool]) -> list[str]:
    """What is wrong with the pools ``make`` builds (each given a stand-in worker)."""
    out: list[str] = []
    pool = make()
    w = _Worker()
    pool._worker = w  # type: ignore[assignment]
    w.gate.clear()                                   # the first still running when asked again
    with pool:
        first = pool.submit(_PROVED)
        again = pool.submit(_PROVED)
        w.gate.set()
        other = pool.submit(_REFUTED)
        longer = pool.submit(_PROVED, timeout_ms=9_000)
        late = pool.submit(_PROVED)                  # asked after the first answered
        steered = pool.submit(_PROVED, strategy="internal")
        a, b, c, d, e, g = (f.result(10) for f in (first, again, other, longer, late, steered))
    if (a.answer, a.reason) != (b.answer, b.reason) or (a.answer, a.reason) != (e.answer, e.reason):
        out.append(f"a repeat got another answer: {a}, {b}, {e}")
    if a.seconds != 1.5 or b.seconds != 0.0 or e.seconds != 0.0:
        out.append(f"the time is not counted once: {a.seconds}, {b.seconds}, {e.seconds}")
    if c.answer != "sat":
        out.append(f"another text got a shared answer: {c}")
    if d.reason != "limit 9000":
        out.append(f"another limit got a shared answer: {d}")
    if g.strategy != "internal":
        out.append(f"another strategy got a shared answer: {g}")
    ran = sorted(w.ran)
    j, ms = "justification", pool.timeout_ms
    if ran != sorted([(_PROVED, ms, j), (_REFUTED, ms, j), (_PROVED, 9_000, j),
                      (_PROVED, ms, "internal")]):
        out.append(f"the worker ran {ran}")
    return out


def test_a_repeated_text_is_run_once_and_shares_the_answer():
    assert _problems(Cvc5Pool) == []


class _ByPrefix(Cvc5Pool):
    # Seeded fault: a key too coarse (the two texts share their first 60 characters).
    @staticmethod
    def _key(text: str, timeout_ms: int) -> tuple[str, int]:
        return text[:60], timeout_ms


class _NoLimit(Cvc5Pool):
    # Seeded fault: the limit left out of the key.
    @staticmethod
    def _key(text: str, timeout_ms: int) -> tuple[str, int]:
        return Cvc5Pool._key(text, 0)


class _NoStrategy(Cvc5Pool):
    # Seeded fault: the strategy left out of the key (and of the run).
    def submit(self, text: str, timeout_ms: int | None = None,  # type: ignore[no-untyped-def]
               strategy: str = "justification"):
        return super().submit(text, timeout_ms)


class _SameFuture(Cvc5Pool):
    # Seeded fault: the repeat handed the first's own Future, its time then counted twice.
    def submit(self, text: str, timeout_ms: int | None = None,  # type: ignore[no-untyped-def]
               strategy: str = "justification"):
        ms = self.timeout_ms if timeout_ms is None else timeout_ms
        key = (*self._key(text, ms), strategy)
        if key not in self._asked:
            self._asked[key] = self._ex.submit(self._worker.check, text, ms, strategy)
        return self._asked[key]


class _NoCache(Cvc5Pool):
    # Seeded fault: every submission run.
    @staticmethod
    def _key(text: str, timeout_ms: int) -> tuple[str, int]:
        return uuid.uuid4().hex, timeout_ms


@pytest.mark.parametrize("faulty, caught", [
    (_ByPrefix, "another text got a shared answer"),
    (_NoLimit, "another limit got a shared answer"),
    (_NoStrategy, "another strategy got a shared answer"),
    (_SameFuture, "the time is not counted once"),
    (_NoCache, "the worker ran"),
])
def test_the_check_catches_a_wrong_cache(faulty: Callable[[], Cvc5Pool], caught: str):
    assert any(p.startswith(caught) for p in _problems(faulty))


def test_a_failed_first_run_fails_the_repeat_too():
    pool = Cvc5Pool()
    w = _Worker()
    pool._worker = w  # type: ignore[assignment]

    def boom(text: str, timeout_ms: int, strategy: str = "") -> Cvc5Answer:
        raise RuntimeError("the thread broke")

    w.check = boom  # type: ignore[method-assign]
    with pool:
        first, again = pool.submit(_PROVED), pool.submit(_PROVED)
        for f in (first, again):
            with pytest.raises(RuntimeError, match="the thread broke"):
                f.result(10)


@needs_cvc5
def test_cvc5_itself_runs_a_repeat_once():
    with Cvc5Pool() as pool:
        calls: list[str] = []
        real = pool._worker.check

        def counted(text: str, timeout_ms: int, strategy: str) -> Cvc5Answer:
            calls.append(text)
            return real(text, timeout_ms, strategy)

        pool._worker.check = counted  # type: ignore[method-assign]
        a, b, c = (f.result(30) for f in [pool.submit(_PROVED), pool.submit(_REFUTED),
                                          pool.submit(_PROVED)])
    assert (a.answer, b.answer, c.answer) == ("unsat", "sat", "unsat")
    assert a.seconds > 0.0 and c.seconds == 0.0 and calls == [_PROVED, _REFUTED]


def test_an_unknown_strategy_is_refused_when_queued():
    with Cvc5Pool() as pool, pytest.raises(ValueError, match="strategy='fast' is not one of"):
        pool.submit(_PROVED, strategy="fast")


@needs_cvc5
@pytest.mark.parametrize("strategy", sorted(STRATEGIES))
def test_cvc5_runs_under_the_options_of_the_strategy_asked(strategy: str):
    with Cvc5Worker() as w:
        a = w.check(_PROVED, 5_000, strategy)
    assert (a.answer, a.strategy) == ("unsat", strategy)
    assert strategy_flags(strategy).startswith("--decision=")


@needs_cvc5
def test_an_answer_under_other_options_than_asked_is_not_taken():
    # Seeded fault: a query that changes cvc5's options itself (a worker that ignored the
    # strategy would be seen the same way): the options read back differ, so no answer.
    with Cvc5Worker() as w:
        a = w.check("(set-option :decision internal)\n" + _PROVED, 5_000, "justification")
    assert a.answer == "unknown" and "not the options asked" in a.reason


def test_a_reply_without_the_options_read_back_is_not_taken():
    # Seeded fault: a worker that does not say what it ran under.
    assert _taken({"answer": "unsat"}, STRATEGIES["internal"]).answer == "unknown"
    assert _taken({"answer": "unsat", "ran": {"decision": "internal"}},
                  STRATEGIES["internal"]).answer == "unsat"
    # An undecided answer says why, whatever it ran under.
    assert _taken({"answer": "unknown", "reason": "timeout"}, OPTIONS).reason == "timeout"
