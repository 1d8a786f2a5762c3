"""Provenance of a report: tool and library versions, git commit and cleanliness (of the checkout,
or as an installed wheel recorded them when it was built), command, date."""

from __future__ import annotations

import datetime as _dt
import importlib.metadata as _metadata
import shlex
import sys
from collections.abc import Sequence
from typing import Any

from ..gitstate import git_state, package_state

__all__ = ["REPORTED_DISTRIBUTIONS", "VERSION_GROUPS", "git_state", "library_versions",
           "provenance"]

#: Distributions besides those of ``cfmpa.runs.versions`` (Python, numpy, shapely, Z3) whose
#: version the report gives (key -> distribution name): the second SMT solver, which replays
#: every VC (cvc5), the exact symbolic engine (sympy), the ball arithmetic of the exact
#: re-decision (python-flint), the fast kernels' compiler (numba on llvmlite), and what draws
#: and writes the report (matplotlib with Pillow, Jinja2).
REPORTED_DISTRIBUTIONS = {"cvc5": "cvc5", "sympy": "sympy", "python-flint": "python-flint",
                          "numba": "numba", "llvmlite": "llvmlite", "matplotlib": "matplotlib",
                          "pillow": "pillow", "jinja2": "jinja2"}

#: How the provenance table groups the versions (docs/model.md §8): every key of
#: ``provenance.versions`` is in exactly one group (tested).
VERSION_GROUPS: tuple[tuple[str, tuple[str, ...]], ...] = (
    ("tool", ("cfmpa", "python")),
    ("solvers", ("z3", "cvc5", "sympy")),
    ("numerics", ("numpy", "shapely", "python-flint", "numba", "llvmlite")),
    ("report", ("matplotlib", "pillow", "jinja2")),
)


def library_versions() -> dict[str, str]:
    """Installed versions of REPORTED_DISTRIBUTIONS, read from package metadata (no import)."""
    out = {}
    for key, dist in REPORTED_DISTRIBUTIONS.items():
        try:
            out[key] = _metadata.version(dist)
        except _metadata.PackageNotFoundError:
            out[key] = "not installed"
    return out


def provenance(argv: Sequence[str] | None, scenarios: Sequence[Any]) -> dict[str, Any]:
    """The report's provenance header; ``scenarios`` are validated Scenario values."""
    from ..runs import versions

    v = versions()
    v.update(library_versions())
    args = list(sys.argv if argv is None else argv)
    return {
        "tool": "cfmpa",
        "version": v["cfmpa"],
        "versions": dict(sorted(v.items())),
        # The checkout's state, or an installed wheel's build record (cfmpa.gitstate).
        "git": package_state(),
        "command_line": shlex.join(args),
        "date_utc": _dt.datetime.now(_dt.UTC).isoformat(timespec="seconds"),
        "scenarios": [{"name": s.name, "path": s.source, "sha256": s.sha256} for s in scenarios],
    }
