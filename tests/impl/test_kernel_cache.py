"""The fast kernels' first run (docs/model.md §7.5): while numba's cache is cold, one line on
stderr says what compiles (a count), the groups compile in processes of their own, and their
stamps make the next process silent; a stale stamp (another source, or the same source saved
again) compiles that group again. The real compile, in a fresh NUMBA_CACHE_DIR, is the slow test
at the end (it also sees that the process compiles nothing itself). Seeded faults: a stamp blind
to the source, a compile process that fails."""

from __future__ import annotations

import os
import subprocess
import sys
from pathlib import Path

import pytest

from cfmpa.impl import _kernel_cache as kc

ROOT = Path(__file__).resolve().parents[2]


@pytest.fixture
def fake(monkeypatch, tmp_path):
    """The module with its stamps in tmp_path and its compiles recorded, not run."""
    calls: dict[str, list] = {"processes": [], "here": []}
    keys = {name: f"key-{name}" for name in kc.GROUPS}
    monkeypatch.setattr(kc, "_stamp_path", lambda name: tmp_path / f"cfmpa-{name}.stamp")
    monkeypatch.setattr(kc, "_cache_dir", lambda mod: tmp_path)
    monkeypatch.setattr(kc, "_key", lambda name: keys[name])
    monkeypatch.setattr(kc, "_READY", [False])

    def processes(names):
        calls["processes"].append(list(names))
        return []
    monkeypatch.setattr(kc, "_compile_in_processes", processes)
    monkeypatch.setattr(kc, "_warm", lambda name: calls["here"].append(name))
    return calls, keys


def test_a_cold_cache_says_so_once_with_a_count_and_compiles_every_group(fake, capsys):
    calls, _ = fake
    kc.ensure_compiled()
    err = capsys.readouterr().err.splitlines()
    assert err[0] == ("cfmpa: compiling 3 groups of fast kernels for this machine "
                      "(first run only)...")
    assert err[1].startswith("cfmpa: fast kernels compiled in ") and len(err) == 2
    assert calls["processes"] == [list(kc.GROUPS)] and calls["here"] == []
    kc.ensure_compiled()                     # the same process: nothing more
    assert capsys.readouterr().err == "" and len(calls["processes"]) == 1


def test_a_warm_cache_prints_nothing(fake, capsys):
    calls, _ = fake
    kc.ensure_compiled()
    capsys.readouterr()
    kc._READY[0] = False                     # as a new process with the same cache
    kc.ensure_compiled()
    assert capsys.readouterr().err == "" and len(calls["processes"]) == 1
    assert kc.cold_groups() == []


def test_a_stale_stamp_compiles_that_group_alone(fake, capsys):
    calls, keys = fake
    kc.ensure_compiled()
    capsys.readouterr()
    keys["search"] = "key-search-after-an-edit"
    kc._READY[0] = False
    kc.ensure_compiled()
    assert capsys.readouterr().err.startswith("cfmpa: compiling 1 group of fast kernels")
    assert calls["processes"][-1] == ["search"]


def test_seeded_fault_a_failed_compile_process_is_compiled_here(fake, monkeypatch, capsys):
    calls, _ = fake
    monkeypatch.setattr(kc, "_compile_in_processes", lambda names: ["builtdr"])
    kc.ensure_compiled()
    assert calls["here"] == ["builtdr"]
    assert kc.cold_groups() == []            # its stamp written once compiled here


def test_the_stamp_follows_the_source_its_size_and_its_time(monkeypatch, tmp_path):
    source = tmp_path / "_fast_search.py"
    source.write_text("x = 1\n")

    monkeypatch.setattr(kc, "_source", lambda name: source)
    first = kc._key("search")
    source.write_text("x = 2\n")                       # another source, the same size
    os.utime(source, ns=(0, 0))
    second = kc._key("search")
    os.utime(source, ns=(10**9, 10**9))                # saved again: numba recompiles it too
    third = kc._key("search")
    assert len({first, second, third}) == 3
    assert kc._key("search") == third                  # and nothing else moves it


def _same_size_and_time_told_apart(monkeypatch, tmp_path) -> bool:
    """Whether two sources of one size saved at one instant get different keys."""
    source = tmp_path / "_fast_search.py"

    monkeypatch.setattr(kc, "_source", lambda name: source)
    keys = []
    for text in ("x = 1\n", "x = 2\n"):
        source.write_text(text)
        os.utime(source, ns=(7, 7))
        keys.append(kc._key("search"))
    return keys[0] != keys[1]


def test_the_stamp_reads_the_source_itself(monkeypatch, tmp_path):
    assert _same_size_and_time_told_apart(monkeypatch, tmp_path)


def test_seeded_fault_a_stamp_blind_to_the_source_is_caught(monkeypatch, tmp_path):
    monkeypatch.setattr(Path, "read_bytes", lambda self: b"")     # the source not hashed
    assert not _same_size_and_time_told_apart(monkeypatch, tmp_path)


def test_every_group_names_a_kernel_module_with_a_cache():
    for name in kc.GROUPS:
        path = kc._stamp_path(name)
        assert path is not None and path.name == f"cfmpa-{name}.stamp"
    with pytest.raises(ValueError, match="no kernel group"):
        kc._warm("nonesuch")


PROBE = """
import sys, time
from cfmpa.spec import parse_scenario, make_grid, Variant
from cfmpa.impl import build_dr_fast, search_opt_path_fast
import cfmpa.impl._fast_builtdr as B, cfmpa.impl._fast_regions as R, cfmpa.impl._fast_search as S
doc = {"name": "probe", "purpose": "first run", "dt": 0.4,
       "left": {"links": [0.35, 0.30], "width": 0.06, "omega": [1.0, 1.0], "base": [0.0, 0.0],
                "start": [0.3, 0.8], "goal": [1.6, 2.2],
                "tool": {"polygon": [[0.0, -0.03], [0.08, -0.03], [0.08, 0.03], [0.0, 0.03]]}},
       "right": {"links": [0.35, 0.30], "width": 0.06, "omega": [1.0, 1.0], "base": [0.6, 0.0],
                 "limits": [[0.0, 6.283185307179586], [0.0, 6.283185307179586]],
                 "start_cell": [0, 4], "goal_cell": [7, 4],
                 "tool": {"polygon": [[-0.02, -0.04], [0.12, -0.025], [0.12, 0.025],
                                      [-0.02, 0.04]]}}}
s = parse_scenario(doc, check_budget=False)
dr = build_dr_fast(s, Variant.TIGHT, make_grid(s))
search_opt_path_fast(dr, s.right.start_cell, s.right.goal_cell, with_witness=True)
misses = sum(sum(d.stats.cache_misses.values()) for m in (B, R, S)
             for d in vars(m).values() if hasattr(d, "stats"))
print(misses)
"""


@pytest.mark.slow
def test_first_run_says_so_and_the_next_is_silent(tmp_path):
    """A fresh NUMBA_CACHE_DIR: the first process prints the line and the done line and then
    compiles nothing itself (every kernel it calls, with a tool on each wrist too, comes from the
    cache the compile processes wrote); the second prints nothing."""
    env = dict(os.environ, NUMBA_CACHE_DIR=str(tmp_path / "numba"))
    runs = [subprocess.run([sys.executable, "-c", PROBE], cwd=ROOT, env=env,
                           capture_output=True, text=True, timeout=600) for _ in range(2)]
    for run in runs:
        assert run.returncode == 0, run.stderr[-2000:]
        assert run.stdout.split() == ["0"]                 # no kernel compiled in the process
    first = runs[0].stderr.splitlines()
    assert first[0] == ("cfmpa: compiling 3 groups of fast kernels for this machine "
                        "(first run only)...")
    assert first[1].startswith("cfmpa: fast kernels compiled in ")
    assert "compiling" not in runs[1].stderr
