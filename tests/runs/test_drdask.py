"""D_R built on Dask (docs/model.md §9, §13): `cfmpa dr|plan --workers K | --scheduler ADDRESS`
builds blocks of layers as tasks and writes dr.zarr byte for byte as the one-process build does
(a local cluster, a running one, a separately started `dask scheduler` + `dask worker`); a worker
that dies mid-task has its block built again; a refused scheduler, a cluster that loses its
workers, a block that keeps failing and Ctrl-C leave no dr.zarr (an earlier one stays).

The grids are small (the chunks two layers, so a build has several blocks); one separately
started scheduler + worker serves the module (the start and the worker's kernel load cost
seconds, once), an in-process cluster the test that loses its worker, and the local cluster of
`--workers 2` its own (slow) test. The seeded
faults (a chunk encoded otherwise, a flipped cell, a store built in place) show the comparisons
and the checks fail without the code they test.
"""

from __future__ import annotations

import functools
import logging
import os
import shlex
import shutil
import subprocess
import sys
import threading
import time
import tomllib
from pathlib import Path
from typing import Any

import numpy as np
import pytest

import factory
from cfmpa.cli import main
from cfmpa.errors import CfmpaError
from cfmpa.impl import build_dr_fast
from cfmpa.runs import _drdask, _drstore
from cfmpa.runs._drdask import block_dr, blocks_of, build_store
from cfmpa.runs._selftest import WORKCELLS
from cfmpa.spec import Variant, load_scenario, make_grid, parse_scenario

ROOT = Path(__file__).resolve().parents[2]
#: Seconds a guarded run may take before the test calls it hung.
LIMIT_S = 30.0


@pytest.fixture(scope="module")
def small(tmp_path_factory):
    """The small workcell's file and, per variant, the whole build and its one-process
    dr.zarr in chunks of two layers (so four chunks, the last one short)."""
    d = tmp_path_factory.mktemp("drdask")
    toml = d / "small.toml"
    toml.write_text(factory.toml(WORKCELLS["small"]))
    s = load_scenario(toml)
    g = make_grid(s)
    whole, stores = {}, {}
    for v in Variant:
        whole[v] = build_dr_fast(s, v, g, progress=False)
        path, sha = _drstore.write_zarr_atomic(d / v.value / "dr.zarr", whole[v],
                                               layers_per_chunk=2)
        stores[v] = (path, sha)
    return toml, s, whole, stores


@pytest.fixture
def two_layer_chunks(small, monkeypatch):
    """The client cuts chunks of two layers (the workers are told L with each block)."""
    _, s, _, _ = small
    g = make_grid(s)
    monkeypatch.setattr(_drstore, "CHUNK_BYTES", 2 * g.m * g.n)


def _files(root: Path) -> dict[str, bytes]:
    return {str(p.relative_to(root)): p.read_bytes() for p in sorted(root.rglob("*"))
            if p.is_file()}


def assert_same_store(got: Path, want: Path) -> None:
    """Two stores with the same files, byte for byte (zarr.json and every chunk)."""
    a, b = _files(got), _files(want)
    assert sorted(a) == sorted(b), (sorted(a), sorted(b))
    differ = [name for name in a if a[name] != b[name]]
    assert not differ, f"files that differ: {differ}"


def _leftovers(folder: Path) -> list[str]:
    """Temporary stores left in ``folder`` (.dr.zarr.*)."""
    return [p.name for p in folder.iterdir() if p.name.startswith(".dr.zarr.")] \
        if folder.exists() else []


# --- a block of layers is those layers of the whole build --------------------------------------

def _tools_heights(dt: float = 0.08) -> Any:
    doc = tomllib.loads((ROOT / "tests" / "data" / "tools-heights.toml").read_text())
    doc["dt"] = dt
    scale = 0.02 / dt
    for key in ("start_cell", "goal_cell"):
        doc["right"][key] = [int(c * scale) for c in doc["right"][key]]
    return parse_scenario(doc, check_budget=False)


@pytest.mark.parametrize("variant", list(Variant))
@pytest.mark.parametrize("workcell", ["small", "tools-heights"])
def test_a_block_of_layers_is_those_layers_of_the_whole_build(small, variant, workcell):
    s = small[1] if workcell == "small" else _tools_heights()
    g = make_grid(s)
    whole = small[2][variant] if workcell == "small" else build_dr_fast(s, variant, g,
                                                                        progress=False)
    K = g.N + 1
    # Blocks of one, of several, the last one alone (the rest layer N), and the whole.
    for k0, k1 in [(0, 1), (1, 4), (K - 2, K), (K - 1, K), (0, K), (K // 2, K - 1)]:
        got = block_dr(s, variant, g, k0, k1)
        assert got.dtype == np.uint8 and got.shape == (k1 - k0, g.m, g.n)
        assert np.array_equal(got, whole[k0:k1]), (k0, k1)


def test_blocks_are_whole_chunks_within_the_task_budget(monkeypatch):
    L, blocks = blocks_of((11, 10, 10), workers=2, layers_per_chunk=2)
    # 6 chunks, 2 workers x 2 blocks, within one chunk of each other (no worker gets more)
    assert L == 2 and blocks == [(0, 4), (4, 8), (8, 10), (10, 11)]
    assert blocks_of((11, 10, 10), workers=0, layers_per_chunk=2)[1] == [(0, 6), (6, 11)]
    # 25 chunks, 2 workers: 7, 6, 6, 6 (cut by ceil, 7, 7, 7, 4: one worker 14, the other 11)
    assert [b - a for a, b in blocks_of((250, 10, 10), 2, 10)[1]] == [70, 60, 60, 60]
    assert blocks_of((3, 10, 10), 4, 1)[1] == [(0, 1), (1, 2), (2, 3)]   # fewer chunks
    monkeypatch.setattr(_drdask, "TASK_BYTES", 200)              # one chunk a task at most
    assert blocks_of((5, 10, 10), 1, 2)[1] == [(0, 2), (2, 4), (4, 5)]
    monkeypatch.setattr(_drdask, "TASK_BYTES", 400)              # two chunks a task at most
    assert [b - a for a, b in blocks_of((19, 10, 10), 2, 2)[1]] == [4, 4, 4, 4, 2, 1]  # 3 each
    with pytest.raises(ValueError, match="chunk's first layer"):
        _drdask.dr_block_task(parse_scenario(factory.doc(), check_budget=False), "modified",
                              1, 3, 2)


# --- in this process: the engine's serial mode ------------------------------------------------

@pytest.mark.parametrize("variant", list(Variant))
def test_a_store_built_in_blocks_is_the_one_process_store_byte_for_byte(small, tmp_path,
                                                                         variant):
    _, s, whole, stores = small
    want, sha = stores[variant]
    built = build_store(s, variant, tmp_path / "dr.zarr", keep_layers=True, layers_per_chunk=2)
    assert not (tmp_path / "dr.zarr").exists()           # not in place before publish
    assert np.array_equal(np.asarray(built.layers), whole[variant])   # read in layers
    assert built.layers.blocked_cells() == int(np.count_nonzero(whole[variant]))
    assert built.publish() == tmp_path / "dr.zarr"
    assert_same_store(tmp_path / "dr.zarr", want)
    assert built.sha256 == sha == _drstore.dr_sha256_of(whole[variant])
    assert built.free_fraction == 1.0 - float(whole[variant].mean())     # the same float
    assert _leftovers(tmp_path) == []


def test_seeded_fault_a_chunk_encoded_otherwise_is_told_apart(small, tmp_path, monkeypatch):
    """zstd at another level decodes to the same cells, but the files differ: the byte
    comparison above would fail."""
    from numcodecs.zstd import Zstd

    _, s, _, stores = small

    def level_5(layers, L):
        raw = np.zeros((L, *layers.shape[1:]), dtype=np.uint8)
        raw[:layers.shape[0]] = layers
        return bytes(Zstd(level=5, checksum=True).encode(raw.tobytes()))

    monkeypatch.setattr(_drdask, "encode_chunk", level_5)
    built = build_store(s, "modified", tmp_path / "dr.zarr", layers_per_chunk=2)
    built.publish()
    assert built.sha256 == stores[Variant.MODIFIED][1]         # the same array ...
    with pytest.raises(AssertionError, match="files that differ"):
        assert_same_store(tmp_path / "dr.zarr", stores[Variant.MODIFIED][0])   # ... not bytes


def test_seeded_fault_a_flipped_cell_in_a_block_changes_the_store(small, tmp_path, monkeypatch):
    _, s, _, stores = small
    real = _drdask.block_dr

    def flipped(*args):
        out = real(*args)
        out[0, 3, 3] ^= 1
        return out

    monkeypatch.setattr(_drdask, "block_dr", flipped)
    built = build_store(s, "modified", tmp_path / "dr.zarr", layers_per_chunk=2)
    assert built.sha256 != stores[Variant.MODIFIED][1]
    built.discard()
    assert not (tmp_path / "dr.zarr").exists() and _leftovers(tmp_path) == []


# --- no half-written store ----------------------------------------------------------------------

def _interrupt_after_the_first_block(written: int) -> None:
    raise KeyboardInterrupt


def test_an_interrupted_build_leaves_no_dr_zarr_and_keeps_the_earlier_one(small, tmp_path):
    _, s, _, stores = small
    with pytest.raises(KeyboardInterrupt):
        build_store(s, "modified", tmp_path / "new" / "dr.zarr", layers_per_chunk=2,
                    _after_block=_interrupt_after_the_first_block)
    assert not (tmp_path / "new" / "dr.zarr").exists() and _leftovers(tmp_path / "new") == []
    # A folder with an earlier store: it stays as it was.
    shutil.copytree(stores[Variant.TIGHT][0], tmp_path / "old" / "dr.zarr")
    with pytest.raises(KeyboardInterrupt):
        build_store(s, "modified", tmp_path / "old" / "dr.zarr", layers_per_chunk=2,
                    _after_block=_interrupt_after_the_first_block)
    assert_same_store(tmp_path / "old" / "dr.zarr", stores[Variant.TIGHT][0])
    assert _leftovers(tmp_path / "old") == []


def test_seeded_fault_a_store_built_in_place_is_left_half_written(small, tmp_path, monkeypatch):
    """Chunks written straight into DIR/dr.zarr: the interruption leaves a store with a chunk
    of four, so the test above would fail."""
    _, s, _, _ = small

    def in_place(target):
        Path(target).mkdir(parents=True, exist_ok=True)
        return Path(target)

    monkeypatch.setattr(_drdask, "temporary_store", in_place)
    monkeypatch.setattr(_drdask.shutil, "rmtree", lambda *a, **k: None)
    with pytest.raises(KeyboardInterrupt):
        build_store(s, "modified", tmp_path / "dr.zarr", layers_per_chunk=2,
                    _after_block=_interrupt_after_the_first_block)
    assert (tmp_path / "dr.zarr" / "zarr.json").exists()


# --- options refused before any work -------------------------------------------------------------

@pytest.mark.parametrize("extra, said", [
    (["--workers", "2", "--store", "npy"], "error: --store must be zarr with --workers or "
                                           "--scheduler"),
    (["--workers", "2", "--kernel", "reference"], "error: --kernel must be fast with --workers"),
    (["--workers", "2", "--scheduler", "tcp://127.0.0.1:9"], "cannot be combined with "
                                                            "--scheduler"),
    (["--scheduler", "not an address"], "error: --scheduler must be a Dask scheduler address"),
    (["--workers", "1", "--worker-timeout", "0"], "--worker-timeout must be a number of "
                                                  "seconds > 0"),
])
@pytest.mark.parametrize("command", ["dr", "plan"])
def test_what_a_dask_build_cannot_do_is_exit_2_before_any_work(small, tmp_path, capsys, extra,
                                                               said, command):
    toml = small[0]
    out = tmp_path / "out"
    assert main([command, str(toml), "--out", str(out), *extra]) == 2
    err = capsys.readouterr().err
    assert said in err and "Traceback" not in err
    assert not out.exists()


def test_workers_0_is_the_one_process_build(small, two_layer_chunks, tmp_path, capsys):
    toml, _, _, stores = small
    out = tmp_path / "out"
    assert main(["dr", str(toml), "--out", str(out), "--store", "zarr", "--workers", "0"]) == 0
    printed = capsys.readouterr().out
    assert "engine" not in printed and "dr_tasks" not in printed
    assert_same_store(out / "dr.zarr", stores[Variant.MODIFIED][0])


def test_a_scheduler_that_does_not_answer_writes_nothing(small, tmp_path, capsys):
    out = tmp_path / "out"
    t0 = time.monotonic()
    assert main(["dr", str(small[0]), "--out", str(out), "--scheduler", "tcp://127.0.0.1:9",
                 "--connect-timeout", "1"]) == 2
    err = capsys.readouterr().err
    assert "error: --scheduler did not answer within 1 s" in err and "Traceback" not in err
    assert len(err.strip().splitlines()) == 1
    assert not out.exists() and time.monotonic() - t0 < 10


# --- on a cluster ---------------------------------------------------------------------------------

@pytest.mark.slow     # its own cluster: 5-20 s to start two workers and load their kernels
def test_cfmpa_dr_on_two_local_workers_writes_the_one_process_store(small, two_layer_chunks,
                                                                     tmp_path, capsys):
    toml, _, _, stores = small
    out = tmp_path / "out"
    assert main(["dr", str(toml), "--out", str(out), "--workers", "2"]) == 0
    printed = capsys.readouterr().out
    assert "engine    local Dask cluster, 2 worker process(es)" in printed
    assert f"wrote     {out / 'dr.zarr'}" in printed
    assert_same_store(out / "dr.zarr", stores[Variant.MODIFIED][0])
    assert _leftovers(out) == []


# --- a separately started `dask scheduler` and `dask worker` -------------------------------------

@pytest.fixture(scope="module")
def started(tmp_path_factory):
    """`dask scheduler` and one `dask worker` (one thread), each its own process, as a user
    starts them; the scheduler's address."""
    d = tmp_path_factory.mktemp("started")
    file = d / "scheduler.json"
    dask = Path(sys.executable).parent / "dask"
    env = os.environ | {"PYTHONWARNINGS": "ignore"}
    procs = [subprocess.Popen([str(dask), "scheduler", "--host", "127.0.0.1", "--port", "0",
                               "--no-dashboard", "--scheduler-file", str(file)],
                              stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL, env=env)]
    try:
        t0 = time.monotonic()
        while not file.exists() and time.monotonic() - t0 < LIMIT_S:
            time.sleep(0.05)
        assert file.exists(), "dask scheduler did not start"
        procs.append(subprocess.Popen([str(dask), "worker", "--scheduler-file", str(file),
                                       "--nthreads", "1", "--no-dashboard",
                                       "--host", "127.0.0.1"], cwd=d,
                                      stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL,
                                      env=env))
        import json

        time.sleep(0.2)
        yield json.loads(file.read_text())["address"]
    finally:
        for p in reversed(procs):          # the worker (and its nanny) while the scheduler is up
            p.terminate()
            try:
                p.wait(10)
            except subprocess.TimeoutExpired:
                p.kill()
                p.wait()


def test_a_separately_started_scheduler_and_worker_build_the_one_process_store(
        small, two_layer_chunks, started, tmp_path, capsys):
    toml, _, _, stores = small
    out = tmp_path / "out"
    assert main(["dr", str(toml), "--variant", "tight", "--out", str(out), "--scheduler",
                 started, "--connect-timeout", "20"]) == 0
    printed = capsys.readouterr().out
    assert f"engine    Dask scheduler {started}, 1 worker(s)" in printed
    assert "(engine_start " in printed and " dr_tasks " in printed
    assert_same_store(out / "dr.zarr", stores[Variant.TIGHT][0])


def _plan_doc(folder: Path) -> dict:
    import json

    doc = json.loads((folder / "plan.json").read_text())
    del doc["timings_s"]
    return doc


def test_cfmpa_plan_on_a_cluster_writes_the_one_process_plan(small, two_layer_chunks, started,
                                                             tmp_path, capsys):
    toml, _, _, stores = small
    one, dask = tmp_path / "one", tmp_path / "dask"
    assert main(["plan", str(toml), "--out", str(one), "--store", "zarr"]) == 0
    (one / "dr.npy").write_bytes(b"left by an earlier run")
    shutil.copytree(one, dask)
    assert main(["plan", str(toml), "--out", str(dask), "--scheduler", started]) == 0
    printed = capsys.readouterr().out
    assert f"engine    Dask scheduler {started}, 1 worker(s)" in printed
    assert "dr_tasks" in printed
    assert_same_store(dask / "dr.zarr", stores[Variant.MODIFIED][0])
    assert _plan_doc(dask) == _plan_doc(one)
    assert (dask / "traj.csv").read_bytes() == (one / "traj.csv").read_bytes()
    assert not (dask / "dr.npy").exists()            # a folder keeps one D_R


def test_a_plan_on_a_cluster_searches_the_store_and_never_reads_dr_whole(
        small, two_layer_chunks, started, tmp_path, monkeypatch, capsys):
    """`plan --scheduler` checks and searches the store it built a layer at a time (§9): with
    the whole-store read and the layers' whole-array conversion made to raise, its plan.json is
    the in-process `--store zarr` plan's, and the search read the store's chunks."""
    from cfmpa.spec import Layers

    toml = small[0]
    one, dask = tmp_path / "one", tmp_path / "dask"
    argv = ["--contracts", "off"]
    assert main(["plan", str(toml), "--out", str(one), "--store", "zarr", *argv]) == 0

    def whole(*args: Any, **kw: Any) -> Any:
        raise AssertionError("D_R materialised whole")

    monkeypatch.setattr(_drstore.ZarrDr, "read", whole)
    monkeypatch.setattr(Layers, "__array__", whole)
    read: list[int] = []
    chunk = _drstore.ZarrDr.chunk
    monkeypatch.setattr(_drstore.ZarrDr, "chunk",
                        lambda self, c: read.append(c) or chunk(self, c))
    assert main(["plan", str(toml), "--out", str(dask), "--scheduler", started, *argv]) == 0
    capsys.readouterr()
    assert _plan_doc(dask) == _plan_doc(one)
    assert (dask / "traj.csv").read_bytes() == (one / "traj.csv").read_bytes()
    g = make_grid(small[1])
    chunks = -(-(g.N + 1) // 2)
    # the sha pass reads every chunk once; the search reads them again, layer after layer
    assert read[:chunks] == list(range(chunks)) and set(read[chunks:]) == set(range(chunks))
    # Seeded fault: the store read back whole for the search (as before) is caught.
    monkeypatch.setattr(_drstore.ZarrDr, "layers", lambda self, blocked=None: self.read()[0])
    with pytest.raises(AssertionError, match="materialised whole"):
        main(["plan", str(toml), "--out", str(tmp_path / "whole"), "--scheduler", started,
              *argv])
    capsys.readouterr()
    assert not (tmp_path / "whole" / "plan.json").exists()


def test_a_plan_on_a_cluster_with_full_contracts_does_not_read_the_store_whole(
        small, two_layer_chunks, started, tmp_path, monkeypatch, capsys):
    """Full contracts too: the store's whole read is never used (the contracts' checkers read
    D_R through ``spec.Layers``; docs/model.md §9 says which of them still convert it)."""
    toml = small[0]

    def whole(*args: Any, **kw: Any) -> Any:
        raise AssertionError("the store read whole")

    monkeypatch.setattr(_drstore.ZarrDr, "read", whole)
    out = tmp_path / "out"
    assert main(["plan", str(toml), "--out", str(out), "--scheduler", started]) == 0
    capsys.readouterr()
    doc = _plan_doc(out)
    assert doc["contracts"]["mode"] == "full" and not doc["contracts"]["violations"]
    assert (out / "dr.zarr" / "zarr.json").exists()
    # Seeded fault: a builder that reads the store back whole for the contracts is caught.
    monkeypatch.setattr(_drdask, "_sha256_and_blocked",
                        lambda zarr: (zarr.read()[1], zarr.layers().blocked_cells()))
    with pytest.raises(AssertionError, match="read whole"):
        main(["plan", str(toml), "--out", str(tmp_path / "again"), "--scheduler", started])
    capsys.readouterr()


def test_the_engine_says_how_many_workers_it_has(started):
    from cfmpa.runs._engine import Engine

    assert Engine().worker_count() == 1
    assert Engine(3).worker_count() == 3          # a local cluster not started: its processes
    with Engine(0, started, connect_timeout=20) as e:
        assert e.worker_count() == 1
    import inspect

    assert "_client" not in inspect.getsource(_drdask)    # the engine's count, not its client


def test_a_block_that_keeps_failing_ends_the_run_without_a_store(small, two_layer_chunks,
                                                                  started, tmp_path,
                                                                  monkeypatch, capsys):
    toml = small[0]
    monkeypatch.setenv("CFMPA_TEST_FAULTS", '{"2": "raise"}')
    out = tmp_path / "out"
    out.mkdir()
    assert main(["dr", str(toml), "--out", str(out), "--scheduler", started]) == 1
    err = capsys.readouterr().err
    (line,) = [x for x in err.splitlines() if x.startswith("error: ")]
    # One worker: two blocks of two chunks, the second's first chunk is chunk 2.
    assert "error: layers 4..6 of D_R could not be built on the Dask cluster" in line
    assert "no dr.zarr is written" in line and "Traceback" not in err
    assert not (out / "dr.zarr").exists() and _leftovers(out) == []


def test_a_plan_interrupted_after_the_build_leaves_no_dr_zarr(small, two_layer_chunks, started,
                                                              tmp_path, monkeypatch, capsys):
    """Ctrl-C in the search, after the store is built: it is not renamed into place."""
    import cfmpa.impl

    real = cfmpa.impl.kernels

    def interrupted(*args: Any, **kw: Any) -> Any:
        raise KeyboardInterrupt

    monkeypatch.setattr(cfmpa.impl, "kernels",
                        lambda name="fast": (real(name)[0], interrupted))
    out = tmp_path / "out"
    assert main(["plan", str(small[0]), "--out", str(out), "--scheduler", started]) == 130
    capsys.readouterr()
    assert out.is_dir() and not (out / "dr.zarr").exists() and _leftovers(out) == []
    assert not (out / "plan.json").exists()
    # Seeded fault: the built store not discarded is left behind, so the check above is real.
    monkeypatch.setattr(_drdask.BuiltStore, "discard", lambda self: None)
    assert main(["plan", str(small[0]), "--out", str(out), "--scheduler", started]) == 130
    capsys.readouterr()
    assert len(_leftovers(out)) == 1 and not (out / "dr.zarr").exists()


def test_a_worker_that_dies_mid_task_has_its_block_built_again(small, two_layer_chunks, started,
                                                               tmp_path, monkeypatch, capsys):
    """The worker process exits mid-task; its nanny starts another, which builds the block
    again (the last test on the started worker: the new one loads its kernels anew)."""
    toml, _, _, stores = small
    mark = tmp_path / "killed"
    monkeypatch.setenv("CFMPA_TEST_FAULTS", f'{{"2": "exit-once:{mark}"}}')
    out = tmp_path / "out"
    assert main(["dr", str(toml), "--out", str(out), "--scheduler", started,
                 "--connect-timeout", "30"]) == 0
    assert mark.exists(), "the fault did not kill the worker"
    assert_same_store(out / "dr.zarr", stores[Variant.MODIFIED][0])


# --- a cluster that loses its workers ------------------------------------------------------------

@pytest.fixture
def inproc():
    """A cluster of one in-process worker, its own per test (its worker is closed mid-run)."""
    from dask.distributed import LocalCluster

    c = LocalCluster(n_workers=1, threads_per_worker=1, processes=False, protocol="tcp",
                     host="127.0.0.1", dashboard_address="127.0.0.1:0",
                     silence_logs=logging.CRITICAL)
    yield c
    for w in list(c.workers.values()):
        c.sync(functools.partial(w.close, executor_wait=False))
    c.close()


def test_a_cluster_that_loses_its_worker_stops_with_the_command_that_builds_again(
        small, two_layer_chunks, inproc, tmp_path, monkeypatch, capsys):
    toml, _, _, stores = small
    out = tmp_path / "out"
    shutil.copytree(stores[Variant.TIGHT][0], out / "dr.zarr")      # an earlier store
    monkeypatch.setenv("CFMPA_TEST_FAULTS", '{"2": "sleep:2", "4": "sleep:2", "6": "sleep:2"}')
    argv = ["dr", str(toml), "--out", str(out), "--scheduler", inproc.scheduler_address,
            "--worker-timeout", "1"]
    got: dict[str, Any] = {}

    def first_block_in() -> bool:
        return any((p / "c" / "0").exists() for p in out.glob(".dr.zarr.*.tmp"))

    def close_when_ready() -> None:
        t0 = time.monotonic()
        while time.monotonic() - t0 < LIMIT_S and not first_block_in():
            time.sleep(0.02)
        for w in list(inproc.workers.values()):
            inproc.sync(functools.partial(w.close, executor_wait=False))

    watcher = threading.Thread(target=close_when_ready, daemon=True)
    watcher.start()
    run = threading.Thread(target=lambda: got.update(code=main(argv)), daemon=True)
    run.start()
    run.join(LIMIT_S)
    assert not run.is_alive(), "the build waited for a worker that never came"
    err = capsys.readouterr().err
    assert got["code"] == 2, err
    assert f"warning: the Dask cluster {inproc.scheduler_address} has no worker" in err
    (line,) = [x for x in err.splitlines() if x.startswith("error: ")]
    assert "had no worker for 1 s (--worker-timeout)" in line
    assert "No dr.zarr is written (an earlier one stays as it was)" in line
    assert line.split("run it again with: ", 1)[1] == shlex.join(
        ["cfmpa", "dr", str(toml), "--variant", "modified", *argv[2:]])
    assert_same_store(out / "dr.zarr", stores[Variant.TIGHT][0])
    assert _leftovers(out) == []


def test_the_store_is_what_any_zarr_reader_reads(small, tmp_path):
    import zarr

    _, s, whole, _ = small
    built = build_store(s, "original", tmp_path / "dr.zarr", layers_per_chunk=3)
    built.publish()
    a = zarr.open_array(tmp_path / "dr.zarr", mode="r")
    assert a.chunks[0] == 3 and np.array_equal(a[:], whole[Variant.ORIGINAL])
    with pytest.raises(CfmpaError):   # a task that returns another block is refused
        _drdask._run_blocks(_Fake(), s, Variant.MODIFIED, tmp_path, 2, [(0, 2)], {}, False,
                            None)


class _Fake:
    """An engine whose one task returns the wrong block."""

    def run(self, fn: Any, argsets: Any, on_done: Any, **kw: Any) -> None:
        on_done(0, {"k0": 2, "k1": 4, "chunks": [b""], "blocked": 0})
