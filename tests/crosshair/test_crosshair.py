"""CrossHair searches the contracts of targets.py for counterexamples (none may be found) and
those of mutants.py, seeded faults in copies of the same functions (each must be found)."""

from __future__ import annotations

import ast
import re
import subprocess
import sys
from pathlib import Path

import pytest

HERE = Path(__file__).resolve().parent
CROSSHAIR = [sys.executable, "-m", "crosshair", "check", "--analysis_kind=asserts",
             "--per_condition_timeout=20", "--per_path_timeout=4"]


def _functions(path: Path) -> list[ast.FunctionDef]:
    return [n for n in ast.parse(path.read_text()).body
            if isinstance(n, ast.FunctionDef) and not n.name.startswith("_")]


@pytest.mark.parametrize("name", ["targets.py", "mutants.py"])
def test_every_contract_leads_with_its_preconditions(name: str):
    # CrossHair skips, silently, a function whose body does not start with an assert (after the
    # docstring): such a contract would be checked by nobody.
    for fn in _functions(HERE / name):
        body = [s for s in fn.body if not (isinstance(s, ast.Expr)
                                           and isinstance(s.value, ast.Constant))]
        assert isinstance(body[0], ast.Assert), f"{name}:{fn.lineno}: {fn.name}"


def _check(name: str) -> subprocess.CompletedProcess[str]:
    return subprocess.run([*CROSSHAIR, str(HERE / name)], capture_output=True, text=True,
                          timeout=1200, check=False, cwd=HERE)


@pytest.mark.slow
def test_crosshair_finds_no_counterexample_to_the_contracts():
    proc = _check("targets.py")
    assert proc.returncode == 0 and "error" not in proc.stdout, proc.stdout + proc.stderr


@pytest.mark.slow
def test_crosshair_finds_every_seeded_fault():
    proc = _check("mutants.py")
    lines = {int(m.group(1)) for m in re.finditer(r"mutants\.py:(\d+): error", proc.stdout)}
    found = {fn.name for fn in _functions(HERE / "mutants.py")
             if any(fn.lineno <= ln <= (fn.end_lineno or fn.lineno) for ln in lines)}
    expected = {fn.name for fn in _functions(HERE / "mutants.py")}
    assert found == expected, (expected - found, proc.stdout)
