"""The bundled workcells (``*.toml``), shipped with the package as ``cfmpa.scenarios``.

A command that takes a scenario accepts a bundled name (``default``) or a path; see
docs/model.md §3 for the file format.
"""

from __future__ import annotations

from pathlib import Path

__all__ = ["BUNDLED_DIR", "bundled_names", "resolve"]

#: Where the bundled files are: the checkout's scenarios/ or, installed, the package's folder.
BUNDLED_DIR = Path(__file__).resolve().parent


def bundled_names() -> tuple[str, ...]:
    """The stems of the bundled scenario files, sorted."""
    return tuple(sorted(p.stem for p in BUNDLED_DIR.glob("*.toml")))


def resolve(arg: str | Path) -> Path:
    """``arg`` as a path if it names an existing file (or has a folder or a .toml suffix), else
    the bundled file of that name when there is one; otherwise ``arg`` unchanged, so that the
    loader reports the missing file by the name the user gave."""
    p = Path(arg)
    if p.exists() or p.suffix == ".toml" or len(p.parts) != 1:
        return p
    bundled = BUNDLED_DIR / f"{p.name}.toml"
    return bundled if bundled.is_file() else p
