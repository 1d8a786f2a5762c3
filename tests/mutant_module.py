"""A seeded fault as a module: a package file of cfmpa with one-line edits, loaded as a module of
its package with its source registered for inspect (the obligations that read code through
inspect then read the mutated copy). Shared by the proof tests that plant code mutants."""

from __future__ import annotations

import importlib
import linecache
import types
from collections.abc import Callable, Sequence
from pathlib import Path


def source(file: str) -> tuple[str, str]:
    """(module name, source text) of a package file such as ``spec/_exact.py``."""
    folder, stem = file.split("/")[0], Path(file).stem
    name = f"cfmpa.{folder}.{stem}"
    return name, Path(importlib.import_module(name).__file__).read_text()  # type: ignore[arg-type]


def mutated_module(name: str, file: str, edits: Sequence[tuple[str, str]],
                   register: Callable[[str, types.ModuleType], None]) -> types.ModuleType:
    """``file`` with each (old, new) of ``edits`` applied (each old text must occur once),
    executed as module ``<package module>_mutant_<name>``, which ``register`` puts in
    sys.modules (a monkeypatch's setitem, or a plain assignment)."""
    modname, src = source(file)
    for old, new in edits:
        assert src.count(old) == 1, (name, old)
        src = src.replace(old, new)
    fname = f"<mutant {name} of {file}>"
    linecache.cache[fname] = (len(src), None, src.splitlines(True), fname)
    mod = types.ModuleType(f"{modname}_mutant_{name}")
    mod.__package__ = modname.rsplit(".", 1)[0]
    mod.__file__ = fname
    register(mod.__name__, mod)
    exec(compile(src, fname, "exec"), mod.__dict__)
    return mod
