"""Provenance of a report: tool and library versions, git commit and cleanliness, command, date."""

from __future__ import annotations

import datetime as _dt
import importlib.metadata as _metadata
import shlex
import subprocess
import sys
from collections.abc import Sequence
from pathlib import Path
from typing import Any

__all__ = ["REPORTED_DISTRIBUTIONS", "git_state", "library_versions", "provenance"]

#: Seconds allowed for each git call; a hung git must not hang the report.
GIT_TIMEOUT_S = 10
#: Modified or untracked paths listed in the provenance; the rest are counted.
MAX_PATHS = 20


def git_state(where: Path) -> dict[str, Any]:
    """Commit, and whether the work tree was clean (no modified, staged or untracked files);
    when not, which paths (``git status`` codes, the first MAX_PATHS) and how many more."""
    def git(*args: str) -> str | None:
        try:
            out = subprocess.run(["git", "-C", str(where), *args], capture_output=True, text=True,
                                 timeout=GIT_TIMEOUT_S, check=False)
        except (OSError, subprocess.TimeoutExpired):
            return None
        return out.stdout if out.returncode == 0 else None

    commit = git("rev-parse", "HEAD")
    if commit is None:
        return {"available": False, "commit": None, "clean": None, "modified": None,
                "untracked": None, "paths": [], "paths_omitted": 0,
                "note": f"{where} is not in a git work tree (or git is missing)"}
    status = git("status", "--porcelain") or ""
    lines = [ln for ln in status.splitlines() if ln.strip()]
    untracked = sum(1 for ln in lines if ln.startswith("??"))
    modified = len(lines) - untracked
    # Which files differ, not just how many: a reviewer can tell an edited spec from a stray log.
    paths = [{"status": ln[:2].strip() or "?", "path": ln[3:]} for ln in lines[:MAX_PATHS]]
    omitted = len(lines) - len(paths)
    note = "clean" if not lines else (f"{modified} modified/staged, {untracked} untracked"
                                      + (f"; the first {len(paths)} listed" if omitted else ""))
    return {"available": True, "commit": commit.strip(), "clean": not lines,
            "modified": modified, "untracked": untracked, "paths": paths,
            "paths_omitted": omitted, "note": note}


#: Distributions besides those of ``cfmpa.proofs._plan.versions`` whose version the report gives:
#: the prover's second engine (sympy), the fast kernels' compiler (numba on llvmlite), and what
#: draws and writes the report (matplotlib with Pillow, Jinja2).
REPORTED_DISTRIBUTIONS = {"sympy": "sympy", "numba": "numba", "llvmlite": "llvmlite",
                          "matplotlib": "matplotlib", "pillow": "pillow", "jinja2": "jinja2"}


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
    from ..proofs._plan import versions

    v = versions()
    v.update(library_versions())
    args = list(sys.argv if argv is None else argv)
    repo = Path(__file__).resolve().parents[2]
    return {
        "tool": "cfmpa",
        "version": v["cfmpa"],
        "versions": dict(sorted(v.items())),
        "git": git_state(repo),
        "command_line": shlex.join(args),
        "date_utc": _dt.datetime.now(_dt.timezone.utc).isoformat(timespec="seconds"),
        "scenarios": [{"name": s.name, "path": s.source, "sha256": s.sha256} for s in scenarios],
    }
