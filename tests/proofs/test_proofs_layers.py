"""proofs/ as an engine and a catalogue (docs/model.md §6, docs/contributing.md): the imports
between its modules, read with ast, form no cycle, and the catalogue (``_obl_*``: one module per
group, the safety theorem one per part) imports the engine, never the reverse except through the
registry that collects the obligations."""

from __future__ import annotations

import ast
import shutil
from pathlib import Path

import pytest

import cfmpa.proofs

PROOFS = Path(cfmpa.proofs.__file__).parent

#: Engine modules that read the catalogue, and why: the registry collects the obligations, and
#: the controls run the safety compositions without each premise. No import, at module level or
#: inside a function, closes a cycle.
READS_CATALOGUE = {
    "__init__": "the package's face",
    "_runner": "the per-scenario checks (CHECKS) and the registry's views",
    "_registry": "the registry: COLLECTORS and the views of its declarations",
    "_summaries": "the registry's summaries of per-scenario checks",
    "_controls": "the premise controls read Safety.*.composition's VC",
    "_controls_wiring": "the kinds controls read the registry's views (FIXED_IDS, kind_of)",
}


def _is_catalogue(module: str) -> bool:
    return module.startswith("_obl_")


def import_graph(root: Path) -> dict[str, dict[str, bool]]:
    """module -> {imported module of the same package: whether the import is at module level}."""
    graph: dict[str, dict[str, bool]] = {}
    for path in sorted(root.glob("*.py")):
        tree = ast.parse(path.read_text(encoding="utf-8"), str(path))
        top = {id(n) for n in tree.body}
        deps: dict[str, bool] = {}
        for node in ast.walk(tree):
            if not (isinstance(node, ast.ImportFrom) and node.level == 1):
                continue
            names = [node.module.split(".")[0]] if node.module else [a.name for a in node.names]
            for name in names:
                if (root / f"{name}.py").exists():
                    deps[name] = deps.get(name, False) or id(node) in top
        graph[path.stem] = deps
    return graph


def find_cycle(graph: dict[str, set[str]]) -> list[str] | None:
    """A cycle of ``graph`` as the list of its modules (the first repeated at the end), or None."""
    state: dict[str, int] = {}
    stack: list[str] = []

    def visit(m: str) -> list[str] | None:
        state[m] = 1
        stack.append(m)
        for d in sorted(graph.get(m, ())):
            if state.get(d) == 1:
                return stack[stack.index(d):] + [d]
            if d not in state and (found := visit(d)):
                return found
        stack.pop()
        state[m] = 2
        return None

    for m in sorted(graph):
        if m not in state and (found := visit(m)):
            return found
    return None


def layer_faults(root: Path) -> list[str]:
    """What breaks the layering of the proofs package at ``root`` (empty: none)."""
    graph = import_graph(root)
    faults = []
    top = {m: {d for d, at_top in deps.items() if at_top} for m, deps in graph.items()}
    if cycle := find_cycle(top):
        faults.append("module-level import cycle: " + " -> ".join(cycle))
    if cycle := find_cycle({m: set(deps) for m, deps in graph.items()}):   # lazy ones too
        faults.append("import cycle: " + " -> ".join(cycle))
    for m, deps in graph.items():
        if _is_catalogue(m) or m in READS_CATALOGUE:
            continue
        for d in deps:
            if _is_catalogue(d):
                faults.append(f"engine module {m} imports the catalogue's {d}")
            elif d in READS_CATALOGUE and d != "__init__":
                faults.append(f"engine module {m} imports {d}, which reads the catalogue")
    return faults


def test_proofs_imports_are_layered_and_acyclic():
    assert layer_faults(PROOFS) == []


def test_the_safety_theorem_is_split_by_its_parts():
    graph = import_graph(PROOFS)
    parts = {"_obl_safety_principal", "_obl_safety_subordinate", "_obl_safety_region",
             "_obl_safety_separation"}
    assert parts <= set(graph["_obl_safety"])
    assert all(not _is_catalogue(d) or d in parts | {"_obl_arc_chord", "_obl_margin"}
               for p in parts for d in graph[p])
    shared = {"_z3vec", "_lemmas", "_onterms", "_select"}
    assert shared <= set(graph)
    assert not [(m, d) for m in shared for d in graph[m] if _is_catalogue(d)]


def _copy(tmp_path: Path) -> Path:
    root = tmp_path / "proofs"
    shutil.copytree(PROOFS, root, ignore=shutil.ignore_patterns("__pycache__", "*.lock"))
    return root


def _plant(path: Path, after: str, line: str) -> None:
    text = path.read_text(encoding="utf-8")
    assert after in text
    path.write_text(text.replace(after, after + line, 1), encoding="utf-8")


@pytest.mark.parametrize("module, after, line, fault", [
    # Seeded fault: the vector helpers import a catalogue module (engine -> catalogue).
    ("_z3vec.py", "import z3\n", "from ._obl_margin import GROUP\n", "engine module _z3vec"),
    # Seeded fault: a lazy import back from a safety part to the composition (a cycle).
    ("_obl_safety_region.py", "    k.update(arc_steps(arc, k))\n",
     "    from ._obl_safety import VARIANTS  # noqa: F401\n", "import cycle"),
    # Seeded fault: the runner and the controls import each other again at module level.
    ("_controls.py", "import z3\n", "from ._runner import selected\n",
     "module-level import cycle"),
    # Seeded fault: the kinds controls read the runner's views again, lazily (the runner runs
    # the controls: a cycle through a function-level import).
    ("_controls_wiring.py", "def _accept_kinds() -> tuple[str, str]:\n",
     "    from ._runner import kind_of as _k  # noqa: F401\n", "import cycle"),
    # Seeded fault: the controls' base imports the checkers' controls back, lazily.
    ("_control_base.py", "    if not _CASE:\n",
     "        from ._controls import positive_controls  # noqa: F401\n", "import cycle"),
])
def test_a_planted_fault_is_found(tmp_path, module, after, line, fault):
    root = _copy(tmp_path)
    _plant(root / module, after, line)
    assert layer_faults(_copy(tmp_path / "clean")) == []
    assert any(fault in f for f in layer_faults(root)), layer_faults(root)
