"""Which BuiltDR and searchoptpath a run uses: the fast kernels or the reference, by name."""

from __future__ import annotations

from collections.abc import Callable
from typing import Any

__all__ = ["KERNELS", "kernel_name", "kernels"]

#: The kernel names a user can pick; "fast" is bit-identical to "reference" (tested).
KERNELS: tuple[str, ...] = ("fast", "reference")


def kernels(name: str = "fast") -> tuple[Callable[..., Any], Callable[..., Any]]:
    """(build, search) of the kernel called ``name``; ValueError for another name. The kernels
    are imported here, not with KERNELS: every command's parser lists KERNELS, and the fast
    ones load numba (a command imports only what it needs: tests/test_startup.py)."""
    from ._builtdr import build_dr
    from ._fast_builtdr import build_dr_fast
    from ._fast_search import search_opt_path_fast
    from ._search import search_opt_path

    if name == "fast":
        return build_dr_fast, search_opt_path_fast
    if name == "reference":
        return build_dr, search_opt_path
    raise ValueError(f"kernel={name!r} is not one of {', '.join(KERNELS)}")


def kernel_name(build: Callable[..., Any], search: Callable[..., Any]) -> str:
    """The name of the pair ``(build, search)``, "custom" for anything not in KERNELS."""
    for name in KERNELS:
        if kernels(name) == (build, search):
            return name
    return "custom"
