"""What a process pays to start the fast kernels from a warm cache (docs/model.md §7.5): their
machine code is loaded without numba's registries (``_kernel_cache.lean_loads``), and the
kernels `cfmpa dr` calls allocate nothing (an allocating kernel's cache load imports numba's
array implementation). The D_R is the reference's, bit for bit, either way. Seeded faults: the
lean loads turned off (the registries come back), the allocating ``_pack`` as it was (the
source check flags it), a lean load that fails (loaded numba's way instead)."""

from __future__ import annotations

import ast
import importlib
import inspect
import json
import os
import subprocess
import sys
import textwrap
from pathlib import Path

import pytest

from cfmpa.impl import _fast_builtdr, _fast_regions
from cfmpa.impl import _kernel_cache as kc

ROOT = Path(__file__).resolve().parents[2]

#: Modules only numba's registry refresh imports (not `import numba`), and numba's array
#: implementation, which a cache load imports for a kernel that allocates.
REGISTRIES = ("numba.cpython.unicode", "numba.typed.typeddict", "numba.np.random.legacy")
ARRAYOBJ = "numba.np.arrayobj"

PROBE = """
import json, sys
import numpy as np
from cfmpa.impl import build_dr, kernels, resolved
from cfmpa.spec import Variant, make_grid
import factory
s = factory.scenario()
g = make_grid(s)
name = resolved("fast")
fast = kernels("fast")[0](s, Variant.MODIFIED, g)
same = bool(np.array_equal(fast, build_dr(s, Variant.MODIFIED, g)))
print(json.dumps([name, same, sorted(m for m in sys.modules if m.startswith("numba."))]))
"""


def _fresh(prelude: str = "") -> tuple[str, bool, set[str]]:
    """(kernel that ran, D_R equal to the reference's, numba modules loaded) of the fast
    BuiltDR on a tiny workcell in a fresh interpreter (compiled first if the cache is cold)."""
    env = dict(os.environ, CFMPA_KERNEL_COMPILE="wait",
               PYTHONPATH=os.pathsep.join([str(ROOT / "tests"), *sys.path]))
    proc = subprocess.run([sys.executable, "-c", prelude + PROBE], cwd=ROOT, env=env,
                          capture_output=True, text=True, timeout=600)
    assert proc.returncode == 0, proc.stderr[-2000:]
    name, same, mods = json.loads(proc.stdout.strip().splitlines()[-1])
    return name, same, set(mods)


def test_the_kernels_load_without_numbas_registries_and_give_the_reference():
    name, same, mods = _fresh()
    assert name == "fast" and same
    assert not mods & set(REGISTRIES), sorted(mods & set(REGISTRIES))
    assert ARRAYOBJ not in mods


def test_seeded_fault_lean_loads_off_bring_the_registries_back():
    off = "import cfmpa.impl._kernel_cache as k\nk.lean_loads = lambda mod: 0\n"
    name, same, mods = _fresh(off)
    assert name == "fast" and same                 # the same D_R, numba's way
    assert set(REGISTRIES) <= mods


# --- the kernels `cfmpa dr` calls allocate nothing ------------------------------------------

#: numpy's allocating functions, as a kernel would call them.
ALLOCATING = {"empty", "zeros", "ones", "full", "empty_like", "zeros_like", "ones_like",
              "full_like", "array", "copy", "arange", "concatenate", "stack"}


def _allocations(source: str) -> list[str]:
    """The np.<allocating function> calls in ``source`` (a function's text)."""
    tree = ast.parse(textwrap.dedent(source))
    return [node.func.attr for node in ast.walk(tree)
            if isinstance(node, ast.Call) and isinstance(node.func, ast.Attribute)
            and isinstance(node.func.value, ast.Name) and node.func.value.id == "np"
            and node.func.attr in ALLOCATING]


def _kernels(mod) -> dict[str, str]:
    """name -> source of each numba dispatcher of ``mod``."""
    return {name: inspect.getsource(obj.py_func) for name, obj in vars(mod).items()
            if hasattr(obj, "py_func") and hasattr(obj, "_cache")}


def test_the_kernels_of_dr_allocate_nothing():
    kernels = {**_kernels(_fast_regions), **_kernels(_fast_builtdr)}
    assert {"_hulls", "_hull", "_turn", "_pack_into", "_boxes", "_layers", "_row"} <= set(kernels)
    assert {name: calls for name, src in kernels.items() if (calls := _allocations(src))} == {}


def test_seeded_fault_the_allocating_pack_is_flagged():
    old_pack = '''
    def _pack(verts):
        C, V = verts.shape[0], verts.shape[1]
        geo = np.zeros((C, V, 6))
        box = np.empty((C, 4))
        for c in range(C):
            _box_one(verts, c, box)
        return geo, box
    '''
    assert _allocations(old_pack) == ["zeros", "empty"]


# --- a lean load that fails is loaded numba's way -------------------------------------------

KERNEL_MODULE = """
from numba import njit


@njit(cache=True)
def twice(x):
    return 2.0 * x
"""


def test_a_failing_lean_load_is_done_numbas_way(tmp_path, monkeypatch):
    (tmp_path / "lean_probe_kernel.py").write_text(KERNEL_MODULE)
    monkeypatch.syspath_prepend(str(tmp_path))
    mod = importlib.import_module("lean_probe_kernel")
    try:
        assert mod.twice(1.5) == 3.0                   # compiled here, and cached
        base = type(importlib.reload(mod).twice._cache)
        real = base._load_overload
        calls: list[object] = []

        def once_failing(self, sig, target_context):
            calls.append(sig)
            if len(calls) % 2 == 1:
                raise RuntimeError("planted: this load fails")
            return real(self, sig, target_context)
        monkeypatch.setattr(base, "_load_overload", once_failing)
        # numba's own cache (no lean loads): the planted failure is raised.
        with pytest.raises(RuntimeError, match="planted"):
            mod.twice(2.0)
        calls.clear()
        mod = importlib.reload(mod)                    # a new dispatcher, loading from the cache
        assert kc.lean_loads(mod) == 1
        assert mod.twice(2.0) == 4.0                   # the lean load failed; numba's way served
        assert len(calls) == 2
        assert sum(mod.twice.stats.cache_hits.values()) == 1        # loaded, not compiled
        assert sum(mod.twice.stats.cache_misses.values()) == 0
    finally:
        sys.modules.pop("lean_probe_kernel", None)
