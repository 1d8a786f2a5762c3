"""Variant logic asks the rule, never the name (docs/model.md §4.1): no code of the packages
compares a variant with a variant's name (``v == "tight"``, ``v in ("original", ...)``,
``v is Variant.MODIFIED``); it reads the field of spec.Variant's rule it needs (``rest_at_goal``,
``within``, ``theorems``, ...), so that another variant is one row of the rule table. Seeded
fault: a planted comparison is found, naming file:line."""

from __future__ import annotations

import ast
from pathlib import Path

from cfmpa.spec import Variant

ROOT = Path(__file__).resolve().parents[1]
PACKAGES = ("spec", "impl", "proofs", "runs", "report", "cfmpa")
NAMES = {v.value for v in Variant}
MEMBERS = {v.name for v in Variant}

#: Files that still compare names, each with the reason (empty them as they move to the rule).
ALLOWED = {
    # the safety theorem's modules (docs/model.md §10): their rest layer by name, and a test
    # mutant that mirrors the modified box; to read Variant.rest_at_goal / the rule's words
    "proofs/_obl_safety_principal.py": "safety: the sign-flip test mutant picks modified",
    # presentation: which found plan the pictures draw first (the paper's modified)
    "report/_audit.py": "the pictures' preferred plan",
}


def _names_a_variant(e: ast.expr) -> bool:
    if isinstance(e, ast.Constant):
        return e.value in NAMES
    if isinstance(e, (ast.Tuple, ast.List, ast.Set)):
        return any(_names_a_variant(x) for x in e.elts)
    return (isinstance(e, ast.Attribute) and isinstance(e.value, ast.Name)
            and e.value.id == "Variant" and e.attr in MEMBERS)


def name_comparisons(source: str, where: str) -> list[str]:
    """``where:line: the comparison`` for each comparison in ``source`` with a variant's name."""
    out = []
    for node in ast.walk(ast.parse(source)):
        if isinstance(node, ast.Compare) and any(
                _names_a_variant(x) for x in (node.left, *node.comparators)):
            out.append(f"{where}:{node.lineno}: {ast.unparse(node)}")
    return out


def test_no_package_compares_a_variant_with_its_name():
    found = []
    for package in PACKAGES:
        for path in sorted((ROOT / package).rglob("*.py")):
            rel = path.relative_to(ROOT).as_posix()
            if rel not in ALLOWED:
                found += name_comparisons(path.read_text(encoding="utf-8"), rel)
    assert not found, "ask the variant's rule (spec.Variant.rule) instead:\n" + "\n".join(found)


def test_a_planted_name_comparison_is_found():
    planted = ("def f(variant, rule, v):\n"
               "    a = region_rest() if rule.rest_at_goal else None\n"
               "    b = variant == 'tight'\n"
               "    c = v.value in ('original', 'modified')\n"
               "    d = v is Variant.TIGHT\n")
    assert name_comparisons(planted, "x.py") == [
        "x.py:3: variant == 'tight'", "x.py:4: v.value in ('original', 'modified')",
        "x.py:5: v is Variant.TIGHT"]
