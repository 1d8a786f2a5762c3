"""The git state of a work tree (commit, clean or which paths differ), for records a reviewer reads:
the audit report's provenance and results.json of a prove run; and the commit an installed
package was built from (``BUILD_INFO``, written by setup.py's build_py), for a package that is
not in a checkout of its own."""

from __future__ import annotations

import json
import subprocess
from pathlib import Path
from typing import Any

__all__ = ["BUILD_INFO", "MAX_PATHS", "build_info", "git_state", "package_state", "repo_root",
           "source_commit"]

#: Seconds allowed for each git call; a hung git must not hang the report.
GIT_TIMEOUT_S = 10
#: Modified or untracked paths listed in the provenance; the rest are counted.
MAX_PATHS = 20
#: The build record's name in the installed package (setup.py writes it into the wheel):
#: {"commit": "<40 hex>", "clean": true|false} or {"commit": null, "clean": null, "why": "..."}.
BUILD_INFO = "_build_info.json"


def _git(where: Path, *args: str) -> str | None:
    try:
        out = subprocess.run(["git", "-C", str(where), *args], capture_output=True, text=True,
                             timeout=GIT_TIMEOUT_S, check=False)
    except (OSError, subprocess.TimeoutExpired):
        return None
    return out.stdout if out.returncode == 0 else None


def _toplevel_is(where: Path) -> bool:
    """Whether ``where`` is the top of its git work tree: a folder merely inside another
    checkout (site-packages of a virtual environment kept in one) is not that checkout."""
    top = _git(where, "rev-parse", "--show-toplevel")
    return top is not None and Path(top.strip()).resolve() == where.resolve()


def git_state(where: Path) -> dict[str, Any]:
    """Commit, and whether the work tree was clean (no modified, staged or untracked files);
    when not, which paths (``git status`` codes, the first MAX_PATHS) and how many more.
    ``where`` must be the top of its work tree, else it counts as no work tree."""
    commit = _git(where, "rev-parse", "HEAD") if _toplevel_is(where) else None
    if commit is None:
        return {"available": False, "commit": None, "clean": None, "modified": None,
                "untracked": None, "paths": [], "paths_omitted": 0,
                "note": f"{where} is not the top of a git work tree (or git is missing)"}
    status = _git(where, "status", "--porcelain") or ""
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


def source_commit(where: Path) -> dict[str, Any]:
    """The build record for the source tree at ``where`` (setup.py calls this when it builds a
    wheel): its commit and cleanliness, or commit None and why."""
    state = git_state(where)
    if not state["available"]:
        return {"commit": None, "clean": None, "why": "not built from a git checkout"}
    return {"commit": state["commit"], "clean": state["clean"]}


def build_info(package: Path | None = None) -> dict[str, Any] | None:
    """The build record of the installed package (``package``: its folder, default this one's),
    None when it has none (a checkout, an editable install); an unreadable or malformed record
    is a record of an unknown commit, saying why."""
    path = (package or Path(__file__).resolve().parent) / BUILD_INFO
    try:
        doc = json.loads(path.read_text(encoding="utf-8"))
    except FileNotFoundError:
        return None
    except (OSError, ValueError) as exc:
        return {"commit": None, "clean": None, "why": f"{path} is unreadable ({exc})"}
    commit = doc.get("commit") if isinstance(doc, dict) else None
    if not (isinstance(commit, str) and len(commit) >= 40
            and all(c in "0123456789abcdef" for c in commit)):
        why = doc.get("why") if isinstance(doc, dict) and commit is None else None
        return {"commit": None, "clean": None,
                "why": why if isinstance(why, str) and why else
                f"{path} records no commit ({str(doc)[:80]})"}
    clean = doc.get("clean")
    return {"commit": commit, "clean": clean if isinstance(clean, bool) else None}


def package_state() -> dict[str, Any]:
    """The state of the code that runs, as ``git_state`` gives it: the checkout's when the package
    is in one (``repo_root``), else the commit its build recorded (``available`` False: no work
    tree to list), else commit None and why it is unknown."""
    root = repo_root()
    state = git_state(root)
    if state["available"]:
        return state
    info = build_info()
    if info is None:
        state["note"] += "; the package holds no build record (an install not from a wheel)"
        return state
    if info["commit"] is None:
        state["note"] = f"installed package: {info['why']}"
        return state
    clean = {True: "a clean work tree", False: "a work tree with local changes",
             None: "a work tree of unknown state"}[info["clean"]]
    return {**state, "commit": info["commit"], "clean": info["clean"],
            "note": f"installed package built from commit {info['commit']} ({clean}); "
                    f"no work tree to list"}


def repo_root() -> Path:
    """The folder that holds this checkout of cfmpa (the package's parent)."""
    return Path(__file__).resolve().parents[1]
