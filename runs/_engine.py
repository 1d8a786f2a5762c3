"""Many independent tasks on dask.distributed: `cfmpa compare` (one task per workcell) and
`cfmpa check --batch` (one task per plan folder).

Three ways to run, one interface (``Engine``): ``workers=0`` runs the tasks in this process, one
after the other (tests, small runs); ``workers=K`` starts a local cluster of K worker processes
with one thread each (the default; its dashboard address is printed); ``scheduler=ADDRESS``
connects to a running cluster (``dask scheduler`` and ``dask worker ADDRESS``, each worker with
cfmpa installed). A malformed address is refused before any connection, and a scheduler that
does not answer within the connect timeout is an input error too, as is an address where
something else answers (a worker, the dashboard's HTTP port): none of them hangs.

Results come back in completion order to one callback in the client (which records them);
nothing depends on which worker ran what. A task that raises is retried (``RETRIES``), and a
task whose worker dies is rescheduled by the scheduler (up to its ``allowed-failures``); a task
that is lost all the same reaches the callback as a ``TaskLost``, so that it is recorded, never
dropped. The tasks of cfmpa catch their own exceptions and return an error record, so a
``TaskLost`` means the machinery failed, not the workcell.

A cluster that loses all its workers would leave the tasks waiting forever (the scheduler keeps
them for a worker that may come back). So while no task completes the client asks the scheduler
for its workers about once a second: when it has none it warns on stderr, and when it has had
none for ``worker_timeout`` seconds the run stops with ``WorkersLost`` (exit 2), its pending
tasks cancelled; whatever the callback recorded stays recorded (docs/model.md §13). A client
that loses its scheduler (dask then cancels every future) stops with ``WorkersLost`` too,
rather than recording each pending task as lost.
"""

from __future__ import annotations

import logging
import math
import sys
import time
import uuid
import warnings
from collections.abc import Callable, Sequence
from dataclasses import dataclass
from types import TracebackType
from typing import Any, TextIO
from urllib.parse import urlsplit

from ..errors import CfmpaError, InputError, WorkersLost
from ..impl import Progress

__all__ = ["CONNECT_TIMEOUT_S", "RETRIES", "SCHEMES", "WORKER_TIMEOUT_S", "Engine", "ProgressBar",
           "TaskLost", "check_scheduler_address", "error_message"]

#: Seconds to wait for a scheduler (and then for its first worker) before giving up.
CONNECT_TIMEOUT_S = 10.0
#: Seconds a run waits while its cluster has no worker before it stops (--worker-timeout).
WORKER_TIMEOUT_S = 60.0
#: Retries of a task that raises on a worker (dask's ``retries=``).
RETRIES = 2
#: Address schemes of dask.distributed's communication layers that cfmpa accepts.
SCHEMES = ("tcp", "tls", "ws", "wss")


@dataclass(frozen=True)
class TaskLost:
    """A task that ended without a result (after the retries): what dask said."""

    message: str


def error_message(exc: BaseException) -> str:
    """``Type: message`` of an exception, in one line (what an error record keeps)."""
    text = " ".join(str(exc).split())
    return f"{type(exc).__name__}: {text}" if text else type(exc).__name__


def check_scheduler_address(address: str) -> str:
    """``address`` as ``scheme://host:port`` (a bare ``host:port`` is tcp); InputError naming
    --scheduler when it is not one."""
    def bad(why: str) -> InputError:
        return InputError("--scheduler", address, f"must be a Dask scheduler address such as "
                          f"tcp://127.0.0.1:8786 ({why})")

    if not isinstance(address, str) or not address.strip() or address != address.strip():
        raise bad("empty or padded with spaces")
    text = address if "://" in address else f"tcp://{address}"
    parts = urlsplit(text)
    if parts.scheme not in SCHEMES:
        raise bad(f"the scheme must be one of {', '.join(SCHEMES)}")
    if parts.path not in ("", "/") or parts.query or parts.fragment or parts.username:
        raise bad("only scheme://host:port")
    try:
        port = parts.port
    except ValueError:
        raise bad("the port must be a number from 1 to 65535") from None
    if not parts.hostname:
        raise bad("no host")
    if port is None or not 1 <= port <= 65535:
        raise bad("no port" if port is None else "the port must be a number from 1 to 65535")
    return f"{parts.scheme}://{parts.netloc}"


#: The campaign's and batch's bar: cfmpa's one progress bar (``impl.Progress``).
ProgressBar = Progress


def _probe_scheduler(address: str, timeout: float) -> None:
    """InputError unless a Dask scheduler answers at ``address`` within ``timeout`` seconds.

    dask's own connect bounds the TCP connect but not the handshake after it: a server of another
    protocol (the dashboard's HTTP port, say) would keep ``Client`` waiting forever, and a
    worker's address is not a scheduler's. So one bounded exchange first: the handshake and an
    ``identity`` request, in an event loop of its own (whatever runs in this thread)."""
    import asyncio
    from concurrent.futures import ThreadPoolExecutor

    from distributed.comm.core import connect  # what distributed.comm re-exports
    from distributed.security import Security

    args = Security().get_connection_args("client")   # as Client's (TLS from dask's config)

    async def identity() -> Any:
        comm = await connect(address, timeout=timeout, **args)
        try:
            await comm.write({"op": "identity"})
            return await comm.read()
        finally:
            comm.abort()

    async def bounded() -> Any:
        return await asyncio.wait_for(identity(), timeout)

    try:
        with ThreadPoolExecutor(1) as pool:
            info = pool.submit(asyncio.run, bounded()).result()
    except (OSError, TimeoutError) as exc:   # asyncio.TimeoutError is TimeoutError (3.11)
        raise InputError("--scheduler", address, f"did not answer within {timeout:g} s "
                         f"({error_message(exc)[:200]})") from None
    except Exception as exc:
        raise InputError("--scheduler", address, f"does not answer as a Dask scheduler "
                         f"({error_message(exc)[:200]})") from None
    kind = info.get("type") if isinstance(info, dict) else None
    if kind != "Scheduler":
        raise InputError("--scheduler", address, f"is not a Dask scheduler (it answered as "
                         f"{kind or 'something else'}); give the address `dask scheduler` "
                         f"prints")


def _one_kernel_thread() -> None:
    """BuiltDR's kernel on one thread in a worker process that shares the machine's cores."""
    from ..impl import set_kernel_threads

    set_kernel_threads(1)


def _ignore_interrupt() -> None:
    """SIGINT ignored in a local worker process (run in its event loop: its main thread)."""
    import signal
    import threading

    if threading.current_thread() is threading.main_thread():
        signal.signal(signal.SIGINT, signal.SIG_IGN)


class Engine:
    """Run tasks serially (``workers=0``), on a local cluster (``workers=K``) or on the cluster of
    ``scheduler``. Use as a context manager: the cluster starts on entry and closes on exit (also
    on Ctrl-C); ``info`` says where the tasks run (printed on entry to ``stream``). ``warm``, if
    given, runs once on every worker at the start (imports, compiled kernels), so that
    ``timings_s["tasks"]`` measures the tasks, not the workers' first loads."""

    def __init__(self, workers: int = 0, scheduler: str | None = None, *,
                 connect_timeout: float = CONNECT_TIMEOUT_S,
                 worker_timeout: float = WORKER_TIMEOUT_S, stream: TextIO | None = None,
                 warm: Callable[[], Any] | None = None) -> None:
        if isinstance(workers, bool) or not isinstance(workers, int) or workers < 0:
            raise InputError("--workers", workers, "must be an integer >= 0 (0: in this process)")
        for option, value in (("--connect-timeout", connect_timeout),
                              ("--worker-timeout", worker_timeout)):
            if not (isinstance(value, (int, float)) and not isinstance(value, bool)
                    and math.isfinite(value) and value > 0):
                raise InputError(option, value, "must be a number of seconds > 0")
        self.workers = workers
        self.scheduler = None if scheduler is None else check_scheduler_address(scheduler)
        self.connect_timeout = float(connect_timeout)
        self.worker_timeout = float(worker_timeout)
        self.stream = stream
        self.warm = warm
        self.info = "in this process, one task after the other"
        #: Seconds to start (connect, warm the workers) and to run the tasks (submit to last).
        self.timings_s: dict[str, float] = {"engine_start": 0.0, "tasks": 0.0}
        self.dashboard: str | None = None
        self._client: Any = None
        self._cluster: Any = None

    @property
    def serial(self) -> bool:
        return self.scheduler is None and self.workers == 0

    def worker_count(self) -> int:
        """The workers the tasks run on now: 1 in this process, the local cluster's processes,
        or a running cluster's workers as its scheduler reports them (1 when it does not say,
        or before the engine is entered). Blocks of work are cut for this many."""
        if self.serial:
            return 1
        client = self._client
        if client is None:
            return max(1, self.workers)
        try:
            return max(1, len(client.nthreads()))
        except Exception:        # the scheduler did not say: work cut for one worker
            return 1

    def options(self) -> list[str]:
        """This engine's settings as the command line's options (for a command that resumes)."""
        where = (["--scheduler", self.scheduler] if self.scheduler is not None
                 else ["--workers", str(self.workers)])
        for option, value, default in (
                ("--connect-timeout", self.connect_timeout, CONNECT_TIMEOUT_S),
                ("--worker-timeout", self.worker_timeout, WORKER_TIMEOUT_S)):
            if value != default:
                where += [option, f"{value:g}"]
        return where

    def __enter__(self) -> Engine:
        t0 = time.perf_counter()
        try:
            if not self.serial:
                self._start()
            if self.stream is not None:   # the dashboard's address as soon as it serves
                print(f"engine    {self.info}", file=self.stream, flush=True)
            if self.warm is not None:
                # Imports and the kernels' cache load on every worker at once, before the
                # first task: the task times are then the tasks' own.
                self._warm()
        except BaseException:
            self.close()
            raise
        self.timings_s["engine_start"] = time.perf_counter() - t0
        return self

    def __exit__(self, exc_type: type[BaseException] | None, exc: BaseException | None,
                 tb: TracebackType | None) -> None:
        self.close()

    def _start(self) -> None:
        from dask.distributed import Client, LocalCluster

        if self.scheduler is not None:
            _probe_scheduler(self.scheduler, self.connect_timeout)
            try:
                self._client = Client(self.scheduler, timeout=self.connect_timeout,
                                      set_as_default=False)
            except (OSError, TimeoutError) as exc:
                raise InputError("--scheduler", self.scheduler, f"did not answer within "
                                 f"{self.connect_timeout:g} s ({error_message(exc)[:200]})"
                                 ) from None
            try:
                self._client.wait_for_workers(1, timeout=self.connect_timeout)
            except (OSError, TimeoutError):
                raise InputError("--scheduler", self.scheduler, f"has no worker after "
                                 f"{self.connect_timeout:g} s (start one with `dask worker "
                                 f"{self.scheduler}`)") from None
            n = len(self._client.nthreads())
            self.dashboard = self._client.dashboard_link
            self.info = (f"Dask scheduler {self.scheduler}, {n} worker(s) now; dashboard "
                         f"{self.dashboard}")
            return
        # Loopback only (scheduler, workers and dashboard); one thread per worker process: the
        # kernels are single-threaded and the GIL would serialise threads anyway.
        with warnings.catch_warnings():
            # 8787 taken (another cluster): dask serves the dashboard on a free port instead,
            # and the address printed below is the one it took.
            warnings.filterwarnings("ignore", message="Port 8787 is already in use")
            self._cluster = LocalCluster(n_workers=self.workers, threads_per_worker=1,
                                         processes=True, host="127.0.0.1",
                                         dashboard_address="127.0.0.1:8787",
                                         silence_logs=logging.CRITICAL)
        self._client = Client(self._cluster, set_as_default=False)
        # Ctrl-C reaches the workers too (one process group): the client alone handles it and
        # closes the cluster, so the workers ignore it (else each prints a traceback).
        self._client.run(_ignore_interrupt)
        # A local worker is one process of one thread, its kernels too, whatever the number of
        # workers: K workers use K cores, as the info line says (docs/model.md §13).
        self._client.run(_one_kernel_thread)
        self.dashboard = self._client.dashboard_link
        self.info = (f"local Dask cluster, {self.workers} worker process(es) x 1 thread; "
                     f"dashboard {self.dashboard}")

    def _warm(self) -> None:
        assert self.warm is not None
        if self.serial:
            self.warm()
            return
        try:
            # One task pinned to each worker, in its task thread (client.run would block the
            # worker's event loop, and its heartbeats, for as long as the imports take).
            client = self._client
            tag = uuid.uuid4().hex[:8]
            futures = [client.submit(self.warm, key=f"warm-{tag}-{k}", workers=[address],
                                     allow_other_workers=False, pure=False)
                       for k, address in enumerate(client.nthreads())]
            client.gather(futures)
        except Exception as exc:
            raise CfmpaError(f"a Dask worker cannot run cfmpa's tasks ({error_message(exc)}); "
                             f"is this version of cfmpa installed where the workers run?"
                             ) from None

    def close(self) -> None:
        client, cluster = self._client, self._cluster
        self._client = self._cluster = None
        if client is not None:
            client.close()
        if cluster is not None:
            cluster.close()

    def run(self, fn: Callable[..., Any], argsets: Sequence[tuple[Any, ...]],
            on_done: Callable[[int, Any], None], *, name: str = "task",
            progress: ProgressBar | None = None, retries: int = RETRIES) -> None:
        """Call ``fn(*argsets[i])`` for every i; ``on_done(i, result)`` in the client as each
        finishes (in completion order), with a ``TaskLost`` for a task that ended without one.
        ``fn`` must be importable by the workers (a module-level function of cfmpa)."""
        bar = progress or ProgressBar(name, len(argsets))
        bar.restart()       # the rate and time left count from here, not from the engine start
        t0 = time.perf_counter()
        try:
            if self.serial:
                for i, args in enumerate(argsets):
                    try:
                        result: Any = fn(*args)
                    except Exception as exc:
                        result = TaskLost(error_message(exc))
                    on_done(i, result)
                    bar.advance()
                return
            self._run_dask(fn, argsets, on_done, name, bar, retries)
        finally:
            self.timings_s["tasks"] += time.perf_counter() - t0
            bar.close()

    def _run_dask(self, fn: Callable[..., Any], argsets: Sequence[tuple[Any, ...]],
                  on_done: Callable[[int, Any], None], name: str, bar: ProgressBar,
                  retries: int) -> None:
        from dask.distributed import as_completed

        client = self._client
        assert client is not None, "Engine.run outside its with block"
        run_id = uuid.uuid4().hex[:8]   # keys unique per run: another run's results never mix
        futures = {client.submit(fn, *args, key=f"{name}-{run_id}-{i}", retries=retries,
                                 pure=False): i for i, args in enumerate(argsets)}
        watch = _WorkerWatch(lambda: _live_workers(client), self.worker_timeout,
                             self.scheduler or "of this run")
        try:
            done = as_completed(futures, loop=client.loop)
            while not done.is_empty():
                batch = done.next_batch(block=False)
                if not batch:
                    # Nothing finished: a cluster without workers would wait forever here.
                    watch.idle(time.monotonic())
                    time.sleep(_IDLE_S)
                    continue
                watch.progress(time.monotonic())
                for fut in batch:
                    i = futures[fut]
                    try:
                        result = _fetched(fut, watch.poll_s)
                        if result is _LOST_AGAIN:
                            done.add(fut)      # its worker left with the result: computed again
                            continue
                    except Exception as exc:   # the task's worker died too often, or it raised
                        if _scheduler_lost(client, fut, exc):
                            # Not the task's failure: recorded as one, it would be an error
                            # record of a workcell that nothing is wrong with.
                            raise WorkersLost(f"the client lost the connection to the Dask "
                                              f"scheduler {watch.where}; the run stopped"
                                              ) from None
                        result = TaskLost(error_message(exc))
                    on_done(i, result)
                    fut.release()
                    bar.advance()
        finally:
            client.cancel([f for f in futures if not f.done()])


#: Seconds between looks at the finished tasks while none has finished.
_IDLE_S = 0.05
#: What ``_fetched`` returns for a task whose result was lost before it was fetched.
_LOST_AGAIN = object()


def _fetched(fut: Any, timeout: float) -> Any:
    """``fut``'s result, or _LOST_AGAIN if the result left with its worker before it reached
    the client (the scheduler then computes the task again; a plain ``fut.result()`` would wait
    for that, past the watchdog, forever if no worker comes)."""
    while True:
        try:
            return fut.result(timeout=timeout)
        except TimeoutError:
            if fut.status != "finished":
                return _LOST_AGAIN


def _scheduler_lost(client: Any, fut: Any, exc: Exception) -> bool:
    """Whether ``fut`` failed because the client lost its scheduler: dask then cancels every
    future (reason ``scheduler-connection-lost``) while it reconnects."""
    return bool(fut.cancelled()) and (
        getattr(exc, "reason", None) == "scheduler-connection-lost"
        or getattr(client, "status", "running") != "running")


def _live_workers(client: Any) -> int | None:
    """The scheduler's workers that are not closing, or None when the scheduler did not say."""
    try:
        workers = client.scheduler_info()["workers"]
    except Exception:      # the scheduler gone too: no worker the run can count on
        return None
    return sum(1 for w in workers.values()
               if str(w.get("status", "running")) not in ("closing", "closing_gracefully",
                                                          "closed"))


class _WorkerWatch:
    """The watchdog of a run on a cluster: ``idle(now)`` while no task finishes asks ``count``
    (the cluster's workers) at most every ``poll_s`` seconds; the first time it is 0 (or
    unknown) it warns on stderr; when it has been so for ``timeout`` seconds it raises
    WorkersLost. A worker seen again, or a task finished, resets it."""

    def __init__(self, count: Callable[[], int | None], timeout: float, where: str) -> None:
        self.count, self.timeout, self.where = count, timeout, where
        self.poll_s = min(1.0, timeout / 4)
        self._asked = -math.inf
        self._empty_since: float | None = None

    def progress(self, now: float) -> None:
        self._asked = now              # a task finished: there was a worker a moment ago
        self._back()

    def idle(self, now: float) -> None:
        if now - self._asked < self.poll_s:
            return
        self._asked = now
        n = self.count()
        if n:
            self._back()
            return
        if self._empty_since is None:
            self._empty_since = now
            print(f"warning: the Dask cluster {self.where} has no worker; waiting up to "
                  f"{self.timeout:g} s (--worker-timeout) for one, then stopping",
                  file=sys.stderr, flush=True)
        elif now - self._empty_since >= self.timeout:
            raise WorkersLost(f"the Dask cluster {self.where} had no worker for "
                              f"{self.timeout:g} s (--worker-timeout); the run stopped")

    def _back(self) -> None:
        if self._empty_since is not None:
            self._empty_since = None
            print(f"warning: the Dask cluster {self.where} has a worker again; going on",
                  file=sys.stderr, flush=True)

