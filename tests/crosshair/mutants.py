"""Seeded faults in copies of the functions targets.py checks: CrossHair must find a
counterexample to each (tests/crosshair/test_crosshair.py), or the contracts prove nothing."""

from __future__ import annotations

import math
from fractions import Fraction

from cfmpa.impl import SNAP
from crosshair import realize


def _lattice_range_floor_hi(lo: float, hi: float, anchor: float, g: float) -> tuple[int, int]:
    i_lo = math.floor((lo - anchor) / g + SNAP)
    i_hi = math.floor((hi - anchor) / g - SNAP)          # fault: floor, so hi may be uncovered
    return (min(i_lo, i_hi), max(i_lo, i_hi))


def mutant_lattice_range_covers_the_box(lo: float, hi: float, anchor: float, g: float) -> None:
    assert -4.0 <= lo <= hi <= 4.0 and -4.0 <= anchor <= 4.0 and 0.01 <= g <= 3.14
    i_lo, i_hi = _lattice_range_floor_hi(lo, hi, anchor, g)
    assert anchor + i_hi * g >= hi - SNAP * g


def mutant_reach_without_the_cap(l2: float, w: float, u: float, v: float) -> None:
    # fault: R_elbow = hypot(l2, w/2), forgetting that the rectangle extends w/2 past the tip
    assert 0.05 <= l2 <= 1.0 and 0.01 <= w <= 0.2 and -1.0 <= u <= 1.0 and -1.0 <= v <= 1.0
    r_elbow = math.hypot(realize(l2), realize(w) / 2)
    along, across = (l2 + w) * (u + 1) / 2 - w / 2, v * w / 2
    assert along ** 2 + across ** 2 <= r_elbow ** 2 * (1 + 1e-12)


def mutant_cost_keys_with_a_narrow_shift(a1: int, a2: int, b1: int, b2: int) -> None:
    assert 0 <= a1 < 2 ** 30 and 0 <= b1 < 2 ** 30 and 0 <= a2 <= 2 * a1 and 0 <= b2 <= 2 * b1
    shift = 1                                            # fault: J2 overflows into J1's bits
    ka, kb = a1 * 2 ** shift + a2, b1 * 2 ** shift + b2
    assert (ka < kb) == ((a1, a2) < (b1, b2))


def mutant_ceil_is_floor(p: int, q: int) -> None:
    assert 1 <= q <= 10 ** 6 and -10 ** 9 <= p <= 10 ** 9
    x = Fraction(p, q)
    c = x.numerator // x.denominator                    # fault: floor
    assert c * q >= p and (c - 1) * q < p


def mutant_modified_box_both_sided(a0: float, g0: float, w: float) -> None:
    assert -3.0 <= a0 <= 3.0 and -3.0 <= g0 <= 3.0 and abs(g0 - a0) >= 0.1 and 0.5 <= w <= 2.0
    step = w * 0.02
    sign = 1.0                                           # fault: the sign ignores the direction
    lo, hi = min(a0, a0 + sign * step), max(a0, a0 + sign * step)
    if g0 > a0:
        assert abs(lo - a0) <= 1e-12 and abs(hi - (a0 + step)) <= 1e-12
    else:
        assert abs(hi - a0) <= 1e-12 and abs(lo - (a0 - step)) <= 1e-12
