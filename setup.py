"""Build hook (the project's metadata is in pyproject.toml): a wheel records the commit it was
built from, and carries docs/model.md, the model the command line's help cites, as
cfmpa/docs/model.md (`cfmpa docs` prints where it is). build_py writes cfmpa/_build_info.json
into the build (never into the source tree): the checkout's commit and whether it was clean, or
commit null and why (built from an sdist or a copy without .git). An installed package reads it
through cfmpa.gitstate.package_state; a checkout or an editable install reads git itself."""

from __future__ import annotations

import importlib.util
import json
from pathlib import Path

from setuptools import setup
from setuptools.command.build_py import build_py

HERE = Path(__file__).resolve().parent


def _gitstate():
    # cfmpa/gitstate.py by path: the package itself cannot be imported before it is built.
    spec = importlib.util.spec_from_file_location("_cfmpa_gitstate", HERE / "cfmpa" / "gitstate.py")
    mod = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(mod)
    return mod


class BuildPyWithCommit(build_py):
    def run(self) -> None:
        super().run()
        if getattr(self, "editable_mode", False):
            return                  # an editable install runs from the checkout: git says it
        gs = _gitstate()
        target = Path(self.build_lib) / "cfmpa" / gs.BUILD_INFO
        target.parent.mkdir(parents=True, exist_ok=True)
        target.write_text(json.dumps(gs.source_commit(HERE)) + "\n", encoding="utf-8")
        model = HERE / "docs" / "model.md"
        if model.is_file():         # an sdist carries it too (MANIFEST.in)
            doc = Path(self.build_lib) / "cfmpa" / "docs" / "model.md"
            doc.parent.mkdir(parents=True, exist_ok=True)
            doc.write_bytes(model.read_bytes())


setup(cmdclass={"build_py": BuildPyWithCommit})
