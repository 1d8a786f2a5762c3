"""Campaigns that lose their workers: `cfmpa compare --scheduler` and `cfmpa check
--batch --scheduler` whose cluster loses its last worker mid-run warn, stop after
--worker-timeout seconds with exit 2 and the command that resumes, and keep what was recorded;
a refused --scheduler writes nothing.

Each test has a cluster of its own (one in-process worker: it starts in a fraction of a second)
whose worker a thread closes mid-run. Every run is in a thread joined with a time limit, so a
run that waits forever fails the test instead of hanging the suite; the seeded faults (the
watchdog disabled, the store opened before the scheduler is reached) show the tests fail
without the code they test.
"""

from __future__ import annotations

import functools
import logging
import shlex
import threading
import time
from pathlib import Path
from typing import Any

import pytest

import cfmpa.runs._batch as batch_module
import cfmpa.runs._campaign as campaign_module
import cfmpa.runs._engine as engine_module
from cfmpa.cli import main
from cfmpa.runs._campaign import STORE_NAME

SEED, N, DT = 5, 4, 0.5
#: Seconds a guarded run may take before the test calls it hung (the runs here take ~5 s).
LIMIT_S = 15.0


@pytest.fixture
def cluster():
    """A local cluster of one in-process worker (threads of this process), its own per test."""
    from dask.distributed import LocalCluster

    c = LocalCluster(n_workers=1, threads_per_worker=1, processes=False, protocol="tcp",
                     host="127.0.0.1", dashboard_address="127.0.0.1:0",
                     silence_logs=logging.CRITICAL)
    c.extra_workers = []           # workers a test starts (_new_worker), closed with the cluster
    yield c
    for w in c.extra_workers:
        c.sync(functools.partial(w.close, executor_wait=False))
    import dask

    _close_workers(c)
    # A closed scheduler (the tests that lose it): the cluster's close would try to reach it
    # for dask's 30 s connect timeout.
    with dask.config.set({"distributed.comm.timeouts.connect": "1s"}):
        c.close()


def _close_workers(cluster: Any) -> None:
    """The cluster's workers closed, not waiting for a task's thread (as a killed worker is)."""
    for w in list(cluster.workers.values()):
        cluster.sync(functools.partial(w.close, executor_wait=False))


def _new_worker(cluster: Any) -> None:
    """A fresh in-process worker on ``cluster``'s scheduler (a worker started again)."""
    from dask.distributed import Worker

    async def start() -> Any:
        return await Worker(cluster.scheduler_address, nthreads=1)

    cluster.extra_workers.append(cluster.sync(start))


class Run:
    """``main(argv)`` in a thread joined for ``limit`` s: ``hung`` (still running then) and
    ``code`` (its exit code, or the exception it raised)."""

    def __init__(self, argv: list[str], limit: float = LIMIT_S) -> None:
        self.got: dict[str, Any] = {}
        self.thread = threading.Thread(target=self._run, args=(argv,), daemon=True)
        self.thread.start()
        self.thread.join(limit)
        self.hung = self.thread.is_alive()

    def _run(self, argv: list[str]) -> None:
        try:
            self.got["code"] = main(argv)
        except BaseException as exc:      # reported to the test, not lost in the thread
            self.got["code"] = exc

    @property
    def code(self) -> Any:
        return self.got.get("code")


def _guarded(argv: list[str], limit: float = LIMIT_S) -> tuple[bool, Any]:
    """(still running after ``limit`` s, exit code or exception) of ``main(argv)``."""
    run = Run(argv, limit)
    return run.hung, run.code


def _when(condition: Any, then: Any, limit: float = LIMIT_S) -> threading.Thread:
    """A thread that calls ``then()`` as soon as ``condition()`` holds (polled every 20 ms)."""
    def watch() -> None:
        t0 = time.monotonic()
        while time.monotonic() - t0 < limit:
            if condition():
                then()
                return
            time.sleep(0.02)

    t = threading.Thread(target=watch, daemon=True)
    t.start()
    return t


def _records(out: Path) -> list[bytes]:
    """The store's record lines (the header left out), [] when there is no store."""
    path = out / STORE_NAME
    return path.read_bytes().splitlines()[1:] if path.exists() else []


def _lose_the_worker_of_a_campaign(cluster: Any, out: Path, monkeypatch: Any,
                                   limit: float = LIMIT_S) -> Run:
    """A campaign of N workcells on ``cluster`` whose worker is closed as soon as the first
    workcell is recorded (the later ones are slowed by 2 s, so the worker has work then), run
    for at most ``limit`` s."""
    monkeypatch.setenv("CFMPA_TEST_FAULTS", '{"1": "sleep:2", "2": "sleep:2", "3": "sleep:2"}')
    argv = ["compare", "--n", str(N), "--seed", str(SEED), "--dt", str(DT), "--out", str(out),
            "--scheduler", cluster.scheduler_address, "--worker-timeout", "2"]
    _when(lambda: len(_records(out)) >= 1, lambda: _close_workers(cluster))
    run = Run(argv, limit)
    monkeypatch.delenv("CFMPA_TEST_FAULTS")
    return run


def test_a_campaign_that_loses_its_last_worker_stops_with_the_command_that_resumes(
        cluster, tmp_path, monkeypatch, capsys):
    out = tmp_path / "c"
    t0 = time.monotonic()
    run = _lose_the_worker_of_a_campaign(cluster, out, monkeypatch)
    err = capsys.readouterr().err
    assert not run.hung, "the campaign waited for a worker that never came"
    assert run.code == 2, err
    assert time.monotonic() - t0 < LIMIT_S
    address = cluster.scheduler_address
    assert f"warning: the Dask cluster {address} has no worker; waiting up to 2 s" in err
    assert "Traceback" not in err
    recorded = _records(out)
    assert 1 <= len(recorded) < N            # what was recorded stays, nothing more
    assert all(b'"status":"ok"' in line for line in recorded)
    assert not (out / "compare.json").exists()
    (last,) = [line for line in err.splitlines() if line.startswith("error: ")]
    assert "had no worker for 2 s (--worker-timeout)" in last
    assert f"{len(recorded)} of {N} workcells are recorded in {out / STORE_NAME}" in last
    command = last.split("resume with: ", 1)[1]
    assert command == shlex.join(["cfmpa", "compare", "--n", str(N), "--seed", str(SEED),
                                  "--dt", str(DT), "--out", str(out), "--scheduler", address,
                                  "--worker-timeout", "2"])
    # The command resumes: with a worker again, it reuses the records and plans the rest.
    _new_worker(cluster)
    hung, code = _guarded(shlex.split(command)[1:])
    printed = capsys.readouterr().out
    assert not hung and code == 0, printed
    assert f"reused {len(recorded)} finished workcell(s), computing {N - len(recorded)}" in printed
    assert len(_records(out)) == N and (out / "compare.json").exists()


def test_seeded_fault_without_the_watchdog_the_campaign_waits_forever(cluster, tmp_path,
                                                                      monkeypatch, capsys):
    """The watchdog disabled (it never gives up until the test releases it): the run is still
    waiting well after --worker-timeout, so the test above would fail."""
    release = threading.Event()

    class Released(Exception):
        pass

    def no_watchdog(self: Any, now: float) -> None:
        if release.is_set():
            raise Released
    monkeypatch.setattr(engine_module._WorkerWatch, "idle", no_watchdog)
    run = _lose_the_worker_of_a_campaign(cluster, tmp_path / "c", monkeypatch, limit=8.0)
    release.set()
    run.thread.join(LIMIT_S)                   # the released run closes its client and store
    assert run.hung, f"the run ended ({run.code!r}) without its watchdog"
    assert isinstance(run.code, Released)
    assert "had no worker" not in capsys.readouterr().err


def test_a_worker_back_within_the_timeout_lets_the_campaign_go_on(cluster, tmp_path,
                                                                  monkeypatch, capsys):
    """Not a false alarm: a cluster without a worker for less than --worker-timeout goes on."""
    out = tmp_path / "c"
    monkeypatch.setenv("CFMPA_TEST_FAULTS", '{"1": "sleep:1"}')

    def replace() -> None:
        _close_workers(cluster)
        time.sleep(1.0)
        _new_worker(cluster)

    _when(lambda: len(_records(out)) >= 1, replace)
    hung, code = _guarded(["compare", "--n", "3", "--seed", str(SEED), "--dt", str(DT),
                           "--out", str(out), "--scheduler", cluster.scheduler_address,
                           "--worker-timeout", "8"])
    err = capsys.readouterr().err
    assert not hung and code == 0, err
    assert len(_records(out)) == 3


def _lose_the_scheduler_of_a_campaign(cluster: Any, out: Path, monkeypatch: Any) -> Run:
    """As ``_lose_the_worker_of_a_campaign``, the scheduler closed instead of the worker."""
    monkeypatch.setenv("CFMPA_TEST_FAULTS", '{"1": "sleep:2", "2": "sleep:2", "3": "sleep:2"}')
    argv = ["compare", "--n", str(N), "--seed", str(SEED), "--dt", str(DT), "--out", str(out),
            "--scheduler", cluster.scheduler_address, "--worker-timeout", "2"]
    _when(lambda: len(_records(out)) >= 1, lambda: cluster.sync(cluster.scheduler.close))
    run = Run(argv)
    monkeypatch.delenv("CFMPA_TEST_FAULTS")
    return run


def test_a_campaign_that_loses_its_scheduler_stops_with_the_command_that_resumes(
        cluster, tmp_path, monkeypatch, capsys):
    """dask cancels every future when the client loses its scheduler: the run stops (exit 2)
    with the resume command, and no workcell is recorded as an error for it."""
    out = tmp_path / "c"
    run = _lose_the_scheduler_of_a_campaign(cluster, out, monkeypatch)
    err = capsys.readouterr().err
    assert not run.hung and run.code == 2, err
    (last,) = [line for line in err.splitlines() if line.startswith("error: ")]
    assert f"lost the connection to the Dask scheduler {cluster.scheduler_address}" in last
    assert f"resume with: cfmpa compare --n {N}" in last
    recorded = _records(out)
    assert 1 <= len(recorded) < N and all(b'"status":"ok"' in line for line in recorded)
    assert not (out / "compare.json").exists()


def test_seeded_fault_a_lost_scheduler_taken_for_lost_tasks_records_errors(
        cluster, tmp_path, monkeypatch, capsys):
    """Without the check, every pending workcell is recorded as an error and compare.json is
    written with them (exit 1): the test above would fail."""
    monkeypatch.setattr(engine_module, "_scheduler_lost", lambda client, fut, exc: False)
    out = tmp_path / "c"
    run = _lose_the_scheduler_of_a_campaign(cluster, out, monkeypatch)
    capsys.readouterr()
    assert not run.hung and run.code == 1
    assert any(b'"status":"error"' in line for line in _records(out))


# --- a refused --scheduler writes nothing -------------------------------------------------------

def test_a_scheduler_that_does_not_answer_writes_no_store(tmp_path, capsys):
    out = tmp_path / "c"
    hung, code = _guarded(["compare", "--n", "2", "--scheduler", "tcp://127.0.0.1:9",
                           "--connect-timeout", "1", "--out", str(out)])
    assert not hung and code == 2
    assert "error: --scheduler did not answer within 1 s" in capsys.readouterr().err
    assert not (out / STORE_NAME).exists() and not out.exists()


def test_a_scheduler_without_workers_writes_no_store(tmp_path, capsys):
    from dask.distributed import LocalCluster

    out = tmp_path / "c"
    with LocalCluster(n_workers=0, processes=False, protocol="tcp", host="127.0.0.1",
                      dashboard_address="127.0.0.1:0", silence_logs=logging.CRITICAL) as empty:
        hung, code = _guarded(["compare", "--n", "2", "--scheduler", empty.scheduler_address,
                               "--connect-timeout", "1", "--out", str(out)])
    assert not hung and code == 2
    assert "has no worker after 1 s" in capsys.readouterr().err
    assert not out.exists()


def test_seeded_fault_a_store_opened_before_the_scheduler_is_reached_is_left_behind(
        tmp_path, monkeypatch, capsys):
    """The old order (store first, scheduler when the tasks start): the refusal leaves a
    compare.jsonl, so the tests above would fail."""
    monkeypatch.setattr(campaign_module, "_connect_first", lambda engine: False)
    out = tmp_path / "c"
    hung, code = _guarded(["compare", "--n", "2", "--scheduler", "tcp://127.0.0.1:9",
                           "--connect-timeout", "1", "--out", str(out)])
    assert not hung and code == 2
    capsys.readouterr()
    assert (out / STORE_NAME).exists()


# --- check --batch ------------------------------------------------------------------------------

@pytest.fixture(scope="module")
def plans(tmp_path_factory):
    """A scenario file and three plan folders of it."""
    import factory
    from cfmpa.runs._plan import plan, write_plan
    from cfmpa.runs._selftest import WORKCELLS
    from cfmpa.spec import load_scenario

    d = tmp_path_factory.mktemp("batch")
    (d / "small.toml").write_text(factory.toml(WORKCELLS["small"]))
    s = load_scenario(d / "small.toml")
    for name in ("a", "b", "c"):
        write_plan(plan(s, "modified", contracts="off"), d / "plans" / name)
    return d


#: Set when the first plan's check is done (the batch's task below runs in this process).
_FIRST_CHECKED = threading.Event()


def _slow_after_the_first(folder: str, scenario: str | None, rel: str) -> dict[str, Any]:
    """check_plan_folder, 2 s slower for every plan but "a" (module level: tasks are pickled,
    by reference; the in-process worker runs this very function)."""
    if rel != "a":
        time.sleep(2)
    row = _REAL_CHECK(folder, scenario, rel)
    _FIRST_CHECKED.set()
    return row


_REAL_CHECK = batch_module.check_plan_folder


def test_a_batch_that_loses_its_last_worker_stops_with_the_command_that_runs_it_again(
        cluster, plans, tmp_path, monkeypatch, capsys):
    _FIRST_CHECKED.clear()
    monkeypatch.setattr(batch_module, "check_plan_folder", _slow_after_the_first)
    summary = tmp_path / "summary.json"
    argv = ["check-batch", str(plans / "plans"), str(plans / "small.toml"),
            "--json", str(summary), "--scheduler", cluster.scheduler_address,
            "--worker-timeout", "2"]
    _when(_FIRST_CHECKED.is_set, lambda: _close_workers(cluster))
    hung, code = _guarded(argv)
    err = capsys.readouterr().err
    assert not hung, f"the batch waited for a worker that never came: {err}"
    assert code == 2, err
    assert f"warning: the Dask cluster {cluster.scheduler_address} has no worker" in err
    (last,) = [line for line in err.splitlines() if line.startswith("error: ")]
    # "a" is checked; its row reaches the client unless the worker closes first (then its
    # result is lost with the worker and the task waits for another: _fetched).
    assert "had no worker for 2 s" in last
    assert "1 of 3 plans were checked" in last or "0 of 3 plans were checked" in last
    assert "no summary is written" in last
    assert last.split("run it again with: ", 1)[1] == shlex.join(["cfmpa", *argv])
    assert not summary.exists()


# --- --worker-timeout's budget ------------------------------------------------------------------

@pytest.mark.parametrize("value, said", [
    ("1e9", "--worker-timeout must be at most 86400 (a day)"),
    ("inf", "--worker-timeout must be a finite number"),
    ("nan", "--worker-timeout must be a finite number"),
    ("-1", "--worker-timeout must be at least 0"),
    ("0", "--worker-timeout must be a number of seconds > 0"),
])
def test_a_worker_timeout_out_of_its_budget_is_exit_2_before_anything_is_written(
        value, said, plans, tmp_path, capsys):
    out = tmp_path / "c"
    assert main(["compare", "--n", "1", "--workers", "0", "--out", str(out),
                 "--worker-timeout", value]) == 2
    assert said in capsys.readouterr().err
    assert not out.exists()
    summary = tmp_path / "summary.json"
    assert main(["check", "--batch", str(plans / "plans"), "--workers", "0",
                 "--json", str(summary), "--worker-timeout", value]) == 2
    assert said in capsys.readouterr().err
    assert not summary.exists()


# --- the watchdog alone (a fake cluster, a fake clock) -----------------------------------------

def test_the_watchdog_stops_only_after_the_timeout_without_a_worker(capsys):
    from cfmpa.errors import WorkersLost, exit_code

    counts = iter([1, 0, 0, 2, None, 0, 0, 0])      # None: the scheduler did not say
    watch = engine_module._WorkerWatch(lambda: next(counts), 2.0, "tcp://x:1")
    assert watch.poll_s == 0.5
    watch.idle(0.0)                                  # 1 worker
    watch.idle(0.2)                                  # too soon to ask again: nothing asked
    watch.idle(0.5)                                  # 0: the warning, the clock starts
    assert "has no worker; waiting up to 2 s" in capsys.readouterr().err
    watch.idle(2.0)                                  # 0 for 1.5 s: not yet
    watch.idle(2.5)                                  # 2 workers: back, the clock reset
    assert "has a worker again" in capsys.readouterr().err
    watch.idle(3.0)                                  # unknown: as none, the clock starts
    watch.progress(3.2)                              # a task finished: reset, nothing asked
    watch.idle(3.7)                                  # 0: the clock starts again at 3.7
    watch.idle(5.6)                                  # 0 for 1.9 s: not yet
    watch.idle(5.7)                                  # too soon to ask again
    with pytest.raises(WorkersLost, match="had no worker for 2 s") as lost:
        watch.idle(6.1)                              # 0 for 2.4 s
    assert exit_code(lost.value) == 2


class _Future:
    """A finished future whose result's fetch times out ``slow`` times, then succeeds; with
    ``lost``, the scheduler says (after the first time-out) that the result is gone."""

    def __init__(self, slow: int, lost: bool = False) -> None:
        self.slow, self.lost, self.status, self.calls = slow, lost, "finished", 0

    def result(self, timeout: float | None = None) -> str:
        assert timeout is not None, "a fetch without a time-out can wait forever"
        self.calls += 1
        if self.calls <= self.slow:
            if self.lost:
                self.status = "pending"
            raise TimeoutError
        return "row"


def test_a_result_lost_with_its_worker_before_it_is_fetched_goes_back_to_waiting():
    assert engine_module._fetched(_Future(0), 0.5) == "row"
    assert engine_module._fetched(_Future(2), 0.5) == "row"        # slow, not lost: waited for
    assert engine_module._fetched(_Future(1, lost=True), 0.5) is engine_module._LOST_AGAIN
