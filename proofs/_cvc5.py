"""The second solver: replay a VC's standard SMT-LIB 2.6 proof check in cvc5.

cvc5 runs in a worker process (this module run as a script), fed one query at a time over a
pipe. Its limit is CPU time, the worker's own (read from /proc while waiting): on a loaded
machine a query gets the same CPU before it is stopped as on a quiet one, so whether cvc5
decides a statement does not depend on the load (a 2.2 s query ran out of a 5 s wall-clock limit
at a load of 4.6). The worker is killed when it has spent the limit on a query, and restarted for
the next; cvc5's own time limit (``tlimit-per``, wall clock, and not always honoured by the
nonlinear procedures) is set to ``_limits.WALL_NET_FACTOR`` times the limit, a net, as the
parent's wait is. Where /proc cannot be read, the limit is the wall clock, as cvc5's own. The
answer is cvc5's: ``unsat``, ``sat`` or ``unknown`` with its explanation (``timeout``,
``incomplete``, ...), or ``unknown`` with the reason it could not run (``killed after ...``,
cvc5 not installed, a parse error). Only ``unsat`` confirms a proof (``sat`` a refutation); an
answer contradicting Z3's is a disagreement, which the caller makes a FAILED verdict.
``Cvc5Pool`` runs the queries in the background (one worker, fed by a thread), so cvc5 works
on the other core while the prove run goes on with Z3, and runs a text it was given before only
once (two obligations can state the same VC).

A query runs under a strategy (``STRATEGIES``: cvc5's search options, never its logic or its
limits), the default one unless proofs/obligations.lock names another for the statement
(``_pins.cvc5_strategies``, chosen by measurement: bench/tune_cvc5.py, docs/model.md §6.4). The
worker reads the options back from cvc5 and says which it ran under; an answer under other
options than asked is not taken.
"""

from __future__ import annotations

import dataclasses
import hashlib
import json
import os
import select
import subprocess
import sys
import threading
import time
from concurrent.futures import Future, ThreadPoolExecutor
from dataclasses import dataclass

__all__ = ["CVC5_TIMEOUT_MS", "DEFAULT_STRATEGY", "STRATEGIES", "Cvc5Answer", "Cvc5Pool",
           "Cvc5Worker", "cvc5_version", "strategy_flags"]

#: cvc5's time limit per query. A run replays only the statements cvc5 decided when they were
#: pinned (``_pins.cvc5_skips``: the others' answer is the pinned one), so a query that runs
#: into it is rare; ``--repin`` and ``--recheck-undecided`` replay every one on this budget.
CVC5_TIMEOUT_MS = 5_000
#: cvc5's options beyond its defaults, set on every query. Justification-based decisions:
#: measured over the 290 queries cvc5 decided with its defaults (CPU, each in a process of its
#: own), every one still decided, the same answers, 30.0 -> 27.3 s in all, and the slowest
#: query 4.3 -> 2.4 s (``Exact.gap_formula``'s gap, which ran close to the 5 s limit, 0.6 s).
#: The lock's answers of the queries cvc5 does not decide were pinned under these options.
OPTIONS: tuple[tuple[str, str], ...] = (("decision", "justification"),)
#: The strategies a statement can be replayed under, by name: each a set of cvc5 options that
#: steer its search (the SAT solver's decisions; the nonlinear solver's relevance filter) and
#: change neither what is asserted, nor the logic, nor the time limit; so an answer under any of
#: them is cvc5's answer on the same query. Measured over the 291 queries cvc5 decides (CPU, a
#: process each): no one strategy is the quickest on all (Safety.tool_region's far_vertex: 2.3 s
#: under justification, 0.1 s under internal; Monitor.reference_speeds' gap_path1: 1.7 s, and a
#: timeout under internal), so the lock names, per statement, the one measured quickest
#: (bench/tune_cvc5.py).
STRATEGIES: dict[str, tuple[tuple[str, str], ...]] = {
    "justification": OPTIONS,
    "internal": (("decision", "internal"),),
    "internal-relevance": (("decision", "internal"), ("nl-rlv", "always")),
}
#: A statement the lock names no strategy for runs under this one.
DEFAULT_STRATEGY = "justification"
#: How long past its own limit a query may run before the worker is killed (wall-clock mode).
_GRACE_S = 1.0
#: How often the parent reads the worker's CPU time while it waits for an answer.
_POLL_S = 0.05
#: The worker's start-up (importing cvc5), allowed on top on a query that starts it.
_START_S = 2.0


@dataclass(frozen=True)
class Cvc5Answer:
    answer: str          # unsat | sat | unknown
    reason: str = ""     # cvc5's explanation of unknown, or why it did not run
    seconds: float = 0.0  # the worker's time on it; 0.0 for an answer shared with an earlier query
    strategy: str = DEFAULT_STRATEGY   # the options it ran under (STRATEGIES)
    cpu_seconds: float = 0.0   # the worker's CPU on it (read and solve; what a strategy saves)


def strategy_flags(strategy: str) -> str:
    """cvc5's command-line flags of ``strategy`` (a replay of a saved query: docs/model.md
    §6.4), e.g. ``--decision=internal --nl-rlv=always``; ValueError for an unknown name."""
    return " ".join(f"--{k}={v}" for k, v in _options(strategy))


def _options(strategy: str) -> tuple[tuple[str, str], ...]:
    try:
        return STRATEGIES[strategy]
    except KeyError:
        raise ValueError(f"strategy={strategy!r} is not one of {sorted(STRATEGIES)}") from None


def cvc5_version() -> str | None:
    try:
        import cvc5
    except ImportError:
        return None
    return str(getattr(cvc5, "__version__", "unknown version"))


class Cvc5Worker:
    """A cvc5 process answering queries one at a time; restarted after a kill."""

    def __init__(self) -> None:
        self.proc: subprocess.Popen[str] | None = None

    def __enter__(self) -> Cvc5Worker:
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()

    def _start(self) -> tuple[subprocess.Popen[str], bool]:
        if self.proc is None or self.proc.poll() is not None:
            self.proc = subprocess.Popen(
                [sys.executable, "-u", os.path.abspath(__file__)], stdin=subprocess.PIPE,
                stdout=subprocess.PIPE, stderr=subprocess.DEVNULL, text=True, bufsize=1)
            return self.proc, True
        return self.proc, False

    def close(self) -> None:
        if self.proc is not None:
            if self.proc.poll() is None:
                self.proc.kill()
            self.proc.wait()
            for f in (self.proc.stdin, self.proc.stdout):
                if f is not None:
                    f.close()
            self.proc = None

    def check(self, text: str, timeout_ms: int = CVC5_TIMEOUT_MS,
              strategy: str = DEFAULT_STRATEGY) -> Cvc5Answer:
        """cvc5's answer on ``text`` under ``strategy`` (ValueError for an unknown one)."""
        options = _options(strategy)
        t0 = time.monotonic()
        a = self._check(text, timeout_ms, options)
        return Cvc5Answer(a.answer, a.reason, time.monotonic() - t0, strategy, a.cpu_seconds)

    def _check(self, text: str, timeout_ms: int,
               options: tuple[tuple[str, str], ...]) -> Cvc5Answer:
        if cvc5_version() is None:
            return Cvc5Answer("unknown", "cvc5 is not installed")
        proc, started = self._start()
        assert proc.stdin is not None and proc.stdout is not None
        cpu0 = _cpu_seconds(proc.pid)
        # With the CPU limit ours, cvc5's own (wall clock) is only the net.
        wall_ms = timeout_ms if cpu0 is None else timeout_ms * _net_factor()
        try:
            proc.stdin.write(json.dumps({"text": text, "ms": timeout_ms, "wall_ms": wall_ms,
                                         "options": [list(o) for o in options]}) + "\n")
            proc.stdin.flush()
        except (BrokenPipeError, OSError):
            self.close()
            return Cvc5Answer("unknown", "the cvc5 worker died")
        why = _wait(proc, timeout_ms, started, cpu0)
        if why:
            self.close()
            return Cvc5Answer("unknown", why)
        line = proc.stdout.readline()
        if not line:
            self.close()
            return Cvc5Answer("unknown", "the cvc5 worker died")
        doc = json.loads(line)
        return _taken(doc, options)


def _net_factor() -> int:
    from ._limits import WALL_NET_FACTOR

    return WALL_NET_FACTOR


def _cpu_seconds(pid: int) -> float | None:
    """The CPU time (user + system) process ``pid`` has spent, from /proc; None where it cannot
    be read (not Linux, or the process gone)."""
    try:
        with open(f"/proc/{pid}/stat", "rb") as f:
            stat = f.read(4096)
        # The fields after the command's closing parenthesis (the command may hold spaces).
        fields = stat[stat.rindex(b")") + 2:].split()
        return (int(fields[11]) + int(fields[12])) / os.sysconf("SC_CLK_TCK")
    except (OSError, ValueError, IndexError):
        return None


def _wait(proc: subprocess.Popen[str], timeout_ms: int, started: bool,
          cpu0: float | None) -> str:
    """Wait for the worker's answer to the query just sent: "" once it can be read, else why it
    was stopped. ``cpu0``: the worker's CPU time before the query (None: the wall clock is the
    limit, with ``_GRACE_S`` for cvc5's own to act first). A worker just started may spend
    ``_START_S`` more (importing cvc5)."""
    assert proc.stdout is not None
    extra = _START_S if started else 0.0
    t0 = time.monotonic()
    if cpu0 is None:
        ready, _, _ = select.select([proc.stdout], [], [], timeout_ms / 1000 + _GRACE_S + extra)
        return "" if ready else (f"killed after {time.monotonic() - t0:.1f} s "
                                 f"(cvc5 overran its {timeout_ms} ms limit)")
    net = timeout_ms / 1000 * _net_factor() + _GRACE_S + extra
    while True:
        ready, _, _ = select.select([proc.stdout], [], [], _POLL_S)
        if ready:
            return ""
        cpu = _cpu_seconds(proc.pid)
        if cpu is not None and cpu - cpu0 > timeout_ms / 1000 + extra:
            return (f"killed after {cpu - cpu0:.1f} s of CPU "
                    f"(cvc5 overran its {timeout_ms} ms limit)")
        if time.monotonic() - t0 > net:
            return (f"killed after {time.monotonic() - t0:.1f} s "
                    f"(cvc5 overran its {timeout_ms} ms limit's wall-clock net)")


def _taken(doc: dict[str, object], options: tuple[tuple[str, str], ...]) -> Cvc5Answer:
    """The worker's reply as an answer, if it ran under ``options`` (the values it read back
    from cvc5, ``ran``); otherwise unknown, saying what it ran under instead."""
    ran = doc.get("ran")
    want = {k: v for k, v in options}
    if doc.get("answer") in ("sat", "unsat") and ran != want:
        return Cvc5Answer("unknown", f"cvc5 ran under {ran!r}, not the options asked, {want!r}")
    cpu = doc.get("cpu_s")
    return Cvc5Answer(str(doc["answer"]), str(doc.get("reason", "")),
                      cpu_seconds=float(cpu) if isinstance(cpu, (int, float)) else 0.0)


class Cvc5Pool:
    """cvc5 in the background: ``submit`` queues a query for one worker (a thread waiting on
    the worker process), so cvc5 runs on while the caller goes on with Z3.

    A text submitted again with the same limit, in the pool's life, is not run again: it gets
    the first submission's answer, with ``seconds`` 0.0 (the time was spent once, on the
    first). The answer is the same by construction: the same text, under the same options
    (``_serve`` sets nothing else) and the same limit, is the same query (the rule that lets a
    run take an undecided statement's answer from the lock, docs/model.md §6.4). That includes
    an ``unknown`` because the worker was killed or died: the second gets it too."""

    def __init__(self, timeout_ms: int = CVC5_TIMEOUT_MS) -> None:
        self.timeout_ms = timeout_ms
        self._worker = Cvc5Worker()
        self._ex = ThreadPoolExecutor(max_workers=1, thread_name_prefix="cvc5")
        self._asked: dict[tuple[str, int, str], Future[Cvc5Answer]] = {}
        self._lock = threading.Lock()     # so that submit is safe from any thread

    @staticmethod
    def _key(text: str, timeout_ms: int) -> tuple[str, int]:
        # The digest, not the text: a pool's life can see every VC of a prove run.
        return hashlib.sha256(text.encode()).hexdigest(), timeout_ms

    def submit(self, text: str, timeout_ms: int | None = None,
               strategy: str = DEFAULT_STRATEGY) -> Future[Cvc5Answer]:
        """Queue ``text``; ``timeout_ms`` (default the pool's) is cvc5's limit on it, under
        ``strategy`` (ValueError now for an unknown one). A text, limit and strategy queued
        before are not run again (see the class): the Future gets the first one's answer with
        ``seconds`` 0.0."""
        ms = self.timeout_ms if timeout_ms is None else timeout_ms
        _options(strategy)
        key = (*self._key(text, ms), strategy)
        with self._lock:
            first = self._asked.get(key)
            if first is None:
                fut = self._ex.submit(self._worker.check, text, ms, strategy)
                self._asked[key] = fut
                return fut
        # A Future of its own, so that the time spent counts once in the caller's sums.
        again: Future[Cvc5Answer] = Future()

        def share(done: Future[Cvc5Answer]) -> None:
            try:
                a = done.result()
            except BaseException as exc:  # noqa: BLE001 - passed on to the waiter as it is
                again.set_exception(exc)
                return
            again.set_result(dataclasses.replace(a, seconds=0.0))

        first.add_done_callback(share)
        return again

    def close(self) -> None:
        self._ex.shutdown(wait=True)
        self._worker.close()

    def __enter__(self) -> Cvc5Pool:
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()


def _serve() -> None:
    """The worker's loop: one JSON query a line in, one JSON answer a line out."""
    import cvc5

    for line in sys.stdin:
        q = json.loads(line)
        cpu0 = time.process_time()
        try:
            tm = cvc5.TermManager()
            s = cvc5.Solver(tm)
            s.setOption("tlimit-per", str(int(q["wall_ms"])))
            options = [tuple(o) for o in q["options"]]
            for name, value in options:
                s.setOption(name, value)
            p = cvc5.InputParser(s)
            p.setStringInput(cvc5.InputLanguage.SMT_LIB_2_6, q["text"], "vc")
            sm = p.getSymbolManager()
            res = None
            out: dict[str, object]
            while True:
                cmd = p.nextCommand()
                if cmd.isNull():
                    break
                if cmd.getCommandName() == "check-sat":
                    res = s.checkSat()
                else:
                    cmd.invoke(s, sm)
            if res is None:
                out = {"answer": "unknown", "reason": "no check-sat in the query"}
            elif res.isUnsat():
                out = {"answer": "unsat"}
            elif res.isSat():
                out = {"answer": "sat"}
            else:
                why = str(res.getUnknownExplanation()).rsplit(".", 1)[-1].lower()
                out = {"answer": "unknown",
                       "reason": f"{why} at {int(q['ms'])} ms" if why == "timeout" else why}
            # Read back after the query (which could set options of its own), so the caller
            # sees what cvc5 ran under (``_taken``).
            out["ran"] = {name: s.getOption(name) for name, _ in options}
        except Exception as exc:  # noqa: BLE001 - a parse or API error is an answer, not a crash
            out = {"answer": "unknown", "reason": f"cvc5 error: {exc}"}
        out["cpu_s"] = round(time.process_time() - cpu0, 4)
        sys.stdout.write(json.dumps(out) + "\n")
        sys.stdout.flush()


if __name__ == "__main__":
    _serve()
