"""The fast kernels' machine code: compiled once per machine, the groups at once in their own
processes, then loaded from numba's cache; one line on stderr while anything compiles.

numba compiles a kernel at its first call and keeps the machine code (``cache=True``) in a folder
beside the source (``__pycache__``) or under NUMBA_CACHE_DIR: a cold cache costs seconds per group
of kernels (GROUPS: the regions' hulls, BuiltDR's layer kernel, the search). So the first fast
kernel a process calls runs ``ensure_compiled``. Each group has a stamp in numba's cache folder:
a file holding a hash of what that cache depends on (cfmpa's, Python's, numba's, llvmlite's and
numpy's versions; the group's module: its source, and its size and modification time, numba's
own key; the host CPU's name and features). The groups whose stamp is missing or stale are
compiled each in its own process, all at once (each writes numba's cache; warm-up calls on a tiny
workcell with the same types as a real run), while stderr says so with a count, and their stamps
written; this process then loads the kernels from the cache as they are called. A lock file makes
processes that start cold together (a campaign's workers) wait for one compile. With a warm cache
it costs a few file reads and prints nothing. docs/model.md §7.5.

A run that finds the cache cold uses the numpy kernels (``numpy_while_cold``). Finding the
stamps takes numba's import (0.25 s: numba's cache folder and key come from it), pure cost in
that first run; so a marker file (``_marker``: under NUMBA_CACHE_DIR, else this package's
``__pycache__``), written once every group has been seen warm (by a compile, or by the
detached process of one that found none cold), holds a fingerprint that needs no numba
(cfmpa's and Python's versions, the groups' sources' sizes and times): a run that finds no
matching marker is cold without importing numba, and the detached compile checks the stamps
itself (compiling only what is cold) and writes the marker; while it runs it holds a start lock
beside the marker, so the runs started meanwhile start no other. A matching marker is only a
hint: the stamps are checked as before. Where the marker's folder cannot be written (or a
source cannot be read), the stamps are checked every time.

Loading from a warm cache: numba's FunctionCache refreshes its typing and target registries
before the first load in a process (it imports and registers every implementation numba has:
about 0.16 s CPU, a quarter of `cfmpa dr`'s whole process), which only a compile needs. So the
first ``ensure_compiled`` in a process gives the groups' dispatchers ``_LeanCache``
(``lean_loads``): the same cache, loaded after the runtime's set-up alone; a compile (a cache
miss) still refreshes, in numba's compiler, and a load that fails lean is done numba's way.
"""

from __future__ import annotations

import contextlib
import hashlib
import importlib
import os
import subprocess
import sys
import threading
import time
from collections.abc import Iterator
from pathlib import Path
from types import ModuleType
from typing import Any

__all__ = ["COMPILE_ENV", "GROUPS", "WARM_UP", "cold_groups", "ensure_compiled", "lean_loads",
           "load_fast_kernels", "numpy_while_cold", "wait_compiled"]

#: The environment variable choosing what a cold cache does: "background" (the default: the
#: groups compile in detached low-priority processes and the run uses the numpy kernels) or
#: "wait" (compile now, all groups at once, and wait; the behaviour before §7.5's change).
COMPILE_ENV = "CFMPA_KERNEL_COMPILE"

#: The groups of kernels compiled apart, and their modules (none calls another's kernels).
GROUPS: dict[str, str] = {"regions": "._fast_regions", "builtdr": "._fast_builtdr",
                          "search": "._fast_search"}

#: A workcell with a 4 x 14 x 14 grid: calling the fast kernels on it compiles (or loads) every
#: numba specialisation a real run uses (same dtypes and layouts), in milliseconds of work.
WARM_UP: dict[str, Any] = {
    "name": "kernel-warm-up", "purpose": "load the fast kernels", "dt": 0.5,
    "left": {"links": [0.35, 0.30], "width": 0.06, "omega": [1.0, 1.0], "base": [0.0, 0.0],
             "start": [0.3, 0.8], "goal": [1.6, 2.2]},
    "right": {"links": [0.35, 0.30], "width": 0.06, "omega": [1.0, 1.0], "base": [0.6, 0.0],
              "limits": [[0.0, 6.283185307179586], [0.0, 6.283185307179586]],
              "start_cell": [0, 4], "goal_cell": [7, 4]},
}

#: Bumped when the stamp's meaning changes.
_STAMP_FORMAT = "cfmpa kernel stamp 1"
_READY = [False]          # this process has made sure (or is a compile process itself)
_LOCK = threading.Lock()
_LOADED: list[float] = []
_NUMPY: list[bool] = []   # decided once per process: the fast kernels were cold (numpy in use)
#: The marker's file name (see the module docstring), and the lock beside it that a detached
#: compile started on an unmarked machine holds for its life.
_MARKER = "cfmpa-kernels.warm"
_START_LOCK = "cfmpa-kernels-start.lock"


def ensure_compiled() -> None:
    """Compile the groups whose cache is cold (see the module docstring); at once after the
    first call in a process. Called by every fast kernel's entry point."""
    if _READY[0]:
        return
    with _LOCK:
        if not _READY[0]:
            _compile_cold()
            for name in GROUPS:
                lean_loads(_module(name))
            _READY[0] = True


def lean_loads(mod: ModuleType) -> int:
    """Give the numba dispatchers of ``mod`` that cache with numba's own FunctionCache the
    ``_LeanCache`` (see the module docstring); how many were given it."""
    lean = _lean_cache()
    if lean is None:
        return 0
    count = 0
    for obj in vars(mod).values():
        cache = getattr(obj, "_cache", None)
        if type(cache) is lean.__base__:
            cache.__class__ = lean
            count += 1
    return count


_LEAN: list[Any] = []


def _lean_cache() -> Any:
    """The class ``_LeanCache`` (made once: it subclasses numba's FunctionCache, imported
    only here), or None where numba's cache lacks what it overrides."""
    if _LEAN:
        return _LEAN[0]
    from numba.core.caching import FunctionCache
    from numba.core.runtime.nrt import rtsys

    if not all(hasattr(FunctionCache, a) for a in ("load_overload", "_load_overload",
                                                   "_guard_against_spurious_io_errors")):
        _LEAN.append(None)
        return None

    class _LeanCache(FunctionCache):
        """numba's FunctionCache, loading without the registries' refresh: the machine code,
        its environment and its wrapper need only the runtime (NRT) set up."""

        def load_overload(self, sig: Any, target_context: Any) -> Any:
            try:
                rtsys.initialize(target_context)
                with self._guard_against_spurious_io_errors():
                    return self._load_overload(sig, target_context)
            except Exception:  # noqa: BLE001 - loaded again numba's way, which raises its own
                return super().load_overload(sig, target_context)

    _LEAN.append(_LeanCache)
    return _LeanCache


def load_fast_kernels() -> float:
    """Seconds spent making the fast kernels ready in this process by this call: compiling
    any cold group, then loading every kernel from the cache by calling it on WARM_UP (0.0 if
    done before in this process)."""
    if _LOADED or (_NUMPY and _NUMPY[0]):
        return 0.0            # numpy in use: nothing to load, and never a compile here
    t0 = time.perf_counter()
    ensure_compiled()
    for name in GROUPS:
        _warm(name)
    _LOADED.append(time.perf_counter() - t0)
    return _LOADED[0]


def numpy_while_cold() -> bool:
    """Whether this process runs the numpy kernels for "fast" (decided at the first call): the
    cache is cold and COMPILE_ENV is not "wait". Then the cold groups' compile is started in
    the background (unless one is running already: the lock is held) and one line on stderr
    says so, with a count; a later run uses the fast kernels once their stamps are warm."""
    if not _NUMPY:
        mode = os.environ.get(COMPILE_ENV, "background").strip().lower()
        marker = None if mode == "wait" or _READY[0] else _marker()
        unseen = marker is not None and not _marker_matches(*marker)
        if mode == "wait" or _READY[0]:
            cold = []
        elif unseen:
            # Never seen warm here: cold, decided without numba's import (the detached
            # compile checks the stamps and compiles only what is cold).
            cold = list(GROUPS)
        else:
            cold = cold_groups()
        if cold:
            # Unseen: whether a compile runs is told by its start lock, beside the marker.
            started = _start_background(cold, None if marker is None or not unseen
                                        else marker[0].parent)
            groups = f"{len(cold)} group{'s' if len(cold) > 1 else ''}"
            print(f"cfmpa: fast kernels not compiled for this machine yet: {groups} "
                  f"{'compiling' if started else 'being compiled'} in the background; this "
                  "run uses the numpy kernels (bit-identical, slower)", file=sys.stderr,
                  flush=True)
        _NUMPY.append(bool(cold))
    return _NUMPY[0]


def wait_compiled(timeout: float = 600.0) -> bool:
    """Wait until no group is cold (a background compile finished), at most ``timeout``
    seconds; whether none is. Compiles nothing itself."""
    deadline = time.monotonic() + timeout
    while cold_groups():
        if time.monotonic() > deadline:
            return False
        time.sleep(0.2)
    return True


def cold_groups() -> list[str]:
    """The groups whose stamp is missing or stale (numba's cache off: none)."""
    return [name for name in GROUPS if not _stamp_ok(name)]


# ------------------------------------------------------------------------------- stamps ----

def _module(name: str) -> ModuleType:
    return importlib.import_module(GROUPS[name], __package__)


def _cache_dir(mod: ModuleType) -> Path | None:
    """numba's cache folder for the kernels of ``mod`` (None: caching is off)."""
    for obj in vars(mod).values():
        path = getattr(getattr(obj, "_cache", None), "_cache_path", None)
        if path:
            return Path(path)
    return None


def _stamp_path(name: str) -> Path | None:
    folder = _cache_dir(_module(name))
    return None if folder is None else folder / f"cfmpa-{name}.stamp"


def _key(name: str) -> str:
    """The hash the stamp of group ``name`` holds: what numba's cache of it depends on."""
    import llvmlite  # type: ignore[import-untyped]  # no py.typed: read for versions only
    import llvmlite.binding as ll  # type: ignore[import-untyped]  # the host CPU, likewise
    import numba
    import numpy

    from .. import __version__

    source = _source(name)
    st = source.stat()
    h = hashlib.sha256()
    for part in (_STAMP_FORMAT, __version__, sys.version, numba.__version__,
                 llvmlite.__version__, numpy.__version__, str(st.st_size), str(st.st_mtime_ns),
                 os.environ.get("NUMBA_CPU_NAME", ""), os.environ.get("NUMBA_CPU_FEATURES", ""),
                 ll.get_host_cpu_name(), ll.get_host_cpu_features().flatten()):
        h.update(part.encode() + b"\0")
    h.update(source.read_bytes())
    return h.hexdigest()


def _stamp_ok(name: str) -> bool:
    path = _stamp_path(name)
    if path is None:
        return True
    try:
        return path.read_text() == _key(name)
    except OSError:
        return False


def _write_stamp(name: str) -> None:
    path = _stamp_path(name)
    if path is None:
        return
    tmp = path.with_name(f"{path.name}.{os.getpid()}.tmp")
    with contextlib.suppress(OSError):     # an unwritable cache: compiled again next time
        tmp.write_text(_key(name))
        os.replace(tmp, path)


@contextlib.contextmanager
def _file_lock(folder: Path | None, name: str = "cfmpa-kernels.lock") -> Iterator[None]:
    """Held by one process at a time (where fcntl and the folder allow it): the compile lock,
    or ``name``'s."""
    try:
        import fcntl
    except ImportError:   # pragma: no cover - not on Linux
        yield
        return
    if folder is None:
        yield
        return
    try:
        folder.mkdir(parents=True, exist_ok=True)
        fh = open(folder / name, "a")   # noqa: SIM115 - closed below
    except OSError:
        yield
        return
    with fh:
        fcntl.flock(fh, fcntl.LOCK_EX)
        try:
            yield
        finally:
            fcntl.flock(fh, fcntl.LOCK_UN)


# ------------------------------------------------------------------------------ compiling ----

def _compile_cold() -> None:
    cold = cold_groups()
    if not cold:
        return
    with _file_lock(_cache_dir(_module(cold[0]))):
        cold = cold_groups()                  # another process may have compiled them
        if not cold:
            return
        t0 = time.perf_counter()
        groups = f"{len(cold)} group{'s' if len(cold) > 1 else ''}"
        print(f"cfmpa: compiling {groups} of fast kernels for this machine (first run only)...",
              file=sys.stderr, flush=True)
        failed = _compile_in_processes(cold)
        for name in failed:                   # compiled here instead (the cache is written too)
            _warm(name)
        for name in cold:
            _write_stamp(name)
        if not cold_groups():
            _write_marker()
        print(f"cfmpa: fast kernels compiled in {time.perf_counter() - t0:.1f} s "
              "(cached for later runs)", file=sys.stderr, flush=True)


def _lock_free(folder: Path | None, name: str = "cfmpa-kernels.lock") -> bool:
    """Whether no process holds the compile lock (or ``name``'s) now (it is released again at
    once)."""
    try:
        import fcntl
    except ImportError:   # pragma: no cover - not on Linux
        return True
    if folder is None:
        return True
    try:
        folder.mkdir(parents=True, exist_ok=True)
        with open(folder / name, "a") as fh:
            try:
                fcntl.flock(fh, fcntl.LOCK_EX | fcntl.LOCK_NB)
            except OSError:
                return False
            fcntl.flock(fh, fcntl.LOCK_UN)
    except OSError:
        return True
    return True


def _start_background(cold: list[str], marker_folder: Path | None = None) -> bool:
    """Start a detached process (its own session, lowest priority) that takes the compile lock
    and compiles the groups still cold then, as ``_compile_cold`` does (a process per group,
    the stamps written, then the marker); False when another compile is under way or the
    process could not start (the next run tries again). Under way: the compile lock is held
    (found through numba's cache folder, so numba is imported), or, given ``marker_folder``
    (an unmarked machine, decided without numba), the start lock there, which the detached
    process holds for its life."""
    held = (_lock_free(marker_folder, _START_LOCK) if marker_folder is not None
            else _lock_free(_cache_dir(_module(cold[0]))))
    if not held:
        return False
    env = dict(os.environ)
    env["PYTHONPATH"] = os.pathsep.join(p for p in sys.path if p)   # this process's cfmpa
    try:
        # Lowest priority from its first line, before its imports (its compile processes
        # inherit it).
        code = ("import os, contextlib\nwith contextlib.suppress(OSError): os.nice(19)\n"
                f"import {__name__} as k; k._background()")
        subprocess.Popen([sys.executable, "-c", code],
                         env=env, stdin=subprocess.DEVNULL, stdout=subprocess.DEVNULL,
                         stderr=subprocess.DEVNULL, start_new_session=True)
    except OSError:
        return False
    return True


def _background() -> None:
    """The detached compile process's work (it runs at the lowest priority), under the start
    lock beside the marker: the cold groups compiled (``_compile_cold`` marks the machine), or,
    none cold (another compiled them), the machine marked here."""
    marker = _marker()
    with _file_lock(None if marker is None else marker[0].parent, _START_LOCK):
        _compile_cold()
        if marker is not None and not _marker_matches(*marker) and not cold_groups():
            _write_marker()


def _source(name: str) -> Path:
    """The source file of group ``name``'s module, found without importing it (nor numba)."""
    import importlib.util

    spec = importlib.util.find_spec(GROUPS[name], __package__)
    if spec is None or spec.origin is None:
        raise OSError(f"no source for {GROUPS[name]}")
    return Path(spec.origin)


def _marker() -> tuple[Path, str] | None:
    """The marker file and the fingerprint it must hold: the file under NUMBA_CACHE_DIR when
    set, else this package's ``__pycache__``; the fingerprint cfmpa's and Python's versions and
    the groups' sources' sizes and modification times, all read without numba. None where the
    folder (or, not made yet, its nearest existing parent) is not a folder this process can
    write, or a source cannot be read: the marker could not appear, so the stamps are checked
    every time (a machine never marked would otherwise be cold for ever)."""
    env = os.environ.get("NUMBA_CACHE_DIR", "").strip()
    folder = Path(env) if env else Path(__file__).resolve().parent / "__pycache__"
    probe = folder
    while not probe.exists():
        if probe.parent == probe:
            return None
        probe = probe.parent
    if not probe.is_dir() or not os.access(probe, os.W_OK):
        return None
    from .. import __version__

    parts = [_STAMP_FORMAT, __version__, sys.version]
    try:
        for name in sorted(GROUPS):
            st = _source(name).stat()
            parts += [name, str(st.st_size), str(st.st_mtime_ns)]
    except OSError:
        return None
    return folder / _MARKER, "\n".join(parts)


def _marker_matches(path: Path, fingerprint: str) -> bool:
    try:
        return path.read_text() == fingerprint
    except OSError:
        return False


def _write_marker() -> None:
    marker = _marker()
    if marker is None:
        return
    path, fingerprint = marker
    tmp = path.with_name(f"{path.name}.{os.getpid()}.tmp")
    with contextlib.suppress(OSError):     # unwritable after all: the stamps are checked
        path.parent.mkdir(parents=True, exist_ok=True)
        tmp.write_text(fingerprint)
        os.replace(tmp, path)


def _compile_in_processes(names: list[str]) -> list[str]:
    """Compile each group in a process of its own, all at once; the names that failed (they are
    compiled in this process instead, so a failure here costs time, not the run)."""
    env = dict(os.environ)
    env["PYTHONPATH"] = os.pathsep.join(p for p in sys.path if p)   # this process's cfmpa
    procs: list[tuple[str, subprocess.Popen[bytes] | None]] = []
    for name in names:
        code = f"import {__name__} as k; k._compile_here({name!r})"
        try:
            proc: subprocess.Popen[bytes] | None = subprocess.Popen(
                [sys.executable, "-c", code], env=env, stdin=subprocess.DEVNULL,
                stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
        except OSError:
            proc = None
        procs.append((name, proc))
    return [name for name, proc in procs if proc is None or proc.wait() != 0]


def _compile_here(name: str) -> None:
    """A compile process's work: group ``name``'s kernels on WARM_UP (numba writes its cache)."""
    _READY[0] = True
    _warm(name)


def _warm(name: str) -> None:
    """Call group ``name``'s kernels on WARM_UP with the types of a real run (compiling them or
    loading them from the cache); only its own kernels: the inputs come from the reference."""
    from ..spec import Variant, make_grid, parse_scenario
    from ._builtdr import build_dr, left_regions, right_regions

    s = parse_scenario(WARM_UP, check_budget=False)
    g = make_grid(s)
    v = Variant.MODIFIED
    if name == "regions":
        from ._fast_regions import left_regions_fast, right_regions_fast
        right_regions_fast(s, g)
        left_regions_fast(s, v, g)
    elif name == "builtdr":
        from ._fast_builtdr import build_from_regions
        build_from_regions(s, g, right_regions(s, g), left_regions(s, v, g), progress=False)
    elif name == "search":
        from ._fast_search import search_opt_path_fast
        dr = build_dr(s, v, g)
        search_opt_path_fast(dr, s.right.start_cell, s.right.goal_cell, progress=False)
        found = search_opt_path_fast(dr, s.right.start_cell, s.right.goal_cell, progress=False,
                                     with_witness=True)
        if found.witness is not None:
            found.witness.close()          # its labels' spill files, if any: not left to the GC
    else:
        raise ValueError(f"no kernel group {name!r} (known: {', '.join(GROUPS)})")
