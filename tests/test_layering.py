"""The layers point one way and each package's private modules stay its own (docs/model.md §1).

Every module of the installed packages is parsed; an import of another package's private module
(``from ..impl._regions import SNAP``, ``from ..impl import _regions``) or an import against the
layer order fails, naming the file and line.
"""

from __future__ import annotations

import ast
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]

#: Folder of the checkout -> the package it is installed as (pyproject's package-dir).
PACKAGES = {"cfmpa": "cfmpa", "spec": "cfmpa.spec", "impl": "cfmpa.impl",
            "proofs": "cfmpa.proofs", "runs": "cfmpa.runs", "report": "cfmpa.report",
            "scenarios": "cfmpa.scenarios"}

#: Which packages each may import (besides itself); cfmpa's own leaf modules (errors, files,
#: gitstate, scenarios) are open to all, the command line to none.
ALLOWED = {
    "cfmpa.scenarios": set(),
    "cfmpa.spec": set(),
    "cfmpa.impl": {"cfmpa.spec"},
    "cfmpa.proofs": {"cfmpa.spec", "cfmpa.impl"},
    "cfmpa.runs": {"cfmpa.spec", "cfmpa.impl"},
    "cfmpa.report": {"cfmpa.spec", "cfmpa.impl", "cfmpa.proofs", "cfmpa.runs"},
    "cfmpa": {"cfmpa.spec", "cfmpa.impl", "cfmpa.proofs", "cfmpa.runs", "cfmpa.report"},
}
LEAVES = {"cfmpa", "cfmpa.lazy", "cfmpa.errors", "cfmpa.files", "cfmpa.gitstate",
          "cfmpa.scenarios"}
#: Libraries a module may not import, by module name prefix: the report presents what runs/
#: computed (the campaign's engine is runs/_engine.py's), so it has no dask of its own; the
#: command line parses and prints, so it starts no process (prove --audit's fork is
#: report/_prove_audit.py's).
FORBIDDEN = {"cfmpa.report": {"dask", "distributed"}, "cfmpa.cli": {"multiprocessing"},
             "cfmpa._arguments": {"multiprocessing"}}


def _modules() -> list[tuple[str, str, Path]]:
    """(package, module name, file) for every module of the installed packages."""
    out = []
    for folder, pkg in PACKAGES.items():
        for f in sorted((ROOT / folder).glob("*.py")):
            name = pkg if f.stem == "__init__" else f"{pkg}.{f.stem}"
            out.append((pkg, name, f))
    return out


def _imports(pkg: str, module: str, tree: ast.AST) -> list[tuple[int, str, str | None]]:
    """(line, imported module, imported name or None) for every import in ``tree``."""
    base = pkg.split(".") if module == pkg else module.split(".")[:-1]
    if module == pkg:
        base = pkg.split(".")
    out: list[tuple[int, str, str | None]] = []
    for node in ast.walk(tree):
        if isinstance(node, ast.ImportFrom):
            if node.level:
                parts = base[:len(base) - node.level + 1]
                target = ".".join(parts + ([node.module] if node.module else []))
            else:
                target = node.module or ""
            out += [(node.lineno, target, a.name) for a in node.names]
        elif isinstance(node, ast.Import):
            out += [(node.lineno, a.name, None) for a in node.names]
    return out


def _owner(name: str) -> str | None:
    """The cfmpa package that module ``name`` belongs to, None outside cfmpa."""
    if name != "cfmpa" and not name.startswith("cfmpa."):
        return None
    for pkg in sorted(PACKAGES.values(), key=len, reverse=True):
        if name == pkg or name.startswith(pkg + "."):
            return pkg
    return "cfmpa"


def _private(part: str) -> bool:
    return part.startswith("_") and not (part.startswith("__") and part.endswith("__"))


def _problems(pkg: str, module: str, f: Path) -> list[str]:
    """Rule breaks of module ``module`` of package ``pkg`` (file ``f``), one line each."""
    found = []
    for line, target, name in _imports(pkg, module, ast.parse(f.read_text(), str(f))):
        owner = _owner(target)
        if owner is None or owner == pkg:
            continue
        where = f"{f.relative_to(ROOT)}:{line}"
        inside = target.split(".")[len(owner.split(".")):]
        if any(_private(p) for p in inside) or (name is not None and _private(name)):
            found.append(f"{where}: imports {target}{'.' + name if name else ''}, "
                         f"a private part of {owner}")
        leaf = target in LEAVES or f"{target}.{name}" in LEAVES
        if owner not in ALLOWED[pkg] and not leaf:
            found.append(f"{where}: {pkg} may not import {owner} (layer order)")
    return found + _forbidden(pkg, module, f)


def _forbidden(pkg: str, module: str, f: Path) -> list[str]:
    """Imports of a library that FORBIDDEN keeps out of ``module``, one line each."""
    banned = set().union(*(libs for prefix, libs in FORBIDDEN.items()
                           if module == prefix or module.startswith(prefix + ".")))
    found = []
    for line, target, _ in _imports(pkg, module, ast.parse(f.read_text(), str(f))):
        if target.split(".")[0] in banned:
            found.append(f"{f.relative_to(ROOT)}:{line}: {module} may not import "
                         f"{target.split('.')[0]}")
    return found


def test_no_package_imports_another_packages_private_module_or_against_the_layers():
    problems = [p for pkg, mod, f in _modules() for p in _problems(pkg, mod, f)]
    assert not problems, "\n".join(problems)


def _planted_problems(folder: str, source: str) -> list[str]:
    """The layering problems of a module holding ``source``, planted in ``folder`` for the call."""
    planted = ROOT / folder / "_planted_for_test.py"
    planted.write_text(source)
    try:
        return _problems(f"cfmpa.{folder}", f"cfmpa.{folder}._planted_for_test", planted)
    finally:
        planted.unlink()


@pytest.mark.parametrize("source, expected", [
    ("from ..impl._regions import SNAP\n", "a private part of cfmpa.impl"),
    ("from ..impl import _regions\n", "a private part of cfmpa.impl"),
    ("from cfmpa.spec._paths import MOVES\n", "a private part of cfmpa.spec"),
    ("from ..runs import plan\n", "may not import cfmpa.runs"),
])
def test_the_rule_catches_a_planted_import(source: str, expected: str):
    problems = _planted_problems("proofs", source)
    assert any(expected in p and "proofs/_planted_for_test.py:1" in p for p in problems), problems


@pytest.mark.parametrize("source", ["import dask\n", "from dask.distributed import Client\n",
                                    "def f():\n    from distributed import as_completed\n"])
def test_the_report_may_not_import_dask(source: str):
    problems = _planted_problems("report", source)
    assert any("cfmpa.report._planted_for_test may not import" in p for p in problems), problems
    assert not _problems("cfmpa.runs", "cfmpa.runs._planted", ROOT / "runs" / "_engine.py")


def test_the_rule_lets_a_public_import_through():
    planted = ROOT / "impl" / "_planted_for_test.py"
    planted.write_text("from ..spec import MOVES\nfrom ..errors import InputError\n")
    try:
        assert _problems("cfmpa.impl", "cfmpa.impl._planted_for_test", planted) == []
    finally:
        planted.unlink()


@pytest.mark.parametrize("planted", ["import multiprocessing\n",
                                     "    from multiprocessing import get_context\n",
                                     "    import multiprocessing.pool\n"])
def test_the_cli_may_not_import_multiprocessing(planted: str):
    # A copy of the real cli.py with the import planted in main's body (or at the top): the
    # rule names it; the real file passes.
    real = ROOT / "cfmpa" / "cli.py"
    source = real.read_text()
    if planted.startswith(" "):
        at = source.index("    parser = _parser()\n")
        source = source[:at] + planted + source[at:]
    else:
        source = planted + source
    copy = ROOT / "cfmpa" / "_planted_for_test.py"
    copy.write_text(source)
    try:
        problems = _forbidden("cfmpa", "cfmpa.cli", copy)
    finally:
        copy.unlink()
    assert any("cfmpa.cli may not import multiprocessing" in p for p in problems), problems
    assert _forbidden("cfmpa", "cfmpa.cli", real) == []
    assert _forbidden("cfmpa", "cfmpa._arguments", ROOT / "cfmpa" / "_arguments.py") == []
