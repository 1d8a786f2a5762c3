"""`make lint` as the field does it (docs/contributing.md, "Lint"): mypy reads every package the
wheel installs, none of them silenced wholesale, and pytest turns warnings into errors. Checked
on pyproject.toml, and each rule on a copy with the fault it is there to catch."""

from __future__ import annotations

import copy
import tomllib
from pathlib import Path
from typing import Any

import pytest

PYPROJECT = Path(__file__).resolve().parents[1] / "pyproject.toml"

#: Override settings that hide a module's own errors (each of ours must be checked).
_SILENCING = {"follow_imports": ("silent", "skip"), "ignore_errors": (True,)}


def _listed(names: Any) -> list[str]:
    return [names] if isinstance(names, str) else list(names or ())


def _covered(module: str, packages: list[str], modules: list[str]) -> bool:
    """Whether mypy checks ``module``: named in ``modules`` or inside a package of ``packages``."""
    return module in modules or any(module == p or module.startswith(p + ".") for p in packages)


def lint_problems(doc: dict[str, Any]) -> list[str]:
    """What keeps [tool.mypy] and [tool.pytest.ini_options] from checking every package with
    warnings as errors, one line each ([] when nothing does)."""
    out: list[str] = []
    tool = doc.get("tool", {})
    installed = _listed(tool.get("setuptools", {}).get("packages"))
    mypy = tool.get("mypy", {})
    packages, modules = _listed(mypy.get("packages")), _listed(mypy.get("modules"))
    out += [f"mypy does not check the package {p}" for p in installed
            if not _covered(p, packages, modules)]
    for o in mypy.get("overrides", []):
        ours = [m for m in _listed(o.get("module")) if m == "cfmpa" or m.startswith("cfmpa.")]
        for key, bad in _SILENCING.items():
            if ours and o.get(key) in bad:
                out.append(f"an override sets {key} = {o[key]!r} for {', '.join(ours)}")
        if ours and o.get("ignore_missing_imports"):
            out.append(f"ignore_missing_imports (for untyped third-party code) on {ours}")
    warnings = _listed(tool.get("pytest", {}).get("ini_options", {}).get("filterwarnings"))
    if not warnings or warnings[0] != "error":
        out.append("pytest's filterwarnings does not start with \"error\"")
    out += [f"a filter {w!r} ignores every warning, not one by name" for w in warnings
            if w.split(":")[0] == "ignore" and not any(w.split(":")[1:])]
    return out


@pytest.fixture(scope="module")
def pyproject() -> dict[str, Any]:
    return tomllib.loads(PYPROJECT.read_text(encoding="utf-8"))


def test_the_lint_configuration_checks_every_package_with_warnings_as_errors(pyproject):
    assert lint_problems(pyproject) == []


def _mypy(doc: dict[str, Any]) -> dict[str, Any]:
    return doc["tool"]["mypy"]


def _drop_report(doc: dict[str, Any]) -> None:
    m = _mypy(doc)
    m["packages"] = ["cfmpa.spec", "cfmpa.impl", "cfmpa.runs", "cfmpa.proofs", "cfmpa.scenarios"]
    m["modules"] = ["cfmpa", "cfmpa.cli"]


def _silence_proofs(doc: dict[str, Any]) -> None:
    _mypy(doc).setdefault("overrides", []).append(
        {"module": ["cfmpa.proofs", "cfmpa.proofs.*"], "follow_imports": "silent"})


def _ignore_report_errors(doc: dict[str, Any]) -> None:
    _mypy(doc).setdefault("overrides", []).append({"module": "cfmpa.report.*",
                                                   "ignore_errors": True})


def _untyped_spec(doc: dict[str, Any]) -> None:
    _mypy(doc).setdefault("overrides", []).append({"module": ["z3", "cfmpa.spec"],
                                                   "ignore_missing_imports": True})


def _warnings_off(doc: dict[str, Any]) -> None:
    doc["tool"]["pytest"]["ini_options"].pop("filterwarnings", None)


def _ignore_all_warnings(doc: dict[str, Any]) -> None:
    ini = doc["tool"]["pytest"]["ini_options"]
    ini["filterwarnings"] = [*_listed(ini.get("filterwarnings")), "ignore::"]


@pytest.mark.parametrize("fault, said", [
    (_drop_report, "does not check the package cfmpa.report"),
    (_silence_proofs, "follow_imports = 'silent' for cfmpa.proofs"),
    (_ignore_report_errors, "ignore_errors = True for cfmpa.report.*"),
    (_untyped_spec, "ignore_missing_imports (for untyped third-party code) on ['cfmpa.spec']"),
    (_warnings_off, "does not start with \"error\""),
    (_ignore_all_warnings, "ignores every warning"),
])
def test_each_rule_catches_its_fault(pyproject, fault, said):
    doc = copy.deepcopy(pyproject)
    fault(doc)
    problems = lint_problems(doc)
    assert any(said in p for p in problems), problems


#: The proofs engine's modules (docs/contributing.md, "Lint"): checked at mypy --strict's level.
ENGINE = ("_obligation", "_runner", "_cvc5", "_smtlib", "_sos", "_depth", "_pins", "_controls",
          "_control_base", "_controls_wiring", "_registry", "_select", "_symexec", "_onterms",
          "_extract", "_while", "_lemmas", "_z3vec")
#: What --strict adds to the project's settings, each of which the engine's override must set.
STRICT = ("warn_return_any", "disallow_untyped_calls", "disallow_any_generics",
          "disallow_untyped_decorators", "disallow_subclassing_any")


def engine_not_strict(doc: dict[str, Any]) -> list[str]:
    """The engine modules and the strict settings no override of ``doc`` sets for them."""
    strict: dict[str, set[str]] = {}
    for o in doc["tool"]["mypy"].get("overrides", []):
        for m in _listed(o.get("module")):
            strict.setdefault(m, set()).update(k for k in STRICT if o.get(k) is True)
    return [f"cfmpa.proofs.{m}: {k}" for m in ENGINE for k in STRICT
            if k not in strict.get(f"cfmpa.proofs.{m}", set())]


def test_the_proofs_engine_is_checked_at_strict_level():
    doc = tomllib.loads(PYPROJECT.read_text())
    assert engine_not_strict(doc) == []
    assert all((Path(__file__).resolve().parents[1] / "proofs" / f"{m}.py").is_file()
               for m in ENGINE)
    # Seeded faults: a module dropped from the override, a setting turned off.
    dropped = copy.deepcopy(doc)
    o = next(o for o in dropped["tool"]["mypy"]["overrides"]
             if "cfmpa.proofs._runner" in _listed(o.get("module")))
    o["module"] = [m for m in o["module"] if m != "cfmpa.proofs._runner"]
    assert engine_not_strict(dropped) == [f"cfmpa.proofs._runner: {k}" for k in STRICT]
    off = copy.deepcopy(doc)
    o = next(o for o in off["tool"]["mypy"]["overrides"]
             if "cfmpa.proofs._runner" in _listed(o.get("module")))
    o["warn_return_any"] = False
    assert len(engine_not_strict(off)) == len(ENGINE)
