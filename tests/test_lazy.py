"""The package faces list each public name once (cfmpa.lazy, docs/model.md §1.1): the
``if TYPE_CHECKING:`` block of ``from ._module import name as name`` is what the type checker
exports and what the run time serves, and ``__all__`` is read from it. Seeded faults: a face
whose block imports a name in another form, twice, or holds anything else is refused, naming
file:line; a name added to a planted package's block is served with no second list."""

from __future__ import annotations

import importlib
import re
import sys
from pathlib import Path

import pytest

import cfmpa.lazy
from cfmpa.lazy import face_exports

ROOT = Path(__file__).resolve().parents[1]
FACES = {"spec": "cfmpa.spec", "impl": "cfmpa.impl", "report": "cfmpa.report",
         "runs": "cfmpa.runs"}

HEAD = "from typing import TYPE_CHECKING\n\nif TYPE_CHECKING:\n"
TAIL = "\nfrom cfmpa.lazy import lazy_face\n__getattr__, __dir__, __all__ = lazy_face(__name__, __file__)\n"


def _face(tmp_path: Path, block: str) -> Path:
    path = tmp_path / "__init__.py"
    path.write_text(HEAD + block + TAIL)
    return path


@pytest.mark.parametrize("folder", sorted(FACES))
def test_each_face_is_one_list(folder):
    pkg = importlib.import_module(FACES[folder])
    exports = face_exports(ROOT / folder / "__init__.py")
    assert pkg.__all__ == sorted(exports)
    assert "_EXPORTS" not in vars(pkg)
    # The one list in the source: each public name appears once as an import target.
    text = (ROOT / folder / "__init__.py").read_text()
    for name in exports:
        assert len(re.findall(rf"(?<![\w.]){name} as {name}\b", text)) == 1, name


@pytest.mark.parametrize("block, expected", [
    ("    from ._a import x\n", "__init__.py:4: 'x' is imported without `as x`"),
    ("    from ._a import x as y\n", "__init__.py:4: 'x' is imported without `as x`"),
    ("    from ._a import x as x\n    from ._b import x as x\n", "__init__.py:5: 'x' is listed twice"),
    ("    import os\n", "__init__.py:4: a face's TYPE_CHECKING block holds only"),
    ("    from cfmpa.spec import EPS as EPS\n", "__init__.py:4: a face's TYPE_CHECKING block"),
    ("    X = 1\n", "__init__.py:4: a face's TYPE_CHECKING block holds only"),
])
def test_a_face_in_another_form_is_refused(tmp_path, block, expected):
    with pytest.raises(ImportError) as err:
        face_exports(_face(tmp_path, block))
    assert expected in str(err.value)


def test_a_face_without_its_block_is_refused(tmp_path):
    path = tmp_path / "__init__.py"
    path.write_text("from ._a import x\n__all__ = ['x']\n")
    with pytest.raises(ImportError, match="no `if TYPE_CHECKING:` block"):
        face_exports(path)


def test_the_face_reader_is_bounded(tmp_path, monkeypatch):
    path = _face(tmp_path, "    from ._a import x as x\n")
    monkeypatch.setattr(cfmpa.lazy, "MAX_FACE_BYTES", 40)
    with pytest.raises(ImportError, match="over 40 bytes"):
        face_exports(path)


def test_a_name_added_to_the_block_is_served(tmp_path, monkeypatch):
    pkg = tmp_path / "planted_face_pkg"
    pkg.mkdir()
    (pkg / "_a.py").write_text("x = 1\ny = 2\n")
    (pkg / "_b.py").write_text("z = 3\n")
    _face(pkg, "    from ._a import x as x, y as y\n    from ._b import z as z\n")
    monkeypatch.syspath_prepend(str(tmp_path))
    try:
        mod = importlib.import_module("planted_face_pkg")
        assert mod.__all__ == ["x", "y", "z"]
        assert "planted_face_pkg._b" not in sys.modules          # imported on first use
        assert (mod.x, mod.y, mod.z) == (1, 2, 3)
        assert "planted_face_pkg._b" in sys.modules
        assert {"x", "y", "z"} <= set(dir(mod))
        assert mod._a is sys.modules["planted_face_pkg._a"]     # a private module, as import
        with pytest.raises(AttributeError):
            mod.w  # noqa: B018
    finally:
        for name in [m for m in sys.modules if m.startswith("planted_face_pkg")]:
            del sys.modules[name]
