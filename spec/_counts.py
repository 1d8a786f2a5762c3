"""Grid counts from a scenario's numbers, in exact rationals (docs/model.md §2).

Pure functions of the doubles a scenario holds, so that the loader (which sizes the grid and
places the subordinate's start and goal before building a Scenario), the grid, the contracts
and the obligations count and judge the same way. This module owns the counts.

Two readings of every number (``READINGS``). *Binary*: the IEEE double the code computes with,
as the exact rational it is (``Fraction(0.02)`` = 0.0200000000000000004163...), the reading the
planner's safety rests on. *Decimal*: the number as written, recovered from the double itself as
``Fraction(repr(x))`` (repr is the shortest decimal that rounds to the same double, so it is the
text as written whenever that has at most 17 significant digits and no superfluous ones).

``time_steps`` gives the least N >= 1 with N dt >= Tf in both readings. ``joint_grid`` gives
m_q and the float spacing h_q = (hi - lo) / (m_q - 1) the planner uses; it starts from the least
m with (hi - lo) / (m - 1) <= omega dt in both readings, then adds a point while the float h
exceeds the exact binary bound or the grid misses the upper limit: when (hi - lo) / (omega dt) is
an integer in decimal, the rounded float h can exceed the exact product of the doubles by an
ulp, so the round-number grid is unsafe and one more point makes it safe.
"""

from __future__ import annotations

from collections.abc import Sequence
from fractions import Fraction

__all__ = ["READINGS", "SPAN_TOLERANCE", "MAX_EXTRA_POINTS", "GridRefused", "ceil_fraction",
           "decimal", "joint_grid", "joint_points", "min_points", "spacing_ok", "spacing_readings",
           "time_readings", "travel_time", "time_steps"]

#: The two readings of a number in a scenario file (see the module docstring).
READINGS = ("binary", "decimal")
#: The grid's last point lo + (m - 1) h must lie this close to the upper limit (rad).
SPAN_TOLERANCE = 1e-9
#: Points ``joint_grid`` may add beyond the exact count before it gives up (then the loader
#: refuses the joint with exit 2). One is all any workcell within the physical range needs.
MAX_EXTRA_POINTS = 4


class GridRefused(ValueError):
    """No grid of a joint could be confirmed safe (the loader turns this into an InputError)."""


def ceil_fraction(x: Fraction) -> int:
    """The least integer >= x."""
    return -((-x.numerator) // x.denominator)


def decimal(x: float) -> Fraction:
    """The decimal reading of a double: the shortest decimal that rounds to it, exactly."""
    return Fraction(repr(float(x)))


def _read(x: float, reading: str) -> Fraction:
    if reading == "binary":
        return Fraction(x)
    if reading == "decimal":
        return decimal(x)
    raise ValueError(f"unknown reading {reading!r} (known: {', '.join(READINGS)})")


def travel_time(start: Sequence[float], goal: Sequence[float], omega: Sequence[float],
                reading: str = "binary") -> Fraction:
    """Tf = max_q |goal_q - start_q| / omega_q, exactly, in ``reading``."""
    return max(abs(_read(goal[q], reading) - _read(start[q], reading)) / _read(omega[q], reading)
               for q in range(2))


def time_readings(start: Sequence[float], goal: Sequence[float], omega: Sequence[float],
                  dt: float) -> dict[str, tuple[Fraction, Fraction]]:
    """{reading: (dt, Tf)} for both readings, exactly."""
    return {r: (_read(dt, r), travel_time(start, goal, omega, r)) for r in READINGS}


def time_steps(start: Sequence[float], goal: Sequence[float], omega: Sequence[float],
               dt: float) -> int:
    """N: the least N >= 1 with N dt >= Tf in both readings (exactly)."""
    return max([1] + [ceil_fraction(tf / d)
                      for d, tf in time_readings(start, goal, omega, dt).values()])


def spacing_readings(lo: float, hi: float, omega: float, dt: float
                     ) -> dict[str, tuple[Fraction, Fraction]]:
    """{reading: (hi - lo, omega dt)} for both readings, exactly."""
    return {r: (_read(hi, r) - _read(lo, r), _read(omega, r) * _read(dt, r)) for r in READINGS}


def spacing_ok(lo: float, hi: float, omega: float, dt: float, m: int, h: float) -> bool:
    """Whether m points spaced by the float h are safe: (hi - lo) / (m - 1) <= omega dt in both
    readings, the float h <= omega dt exactly (binary), and the last point within
    SPAN_TOLERANCE of hi."""
    if m < 2:
        return False
    readings = spacing_readings(lo, hi, omega, dt)
    if any(span / (m - 1) > step for span, step in readings.values()):
        return False
    if Fraction(h) > readings["binary"][1]:
        return False
    return abs(lo + (m - 1) * h - hi) <= SPAN_TOLERANCE


def joint_grid(lo: float, hi: float, omega: float, dt: float,
               extra: int | None = None) -> tuple[int, float]:
    """(m, h): the points of one joint and their float spacing, safe by construction.

    m starts at the least count with (hi - lo) / (m - 1) <= omega dt in both readings; a point
    is added while ``spacing_ok`` fails, at most ``extra`` (default MAX_EXTRA_POINTS) times,
    after which GridRefused is raised.
    """
    limit = MAX_EXTRA_POINTS if extra is None else extra
    m = min_points(lo, hi, omega, dt)
    for _ in range(limit + 1):
        h = (hi - lo) / (m - 1)
        if spacing_ok(lo, hi, omega, dt, m, h):
            return m, h
        m += 1
    raise GridRefused(f"no grid of [{lo!r}, {hi!r}] with spacing <= omega dt = {omega!r} * "
                      f"{dt!r} could be confirmed within {limit} extra point(s)")


def min_points(lo: float, hi: float, omega: float, dt: float) -> int:
    """The least m >= 2 with (hi - lo) / (m - 1) <= omega dt in both readings, in exact integers
    (no float is formed, so the loader can hold it to the budget first)."""
    return max([2] + [ceil_fraction(span / step) + 1
                      for span, step in spacing_readings(lo, hi, omega, dt).values()])


def joint_points(lo: float, hi: float, omega: float, dt: float) -> int:
    """m_q, as ``joint_grid`` gives it."""
    return joint_grid(lo, hi, omega, dt)[0]
