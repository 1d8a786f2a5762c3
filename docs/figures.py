"""Regenerate the pictures in docs/ from the bundled scenarios: `.venv/bin/python docs/figures.py`.

docs/default-cspace.png: the default workcell's D_R layers (modified variant) with the optimal
path, the picture the README points to.
"""

from __future__ import annotations

from pathlib import Path

from cfmpa.files import write_bytes_atomic
from cfmpa.report import cspace_figure
from cfmpa.runs import plan
from cfmpa.scenarios import resolve
from cfmpa.spec import Variant, load_scenario

HERE = Path(__file__).resolve().parent


def main() -> None:
    s = load_scenario(resolve("default"))
    p = plan(s, Variant.MODIFIED)
    fig = cspace_figure("default-cspace", s, p.grid, p.dr, p.search.path, Variant.MODIFIED)
    out = write_bytes_atomic(HERE / "default-cspace.png", fig.png)
    print(f"wrote {out} (J1={p.search.J1}, J2={p.search.J2}, {len(p.search.path)} cells)")


if __name__ == "__main__":
    main()
