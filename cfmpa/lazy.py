"""Lazy exports for the packages' ``__init__`` (PEP 562): a public name's module is imported
on first use, so a command loads only what it needs (no z3, matplotlib or dask for `cfmpa dr`,
`plan` or `certify`; docs/model.md §1.1). The packages keep their ``__all__``; the type checker
reads their imports under ``TYPE_CHECKING``."""

from __future__ import annotations

import importlib
import sys
from collections.abc import Callable, Iterable, Mapping
from typing import Any

__all__ = ["lazy_exports"]


def lazy_exports(package: str, exports: Mapping[str, str], public: Iterable[str]
                 ) -> tuple[Callable[[str], Any], Callable[[], list[str]]]:
    """``__getattr__`` and ``__dir__`` for ``package``: ``exports`` maps each public name to
    ``"module:attribute"`` (the module relative to the package). A name is bound in the package
    once read; a private module (``_plan``) is given as ``import`` would give it."""
    table = dict(exports)
    names = sorted(set(public))

    def __getattr__(name: str) -> Any:
        if name in table:
            module, attr = table[name].split(":")
            value = getattr(importlib.import_module(module, package), attr)
            setattr(sys.modules[package], name, value)
            return value
        if name.startswith("_") and not name.startswith("__"):
            try:
                return importlib.import_module(f"{package}.{name}")
            except ModuleNotFoundError:
                pass
        raise AttributeError(f"module {package!r} has no attribute {name!r}")

    def __dir__() -> list[str]:
        return sorted(set(vars(sys.modules[package])) | set(names))

    return __getattr__, __dir__
