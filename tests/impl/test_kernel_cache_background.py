"""A cold cache does not make the run wait (docs/model.md §7.5): "fast" gives the numpy kernels,
a detached low-priority process compiles the cold groups (one at a time per machine: the lock),
one line on stderr says so with a count, and load_fast_kernels compiles nothing. A warm cache,
or CFMPA_KERNEL_COMPILE=wait, keeps the fast kernels. Seeded faults: a run that waits for the
compile, a second compile started while one holds the lock."""

from __future__ import annotations

import fcntl

import pytest

from cfmpa.impl import _kernel_cache as kc
from cfmpa.impl import _kernels, build_dr_fast, search_opt_path_fast
from cfmpa.impl._numpy_builtdr import build_dr_numpy
from cfmpa.impl._numpy_search import search_opt_path_numpy


@pytest.fixture
def cold(monkeypatch, tmp_path):
    """Every group cold, stamps and lock in tmp_path; compiles and starts recorded, not run."""
    calls: dict[str, list] = {"started": [], "compiled": []}
    monkeypatch.setattr(kc, "_stamp_path", lambda name: tmp_path / f"cfmpa-{name}.stamp")
    monkeypatch.setattr(kc, "_cache_dir", lambda mod: tmp_path)
    monkeypatch.setattr(kc, "_key", lambda name: f"key-{name}")
    monkeypatch.setenv("NUMBA_CACHE_DIR", str(tmp_path))       # the marker and its lock
    monkeypatch.setattr(kc, "_READY", [False])
    monkeypatch.setattr(kc, "_NUMPY", [])
    monkeypatch.setattr(kc, "_LOADED", [])
    monkeypatch.delenv(kc.COMPILE_ENV, raising=False)

    class Popen:
        def __init__(self, argv, **kw):
            calls["started"].append((argv, kw))
    monkeypatch.setattr(kc.subprocess, "Popen", Popen)
    monkeypatch.setattr(kc, "_compile_in_processes",
                        lambda names: calls["compiled"].append(list(names)) or [])
    monkeypatch.setattr(kc, "_warm", lambda name: calls["compiled"].append([name]))
    return calls, tmp_path


def test_a_cold_cache_gives_the_numpy_kernels_and_starts_a_detached_compile(cold, capsys):
    calls, _ = cold
    assert _kernels.kernels("fast") == (build_dr_numpy, search_opt_path_numpy)
    err = capsys.readouterr().err.splitlines()
    assert err == ["cfmpa: fast kernels not compiled for this machine yet: 3 groups compiling "
                   "in the background; this run uses the numpy kernels (bit-identical, slower)"]
    [(argv, kw)] = calls["started"]
    assert argv[-1].endswith("k._background()") and kw["start_new_session"] is True
    assert argv[-1].index("os.nice(19)") < argv[-1].index("import cfmpa")   # before its imports
    assert kc.load_fast_kernels() == 0.0 and calls["compiled"] == []   # never waits
    assert _kernels.kernels("fast") == (build_dr_numpy, search_opt_path_numpy)
    assert capsys.readouterr().err == "" and len(calls["started"]) == 1   # decided once
    assert _kernels.kernel_name(build_dr_numpy, search_opt_path_numpy) == "numpy"


def test_the_background_process_compiles_the_cold_groups_and_writes_their_stamps(cold):
    calls, _ = cold
    kc._background()
    assert calls["compiled"] == [list(kc.GROUPS)]
    assert kc.cold_groups() == [] and kc.wait_compiled(timeout=0.0)


def test_a_warm_cache_keeps_the_fast_kernels(cold, capsys):
    calls, _ = cold
    for name in kc.GROUPS:
        kc._write_stamp(name)
    kc._write_marker()                   # as the compile that warmed it leaves it
    assert _kernels.kernels("fast") == (build_dr_fast, search_opt_path_fast)
    assert capsys.readouterr().err == "" and calls["started"] == []


def test_wait_keeps_the_old_path(cold, monkeypatch, capsys):
    calls, _ = cold
    monkeypatch.setenv(kc.COMPILE_ENV, "wait")
    assert _kernels.kernels("fast") == (build_dr_fast, search_opt_path_fast)
    assert calls["started"] == [] and capsys.readouterr().err == ""
    kc.load_fast_kernels()        # compiles now, in processes, and waits (warm-ups recorded)
    assert calls["compiled"][0] == list(kc.GROUPS)
    assert "compiling 3 groups" in capsys.readouterr().err


def test_seeded_fault_a_run_that_waits_is_caught(cold, monkeypatch):
    # A build of this module that compiled in the foreground on a cold cache (the old path)
    # would call the compile before returning: the first test's assertion sees it.
    calls, _ = cold
    monkeypatch.setattr(kc, "numpy_while_cold", lambda: (kc.ensure_compiled(), False)[1])
    _kernels.kernels("fast")
    assert calls["compiled"] != []


def test_no_second_compile_while_one_holds_the_lock(cold, capsys):
    calls, folder = cold
    kc._write_marker()          # compiled here before: the stamps (now cold) are checked
    with open(folder / "cfmpa-kernels.lock", "a") as fh:
        fcntl.flock(fh, fcntl.LOCK_EX)
        assert kc.numpy_while_cold()
        fcntl.flock(fh, fcntl.LOCK_UN)
    assert calls["started"] == []
    assert "3 groups being compiled in the background" in capsys.readouterr().err
    assert kc._lock_free(folder)


def test_wait_compiled_gives_up_at_its_timeout(cold):
    assert kc.wait_compiled(timeout=0.0) is False


def test_the_background_compile_marks_the_machine_and_a_marked_one_checks_its_stamps(cold, capsys):
    calls, folder = cold
    kc._background()
    marker = kc._marker()
    assert marker is not None and marker[0] == folder / kc._MARKER
    assert marker[0].read_text() == marker[1]
    capsys.readouterr()                  # the compile's own lines (the detached one's: nowhere)
    # Marked and warm: the fast kernels, nothing started.
    assert _kernels.kernels("fast") == (build_dr_fast, search_opt_path_fast)
    assert calls["started"] == [] and capsys.readouterr().err == ""


def test_an_unmarked_machine_is_cold_without_reading_the_stamps(cold, monkeypatch, capsys):
    # Warm stamps, no marker (a cache warmed before the marker existed): one numpy run, and
    # the background process, finding nothing cold, marks the machine for the next.
    calls, folder = cold
    for name in kc.GROUPS:
        kc._write_stamp(name)
    (folder / kc._MARKER).write_text("a marker of other kernel sources")

    def numba_needed(*args):    # what the stamps' check would call: it imports numba
        raise AssertionError("the stamps were read")
    with monkeypatch.context() as m:
        m.setattr(kc, "cold_groups", numba_needed)
        m.setattr(kc, "_module", numba_needed)
        assert kc.numpy_while_cold()
    assert len(calls["started"]) == 1 and "3 groups compiling" in capsys.readouterr().err
    kc._background()
    marker = kc._marker()
    assert calls["compiled"] == [] and marker is not None
    assert marker[0].read_text() == marker[1]


def test_an_unmarked_run_starts_no_compile_while_one_holds_the_start_lock(cold, capsys):
    calls, folder = cold
    with open(folder / kc._START_LOCK, "a") as fh:
        fcntl.flock(fh, fcntl.LOCK_EX)
        assert kc.numpy_while_cold()
        fcntl.flock(fh, fcntl.LOCK_UN)
    assert calls["started"] == []
    assert "3 groups being compiled in the background" in capsys.readouterr().err


def test_a_stale_marker_is_no_marker(cold, monkeypatch):
    calls, folder = cold
    for name in kc.GROUPS:
        kc._write_stamp(name)
    kc._write_marker()
    # A kernel source edited since (its size and time in the fingerprint): cold again.
    edited = folder / "_fast_search.py"
    edited.write_text("# another source\n")
    real = kc._source
    monkeypatch.setattr(kc, "_source", lambda name: edited if name == "search" else real(name))
    assert kc.numpy_while_cold() and len(calls["started"]) == 1


def test_an_unwritable_marker_folder_means_the_stamps_are_checked(cold, monkeypatch):
    # No marker can appear there: read the stamps (warm here), rather than cold for ever.
    calls, folder = cold
    for name in kc.GROUPS:
        kc._write_stamp(name)
    with monkeypatch.context() as m:
        m.setattr(kc.os, "access", lambda path, mode: False)
        assert kc._marker() is None
        assert not kc.numpy_while_cold() and calls["started"] == []
    # A file where the folder should be, likewise.
    monkeypatch.setenv("NUMBA_CACHE_DIR", str(folder / "a-file" / "numba"))
    (folder / "a-file").write_text("")
    assert kc._marker() is None


def test_a_run_on_the_numpy_kernels_imports_no_numba():
    # The planner's modules import the fast kernels (and numba) only when they are called.
    import subprocess
    import sys
    code = ("import sys, cfmpa.runs._plan, cfmpa.runs._contracts, cfmpa.impl._threads\n"
            "from cfmpa.impl._numpy_builtdr import build_dr_numpy\n"
            "print('numba' in sys.modules)")
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                         timeout=120)
    assert out.stdout.strip() == "False", out.stderr[-2000:]


PROBE = """
import sys
from cfmpa.impl import kernels, _kernel_cache as kc
build, search = kernels("fast")
print(build.__name__)
if sys.argv[1] == "wait":
    print(kc.wait_compiled(900))
"""


@pytest.mark.slow
def test_a_fresh_cache_runs_numpy_then_the_background_compile_makes_the_next_fast(tmp_path):
    import os
    import subprocess
    import sys
    from pathlib import Path

    env = dict(os.environ, NUMBA_CACHE_DIR=str(tmp_path / "numba"))
    env.pop(kc.COMPILE_ENV, None)
    root = Path(__file__).resolve().parents[2]

    def run(arg):
        return subprocess.run([sys.executable, "-c", PROBE, arg], cwd=root, env=env,
                              capture_output=True, text=True, timeout=900)
    first = run("wait")
    assert first.stdout.split() == ["build_dr_numpy", "True"], first.stderr[-2000:]
    assert "3 groups compiling in the background" in first.stderr
    later = run("-")
    assert later.stdout.split() == ["build_dr_fast"] and later.stderr == ""
