"""D_R built on Dask: blocks of layers as tasks, written into dr.zarr (docs/model.md §9, §13).

`cfmpa dr|plan SCENARIO --out DIR --workers K | --scheduler ADDRESS` builds D_R as
dask.distributed tasks on ``Engine`` (a local cluster of K worker processes, or a running
cluster's workers), one task per block of layers, and writes it as DIR/dr.zarr, byte for byte
the store the one-process build writes (the same zarr.json, the same chunk files, so the same
dr_sha256).

Why a block can be built alone: layer k's cells depend only on k and the scenario (the
principal's region at layer k, the subordinate's regions, which do not depend on k), so the
fast kernel (``build_from_regions``) run on the principal's regions of layers k0 .. k1 - 1 gives
exactly those layers of the whole build. Its decision margin is then scaled by the coordinates
of that block's polygons (those it decides on), which is what makes it sound; a pair it leaves
unsure goes to the reference's own routine either way, so the bits do not depend on the blocks
(tests/runs/test_drdask.py compares every variant, a tool and link heights with the whole
build). The original and modified variants' rest layer N is layer N - 1's region: a block that
starts at N computes it afresh, the same bits.

Tasks and chunks: the chunk of the store holds ``L`` whole layers (``chunk_layers``, as the
one-process writer); a task builds a block of whole chunks, at most ``TASK_BYTES`` of cells and
small enough that every worker gets ``TASKS_PER_WORKER`` of them, and returns each chunk
encoded (``encode_chunk``: zarr's own codecs, so the same bytes) with the block's count of
blocked cells; the subordinate's regions, which every block needs, are made once per worker
process and kept for the next block of the same scenario (one scenario's kept). The client
writes each chunk file as its task completes into a temporary folder beside DIR/dr.zarr; once
all are in, every file is flushed, the store is read back a chunk at a time through the bounded
reader (dr_sha256, and its blocked cells counted again; `cfmpa plan` then checks and searches it
a layer at a time, ``ZarrDr.layers``, never whole) and only then renamed into place
(``BuiltStore.publish``). Workers write nothing, so they need no shared file system.

Failures (as in the campaigns, §13): a running cluster is reached (and has a worker) before
anything is written: a refused ``--scheduler`` is exit 2 and DIR is not created. A task whose
worker dies is run again by the scheduler; one that still fails ends the run (exit 1); a
cluster without a worker for ``--worker-timeout`` seconds, or a lost scheduler, is
``WorkersLost`` (exit 2) naming the command that runs the build again. In every case, and on
Ctrl-C, the temporary folder is removed: no half-written dr.zarr, and an earlier one stays as it
was.
"""

from __future__ import annotations

import contextlib
import math
import os
import shlex
import shutil
import time
from collections.abc import Callable, Iterator, Mapping, Sequence
from dataclasses import dataclass, field, replace
from pathlib import Path
from typing import Any, TextIO

import numpy as np
import numpy.typing as npt

from ..errors import CfmpaError, InputError, WorkersLost
from ..spec import Grid, Scenario, Variant, make_grid
from ._drstore import (
    _sync_tree,
    chunk_file,
    chunk_layers,
    create_store,
    encode_chunk,
    open_zarr,
    publish_store,
    temporary_store,
)
from ._engine import CONNECT_TIMEOUT_S, WORKER_TIMEOUT_S, Engine, ProgressBar, TaskLost

__all__ = ["TASKS_PER_WORKER", "TASK_BYTES", "BuiltStore", "EngineOptions", "block_dr",
           "blocks_of", "build_store", "dr_block_task", "rerun_message"]

#: The most cells (bytes) one task builds: what a worker holds of D_R beyond the regions.
TASK_BYTES = 256 * 1024 * 1024
#: Tasks per worker the blocks aim at, so that a slow or lost worker's share is small.
TASKS_PER_WORKER = 2


@dataclass(frozen=True)
class EngineOptions:
    """Where `cfmpa dr` and `cfmpa plan` build D_R: in this process (``workers`` 0, no
    ``scheduler``: the one-process build), on a local cluster of ``workers`` processes, or on
    the running cluster of ``scheduler``; and the campaigns' time-outs (§13)."""

    workers: int = 0
    scheduler: str | None = None
    connect_timeout: float = CONNECT_TIMEOUT_S
    worker_timeout: float = WORKER_TIMEOUT_S
    progress: bool | None = None

    @property
    def on_dask(self) -> bool:
        return self.scheduler is not None or self.workers > 0

    def engine(self) -> Engine:
        """The engine of these options, not started (its checks run: InputError for a bad
        address, count or time-out)."""
        return Engine(self.workers, self.scheduler, connect_timeout=self.connect_timeout,
                      worker_timeout=self.worker_timeout)

    def check(self, kernel: str, store: str | None) -> None:
        """InputError, before any work, for what a build on Dask cannot do."""
        self.engine()
        if kernel != "fast":
            raise InputError("--kernel", kernel, "must be fast with --workers or --scheduler "
                             "(the blocks of layers are built by the fast kernel)")
        if store not in (None, "zarr"):
            raise InputError("--store", store, "must be zarr with --workers or --scheduler "
                             "(the tasks build the chunks of dr.zarr)")

    def kwargs(self) -> dict[str, Any]:
        """``build_store``'s engine arguments."""
        return {"workers": self.workers, "scheduler": self.scheduler,
                "connect_timeout": self.connect_timeout, "worker_timeout": self.worker_timeout,
                "progress": self.progress}

    @contextlib.contextmanager
    def rerun_on_lost(self, command: Sequence[str]) -> Iterator[None]:
        """WorkersLost raised in the block gains the command (`cfmpa` ``command`` and these
        options) that runs the build again (``rerun_message``)."""
        try:
            yield
        except WorkersLost as exc:
            raise rerun_message(exc, ["cfmpa", *command, *self.engine().options()]) from None


def block_dr(s: Scenario, variant: Variant | str, g: Grid, k0: int, k1: int
             ) -> npt.NDArray[np.uint8]:
    """Layers k0 .. k1 - 1 of D_R (uint8 (k1 - k0, m, n)), the same bits as those layers of
    ``build_dr_fast(s, variant, g)`` (see the module docstring)."""
    from ..impl import LeftRegions, build_from_regions, ensure_compiled

    if not 0 <= k0 < k1 <= g.N + 1:
        raise ValueError(f"layers {k0}..{k1 - 1} are not within 0..{g.N}")
    ensure_compiled()
    right, left = _regions(s, Variant(variant), g)
    block = LeftRegions(variant=left.variant, links=left.links[k0:k1])
    return build_from_regions(s, replace(g, N=k1 - k0 - 1), right, block, progress=False)


#: The regions of the last scenario a worker process built a block of: (key, right, left).
_KEPT: list[tuple[Any, Any, Any]] = []


def _regions(s: Scenario, v: Variant, g: Grid) -> tuple[Any, Any]:
    """(the subordinate's regions, the principal's for ``v``): made once per scenario, grid and
    variant in this process and kept for the next block (one such set kept)."""
    from ..impl import left_regions_fast, right_regions_fast

    key = (s, v, g)
    if _KEPT and _KEPT[0][0] == key:
        return _KEPT[0][1], _KEPT[0][2]
    _KEPT.clear()                       # the last scenario's regions go before the new ones
    right = right_regions_fast(s, g)
    left = left_regions_fast(s, v, g)
    _KEPT.append((key, right, left))
    return right, left


def dr_block_task(s: Scenario, variant: str, k0: int, k1: int, layers_per_chunk: int,
                  fault: str | None = None) -> dict[str, Any]:
    """The task of one block (run on a worker): layers k0 .. k1 - 1 built, as the encoded files
    of chunks k0 / L .. (k1 - 1) / L and the count of blocked cells. ``fault`` is for tests
    only (the campaign's hook: ``raise``, ``exit-once:PATH``, ``sleep:S``)."""
    t0 = time.perf_counter()
    L = layers_per_chunk
    if k0 % L:
        raise ValueError(f"a block starts at a chunk's first layer, not at {k0}")
    if fault is not None:
        from ._campaign import _inject

        _inject(fault, k0 // L)
    block = block_dr(s, variant, make_grid(s), k0, k1)
    chunks = [encode_chunk(block[a:a + L], L) for a in range(0, block.shape[0], L)]
    return {"k0": k0, "k1": k1, "chunks": chunks, "blocked": int(np.count_nonzero(block)),
            "seconds": time.perf_counter() - t0}


def blocks_of(shape: tuple[int, int, int], workers: int,
              layers_per_chunk: int | None = None) -> tuple[int, list[tuple[int, int]]]:
    """(L, the blocks (k0, k1)): whole chunks of L layers, at most TASK_BYTES cells each (at
    least one chunk), TASKS_PER_WORKER blocks a worker (or more, a whole number a worker, for
    the budget; fewer when there are fewer chunks), their sizes within one chunk."""
    K, m, n = shape
    L = layers_per_chunk or chunk_layers(m, n, K)
    chunks = -(-K // L)
    most = max(1, TASK_BYTES // max(1, L * m * n))          # chunks a task may hold
    w = max(1, workers)
    # As many blocks as the budget needs and the workers want, a whole number a worker when
    # the chunks allow, of sizes that differ by one chunk at most: no worker gets a block
    # more than another, nor a larger one (an even share ends the build soonest).
    count = min(chunks, max(-(-chunks // most), TASKS_PER_WORKER * w))
    count = min(chunks, -(-count // w) * w)
    if -(-chunks // count) > most:                          # the budget first
        count = -(-chunks // most)
    sizes = [chunks // count + (b < chunks % count) for b in range(count)]
    starts = np.cumsum([0, *sizes])
    return L, [(int(a) * L, min(K, int(b) * L)) for a, b in zip(starts[:-1], starts[1:])]


@dataclass
class BuiltStore:
    """A finished D_R store under a temporary name beside ``target``: flushed, read back a
    chunk at a time (dr_sha256, its blocked cells counted again), not yet in place; ``layers``
    (when asked for) reads it a layer at a time (``ZarrDr.layers``) until it is published.
    ``publish`` renames it to ``target``; ``discard`` removes it (both idempotent)."""

    tmp: Path
    target: Path
    sha256: str
    blocked: int
    shape: tuple[int, int, int]
    layers: Any = None
    timings_s: dict[str, float] = field(default_factory=dict)
    published: bool = False

    @property
    def free_fraction(self) -> float:
        return 1.0 - self.blocked / math.prod(self.shape)

    def publish(self) -> Path:
        if not self.published:
            publish_store(self.tmp, self.target)
            self.published = True
        return self.target

    def discard(self) -> None:
        if not self.published:
            shutil.rmtree(self.tmp, ignore_errors=True)


def build_store(s: Scenario, variant: Variant | str, target: str | os.PathLike[str], *,
                workers: int = 0, scheduler: str | None = None,
                connect_timeout: float = CONNECT_TIMEOUT_S,
                worker_timeout: float = WORKER_TIMEOUT_S, keep_layers: bool = False,
                stream: TextIO | None = None, progress: bool | None = None,
                layers_per_chunk: int | None = None,
                _faults: Mapping[int, str] | None = None,
                _after_block: Callable[[int], None] | None = None) -> BuiltStore:
    """D_R of ``s`` for ``variant`` built block by block on ``Engine(workers, scheduler)`` into
    a temporary store beside ``target`` (dr.zarr), returned unpublished (the module docstring).

    ``keep_layers``: also the store as ``spec.Layers`` read a chunk at a time (`cfmpa plan`
    checks and searches it so, never holding D_R whole). The engine is started, so a running
    cluster reached, before the folder of ``target`` is made. Raises WorkersLost (the caller
    adds the command that runs it again), CfmpaError when a block's task failed after its
    retries; the temporary store is removed whenever this raises. ``_faults`` (chunk index of
    a block's first chunk -> the campaign's fault; by default CFMPA_TEST_FAULTS) and
    ``_after_block`` (called with the blocks written so far) are for tests."""
    from ._campaign import _env_faults

    v = Variant(variant)
    g = make_grid(s)
    shape = (g.N + 1, g.m, g.n)
    faults = dict(_faults) if _faults is not None else _env_faults()
    target = Path(target)
    t0 = time.perf_counter()
    engine = Engine(workers, scheduler, connect_timeout=connect_timeout,
                    worker_timeout=worker_timeout, stream=stream, warm=_warm)
    tmp: Path | None = None
    try:
        with engine:
            n_workers = engine.worker_count()
            L, blocks = blocks_of(shape, n_workers, layers_per_chunk)
            tmp = temporary_store(target)
            create_store(tmp, shape, L)
            try:
                blocked, done = _run_blocks(engine, s, v, tmp, L, blocks, faults, progress,
                                            _after_block)
            finally:
                if engine.serial:
                    # Built in this process: the regions the blocks shared (hundreds of MB on
                    # large grids) go now, before the search and the contracts (§9).
                    _KEPT.clear()
        t_read = time.perf_counter()
        _sync_tree(tmp)
        zarr = open_zarr(tmp, shape)
        sha, counted = _sha256_and_blocked(zarr)
        timings = {"engine_start": engine.timings_s["engine_start"],
                   "dr_tasks": engine.timings_s["tasks"],
                   "dr_read_back": time.perf_counter() - t_read,
                   "dr_store": time.perf_counter() - t0}
        if counted != blocked:
            raise CfmpaError("the store read back does not hold the blocks' cells (a bug of "
                             "cfmpa, not of the input)")
        layers = zarr.layers(blocked) if keep_layers else None
        return BuiltStore(tmp, target, sha, blocked, shape, layers, timings)
    except BaseException:
        if tmp is not None:
            shutil.rmtree(tmp, ignore_errors=True)
        raise


def _run_blocks(engine: Engine, s: Scenario, v: Variant, tmp: Path, L: int,
                blocks: Sequence[tuple[int, int]], faults: Mapping[int, str],
                progress: bool | None, after: Callable[[int], None] | None
                ) -> tuple[int, int]:
    """Every block's task on ``engine``, each chunk file written into ``tmp`` as its task
    completes: (blocked cells, blocks written)."""
    written: set[int] = set()
    blocked = 0

    def on_done(pos: int, result: Any) -> None:
        nonlocal blocked
        k0, k1 = blocks[pos]
        if isinstance(result, TaskLost):
            raise CfmpaError(f"layers {k0}..{k1 - 1} of D_R could not be built on the Dask "
                             f"cluster ({result.message}); no dr.zarr is written")
        chunks = result["chunks"]
        first = k0 // L
        if (result["k0"], result["k1"]) != (k0, k1) or len(chunks) != -(-(k1 - k0) // L):
            raise CfmpaError(f"the task of layers {k0}..{k1 - 1} returned another block")
        for c, data in enumerate(chunks, start=first):
            path = chunk_file(tmp, c)
            path.parent.mkdir(parents=True, exist_ok=True)
            with open(path, "wb") as fh:
                fh.write(data)
        written.update(range(first, first + len(chunks)))
        blocked += int(result["blocked"])
        if after is not None:
            after(len(written))

    bar = ProgressBar.for_terminal("BuiltDR blocks", len(blocks), progress=progress)
    engine.run(dr_block_task, [(s, v.value, k0, k1, L, faults.get(k0 // L))
                               for k0, k1 in blocks], on_done, name="dr-block", progress=bar)
    chunks = -(-blocks[-1][1] // L)
    if written != set(range(chunks)):   # the engine reports every task: a bug, not input
        raise CfmpaError(f"the build ended with {len(written)} of {chunks} chunks written")
    return blocked, len(blocks)


def _sha256_and_blocked(zarr: Any) -> tuple[str, int]:
    """dr_sha256 of an opened store and its blocked cells, from one pass a chunk at a time."""
    import hashlib

    from ._drstore import npy_header

    h = hashlib.sha256(npy_header(zarr.shape))
    blocked = 0
    for _, block in zarr.blocks():
        h.update(np.ascontiguousarray(block).data)
        blocked += int(np.count_nonzero(block))
    return h.hexdigest(), blocked


def _warm() -> None:
    """Load the compiled kernels (once per worker process)."""
    from ..impl import load_fast_kernels

    load_fast_kernels()


def rerun_message(exc: WorkersLost, command: Sequence[str]) -> WorkersLost:
    """``exc`` with what a stopped build leaves and the command that runs it again."""
    return WorkersLost(f"{exc}. No dr.zarr is written (an earlier one stays as it was); run "
                       f"it again with: {shlex.join(command)}")
