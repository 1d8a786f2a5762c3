"""The commit a record names (cfmpa.gitstate): a checkout's, only at the top of its work tree;
an installed package's, from the build record setup.py writes into the wheel; else None and why
(the wheel itself: tests/test_wheel.py, slow)."""

from __future__ import annotations

import json
import shutil
import subprocess
from pathlib import Path

import pytest

from cfmpa import gitstate
from cfmpa.gitstate import BUILD_INFO, build_info, git_state, package_state, source_commit

GIT = shutil.which("git")
needs_git = pytest.mark.skipif(GIT is None, reason="git is not installed")


def _repo(where: Path) -> str:
    def git(*a: str) -> str:
        return subprocess.run([GIT, "-C", str(where), *a], check=True, capture_output=True,
                              text=True).stdout.strip()
    git("init", "-q")
    (where / "f.txt").write_text("x")
    git("add", "f.txt")
    git("-c", "user.name=t", "-c", "user.email=t@t", "commit", "-q", "-m", "a")
    return git("rev-parse", "HEAD")


@needs_git
def test_a_folder_inside_a_checkout_is_not_that_checkout(tmp_path: Path) -> None:
    head = _repo(tmp_path)
    inner = tmp_path / "venv" / "site-packages"
    inner.mkdir(parents=True)
    assert git_state(tmp_path)["commit"] == head
    state = git_state(inner)
    assert state["available"] is False and state["commit"] is None
    assert "not the top of a git work tree" in state["note"]


@needs_git
def test_the_build_record_of_a_checkout_and_of_a_copy_without_git(tmp_path: Path) -> None:
    head = _repo(tmp_path)
    assert source_commit(tmp_path) == {"commit": head, "clean": True}
    (tmp_path / "new.txt").write_text("y")
    assert source_commit(tmp_path) == {"commit": head, "clean": False}
    copy = tmp_path.parent / (tmp_path.name + "-sdist")
    copy.mkdir()
    assert source_commit(copy) == {"commit": None, "clean": None,
                                   "why": "not built from a git checkout"}


def test_build_info_reads_the_record_and_says_why_a_bad_one_is_no_commit(tmp_path: Path) -> None:
    assert build_info(tmp_path) is None                                # no record at all
    rec = tmp_path / BUILD_INFO
    c = "0123456789abcdef" * 2 + "01234567"
    rec.write_text(json.dumps({"commit": c, "clean": True}))
    assert build_info(tmp_path) == {"commit": c, "clean": True}
    rec.write_text(json.dumps({"commit": None, "clean": None,
                               "why": "not built from a git checkout"}))
    assert build_info(tmp_path) == {"commit": None, "clean": None,
                                    "why": "not built from a git checkout"}
    for bad in ('{"commit": "HEAD", "clean": true}', "[1, 2]", "{not json"):
        rec.write_text(bad)
        got = build_info(tmp_path)
        assert got["commit"] is None and got["clean"] is None and BUILD_INFO in got["why"], bad


def test_an_installed_package_takes_its_commit_from_the_build_record(tmp_path: Path,
                                                                     monkeypatch) -> None:
    # The package outside any checkout (repo_root: a plain folder), its record in `pkg`.
    site, pkg = tmp_path / "site", tmp_path / "site" / "cfmpa"
    pkg.mkdir(parents=True)
    monkeypatch.setattr(gitstate, "repo_root", lambda: site)
    real = gitstate.build_info
    monkeypatch.setattr(gitstate, "build_info", lambda package=None: real(pkg))
    none = package_state()
    assert none["commit"] is None and "holds no build record" in none["note"]
    c = "ab" * 20
    (pkg / BUILD_INFO).write_text(json.dumps({"commit": c, "clean": False}))
    state = package_state()
    assert (state["available"], state["commit"], state["clean"]) == (False, c, False)
    assert state["note"].startswith(f"installed package built from commit {c} (a work tree "
                                    "with local changes)")
    (pkg / BUILD_INFO).write_text(json.dumps({"commit": None, "why": "not built from a git "
                                              "checkout"}))
    state = package_state()
    assert state["commit"] is None
    assert state["note"] == "installed package: not built from a git checkout"


def test_this_checkout_reads_git_not_a_build_record() -> None:
    state = package_state()
    if GIT is None or not (gitstate.repo_root() / ".git").exists():
        pytest.skip("not run from a git checkout")
    assert state["available"] is True and len(state["commit"]) == 40
