"""Lazy package faces (PEP 562): a public name's module is imported on first use, so a command
loads only what it needs (no z3, matplotlib or dask for `cfmpa dr`, `plan` or `certify`;
docs/model.md §1.1).

A face lists each public name once, as the type checker reads it: the package's ``__init__.py``
imports it under ``if TYPE_CHECKING:`` in the explicit re-export form ``from ._module import
name as name`` (PEP 484; mypy's ``no_implicit_reexport`` exports exactly these), and ends with
``__getattr__, __dir__, __all__ = lazy_face(__name__, __file__)``: ``lazy_face`` reads that
block from the file (``face_exports``), so the run time's table and ``__all__`` are the type
checker's imports, never a second list."""

from __future__ import annotations

import ast
import importlib
import sys
from collections.abc import Callable, Iterable, Mapping
from pathlib import Path
from typing import Any

__all__ = ["face_exports", "lazy_exports", "lazy_face"]

#: The largest face read (bytes): a package's ``__init__.py`` is a few kilobytes.
MAX_FACE_BYTES = 1 << 20


def face_exports(path: str | Path) -> dict[str, str]:
    """Each public name of the face in ``path`` -> ``"module:attribute"`` (the module relative
    to the package), read from its ``if TYPE_CHECKING:`` block. Anything there but relative
    ``from`` imports of the form ``name as name`` raises ImportError naming file:line: another
    form would be a name the run time serves and the type checker does not export, or the
    reverse."""
    path = Path(path)
    with path.open("rb") as f:
        source = f.read(MAX_FACE_BYTES + 1)
    if len(source) > MAX_FACE_BYTES:
        raise ImportError(f"{path}: a package face over {MAX_FACE_BYTES} bytes")
    out: dict[str, str] = {}
    for node in ast.parse(source, str(path)).body:
        if not (isinstance(node, ast.If) and isinstance(node.test, ast.Name)
                and node.test.id == "TYPE_CHECKING"):
            continue
        for imp in node.body:
            if not (isinstance(imp, ast.ImportFrom) and imp.level == 1 and imp.module):
                raise ImportError(f"{path}:{imp.lineno}: a face's TYPE_CHECKING block holds "
                                  "only `from ._module import name as name`")
            for a in imp.names:
                if a.asname != a.name:
                    raise ImportError(f"{path}:{imp.lineno}: {a.name!r} is imported without "
                                      f"`as {a.name}` (the re-export form the type checker "
                                      "reads)")
                if a.name in out:
                    raise ImportError(f"{path}:{imp.lineno}: {a.name!r} is listed twice")
                out[a.name] = f".{imp.module}:{a.name}"
    if not out:
        raise ImportError(f"{path}: no `if TYPE_CHECKING:` block of public names")
    return out


def lazy_face(package: str, file: str
              ) -> tuple[Callable[[str], Any], Callable[[], list[str]], list[str]]:
    """``__getattr__``, ``__dir__`` and ``__all__`` (sorted) of the face ``file`` of
    ``package``, from its one list of names (``face_exports``)."""
    exports = face_exports(file)
    getattr_, dir_ = lazy_exports(package, exports, exports)
    return getattr_, dir_, sorted(exports)


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
