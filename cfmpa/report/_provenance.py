"""Provenance of a report: tool and library versions, git commit and cleanliness, command, date."""

from __future__ import annotations

import datetime as _dt
import shlex
import subprocess
import sys
from collections.abc import Sequence
from pathlib import Path
from typing import Any

__all__ = ["provenance", "git_state"]

#: Seconds allowed for each git call; a hung git must not hang the report.
GIT_TIMEOUT_S = 10


def git_state(where: Path) -> dict[str, Any]:
    """Commit, and whether the work tree was clean (no modified, staged or untracked files)."""
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
                "untracked": None, "note": f"{where} is not in a git work tree (or git is missing)"}
    status = git("status", "--porcelain") or ""
    lines = [ln for ln in status.splitlines() if ln.strip()]
    untracked = sum(1 for ln in lines if ln.startswith("??"))
    modified = len(lines) - untracked
    return {"available": True, "commit": commit.strip(), "clean": not lines,
            "modified": modified, "untracked": untracked,
            "note": "clean" if not lines else f"{modified} modified/staged, {untracked} untracked"}


def provenance(argv: Sequence[str] | None, scenarios: Sequence[Any]) -> dict[str, Any]:
    """The report's provenance header; ``scenarios`` are validated Scenario values."""
    import jinja2
    import matplotlib

    from ..proofs._plan import versions

    v = versions()
    v.update({"matplotlib": matplotlib.__version__, "jinja2": jinja2.__version__})
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
