"""The campaign of `cfmpa compare`: the paper's experimental claim (Section IV.B), computed on
random workcells; ``cfmpa.report`` formats it (its table, compare.json and the report section).

Each workcell i of a campaign is drawn from ``numpy.random.default_rng([seed, i])`` alone, so a
campaign is reproducible from its seed and dt, a smaller campaign is a prefix of a larger one,
and a workcell's result does not depend on which worker plans it, in which order, or how often.
A workcell: the principal's base at the origin; the subordinate's base at a distance of 0.35 to
0.85 times the sum of both reaches (so the reach disks always overlap), within 0.3 rad of the +x
axis; links 0.25-0.40 m, widths 0.04-0.07 m, joint speeds 0.8-1.5 rad/s; the principal turns
each joint by 0.4-1.8 rad either way; the subordinate's joint 1 spans [0, 2 pi], joint 2
[-2.6, 2.6]; dt = COMPARE_DT by default (a coarse grid, so a campaign of 100 takes seconds;
``--dt`` sets another). The subordinate's start (goal) cell is drawn uniformly among cells whose
pose is apart from the principal's start (goal) pose, as a real task would be; after MAX_DRAWS
failed draws the last one is kept (and counted). Every workcell is planned under the three
variants; every found path gets the continuous-time certificate.

Engine and store (docs/model.md §13): one task per workcell on ``cfmpa.runs.Engine`` (in this
process, a local Dask cluster, or a scheduler's); with an output folder every finished workcell
is appended to DIR/compare.jsonl (``_store``: a header with n, seed and dt, then one line per
workcell, fsynced) as its task completes, and a rerun of the same settings reuses every
recorded workcell and computes only the rest (and those whose task raised). compare.json is
built from the records alone, sorted by index, so it is byte-identical whatever the workers,
the order, the retries or the interruptions, apart from its ``timings_s`` key. On a running
cluster the scheduler is reached (and has a worker) before the store is opened, so a refused
``--scheduler`` leaves no compare.jsonl; a cluster left without workers for ``worker_timeout``
seconds stops the run (``WorkersLost``, exit 2) with the command that resumes it, the records
made so far kept.
"""

from __future__ import annotations

import contextlib
import json
import math
import os
import shlex
import sys
import time
from collections.abc import Callable, Mapping
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, TextIO

import numpy as np

from ..errors import CfmpaError, InputError, WorkersLost
from ..spec import (
    EPS,
    Scenario,
    SearchStatus,
    Variant,
    certify,
    make_grid,
    parse_scenario,
    pose_distance,
)
from ._engine import (
    CONNECT_TIMEOUT_S,
    WORKER_TIMEOUT_S,
    Engine,
    ProgressBar,
    TaskLost,
    error_message,
)
from ._limits import MAX_DT, MAX_WORKCELLS
from ._store import Store, open_store, read_store

__all__ = ["COMPARE_DT", "CONTACT_NOTE", "KERNEL", "MAX_DRAWS", "MAX_DT", "MAX_WORKCELLS",
           "STORE_NAME",
           "Campaign", "CaseError", "CaseResult", "VariantOutcome", "load_campaign",
           "plan_workcell", "random_workcell", "run_campaign", "workcell_task"]

#: Time step of campaign workcells (s): grids of about 10-30 layers of 60-80 x 50-65 cells.
COMPARE_DT = 0.1
#: Draws of a start or goal cell before the campaign keeps a pose in contact (then counted).
MAX_DRAWS = 200
#: Appended to a workcell's purpose when a pose was kept in contact after MAX_DRAWS draws.
CONTACT_NOTE = "(a pose drawn in contact)"
#: The store of finished workcells in the output folder, and its format.
STORE_NAME = "compare.jsonl"
STORE_FORMAT, STORE_VERSION = "cfmpa-compare-store", 1

#: The kernels every workcell is planned with (recorded in compare.json).
KERNEL = "build_dr_fast + search_opt_path_fast"
_TWO_PI = 6.283185307179586


@dataclass(frozen=True)
class VariantOutcome:
    """One variant's plan of one workcell: status, costs, free fraction, certificate, times."""

    variant: Variant
    status: str
    reason: str | None
    J1: int | None
    J2: int | None
    free_fraction: float
    certified_clear: bool | None   # None: no path to certify
    min_clearance_m: float | None
    seconds: float
    path: tuple[tuple[int, int], ...] = ()


@dataclass(frozen=True)
class CaseResult:
    """One random workcell planned under all three variants."""

    index: int
    shape: tuple[int, int, int]
    poses_apart: bool              # start and goal poses drawn apart (not after MAX_DRAWS)
    outcomes: tuple[VariantOutcome, ...]

    def outcome(self, v: Variant) -> VariantOutcome:
        return next(o for o in self.outcomes if o.variant is v)

    def found(self, v: Variant) -> bool:
        return self.outcome(v).status == SearchStatus.FOUND.value


@dataclass(frozen=True)
class CaseError:
    """A workcell whose task raised (or was lost): its index and the message, kept, not dropped."""

    index: int
    message: str


@dataclass(frozen=True)
class Campaign:
    """A seeded campaign: its planned cases, the workcells that raised, the kernel that built
    D_R; ``reused`` workcells came from the store; ``timings_s`` are this run's times (whole
    run, engine start, tasks)."""

    n: int
    seed: int
    dt: float
    kernel: str
    cases: tuple[CaseResult, ...]
    errors: tuple[CaseError, ...] = ()
    reused: int = 0
    timings_s: Mapping[str, float] = field(default_factory=dict)


def random_workcell(seed: int, index: int, dt: float = COMPARE_DT) -> Scenario:
    """Workcell ``index`` of the campaign with ``seed`` at time step ``dt`` (see the module
    docstring); its purpose ends with CONTACT_NOTE when a start or goal pose had to be kept in
    contact."""
    return _workcell(seed, index, dt)[0]


def _workcell(seed: int, index: int, dt: float = COMPARE_DT) -> tuple[Scenario, bool]:
    """The workcell, and whether its start and goal poses were drawn apart from the principal."""
    rng = np.random.default_rng([seed, index])

    def arm() -> dict[str, Any]:
        return {"links": [_r(rng.uniform(0.25, 0.40)), _r(rng.uniform(0.25, 0.40))],
                "width": _r(rng.uniform(0.04, 0.07)),
                "omega": [_r(rng.uniform(0.8, 1.5)), _r(rng.uniform(0.8, 1.5))]}

    left, right = arm(), arm()
    start = [_r(rng.uniform(-math.pi, math.pi)), _r(rng.uniform(-2.4, 2.4))]
    goal = [_r(a + rng.choice([-1.0, 1.0]) * rng.uniform(0.4, 1.8)) for a in start]
    reach = sum(left["links"]) + sum(right["links"])
    d, phi = rng.uniform(0.35, 0.85) * reach, rng.uniform(-0.3, 0.3)
    doc: dict[str, Any] = {
        "name": f"random-{seed}-{index}",
        "purpose": f"cfmpa compare workcell {index} of seed {seed}",
        "dt": dt,
        "left": {"base": [0.0, 0.0], **left, "start": start, "goal": goal},
        "right": {"base": [_r(d * math.cos(phi)), _r(d * math.sin(phi))], **right,
                  "limits": [[0.0, _TWO_PI], [-2.6, 2.6]],
                  "start_cell": [0, 0], "goal_cell": [0, 0]},
    }
    s = parse_scenario(doc)
    g = make_grid(s)
    apart = True
    for key, pose in (("start_cell", start), ("goal_cell", goal)):
        cell, ok = _draw_cell(rng, s, g, pose)
        apart &= ok
        doc["right"][key] = list(cell)
    if not apart:
        doc["purpose"] += f" {CONTACT_NOTE}"
    return parse_scenario(doc), apart


def plan_workcell(seed: int, index: int, dt: float = COMPARE_DT) -> CaseResult:
    """Workcell ``index`` planned under original, modified and tight, each path certified."""
    build, search = _kernels()
    s, apart = _workcell(seed, index, dt)
    g = make_grid(s)
    outcomes = []
    certified: dict[tuple[tuple[int, int], ...], Any] = {}    # variants often plan one path
    for v in Variant:
        t0 = time.perf_counter()
        dr = build(s, v, g)
        r = search(dr, s.right.start_cell, s.right.goal_cell)
        cert = None
        if r.status is SearchStatus.FOUND:
            key = tuple((int(i), int(j)) for i, j in r.path)
            if key not in certified:
                certified[key] = certify(s, g, r.path)
            cert = certified[key]
        outcomes.append(VariantOutcome(
            variant=v, status=r.status.value, reason=r.reason, J1=r.J1, J2=r.J2,
            free_fraction=1.0 - float(dr.mean()),
            certified_clear=None if cert is None else cert.clear,
            min_clearance_m=None if cert is None else cert.min_clearance_m,
            seconds=time.perf_counter() - t0, path=r.path))
    return CaseResult(index=index, shape=g.shape, poses_apart=apart, outcomes=tuple(outcomes))


def workcell_task(seed: int, index: int, dt: float, fault: str | None = None) -> dict[str, Any]:
    """The task of one workcell (run on a worker): its store record, or an error record with the
    message if planning raised. ``fault`` is for tests only: ``"raise"`` raises in the task,
    ``"exit-once:PATH"`` kills the worker process the first time (PATH marks that it did),
    ``"sleep:S"`` delays the task by S seconds."""
    t0 = time.perf_counter()
    try:
        if fault is not None:
            _inject(fault, index)
        return _record(plan_workcell(seed, index, dt))
    except Exception as exc:
        return {"index": index, "status": "error", "error": error_message(exc),
                "seconds": time.perf_counter() - t0}


def _inject(fault: str, index: int) -> None:
    if fault.startswith("sleep:"):      # a slow task (the result is the same)
        time.sleep(float(fault.removeprefix("sleep:")))
        return
    if fault == "raise":
        raise RuntimeError(f"fault injected into workcell {index}")
    if fault.startswith("exit-once:"):
        mark = Path(fault.removeprefix("exit-once:"))
        if not mark.exists():
            mark.write_text("killed once\n")
            os._exit(70)   # the worker dies mid-task: the scheduler must run it again
        return
    raise ValueError(f"unknown fault {fault!r}")


def run_campaign(n: int = 100, seed: int = 0, dt: float = COMPARE_DT, *, workers: int = 0,
                 scheduler: str | None = None, out: str | os.PathLike[str] | None = None,
                 connect_timeout: float = CONNECT_TIMEOUT_S,
                 worker_timeout: float = WORKER_TIMEOUT_S, progress: bool | None = None,
                 stream: TextIO | None = None, _faults: Mapping[int, str] | None = None,
                 _after_record: Callable[[int], None] | None = None) -> Campaign:
    """Plan ``n`` random workcells under original, modified and tight.

    ``workers`` 0 plans them in this process; K >= 1 on a local Dask cluster of K processes;
    ``scheduler`` on a running cluster. With ``out``, every finished workcell is appended to
    ``out``/compare.jsonl and the workcells already recorded there (by a run with the same n,
    seed and dt) are reused, not planned again; records of a workcell whose task raised are
    planned again. With ``scheduler``, the scheduler is reached before the store is opened (a
    refused one: InputError, nothing written); a cluster without a worker for
    ``worker_timeout`` seconds raises WorkersLost naming the command that resumes. ``stream``
    gets the engine's and the store's messages (None: silent); the progress bar is on stderr
    when it is a terminal (``progress`` forces it on or off).
    ``_faults`` (index -> fault of ``workcell_task``; by default the JSON object in the
    environment variable CFMPA_TEST_FAULTS, for tests of the command in a fresh process) and
    ``_after_record`` (called with the number of records written so far in this run) are for
    tests.
    """
    n, seed, dt = _check_settings(n, seed, dt)
    t_start = time.perf_counter()
    engine = Engine(workers, scheduler, connect_timeout=connect_timeout,
                    worker_timeout=worker_timeout, stream=stream, warm=_warm)
    _workcell(seed, 0, dt)           # a dt whose grids the budget refuses: before any work
    store: Store | None = None
    records: dict[int, dict[str, Any]] = {}
    # A running cluster is reached first: an address that refuses, a scheduler without
    # workers, workers without cfmpa are exit 2 before the store exists. (A local cluster
    # starts only when there is work: a finished campaign's rerun starts none.)
    early = _connect_first(engine)
    if early:
        engine.__enter__()
    try:
        if out is not None:
            store = open_store(Path(out) / STORE_NAME, STORE_FORMAT, STORE_VERSION,
                               {"n": n, "seed": seed, "dt": dt})
        if store is not None:
            for k, rec in enumerate(store.records):
                _check_record(rec, n, store.path, k + 2)
                records[rec["index"]] = rec          # a later line supersedes an earlier one
        reused = sum(1 for r in records.values() if r["status"] == "ok")
        todo = [i for i in range(n) if records.get(i, {}).get("status") != "ok"]
        if store is not None and stream is not None:
            retry = sum(1 for r in records.values() if r["status"] == "error")
            print(f"store     {store.path}: reused {reused} finished workcell(s), computing "
                  f"{len(todo)}" + (f" ({retry} that raised before)" if retry else "")
                  + ("; dropped a torn last line (an interrupted write)" if store.torn else ""),
                  file=stream, flush=True)
        faults = dict(_faults) if _faults is not None else _env_faults()
        written = 0

        def on_done(pos: int, result: Any) -> None:
            nonlocal written
            i = todo[pos]
            if isinstance(result, TaskLost):
                result = {"index": i, "status": "error", "seconds": 0.0,
                          "error": f"task lost (not retried further): {result.message}"}
            # The record as the store holds it (JSON), so a clean run and a resumed one build
            # compare.json from the same values.
            try:
                rec = json.loads(json.dumps(result, allow_nan=False))
            except (TypeError, ValueError) as exc:
                rec = {"index": i, "status": "error", "seconds": 0.0,
                       "error": f"result is not JSON: {error_message(exc)}"}
            if store is not None:
                store.append(rec)
            records[i] = rec
            written += 1
            if _after_record is not None:
                _after_record(written)

        if todo:
            bar = ProgressBar.for_terminal("compare", n, start=n - len(todo), progress=progress)
            with contextlib.nullcontext() if early else engine:
                engine.run(workcell_task, [(seed, i, dt, faults.get(i)) for i in todo], on_done,
                           name="workcell", progress=bar)
    except WorkersLost as exc:
        done = sum(1 for r in records.values() if r["status"] == "ok")
        command = ["cfmpa", "compare", "--n", str(n), "--seed", str(seed), "--dt", repr(dt),
                   *(["--out", str(out)] if out is not None else []), *engine.options()]
        kept = (f"{done} of {n} workcells are recorded in {store.path} and stay; resume with: "
                if store is not None else "nothing is kept without --out; run again with: ")
        raise WorkersLost(f"{exc}. {kept}{shlex.join(command)}") from None
    except KeyboardInterrupt:
        if store is not None:
            done = sum(1 for r in records.values() if r["status"] == "ok")
            print(f"interrupted: {done} of {n} workcells are recorded in {store.path}; run the "
                  f"same command again to resume", file=sys.stderr, flush=True)
        raise
    finally:
        if store is not None:
            store.close()
        engine.close()
    missing = [i for i in range(n) if i not in records]
    if missing:   # the engine reports every task; this would be a bug of cfmpa, not of input
        raise CfmpaError(f"campaign ended without a record of workcells {missing[:10]}")
    timings = {"run": time.perf_counter() - t_start, **engine.timings_s}
    return _campaign(n, seed, dt, records, reused, timings)


def load_campaign(folder: str | os.PathLike[str]) -> Campaign:
    """The campaign recorded in ``folder`` by ``cfmpa compare --out`` (its compare.jsonl), read
    only and whole: the same Campaign, so the same compare.json, as the run that wrote it.
    InputError if a workcell is missing or raised (finish it with the same command first)."""
    path = Path(folder) / STORE_NAME
    settings, lines = read_store(path, STORE_FORMAT, STORE_VERSION)
    n, seed, dt = _check_settings(settings.get("n"), settings.get("seed"), settings.get("dt"))
    records: dict[int, dict[str, Any]] = {}
    for k, rec in enumerate(lines):
        _check_record(rec, n, path, k + 2)
        records[rec["index"]] = rec
    ok = sum(1 for r in records.values() if r["status"] == "ok")
    if ok < n:
        raise InputError("--campaign", str(folder), f"holds {ok} of {n} finished workcells; "
                         f"finish it first: cfmpa compare --n {n} --seed {seed} --dt {dt:g} "
                         f"--out {folder}", source=str(path))
    return _campaign(n, seed, dt, records, ok, {})


def _campaign(n: int, seed: int, dt: float, records: Mapping[int, dict[str, Any]],
              reused: int, timings: Mapping[str, float]) -> Campaign:
    cases, errors = [], []
    for i in range(n):
        rec = records[i]
        if rec["status"] == "ok":
            cases.append(_case_of(rec))
        else:
            errors.append(CaseError(i, rec["error"]))
    return Campaign(n=n, seed=seed, dt=dt, kernel=KERNEL, cases=tuple(cases),
                    errors=tuple(errors), reused=reused, timings_s=dict(timings))


def _env_faults() -> dict[int, str]:
    """CFMPA_TEST_FAULTS: a JSON object {"index": "fault"} (tests only; absent: none)."""
    text = os.environ.get("CFMPA_TEST_FAULTS")
    if not text:
        return {}
    try:
        return {int(k): str(v) for k, v in json.loads(text).items()}
    except (ValueError, AttributeError):
        raise InputError("CFMPA_TEST_FAULTS", text, 'must be a JSON object {"index": "fault"}'
                         ) from None


def _check_settings(n: Any, seed: Any, dt: Any) -> tuple[int, int, float]:
    if isinstance(n, bool) or not isinstance(n, int) or n < 1:
        raise InputError("--n", n, "must be an integer >= 1")
    if n > MAX_WORKCELLS:
        raise InputError("--n", n, f"must be at most {MAX_WORKCELLS} (the campaign's budget)")
    if isinstance(seed, bool) or not isinstance(seed, int) or seed < 0:
        raise InputError("--seed", seed, "must be an integer >= 0")
    if (isinstance(dt, bool) or not isinstance(dt, (int, float)) or not math.isfinite(dt)
            or not 0 < dt <= MAX_DT):
        raise InputError("--dt", dt, f"must be a number of seconds in (0, {MAX_DT:g}]")
    return n, seed, float(dt)


def _record(c: CaseResult) -> dict[str, Any]:
    """A planned workcell as its store line (plain JSON values)."""
    return {"index": c.index, "status": "ok", "shape": list(c.shape), "poses_apart": c.poses_apart,
            "seconds": sum(o.seconds for o in c.outcomes),
            "outcomes": {o.variant.value: {
                "status": o.status, "reason": o.reason, "J1": o.J1, "J2": o.J2,
                "free_fraction": o.free_fraction, "certified_clear": o.certified_clear,
                "min_clearance_m": o.min_clearance_m, "seconds": o.seconds,
                "path": [list(cell) for cell in o.path]} for o in c.outcomes}}


def _case_of(rec: dict[str, Any]) -> CaseResult:
    outs = rec["outcomes"]
    return CaseResult(
        index=rec["index"], shape=(int(rec["shape"][0]), int(rec["shape"][1]),
                                   int(rec["shape"][2])),
        poses_apart=bool(rec["poses_apart"]),
        outcomes=tuple(VariantOutcome(
            variant=v, status=outs[v.value]["status"], reason=outs[v.value]["reason"],
            J1=outs[v.value]["J1"], J2=outs[v.value]["J2"],
            free_fraction=outs[v.value]["free_fraction"],
            certified_clear=outs[v.value]["certified_clear"],
            min_clearance_m=outs[v.value]["min_clearance_m"], seconds=outs[v.value]["seconds"],
            path=tuple((int(a), int(b)) for a, b in outs[v.value]["path"])) for v in Variant))


def _check_record(rec: dict[str, Any], n: int, path: str | Path, line: int) -> None:
    """A record read back from the store is one this module wrote (else an input error)."""
    i = rec.get("index")
    if isinstance(i, bool) or not isinstance(i, int) or not 0 <= i < n:
        raise InputError("index", i, f"must be a workcell index in [0, {n})", source=str(path),
                         line=line)
    try:
        if rec["status"] == "ok":
            _case_of(rec)
        elif rec["status"] == "error":
            if not isinstance(rec["error"], str):
                raise TypeError("error")
        else:
            raise ValueError(rec["status"])
    except (KeyError, TypeError, ValueError, IndexError) as exc:
        raise InputError("record", error_message(exc), "is not a workcell record of this "
                         "version (remove the store to start afresh)", source=str(path),
                         line=line) from None


def _connect_first(engine: Engine) -> bool:
    """Whether the engine starts before the store is opened: a running cluster's (reaching it
    is the check of --scheduler), not a local one's (started only when there is work)."""
    return engine.scheduler is not None


def _warm() -> None:
    """Import this module and load the compiled kernels (once per worker process)."""
    plan_workcell(0, 0, MAX_DT)


def _kernels() -> tuple[Any, Any]:
    """(build, search): the fast kernels, quiet (their output is the reference's, which their own
    tests check)."""
    from ..impl import kernels
    build, search = kernels("fast")
    return (lambda s, v, g: build(s, v, g, progress=False),
            lambda dr, a, b: search(dr, a, b, progress=False))


def _draw_cell(rng: np.random.Generator, s: Scenario, g: Any, left_pose: list[float]
               ) -> tuple[tuple[int, int], bool]:
    """A uniformly drawn cell whose pose is apart from the principal at ``left_pose``."""
    left = (left_pose[0], left_pose[1])
    cell = (0, 0)
    for _ in range(MAX_DRAWS):
        cell = (int(rng.integers(g.m)), int(rng.integers(g.n)))
        if pose_distance(s, left, g.angles(cell)) > EPS:
            return cell, True
    return cell, False


def _r(x: float) -> float:
    # Four decimals: readable workcells; the validated scenario is what is planned either way.
    return round(float(x), 4)
