"""What the full contracts share to be fast (docs/model.md §7): the right link-2 and tool
regions' first-row hulls are made once per check, not once per block of rows, and the blocks
built from the shared row are the blocks built alone; the exact re-decision's float hulls are
made once per region, and its ball ends are the balls' (a Z3 term, which the proofs pass, stays
itself). Seeded faults: a shared row of another part, and an end taken at the ball's middle,
are caught."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
from flint import arb

from cfmpa.spec import load_scenario, make_grid
from cfmpa.spec._builtdr_post import TOOL, _Link2, _row0
from cfmpa.spec._exact import _lower, _upper

ROOT = Path(__file__).resolve().parents[2]
FIELDS = ("hx", "hy", "nx", "ny", "offset", "box", "q0", "d", "u", "v", "ext", "core")


def _same(a: _Link2, b: _Link2) -> bool:
    def parts(x: object) -> list[object]:
        return list(x) if isinstance(x, tuple) else [x]

    return a.flat == b.flat and all(
        len(parts(getattr(a, f))) == len(parts(getattr(b, f)))
        and all(np.array_equal(p, q) for p, q in zip(parts(getattr(a, f)), parts(getattr(b, f))))
        for f in FIELDS)


@pytest.fixture(scope="module")
def gripper():
    """The bundled workcell whose subordinate carries a tool (its link 2 and its tool)."""
    s = load_scenario(ROOT / "scenarios" / "gripper.toml")
    assert s.right.tool is not None
    return s, make_grid(s)


@pytest.mark.parametrize("part", [1, TOOL])
def test_a_block_from_the_shared_first_row_is_the_block_built_alone(gripper, part):
    s, g = gripper
    i0, i1 = g.m // 3, g.m // 3 + 4
    alone = _Link2(s, g, i0, i1, part=part)
    assert _same(_Link2(s, g, i0, i1, part=part, row0=_row0(s, g, part)), alone)
    # Seeded fault: the shared row of the other part (the tool's for link 2, and the reverse).
    assert not _same(_Link2(s, g, i0, i1, part=part, row0=_row0(s, g, 1 if part == TOOL
                                                                      else TOOL)), alone)


def test_ball_ends_are_the_balls_and_a_term_stays_itself():
    import z3

    x = arb(1, 0.25)                        # the ball [0.75, 1.25] (its radius rounded up)
    assert _upper(x) >= arb(1.25) and _upper(x) < arb(1.25 + 1e-6)
    assert _lower(x) <= arb(0.75) and _lower(x) > arb(0.75 - 1e-6)
    t = z3.Real("t")
    assert _upper(t) is t and _lower(t) is t
    # Seeded fault: an end taken at the ball's middle is not at or above every point.
    assert not (x.mid() >= arb(1.2)) and _upper(x) >= arb(1.2)
