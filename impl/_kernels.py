"""Which BuiltDR and searchoptpath a run uses: a registry of kernels by name (the fast kernels
and the reference), like the report's sections (docs/model.md §1.1).

A ``Kernel`` names its two functions as ``"module:name"`` of this package, imported when the
kernel is asked for, not with the registry: every command's parser lists ``KERNELS``, and the
fast ones load numba (a command imports only what it needs: tests/test_startup.py). Adding a
kernel is one ``Kernel`` in ``REGISTRY``, its module and its test (bit-identical to the
reference, as tests/impl/test_fast_builtdr.py checks the fast one).
"""

from __future__ import annotations

import importlib
from collections.abc import Callable, Iterable, Mapping
from dataclasses import dataclass
from typing import Any

__all__ = ["KERNELS", "REGISTRY", "Kernel", "kernel_name", "kernels", "registry", "resolved"]


@dataclass(frozen=True)
class Kernel:
    """A (build, search) pair a run can pick by ``name``: ``build`` is BuiltDR, ``search``
    searchoptpath, each ``"module:name"`` with the module relative to ``cfmpa.impl``."""

    name: str
    build: str
    search: str
    #: The kernel run in its place while its machine code is compiled in the background (None:
    #: nothing to compile), docs/model.md §7.5.
    cold: str | None = None

    def load(self) -> tuple[Callable[..., Any], Callable[..., Any]]:
        """(build, search), their modules imported now."""
        return (_function(self.build), _function(self.search))


def _function(where: str) -> Callable[..., Any]:
    module, attr = where.split(":")
    return getattr(importlib.import_module(module, __package__), attr)


def registry(entries: Iterable[Kernel]) -> dict[str, Kernel]:
    """name -> kernel, in the order given (the first is the default); ValueError for a name
    given twice."""
    out: dict[str, Kernel] = {}
    for k in entries:
        if k.name in out:
            raise ValueError(f"kernel {k.name!r} is registered twice")
        out[k.name] = k
    for k in out.values():
        if k.cold is not None and k.cold not in out:
            raise ValueError(f"kernel {k.name!r} runs {k.cold!r} while cold, which is not registered")
    return out


#: The kernels a user can pick, the default first; "fast" and "numpy" are bit-identical to
#: "reference" (tested). "numpy" (no compile) is what "fast" gives while the fast kernels'
#: machine code is compiled in the background (docs/model.md §7.5).
REGISTRY: Mapping[str, Kernel] = registry((
    Kernel("fast", "._fast_builtdr:build_dr_fast", "._fast_search:search_opt_path_fast",
           cold="numpy"),
    Kernel("reference", "._builtdr:build_dr", "._search:search_opt_path"),
    Kernel("numpy", "._numpy_builtdr:build_dr_numpy", "._numpy_search:search_opt_path_numpy"),
))

#: The kernel names, the default first (the command line's --kernel choices).
KERNELS: tuple[str, ...] = tuple(REGISTRY)


def kernels(name: str = "fast", *, wait: bool = False
            ) -> tuple[Callable[..., Any], Callable[..., Any]]:
    """(build, search) of the kernel called ``name``; ValueError for another name.

    "fast" while its machine code is not compiled yet (numba's cache cold): the compile starts
    in the background and this gives the "numpy" pair, unless CFMPA_KERNEL_COMPILE=wait
    (``_kernel_cache.numpy_while_cold``, docs/model.md §7.5) or ``wait`` (the kernel named,
    compiled in the foreground at its first call: what a check of that kernel needs)."""
    return REGISTRY[name if wait and name in REGISTRY else resolved(name)].load()


def resolved(name: str = "fast") -> str:
    """The kernel ``kernels(name)`` gives: ``name``, or "numpy" for "fast" while the fast
    kernels' machine code is compiled in the background (what a run records and prints, so that
    plan.json names the kernel that ran); ValueError for a name not in KERNELS."""
    kernel = REGISTRY.get(name)
    if kernel is None:
        raise ValueError(f"kernel={name!r} is not one of {', '.join(KERNELS)}")
    if kernel.cold is not None:
        from ._kernel_cache import numpy_while_cold
        if numpy_while_cold():
            return kernel.cold
    return name


def kernel_name(build: Callable[..., Any], search: Callable[..., Any]) -> str:
    """The name of the pair ``(build, search)``, "custom" for anything not in KERNELS."""
    for name in KERNELS:
        if REGISTRY[name].load() == (build, search):
            return name
    return "custom"
