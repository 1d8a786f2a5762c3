"""cvc5's limit is the worker's CPU time (docs/model.md §6.4): a worker that gets no CPU for a
while (a loaded machine) is not stopped before it has spent its limit; one that spends it is
killed; a worker that neither answers nor spends CPU is stopped by the wall-clock net."""

from __future__ import annotations

import os
import subprocess
import sys
import time

import pytest

from cfmpa.proofs import _cvc5
from cfmpa.proofs._cvc5 import _cpu_seconds, _wait
from cfmpa.proofs._pins import _reason_class

needs_proc = pytest.mark.skipif(_cpu_seconds(os.getpid()) is None, reason="no /proc")


def _worker(code: str) -> subprocess.Popen[str]:
    return subprocess.Popen([sys.executable, "-c", code], stdin=subprocess.PIPE,
                            stdout=subprocess.PIPE, text=True)


def _stop(p: subprocess.Popen[str]) -> None:
    p.kill()
    p.wait()
    for f in (p.stdin, p.stdout):
        if f is not None:
            f.close()


@needs_proc
def test_the_cpu_time_read_is_the_processs_own():
    end = time.process_time() + 0.2
    while time.process_time() < end:
        pass
    got = _cpu_seconds(os.getpid())
    assert got is not None and abs(got - time.process_time()) < 0.1


@needs_proc
def test_a_starved_worker_is_not_stopped_before_it_has_spent_its_limit():
    # Asleep (no CPU) for longer than the 300 ms limit and its 1 s grace, then it answers
    # (within the 1.5 s + 1 s net): a wall-clock limit would have stopped it; the CPU limit
    # waits for it.
    p = _worker("import time; time.sleep(2.0); print('done', flush=True)")
    try:
        assert _wait(p, 300, False, _cpu_seconds(p.pid)) == ""
        assert p.stdout is not None and p.stdout.readline() == "done\n"
    finally:
        _stop(p)
    # Seeded fault: the wall clock as the limit (no CPU reading): stopped.
    p = _worker("import time; time.sleep(3); print('done', flush=True)")
    try:
        why = _wait(p, 300, False, None)
        assert why.startswith("killed after") and "of CPU" not in why
    finally:
        _stop(p)


@needs_proc
def test_a_worker_that_spends_its_limit_is_stopped():
    p = _worker("while True: pass")
    try:
        t0 = time.monotonic()
        why = _wait(p, 300, False, _cpu_seconds(p.pid))
        assert why.startswith("killed after 0.") and "s of CPU (cvc5 overran its 300 ms limit)" in why
        assert time.monotonic() - t0 < 5.0
        assert _reason_class(why) == "overran its 300 ms limit (killed)"
    finally:
        _stop(p)


@needs_proc
def test_a_worker_that_neither_answers_nor_computes_meets_the_wall_clock_net(monkeypatch):
    monkeypatch.setattr(_cvc5, "_GRACE_S", 0.0)
    p = _worker("import time; time.sleep(30)")
    try:
        t0 = time.monotonic()
        why = _wait(p, 100, False, _cpu_seconds(p.pid))       # net: 5 x 0.1 s
        assert "wall-clock net" in why and time.monotonic() - t0 < 3.0
        # The lock keeps the class of the kill, not the seconds (they follow the load).
        assert _reason_class(why) == "overran its 100 ms limit's wall-clock net (killed)"
    finally:
        _stop(p)
