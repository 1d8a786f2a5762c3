"""Contracts on the small pure functions the geometry rests on, for CrossHair to search for
counterexamples (``assert`` style: the leading asserts are preconditions, the rest
postconditions). Run by tests/crosshair/test_crosshair.py under the ``slow`` marker.

CrossHair reasons about float arithmetic as real arithmetic, so these are statements about the
formulas, not about IEEE rounding (that is what the exact checks on data are for).
"""

from __future__ import annotations

import math
from fractions import Fraction

from cfmpa.impl import SNAP, lattice_range, link_reach
from cfmpa.impl._search import J2_MASK, SHIFT
from cfmpa.spec import Scenario, Variant, left_box
from cfmpa.spec._counts import ceil_fraction
from cfmpa.spec._scenario import LeftArm
from crosshair import realize


def lattice_range_covers_the_box(lo: float, hi: float, anchor: float, g: float) -> None:
    """The lattice indices reach past both ends of [lo, hi] (up to the snap slack SNAP g), and
    no further than one spacing."""
    assert -4.0 <= lo <= hi <= 4.0 and -4.0 <= anchor <= 4.0 and 0.01 <= g <= 3.14
    i_lo, i_hi = lattice_range(lo, hi, anchor, g)
    assert i_lo <= i_hi
    assert anchor + i_lo * g <= lo + SNAP * g
    assert anchor + i_hi * g >= hi - SNAP * g
    assert anchor + (i_lo + 1) * g > lo and anchor + (i_hi - 1) * g < hi


def reach_bounds_every_point_of_link_2(l1: float, l2: float, w: float, u: float, v: float,
                                       t2: float) -> None:
    """A point of link 2's rectangle (length l2 + w, width w, at elbow angle t2) is within
    R_elbow of the elbow and R_base of the base."""
    assert 0.05 <= l1 <= 1.0 and 0.05 <= l2 <= 1.0 and 0.01 <= w <= 0.2
    assert -1.0 <= u <= 1.0 and -1.0 <= v <= 1.0 and -math.pi <= t2 <= math.pi
    # numpy's hypot takes no symbolic values: the arm is concrete on each path CrossHair tries.
    l1, l2, w = realize(l1), realize(l2), realize(w)
    arm = LeftArm(base=(0.0, 0.0), links=(l1, l2), width=w, omega=(1.0, 1.0),
                  start=(0.0, 0.0), goal=(0.0, 0.0))
    r_base, r_elbow = link_reach(arm, 1)
    # The point along the link (from -w/2 to l2 + w/2) and across it (within w/2).
    along, across = (l2 + w) * (u + 1) / 2 - w / 2, v * w / 2
    px = l1 + along * math.cos(t2) - across * math.sin(t2)
    py = along * math.sin(t2) + across * math.cos(t2)
    assert (px - l1) ** 2 + py ** 2 <= r_elbow ** 2 * (1 + 1e-12)
    assert px ** 2 + py ** 2 <= r_base ** 2 * (1 + 1e-12)


def modified_box_is_one_sided(a0: float, g0: float, w: float) -> None:
    """The modified variant's box at layer 0 runs from the start one step of omega dt towards
    the goal, and the original's two steps wide around the start."""
    assert -3.0 <= a0 <= 3.0 and -3.0 <= g0 <= 3.0 and abs(g0 - a0) >= 0.1 and 0.5 <= w <= 2.0
    a0, g0, w = realize(a0), realize(g0), realize(w)     # left_box computes with numpy
    s = Scenario(name="x", purpose="x", dt=0.02,
                 left=LeftArm(base=(0.0, 0.0), links=(0.35, 0.3), width=0.06, omega=(w, w),
                              start=(a0, a0), goal=(g0, g0)),
                 right=None)  # type: ignore[arg-type]  # left_box reads the left arm only
    (lo, hi), _ = left_box(s, Variant.MODIFIED, 0)
    step = w * 0.02
    if g0 > a0:
        assert abs(lo - a0) <= 1e-12 and abs(hi - (a0 + step)) <= 1e-12
    else:
        assert abs(hi - a0) <= 1e-12 and abs(lo - (a0 - step)) <= 1e-12
    (olo, ohi), _ = left_box(s, Variant.ORIGINAL, 0)
    assert olo <= lo and hi <= ohi


def cost_keys_order_like_the_pairs(a1: int, a2: int, b1: int, b2: int) -> None:
    """J1 * 2**SHIFT + J2 unpacks to (J1, J2) and orders like (J1, J2) lexicographically, for the
    costs the search can meet (J2 <= 2 J1, J1 < 2**30)."""
    assert 0 <= a1 < 2 ** 30 and 0 <= b1 < 2 ** 30 and 0 <= a2 <= 2 * a1 and 0 <= b2 <= 2 * b1
    # As the search adds costs (J1 << SHIFT) + J2, written as a product (the same for J1 >= 0),
    # which CrossHair's integer reasoning follows (it found no overflow through the shift).
    ka, kb = a1 * 2 ** SHIFT + a2, b1 * 2 ** SHIFT + b2
    assert (ka >> SHIFT, ka & J2_MASK) == (a1, a2)
    assert (ka < kb) == ((a1, a2) < (b1, b2))


def ceil_of_a_fraction(p: int, q: int) -> None:
    """ceil_fraction is the least integer >= p / q."""
    assert 1 <= q <= 10 ** 6 and -10 ** 9 <= p <= 10 ** 9
    c = ceil_fraction(Fraction(p, q))
    assert c * q >= p and (c - 1) * q < p
