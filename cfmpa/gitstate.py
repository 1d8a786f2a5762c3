"""The git state of a work tree (commit, clean or which paths differ), for records a reviewer reads:
the audit report's provenance and results.json of a prove run."""

from __future__ import annotations

import subprocess
from pathlib import Path
from typing import Any

__all__ = ["MAX_PATHS", "git_state", "repo_root"]

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


def repo_root() -> Path:
    """The folder that holds this checkout of cfmpa (the package's parent)."""
    return Path(__file__).resolve().parents[1]
