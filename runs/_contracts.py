"""Contract-checked BuiltDR and searchoptpath: the triples of ``spec._triples`` at run time.

Modes (docs/model.md §7):
- ``off``: nothing is checked.
- ``sampled``: every precondition; D_R's shape; Theorem 1/3's cell condition at ``sample`` cells
  drawn uniformly without replacement (seeded, recorded) plus every cell the found path
  occupies (the entries its safety rests on); is_path and J1/J2 on the path. Optimality is not
  checked. With no mismatch among n random cells, the fraction of wrong cells is below 3/n with
  95% confidence (P(miss) = (1 - p)^n <= 0.05 for p >= 3/n): 0.073% at n = 4096. That is all a
  sample shows: its checks are recorded with coverage ``sample``, and pre.dr.spec (which rests
  on them) says it held on the sample only.
- ``full``: every cell by the spec's own regions (shapely, sharing no code with impl/), the path
  by is_path, J1/J2 recomputed, and optimality through a witness (docs/model.md §11): the
  search's own (``SearchResult.witness``), else one computed by the fast search, verified by
  ``spec.check_witness``. What is trusted is the checker, not the search that made the witness.

A failed precondition always stops the run (the triple says nothing about C then); a failed
postcondition raises ContractViolation too, unless the caller asked to record and go on.
"""

from __future__ import annotations

import contextlib
import functools
import gc
import math
import os
import pickle
import signal
import struct
import sys
import threading
import time
import traceback
from collections.abc import Callable, Sequence
from dataclasses import dataclass, replace
from enum import Enum
from types import TracebackType
from typing import Any

import numpy as np
import numpy.typing as npt

from ..errors import ContractViolation, InputError
from ..files import jsonable
from ..impl import build_dr, search_opt_path
from ..spec import (
    Failure,
    Grid,
    Scenario,
    SearchResult,
    SearchStatus,
    Triple,
    Variant,
    Witness,
    builtdr_triple,
    cells_failures,
    check_witness,
    dr_cell_failures,
    dr_shape_failures,
    grid_failures,
    path_cells,
    search_failures,
    search_triple,
)

__all__ = [
    "DEFAULT_SAMPLE",
    "BuiltDRCheck",
    "Check",
    "Mode",
    "Settings",
    "TripleRun",
    "builtdr_pre",
    "builtdr_post",
    "builtdr_path_cells",
    "search_pre",
    "search_post",
    "checked_build_dr",
    "checked_search",
    "contracts_json",
    "optimality_failures",
    "overlap_helps",
    "sample_cells",
    "violation_json",
]

#: Cells of the sampled mode's random sample; see the module docstring for the confidence. It
#: costs about 0.5-0.8 s of shapely on the default grid (measured here, in process), so against
#: the fast BuiltDR that `cfmpa plan` uses (0.8-1.4 s) it adds 40-100%, not "a few per cent";
#: only against the reference BuiltDR (~7.5 s) is it under a tenth.
DEFAULT_SAMPLE = 4096

DR = npt.NDArray[np.uint8]
Builder = Callable[[Scenario, Variant, Grid], DR]
Searcher = Callable[[DR, tuple[int, int], tuple[int, int]], SearchResult]


class Mode(str, Enum):
    """How much of the triples a run checks."""

    OFF = "off"
    SAMPLED = "sampled"
    FULL = "full"

    def __str__(self) -> str:
        return self.value


@dataclass(frozen=True)
class Settings:
    """The contract mode, and for ``sampled`` the seed and the number of random cells."""

    mode: Mode = Mode.SAMPLED
    seed: int = 0
    sample: int = DEFAULT_SAMPLE

    @classmethod
    def of(cls, mode: Mode | str = Mode.SAMPLED, seed: int = 0,
           sample: int | None = None) -> Settings:
        """Validated settings; InputError names the bad option."""
        try:
            m = Mode(mode)
        except ValueError:
            raise InputError("--contracts", mode, "must be one of off, sampled, full") from None
        if isinstance(seed, bool) or not isinstance(seed, int) or seed < 0:
            raise InputError("--seed", seed, "must be an integer >= 0")
        n = DEFAULT_SAMPLE if sample is None else sample
        if isinstance(n, bool) or not isinstance(n, int) or n < 1:
            raise InputError("--sample", sample, "must be an integer >= 1")
        return cls(m, seed, n)


@dataclass(frozen=True)
class Check:
    """One condition as a run checked it: over what (``scope``), how many items, and the verdict.

    ``ok`` is None when the condition was not checked (the scope says why). ``coverage`` is
    ``all`` when ``ok`` speaks for the whole condition, ``sample`` when only for the items
    checked (a seeded sample of cells: the condition may still fail elsewhere), ``none`` when
    not checked.
    """

    part: str
    condition: str
    scope: str
    count: int
    ok: bool | None
    coverage: str = "all"


@dataclass(frozen=True)
class TripleRun:
    """What one check of one triple did: its checks and the failures found."""

    triple: Triple
    checks: tuple[Check, ...]
    failures: tuple[Failure, ...]

    @property
    def ok(self) -> bool:
        return not self.failures

    @property
    def checked(self) -> int:
        return sum(c.count for c in self.checks)

    def violations(self) -> list[ContractViolation]:
        return [self.triple.violation(f) for f in self.failures]

    def raise_first(self) -> None:
        """Raise the first failure as ContractViolation; return when there is none."""
        if self.failures:
            raise self.triple.violation(self.failures[0])


#: (condition, scope, count, failures or None for "not checked"[, coverage]).
Item = (tuple[str, str, int, list[Failure] | None]
        | tuple[str, str, int, list[Failure] | None, str])


def _run(triple: Triple, part: str, items: Sequence[Item]) -> TripleRun:
    """A TripleRun from (condition, scope, count, failures or None for 'not checked'[, coverage]);
    coverage is ``all`` unless given (``none`` when not checked)."""
    checks, failures = [], []
    for cid, scope, count, fails, *rest in items:
        ok = None if fails is None else not fails
        coverage = "none" if fails is None else (rest[0] if rest else "all")
        checks.append(Check(part, cid, scope, count if fails is not None else 0, ok, coverage))
        failures += fails or []
    return TripleRun(triple, tuple(checks), tuple(failures))


# --- the checks, as values (no raising) -------------------------------------------------------


def builtdr_pre(s: Scenario, variant: Variant | str, grid: Grid) -> TripleRun:
    """Theorem 1/3's precondition: the grid is well formed and start/goal lie in it."""
    fails = grid_failures(s, grid)
    by = {cid: [f for f in fails if f.condition == cid]
          for cid in ("pre.grid.N", "pre.grid.h", "pre.grid.scenario")}
    cells = cells_failures(grid, s.right.start_cell, s.right.goal_cell)
    return _run(builtdr_triple(variant), "pre", [
        ("pre.grid.N", "N and dt against Tf, exact, binary and decimal readings", 1,
         by["pre.grid.N"]),
        ("pre.grid.h", "h against omega dt per joint, exact (float h; binary and decimal "
         "readings); span of the limits", 2, by["pre.grid.h"]),
        ("pre.grid.scenario", "dt, Tf, lower limits", 1, by["pre.grid.scenario"]),
        ("pre.cells", "start and goal cells", 2, cells),
    ])


def sample_cells(shape: tuple[int, int, int], n: int, seed: int) -> npt.NDArray[np.int64]:
    """``n`` distinct cells (k, i, j) drawn uniformly from ``shape`` with numpy's PCG64(seed),
    sorted; all cells when n >= their number."""
    total = math.prod(shape)
    if n >= total:
        flat = np.arange(total)
    else:
        flat = np.sort(np.random.default_rng(seed).choice(total, size=n, replace=False))
    return np.column_stack(np.unravel_index(flat, shape)).astype(np.int64)


def builtdr_post(s: Scenario, variant: Variant | str, grid: Grid, dr: Any,
                 settings: Settings) -> TripleRun:
    """Theorem 1/3's postcondition: D_R's shape, and its cells (all, or a seeded sample)."""
    triple = builtdr_triple(variant)
    shape = dr_shape_failures(grid, dr)
    items: list[Item] = [("post.shape", f"shape {list(grid.shape)}, uint8, values 0/1", 1, shape)]
    total = math.prod(grid.shape)
    if shape:
        items.append(("post.cells", "not checked: D_R has the wrong shape", 0, None))
    elif settings.mode is Mode.FULL or settings.sample >= total:
        n, fails = dr_cell_failures(s, variant, grid, dr)
        items.append(("post.cells", f"all {n} cells", n, fails))
    else:
        cells = sample_cells(grid.shape, settings.sample, settings.seed)
        n, fails = dr_cell_failures(s, variant, grid, dr, cells)
        items.append(("post.cells", f"{n} random cells of {total} (seed {settings.seed}): a "
                      "sample, not every cell", n, fails, "sample"))
    return _run(triple, "post", items)


def builtdr_path_cells(s: Scenario, variant: Variant | str, grid: Grid, dr: DR,
                       path: Sequence[Sequence[int]]) -> TripleRun:
    """Theorem 1/3's cell condition at the cells a path occupies (each step's layer, and R)."""
    cells = path_cells(path, grid.N)
    n, fails = dr_cell_failures(s, variant, grid, dr, cells)
    return _run(builtdr_triple(variant), "post", [
        ("post.cells", f"the {n} cells the path occupies (step k in its layer, then R)", n,
         fails, "sample")])


def search_pre(variant: Variant | str, grid: Grid, dr: Any, start: Sequence[int],
               goal: Sequence[int], established: TripleRun | None) -> TripleRun:
    """Theorem 2/4's precondition; pre.dr.spec is taken from the BuiltDR check ``established``.

    It is established (coverage ``all``) only when that check covered every cell; after a
    sampled check the record says that it held on the sample, and no more."""
    return _run(search_triple(variant), "pre", [
        ("pre.dr.shape", f"shape {list(grid.shape)}, uint8, values 0/1", 1,
         dr_shape_failures(grid, dr, "pre.dr.shape")),
        ("pre.cells", "start and goal cells", 2, cells_failures(grid, start, goal)),
        _dr_spec_item(established),
    ])


def _dr_spec_item(established: TripleRun | None) -> Item:
    """search_pre's pre.dr.spec, from the BuiltDR postcondition check ``established``."""
    spec: list[Failure] | None
    coverage = "all"
    if established is None:
        scope, spec = "not checked: no BuiltDR postcondition check in this run", None
    else:
        cells = [c for c in established.checks if c.condition == "post.cells"]
        name = established.triple.name
        if cells and all(c.coverage == "all" for c in cells):
            scope = f"by {name}'s post.cells check: " + "; ".join(c.scope for c in cells)
        else:
            coverage = "sample"
            scope = (f"on a sample only: {name}'s post.cells at "
                     + "; ".join(c.scope.split(":")[0] for c in cells)
                     + "; the other cells of D_R are not checked")
        spec = [Failure("pre.dr.spec", f"D_R fails {name}'s {f.condition}: "
                        f"{f.message}", f.values, f.count) for f in established.failures]
    return ("pre.dr.spec", scope, 0, spec, coverage)


def optimality_failures(dr: DR, start: Sequence[int], goal: Sequence[int],
                        result: SearchResult, witness: Witness | None = None
                        ) -> tuple[str, list[Failure]]:
    """post.optimal through a witness: (where the witness came from, the failures).

    ``witness`` (a file's), else the result's own, else one computed by the fast search over
    ``dr``; ``spec.check_witness`` verifies it against the result. A computed witness that
    certifies the other answer (a path where none is reported, or none where one is) is
    verified for that answer, and the mismatch is the failure."""
    start, goal = (int(start[0]), int(start[1])), (int(goal[0]), int(goal[1]))
    if witness is None and result.witness is None:
        # Imported here: a run on the numpy kernels while the fast ones compile makes its own
        # witness and never imports numba (docs/model.md §7.5).
        from ..impl import search_opt_path_fast
        answer = search_opt_path_fast(dr, start, goal, with_witness=True)
        if answer.witness is None:                       # with_witness: never
            return _optimality(dr, start, goal, result, None, answer)
        with answer.witness:            # its spill files (large grids) closed here, not by the GC
            return _optimality(dr, start, goal, result, answer.witness, answer)
    return _optimality(dr, start, goal, result, witness, None)


def _optimality(dr: DR, start: tuple[int, int], goal: tuple[int, int], result: SearchResult,
                witness: Witness | None, answer: SearchResult | None
                ) -> tuple[str, list[Failure]]:
    """``optimality_failures`` given the witness, and the fast search's ``answer`` when the
    witness is the one it computed."""
    source = "the search's own witness"
    if witness is None:
        witness = result.witness
    if answer is not None:
        source = "a witness computed by the fast search"
        if answer.status is not result.status:
            wrong = check_witness(dr, start, goal, answer, witness)
            if wrong:
                return source, [_as_optimal(f, "the fast search's witness of its own answer")
                                for f in wrong]
            return source, [replace(f, message=f"{f.message} (a witness proves the other "
                                    "answer)") for f in search_failures(dr, start, goal, result,
                                                                        answer)
                            if f.condition == "post.optimal"]
    elif witness is not result.witness:
        source = "the witness given"
    return source, [_as_optimal(f, "the witness") for f in
                    check_witness(dr, start, goal, result, witness)]


def _as_optimal(f: Failure, what: str) -> Failure:
    return Failure("post.optimal", f"{what} fails {f.condition}: {f.message}", f.values, f.count)


def search_post(variant: Variant | str, dr: DR, start: Sequence[int], goal: Sequence[int],
                result: SearchResult, settings: Settings, *,
                witness: Witness | None = None) -> TripleRun:
    """Theorem 2/4's postcondition: is_path and J1/J2 always; optimality in full mode only,
    through a witness verified by the spec's checker (``optimality_failures``)."""
    found = result.status is SearchStatus.FOUND
    fails = search_failures(dr, start, goal, result)

    def of(cid: str) -> list[Failure]:
        return [f for f in fails if f.condition == cid]

    steps = max(len(result.path), dr.shape[0] - 1) + 1
    items: list[Item]
    if found:
        items = [("post.is_path", f"{len(result.path)} cells, {steps} step checks", steps,
                  of("post.is_path")),
                 ("post.costs", "J1 and J2 recomputed", 2, of("post.costs"))]
    else:
        items = [("post.is_path", "nothing to check: no path reported", 0, []),
                 ("post.costs", "nothing to check: no path reported", 0, [])]
    if settings.mode is not Mode.FULL:
        items.append(("post.optimal", "not checked in sampled mode (full mode verifies a "
                      "witness of optimality, docs/model.md §11)", 0, None))
    else:
        source, optimal = optimality_failures(dr, start, goal, result, witness)
        items.append(("post.optimal", f"through {source}, verified by spec.check_witness", 1,
                      optimal))
    return _run(search_triple(variant), "post", items)


def _without(run: TripleRun, condition: str) -> TripleRun:
    return replace(run, failures=tuple(f for f in run.failures if f.condition != condition))


# --- the wrappers -----------------------------------------------------------------------------


def checked_build_dr(s: Scenario, variant: Variant | str, grid: Grid, settings: Settings, *,
                     build: Builder = build_dr, stop: bool = True
                     ) -> tuple[DR, tuple[TripleRun, ...]]:
    """``build(s, variant, grid)`` under Theorem 1/3: (D_R, the checks run).

    A failed precondition raises ContractViolation before building; a failed postcondition
    raises after it when ``stop``, else it is returned in the runs.
    """
    check = BuiltDRCheck(s, variant, grid, settings, build=build, stop=stop, overlap=False)
    return check.dr, check.runs


def overlap_helps(dr: Any) -> bool:
    """Whether BuiltDR's postcondition check can run beside the search to advantage
    (docs/model.md §7.5), in a forked worker process: on Linux, D_R is an array in memory (not
    a store read a layer at a time, whose reader a fork would share), this process may run on
    more than one CPU and is running one thread (a fork copies no other thread, yet a lock one
    of them holds), and the kernels run on more than one thread (the prove run's and the audit's
    workers and Dask's workers set one: there the cores are shared out already)."""
    from ..impl import kernel_threads

    return (sys.platform.startswith("linux") and isinstance(dr, np.ndarray)
            and len(os.sched_getaffinity(0)) > 1 and threading.active_count() == 1
            and kernel_threads() > 1)


#: The most bytes a forked check may send back (its pickled TripleRun or exception).
_ANSWER_LIMIT = 64 << 20
#: What the worker process sends before its pickled answer: the check's start and end
#: (time.perf_counter, CLOCK_MONOTONIC on Linux: the same clock in both processes).
_SPAN = struct.Struct("<dd")


class _Forked:
    """``fn()`` in a forked child process, its value or exception sent back pickled on a pipe
    (read, bounded, by ``answer``); the child ends with os._exit (no atexit, no flush)."""

    def __init__(self, fn: Callable[[], Any]) -> None:
        rfd, wfd = os.pipe()
        pid = os.fork()
        if pid == 0:                                              # pragma: no cover - the child
            code = 70
            try:
                gc.disable()          # a collection would touch, so copy, every object's page
                os.close(rfd)
                t0 = time.perf_counter()
                try:
                    answer: tuple[str, Any] = ("value", fn())
                except BaseException as exc:  # noqa: BLE001 - sent to the parent
                    where = "".join(traceback.format_exception(exc))[-4000:]
                    exc.add_note(f"(in BuiltDR's postcondition check's worker process)\n{where}")
                    answer = ("error", exc)
                t1 = time.perf_counter()
                try:
                    data = pickle.dumps(answer)
                except Exception:  # noqa: BLE001 - an answer that cannot be pickled
                    what = ("".join(traceback.format_exception(answer[1]))[-4000:]
                            if answer[0] == "error" else repr(answer[1])[:200])
                    data = pickle.dumps(("error", RuntimeError(
                        f"BuiltDR's postcondition check's answer cannot be sent back: {what}")))
                with os.fdopen(wfd, "wb") as fh:
                    fh.write(_SPAN.pack(t0, t1) + data)
                code = 0
            finally:
                os._exit(code)
        os.close(wfd)
        self._pid, self._rfd = pid, rfd

    def answer(self, *, kill: bool = False) -> tuple[str, Any, tuple[float, float]]:
        """("value" | "error", the value or exception, the check's (start, end)); once. ``kill``:
        end the child first (the caller is being interrupted)."""
        data = b""
        read = False
        try:
            if not kill:
                with os.fdopen(self._rfd, "rb", closefd=False) as fh:
                    data = fh.read(_ANSWER_LIMIT + 1)
                read = True
        finally:
            # Killed when asked, when the read was interrupted (the wait would otherwise last
            # the whole check) and when the answer is over the bound (it stops reading).
            if not read or len(data) > _ANSWER_LIMIT:
                with contextlib.suppress(ProcessLookupError):
                    os.kill(self._pid, signal.SIGKILL)
            os.close(self._rfd)
            _, status = os.waitpid(self._pid, 0)
        if kill:
            return "error", KeyboardInterrupt(), (0.0, 0.0)
        if len(data) > _ANSWER_LIMIT:
            return "error", RuntimeError(f"BuiltDR's postcondition check's answer is over "
                                         f"{_ANSWER_LIMIT} bytes"), (0.0, 0.0)
        if len(data) <= _SPAN.size or os.waitstatus_to_exitcode(status) != 0:
            return "error", RuntimeError(
                "BuiltDR's postcondition check's worker process ended without an answer "
                f"(exit status {os.waitstatus_to_exitcode(status)})"), (0.0, 0.0)
        try:
            kind, value = pickle.loads(data[_SPAN.size:])
        except Exception as exc:  # noqa: BLE001 - e.g. an exception class that cannot be rebuilt
            return "error", RuntimeError(f"BuiltDR's postcondition check's answer cannot be "
                                         f"read back: {exc!r}"[:400]), (0.0, 0.0)
        return kind, value, _SPAN.unpack(data[:_SPAN.size])


class BuiltDRCheck:
    """``checked_build_dr`` with its postcondition check possibly in a forked worker process
    (docs/model.md §7.5), beside what does not depend on it: the search, its own checks, the
    certificate, the exact re-decision.

    The precondition is checked and D_R built in this process (a failed precondition raises
    here). ``overlap``: True runs ``builtdr_post`` in a child process forked right after the
    build (a copy of D_R's pages, shared until written: neither process writes them), False
    runs it here before returning (the serial order: with ``stop``, a failed postcondition
    raises from the constructor), None decides by ``overlap_helps``. Use it as a context
    manager around the dependent work: leaving the block waits for the child (in every case;
    an interrupt kills it), and then, in this order, re-raises an exception the check raised
    (its traceback in the child as a note), raises its first failure as ContractViolation when
    ``stop`` (the block's own result or exception discarded: the serial order would never have
    run the block), else lets the block's exception go on. ``established`` is what
    ``checked_search`` takes for pre.dr.spec (this object while the check is pending), ``runs``
    the BuiltDR checks once joined, ``settled`` the search's checks with pre.dr.spec filled in
    from them. ``seconds`` is the contract time (the precondition and the postcondition's own
    wall time, in whichever process it ran); ``overlapped`` the part of it spent beside this
    process's work (0.0 in the serial order)."""

    def __init__(self, s: Scenario, variant: Variant | str, grid: Grid, settings: Settings, *,
                 build: Builder = build_dr, stop: bool = True, overlap: bool | None = False
                 ) -> None:
        v = Variant(variant)
        self.stop = stop
        self.seconds = 0.0
        self.overlapped = 0.0
        self._pre: TripleRun | None = None
        self._post: TripleRun | None = None
        self._error: BaseException | None = None
        self._worker: _Forked | None = None
        self._span = (0.0, 0.0)
        self._joined = False
        if settings.mode is Mode.OFF:
            self.dr = build(s, v, grid)
            return
        t0 = time.perf_counter()
        pre = builtdr_pre(s, v, grid)
        pre.raise_first()
        self.seconds = time.perf_counter() - t0
        self.dr = dr = build(s, v, grid)
        self._pre = pre
        if overlap or (overlap is None and overlap_helps(dr)):
            self._worker = _Forked(functools.partial(builtdr_post, s, v, grid, dr, settings))
        else:
            t0 = time.perf_counter()
            try:
                self._post = builtdr_post(s, v, grid, dr, settings)
            finally:
                self._span = (t0, time.perf_counter())
            self.join()

    @property
    def pending(self) -> bool:
        """The postcondition check is in its worker process, not yet joined."""
        return self._worker is not None

    def join(self, *, kill: bool = False) -> tuple[TripleRun, ...]:
        """Wait for the check (if in a worker; ``kill`` ends it instead); raise its exception,
        or with ``stop`` its first failure; the BuiltDR checks run (none with contracts off).
        Idempotent."""
        if not self._joined:
            if self._worker is not None:
                waited = time.perf_counter()
                worker, self._worker = self._worker, None
                kind, value, self._span = worker.answer(kill=kill)
                if kind == "value":
                    self._post = value
                else:
                    self._error = value
                self.overlapped = max(0.0, min(self._span[1], waited) - self._span[0])
            self.seconds += self._span[1] - self._span[0]
            self._joined = True
        if self._error is not None:
            raise self._error
        if self._pre is None:
            return ()
        assert self._post is not None
        if self.stop:
            self._post.raise_first()
        return (self._pre, self._post)

    @property
    def established(self) -> TripleRun | BuiltDRCheck | None:
        """For ``checked_search``: the postcondition's run, or this object while pending."""
        return self if self.pending else self._post

    @property
    def runs(self) -> tuple[TripleRun, ...]:
        """The BuiltDR checks (joined: see ``join``)."""
        return self.join()

    def settled(self, search_runs: tuple[TripleRun, ...]) -> tuple[TripleRun, ...]:
        """``checked_search``'s runs with pre.dr.spec taken from this check (joined), as
        ``search_pre`` would have made it given the check's run."""
        if not search_runs:
            return search_runs
        pre, post = search_runs[0], (self.join()[1:] or (None,))[0]
        spec = _run(pre.triple, "pre", [_dr_spec_item(post)])
        return (TripleRun(pre.triple, pre.checks[:-1] + spec.checks,
                          tuple(f for f in pre.failures if f.condition != "pre.dr.spec")
                          + spec.failures), *search_runs[1:])

    def __enter__(self) -> BuiltDRCheck:
        return self

    def __exit__(self, kind: type[BaseException] | None, exc: BaseException | None,
                 tb: TracebackType | None) -> None:
        if exc is not None and not isinstance(exc, Exception):
            with contextlib.suppress(BaseException):    # an interrupt or an exit goes first
                self.join(kill=True)
            return
        self.join()      # the check's exception, or its failure with ``stop``, goes first


def checked_search(s: Scenario, variant: Variant | str, grid: Grid, dr: DR,
                   settings: Settings, *,
                   established: TripleRun | BuiltDRCheck | None = None,
                   search: Searcher = search_opt_path, stop: bool = True
                   ) -> tuple[SearchResult, tuple[TripleRun, ...]]:
    """``search(dr, start, goal)`` under Theorem 2/4: (the result, the checks run).

    ``established`` is the BuiltDR postcondition check that discharges pre.dr.spec. In sampled
    mode, Theorem 1/3's cell condition is also checked at every cell the found path occupies.
    While that check is still running (a pending ``BuiltDRCheck``), pre.dr.spec is left
    unchecked here and filled in by ``BuiltDRCheck.settled`` once it is joined (a failure of
    it, with ``stop``, is raised by the join).
    """
    v = Variant(variant)
    start, goal = s.right.start_cell, s.right.goal_cell
    if settings.mode is Mode.OFF:
        return search(dr, start, goal), ()
    pending = isinstance(established, BuiltDRCheck)
    pre = search_pre(v, grid, dr, start, goal,
                     None if isinstance(established, BuiltDRCheck) else established)
    # A D_R that fails BuiltDR's postcondition is already a recorded violation; without ``stop``
    # the search still runs on it (any 0/1 array of the right shape is a valid input).
    (pre if stop and not pending else _without(pre, "pre.dr.spec")).raise_first()
    result = search(dr, start, goal)
    runs = [pre, search_post(v, dr, start, goal, result, settings)]
    if settings.mode is Mode.SAMPLED and result.status is SearchStatus.FOUND:
        runs.append(builtdr_path_cells(s, v, grid, dr, result.path))
    if stop:
        for r in runs[1:]:
            r.raise_first()
    return result, tuple(runs)


# --- the record in plan.json ------------------------------------------------------------------


def violation_json(v: ContractViolation) -> dict[str, Any]:
    """A violation as plan.json records it: triple, condition, and its values.

    ``condition`` joins the id and the message (kept as it was); ``condition_id`` (``post.costs``,
    ``certificate.contact``) and ``message`` are the two apart."""
    return {"triple": v.triple, "condition": v.condition, "condition_id": v.condition_id,
            "message": v.message, "values": jsonable(v.values)}


def contracts_json(settings: Settings, runs: Sequence[TripleRun],
                   certificate: ContractViolation | None = None,
                   certificate_checked: bool = False) -> dict[str, Any]:
    """plan.json's ``contracts``: {mode, checked, seed, sample, violations, triples, ...}.

    ``checked`` counts the items examined (cells, path steps, conditions). The certificate is
    not a triple; ``certificate_enforced`` says whether a contact counted as a violation (since
    a contact is one in every mode, plan() always passes True; the key stays for readers).
    """
    sampled = settings.mode is Mode.SAMPLED
    violations = [violation_json(v) for r in runs for v in r.violations()]
    if certificate is not None:
        violations.append(violation_json(certificate))
    triples: dict[str, dict[str, Any]] = {}
    for r in runs:
        t = triples.setdefault(r.triple.name, {
            "name": r.triple.name, "title": r.triple.title, "reference": r.triple.reference,
            "statement": str(r.triple), "checks": []})
        t["checks"] += [{"part": c.part, "condition": c.condition, "scope": c.scope,
                         "count": c.count, "ok": c.ok, "coverage": c.coverage} for c in r.checks]
    return {
        "mode": settings.mode.value,
        "seed": settings.seed if sampled else None,
        "sample": settings.sample if sampled else None,
        "checked": sum(r.checked for r in runs),
        "violations": violations,
        "triples": list(triples.values()),
        "certificate_enforced": certificate_checked,
    }
