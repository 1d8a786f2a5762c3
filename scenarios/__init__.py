"""The bundled workcells (``*.toml``), shipped with the package as ``cfmpa.scenarios``.

A command that takes a scenario accepts a bundled name (``default``) or a path; see
docs/model.md §3 for the file format.
"""

from __future__ import annotations

from pathlib import Path
from typing import Any

__all__ = ["BUNDLED_DIR", "SELFCHECK_WORKCELLS", "bundled_names", "resolve"]

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


_ARM = {"links": [0.35, 0.30], "width": 0.06, "omega": [1.0, 1.0]}
_TWO_PI = [0.0, 6.283185307179586]

#: Built-in workcells of the self-checks (``cfmpa selftest``, the negative controls of
#: ``cfmpa prove``), as scenario documents (docs/model.md §3): small enough for seconds.
SELFCHECK_WORKCELLS: dict[str, dict[str, Any]] = {
    "small": {
        "name": "selftest-small", "dt": 0.25,
        "purpose": "the default workcell at dt = 0.25 s, with a path of 15 cells (longer than N)",
        "left": {**_ARM, "base": [0.0, 0.0], "start": [0.3, 0.8], "goal": [1.6, 2.2]},
        "right": {**_ARM, "base": [0.6, 0.0], "limits": [_TWO_PI, _TWO_PI],
                  "start_cell": [2, 8], "goal_cell": [13, 5]},
    },
    "early-arrival": {
        "name": "selftest-early-arrival", "dt": 0.11,
        "purpose": "scenarios/early-arrival.toml at dt = 0.11 s: the shortest list reaches the "
                   "goal before the principal swings through it",
        "left": {**_ARM, "base": [0.0, 0.0], "start": [-0.8, 0.0], "goal": [0.8, 0.0]},
        "right": {**_ARM, "base": [0.9, 0.0], "limits": [_TWO_PI, _TWO_PI],
                  "start_cell": [27, 0], "goal_cell": [29, 0]},
    },
}
