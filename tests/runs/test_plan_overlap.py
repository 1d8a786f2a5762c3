"""BuiltDR's postcondition check beside the search (docs/model.md §7.5): `plan` with the check in
a forked worker process gives what the serial order gives (plan.json but for timings_s, the
violations in their order, the same ContractViolation with ``stop``); the worker's exception
surfaces in the caller; no worker is left; the serial order is kept where overlap cannot help.
Each comparison is also run against a seeded fault (the join skipped), which it must catch."""

from __future__ import annotations

import contextlib
import os
import threading
from pathlib import Path

import numpy as np
import pytest

import factory
from cfmpa.errors import ContractViolation
from cfmpa.impl import build_dr_fast, kernel_threads, set_kernel_threads
from cfmpa.runs import _contracts, _plan
from cfmpa.runs._contracts import BuiltDRCheck, Mode, Settings, TripleRun, overlap_helps
from cfmpa.runs._plan import plan, plan_json
from cfmpa.spec import Variant, load_scenario, make_grid

SCENARIOS = Path(_plan.__file__).resolve().parent.parent / "scenarios"
BUNDLED = sorted(p.stem for p in SCENARIOS.glob("*.toml"))


def _children() -> set[int]:
    """The pids of this process's children, running or unwaited (Linux: /proc)."""
    out: set[int] = set()
    for f in Path(f"/proc/{os.getpid()}/task").glob("*/children"):
        out |= {int(x) for x in f.read_text().split()}
    return out


@pytest.fixture(autouse=True)
def _before() -> None:
    """The children this process had before the test (a test run shares its process with
    others: a solver pool's workers, a background compile)."""
    _BEFORE[:] = [_children()]


_BEFORE: list[set[int]] = [set()]


def _no_children() -> bool:
    """No child process made during this test is left, running or unwaited."""
    return _children() <= _BEFORE[0]


def _doc(p) -> dict:
    doc = plan_json(p)
    doc.pop("timings_s")
    return doc


def _same(a, b) -> None:
    """The checker: the same plan.json apart from timings_s, D_R, violations (in order)."""
    assert _doc(a) == _doc(b)
    assert np.array_equal(a.dr, b.dr)
    assert [str(v) for v in a.violations] == [str(v) for v in b.violations]


@pytest.fixture(scope="module")
def default():
    return load_scenario(SCENARIOS / "default.toml")


@pytest.fixture(scope="module")
def tiny():
    return factory.scenario(right__start_cell=[2, 8], right__goal_cell=[13, 5])


def _flipped(k_frac: float = 0.5):
    """A fault builder: the fast BuiltDR with one blocked cell flipped to free."""
    def build(s, v, g):
        out = build_dr_fast(s, v, g)
        blocked = np.argwhere(out == 1)
        k, i, j = blocked[int(len(blocked) * k_frac)]
        out[k, i, j] = 0
        return out
    return build


# --- the same answer ------------------------------------------------------------------------


@pytest.mark.parametrize("variant", ["modified"])
def test_default_plan_is_the_same_with_and_without_overlap(default, variant):
    serial = plan(default, variant, contracts="full", stop=False, overlap=False)
    both = plan(default, variant, contracts="full", stop=False, overlap=True)
    _same(serial, both)
    assert "contracts_builtdr_overlapped" not in serial.timings_s
    assert 0.0 < both.timings_s["contracts_builtdr_overlapped"] <= both.timings_s[
        "contracts_builtdr"]
    for p in (serial, both):                                   # the keys in their order
        assert [k for k in p.timings_s if k != "kernel_load"][:3] == [
            "build_dr", "contracts_builtdr", "search"]
    assert _no_children()


@pytest.mark.parametrize("contracts", ["sampled", "full", "off"])
def test_tiny_plan_is_the_same_in_every_mode(tiny, contracts):
    serial = plan(tiny, "modified", contracts=contracts, overlap=False)
    both = plan(tiny, "modified", contracts=contracts, overlap=True)
    _same(serial, both)
    assert _no_children()


@pytest.mark.slow
@pytest.mark.parametrize("name", BUNDLED)
@pytest.mark.parametrize("variant", [v.value for v in Variant])
def test_every_bundled_scenario_is_the_same(name, variant):
    s = load_scenario(SCENARIOS / f"{name}.toml")
    _same(plan(s, variant, contracts="full", stop=False, overlap=False),
          plan(s, variant, contracts="full", stop=False, overlap=True))


# --- a failed postcondition ---------------------------------------------------------------


def test_a_flipped_cell_is_recorded_the_same(tiny):
    runs = [plan(tiny, "modified", contracts="full", stop=False, build=_flipped(),
                 overlap=overlap) for overlap in (False, True)]
    _same(*runs)
    ids = [v.condition_id for v in runs[1].violations]
    assert ids[:2] == ["post.cells", "pre.dr.spec"]


def test_a_flipped_cell_raises_the_same_violation(tiny):
    raised = []
    for overlap in (False, True):
        with pytest.raises(ContractViolation) as info:
            plan(tiny, "modified", contracts="full", build=_flipped(), overlap=overlap)
        raised.append(info.value)
    a, b = raised
    assert (str(a), a.triple, a.condition_id, a.values) == (str(b), b.triple, b.condition_id,
                                                           b.values)
    assert b.condition_id == "post.cells" and b.triple.startswith("Theorem 3")
    assert _no_children()


def test_the_postcondition_goes_before_what_the_search_raises(tiny):
    """With ``stop``, the serial order raises BuiltDR's violation before the search runs; under
    overlap the search runs first, and what it raises is discarded for that violation."""
    def failing_search(*_args, **_kw):
        raise ValueError("the search failed")

    for overlap in (False, True):
        with pytest.raises(ContractViolation) as info:
            plan(tiny, "modified", contracts="full", build=_flipped(), search=failing_search,
                 overlap=overlap)
        assert info.value.condition_id == "post.cells"
    # with a good D_R, the search's own exception goes on
    with pytest.raises(ValueError, match="the search failed"):
        plan(tiny, "modified", contracts="full", search=failing_search, overlap=True)
    assert _no_children()


# --- the worker's own failures ------------------------------------------------------------


def test_an_exception_in_the_worker_surfaces(tiny, monkeypatch):
    def broken(*_args):
        raise ValueError("the check broke")

    monkeypatch.setattr(_contracts, "builtdr_post", broken)
    with pytest.raises(ValueError, match="the check broke") as info:
        plan(tiny, "modified", contracts="full", overlap=True)
    assert any("worker process" in n for n in getattr(info.value, "__notes__", []))
    with pytest.raises(ValueError, match="the check broke"):        # the serial order alike
        plan(tiny, "modified", contracts="full", overlap=False)
    assert _no_children()


def test_a_worker_that_dies_or_cannot_answer_is_an_error(tiny, monkeypatch):
    monkeypatch.setattr(_contracts, "builtdr_post", lambda *_a: os._exit(3))
    with pytest.raises(RuntimeError, match=r"ended without an answer \(exit status 3\)"):
        plan(tiny, "modified", contracts="full", overlap=True)

    class Unpicklable(Exception):
        def __reduce__(self):
            raise TypeError("not this one")

    def raises(*_a):
        raise Unpicklable("odd")

    monkeypatch.setattr(_contracts, "builtdr_post", raises)
    with pytest.raises(RuntimeError, match="cannot be sent back"):
        plan(tiny, "modified", contracts="full", overlap=True)
    assert _no_children()


# --- where it runs ------------------------------------------------------------------------


def test_overlap_only_where_it_can_help(monkeypatch):
    dr = np.zeros((2, 3, 3), np.uint8)
    if len(os.sched_getaffinity(0)) < 2 or kernel_threads() < 2:
        pytest.skip("needs two CPUs")
    # A test process runs threads of its own (pytest-xdist's channel): counted as one here,
    # and then a real extra thread below.
    real_count, alone = threading.active_count, threading.active_count()
    monkeypatch.setattr(threading, "active_count", lambda: real_count() - alone + 1)
    assert overlap_helps(dr)
    assert not overlap_helps(dr.tolist())                      # not an array in memory
    before = kernel_threads()
    set_kernel_threads(1)                                      # a prove, audit or Dask worker
    try:
        assert not overlap_helps(dr)
    finally:
        set_kernel_threads(before)
    real_affinity = os.sched_getaffinity
    monkeypatch.setattr(os, "sched_getaffinity", lambda _pid: {0})
    assert not overlap_helps(dr)
    monkeypatch.setattr(os, "sched_getaffinity", real_affinity)
    gate = threading.Event()
    other = threading.Thread(target=gate.wait)
    other.start()
    try:
        assert not overlap_helps(dr)                           # a fork would copy no thread
    finally:
        gate.set()
        other.join()
    assert overlap_helps(dr)


def test_one_kernel_thread_picks_the_serial_order(tiny, monkeypatch):
    def no_fork(*_a):
        raise AssertionError("forked a worker where overlap cannot help")

    monkeypatch.setattr(_contracts, "_Forked", no_fork)
    before = kernel_threads()
    set_kernel_threads(1)
    try:
        p = plan(tiny, "modified", contracts="full")
    finally:
        set_kernel_threads(before)
    assert "contracts_builtdr_overlapped" not in p.timings_s and p.contracts["violations"] == []


# --- the seeded fault: the join skipped ----------------------------------------------------


class _NoJoin(BuiltDRCheck):
    """The fault: the record made without waiting for the worker (its answer is dropped)."""

    left: list[BuiltDRCheck] = []

    def join(self, *, kill: bool = False) -> tuple[TripleRun, ...]:
        if self.pending:
            _NoJoin.left.append(self)
            return (self._pre,) if self._pre is not None else ()
        return super().join(kill=kill)

    def settled(self, search_runs):
        return search_runs

    def __exit__(self, *exc):
        return None


def test_the_checker_catches_a_skipped_join(default, tiny, monkeypatch):
    monkeypatch.setattr(_plan, "BuiltDRCheck", _NoJoin)
    try:
        for s, build in ((tiny, build_dr_fast), (tiny, _flipped())):
            serial = plan(s, "modified", contracts="full", stop=False, build=build,
                          overlap=False)
            faulty = plan(s, "modified", contracts="full", stop=False, build=build,
                          overlap=True)
            with pytest.raises(AssertionError):
                _same(serial, faulty)
        # with stop, the violation is lost: the fault returns where the serial order raises
        assert plan(tiny, "modified", contracts="full", build=_flipped(), overlap=True)
    finally:
        for left in _NoJoin.left:                       # the fault's workers, waited for
            left.__class__ = BuiltDRCheck
            with contextlib.suppress(ContractViolation):
                left.join()
        _NoJoin.left.clear()
    assert _no_children()


def test_checked_build_dr_is_the_serial_order(tiny):
    g = make_grid(tiny)
    check = BuiltDRCheck(tiny, "modified", g, Settings(Mode.FULL), build=build_dr_fast)
    assert not check.pending and len(check.runs) == 2 and check.overlapped == 0.0
    assert check.seconds > 0.0


def test_the_bench_stage_note_counts_the_overlap_once():
    """bench/run.py's note of a plan's stages: the forked check's overlap is counted once, so
    the rest of the process is the wall time less the plan's own time (the overlap summed with
    the stages, as the note had it before, makes it -0.10 s: the fault)."""
    import importlib.util
    import sys

    root = Path(__file__).resolve().parents[2]
    if "cfmpa_bench_run" not in sys.modules:
        spec = importlib.util.spec_from_file_location("cfmpa_bench_run", root / "bench" / "run.py")
        mod = importlib.util.module_from_spec(spec)
        sys.modules["cfmpa_bench_run"] = mod      # dataclasses look their module up
        spec.loader.exec_module(mod)
    note = sys.modules["cfmpa_bench_run"].stage_note
    serial = {"build_dr": 0.1, "contracts_builtdr": 0.4, "search": 0.3}
    forked = serial | {"contracts_builtdr_overlapped": 0.3}
    assert note(serial, 1.0).endswith("(interpreter, imports, files) 0.20 s")
    assert note(forked, 1.0).endswith("(interpreter, imports, files) 0.50 s")
    # the fault, planted in a copy of the note: the overlap not taken off the stages' sum
    import inspect
    import textwrap

    text = textwrap.dedent(inspect.getsource(note))
    planted = text.replace('- 2 * float(\n        timings.get("contracts_builtdr_overlapped", 0.0))',
                           "")
    assert planted != text
    scope: dict = {"Any": object}
    exec(compile("from __future__ import annotations\n" + planted, "planted", "exec"), scope)
    assert scope["stage_note"](forked, 1.0).endswith("(interpreter, imports, files) -0.10 s")


def test_an_answer_over_the_bound_is_an_error_and_leaves_no_worker(monkeypatch):
    # The parent reads at most the bound (plus one byte) and ends the worker, which would
    # otherwise wait on a pipe nobody reads; an answer within the bound is read back whole.
    monkeypatch.setattr(_contracts, "_ANSWER_LIMIT", 1 << 12)
    kind, value, _ = _contracts._Forked(lambda: b"x" * (1 << 20)).answer()
    assert kind == "error" and "over" in str(value)
    assert _no_children()
    kind, value, (t0, t1) = _contracts._Forked(lambda: b"x" * 100).answer()
    assert (kind, value) == ("value", b"x" * 100) and t0 <= t1
    assert _no_children()
