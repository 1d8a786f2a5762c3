"""`cfmpa scenarios`: the bundled workcells listed with their grid size and purpose."""

from __future__ import annotations

import sys
import textwrap
from typing import TextIO

from ..scenarios import BUNDLED_DIR, bundled_names
from ..spec import load_scenario, make_grid

__all__ = ["run_scenarios"]

#: The listing's width: a purpose is wrapped under its name.
WIDTH = 100


def run_scenarios(*, stdout: TextIO | None = None) -> int:
    """Print each bundled scenario's name, time step, grid size and purpose; 0."""
    so = sys.stdout if stdout is None else stdout
    print(f"bundled scenarios in {BUNDLED_DIR} (give the name or a path to any command)", file=so)
    for name in bundled_names():
        s = load_scenario(BUNDLED_DIR / f"{name}.toml")
        g = make_grid(s)
        print(f"{name:<16} dt={s.dt:g} s  grid N={g.N} m={g.m} n={g.n}", file=so)
        # The purpose wrapped under the name: no line of the listing is wider than WIDTH.
        print(textwrap.fill(s.purpose, WIDTH, initial_indent=" " * 17,
                            subsequent_indent=" " * 17), file=so)
    return 0
