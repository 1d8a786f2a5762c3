"""The package as a user installs it: a wheel in a fresh virtual environment, run outside the
checkout, knows the commit it was built from (setup.py's build record), plans a bundled scenario
and proves every obligation, recording that commit (slow: CI runs it once)."""

from __future__ import annotations

import json
import subprocess
import sys
import sysconfig
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
#: The checkout's commit and cleanliness as the build saw them (read when the wheel is built).
BUILT_FROM: dict = {}

pytestmark = pytest.mark.slow


def _run(args: list[str], cwd: Path, timeout: float = 900) -> subprocess.CompletedProcess[str]:
    return subprocess.run(args, cwd=cwd, capture_output=True, text=True, timeout=timeout,
                          check=False)


@pytest.fixture(scope="module")
def venv(tmp_path_factory: pytest.TempPathFactory) -> Path:
    where = tmp_path_factory.mktemp("wheel")
    head = _run(["git", "-C", str(ROOT), "rev-parse", "HEAD"], cwd=where)
    status = _run(["git", "-C", str(ROOT), "status", "--porcelain"], cwd=where)
    BUILT_FROM.update(commit=head.stdout.strip() if head.returncode == 0 else None,
                      clean=not status.stdout.strip() if head.returncode == 0 else None)
    built = _run([sys.executable, "-m", "pip", "wheel", "--no-deps", "-q", "-w", str(where),
                  str(ROOT)], cwd=where)
    assert built.returncode == 0, built.stderr
    (wheel,) = where.glob("cfmpa-*.whl")
    env = where / "venv"
    assert _run([sys.executable, "-m", "venv", str(env)], cwd=where).returncode == 0
    inst = _run([str(env / "bin" / "python"), "-m", "pip", "install", "-q", str(wheel)], cwd=where)
    assert inst.returncode == 0, inst.stderr
    return env


def test_the_wheel_installs_one_package_with_its_scenarios(venv: Path):
    out = _run([str(venv / "bin" / "python"), "-c",
                "import sysconfig; print(sysconfig.get_paths()['purelib'])"], cwd=venv)
    site = Path(out.stdout.strip())
    assert not (site / "spec").exists() and not (site / "impl").exists()
    names = sorted(p.name for p in (site / "cfmpa").iterdir() if p.is_dir())
    for pkg in ("impl", "proofs", "report", "runs", "scenarios", "spec"):
        assert pkg in names, names
    assert (site / "cfmpa" / "scenarios" / "default.toml").is_file()
    assert sysconfig.get_paths()["purelib"] != str(site)      # not this interpreter's own


def test_the_installed_package_knows_the_commit_it_was_built_from(venv: Path, tmp_path: Path):
    import zipfile

    (wheel,) = venv.parent.glob("cfmpa-*.whl")
    with zipfile.ZipFile(wheel) as z:
        record = json.loads(z.read("cfmpa/_build_info.json"))
    if BUILT_FROM["commit"] is None:
        assert record == {"commit": None, "clean": None, "why": "not built from a git checkout"}
    else:
        assert record == BUILT_FROM
    out = _run([str(venv / "bin" / "python"), "-c",
                "import json; from cfmpa.gitstate import package_state; "
                "print(json.dumps(package_state()))"], cwd=tmp_path)
    assert out.returncode == 0, out.stderr
    state = json.loads(out.stdout)
    assert state["available"] is False                     # no work tree: a build record
    assert (state["commit"], state["clean"]) == (record["commit"], record["clean"])
    assert (f"built from commit {record['commit']}" if record["commit"] else
            "not built from a git checkout") in state["note"]


def test_plan_and_prove_run_from_an_unrelated_folder(venv: Path, tmp_path: Path):
    cfmpa = str(venv / "bin" / "cfmpa")
    listed = _run([cfmpa, "scenarios"], cwd=tmp_path)
    assert listed.returncode == 0, listed.stderr
    assert "default" in listed.stdout and "early-arrival" in listed.stdout
    planned = _run([cfmpa, "plan", "default", "--out", "out"], cwd=tmp_path)
    assert planned.returncode == 0, planned.stderr
    doc = json.loads((tmp_path / "out" / "plan.json").read_text())
    assert doc["status"] == "found" and doc["scenario"] == "default" and doc["J1"] > 0
    proved = _run([cfmpa, "prove", "--out", "proofs"], cwd=tmp_path)
    assert proved.returncode == 0, proved.stdout[-3000:] + proved.stderr[-3000:]
    results = json.loads((tmp_path / "proofs" / "results.json").read_text())
    ids = [r["id"] for r in results["obligations"]]
    assert "Scenario.default.containment" in ids
    # The prove run records the commit the wheel was built from, not None.
    assert results["run"]["git"]["commit"] == BUILT_FROM["commit"]


def test_the_wheel_carries_docs_model_md_and_cfmpa_docs_prints_where(venv: Path, tmp_path: Path):
    # The help cites docs/model.md: the wheel carries it (setup.py's build_py), and
    # `cfmpa docs` prints where it is installed, from any folder.
    import zipfile

    (wheel,) = venv.parent.glob("cfmpa-*.whl")
    with zipfile.ZipFile(wheel) as z:
        assert z.read("cfmpa/docs/model.md") == (ROOT / "docs" / "model.md").read_bytes()
    out = _run([str(venv / "bin" / "cfmpa"), "docs"], cwd=tmp_path)
    assert out.returncode == 0, out.stderr
    path = Path(out.stdout.strip())
    assert path.parts[-3:] == ("cfmpa", "docs", "model.md") and venv in path.parents
    assert path.read_text(encoding="utf-8").startswith("# The cfmpa model")
